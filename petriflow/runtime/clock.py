"""How a run's clock moves to the next instant: as fast as it can, or paced to the wall clock.

Moving the clock from one instant to the next steps the world once per tick in
between (a run with no world jumps straight there). :class:`SimulatedClock` does only
that; :class:`RealtimeClock` also sleeps so that simulated time never runs ahead of
the wall clock, as SimPy's ``RealtimeEnvironment`` does. A run takes its clock when it
is made (``Scheduler(..., clock=RealtimeClock())``); nothing else in the run knows
which one it has. A clock made with a stopwatch (:mod:`~petriflow.runtime.stopwatch`)
reports each world step to it as ``physics``.

Examples:
    >>> from petriflow.runtime.kernel import Kernel
    >>> kernel = Kernel(dt=0.5)
    >>> SimulatedClock().advance(kernel, None, 4)
    >>> kernel.now
    2.0
"""

from __future__ import annotations

import time as wallclock
from typing import Any, Protocol

from petriflow.runtime.kernel import Kernel
from petriflow.runtime.stopwatch import Timing

__all__ = ["Clock", "SimulatedClock", "RealtimeClock"]


class Clock(Protocol):
    """Moves a kernel's tick forward, stepping the world on the way."""

    def start(self) -> None:
        """The run starts now (wall-clock reference)."""

    def advance(self, kernel: Kernel, world: Any, tick: int) -> None:
        """Bring ``kernel.tick`` to ``tick``, stepping ``world`` once per tick."""


class SimulatedClock:
    """As fast as the machine goes: simulated time is decoupled from the wall clock.

    Args:
        stopwatch: where each world step's wall-clock time goes (``physics``).
    """

    def __init__(self, stopwatch: Timing | None = None) -> None:
        self.stopwatch = stopwatch

    def start(self) -> None:
        pass

    def advance(self, kernel: Kernel, world: Any, tick: int) -> None:
        if world is None:
            kernel.tick = max(kernel.tick, tick)
            return
        stopwatch = self.stopwatch
        while kernel.tick < tick:
            if stopwatch is None:
                world.step()
            else:
                with stopwatch.measure("physics"):
                    world.step()
            kernel.tick += 1


class RealtimeClock:
    """Paced: after each tick, wait until the wall clock has caught up with simulated
    time (a run that is slower than real time just runs behind)."""

    def __init__(self, stopwatch: Timing | None = None) -> None:
        self._start = wallclock.perf_counter()
        self.stopwatch = stopwatch

    def start(self) -> None:
        self._start = wallclock.perf_counter()

    def advance(self, kernel: Kernel, world: Any, tick: int) -> None:
        while kernel.tick < tick:
            if world is not None and self.stopwatch is not None:
                with self.stopwatch.measure("physics"):
                    world.step()
            elif world is not None:
                world.step()
            kernel.tick += 1
            ahead = kernel.now - (wallclock.perf_counter() - self._start)
            if ahead > 0:
                wallclock.sleep(ahead)
