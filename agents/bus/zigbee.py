"""ZigBee's MAC: XBee radios sharing the air with unslotted CSMA/CA, and the single-hop bus.

Each module talks to its XBee radio over a UART at ``uart_baud`` (57 600 baud); the
radio starts on a frame after the bytes are in and a packetization timeout of
``packetization_chars`` characters (XBee transparent mode). The air is 802.15.4 at
250 kbit/s with unslotted CSMA/CA (:class:`CsmaCa`): a random backoff of 0..2^BE − 1
unit periods (320 µs), then an 8-symbol clear channel assessment; if clear, the radio
turns around (12 symbols, 192 µs) and sends, else BE grows (3 → 5) and after
``max_backoffs`` = 4 failed assessments the frame is dropped
(:attr:`~petriflow.agents.bus.records.Loss.ACCESS_FAILURE`). Two frames that overlap
on the air are both garbled, at the moment they overlap (no capture). A frame survives
each link with the probability of :class:`~petriflow.agents.bus.radio.RadioLink` (the
core's log-distance RSSI, :class:`petriflow.runtime.radio.LogDistance`, at the
distance between the modules, ``spacing`` metres apart per module number). After a
frame the radio waits the long or short interframe spacing.

:class:`ZigbeeMedium` is the single-hop air (``network: false``): frames are
broadcasts (the CPG messages carry their addresses in the payload, as in the paper's
algorithm), so no MAC acknowledgements or retries; received frames reach the module
after the radio has written their payload out over the UART. A module cannot hear the
air: for it the "bus" is free when its own radio has nothing to send. The ZigBee
network (``network: true``, the default) is a layer above the same :class:`CsmaCa`:
:class:`~petriflow.agents.bus.network.ZigbeeNetworkMedium`. The parameters are
:class:`~petriflow.agents.bus.parameters.ZigbeeBus`.

Examples:
    A frame of 9 bytes: 9 + 3 characters over the UART (2083 µs), a backoff of 0..7
    unit periods (here 3: 960 µs), the assessment and the turnaround (320 µs), then 336
    bits on the air (1344 µs):

    >>> from petriflow.agents.bus.parameters import ZigbeeBus
    >>> from petriflow.agents.bus.simulator import BusSimulator
    >>> sim = BusSimulator(ZigbeeBus(network=False), modules=[0, 1], seed=3)
    >>> sim.send(0.0, Frame(0, (1,), bytes(9)))
    >>> [(round(t.start * 1e6), round(t.end * 1e6)) for t in sim.run().transmissions]
    [(3363, 4707)]
"""

from __future__ import annotations

import random
from collections import deque
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any

from petriflow.agents.bus.buffer import MEDIUM, BusMedium
from petriflow.agents.bus.records import Frame, Loss, Lost, Transmission
from petriflow.runtime.media import ProcessClock

if TYPE_CHECKING:
    from petriflow.agents.bus.parameters import ZigbeeBus

__all__ = ["CsmaCa", "ZigbeeMedium"]

# 802.15.4 at 2.4 GHz: 62.5 k symbols a second.
_SYMBOL = 16e-6
_UNIT_BACKOFF = 20 * _SYMBOL
_CCA = 8 * _SYMBOL
_TURNAROUND = 12 * _SYMBOL
_SIFS = 12 * _SYMBOL
_LIFS = 40 * _SYMBOL
_MAX_SIFS_FRAME_BYTES = 18


