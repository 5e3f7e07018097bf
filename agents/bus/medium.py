"""One shared bus at bit-level timing: RS-485, CAN and ZigBee, with the losses of real modules.

Every module of the EMERGE chain hangs on one medium. A :class:`BusMedium` is that
medium's state on a :class:`~petriflow.runtime.media.ProcessClock` (the run's kernel,
or a kernel of its own outside a run: :class:`BusSimulator`): modules
:meth:`~BusMedium.request` frames, the medium puts them on the wire when its access
rule allows, frames occupy it for ``bits / bit rate`` seconds (lengths from
:mod:`~petriflow.agents.bus.frames`), and intact frames land in every other module's
receive buffer, where the module finds them when it next reads it. What happens is
told to listeners as it happens (:meth:`~BusMedium.on_start`, :meth:`~BusMedium.on_end`
of a transmission, :meth:`~BusMedium.on_delivery`: a module read a frame addressed to
it, :meth:`~BusMedium.on_loss`: a :class:`Lost` with a :class:`Loss` reason,
:meth:`~BusMedium.on_idle`); with ``logs=True`` (tests, figures) the medium also keeps
them in :attr:`~BusMedium.transmissions`, :attr:`~BusMedium.deliveries` and
:attr:`~BusMedium.losses` (a run's bus keeps none unless its model says ``logs:
true``, so its memory stays bounded however long the run).

The three buses (their parameters are :class:`SerialBus`, :class:`CanBus`,
:class:`ZigbeeBus`; ``bus.medium(clock, rng, modules)`` starts one):

* **RS-485** (:class:`SerialMedium`): a half-duplex line with no arbitration. A UART
  sends whenever its module asks (after its own previous frame). Two frames that
  overlap in time garble each other: both are lost at every receiver, at the moment
  they overlap (no capture: differential drivers fighting give framing and checksum
  errors; the garbled frames still hold the line to their ends). Carrier sense, for
  algorithm 2, sees a frame ``sense_bits`` bit times after its start bit (the
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
  are both garbled, at the moment they overlap (no capture). A frame survives each
  link with the probability of :class:`~petriflow.agents.bus.radio.RadioLink` (the
  core's log-distance RSSI, :class:`petriflow.runtime.radio.LogDistance`, at the
  distance between the modules, ``spacing`` metres apart per module number). Frames
  are broadcasts (the CPG messages carry their addresses in the payload, as in the
  paper's algorithm), so no MAC acknowledgements or retries. After a frame the radio
  waits the long or short interframe spacing. Received frames reach the module after
  the radio has written their payload out over the UART. A module cannot hear the
  air: for it the "bus" is free when its own radio has nothing to send.
  That is the single-hop air (``network: false``). By default (``network: true``,
  :class:`ZigbeeNetworkMedium`) the radios form a ZigBee network as Digi documents
  it for its XBee ZigBee modules: a payload-addressed frame is a network broadcast;
  the coordinator (the first module) and every router that transmits a broadcast
  record it in a broadcast transaction table of ``btt_entries`` = 8 entries kept
  ``btt_lifetime`` = 8 s each (a node whose table is full drops a new broadcast: its
  module loses it, and it relays nothing, :attr:`Loss.BTT_FULL`); each router relays a
  new broadcast after a random jitter of up to ``max_jitter`` = 63 ms and
  retransmits it, at most ``broadcast_retries`` = 2 times, when ``passive_ack_timeout``
  = 0.5 s after a transmission it has not heard every neighbouring router relay it
  (passive acknowledgement). With ``roles: end_devices`` the modules other than the
  coordinator are its end devices: they send to it (acknowledged, ``mac_retries``)
  and get broadcasts only when they poll it (``poll_period`` = 100 ms); the parent
  buffers one broadcast for all of them, a newer one replacing it
  (:attr:`Loss.PARENT_BUFFER`).

Losses common to all three (real modules' limits):

* **Receive buffer** (``rx_buffer`` frames, default 1): a frame that arrives while the
  buffer is full overwrites the oldest unread frame, which is lost then
  (:attr:`Loss.OVERWRITTEN`). The paper's reception routine checks addresses in
  software ("the receiving module rejects the packets that have not been assigned
  their address"), so by default every intact frame enters every module's buffer and
  a frame for someone else can overwrite one for this module;
  ``acceptance_filter=True`` models a hardware filter (CAN acceptance masks, XBee
  unicast addressing) that keeps them out.
* **Reading the buffer**: each module reads its buffer every ``read period`` seconds
  (:meth:`BusMedium.reads_every`; by default the bus's ``read_period``; 0: on arrival,
  as an interrupt would), at the times ``phase + k · period``: the *phase* is the
  module's own (when its firmware's loop started: the firmware says so, see
  :meth:`~petriflow.agents.bus.channel.BusView.reads_every`; 0 otherwise). A read is
  scheduled only while a frame waits in the buffer: the next such time at or after
  the frame's arrival, so an idle bus schedules nothing.
* **Transmit queue** (``tx_queue`` frames waiting besides the one on the wire): a
  request finding it full is dropped (:attr:`Loss.QUEUE_FULL`). Defaults (assumed):
  3 frames for a UART driver's ring buffer and for the XBee's serial buffer, 2 on CAN
  (a controller such as the MCP2515 has three transmit buffers, one of which holds
  the frame being sent). At the paper's rates (about one message a second per
  module) no queue fills; the limit matters for heavier traffic.

Each bus class is also a petriflow medium (:class:`petriflow.runtime.media.Medium`):
``channels: {bus: {model: bus.can, ...}}`` with the same parameters. When the run
starts, :meth:`BusModel.attach` starts the bus on the run's kernel; each message put
into a channel place becomes frames on it then, and the message is delivered when its
receiver's module reads its last frame, or lost when one of its frames is lost for
that receiver, at that moment (:mod:`~petriflow.agents.bus.channel`: messages to
frames, multicast groups, views). Nothing is decided ahead of time.

Examples:
    >>> from petriflow.runtime.kernel import Kernel
    >>> from petriflow.runtime.media import ProcessClock
    >>> import random
    >>> clock = ProcessClock(Kernel(dt=0.001))
    >>> medium = CanBus().medium(clock, random.Random(0), modules=[0, 1, 2], read_period=None)
    >>> _ = medium.request(Frame(sender=2, receivers=(0,), data=b"late", identifier=0x102))
    >>> _ = medium.request(Frame(sender=1, receivers=(0,), data=b"wins", identifier=0x101))
    >>> clock.run(until=0.01)
    >>> [t.frame.sender for t in medium.transmissions]   # both started together: 0x101 first
    [1, 2]
    >>> [f.data for f in medium.read(0)]                 # one-frame buffer: the first was overwritten
    [b'late']
    >>> [(loss.reason.value, round(loss.time * 1e6)) for loss in medium.losses]  # when the second arrived
    [('overwritten', 309)]
"""

