"""One shared bus at bit-level timing: RS-485, CAN and ZigBee, with the losses of real modules.

Every module of the EMERGE chain hangs on one medium. A :class:`Medium` is that
medium's state on a :class:`~petriflow.agents.bus.timeline.Timeline`: modules
:meth:`~Medium.request` frames, the medium puts them on the wire when its access rule
allows, frames occupy it for ``bits / bit rate`` seconds (lengths from
:mod:`~petriflow.agents.bus.frames`), and intact frames land in every other module's
receive buffer, where the module finds them when it next :meth:`~Medium.read` s.
Everything that happens is logged: :attr:`~Medium.transmissions`,
:attr:`~Medium.deliveries` (a module read a frame addressed to it) and
:attr:`~Medium.losses` (a :class:`Loss` reason each).

The three buses (their parameters are :class:`SerialBus`, :class:`CanBus`,
:class:`ZigbeeBus`; ``bus.medium(timeline, rng, modules)`` starts one):

* **RS-485** (:class:`SerialMedium`): a half-duplex line with no arbitration. A UART
  sends whenever its module asks (after its own previous frame). Two frames that
  overlap in time garble each other: both are lost at every receiver (no capture:
  differential drivers fighting give framing and checksum errors). Carrier sense,
  for algorithm 2, sees a frame ``sense_bits`` bit times after its start bit (the
  receiver must sample the start bit), so two modules that check within that window
  both find the line free and collide.
* **CAN** (:class:`CanMedium`): frames wait in the controller's transmit buffers
  until the bus is idle (after the 3-bit intermission). Every node with a pending
  frame starts its SOF at that instant, or, on an idle bus, within
  ``arbitration_bits`` bit times of the first SOF (a node that has not seen the SOF
  yet); these contend bit by bit and the lowest identifier wins, nothing is lost, and
  the losers contend again when the bus is next idle. Two modules may not share an
  identifier (:class:`~petriflow.agents.bus.frames.FrameError`). Error frames, bit
  errors and bus-off are not modelled.
* **ZigBee** (:class:`ZigbeeMedium`): each module talks to its XBee radio over a
  UART at ``uart_baud`` (57 600 baud); the radio starts on a frame after the bytes
  are in and a packetization timeout of ``packetization_chars`` characters (XBee
  transparent mode). The air is 802.15.4 at 250 kbit/s with unslotted CSMA/CA:
  a random backoff of 0..2^BE − 1 unit periods (320 µs), then an 8-symbol clear
  channel assessment; if clear, the radio turns around (12 symbols, 192 µs) and
  sends, else BE grows (3 → 5) and after ``max_backoffs`` = 4 failed assessments the
  frame is dropped (:attr:`Loss.ACCESS_FAILURE`). Two frames that overlap on the air
  are both garbled (no capture). A frame survives each link with the probability of
  :class:`~petriflow.agents.bus.radio.RadioLink` (RSSI from the distance between the
  modules, ``spacing`` metres apart along the chain). Frames are broadcasts (the CPG
  messages carry their addresses in the payload, as in the paper's algorithm), so no
  MAC acknowledgements or retries. After a frame the radio waits the long or short
  interframe spacing. Received frames reach the module after the radio has written
  their payload out over the UART. A module cannot hear the air: for it the "bus" is
  free when its own radio has nothing to send.

Losses common to all three (real modules' limits):

* **Receive buffer** (``rx_buffer`` frames, default 1): a frame that arrives while the
  buffer is full overwrites the oldest unread frame (:attr:`Loss.OVERWRITTEN`). The
  paper's reception routine checks addresses in software ("the receiving module
  rejects the packets that have not been assigned their address"), so by default
  every intact frame enters every module's buffer and a frame for someone else can
  overwrite one for this module; ``acceptance_filter=True`` models a hardware filter
  (CAN acceptance masks, XBee unicast addressing) that keeps them out.
* **Transmit queue** (``tx_queue`` frames waiting besides the one on the wire): a
  request finding it full is dropped (:attr:`Loss.QUEUE_FULL`). Defaults (assumed):
  3 frames for a UART driver's ring buffer and for the XBee's serial buffer, 2 on CAN
  (a controller such as the MCP2515 has three transmit buffers, one of which holds
  the frame being sent). At the paper's rates (about one message a second per
  module) no queue fills; the limit matters for heavier traffic.

Each bus class is also a petriflow
:class:`~petriflow.runtime.channels.ChannelModel`: ``channels: {bus: {model: ...}}``
with the same parameters. A channel model must decide a message's fate when it is
sent, but on a real bus a frame's fate also depends on frames sent after it (a later
frame can overlap it, or overwrite it in a buffer). The adaptor therefore keeps the
bus's full state, advanced in time order as messages come (the runtime hands them
over in time order), and decides each message by running a copy of that state
forward with no further traffic: the message's delay is the time until its
receiver reads its last frame (modules read every ``read_period`` seconds; 0 means
on arrival). A later message can still take back a promise: when its frame collides
with one already promised or overwrites it in a receiver's buffer before it was read,
the earlier message is revoked (:attr:`~petriflow.runtime.channels.Message.revoked`)
and the runtime records it lost at its delivery time, so losses are counted as the bus
makes them (both frames of a collision, the older frame of an overwrite; the receive
buffer keeps the newest). CAN frames requested within one arbitration window go in
request order instead of identifier order. Messages longer than a frame's payload are
split into frames (8 bytes on CAN) and arrive with their last frame. A message's
bytes are its data when that is ``bytes``, else a fixed pattern of its ``size``.
Module numbers follow the order agents first appear (their position on the chain, and
on CAN their identifier ``0x100 + number``, unless the data names an ``identifier``).

Examples:
    >>> from petriflow.agents.bus.timeline import Timeline
    >>> import random
    >>> timeline = Timeline()
    >>> medium = CanBus().medium(timeline, random.Random(0), modules=[0, 1, 2])
    >>> _ = medium.request(Frame(sender=2, receivers=(0,), data=b"late", identifier=0x102))
    >>> _ = medium.request(Frame(sender=1, receivers=(0,), data=b"wins", identifier=0x101))
    >>> timeline.run(until=0.01)
    >>> [t.frame.sender for t in medium.transmissions]   # both started together: 0x101 first
    [1, 2]
    >>> [f.data for f in medium.read(0)]                 # one-frame buffer: the first was overwritten
    [b'late']
    >>> [loss.reason.value for loss in medium.losses]
    ['overwritten']
"""