class CsmaCa:
    """The modules' 802.15.4 radios on one shared air: where they are, whether a frame
    survives the link between two of them, and their channel access (unslotted CSMA/CA).

    A radio takes one frame at a time (:meth:`send`); the layer above hears of it
    through the callbacks it gives: ``on_start(transmission)`` when a frame goes on the
    air, ``on_collision(transmission)`` when one is first garbled (it overlaps another),
    ``on_sent(node, transmission)`` when the node's frame has left the air (intact or
    garbled), ``on_failure(node)`` when CSMA/CA gave up on it. Then the radio rests (the
    interframe spacing after a transmission) and, unless it took a frame meanwhile,
    calls ``on_free(node)``.

    Args:
        bus: the radios' parameters.
        clock: the clock the air runs on.
        rng: its random numbers (backoffs, link errors).
        positions: each node's place on a line (metres); default ``spacing`` per node number.
    """

    def __init__(self, bus: ZigbeeBus, clock: ProcessClock, rng: random.Random, *,
                 on_start: Callable[[Transmission], Any], on_sent: Callable[[int, Transmission], Any],
                 on_failure: Callable[[int], Any], on_free: Callable[[int], Any],
                 on_collision: Callable[[Transmission], Any] | None = None,
                 positions: dict[int, float] | None = None) -> None:
        self.bus = bus
        self.clock = clock
        self.rng = rng
        self.positions = dict(positions or {})
        self._link = bus.link()
        self._on_start, self._on_collision, self._on_sent = on_start, on_collision, on_sent
        self._on_failure, self._on_free = on_failure, on_free
        self._active: list[Transmission] = []
        self._recent: list[Transmission] = []  # ended less than a CCA ago
        self._serving: dict[int, bool] = {}
        self._frame: dict[int, Frame] = {}  # the frame each radio works on
        self._attempt: dict[int, tuple[int, int]] = {}  # node -> (NB, BE)
        self._on_air: dict[Transmission, int] = {}  # who sends it

    def add_node(self, node: int) -> None:
        """Give ``node`` a radio (a no-op if it has one)."""
        self._serving.setdefault(node, False)

    def distance(self, a: int, b: int) -> float:
        """Metres between two nodes' radios."""
        spacing = self.bus.spacing
        return abs(self.positions.get(a, a * spacing) - self.positions.get(b, b * spacing))

    def survives(self, sender: int, receiver: int, transmission: Transmission) -> bool:
        """Whether ``transmission`` from ``sender`` reaches ``receiver`` free of bit
        errors (a random draw on the link's error probability)."""
        return self._link.survives(self.distance(sender, receiver), transmission.bits, self.rng)

    def serving(self, node: int) -> bool:
        """Whether ``node``'s radio works on a frame (from :meth:`send` to the end of
        its transmission or of CSMA/CA)."""
        return self._serving[node]

    def busy(self) -> bool:
        """Whether a frame is on the air now."""
        return bool(self._active)

    def airtime(self, frame: Frame) -> float:
        """Seconds ``frame`` occupies the air."""
        return self.bus.frame_bits(frame) / self.bus.air_bitrate

    def send(self, node: int, frame: Frame, ready: float | None = None) -> None:
        """``node``'s radio takes ``frame``: CSMA/CA starts now (``ready`` ``None``) or
        at ``ready`` (when the frame is in, at the earliest now)."""
        self._serving[node] = True
        self._frame[node] = frame
        self._attempt[node] = (0, self.bus.min_be)
        if ready is None:
            self._backoff(node)
        else:
            self.clock.at(max(ready, self.clock.now), self._backoff, node, rank=MEDIUM)

    # CSMA/CA --------------------------------------------------------------------------
    def _backoff(self, node: int) -> None:
        _, exponent = self._attempt[node]
        delay = self.rng.randrange(1 << exponent) * _UNIT_BACKOFF
        self.clock.at(self.clock.now + delay + _CCA, self._assess, node, rank=MEDIUM)

    def _assess(self, node: int) -> None:
        """End of the clear channel assessment: was anything on the air during it?"""
        now = self.clock.now
        self._forget(now)
        if not (any(t.start < now for t in self._active) or bool(self._recent)):
            self.clock.at(now + _TURNAROUND, self._transmit, node, rank=MEDIUM)
            return
        backoffs, exponent = self._attempt[node]
        backoffs += 1
        if backoffs > self.bus.max_backoffs:
            self._on_failure(node)
            self._rest(node, now)
            return
        self._attempt[node] = (backoffs, min(exponent + 1, self.bus.max_be))
        self._backoff(node)

    def _forget(self, now: float) -> None:
        """Keep only the frames that ended less than a CCA ago."""
        since = now - _CCA
        self._recent = [t for t in self._recent if t.end > since]

    # The air ---------------------------------------------------------------------------
    def _transmit(self, node: int) -> None:
        """On the air now; with another, both are garbled now."""
        frame, now = self._frame[node], self.clock.now
        bits = self.bus.frame_bits(frame)
        transmission = Transmission(frame, now, now + bits / self.bus.air_bitrate, bits)
        self._on_air[transmission] = node
        self._active.append(transmission)
        self._on_start(transmission)
        if len(self._active) > 1:
            for other in self._active:
                if not other.garbled:
                    other.garbled = True
                    if self._on_collision is not None:
                        self._on_collision(other)
        self.clock.at(transmission.end, self._end, transmission, rank=MEDIUM)

    def _end(self, transmission: Transmission) -> None:
        """Off the air, kept a CCA for carrier sense; the sender rests its interframe spacing."""
        now = self.clock.now
        node = self._on_air.pop(transmission)
        self._active.remove(transmission)
        self._forget(now)
        self._recent.append(transmission)
        self._on_sent(node, transmission)
        # the long interframe spacing after a long MAC frame
        spacing = _LIFS if transmission.bits // 8 - 6 > _MAX_SIFS_FRAME_BYTES else _SIFS
        self._rest(node, now + spacing)

    def _rest(self, node: int, until: float) -> None:
        """The radio is done with its frame; it may take the next one at ``until``."""
        self._serving[node] = False
        self.clock.at(until, self._free, node, rank=MEDIUM)

    def _free(self, node: int) -> None:
        if not self._serving[node]:
            self._on_free(node)


