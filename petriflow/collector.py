"""Pausing Python's cycle collector while a large structure without cycles is built.

Reading a big net, or indexing it for a run, allocates hundreds of thousands of
containers (the YAML's mappings and lists, per-transition tuples) that hold no
reference cycles. Each time the allocations pass the collector's threshold it walks
the objects of its generations, and the older generations hold everything built so
far: for the 3,000-transition net of ``bench/runtime.py`` that was about 40 % of the
loading time. Nothing such a build makes needs the collector, so it is paused for the
build and then left as it was.

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

__all__ = ["paused"]


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
