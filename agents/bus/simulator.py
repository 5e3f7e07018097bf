"""A bus on its own, outside a run (:class:`BusSimulator`): schedule sends and reads on a
kernel of its own, run, look at what happened."""

from __future__ import annotations

import random
from collections.abc import Iterable

from petriflow.agents.bus.buffer import MODULE, BusMedium
from petriflow.agents.bus.parameters import BusModel
from petriflow.agents.bus.records import Delivery, Frame
from petriflow.runtime.kernel import Kernel
from petriflow.runtime.media import ProcessClock

__all__ = ["BusSimulator"]


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
        medium: the bus (:class:`~petriflow.agents.bus.buffer.BusMedium`).
        received: the frames each module read that were addressed to it.
        refused: the frames a full transmit queue dropped.

    Examples:
        >>> from petriflow.agents.bus.parameters import SerialBus
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