from __future__ import annotations

import math
import random
from collections import deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

from petriflow.agents.bus.frames import (
    IEEE802154_MAC_HEADER_BYTES,
    IEEE802154_MAX_FRAME_BYTES,
    FrameError,
    can_frame_bits,
    ieee802154_frame_bits,
    uart_frame_bits,
)
from petriflow.agents.bus.errors import BusError
from petriflow.agents.bus.radio import RadioLink
from petriflow.agents.bus.timeline import MEDIUM, Timeline, Timer

from petriflow.outcome import Name
from petriflow.runtime.channels import ChannelModel, Message

__all__ = [
    "BusModel",
    "BusSimulator",
    "CanBus",
    "CanMedium",
    "Delivery",
    "Frame",
    "Loss",
    "Lost",
    "Medium",
    "SerialBus",
    "SerialMedium",
    "Transmission",
    "ZigbeeBus",
    "ZigbeeMedium",
]

# 802.15.4 at 2.4 GHz: 62.5 k symbols a second.
_SYMBOL = 16e-6
_UNIT_BACKOFF = 20 * _SYMBOL
_CCA = 8 * _SYMBOL
_TURNAROUND = 12 * _SYMBOL
_SIFS = 12 * _SYMBOL
_LIFS = 40 * _SYMBOL
_MAX_SIFS_FRAME_BYTES = 18


class Loss(Name):
    """Why a frame did not reach a module."""

    COLLISION = "collision"
    """It overlapped another frame on the medium; both were garbled."""
    OVERWRITTEN = "overwritten"
    """A newer frame took its place in the receive buffer before the module read it."""
    QUEUE_FULL = "queue_full"
    """The sender's transmit queue was full when its module asked to send it."""
    ACCESS_FAILURE = "access_failure"
    """CSMA/CA found the channel busy at every clear channel assessment and gave up."""
    RADIO = "radio"
    """Bit errors on the radio link to this module."""


