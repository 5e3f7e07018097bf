"""Putting a checked run together: the third step of a run (checked run -> scheduler).

Everything that runs a net (``petriflow run`` and ``--resume``, the Python
:func:`~petriflow.runtime.session.run`, the test kit, scenario scripts) reads its
files (:mod:`~petriflow.runtime.loading`), checks them
(:mod:`~petriflow.runtime.validation`) and then comes here: :func:`open_run` builds
the world from its checked description (or takes the one the caller made) and the
:class:`~petriflow.runtime.scheduler.Scheduler` with its clock, the world's settings
and the checked binding; observers subscribe to what it yields. When the block ends
the actions are torn down and a world built here is closed, whatever happened.

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> from petriflow.runtime.config import RunConfig
    >>> net = loads_net('''
    ... petriflow: 1
    ... places: [{id: i, tokens: 1}, o]
    ... transitions: [{id: rest, action: core.wait, params: {seconds: 2}, in: [i], out: [o]}]
    ... ''')
    >>> checked = CheckedRun(net, validate(net, RunConfig()), RunConfig())
    >>> with open_run(checked, seed=1) as scheduler:
    ...     scheduler.run().time
    2.0
"""

from __future__ import annotations

from contextlib import contextmanager
from typing import Any, Iterator

from petriflow.net import Net
from petriflow.runtime.binding import Binding
from petriflow.runtime.clock import Clock, RealtimeClock, SimulatedClock
from petriflow.runtime.control import Control
from petriflow.runtime.config import RunConfig
from petriflow.runtime.scheduler import Scheduler
from petriflow.runtime.services import RemoteGoals
from petriflow.runtime.stopwatch import UNTIMED, Timing
from petriflow.runtime.validation import CheckedRun, validate

__all__ = ["open_run", "CheckedRun", "validate"]


@contextmanager
def open_run(run: CheckedRun | Net, binding: Binding | None = None, config: RunConfig | None = None, *,
             seed: int | None = None, world: Any = None, gui: bool = False, realtime: bool = False,
             clock: Clock | None = None, stopwatch: Timing | None = None,
             remote: RemoteGoals | None = None, control: Control | None = None) -> Iterator[Scheduler]:
    """A run put together: yields its :class:`~petriflow.runtime.scheduler.Scheduler`.

    Args:
        run: the checked run (or, as older code calls it, the net, with its checked
            ``binding`` and ``config``).
        seed: the run seed (default: the configuration's).
        world: a world the caller made (left open); default: the checked run's world
            file, built here and closed when the block ends.
        gui: open pybullet's GUI for a world built here.
        realtime: pace the run to the wall clock (a :class:`RealtimeClock`).
        clock: the clock (overrides ``realtime``).
        stopwatch: where the run's wall-clock time goes, by category (the world's
            steps, the actions' work: :mod:`~petriflow.runtime.stopwatch`); ``None``:
            nobody times it.
        remote: where the goals of remote transitions go (a run with a ``bridge:``).
        control: the run's control queue, if it is steered
            (:class:`~petriflow.runtime.control.Control`).
    """
    if isinstance(run, Net):
        run = CheckedRun(run, binding, config or RunConfig())
    opened = None
    settings = run.settings
    if world is None and run.world is not None:
        from petriflow.world import World

        opened = world = World(run.world.description, base=run.world.base, gui=gui, path=run.world.path)
    elif world is not None:
        settings = None  # read from the world given (its meta), by the scheduler
    try:
        clock = clock or (RealtimeClock(stopwatch) if realtime else SimulatedClock(stopwatch))
        scheduler = Scheduler(run.net, world=world, config=run.config, seed=seed, binding=run.binding,
                              clock=clock, settings=settings, stopwatch=stopwatch or UNTIMED, remote=remote,
                              control=control)
        with scheduler:
            yield scheduler
    finally:
        if opened is not None:
            opened.close()
