"""The bus models as petriflow channel models: deciding a message's fate when it is sent.

:meth:`BusModel.deliver <petriflow.agents.bus.medium.BusModel.deliver>` hands each
message to a :class:`ChannelState`, which keeps the bus's state between messages and
decides each one by looking ahead on a copy of it (the approximations this implies are
listed in :mod:`petriflow.agents.bus.medium`'s docstring).

Examples:
    >>> from petriflow.agents.bus.medium import CanBus, SerialBus
    >>> from petriflow.runtime.channels import Message
    >>> import random
    >>> bus = SerialBus()
    >>> first = Message("inbox", "a", "b", {"size": 9}, time=0.0, size=9)
    >>> round(bus.deliver(first, random.Random(0)) * 1e6)       # 100 bits at 115 200 baud
    868
    >>> bus.deliver(Message("inbox", "c", "b", {}, 0.0004, 9), random.Random(0)) is None  # overlaps
    True
    >>> can = CanBus()
    >>> long = Message("inbox", "a", "b", b"0123456789abcdef", 0.0, 16)
    >>> can.deliver(long, random.Random(0)) > 2 * 44 / 512_000  # two frames, back to back
    True
"""

from __future__ import annotations

import copy
import math
import random
from typing import TYPE_CHECKING, Any

from petriflow.agents.bus.timeline import MODULE, Timeline

from petriflow.runtime.channels import Message

if TYPE_CHECKING:
    from petriflow.agents.bus.medium import BusModel, Frame, Medium

__all__ = ["ChannelState", "payload_of"]

#: How far ahead (simulated seconds) a message's fate is looked for before it counts as lost.
HORIZON = 3600.0


def payload_of(message: Message) -> bytes:
    """The bytes a message puts on the bus: its data if that is ``bytes``, else a fixed
    pattern of ``message.size`` bytes (so CAN's bit stuffing sees ordinary bits).

    Examples:
        >>> payload_of(Message("p", "a", "b", b"hi", 0.0, 2))
        b'hi'
        >>> payload_of(Message("p", "a", "b", {"size": 3}, 0.0, 3)).hex()
        '0b3055'
    """
    if isinstance(message.data, (bytes, bytearray)):
        return bytes(message.data)
    if isinstance(message.data, dict) and isinstance(message.data.get("payload"), (bytes, bytearray)):
        return bytes(message.data["payload"])
    return bytes((11 + 37 * i) & 0xFF for i in range(max(message.size, 0)))