@dataclass(frozen=True)
class Frame:
    """A frame a module asks its bus to carry.

    Attributes:
        sender: the sending module.
        receivers: the modules it is addressed to (its bytes say so; the medium
            carries it to everyone).
        data: the payload bytes (a CAN frame's data field: at most 8).
        identifier: the CAN identifier (arbitration priority: lower wins).
        tag: anything that identifies the frame to its user (never sent).
    """

    sender: int
    receivers: tuple[int, ...]
    data: bytes
    identifier: int = 0
    tag: Any = None


@dataclass
class Transmission:
    """A frame on the medium from ``start`` to ``end`` (``garbled``: it met another)."""

    frame: Frame
    start: float
    end: float
    bits: int
    garbled: bool = False


@dataclass(frozen=True)
class Delivery:
    """A module read a frame addressed to it: it reached the buffer at ``arrived``."""

    frame: Frame
    module: int
    arrived: float
    read: float


@dataclass(frozen=True)
class Lost:
    """A frame lost for ``module`` (``None``: for every module) at ``time``."""

    frame: Frame
    module: int | None
    reason: Loss
    time: float


@dataclass
class BusModel(ChannelModel):
    """Parameters shared by the buses; a subclass adds its physical layer.

    Attributes:
        tx_queue: frames a module's interface holds waiting besides the one it sends.
        rx_buffer: frames a module's receive buffer holds.
        acceptance_filter: only frames addressed to a module enter its buffer.
        read_period: as a channel model: how often receivers read (0: on arrival).
    """

    tx_queue: int = field(default=3, metadata={"range": (0, 10_000)})
    rx_buffer: int = field(default=1, metadata={"range": (1, 10_000)})
    acceptance_filter: bool = False
    read_period: float = field(default=0.0, metadata={"range": (0.0, 3600.0)})
    _channel: Any = field(default=None, init=False, repr=False, compare=False)
    loss_reason: Any = field(default=None, init=False, repr=False, compare=False)
    _readers: dict[str, float] = field(default_factory=dict, init=False, repr=False, compare=False)

    def payload_limit(self) -> int:
        """Largest payload of one frame in bytes (a longer channel message is split)."""
        return 1 << 30

    def frame_bits(self, frame: Frame) -> int:
        """Bits the frame occupies the medium for."""
        raise NotImplementedError

    def medium(self, timeline: Timeline, rng: random.Random, modules: Iterable[int] = ()) -> Medium:
        """Start this bus on ``timeline`` with ``modules`` attached."""
        raise NotImplementedError

    def deliver(self, message: Message, rng: Any) -> float | None:
        """As a petriflow channel model: the message's delay, or ``None`` if it is lost
        (see the module's docstring for how the bus state is kept between messages)."""
        if self._channel is None:
            from petriflow.agents.bus.channel import ChannelState

            self._channel = ChannelState(self, random.Random(rng.getrandbits(64)))
        return self._channel.deliver(message)

    def reads_every(self, agent: str, period: float) -> None:
        """As a channel model: ``agent``'s module reads its receive buffer every
        ``period`` seconds (0: on arrival) instead of ``read_period`` (its firmware's
        loop says how often; call before its first message)."""
        if not (math.isfinite(period) and period >= 0.0):
            raise BusError(f"a read period is a number of seconds >= 0, got {period!r}")
        self._readers[agent] = float(period)

    def read_period_of(self, agent: str | None) -> float:
        return self._readers.get(agent, self.read_period)

    def quiet_for(self, now: float) -> float:
        """As a channel model: how long the bus has carried nothing at ``now`` (0 while a
        frame is on it); since the first message when none was ever sent."""
        if self._channel is None:
            return now
        return self._channel.quiet_for(now)


