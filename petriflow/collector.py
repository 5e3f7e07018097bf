"""Pausing Python's cycle collector while a large structure without cycles is built,
and letting it walk the old objects less often while a run goes on.

Reading a big net, or indexing it for a run, allocates hundreds of thousands of
containers (the YAML's mappings and lists, per-transition tuples) that hold no
reference cycles. Each time the allocations pass the collector's threshold it walks
the objects of its generations, and the older generations hold everything built so
far: for the 3,000-transition net of ``bench/runtime.py`` that was about 40 % of the
loading time. Nothing such a build makes needs the collector, so it is paused for the
build and then left as it was.

A long run keeps what its agents learn (maps, histories, per-peer records): hundreds of
thousands of long-lived containers. The collector's full passes walk all of them each
time the old generation has grown by a quarter and ten middle-generation passes have
gone by, so their cost grew faster than the team: 12 full passes, 2.3 s of 16.8 s of
CPU, in 30 simulated seconds of the 1,000-robot swarm. During a run (:func:`relaxed`)
a full pass waits for 100 middle-generation passes instead of 10, and the young
generation is collected after 2,000 allocations instead of 700: the young and middle
passes still collect short-lived cycles, and the old generation is still collected,
less often. The thresholds are set back when the run returns.

What exists when the run starts (the net, its index, the world, the scheduler's
tables: 160,000 tracked objects for the swarm of 1,000 robots) lives as long as the
run, so during it those objects are also set aside from the collector's walks
(``gc.freeze``) and given back when the run returns (``gc.unfreeze``); a run inside a
run that froze leaves the freezing to the outer one. Over 120 simulated seconds of
1,000 robots (ten copies of the 100-robot maze) the collector took 2.8 to 3.1 s in
four runs with it (two full passes), 5.3 s in one run without (three full passes; the
machine was busier then) (``python bench/swarm.py --robots 100 1000 --tile 100 --until
120``, its ``collector`` line); timed the same way around one run each, 3.8 s without
and 2.7 s with. A cycle that was already garbage when the run started is collected
after it.

Examples:
    >>> import gc
    >>> with paused():
    ...     gc.isenabled()
    False
    >>> gc.isenabled()
    True
"""

from __future__ import annotations

import contextlib
import gc
from typing import Iterator

__all__ = ["paused", "relaxed"]

#: The collector's thresholds during a run (:func:`relaxed`): at least these.
RUN_THRESHOLDS = (2000, 10, 100)


@contextlib.contextmanager
def paused() -> Iterator[None]:
    """Pause the cycle collector for the block (it stays off if it was off)."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


@contextlib.contextmanager
def relaxed() -> Iterator[None]:
    """Raise the collector's thresholds to at least :data:`RUN_THRESHOLDS` and set aside
    what exists now from its walks for the block; undo both after (see the module).

    Examples:
        >>> import gc
        >>> before = gc.get_threshold()
        >>> with relaxed():
        ...     gc.get_threshold()[2] >= 100
        True
        >>> gc.get_threshold() == before
        True
        >>> with relaxed():
        ...     gc.get_freeze_count() > 0
        True
        >>> gc.get_freeze_count()
        0
    """
    before = gc.get_threshold()
    gc.set_threshold(*(max(now, least) for now, least in zip(before, RUN_THRESHOLDS)))
    freeze = gc.get_freeze_count() == 0
    if freeze:
        gc.freeze()
    try:
        yield
    finally:
        if freeze:
            gc.unfreeze()
        gc.set_threshold(*before)