class ZigbeeMedium(BusMedium):
    """XBee radios sharing the air with unslotted CSMA/CA, single hop (see the module).
    With ``addressing: unicast`` a radio hands its module only frames addressed to it (a
    sniffer takes all); acknowledgements and retries are the network's
    (:class:`~petriflow.agents.bus.network.ZigbeeNetworkMedium`), not this medium's.

    Attributes:
        radio: the radios on the air (:class:`CsmaCa`).
    """

    bus: ZigbeeBus

    def __init__(self, bus: ZigbeeBus, clock: ProcessClock, rng: random.Random, modules: Iterable[int] = (),
                 positions: dict[int, float] | None = None, **options: Any) -> None:
        self.radio = CsmaCa(bus, clock, rng, on_start=self._started, on_collision=self._collided,
                            on_sent=self._sent, on_failure=self._failed, on_free=self._free,
                            positions=positions)
        self._ready: dict[int, deque[float]] = {}  # when each queued frame is in its radio
        super().__init__(bus, clock, rng, modules, **options)

    def add_module(self, module: int) -> None:
        super().add_module(module)
        self.radio.add_node(module)
        self._ready.setdefault(module, deque())

    def is_free(self, module: int) -> bool:
        return not self.radio.serving(module) and not self._queues[module]

    def busy(self) -> bool:
        return self.radio.busy()

    def _request(self, frame: Frame) -> bool:
        sender = frame.sender
        if not self._enqueue(frame, self.radio.serving(sender)):
            return False
        # The module's UART writes the bytes, then the XBee waits the packetization timeout.
        uart = self.bus.uart_time(len(frame.data) + self.bus.packetization_chars)
        self._ready[sender].append(self.clock.now + uart)
        if not self.radio.serving(sender):
            self._serve(sender)
        return True

    def _serve(self, module: int) -> None:
        """The radio takes the next frame of its queue."""
        self.radio.send(module, self._queues[module][0], ready=self._ready[module][0])

    def _collided(self, transmission: Transmission) -> None:
        self._lost(Lost(transmission.frame, None, Loss.COLLISION, self.clock.now))

    def _sent(self, sender: int, transmission: Transmission) -> None:
        now = self.clock.now
        frame = transmission.frame
        self._ended(transmission)
        if not transmission.garbled:
            out = self.bus.uart_time(len(frame.data))
            unicast = self.bus.addressing == "unicast"
            for module in self.modules:
                if module == sender or (unicast and module not in frame.receivers and module not in self.sniffers):
                    continue  # with unicast addressing a radio drops frames for other addresses
                if self.radio.survives(sender, module, transmission):
                    self.clock.at(now + out, self._arrive, frame, module, rank=MEDIUM)
                else:
                    self._lost(Lost(frame, module, Loss.RADIO, now))
        self._done(sender)

    def _failed(self, module: int) -> None:
        self._lost(Lost(self._queues[module][0], None, Loss.ACCESS_FAILURE, self.clock.now))
        self._done(module)

    def _done(self, module: int) -> None:
        self._queues[module].popleft()
        self._ready[module].popleft()

    def _free(self, module: int) -> None:
        if self._queues[module]:
            self._serve(module)
        else:
            self._notify_idle([module])