@dataclass
class SerialBus(BusModel):
    """RS-485 with UARTs (8N1) at ``baud``; a frame is the payload and a checksum byte.

    Examples:
        >>> SerialBus().frame_bits(Frame(0, (1,), bytes(9)))  # (9 + 1) bytes × 10 bits
        100
    """

    baud: float = field(default=115_200.0, metadata={"range": (1.0, 1e9)})
    checksum_bytes: int = field(default=1, metadata={"range": (0, 16)})
    sense_bits: float = field(default=1.0, metadata={"range": (0.0, 1e6)})

    def frame_bits(self, frame: Frame) -> int:
        return uart_frame_bits(len(frame.data) + self.checksum_bytes)

    def medium(self, timeline: Timeline, rng: random.Random, modules: Iterable[int] = ()) -> SerialMedium:
        return SerialMedium(self, timeline, rng, modules)


@dataclass
class CanBus(BusModel):
    """CAN 2.0A at ``bitrate``; frames are stuffed as their bits require. ``tx_queue``
    defaults to 2: three transmit buffers, one holding the frame on the bus.

    Examples:
        >>> CanBus().frame_bits(Frame(0, (1,), bytes(8), identifier=0x100)) >= 44 + 64
        True
    """

    tx_queue: int = field(default=2, metadata={"range": (0, 10_000)})
    bitrate: float = field(default=512_000.0, metadata={"range": (1.0, 1e9)})
    arbitration_bits: float = field(default=1.0, metadata={"range": (0.0, 1e6)})

    def payload_limit(self) -> int:
        return 8

    def frame_bits(self, frame: Frame) -> int:
        return can_frame_bits(frame.identifier, frame.data, interframe=False)

    def medium(self, timeline: Timeline, rng: random.Random, modules: Iterable[int] = ()) -> CanMedium:
        return CanMedium(self, timeline, rng, modules)


@dataclass
class ZigbeeBus(BusModel):
    """XBee radios: UART at ``uart_baud`` to each module, 802.15.4 CSMA/CA on the air.

    Examples:
        >>> bus = ZigbeeBus()
        >>> bus.frame_bits(Frame(0, (1,), bytes(9)))   # 6 PHY + 9 MAC + 16 NWK/APS + 9 + 2 FCS bytes
        336
        >>> round(bus.link().rssi(0.08), 1)
        -18.1
    """

    uart_baud: float = field(default=57_600.0, metadata={"range": (1.0, 1e9)})
    air_bitrate: float = field(default=250_000.0, metadata={"range": (1.0, 1e9)})
    network_bytes: int = field(default=16, metadata={"range": (0, 100)})
    packetization_chars: float = field(default=3.0, metadata={"range": (0.0, 1000.0)})
    min_be: int = field(default=3, metadata={"range": (0, 8)})
    max_be: int = field(default=5, metadata={"range": (3, 8)})
    max_backoffs: int = field(default=4, metadata={"range": (0, 5)})
    spacing: float = field(default=0.08, metadata={"range": (0.0, 1e4)})
    tx_power_dbm: float = field(default=0.0, metadata={"range": (-100.0, 40.0)})
    reference_loss_db: float = field(default=40.0, metadata={"range": (0.0, 200.0)})
    exponent: float = field(default=2.0, metadata={"range": (1.0, 8.0)})
    noise_floor_dbm: float = field(default=-93.0, metadata={"range": (-200.0, 0.0)})
    interference_dbm: float = field(default=-200.0, metadata={"range": (-200.0, 40.0)})
    shadowing_db: float = field(default=0.0, metadata={"range": (0.0, 40.0)})

    def __post_init__(self) -> None:
        if self.min_be > self.max_be:
            raise FrameError(f"min_be {self.min_be} is above max_be {self.max_be}")

    def payload_limit(self) -> int:
        return IEEE802154_MAX_FRAME_BYTES - IEEE802154_MAC_HEADER_BYTES - self.network_bytes - 2

    def frame_bits(self, frame: Frame) -> int:
        return ieee802154_frame_bits(len(frame.data), network_bytes=self.network_bytes)

    def link(self) -> RadioLink:
        """The radio link model every pair of modules shares."""
        interference = -math.inf if self.interference_dbm <= -200.0 else self.interference_dbm
        return RadioLink(self.tx_power_dbm, self.reference_loss_db, self.exponent, self.noise_floor_dbm,
                         interference, self.shadowing_db)

    def medium(self, timeline: Timeline, rng: random.Random, modules: Iterable[int] = ()) -> ZigbeeMedium:
        return ZigbeeMedium(self, timeline, rng, modules)


