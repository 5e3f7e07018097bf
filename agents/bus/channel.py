"""A bus as a petriflow medium: a run's channel messages as frames on the bus, and the
frames' fates as the messages' fates, each when it happens.

:meth:`BusModel.attach <petriflow.agents.bus.parameters.BusModel.attach>` starts a
:class:`Carrier` on the run's kernel; the run hands it every message put into a
channel place the bus carries (:meth:`Carrier.send`), and the carrier:

* numbers the agents as they first appear to the bus (a view asked for, a message
  sent or addressed): the first is module 0, and so on. The number is the module's
  place on a ZigBee chain (``spacing`` metres apart) and, unless the data names an
  ``identifier``, its CAN identifier ``0x100 + number``;
* turns the message into frames: its bytes (:func:`payload_of`) in frames of the
  bus's payload (8 bytes on CAN; a longer message is split and arrives with its last
  frame), addressed to its receiver. A message whose data names a ``multicast`` group
  and its ``receivers`` (agents) is ONE frame addressed to all of them, as a module
  sends one message to both neighbours: its first copy requests the frame, the other
  copies of the group (same sender, same instant, one per receiver's place) join it;
* gives each message its fate when it happens (:class:`~petriflow.runtime.media.MediumPort`):
  delivered when its receiver's module has read its last frame from its receive
  buffer; lost, with the bus's reason (``collision``, ``overwritten``,
  ``queue_full``, ``access_failure``, ``radio``), when one of its frames is lost for
  that receiver or for everyone. A message for no agent (a frame for an address no
  module holds) is delivered when its frame leaves the bus intact.

Firmware asks the bus only through a :class:`BusView` (``ctx.medium(place)``).

Examples:
    >>> from petriflow.agents.bus.parameters import SerialBus
    >>> from petriflow.runtime.channels import Message
    >>> from petriflow.runtime.kernel import Kernel
    >>> from petriflow.runtime.media import MediumPort, ProcessClock
    >>> import random
    >>> seen = []
    >>> clock = ProcessClock(Kernel(dt=0.0001))
    >>> def fate(what, m): seen.append((what, m.data["n"], round(clock.now * 1e6)))
    >>> port = MediumPort(clock, lambda m: fate("delivered", m), lambda m, why: fate(why, m), random.Random(0))
    >>> bus = SerialBus()
    >>> bus.attach(port)
    >>> bus.send(Message("inbox", "a", "b", {"n": 1, "size": 9}, 0.0, 9))   # 100 bits: 868 µs
    >>> _ = clock.at(0.0004, bus.send, Message("inbox", "c", "b", {"n": 2, "size": 9}, 0.0004, 9))
    >>> _ = clock.at(0.002, bus.send, Message("inbox", "c", "b", {"n": 3, "size": 9}, 0.002, 9))
    >>> clock.run(until=0.01)
    >>> seen                                   # 1 and 2 overlap: both lost then; 3 read on arrival
    [('collision', 1, 400), ('collision', 2, 400), ('delivered', 3, 2868)]
    >>> bus.view("b").reads_every(0.005)       # b now reads its buffer every 5 ms
    >>> bus.send(Message("inbox", "a", "b", {"n": 4, "size": 9}, clock.now, 9))
    >>> clock.run(until=0.02); seen[-1]
    ('delivered', 4, 15000)
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from petriflow.agents.bus.records import Delivery, Frame, Lost, Transmission
from petriflow.runtime.channels import Message
from petriflow.runtime.media import MediumPort

if TYPE_CHECKING:
    from petriflow.agents.bus.parameters import BusModel

__all__ = ["BusView", "Carrier", "payload_of"]


def payload_of(message: Message) -> bytes:
    """The bytes a message puts on the bus: its data if that is ``bytes`` (or a
    ``payload`` in a dict), else a fixed pattern of ``message.size`` bytes (so CAN's bit
    stuffing sees ordinary bits).

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


#: The key of a message for no agent among an outgoing message's receivers.
_NOBODY = None


