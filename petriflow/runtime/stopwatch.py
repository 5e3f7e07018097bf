"""Where a run's wall-clock time goes: a stopwatch the run's parts report to, by category.

A run given a :class:`Stopwatch` (``run_files(..., stopwatch=...)``, ``open_run``,
``Scheduler``) adds up the wall-clock seconds of the work that reports to it, by
category: the clock's world steps (``physics``), and what an action measures itself,
``with ctx.stopwatch.measure("vision"): ...``, or declares for a whole method with
:func:`timed` (``@timed("control")`` on its ``poll``). Nested measures of one category
count once (a subclass's ``poll`` calling its parent's). A run without a stopwatch
measures nothing: ``ctx.stopwatch`` is then :data:`UNTIMED`, whose ``measure`` does
nothing, so an action measures the same way whether anyone listens or not. Nothing is
patched: what is measured is what the code says it measures.

The wall clock never enters a run's behaviour or its trace: a stopwatch only reads it.

Examples:
    >>> watch = Stopwatch()
    >>> with watch.measure("vision", keep=True):
    ...     with watch.measure("vision"):   # nested: counted once
    ...         pass
    >>> watch.calls["vision"], len(watch.samples["vision"]), watch.seconds["vision"] >= 0
    (1, 1, True)
    >>> with UNTIMED.measure("vision"):
    ...     pass
"""

from __future__ import annotations

import functools
import time
from collections import defaultdict
from contextlib import contextmanager, nullcontext
from typing import Any, Callable, ContextManager, Iterable, Iterator, Protocol

__all__ = ["Timing", "Stopwatch", "Untimed", "UNTIMED", "timed"]


class Timing(Protocol):
    """What a run's parts report their work to (:class:`Stopwatch`, :class:`Untimed`)."""

    def measure(self, category: str, keep: bool = False) -> ContextManager[Any]:
        """A block whose wall-clock time counts for ``category`` (``keep``: also keep
        each duration in ``samples``)."""


class Stopwatch:
    """Wall-clock seconds, calls and (where asked) each duration, per category.

    Args:
        categories: categories to show even when nothing reported to them (0 s, 0 calls).

    Attributes:
        seconds: ``{category: seconds}``.
        calls: ``{category: measured blocks}`` (outermost ones).
        samples: ``{category: [seconds, ...]}`` of the blocks measured with ``keep``.
    """

    def __init__(self, categories: Iterable[str] = ()) -> None:
        self.seconds: dict[str, float] = defaultdict(float)
        self.calls: dict[str, int] = defaultdict(int)
        self.samples: dict[str, list[float]] = defaultdict(list)
        self._depth: dict[str, int] = defaultdict(int)
        for category in categories:
            self.seconds[category], self.calls[category], self.samples[category] = 0.0, 0, []

    @contextmanager
    def measure(self, category: str, keep: bool = False) -> Iterator[None]:
        """Count the block's wall-clock time for ``category`` (once when nested)."""
        if self._depth[category]:
            yield
            return
        self._depth[category] += 1
        began = time.perf_counter()
        try:
            yield
        finally:
            took = time.perf_counter() - began
            self._depth[category] -= 1
            self.seconds[category] += took
            self.calls[category] += 1
            if keep:
                self.samples[category].append(took)


class Untimed:
    """A stopwatch that measures nothing (a run without one)."""

    def measure(self, category: str, keep: bool = False) -> ContextManager[None]:
        """A block measured by nobody."""
        return nullcontext()


#: The stopwatch of a run nobody times (stateless).
UNTIMED = Untimed()


def timed(category: str, keep: bool = False) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Declare that an action's method ``f(self, ctx, ...)`` is work of ``category``:
    each call is measured by the run's stopwatch (``ctx.stopwatch``).

    Examples:
        >>> class Context:
        ...     stopwatch = Stopwatch()
        >>> class Gait:
        ...     @timed("control")
        ...     def poll(self, ctx):
        ...         return "running"
        >>> ctx = Context()
        >>> Gait().poll(ctx), ctx.stopwatch.calls["control"]
        ('running', 1)
    """

    def decorate(method: Callable[..., Any]) -> Callable[..., Any]:
        @functools.wraps(method)
        def measured(self: Any, ctx: Any, *args: Any, **kwargs: Any) -> Any:
            with ctx.stopwatch.measure(category, keep):
                return method(self, ctx, *args, **kwargs)

        return measured

    return decorate
