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
from typing import Any, Callable, Protocol

from petriflow.runtime.kernel import Kernel
from petriflow.runtime.stopwatch import Timing

__all__ = ["Clock", "SimulatedClock", "RealtimeClock"]


class Clock(Protocol):
    """Moves a kernel's tick forward, stepping the world on the way."""

    def start(self) -> None:
        """The run starts now (wall-clock reference)."""

    def advance(self, kernel: Kernel, world: Any, tick: int) -> None:
        """Bring ``kernel.tick`` to ``tick``, stepping ``world`` once per tick (or stop
        earlier, when its ``interrupt`` says so)."""


class SimulatedClock:
    """As fast as the machine goes: simulated time is decoupled from the wall clock.

    Args:
        stopwatch: where each world step's wall-clock time goes (``physics``).

    Attributes:
        interrupt: called after each world step; ``True`` stops the advance at that tick
            (someone steering the run wants it to stop there, :mod:`~.control`).
    """

    def __init__(self, stopwatch: Timing | None = None) -> None:
        self.stopwatch = stopwatch
        self.interrupt: Callable[[], bool] | None = None

    def start(self) -> None:
        pass

    def advance(self, kernel: Kernel, world: Any, tick: int) -> None:
        if world is None:
            kernel.tick = max(kernel.tick, tick)
            return
        interrupt = self.interrupt
        stopwatch = self.stopwatch
        while kernel.tick < tick:
            if stopwatch is None:
                world.step()
            else:
                with stopwatch.measure("physics"):
                    world.step()
            kernel.tick += 1
            if interrupt is not None and interrupt():
                return


class RealtimeClock:
    """Paced: after each tick, wait until the wall clock has caught up with simulated
    time divided by ``factor`` (a run that is slower than that just runs behind).

    Args:
        stopwatch: where each world step's wall-clock time goes (``physics``).
        factor: simulated seconds per wall-clock second (2: twice as fast as real time).
        now: the simulated time the clock starts from (a run paced from the middle on).

    Attributes:
        interrupt: called after each tick; ``True`` stops the advance at that tick.
    """

    def __init__(self, stopwatch: Timing | None = None, factor: float = 1.0, now: float = 0.0) -> None:
        if not factor > 0:
            raise ValueError(f"a real-time factor is > 0, got {factor!r}")
        self.factor = factor
        self._from = now
        self._start = wallclock.perf_counter()
        self.stopwatch = stopwatch
        self.interrupt: Callable[[], bool] | None = None

    def start(self) -> None:
        self._start = wallclock.perf_counter()

    def rebase(self, now: float) -> None:
        """Pace from simulated time ``now`` as from this moment on (after a pause: the
        run does not rush to catch up with the time it stood still)."""
        self._from = now
        self._start = wallclock.perf_counter()

    def advance(self, kernel: Kernel, world: Any, tick: int) -> None:
        while kernel.tick < tick:
            if world is not None and self.stopwatch is not None:
                with self.stopwatch.measure("physics"):
                    world.step()
            elif world is not None:
                world.step()
            kernel.tick += 1
            ahead = (kernel.now - self._from) / self.factor - (wallclock.perf_counter() - self._start)
            if ahead > 0:
                wallclock.sleep(ahead)
            if self.interrupt is not None and self.interrupt():
                return