class _Outgoing:
    """One message, or one multicast group's copies, on the bus: the frames each
    receiver (a module number, or :data:`_NOBODY`) still has to read, the copies not yet
    decided, and the fates decided (``None``: delivered, else the loss's reason)."""

    __slots__ = ("left", "messages", "fates")

    def __init__(self, keys: list[int | None], frames: int) -> None:
        self.left: dict[int | None, int] = {key: frames for key in keys}
        self.messages: dict[int | None, Message] = {}
        self.fates: dict[int | None, str | None] = {}

    def joins(self, key: int | None) -> bool:
        """Whether a copy for ``key`` belongs here (a receiver of the frame, not yet joined)."""
        return key in self.left and key not in self.messages and key not in self.fates


class Carrier:
    """One run's messages on one bus (see the module).

    Args:
        bus: the bus parameters.
        port: where the run's clock is and where fates go.
        logs: the bus keeps its transmissions, deliveries and losses.

    Attributes:
        medium: the bus (:class:`~petriflow.agents.bus.buffer.BusMedium`) on the run's kernel.
        numbers: ``{agent: module number}``.
    """

    def __init__(self, bus: BusModel, port: MediumPort, logs: bool = False) -> None:
        import random

        self.bus = bus
        self.port = port
        rng = port.rng if port.rng is not None else random.Random(0)
        self.medium = bus.medium(port.clock, rng, (), logs=logs)
        self.medium.on_delivery(self._read)
        self.medium.on_loss(self._lost)
        self.medium.on_end(self._ended)
        self.numbers: dict[str | None, int] = {}
        self._group: tuple[Any, _Outgoing] | None = None  # the last multicast group sent

    def module(self, agent: str | None) -> int:
        """The module number of an agent (the next free number the first time)."""
        number = self.numbers.get(agent)
        if number is None:
            number = self.numbers[agent] = len(self.numbers)
            self.medium.add_module(number)
        return number

    def _key(self, agent: str | None) -> int | None:
        return _NOBODY if agent is None else self.module(agent)

    def send(self, message: Message) -> None:
        """``message`` is put into its channel place now: request its frames (or join
        its multicast group's frame)."""
        data = message.data if isinstance(message.data, dict) else {}
        group = data.get("multicast")
        now = self.port.clock.now
        key = (message.sender, group, now)
        if group is not None and self._group is not None and self._group[0] == key \
                and self._group[1].joins(self._key(message.receiver)):
            self._join(self._group[1], message)
            return
        targets: list[str | None] = [message.receiver]
        if group is not None:
            targets = list(data.get("receivers") or [message.receiver])
            if message.receiver not in targets:
                targets.append(message.receiver)
        sender = self.module(message.sender)
        keys = list(dict.fromkeys(self._key(t) for t in targets))
        receivers = tuple(k for k in keys if k is not _NOBODY)
        identifier = data.get("identifier")
        if not isinstance(identifier, int) or isinstance(identifier, bool):
            identifier = 0x100 + sender
        payload = payload_of(message)
        limit = self.bus.payload_limit()
        chunks = [payload[i:i + limit] for i in range(0, len(payload), limit)] or [b""]
        outgoing = _Outgoing(keys, len(chunks))
        self._group = (key, outgoing) if group is not None else None
        self._join(outgoing, message)
        for index, chunk in enumerate(chunks):
            if not self.medium.request(Frame(sender, receivers, chunk, identifier, (outgoing, index))):
                break  # the transmit queue was full: the message is lost (the rest is not sent)

    def _join(self, outgoing: _Outgoing, message: Message) -> None:
        key = self._key(message.receiver)
        if key in outgoing.fates:  # decided before this copy came (a full queue, a collision)
            self._give(message, outgoing.fates[key])
        else:
            outgoing.messages[key] = message

    def _decide(self, outgoing: _Outgoing, key: int | None, why: str | None) -> None:
        if key in outgoing.fates:
            return
        outgoing.fates[key] = why
        message = outgoing.messages.pop(key, None)
        if message is not None:
            self._give(message, why)

    def _give(self, message: Message, why: str | None) -> None:
        if why is None:
            self.port.deliver(message)
        else:
            self.port.lose(message, why)

    # The bus's listeners -----------------------------------------------------------
    def _read(self, delivery: Delivery) -> None:
        """A module read a frame addressed to it: the message is delivered with its last frame."""
        outgoing = delivery.frame.tag[0]
        module = delivery.module
        if module in outgoing.left and module not in outgoing.fates:
            outgoing.left[module] -= 1
            if outgoing.left[module] <= 0:
                self._decide(outgoing, module, None)

    def _lost(self, lost: Lost) -> None:
        """A frame was lost for one module (or for all): so are its messages for it."""
        outgoing = lost.frame.tag[0]
        keys = list(outgoing.left) if lost.module is None else [lost.module]
        for key in keys:
            if key in outgoing.left:
                self._decide(outgoing, key, lost.reason.value)

    def _ended(self, transmission: Transmission) -> None:
        """A frame left the bus: intact, it reached a message's nobody."""
        if transmission.garbled:
            return
        outgoing = transmission.frame.tag[0]
        if _NOBODY in outgoing.left and _NOBODY not in outgoing.fates:
            outgoing.left[_NOBODY] -= 1
            if outgoing.left[_NOBODY] <= 0:
                self._decide(outgoing, _NOBODY, None)