class Medium:
    """The state of one bus on a timeline (see the module docstring for the rules).

    Args:
        bus: the bus parameters.
        timeline: the clock shared with the modules.
        rng: the medium's random numbers (backoffs, radio errors).
        modules: the modules attached from the start (more with :meth:`add_module`).

    Attributes:
        transmissions: every frame put on the medium, in start order.
        deliveries: every frame a module read that was addressed to it.
        losses: every loss, with its reason.
        keep_newest: a full receive buffer drops its oldest frame for a new one (the
            hardware's behaviour); ``False`` drops the new one.
    """

    def __init__(self, bus: BusModel, timeline: Timeline, rng: random.Random, modules: Iterable[int] = ()) -> None:
        self.bus = bus
        self.timeline = timeline
        self.rng = rng
        self.modules: list[int] = []
        self.transmissions: list[Transmission] = []
        self.deliveries: list[Delivery] = []
        self.losses: list[Lost] = []
        self.keep_newest = True
        self.read_on_arrival = False
        self._buffers: dict[int, deque[tuple[Frame, float]]] = {}
        self._queues: dict[int, deque[Frame]] = {}
        self._idle_listeners: list[Callable[[int], Any]] = []
        for module in modules:
            self.add_module(module)

    # The modules' side -------------------------------------------------------------
    def add_module(self, module: int) -> None:
        """Attach a module (a no-op if it is attached)."""
        if module not in self._buffers:
            self.modules.append(module)
            self._buffers[module] = deque()
            self._queues[module] = deque()

    def request(self, frame: Frame) -> bool:
        """The sender's module asks to send ``frame`` now; ``False`` if its transmit queue
        was full and the frame is dropped.

        Raises:
            FrameError: the bus cannot carry this frame, or the sender is not attached.
        """
        if frame.sender not in self._queues:
            raise FrameError(f"module {frame.sender} is not attached to this bus")
        self.bus.frame_bits(frame)  # raises for a frame the bus cannot carry
        return self._request(frame)

    def read(self, module: int) -> list[Frame]:
        """The module empties its receive buffer; returns the frames addressed to it
        (oldest first), which count as delivered. Frames for others are discarded."""
        buffer = self._buffers[module]
        frames = []
        now = self.timeline.now
        while buffer:
            frame, arrived = buffer.popleft()
            if module in frame.receivers:
                frames.append(frame)
                self.deliveries.append(Delivery(frame, module, arrived, now))
        return frames

    def is_free(self, module: int) -> bool:
        """Whether the bus looks free to ``module`` now (algorithm 2's "bus available")."""
        raise NotImplementedError

    def on_idle(self, callback: Callable[[int], Any]) -> None:
        """Call ``callback(module)`` whenever the bus turns free in ``module``'s view
        (a bound method: the medium must stay copyable)."""
        self._idle_listeners.append(callback)

    def pending(self, module: int) -> int:
        """Frames the module's interface still holds (waiting or on the medium)."""
        return len(self._queues[module])

    # Shared mechanics ---------------------------------------------------------------
    def _request(self, frame: Frame) -> bool:
        raise NotImplementedError

    def _enqueue(self, frame: Frame, in_service: bool) -> bool:
        """Put a frame in its sender's queue (the head is the one in service)."""
        queue = self._queues[frame.sender]
        if len(queue) - int(in_service) >= self.bus.tx_queue:
            self.losses.append(Lost(frame, None, Loss.QUEUE_FULL, self.timeline.now))
            return False
        queue.append(frame)
        return True

    def _arrive(self, frame: Frame, module: int) -> None:
        """An intact frame reaches ``module``'s receive buffer now."""
        if self.bus.acceptance_filter and module not in frame.receivers:
            return
        now = self.timeline.now
        if self.read_on_arrival is True or (self.read_on_arrival and module in self.read_on_arrival):
            if module in frame.receivers:
                self.deliveries.append(Delivery(frame, module, now, now))
            return
        buffer = self._buffers[module]
        if len(buffer) >= self.bus.rx_buffer:
            if not self.keep_newest:
                self.losses.append(Lost(frame, module, Loss.OVERWRITTEN, now))
                return
            old, _ = buffer.popleft()
            self.losses.append(Lost(old, module, Loss.OVERWRITTEN, now))
        buffer.append((frame, now))

    def _notify_idle(self, modules: Iterable[int]) -> None:
        for module in modules:
            for callback in self._idle_listeners:
                callback(module)


