"""CAN: frames wait for an idle bus and arbitrate by identifier (:class:`CanMedium`).

Frames wait in the controller's transmit buffers until the bus is idle (after the
3-bit intermission). Every node with a pending frame starts its SOF at that instant,
or, on an idle bus, within ``arbitration_bits`` bit times of the first SOF (a node
that has not seen the SOF yet); these contend bit by bit and the lowest identifier
wins, nothing is lost, and the losers contend again when the bus is next idle. Two
modules may not share an identifier (:class:`~petriflow.agents.bus.frames.FrameError`).
Error frames, bit errors and bus-off are not modelled. The parameters are
:class:`~petriflow.agents.bus.parameters.CanBus`.

Examples:
    Two frames asked for at once: the lower identifier goes first, and the module that
    reads its one-frame buffer after both arrived finds the second only:

    >>> from petriflow.agents.bus.parameters import CanBus
    >>> from petriflow.agents.bus.simulator import BusSimulator
    >>> sim = BusSimulator(CanBus(), modules=[0, 1, 2])
    >>> sim.send(0.0, Frame(sender=2, receivers=(0,), data=b"late", identifier=0x102))
    >>> sim.send(0.0, Frame(sender=1, receivers=(0,), data=b"wins", identifier=0x101))
    >>> sim.read(0.01, 0)
    >>> bus = sim.run()
    >>> [t.frame.sender for t in bus.transmissions], [f.data for f in sim.received[0]]
    ([1, 2], [b'late'])
    >>> [(loss.reason.value, round(loss.time * 1e6)) for loss in bus.losses]  # when the second arrived
    [('overwritten', 309)]
"""

from __future__ import annotations

import math
import random
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from petriflow.agents.bus.buffer import MEDIUM, BusMedium
from petriflow.agents.bus.frames import FrameError
from petriflow.agents.bus.records import Frame, Transmission
from petriflow.runtime.media import ProcessClock, Timer

if TYPE_CHECKING:
    from petriflow.agents.bus.parameters import CanBus

__all__ = ["CanMedium"]


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