class BusView:
    """What one module's firmware may ask its bus (``ctx.medium(place)``); the same
    interface on every bus.

    * :meth:`reads_every`: how often the module reads its receive buffer, and from when;
    * :meth:`quiet_for`: how long the bus has been quiet, now;
    * :attr:`sender_in_identifier`: whether the sender's address travels in the frame's
      identifier (CAN), so a payload need not carry it;
    * :attr:`loop_cost`: what each iteration of the module's loop spends on the bus;
    * :meth:`sniff`, :meth:`captured`: for a sniffer's agent, join the bus as a sniffer
      and count what it captured.

    Args:
        carrier: the run's bus.
        agent: the module's agent.
    """

    __slots__ = ("_carrier", "agent")

    def __init__(self, carrier: Carrier, agent: str | None) -> None:
        self._carrier = carrier
        self.agent = agent

    @property
    def sender_in_identifier(self) -> bool:
        """The sender's address travels in the frame's identifier (CAN)."""
        return bool(self._carrier.bus.sender_in_identifier)

    @property
    def loop_cost(self) -> float:
        """Seconds each iteration of the module's control loop spends on the bus's
        interface (the bus's ``loop_cost``)."""
        return float(self._carrier.bus.loop_cost)

    def reads_every(self, period: float, start: float | None = None) -> None:
        """This module reads its receive buffer every ``period`` seconds (0: on arrival),
        at ``start + k · period``: ``start`` is when its loop's first iteration begins
        (default: now), the module's own phase.

        Raises:
            BusError: a period that is not a number of seconds >= 0.
        """
        carrier = self._carrier
        phase = carrier.port.clock.now if start is None else start
        carrier.medium.reads_every(carrier.module(self.agent), period, phase)

    @property
    def read_period(self) -> float | None:
        """How often this module reads its receive buffer (0: on arrival)."""
        carrier = self._carrier
        return carrier.medium.read_period_of(carrier.module(self.agent))

    def quiet_for(self) -> float:
        """Seconds the bus has carried nothing, now (0 while a frame is on it)."""
        return self._carrier.medium.quiet_for()

    def sniff(self) -> None:
        """This agent is a sniffer on the bus: a node that never sends and takes every
        intact frame that reaches it, whoever it is for, on arrival
        (:meth:`~petriflow.agents.bus.buffer.BusMedium.sniff`)."""
        carrier = self._carrier
        carrier.medium.sniff(carrier.module(self.agent))

    def captured(self) -> dict[str, int]:
        """What this agent captured as a sniffer so far: ``{sender's agent: frames}``."""
        carrier = self._carrier
        counts = carrier.medium.captured.get(carrier.module(self.agent), {})
        agents = {number: agent for agent, number in carrier.numbers.items()}
        return {str(agents[number]): n for number, n in sorted(counts.items()) if number in agents}