class SerialMedium(Medium):
    """An RS-485 line: frames go out when asked; overlapping frames garble each other."""

    bus: SerialBus

    def __init__(self, bus: SerialBus, timeline: Timeline, rng: random.Random, modules: Iterable[int] = ()) -> None:
        super().__init__(bus, timeline, rng, modules)
        self._active: list[Transmission] = []

    def is_free(self, module: int) -> bool:
        horizon = self.timeline.now - self.bus.sense_bits / self.bus.baud
        return not self._queues[module] and not any(t.start <= horizon for t in self._active)

    def _request(self, frame: Frame) -> bool:
        busy = bool(self._queues[frame.sender])
        if not self._enqueue(frame, busy):
            return False
        if not busy:
            self._start(frame)
        return True

    def _start(self, frame: Frame) -> None:
        now = self.timeline.now
        bits = self.bus.frame_bits(frame)
        transmission = Transmission(frame, now, now + bits / self.bus.baud, bits)
        for other in self._active:
            other.garbled = transmission.garbled = True
        self._active.append(transmission)
        self.transmissions.append(transmission)
        self.timeline.at(transmission.end, self._end, transmission, rank=MEDIUM)

    def _end(self, transmission: Transmission) -> None:
        self._active.remove(transmission)
        frame = transmission.frame
        if transmission.garbled:
            self.losses.append(Lost(frame, None, Loss.COLLISION, self.timeline.now))
        else:
            for module in self.modules:
                if module != frame.sender:
                    self._arrive(frame, module)
        queue = self._queues[frame.sender]
        queue.popleft()
        if queue:
            self._start(queue[0])
        if not self._active:
            self._notify_idle(self.modules)


class CanMedium(Medium):
    """A CAN bus: frames wait for an idle bus; simultaneous starts arbitrate by identifier."""

    bus: CanBus

    def __init__(self, bus: CanBus, timeline: Timeline, rng: random.Random, modules: Iterable[int] = ()) -> None:
        super().__init__(bus, timeline, rng, modules)
        self._current: Transmission | None = None
        self._busy_until = -math.inf
        self._start_of_frame: float | None = None  # SOF of an arbitration not yet decided
        self._idle_timer: Timer | None = None

    def is_free(self, module: int) -> bool:
        now = self.timeline.now
        if self._current is not None or now < self._busy_until:
            return False
        sof = self._start_of_frame
        return sof is None or now < sof + self._window()

    def _window(self) -> float:
        return self.bus.arbitration_bits / self.bus.bitrate

    def _request(self, frame: Frame) -> bool:
        current = self._current
        if not self._enqueue(frame, current is not None and current.frame.sender == frame.sender):
            return False
        now = self.timeline.now
        if self._current is None and self._start_of_frame is None and now >= self._busy_until:
            if self._idle_timer is not None:
                self._idle_timer.cancel()
                self._idle_timer = None
            self._begin_arbitration(now)
        return True

    def _begin_arbitration(self, start: float) -> None:
        self._start_of_frame = start
        self.timeline.at(start + self._window(), self._arbitrate, rank=MEDIUM)

    def _arbitrate(self) -> None:
        start = self._start_of_frame
        assert start is not None
        self._start_of_frame = None
        heads = [queue[0] for queue in self._queues.values() if queue]
        winner = min(heads, key=lambda f: f.identifier)
        if sum(f.identifier == winner.identifier for f in heads) > 1:
            raise FrameError(f"two modules arbitrate with the same identifier {winner.identifier:#x}")
        bits = self.bus.frame_bits(winner)
        transmission = Transmission(winner, start, start + bits / self.bus.bitrate, bits)
        self._current = transmission
        self.transmissions.append(transmission)
        self.timeline.at(transmission.end, self._end, transmission, rank=MEDIUM)

    def _end(self, transmission: Transmission) -> None:
        frame = transmission.frame
        self._queues[frame.sender].popleft()
        self._current = None
        for module in self.modules:
            if module != frame.sender:
                self._arrive(frame, module)
        self._busy_until = transmission.end + 3 / self.bus.bitrate
        self._idle_timer = self.timeline.at(self._busy_until, self._idle, rank=MEDIUM)

    def _idle(self) -> None:
        self._idle_timer = None
        if any(self._queues.values()):
            self._begin_arbitration(self.timeline.now)
        else:
            self._notify_idle(self.modules)