from __future__ import annotations

import math
import random
from collections import deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any, ClassVar

from petriflow.agents.bus.errors import BusError
from petriflow.agents.bus.frames import (
    IEEE802154_MAC_HEADER_BYTES,
    IEEE802154_MAX_FRAME_BYTES,
    FrameError,
    can_frame_bits,
    ieee802154_frame_bits,
    uart_frame_bits,
)
from petriflow.agents.bus.radio import RadioLink
from petriflow.outcome import Name
from petriflow.runtime.channels import Message
from petriflow.runtime.kernel import Kernel
from petriflow.runtime.media import Medium, MediumPort, ProcessClock, Timer

__all__ = [
    "MEDIUM",
    "MODULE",
    "BusMedium",
    "BusModel",
    "BusSimulator",
    "CanBus",
    "CanMedium",
    "Delivery",
    "Frame",
    "Loss",
    "Lost",
    "SerialBus",
    "SerialMedium",
    "Transmission",
    "ZigbeeBus",
    "ZigbeeMedium",
    "ZigbeeNetworkMedium",
]

#: Rank of the media's own events (frame ends, arrivals): at one instant they run first.
MEDIUM = 0
#: Rank of the modules' events (buffer reads, sends in a :class:`BusSimulator`): they
#: see the settled bus.
MODULE = 1

# 802.15.4 at 2.4 GHz: 62.5 k symbols a second.
_SYMBOL = 16e-6
_UNIT_BACKOFF = 20 * _SYMBOL
_CCA = 8 * _SYMBOL
_TURNAROUND = 12 * _SYMBOL
_SIFS = 12 * _SYMBOL
_LIFS = 40 * _SYMBOL
_MAX_SIFS_FRAME_BYTES = 18

#: ``read_period`` of :meth:`BusModel.medium` when not given: the bus's own.
_BUS_DEFAULT: Any = object()


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
    BTT_FULL = "btt_full"
    """A ZigBee node's broadcast transaction table was full: it dropped a new broadcast."""
    PARENT_BUFFER = "parent_buffer"
    """A ZigBee parent replaced the one broadcast it buffers for its end devices before
    this end device polled for it."""


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


@dataclass(eq=False)
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
class BusModel(Medium):
    """Parameters shared by the buses; a subclass adds its physical layer. As a petriflow
    :class:`~petriflow.runtime.media.Medium` it carries a run's channel messages (see
    the module and :mod:`~petriflow.agents.bus.channel`).

    Attributes:
        tx_queue: frames a module's interface holds waiting besides the one it sends.
        rx_buffer: frames a module's receive buffer holds.
        acceptance_filter: only frames addressed to a module enter its buffer.
        read_period: how often a module reads its receive buffer, until its firmware
            says otherwise (0: on arrival).
        logs: in a run, keep every transmission, delivery and loss in the medium's
            lists (memory grows with the run; for tests and figures).
        sender_in_identifier: (class constant) the sender's address travels in the
            frame's identifier, so a payload need not carry it (CAN).
    """

    tx_queue: int = field(default=3, metadata={"range": (0, 10_000)})
    rx_buffer: int = field(default=1, metadata={"range": (1, 10_000)})
    acceptance_filter: bool = False
    read_period: float = field(default=0.0, metadata={"range": (0.0, 3600.0)})
    logs: bool = False

    sender_in_identifier: ClassVar[bool] = False

    def payload_limit(self) -> int:
        """Largest payload of one frame in bytes (a longer channel message is split)."""
        return 1 << 30

    def frame_bits(self, frame: Frame) -> int:
        """Bits the frame occupies the medium for."""
        raise NotImplementedError

    def medium(self, clock: ProcessClock, rng: random.Random, modules: Iterable[int] = (), *,
               logs: bool = True, read_period: float | None = _BUS_DEFAULT) -> BusMedium:
        """Start this bus on ``clock`` with ``modules`` attached (see :class:`BusMedium`)."""
        raise NotImplementedError

    # As a petriflow medium --------------------------------------------------------
    def attach(self, port: MediumPort) -> None:
        """A run starts: the bus starts on the run's kernel (``port.clock``), its
        random numbers from ``port.rng``; messages' fates go to ``port``."""
        from petriflow.agents.bus.channel import Carrier

        self._carrier = Carrier(self, port, logs=self.logs)

    def send(self, message: Message) -> None:
        """A message is put into a channel place now: its frames are requested now."""
        self._attached().send(message)

    def view(self, agent: str | None) -> Any:
        """What ``agent``'s firmware may ask the bus: a
        :class:`~petriflow.agents.bus.channel.BusView`."""
        from petriflow.agents.bus.channel import BusView

        return BusView(self._attached(), agent)

    @property
    def state(self) -> BusMedium | None:
        """The bus of the run this model is attached to (``None`` before
        :meth:`attach`): its listeners, its logs if ``logs`` is set."""
        carrier = getattr(self, "_carrier", None)
        return carrier.medium if carrier is not None else None

    def _attached(self) -> Any:
        carrier = getattr(self, "_carrier", None)
        if carrier is None:
            raise BusError(f"the {type(self).__name__} is not attached to a run (attach(port) first)")
        return carrier


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

    def medium(self, clock: ProcessClock, rng: random.Random, modules: Iterable[int] = (), *,
               logs: bool = True, read_period: float | None = _BUS_DEFAULT) -> SerialMedium:
        return SerialMedium(self, clock, rng, modules, logs=logs, read_period=read_period)


