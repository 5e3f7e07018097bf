"""The three buses' parameters, and each bus as a petriflow medium.

Every module of the EMERGE chain hangs on one bus, at bit-level timing, with the losses
of real modules. A bus's parameters are a :class:`BusModel` (:class:`SerialBus`,
:class:`CanBus`, :class:`ZigbeeBus`); ``bus.medium(clock, rng, modules)`` starts one on
a :class:`~petriflow.runtime.media.ProcessClock`:

* **RS-485** (:class:`SerialBus`): :class:`~petriflow.agents.bus.rs485.SerialMedium`,
  a half-duplex line with no arbitration;
* **CAN** (:class:`CanBus`): :class:`~petriflow.agents.bus.can.CanMedium`, arbitration
  by identifier;
* **ZigBee** (:class:`ZigbeeBus`): XBee radios with 802.15.4 CSMA/CA
  (:mod:`~petriflow.agents.bus.zigbee`), as a ZigBee network by default
  (:class:`~petriflow.agents.bus.network.ZigbeeNetworkMedium`), or single-hop
  (``network: false``, :class:`~petriflow.agents.bus.zigbee.ZigbeeMedium`).

What every bus shares (transmit queues, receive buffers, reads, listeners) is
:class:`~petriflow.agents.bus.buffer.BusMedium`'s.

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
    >>> [type(bus.medium(clock, random.Random(0))).__name__
    ...  for bus in (SerialBus(), CanBus(), ZigbeeBus(), ZigbeeBus(network=False))]
    ['SerialMedium', 'CanMedium', 'ZigbeeNetworkMedium', 'ZigbeeMedium']
"""

from __future__ import annotations

import math
import random
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any, ClassVar

from petriflow.agents.bus.buffer import OWN_READ_PERIOD, BusMedium
from petriflow.agents.bus.can import CanMedium
from petriflow.agents.bus.channel import BusView, Carrier
from petriflow.agents.bus.errors import BusError
from petriflow.agents.bus.frames import (
    IEEE802154_MAC_HEADER_BYTES,
    IEEE802154_MAX_FRAME_BYTES,
    FrameError,
    can_frame_bits,
    ieee802154_frame_bits,
    uart_frame_bits,
)
from petriflow.agents.bus.network import ZigbeeNetworkMedium
from petriflow.agents.bus.radio import RadioLink
from petriflow.agents.bus.records import Frame
from petriflow.agents.bus.rs485 import SerialMedium
from petriflow.agents.bus.zigbee import ZigbeeMedium
from petriflow.runtime.channels import Message
from petriflow.runtime.media import Medium, MediumPort, ProcessClock

__all__ = ["BusModel", "CanBus", "SerialBus", "ZigbeeBus"]