class ZigbeeMedium(Medium):
    """XBee radios sharing the air with unslotted CSMA/CA."""

    bus: ZigbeeBus

    def __init__(self, bus: ZigbeeBus, timeline: Timeline, rng: random.Random, modules: Iterable[int] = (),
                 positions: dict[int, float] | None = None) -> None:
        self.positions = dict(positions or {})
        self._link = bus.link()
        self._active: list[Transmission] = []
        self._recent: list[Transmission] = []  # ended less than a CCA ago
        self._serving: dict[int, bool] = {}
        self._ready: dict[int, deque[float]] = {}
        self._attempt: dict[int, tuple[int, int]] = {}  # module -> (NB, BE)
        super().__init__(bus, timeline, rng, modules)

    def add_module(self, module: int) -> None:
        super().add_module(module)
        self._serving.setdefault(module, False)
        self._ready.setdefault(module, deque())

    def distance(self, a: int, b: int) -> float:
        """Metres between two modules' radios (``spacing`` per place along the chain)."""
        return abs(self.positions.get(a, a * self.bus.spacing) - self.positions.get(b, b * self.bus.spacing))

    def is_free(self, module: int) -> bool:
        return not self._serving[module] and not self._queues[module]

    def _uart_time(self, n_bytes: float) -> float:
        return uart_frame_bits(1) * n_bytes / self.bus.uart_baud

    def _request(self, frame: Frame) -> bool:
        if not self._enqueue(frame, self._serving[frame.sender]):
            return False
        now = self.timeline.now
        # The module's UART writes the bytes, then the XBee waits the packetization timeout.
        self._ready[frame.sender].append(now + self._uart_time(len(frame.data) + self.bus.packetization_chars))
        if not self._serving[frame.sender]:
            self._serve(frame.sender)
        return True

    def _serve(self, module: int) -> None:
        """The radio takes the next frame of its queue."""
        self._serving[module] = True
        ready = self._ready[module][0]
        self._attempt[module] = (0, self.bus.min_be)
        self.timeline.at(max(ready, self.timeline.now), self._backoff, module, rank=MEDIUM)

    def _backoff(self, module: int) -> None:
        _, exponent = self._attempt[module]
        delay = self.rng.randrange(1 << exponent) * _UNIT_BACKOFF
        self.timeline.at(self.timeline.now + delay + _CCA, self._assess, module, rank=MEDIUM)

    def _assess(self, module: int) -> None:
        """End of the clear channel assessment: was anything on the air during it?"""
        now = self.timeline.now
        since = now - _CCA
        self._recent = [t for t in self._recent if t.end > since]
        busy = any(t.start < now for t in self._active) or bool(self._recent)
        if not busy:
            self.timeline.at(now + _TURNAROUND, self._transmit, module, rank=MEDIUM)
            return
        backoffs, exponent = self._attempt[module]
        backoffs += 1
        if backoffs > self.bus.max_backoffs:
            frame = self._queues[module][0]
            self.losses.append(Lost(frame, None, Loss.ACCESS_FAILURE, now))
            self._next(module, now)
            return
        self._attempt[module] = (backoffs, min(exponent + 1, self.bus.max_be))
        self._backoff(module)

    def _transmit(self, module: int) -> None:
        now = self.timeline.now
        frame = self._queues[module][0]
        bits = self.bus.frame_bits(frame)
        transmission = Transmission(frame, now, now + bits / self.bus.air_bitrate, bits)
        for other in self._active:
            other.garbled = transmission.garbled = True
        self._active.append(transmission)
        self.transmissions.append(transmission)
        self.timeline.at(transmission.end, self._end, transmission, rank=MEDIUM)

    def _end(self, transmission: Transmission) -> None:
        now = self.timeline.now
        self._active.remove(transmission)
        self._recent.append(transmission)
        frame = transmission.frame
        if transmission.garbled:
            self.losses.append(Lost(frame, None, Loss.COLLISION, now))
        else:
            out = self._uart_time(len(frame.data))
            for module in self.modules:
                if module == frame.sender:
                    continue
                if self._link.survives(self.distance(frame.sender, module), transmission.bits, self.rng):
                    self.timeline.at(now + out, self._arrive, frame, module, rank=MEDIUM)
                else:
                    self.losses.append(Lost(frame, module, Loss.RADIO, now))
        mac_bytes = transmission.bits // 8 - 6
        spacing = _LIFS if mac_bytes > _MAX_SIFS_FRAME_BYTES else _SIFS
        self._next(frame.sender, now + spacing)

    def _next(self, module: int, when: float) -> None:
        """The radio is done with its head frame; it may take the next one at ``when``."""
        self._queues[module].popleft()
        self._ready[module].popleft()
        self._serving[module] = False
        self.timeline.at(when, self._resume, module, rank=MEDIUM)

    def _resume(self, module: int) -> None:
        if self._serving[module]:
            return
        if self._queues[module]:
            self._serve(module)
        else:
            self._notify_idle([module])