@dataclass
class CanBus(BusModel):
    """CAN 2.0A at ``bitrate``; frames are stuffed as their bits require. ``tx_queue``
    defaults to 2: three transmit buffers, one holding the frame on the bus. The
    sender's address travels in the identifier (``sender_in_identifier``).

    Examples:
        >>> CanBus().frame_bits(Frame(0, (1,), bytes(8), identifier=0x100)) >= 44 + 64
        True
    """

    tx_queue: int = field(default=2, metadata={"range": (0, 10_000)})
    bitrate: float = field(default=512_000.0, metadata={"range": (1.0, 1e9)})
    arbitration_bits: float = field(default=1.0, metadata={"range": (0.0, 1e6)})

    sender_in_identifier: ClassVar[bool] = True

    def payload_limit(self) -> int:
        return 8

    def frame_bits(self, frame: Frame) -> int:
        return can_frame_bits(frame.identifier, frame.data, interframe=False)

    def medium(self, clock: ProcessClock, rng: random.Random, modules: Iterable[int] = (), *,
               logs: bool = True, read_period: float | None = _BUS_DEFAULT) -> CanMedium:
        return CanMedium(self, clock, rng, modules, logs=logs, read_period=read_period)


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
    network: bool = True
    roles: str = "routers"
    btt_entries: int = field(default=8, metadata={"range": (1, 1000)})
    btt_lifetime: float = field(default=8.0, metadata={"range": (0.0, 3600.0)})
    broadcast_retries: int = field(default=2, metadata={"range": (0, 10)})
    passive_ack_timeout: float = field(default=0.5, metadata={"range": (0.0, 60.0)})
    max_jitter: float = field(default=0.063, metadata={"range": (0.0, 10.0)})
    poll_period: float = field(default=0.1, metadata={"range": (1e-4, 60.0)})
    mac_retries: int = field(default=3, metadata={"range": (0, 10)})

    def __post_init__(self) -> None:
        if self.min_be > self.max_be:
            raise FrameError(f"min_be {self.min_be} is above max_be {self.max_be}")
        if self.roles not in ("routers", "end_devices"):
            raise FrameError(f"roles is 'routers' or 'end_devices', not {self.roles!r}")

    def payload_limit(self) -> int:
        return IEEE802154_MAX_FRAME_BYTES - IEEE802154_MAC_HEADER_BYTES - self.network_bytes - 2

    def frame_bits(self, frame: Frame) -> int:
        return ieee802154_frame_bits(len(frame.data), network_bytes=self.network_bytes)

    def link(self) -> RadioLink:
        """The radio link model every pair of modules shares."""
        interference = -math.inf if self.interference_dbm <= -200.0 else self.interference_dbm
        return RadioLink(self.tx_power_dbm, self.reference_loss_db, self.exponent, self.noise_floor_dbm,
                         interference, self.shadowing_db)

    def medium(self, clock: ProcessClock, rng: random.Random, modules: Iterable[int] = (), *,
               logs: bool = True, read_period: float | None = _BUS_DEFAULT) -> ZigbeeMedium:
        kind = ZigbeeNetworkMedium if self.network else ZigbeeMedium
        return kind(self, clock, rng, modules, logs=logs, read_period=read_period)


def _check_period(period: float | None) -> float | None:
    if period is None:
        return None
    if isinstance(period, bool) or not isinstance(period, (int, float)) \
            or not (math.isfinite(period) and period >= 0):
        raise BusError(f"a read period is a number of seconds >= 0, got {period!r}")
    return float(period)


