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
    """Raise the collector's thresholds to at least :data:`RUN_THRESHOLDS` for the block
    and set them back after (see the module).

    Examples:
        >>> import gc
        >>> before = gc.get_threshold()
        >>> with relaxed():
        ...     gc.get_threshold()[2] >= 100
        True
        >>> gc.get_threshold() == before
        True
    """
    before = gc.get_threshold()
    gc.set_threshold(*(max(now, least) for now, least in zip(before, RUN_THRESHOLDS)))
    try:
        yield
    finally:
        gc.set_threshold(*before)