def _ranged(default: float, low: float, high: float) -> Any:
    """A parameter's default and the range a run configuration may set it in."""
    return field(default=default, metadata={"range": (low, high)})


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
        loop_cost: seconds each iteration of a module's control loop spends driving
            its bus interface (a controller's registers, a driver), added to the
            iteration (0: none); the firmware asks it through
            :attr:`~petriflow.agents.bus.channel.BusView.loop_cost`.
        logs: in a run, keep every transmission, delivery and loss in the medium's
            lists (memory grows with the run; for tests and figures).
        sender_in_identifier: (class constant) the sender's address travels in the
            frame's identifier, so a payload need not carry it (CAN).
    """

    tx_queue: int = _ranged(3, 0, 10_000)
    rx_buffer: int = _ranged(1, 1, 10_000)
    acceptance_filter: bool = False
    read_period: float = _ranged(0.0, 0.0, 3600.0)
    loop_cost: float = _ranged(0.0, 0.0, 10.0)
    logs: bool = False

    sender_in_identifier: ClassVar[bool] = False
    _carrier = None  # the run's Carrier once attached (a class default, not a parameter)

    def payload_limit(self) -> int:
        """Largest payload of one frame in bytes (a longer channel message is split)."""
        return 1 << 30

    def frame_bits(self, frame: Frame) -> int:
        """Bits the frame occupies the medium for."""
        raise NotImplementedError

    def medium(self, clock: ProcessClock, rng: random.Random, modules: Iterable[int] = (), *,
               logs: bool = True, read_period: float | None = OWN_READ_PERIOD) -> BusMedium:
        """Start this bus on ``clock`` with ``modules`` attached (see
        :class:`~petriflow.agents.bus.buffer.BusMedium`)."""
        raise NotImplementedError

    # As a petriflow medium --------------------------------------------------------
    def attach(self, port: MediumPort) -> None:
        """A run starts: the bus starts on the run's kernel (``port.clock``), its
        random numbers from ``port.rng``; messages' fates go to ``port``."""
        self._carrier = Carrier(self, port, logs=self.logs)

    def send(self, message: Message) -> None:
        """A message is put into a channel place now: its frames are requested now."""
        self._attached().send(message)

    def view(self, agent: str | None) -> BusView:
        """What ``agent``'s firmware may ask the bus: a
        :class:`~petriflow.agents.bus.channel.BusView`."""
        return BusView(self._attached(), agent)

    @property
    def carrier(self) -> Carrier | None:
        """The run's messages on this bus (``None`` before :meth:`attach`)."""
        return self._carrier

    @property
    def state(self) -> BusMedium | None:
        """The bus of the run this model is attached to (``None`` before
        :meth:`attach`): its listeners, its logs if ``logs`` is set."""
        return self._carrier.medium if self._carrier is not None else None

    def _attached(self) -> Carrier:
        if self._carrier is None:
            raise BusError(f"the {type(self).__name__} is not attached to a run (attach(port) first)")
        return self._carrier


@dataclass
class SerialBus(BusModel):
    """RS-485 with UARTs (8N1) at ``baud``; a frame is the payload and a checksum byte.

    Examples:
        >>> SerialBus().frame_bits(Frame(0, (1,), bytes(9)))  # (9 + 1) bytes × 10 bits
        100
    """

    baud: float = _ranged(115_200.0, 1.0, 1e9)
    checksum_bytes: int = _ranged(1, 0, 16)
    sense_bits: float = _ranged(1.0, 0.0, 1e6)

    def frame_bits(self, frame: Frame) -> int:
        return uart_frame_bits(len(frame.data) + self.checksum_bytes)

    def medium(self, clock: ProcessClock, rng: random.Random, modules: Iterable[int] = (), *,
               logs: bool = True, read_period: float | None = OWN_READ_PERIOD) -> SerialMedium:
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

    tx_queue: int = _ranged(2, 0, 10_000)
    bitrate: float = _ranged(512_000.0, 1.0, 1e9)
    arbitration_bits: float = _ranged(1.0, 0.0, 1e6)

    sender_in_identifier: ClassVar[bool] = True

    def payload_limit(self) -> int:
        return 8

    def frame_bits(self, frame: Frame) -> int:
        return can_frame_bits(frame.identifier, frame.data, interframe=False)

    def medium(self, clock: ProcessClock, rng: random.Random, modules: Iterable[int] = (), *,
               logs: bool = True, read_period: float | None = OWN_READ_PERIOD) -> CanMedium:
        return CanMedium(self, clock, rng, modules, logs=logs, read_period=read_period)


@dataclass
class ZigbeeBus(BusModel):
    """XBee radios: UART at ``uart_baud`` to each module, 802.15.4 CSMA/CA on the air;
    a ZigBee network unless ``network`` is false (see the module). ``addressing``:
    ``broadcast`` (the default: a payload-addressed frame is a network broadcast, the
    XBee's transparent mode to 0xFFFF) or ``unicast`` (each module has its own address: a
    frame goes, acknowledged, to each of its addressees only;
    :mod:`~petriflow.agents.bus.network`).

    Examples:
        >>> bus = ZigbeeBus()
        >>> bus.frame_bits(Frame(0, (1,), bytes(9)))   # 6 PHY + 9 MAC + 16 NWK/APS + 9 + 2 FCS bytes
        336
        >>> round(bus.link().rssi(0.08), 1)
        -18.1
        >>> round(bus.uart_time(12) * 1e3, 3)          # 12 characters of 10 bits at 57 600 baud
        2.083
    """

    uart_baud: float = _ranged(57_600.0, 1.0, 1e9)
    air_bitrate: float = _ranged(250_000.0, 1.0, 1e9)
    network_bytes: int = _ranged(16, 0, 100)
    packetization_chars: float = _ranged(3.0, 0.0, 1000.0)
    min_be: int = _ranged(3, 0, 8)
    max_be: int = _ranged(5, 3, 8)
    max_backoffs: int = _ranged(4, 0, 5)
    spacing: float = _ranged(0.08, 0.0, 1e4)
    # the radios' link budget: RadioLink's defaults (one home for the XBee's numbers)
    tx_power_dbm: float = _ranged(RadioLink.tx_power_dbm, -100.0, 40.0)
    reference_loss_db: float = _ranged(RadioLink.reference_loss_db, 0.0, 200.0)
    exponent: float = _ranged(RadioLink.exponent, 1.0, 8.0)
    noise_floor_dbm: float = _ranged(RadioLink.noise_floor_dbm, -200.0, 0.0)
    interference_dbm: float = _ranged(-200.0, -200.0, 40.0)
    shadowing_db: float = _ranged(0.0, 0.0, 40.0)
    network: bool = True
    roles: str = "routers"
    btt_entries: int = _ranged(8, 1, 1000)
    btt_lifetime: float = _ranged(8.0, 0.0, 3600.0)
    broadcast_retries: int = _ranged(2, 0, 10)
    passive_ack_timeout: float = _ranged(0.5, 0.0, 60.0)
    max_jitter: float = _ranged(0.063, 0.0, 10.0)
    poll_period: float = _ranged(0.1, 1e-4, 60.0)
    mac_retries: int = _ranged(3, 0, 10)
    addressing: str = "broadcast"

    def __post_init__(self) -> None:
        if self.min_be > self.max_be:
            raise FrameError(f"min_be {self.min_be} is above max_be {self.max_be}")
        if self.addressing not in ("broadcast", "unicast"):
            raise FrameError(f"addressing is 'broadcast' or 'unicast', not {self.addressing!r}")
        if self.roles not in ("routers", "end_devices"):
            raise FrameError(f"roles is 'routers' or 'end_devices', not {self.roles!r}")

    def payload_limit(self) -> int:
        return IEEE802154_MAX_FRAME_BYTES - IEEE802154_MAC_HEADER_BYTES - self.network_bytes - 2

    def frame_bits(self, frame: Frame) -> int:
        return ieee802154_frame_bits(len(frame.data), network_bytes=self.network_bytes)

    def uart_time(self, characters: float) -> float:
        """Seconds the UART between a module and its radio takes for ``characters``
        characters (8N1), either way."""
        return uart_frame_bits(1) * characters / self.uart_baud

    def link(self) -> RadioLink:
        """The radio link model every pair of modules shares."""
        interference = -math.inf if self.interference_dbm <= -200.0 else self.interference_dbm
        return RadioLink(self.tx_power_dbm, self.reference_loss_db, self.exponent, self.noise_floor_dbm,
                         interference, self.shadowing_db)

    def medium(self, clock: ProcessClock, rng: random.Random, modules: Iterable[int] = (), *,
               logs: bool = True, read_period: float | None = OWN_READ_PERIOD) -> BusMedium:
        kind = ZigbeeNetworkMedium if self.network else ZigbeeMedium
        return kind(self, clock, rng, modules, logs=logs, read_period=read_period)