class BusMedium:
    """The state of one bus on a clock (see the module docstring for the rules).

    Args:
        bus: the bus parameters.
        clock: the clock it runs on (``now``, ``at(time, callback, *args, rank=)``): the
            run's :class:`~petriflow.runtime.media.ProcessClock`.
        rng: the medium's random numbers (backoffs, radio errors).
        modules: the modules attached from the start (more with :meth:`add_module`).
        logs: keep :attr:`transmissions`, :attr:`deliveries` and :attr:`losses`.
        read_period: how often a module reads its buffer until :meth:`reads_every`
            says otherwise: seconds (0: on arrival), or ``None``: only when
            :meth:`read` is called (default: the bus's ``read_period``).

    Attributes:
        transmissions: every frame put on the medium, in start order (with ``logs``).
        deliveries: every frame a module read that was addressed to it (with ``logs``).
        losses: every loss, with its reason (with ``logs``).
        keep_newest: a full receive buffer drops its oldest frame for a new one (the
            hardware's behaviour); ``False`` drops the new one.
    """

    def __init__(self, bus: BusModel, clock: ProcessClock, rng: random.Random, modules: Iterable[int] = (), *,
                 logs: bool = True, read_period: float | None = _BUS_DEFAULT) -> None:
        self.bus = bus
        self.clock = clock
        self.rng = rng
        self.modules: list[int] = []
        self.logs = logs
        self.transmissions: list[Transmission] = []
        self.deliveries: list[Delivery] = []
        self.losses: list[Lost] = []
        self.keep_newest = True
        self.read_period = _check_period(bus.read_period if read_period is _BUS_DEFAULT else read_period)
        self.started = clock.now
        self.last_end: float | None = None  # when the last frame left the medium
        self._buffers: dict[int, deque[tuple[Frame, float]]] = {}
        self._queues: dict[int, deque[Frame]] = {}
        self._readers: dict[int, tuple[float | None, float]] = {}  # module -> (period, phase)
        self._reads: dict[int, Timer] = {}  # the read scheduled while a frame waits
        self._on_start: list[Callable[[Transmission], Any]] = []
        self._on_end: list[Callable[[Transmission], Any]] = []
        self._on_delivery: list[Callable[[Delivery], Any]] = []
        self._on_loss: list[Callable[[Lost], Any]] = []
        self._on_idle: list[Callable[[int], Any]] = []
        self.sniffers: set[int] = set()
        self.captured: dict[int, dict[int, int]] = {}
        for module in modules:
            self.add_module(module)

    # Listeners -----------------------------------------------------------------------
    def on_start(self, callback: Callable[[Transmission], Any]) -> None:
        """Call ``callback(transmission)`` when a frame goes on the medium."""
        self._on_start.append(callback)

    def on_end(self, callback: Callable[[Transmission], Any]) -> None:
        """Call ``callback(transmission)`` when a frame leaves the medium (intact or garbled)."""
        self._on_end.append(callback)

    def on_delivery(self, callback: Callable[[Delivery], Any]) -> None:
        """Call ``callback(delivery)`` when a module reads a frame addressed to it."""
        self._on_delivery.append(callback)

    def on_loss(self, callback: Callable[[Lost], Any]) -> None:
        """Call ``callback(lost)`` when a frame is lost (for one module or for all)."""
        self._on_loss.append(callback)

    def on_idle(self, callback: Callable[[int], Any]) -> None:
        """Call ``callback(module)`` whenever the bus turns free in ``module``'s view."""
        self._on_idle.append(callback)

    # The modules' side -------------------------------------------------------------
    def add_module(self, module: int) -> None:
        """Attach a module (a no-op if it is attached)."""
        if module not in self._buffers:
            self.modules.append(module)
            self._buffers[module] = deque()
            self._queues[module] = deque()

    def sniff(self, module: int) -> None:
        """Attach ``module`` as a sniffer: a node that never sends, takes every intact
        frame it receives whoever it is for (no acceptance filter), reads on arrival,
        and counts them per sender in :attr:`captured` (``{sniffer: {sender: frames}}``)."""
        self.add_module(module)
        self.sniffers.add(module)
        self.captured.setdefault(module, {})
        self._readers[module] = (0.0, 0.0)

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

    def reads_every(self, module: int, period: float | None, phase: float = 0.0) -> None:
        """``module`` reads its receive buffer at ``phase + k · period`` (``period``
        seconds; 0: on arrival; ``None``: only when :meth:`read` is called). A frame
        already waiting is read on the new schedule.

        Raises:
            BusError: a period that is not a number of seconds >= 0, or a phase that
                is not finite.
        """
        period = _check_period(period)
        if not (isinstance(phase, (int, float)) and math.isfinite(phase)):
            raise BusError(f"a read phase is a time in seconds, got {phase!r}")
        self.add_module(module)
        self._readers[module] = (period, float(phase))
        timer = self._reads.pop(module, None)
        if timer is not None:
            timer.cancel()
        if self._buffers[module]:
            if period == 0.0:
                self.read(module)
            elif period is not None:
                self._schedule_read(module)

    def read_period_of(self, module: int) -> float | None:
        """How often ``module`` reads its buffer (see :meth:`reads_every`)."""
        return self._readers.get(module, (self.read_period, 0.0))[0]

    def read(self, module: int) -> list[Frame]:
        """The module empties its receive buffer now; returns the frames addressed to it
        (oldest first), which count as delivered. Frames for others are discarded."""
        timer = self._reads.pop(module, None)
        if timer is not None:
            timer.cancel()
        buffer = self._buffers[module]
        frames = []
        now = self.clock.now
        while buffer:
            frame, arrived = buffer.popleft()
            if module in frame.receivers:
                frames.append(frame)
                self._delivered(Delivery(frame, module, arrived, now))
        return frames

    def waiting(self, module: int) -> int:
        """Frames in ``module``'s receive buffer now."""
        return len(self._buffers[module])

    def is_free(self, module: int) -> bool:
        """Whether the bus looks free to ``module`` now (algorithm 2's "bus available")."""
        raise NotImplementedError

    def busy(self) -> bool:
        """Whether a frame is on the medium now."""
        raise NotImplementedError

    def quiet_for(self) -> float:
        """Seconds the medium has carried nothing, now (0 while a frame is on it; since
        the medium started when none ever was)."""
        if self.busy():
            return 0.0
        return self.clock.now - (self.started if self.last_end is None else self.last_end)

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
            self._lost(Lost(frame, None, Loss.QUEUE_FULL, self.clock.now))
            return False
        queue.append(frame)
        return True

    def _arrive(self, frame: Frame, module: int) -> None:
        """An intact frame reaches ``module``'s receive buffer now."""
        if module in self.sniffers:
            counts = self.captured[module]
            counts[frame.sender] = counts.get(frame.sender, 0) + 1
            return
        if self.bus.acceptance_filter and module not in frame.receivers:
            return
        now = self.clock.now
        period = self.read_period_of(module)
        if period == 0.0:  # read on arrival
            if module in frame.receivers:
                self._delivered(Delivery(frame, module, now, now))
            return
        buffer = self._buffers[module]
        if len(buffer) >= self.bus.rx_buffer:
            if not self.keep_newest:
                self._lost(Lost(frame, module, Loss.OVERWRITTEN, now))
                return
            old, _ = buffer.popleft()
            self._lost(Lost(old, module, Loss.OVERWRITTEN, now))
        buffer.append((frame, now))
        if period is not None and module not in self._reads:
            self._schedule_read(module)

    def _schedule_read(self, module: int) -> None:
        """The module's next read at or after now, on its phase (a frame waits)."""
        period, phase = self._readers.get(module, (self.read_period, 0.0))
        assert period is not None and period > 0.0
        now = self.clock.now
        when = phase + math.ceil((now - phase) / period - 1e-9) * period
        self._reads[module] = self.clock.at(max(when, now), self._scheduled_read, module, rank=MODULE)

    def _scheduled_read(self, module: int) -> None:
        self._reads.pop(module, None)
        self.read(module)

    def _started(self, transmission: Transmission) -> None:
        if self.logs:
            self.transmissions.append(transmission)
        for callback in self._on_start:
            callback(transmission)

    def _ended(self, transmission: Transmission) -> None:
        self.last_end = transmission.end if self.last_end is None else max(self.last_end, transmission.end)
        for callback in self._on_end:
            callback(transmission)

    def _garble(self, transmission: Transmission) -> None:
        """``transmission`` overlaps another now: it is lost to everyone now."""
        if not transmission.garbled:
            transmission.garbled = True
            self._lost(Lost(transmission.frame, None, Loss.COLLISION, self.clock.now))

    def _delivered(self, delivery: Delivery) -> None:
        if self.logs:
            self.deliveries.append(delivery)
        for callback in self._on_delivery:
            callback(delivery)

    def _lost(self, lost: Lost) -> None:
        if self.logs:
            self.losses.append(lost)
        for callback in self._on_loss:
            callback(lost)

    def _notify_idle(self, modules: Iterable[int]) -> None:
        for module in modules:
            for callback in self._on_idle:
                callback(module)