class BusSimulator:
    """A bus on its own: schedule sends and reads, run, look at what happened.

    Args:
        bus: the bus parameters.
        modules: the attached modules.
        seed: seed of the medium's random numbers.

    Examples:
        >>> sim = BusSimulator(SerialBus(), modules=[0, 1, 2], seed=1)
        >>> sim.send(0.0, Frame(0, (1,), bytes(9)))
        >>> sim.send(0.0005, Frame(2, (1,), bytes(9)))   # starts while the first is on the line
        >>> sim.read(0.01, 1)
        >>> medium = sim.run()
        >>> [t.garbled for t in medium.transmissions], len(sim.received[1])
        ([True, True], 0)
    """

    def __init__(self, bus: BusModel, modules: Iterable[int], seed: int = 0) -> None:
        self.timeline = Timeline()
        self.medium = bus.medium(self.timeline, random.Random(seed), modules)
        self.received: dict[int, list[Frame]] = {m: [] for m in self.medium.modules}
        self.refused: list[Frame] = []

    def send(self, time: float, frame: Frame) -> None:
        """The frame's sender asks to send it at ``time``."""
        self.timeline.at(time, self._send, frame)

    def read(self, time: float, module: int) -> None:
        """``module`` reads its receive buffer at ``time``."""
        self.timeline.at(time, self._read, module)

    def read_every(self, module: int, period: float, start: float = 0.0, until: float = math.inf) -> None:
        """``module`` reads every ``period`` seconds from ``start`` while before ``until``."""
        if start <= until:
            self.timeline.at(start, self._read_periodically, module, period, until)

    def run(self, until: float | None = None) -> Medium:
        """Run the bus (until nothing is left, or up to ``until``); returns the medium."""
        self.timeline.run(until)
        return self.medium

    def _send(self, frame: Frame) -> None:
        if not self.medium.request(frame):
            self.refused.append(frame)

    def _read(self, module: int) -> None:
        self.received[module].extend(self.medium.read(module))

    def _read_periodically(self, module: int, period: float, until: float) -> None:
        self._read(module)
        if self.timeline.now + period <= until:
            self.timeline.after(period, self._read_periodically, module, period, until)
