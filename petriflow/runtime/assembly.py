"""One place that checks a run's inputs and puts a run together.

Everything that runs a net (``petriflow run`` and ``--resume``, the Python
:func:`~petriflow.runtime.session.run`, sweep trials, the test kit, scenario scripts)
goes through two functions:

* :func:`validate`: the net bound to the registry, the run configuration checked
  against the net, the counts a run can hold, and the world an action needs: once.
  The :class:`~petriflow.runtime.binding.Binding` it returns says it was checked, so
  nothing checks it again.
* :func:`open_run`: the world (a :class:`~petriflow.world.World`, or its checked
  description, loaded here and closed when the run is over) and the
  :class:`~petriflow.runtime.scheduler.Scheduler` with its clock; observers subscribe
  to what it yields.

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> from petriflow.runtime.config import RunConfig
    >>> net = loads_net('''
    ... petriflow: 1
    ... places: [{id: i, tokens: 1}, o]
    ... transitions: [{id: rest, action: core.wait, params: {seconds: 2}, in: [i], out: [o]}]
    ... ''')
    >>> binding = validate(net, RunConfig())
    >>> with open_run(net, binding, RunConfig(), seed=1) as scheduler:
    ...     scheduler.run().time
    2.0
"""

from __future__ import annotations

import dataclasses
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator

from petriflow.errors import NetFormatError
from petriflow.net import Net
from petriflow.runtime.binding import Binding, bind, check_sizes, check_world
from petriflow.runtime.clock import Clock, RealtimeClock, SimulatedClock
from petriflow.runtime.config import RunConfig
from petriflow.runtime.registry import Registry

__all__ = ["validate", "open_run"]


def validate(net: Net, config: RunConfig, *, binding: Binding | None = None, registry: Registry | None = None,
             path: str | None = None, has_world: bool | None = None) -> Binding:
    """Check a run's inputs once; returns the binding, marked checked.

    Args:
        net: the net.
        config: its run configuration.
        binding: the net already bound (else it is bound to ``registry`` here).
        registry: where names are looked up when binding here.
        path: the net's file, named in errors.
        has_world: whether the run has a world (``None``: not known yet, not checked).

    Raises:
        NetFormatError: ``file:line`` for what does not bind, a fault or channel naming
            nothing in the net, counts a run cannot hold, an action needing a world
            the run lacks.
    """
    if binding is not None and binding.checked and has_world is None:
        return binding
    if binding is None:
        try:
            binding = bind(net, registry, path=path)
        except NetFormatError as exc:
            raise config.blame(exc) from None
    config.check(net)
    check_sizes(net, path or net.path)
    if has_world is not None:
        check_world(binding, has_world, path or net.path)
    return dataclasses.replace(binding, checked=True)


@contextmanager
def open_run(net: Net, binding: Binding, config: RunConfig, *, seed: int | None = None, world: Any = None,
             world_data: dict[str, Any] | None = None, world_file: str | Path | None = None,
             world_base: str | Path | None = None, gui: bool = False, realtime: bool = False,
             clock: Clock | None = None) -> Iterator[Any]:
    """A run put together: yields its :class:`~petriflow.runtime.scheduler.Scheduler`.

    The world is ``world`` (an object made by the caller, left open), or loaded here
    from its checked description ``world_data`` (relative files resolved beside
    ``world_file``, or in ``world_base``) or from ``world_file``, and closed when the
    block ends. The
    scheduler's actions are torn down when the block ends, whatever happened.

    Args:
        seed: the run seed (default: the configuration's).
        gui: open pybullet's GUI for a world loaded here.
        realtime: pace the run to the wall clock (a :class:`RealtimeClock`).
        clock: the clock (overrides ``realtime``).
    """
    from petriflow.runtime.scheduler import Scheduler

    opened = None
    if world is None and (world_data is not None or world_file is not None):
        from petriflow.world import World, load_world

        if world_data is not None:
            base = world_base if world_base is not None else (
                Path(world_file).resolve().parent if world_file is not None else Path("."))
            opened = World(world_data, base=base, gui=gui, path=None if world_file is None else str(world_file))
        else:
            opened = load_world(world_file, gui=gui)
        world = opened
    try:
        scheduler = Scheduler(net, world=world, config=config, seed=seed, binding=binding,
                              clock=clock or (RealtimeClock() if realtime else SimulatedClock()))
        with scheduler:
            yield scheduler
    finally:
        if opened is not None:
            opened.close()