class SerialMedium(BusMedium):
    """An RS-485 line: frames go out when asked; overlapping frames garble each other."""

    bus: SerialBus

    def __init__(self, bus: SerialBus, clock: ProcessClock, rng: random.Random, modules: Iterable[int] = (),
                 **options: Any) -> None:
        super().__init__(bus, clock, rng, modules, **options)
        self._active: list[Transmission] = []

    def is_free(self, module: int) -> bool:
        horizon = self.clock.now - self.bus.sense_bits / self.bus.baud
        return not self._queues[module] and not any(t.start <= horizon for t in self._active)

    def busy(self) -> bool:
        return bool(self._active)

    def _request(self, frame: Frame) -> bool:
        busy = bool(self._queues[frame.sender])
        if not self._enqueue(frame, busy):
            return False
        if not busy:
            self._start(frame)
        return True

    def _start(self, frame: Frame) -> None:
        now = self.clock.now
        bits = self.bus.frame_bits(frame)
        transmission = Transmission(frame, now, now + bits / self.bus.baud, bits)
        self._active.append(transmission)
        self._started(transmission)
        if len(self._active) > 1:  # the line was busy: this frame and those on it are garbled now
            for other in self._active:
                self._garble(other)
        self.clock.at(transmission.end, self._end, transmission, rank=MEDIUM)

    def _end(self, transmission: Transmission) -> None:
        self._active.remove(transmission)
        frame = transmission.frame
        self._ended(transmission)
        if not transmission.garbled:
            for module in self.modules:
                if module != frame.sender:
                    self._arrive(frame, module)
        queue = self._queues[frame.sender]
        queue.popleft()
        if queue:
            self._start(queue[0])
        if not self._active:
            self._notify_idle(self.modules)


class CanMedium(BusMedium):
    """A CAN bus: frames wait for an idle bus; simultaneous starts arbitrate by identifier."""

    bus: CanBus

    def __init__(self, bus: CanBus, clock: ProcessClock, rng: random.Random, modules: Iterable[int] = (),
                 **options: Any) -> None:
        super().__init__(bus, clock, rng, modules, **options)
        self._current: Transmission | None = None
        self._busy_until = -math.inf
        self._start_of_frame: float | None = None  # SOF of an arbitration not yet decided
        self._idle_timer: Timer | None = None

    def is_free(self, module: int) -> bool:
        now = self.clock.now
        if self._current is not None or now < self._busy_until:
            return False
        sof = self._start_of_frame
        return sof is None or now < sof + self._window()

    def busy(self) -> bool:
        return self._current is not None or self._start_of_frame is not None

    def _window(self) -> float:
        return self.bus.arbitration_bits / self.bus.bitrate

    def _request(self, frame: Frame) -> bool:
        current = self._current
        if not self._enqueue(frame, current is not None and current.frame.sender == frame.sender):
            return False
        now = self.clock.now
        if self._current is None and self._start_of_frame is None and now >= self._busy_until:
            if self._idle_timer is not None:
                self._idle_timer.cancel()
                self._idle_timer = None
            self._begin_arbitration(now)
        return True

    def _begin_arbitration(self, start: float) -> None:
        self._start_of_frame = start
        self.clock.at(start + self._window(), self._arbitrate, rank=MEDIUM)

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
        self._started(transmission)
        self.clock.at(transmission.end, self._end, transmission, rank=MEDIUM)

    def _end(self, transmission: Transmission) -> None:
        frame = transmission.frame
        self._queues[frame.sender].popleft()
        self._current = None
        self._ended(transmission)
        for module in self.modules:
            if module != frame.sender:
                self._arrive(frame, module)
        self._busy_until = transmission.end + 3 / self.bus.bitrate
        self._idle_timer = self.clock.at(self._busy_until, self._idle, rank=MEDIUM)

    def _idle(self) -> None:
        self._idle_timer = None
        if any(self._queues.values()):
            self._begin_arbitration(self.clock.now)
        else:
            self._notify_idle(self.modules)


class ZigbeeMedium(BusMedium):
    """XBee radios sharing the air with unslotted CSMA/CA."""

    bus: ZigbeeBus

    def __init__(self, bus: ZigbeeBus, clock: ProcessClock, rng: random.Random, modules: Iterable[int] = (),
                 positions: dict[int, float] | None = None, **options: Any) -> None:
        self.positions = dict(positions or {})
        self._link = bus.link()
        self._active: list[Transmission] = []
        self._recent: list[Transmission] = []  # ended less than a CCA ago
        self._serving: dict[int, bool] = {}
        self._ready: dict[int, deque[float]] = {}
        self._attempt: dict[int, tuple[int, int]] = {}  # module -> (NB, BE)
        super().__init__(bus, clock, rng, modules, **options)

    def add_module(self, module: int) -> None:
        super().add_module(module)
        self._serving.setdefault(module, False)
        self._ready.setdefault(module, deque())

    def distance(self, a: int, b: int) -> float:
        """Metres between two modules' radios (``spacing`` per module number, unless
        ``positions`` places them)."""
        return abs(self.positions.get(a, a * self.bus.spacing) - self.positions.get(b, b * self.bus.spacing))

    def is_free(self, module: int) -> bool:
        return not self._serving[module] and not self._queues[module]

    def busy(self) -> bool:
        return bool(self._active)

    def _uart_time(self, n_bytes: float) -> float:
        return uart_frame_bits(1) * n_bytes / self.bus.uart_baud

    def _request(self, frame: Frame) -> bool:
        if not self._enqueue(frame, self._serving[frame.sender]):
            return False
        now = self.clock.now
        # The module's UART writes the bytes, then the XBee waits the packetization timeout.
        ready = now + self._uart_time(len(frame.data) + self.bus.packetization_chars)
        self._ready[frame.sender].append(ready)
        if not self._serving[frame.sender]:
            self._serve(frame.sender)
        return True

    def _serve(self, module: int) -> None:
        """The radio takes the next frame of its queue."""
        self._serving[module] = True
        ready = self._ready[module][0]
        self._attempt[module] = (0, self.bus.min_be)
        self.clock.at(max(ready, self.clock.now), self._backoff, module, rank=MEDIUM)

    def _backoff(self, module: int) -> None:
        _, exponent = self._attempt[module]
        delay = self.rng.randrange(1 << exponent) * _UNIT_BACKOFF
        self.clock.at(self.clock.now + delay + _CCA, self._assess, module, rank=MEDIUM)

    def _assess(self, module: int) -> None:
        """End of the clear channel assessment: was anything on the air during it?"""
        now = self.clock.now
        self._forget(now)
        busy = any(t.start < now for t in self._active) or bool(self._recent)
        if not busy:
            self.clock.at(now + _TURNAROUND, self._transmit, module, rank=MEDIUM)
            return
        backoffs, exponent = self._attempt[module]
        backoffs += 1
        if backoffs > self.bus.max_backoffs:
            frame = self._queues[module][0]
            self._lost(Lost(frame, None, Loss.ACCESS_FAILURE, now))
            self._next(module, now)
            return
        self._attempt[module] = (backoffs, min(exponent + 1, self.bus.max_be))
        self._backoff(module)

    def _forget(self, now: float) -> None:
        """Keep only the frames that ended less than a CCA ago."""
        since = now - _CCA
        self._recent = [t for t in self._recent if t.end > since]

    def _transmission(self, frame: Frame) -> Transmission:
        """``frame`` sent from now, for its airtime at the air bitrate."""
        now = self.clock.now
        bits = self.bus.frame_bits(frame)
        return Transmission(frame, now, now + bits / self.bus.air_bitrate, bits)

    def _put_on_air(self, transmission: Transmission) -> None:
        """Start ``transmission``: on the air with another, both are garbled now; its
        end is scheduled (:meth:`_end`)."""
        self._active.append(transmission)
        self._started(transmission)
        if len(self._active) > 1:
            for other in self._active:
                self._garble(other)
        self.clock.at(transmission.end, self._end, transmission, rank=MEDIUM)

    def _take_off_air(self, transmission: Transmission) -> float:
        """``transmission`` has ended: off the air, kept a CCA for carrier sense; the time now."""
        now = self.clock.now
        self._active.remove(transmission)
        self._forget(now)
        self._recent.append(transmission)
        return now

    @staticmethod
    def _spacing(transmission: Transmission) -> float:
        """The interframe spacing after ``transmission`` (long after a long MAC frame)."""
        return _LIFS if transmission.bits // 8 - 6 > _MAX_SIFS_FRAME_BYTES else _SIFS

    def _transmit(self, module: int) -> None:
        self._put_on_air(self._transmission(self._queues[module][0]))

    def _end(self, transmission: Transmission) -> None:
        now = self._take_off_air(transmission)
        frame = transmission.frame
        self._ended(transmission)
        if not transmission.garbled:
            out = self._uart_time(len(frame.data))
            for module in self.modules:
                if module == frame.sender:
                    continue
                if self._link.survives(self.distance(frame.sender, module), transmission.bits, self.rng):
                    self.clock.at(now + out, self._arrive, frame, module, rank=MEDIUM)
                else:
                    self._lost(Lost(frame, module, Loss.RADIO, now))
        self._next(frame.sender, now + self._spacing(transmission))

    def _next(self, module: int, when: float) -> None:
        """The radio is done with its head frame; it may take the next one at ``when``."""
        self._queues[module].popleft()
        self._ready[module].popleft()
        self._serving[module] = False
        self.clock.at(when, self._resume, module, rank=MEDIUM)

    def _resume(self, module: int) -> None:
        if self._serving[module]:
            return
        if self._queues[module]:
            self._serve(module)
        else:
            self._notify_idle([module])


