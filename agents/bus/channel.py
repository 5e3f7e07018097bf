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
        self.medium.keep_newest = False
        self.medium.read_on_arrival = bus.read_period <= 0.0
        self.numbers: dict[str | None, int] = {}
        self.sent = 0

    def module(self, agent: str | None) -> int:
        """The module number of an agent (the next free number the first time)."""
        if agent not in self.numbers:
            number = self.numbers[agent] = len(self.numbers)
            self.medium.add_module(number)
            period = self.bus.read_period
            if period > 0.0:
                first = math.ceil(self.timeline.now / period) * period
                self.timeline.at(first, self._read, number, rank=MODULE)
        return self.numbers[agent]

    def _read(self, module: int) -> None:
        self.medium.read(module)
        self.timeline.after(self.bus.read_period, self._read, module, rank=MODULE)

    def frames(self, message: Message) -> list[Frame]:
        """The frames that carry ``message`` (one, or several of ``payload_limit`` bytes)."""
        from petriflow.agents.bus.medium import Frame

        sender = self.module(message.sender)
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
        """The delay until the receiver reads the whole message, or ``None`` if it is lost."""
        self.timeline.run(until=message.time)
        frames = self.frames(message)
        # The bus parameters are shared, not copied (they hold this state object).
        ahead = copy.deepcopy((self.timeline, self.medium), memo={id(self.bus): self.bus})
        arrival = _look_ahead(ahead[0], ahead[1], frames)
        for frame in frames:  # the same requests on the kept state: the same draws follow
            self.medium.request(frame)
        medium = self.medium  # the logs are not needed again: keep the copies small
        medium.transmissions = [t for t in medium.transmissions if t.end > message.time]
        medium.deliveries.clear()
        medium.losses.clear()
        return None if arrival is None else max(0.0, arrival - message.time)


def _look_ahead(timeline: Timeline, medium: Medium, frames: list[Frame]) -> float | None:
    """Request ``frames`` on a copy of the bus and run it until each is read or lost;
    the time the last is read, or ``None``."""
    tags = {frame.tag for frame in frames}
    for frame in frames:
        if not medium.request(frame):
            return None
    done: dict[Any, float] = {}
    limit = timeline.now + HORIZON
    seen_deliveries = len(medium.deliveries)
    seen_losses = len(medium.losses)

    def settled() -> bool:
        nonlocal seen_deliveries, seen_losses
        for loss in medium.losses[seen_losses:]:
            receivers = loss.frame.receivers
            if loss.frame.tag in tags and (loss.module is None or not receivers or loss.module in receivers):
                return True
        seen_losses = len(medium.losses)
        for delivery in medium.deliveries[seen_deliveries:]:
            if delivery.frame.tag in tags:
                done[delivery.frame.tag] = delivery.read
        seen_deliveries = len(medium.deliveries)
        if not frames[0].receivers:  # nobody to read it: delivered when it leaves the bus
            for transmission in medium.transmissions:
                if transmission.frame.tag in tags and not transmission.garbled and transmission.end <= timeline.now:
                    done[transmission.frame.tag] = transmission.end
        return len(done) == len(tags)

    while timeline.peek() <= limit:
        timeline.step()
        if settled():
            break
    else:
        return None
    if len(done) < len(tags):
        return None
    return max(done.values())
