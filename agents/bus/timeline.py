"""A simulated clock for the bus models: callbacks run at simulated times, in order.

The bus media, the modules' control loops and the experiment all share one
:class:`Timeline`. It follows SimPy's shape in miniature: :meth:`Timeline.at` and
:meth:`Timeline.after` schedule a callback, :meth:`Timeline.peek` tells when the next one
is due, :meth:`Timeline.step` runs it and :meth:`Timeline.run` runs up to a time.

Ordering: callbacks run by time, then by ``rank`` (lower first), then in the order they
were scheduled, so equal-time events are deterministic. The media use ranks so that at
one instant the bus settles (a frame ends, a frame reaches a buffer) before a module
acts on it (reads its buffer, senses the bus): :data:`MEDIUM` < :data:`MODULE`.

Scheduled callbacks are plain callables with their arguments (bound methods in
practice), never closures over mutable state, so a timeline and everything on it can
be copied with :func:`copy.deepcopy` (the channel adaptors of
:mod:`~petriflow.agents.bus.medium` rely on that to look ahead).

Examples:
    >>> timeline = Timeline()
    >>> seen = []
    >>> _ = timeline.at(2.0, seen.append, "b")
    >>> _ = timeline.at(1.0, seen.append, "a")
    >>> late = timeline.at(3.0, seen.append, "never")
    >>> late.cancel()
    >>> timeline.run(until=5.0)
    >>> seen, timeline.now
    (['a', 'b'], 5.0)
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable
from typing import Any

__all__ = ["MEDIUM", "MODULE", "Timeline", "Timer"]

#: Rank of the media's own events (frame ends, arrivals): they run first at an instant.
MEDIUM = 0
#: Rank of the modules' events (control steps, interrupts): they see the settled bus.
MODULE = 1


class Timer:
    """A scheduled callback; :meth:`cancel` stops it from running.

    Attributes:
        time: when it runs (simulated seconds).
        cancelled: whether :meth:`cancel` was called.
    """

    __slots__ = ("args", "callback", "cancelled", "time")

    def __init__(self, time: float, callback: Callable[..., Any], args: tuple[Any, ...]) -> None:
        self.time = time
        self.callback = callback
        self.args = args
        self.cancelled = False

    def cancel(self) -> None:
        """Do not run this callback (a no-op once it has run)."""
        self.cancelled = True

    def __repr__(self) -> str:
        name = getattr(self.callback, "__name__", repr(self.callback))
        return f"Timer({self.time!r}, {name}{', cancelled' if self.cancelled else ''})"


class Timeline:
    """Simulated time and a heap of :class:`Timer` objects.

    Args:
        start: the initial time in seconds.
    """

    def __init__(self, start: float = 0.0) -> None:
        self.now = float(start)
        self._heap: list[tuple[float, int, int, Timer]] = []
        self._count = 0

    def at(self, time: float, callback: Callable[..., Any], *args: Any, rank: int = MODULE) -> Timer:
        """Run ``callback(*args)`` at ``time`` (not before now).

        Raises:
            ValueError: ``time`` is in the past or not finite.
        """
        if not math.isfinite(time) or time < self.now:
            raise ValueError(f"cannot schedule at {time!r}: now is {self.now!r}")
        timer = Timer(float(time), callback, args)
        heapq.heappush(self._heap, (timer.time, rank, self._count, timer))
        self._count += 1
        return timer

    def after(self, delay: float, callback: Callable[..., Any], *args: Any, rank: int = MODULE) -> Timer:
        """Run ``callback(*args)`` ``delay`` seconds from now."""
        return self.at(self.now + delay, callback, *args, rank=rank)

    def peek(self) -> float:
        """Time of the next callback that will run (``inf`` when none is left)."""
        heap = self._heap
        while heap and heap[0][3].cancelled:
            heapq.heappop(heap)
        return heap[0][0] if heap else math.inf

    def step(self) -> bool:
        """Run the next callback; ``False`` when none is left."""
        if self.peek() == math.inf:
            return False
        time, _, _, timer = heapq.heappop(self._heap)
        self.now = time
        timer.callback(*timer.args)
        return True

    def run(self, until: float | None = None, stop: Callable[[], bool] | None = None) -> None:
        """Run callbacks in order up to and including time ``until`` (then set the clock
        to ``until``), or until none is left, or until ``stop()`` is true after a step.
        """
        limit = math.inf if until is None else until
        while (next_time := self.peek()) <= limit and next_time < math.inf:
            self.step()
            if stop is not None and stop():
                return
        if until is not None and until > self.now:
            self.now = float(until)