class _Broadcast:
    """One payload-addressed frame as a ZigBee network broadcast: which nodes have it,
    why the others have not (yet), and how much of its relaying is still under way."""

    __slots__ = ("frame", "origin", "key", "pending", "reached", "why", "heard", "tries", "intact", "done")

    def __init__(self, frame: Frame, origin: int, key: Any) -> None:
        self.frame = frame
        self.origin = origin
        self.key = key
        self.pending = 0  # transmissions, jitter waits, passive-ack waits and polls to come
        self.reached: set[int] = {origin}
        self.why: dict[int | None, Loss] = {}
        self.heard: dict[int, set[int]] = {}  # node -> the routers it heard transmit this broadcast
        self.tries: dict[int, int] = {}
        self.intact = False
        self.done = False


class ZigbeeNetworkMedium(ZigbeeMedium):
    """XBee radios as a ZigBee network (``network: true``, the default): a module's
    payload-addressed frame is a network broadcast. See :class:`ZigbeeBus` and the
    module docstring: the coordinator and routers record each new broadcast in their
    broadcast transaction table (``btt_entries`` entries, each kept ``btt_lifetime``
    s; a node whose table is full drops a new broadcast: it neither delivers nor
    relays it) and relay it after a jitter of up to ``max_jitter``, retransmitting it
    (at most ``broadcast_retries`` times) when, ``passive_ack_timeout`` after a
    transmission, it has not heard every neighbouring router relay it (passive
    acknowledgement). With ``roles: end_devices`` every module but the coordinator
    (the first attached) is an end device: it sends its frame to its parent (MAC
    acknowledged, ``mac_retries`` retries), and receives broadcasts only when it polls
    its parent (every ``poll_period`` s), which buffers ONE broadcast for all its end
    devices, a new one replacing it. A sniffer (:meth:`~BusMedium.sniff`) is a router.
    A broadcast's losses are decided when its last transmission, wait or poll is over.
    """

    def __init__(self, bus: ZigbeeBus, clock: ProcessClock, rng: random.Random, modules: Iterable[int] = (),
                 positions: dict[int, float] | None = None, **options: Any) -> None:
        self._btt: dict[int, deque[tuple[float, Any]]] = {}
        self._radio: dict[int, deque[tuple[_Broadcast, str]]] = {}
        self._uart_free: dict[int, float] = {}
        self._buffered: dict[int, tuple[_Broadcast, set[int]]] = {}  # parent -> (broadcast, children to poll)
        self._polls: dict[int, Timer] = {}
        self._poll_phase: dict[int, float] = {}
        self._on_air: dict[Transmission, tuple[int, _Broadcast, str]] = {}
        self._sequence = 0
        super().__init__(bus, clock, rng, modules, positions, **options)

    def add_module(self, module: int) -> None:
        super().add_module(module)
        self._btt.setdefault(module, deque())
        self._radio.setdefault(module, deque())

    # Roles ----------------------------------------------------------------------------
    def coordinator(self) -> int | None:
        """The coordinator: the first attached module that is not a sniffer."""
        return next((m for m in self.modules if m not in self.sniffers), None)

    def role(self, node: int) -> str:
        """``"coordinator"``, ``"router"`` or ``"end_device"``."""
        if node == self.coordinator():
            return "coordinator"
        if node in self.sniffers or self.bus.roles == "routers":
            return "router"
        return "end_device"

    def parent(self, node: int) -> int | None:
        """An end device's parent (the coordinator); ``None`` for the others."""
        return self.coordinator() if self.role(node) == "end_device" else None

    def btt_size(self, node: int) -> int:
        """Entries in ``node``'s broadcast transaction table now."""
        self._purge(node)
        return len(self._btt[node])

    # The host's side ------------------------------------------------------------------
    def is_free(self, module: int) -> bool:
        return not self._serving[module] and not self._queues[module] and not self._radio[module]

    def _request(self, frame: Frame) -> bool:
        if not self._enqueue(frame, False):
            return False
        sender = frame.sender
        now = self.clock.now
        start = max(now, self._uart_free.get(sender, now))
        ready = start + self._uart_time(len(frame.data) + self.bus.packetization_chars)
        self._uart_free[sender] = ready
        self.clock.at(ready, self._originate, sender, rank=MEDIUM)
        return True

    def _originate(self, node: int) -> None:
        """The radio has the frame from its host's UART: a new broadcast."""
        frame = self._queues[node].popleft()
        self._sequence += 1
        broadcast = _Broadcast(frame, node, (node, self._sequence))
        if self.role(node) == "end_device":
            self._push(node, broadcast, "up")
            return
        if not self._record(node, broadcast):
            self._lost(Lost(frame, None, Loss.BTT_FULL, self.clock.now))
            if not self._radio[node] and not self._serving[node]:
                self._notify_idle([node])
            return
        self._push(node, broadcast, "broadcast")
        self._buffer_for_children(node, broadcast)

    # Broadcast transaction table --------------------------------------------------------
    def _purge(self, node: int) -> None:
        table, now = self._btt[node], self.clock.now
        while table and table[0][0] <= now:
            table.popleft()

    def _record(self, node: int, broadcast: _Broadcast) -> bool:
        """Make ``node``'s table entry for a new broadcast; ``False`` if the table is full."""
        self._purge(node)
        table = self._btt[node]
        if len(table) >= self.bus.btt_entries:
            return False
        table.append((self.clock.now + self.bus.btt_lifetime, broadcast.key))
        return True

    def _take(self, node: int, broadcast: _Broadcast) -> None:
        """A router or the coordinator received an intact copy now."""
        if node in broadcast.reached:
            return  # a duplicate: only a passive acknowledgement
        now = self.clock.now
        if not self._record(node, broadcast):
            broadcast.why[node] = Loss.BTT_FULL
            for child in self.modules:  # its end devices get nothing from it either
                if self.parent(child) == node:
                    broadcast.why.setdefault(child, Loss.BTT_FULL)
            return
        broadcast.reached.add(node)
        broadcast.why.pop(node, None)
        frame = broadcast.frame
        self.clock.at(now + self._uart_time(len(frame.data)), self._arrive, frame, node, rank=MEDIUM)
        broadcast.pending += 1
        self.clock.at(now + self.rng.uniform(0.0, self.bus.max_jitter), self._relay, node, broadcast, rank=MEDIUM)
        self._buffer_for_children(node, broadcast)

    def _relay(self, node: int, broadcast: _Broadcast) -> None:
        broadcast.pending -= 1
        self._push(node, broadcast, "broadcast")

    # End devices --------------------------------------------------------------------------
    def _buffer_for_children(self, node: int, broadcast: _Broadcast) -> None:
        children = {m for m in self.modules if m != broadcast.origin and self.parent(m) == node}
        if not children:
            return
        old = self._buffered.pop(node, None)
        self._buffered[node] = (broadcast, children)
        broadcast.pending += len(children)
        if old is not None:
            dropped, waiting = old
            for child in waiting:
                dropped.why[child] = Loss.PARENT_BUFFER
                dropped.pending -= 1
            self._check_done(dropped)
        for child in children:
            self._schedule_poll(child)

    def _schedule_poll(self, child: int) -> None:
        if child in self._polls:
            return
        period = self.bus.poll_period
        phase = self._poll_phase.setdefault(child, self.rng.uniform(0.0, period))
        now = self.clock.now
        when = phase + math.ceil((now - phase) / period - 1e-9) * period
        self._polls[child] = self.clock.at(max(when, now), self._poll, child, rank=MEDIUM)

    def _poll(self, child: int) -> None:
        """An end device polls its parent: it gets the buffered broadcast it has not had."""
        self._polls.pop(child, None)
        parent = self.parent(child)
        entry = self._buffered.get(parent) if parent is not None else None
        if entry is None or child not in entry[1]:
            return
        broadcast, waiting = entry
        waiting.discard(child)
        if not waiting:
            del self._buffered[parent]
        broadcast.pending -= 1
        broadcast.reached.add(child)
        broadcast.why.pop(child, None)
        frame = broadcast.frame
        out = self.bus.frame_bits(frame) / self.bus.air_bitrate + self._uart_time(len(frame.data))
        self.clock.at(self.clock.now + out, self._arrive, frame, child, rank=MEDIUM)
        self._check_done(broadcast)

    # The radio ------------------------------------------------------------------------------
    def _push(self, node: int, broadcast: _Broadcast, kind: str) -> None:
        broadcast.pending += 1
        self._radio[node].append((broadcast, kind))
        if not self._serving[node]:
            self._serve(node)

    def _serve(self, module: int) -> None:
        self._serving[module] = True
        self._attempt[module] = (0, self.bus.min_be)
        self._backoff(module)

    def _assess(self, module: int) -> None:
        now = self.clock.now
        self._forget(now)
        if not (any(t.start < now for t in self._active) or bool(self._recent)):
            self.clock.at(now + _TURNAROUND, self._transmit, module, rank=MEDIUM)
            return
        backoffs, exponent = self._attempt[module]
        backoffs += 1
        if backoffs > self.bus.max_backoffs:
            broadcast, kind = self._radio[module][0]
            broadcast.why.setdefault(None, Loss.ACCESS_FAILURE)
            self._after(module, broadcast, kind, None)
            self._next(module, now)
            return
        self._attempt[module] = (backoffs, min(exponent + 1, self.bus.max_be))
        self._backoff(module)

    def _garble(self, transmission: Transmission) -> None:
        transmission.garbled = True  # other copies may still arrive: decided at the end

    def _transmit(self, module: int) -> None:
        broadcast, kind = self._radio[module][0]
        transmission = self._transmission(broadcast.frame)
        self._on_air[transmission] = (module, broadcast, kind)
        self._put_on_air(transmission)

    def _end(self, transmission: Transmission) -> None:
        now = self._take_off_air(transmission)
        node, broadcast, kind = self._on_air.pop(transmission)
        if not transmission.garbled:
            broadcast.intact = True
        self._ended(transmission)
        self._after(node, broadcast, kind, transmission)
        self._next(node, now + self._spacing(transmission))

    def _after(self, node: int, broadcast: _Broadcast, kind: str, transmission: Transmission | None) -> None:
        """``node``'s transmission of ``broadcast`` is over (``None``: CSMA/CA gave up)."""
        broadcast.tries[node] = broadcast.tries.get(node, 0) + 1
        if kind == "up":
            parent = self.parent(node)
            if transmission is not None and not transmission.garbled and parent is not None \
                    and self._link.survives(self.distance(node, parent), transmission.bits, self.rng):
                self._take(parent, broadcast)
                if parent not in broadcast.reached:  # the parent's table was full: it went no further
                    broadcast.why[None] = Loss.BTT_FULL
            else:
                if transmission is not None:
                    broadcast.why[None] = Loss.COLLISION if transmission.garbled else Loss.RADIO
                if broadcast.tries[node] <= self.bus.mac_retries:
                    self._push(node, broadcast, "up")
        elif transmission is not None:
            for other in self.modules:
                if other == node or self.role(other) == "end_device":
                    continue
                if transmission.garbled:
                    broadcast.why.setdefault(other, Loss.COLLISION)
                    continue
                if not self._link.survives(self.distance(node, other), transmission.bits, self.rng):
                    broadcast.why.setdefault(other, Loss.RADIO)
                    continue
                broadcast.heard.setdefault(other, set()).add(node)
                self._take(other, broadcast)
        if kind == "broadcast":
            broadcast.pending += 1
            self.clock.at(self.clock.now + self.bus.passive_ack_timeout, self._passive_ack, node, broadcast,
                          rank=MEDIUM)
        broadcast.pending -= 1
        self._check_done(broadcast)

    def _passive_ack(self, node: int, broadcast: _Broadcast) -> None:
        """The passive acknowledgement timeout: retransmit unless every neighbouring
        router (and the coordinator) was heard transmitting the broadcast."""
        broadcast.pending -= 1
        neighbours = [m for m in self.modules if m != node and self.role(m) != "end_device"]
        heard = broadcast.heard.get(node, set())
        if any(m not in heard for m in neighbours) and broadcast.tries.get(node, 0) <= self.bus.broadcast_retries:
            self._push(node, broadcast, "broadcast")
        self._check_done(broadcast)

    def _next(self, module: int, when: float) -> None:
        self._radio[module].popleft()
        self._serving[module] = False
        self.clock.at(when, self._resume, module, rank=MEDIUM)

    def _resume(self, module: int) -> None:
        if self._serving[module]:
            return
        if self._radio[module]:
            self._serve(module)
        elif not self._queues[module]:
            self._notify_idle([module])

    def _check_done(self, broadcast: _Broadcast) -> None:
        """Nothing of the broadcast is under way: the nodes it did not reach lost it now."""
        if broadcast.pending > 0 or broadcast.done:
            return
        broadcast.done = True
        now = self.clock.now
        if not broadcast.intact:
            self._lost(Lost(broadcast.frame, None, broadcast.why.get(None, Loss.COLLISION), now))
            return
        default = broadcast.why.get(None, Loss.COLLISION)
        for node in self.modules:
            if node not in broadcast.reached:
                self._lost(Lost(broadcast.frame, node, broadcast.why.get(node, default), now))