class ChannelState:
    """A bus's state as a channel model sees it: one medium, advanced message by message.

    Args:
        bus: the bus parameters.
        rng: random numbers of the medium (seeded from the run's channel generator).
    """

    def __init__(self, bus: BusModel, rng: random.Random) -> None:
        self.bus = bus
        self.timeline = Timeline()
        self.medium: Medium = bus.medium(self.timeline, rng)
        self.pending: dict[tuple[Any, int | None], tuple[Message, float]] = {}
        self.medium.read_on_arrival = set()  # the modules that read on arrival (read period 0)
        self.last_end = None
        self.numbers: dict[str | None, int] = {}
        self.sent = 0
        self.multicast: tuple[Any, dict[str | None, float | None], dict[str | None, str]] | None = None
        self.reasons: dict[str | None, str] = {}
        self.tags: tuple[Any, ...] = ()
        self.periods: dict[int, float] = {}

    def module(self, agent: str | None) -> int:
        """The module number of an agent (the next free number the first time)."""
        if agent not in self.numbers:
            number = self.numbers[agent] = len(self.numbers)
            self.medium.add_module(number)
            period = self.bus.read_period_of(agent)
            self.periods[number] = period
            if period > 0.0:
                first = math.ceil(self.timeline.now / period) * period
                self.timeline.at(first, self._read, number, rank=MODULE)
            else:
                self.medium.read_on_arrival.add(number)
        return self.numbers[agent]

    def _read(self, module: int) -> None:
        self.medium.read(module)
        self.timeline.after(self.periods[module], self._read, module, rank=MODULE)

    def quiet_for(self, now: float) -> float:
        """How long the medium has been silent at ``now`` (0 while a frame is on it).
        The bus is run up to ``now`` first (later messages cannot come earlier)."""
        if now > self.timeline.now:
            self.timeline.run(until=now)
        ends = [t.end for t in self.medium.transmissions]
        if any(t.start <= now < t.end for t in self.medium.transmissions):
            return 0.0
        done = [end for end in ends if end <= now]
        last = max(done + ([self.last_end] if self.last_end is not None and self.last_end <= now else []),
                   default=None)
        return now if last is None else now - last

    def frames(self, message: Message, targets: list[str | None] | None = None) -> list[Frame]:
        """The frames that carry ``message`` (one, or several of ``payload_limit`` bytes)
        to its receiver, or to every agent of ``targets``."""
        from petriflow.agents.bus.medium import Frame

        sender = self.module(message.sender)
        if targets is not None:
            receivers = tuple(self.module(t) for t in targets)
        else:
            receivers = (self.module(message.receiver),) if message.receiver is not None else ()
        identifier = message.data.get("identifier") if isinstance(message.data, dict) else None
        if not isinstance(identifier, int) or isinstance(identifier, bool):
            identifier = 0x100 + sender
        data = payload_of(message)
        limit = self.bus.payload_limit()
        chunks = [data[i:i + limit] for i in range(0, len(data), limit)] or [b""]
        self.sent += 1
        return [Frame(sender, receivers, chunk, identifier, (self.sent, index)) for index, chunk in enumerate(chunks)]

    def deliver(self, message: Message) -> float | None:
        """The delay until the receiver reads the whole message, or ``None`` if it is lost.

        A message whose data names a ``multicast`` group and its ``receivers`` (agents)
        is one frame addressed to all of them (as a module sends one message to both
        neighbours): its first copy puts the frame on the bus and decides every
        receiver's fate; the other copies of the group (same sender, same time) only
        read theirs.
        """
        data = message.data if isinstance(message.data, dict) else {}
        group = data.get("multicast")
        if group is not None:
            key = (message.sender, group, message.time)
            if self.multicast is not None and self.multicast[0] == key:
                self.bus.loss_reason = self.multicast[2].get(message.receiver)
                return self._remember(message, self.multicast[3], self.multicast[1].get(message.receiver))
            targets = list(data.get("receivers") or [message.receiver])
            if message.receiver not in targets:
                targets.append(message.receiver)
            fates = self._decide(message, targets)
            self.multicast = (key, fates, dict(self.reasons), self.tags)
            self.bus.loss_reason = self.reasons.get(message.receiver)
            return self._remember(message, self.tags, fates.get(message.receiver))
        fates = self._decide(message, None)
        self.bus.loss_reason = self.reasons.get(message.receiver)
        return self._remember(message, self.tags, fates[message.receiver])

    def _remember(self, message: Message, tags: tuple[Any, ...], delay: float | None) -> float | None:
        """Keep a message that will be read later: a later frame may overwrite it first."""
        if delay is not None and delay > 0.0 and message.receiver is not None:
            module = self.numbers.get(message.receiver)
            for tag in tags:
                self.pending[(tag, module)] = (message, message.time + delay)
        return delay

    def _revoke(self, losses: list[Any], now: float) -> None:
        """Frames already promised to a receiver that this new frame overwrote in its
        buffer before the receiver read them, or garbled on the medium (a collision
        with a frame still on the bus): their messages are lost after all."""
        self.pending = {key: value for key, value in self.pending.items() if value[1] > now}
        for loss in losses:
            keys = [(loss.frame.tag, loss.module)] if loss.module is not None else [
                key for key in self.pending if key[0] == loss.frame.tag]  # garbled on the bus: for everyone
            for key in keys:
                entry = self.pending.pop(key, None)
                if entry is not None and entry[0].revoked is None:
                    entry[0].revoked = loss.reason.value

    def _decide(self, message: Message, targets: list[str | None] | None) -> dict[str | None, float | None]:
        self.timeline.run(until=message.time)
        frames = self.frames(message, targets)
        # The bus parameters are shared, not copied (they hold this state object).
        ahead = copy.deepcopy((self.timeline, self.medium), memo={id(self.bus): self.bus})
        modules = {self.numbers[t]: t for t in targets} if targets is not None else {
            self.numbers.get(message.receiver) if message.receiver is not None else None: message.receiver}
        arrivals, reasons = _look_ahead(ahead[0], ahead[1], frames, list(modules))
        self.reasons = {agent: reasons[module] for module, agent in modules.items() if module in reasons}
        self.tags = tuple(frame.tag for frame in frames)
        self._revoke(ahead[1].losses, message.time)
        for frame in frames:  # the same requests on the kept state: the same draws follow
            self.medium.request(frame)
        medium = self.medium  # the logs are not needed again: keep the copies small
        ended = [t.end for t in medium.transmissions if t.end <= message.time]
        if ended:
            self.last_end = max(ended + ([self.last_end] if self.last_end is not None else []))
        medium.transmissions = [t for t in medium.transmissions if t.end > message.time]
        medium.deliveries.clear()
        medium.losses.clear()
        return {agent: None if arrivals.get(module) is None else max(0.0, arrivals[module] - message.time)
                for module, agent in modules.items()}


def _look_ahead(timeline: Timeline, medium: Medium, frames: list[Frame],
                modules: list[int | None]) -> dict[int | None, float | None]:
    """Request ``frames`` on a copy of the bus and run it until each is read or lost by
    each of ``modules`` (``None``: nobody in particular); for each module, the time it
    read the last frame, or ``None`` if one was lost for it."""
    tags = {frame.tag for frame in frames}
    if not all(medium.request(frame) for frame in frames):
        return {module: None for module in modules}, {module: "queue_full" for module in modules}
    read: dict[int | None, dict[Any, float]] = {module: {} for module in modules}
    lost: dict[int | None, str] = {}
    limit = timeline.now + HORIZON
    seen_deliveries = len(medium.deliveries)
    seen_losses = len(medium.losses)

    def settled() -> bool:
        nonlocal seen_deliveries, seen_losses
        for loss in medium.losses[seen_losses:]:
            if loss.frame.tag not in tags:
                continue
            for module in modules:
                # a frame for nobody is lost only on the bus itself (a collision...)
                if loss.module is None or (module is not None and loss.module == module):
                    lost.setdefault(module, loss.reason.value)
        seen_losses = len(medium.losses)
        for delivery in medium.deliveries[seen_deliveries:]:
            if delivery.frame.tag in tags:
                for module in modules:
                    if module is None or delivery.module == module:
                        read[module][delivery.frame.tag] = delivery.read
        seen_deliveries = len(medium.deliveries)
        if not frames[0].receivers:  # nobody to read it: delivered when it leaves the bus
            for transmission in medium.transmissions:
                if transmission.frame.tag in tags and not transmission.garbled and transmission.end <= timeline.now:
                    for module in modules:
                        read[module][transmission.frame.tag] = transmission.end
        return all(module in lost or len(read[module]) == len(tags) for module in modules)

    while timeline.peek() <= limit:
        timeline.step()
        if settled():
            break
    arrivals = {module: None if module in lost or len(read[module]) < len(tags) else max(read[module].values())
                for module in modules}
    return arrivals, {module: lost.get(module, "unread") for module in modules if arrivals[module] is None}