class BusSimulator:
    """A bus on its own, outside a run: schedule sends and reads on a kernel of its own
    (:class:`~petriflow.runtime.media.ProcessClock`), run, look at what happened.

    Modules read their buffers only when told (:meth:`read`, :meth:`reads_every`).

    Args:
        bus: the bus parameters.
        modules: the attached modules.
        seed: seed of the medium's random numbers.
        dt: the kernel's tick (s): events keep their exact times whatever it is; ``now``
            after :meth:`run` is ``until`` rounded up to it.

    Attributes:
        received: the frames each module read that were addressed to it.
        refused: the frames a full transmit queue dropped.

    Examples:
        >>> sim = BusSimulator(SerialBus(), modules=[0, 1, 2], seed=1)
        >>> sim.send(0.0, Frame(0, (1,), bytes(9)))
        >>> sim.send(0.0005, Frame(2, (1,), bytes(9)))   # starts while the first is on the line
        >>> sim.read(0.01, 1)
        >>> medium = sim.run()
        >>> [t.garbled for t in medium.transmissions], len(sim.received[1])
        ([True, True], 0)
        >>> [(loss.reason.value, loss.time) for loss in medium.losses]   # both, when they overlapped
        [('collision', 0.0005), ('collision', 0.0005)]
    """

    def __init__(self, bus: BusModel, modules: Iterable[int], seed: int = 0, dt: float = 1e-6) -> None:
        self.clock = ProcessClock(Kernel(dt))
        self.medium = bus.medium(self.clock, random.Random(seed), modules, read_period=None)
        self.received: dict[int, list[Frame]] = {m: [] for m in self.medium.modules}
        self.refused: list[Frame] = []
        self.medium.on_delivery(self._delivered)

    def send(self, time: float, frame: Frame) -> None:
        """The frame's sender asks to send it at ``time``."""
        self.clock.at(time, self._send, frame, rank=MODULE)

    def read(self, time: float, module: int) -> None:
        """``module`` reads its receive buffer at ``time``."""
        self.clock.at(time, self.medium.read, module, rank=MODULE)

    def reads_every(self, module: int, period: float, phase: float = 0.0) -> None:
        """``module`` reads its buffer at ``phase + k · period`` while a frame waits (0:
        on arrival)."""
        self.medium.reads_every(module, period, phase)

    def run(self, until: float | None = None) -> BusMedium:
        """Run the bus (until nothing is left, or up to ``until``); returns the medium."""
        kernel = self.clock.kernel
        if until is not None:
            self.clock.run(until)
            return self.medium
        while (tick := kernel.peek()) is not None:
            self.clock.run(tick * kernel.dt)
        return self.medium

    def _send(self, frame: Frame) -> None:
        if not self.medium.request(frame):
            self.refused.append(frame)

    def _delivered(self, delivery: Delivery) -> None:
        self.received.setdefault(delivery.module, []).append(delivery.frame)
