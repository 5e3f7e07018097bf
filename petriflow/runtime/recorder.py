"""A run's events and who listens to them.

Every event of a run gets the next sequence number whether or not anyone listens, so
a run with a trace and one without make the same numbers; an event object is built
only when an observer is subscribed to its kind (:meth:`Recorder.wants`), so a run
nobody watches pays one counter increment per event, and one whose metrics read only
custom events builds no event for the firings.

Examples:
    >>> from petriflow.runtime.kernel import Kernel
    >>> recorder = Recorder(Kernel(dt=0.5))
    >>> recorder.emit("custom")  # nobody listens: only the count moves
    >>> seen = []; recorder.on_event(seen.append)
    >>> recorder.emit("custom", "t", None, name="x")
    >>> [(e.seq, e.kind, e.transition) for e in seen], recorder.count
    ([(1, 'custom', 't')], 2)
    >>> starts = []; recorder.on_event(starts.append, kinds=["start"])
    >>> recorder.emit("start", "t", None); recorder.emit("custom", "t", None, name="y")
    >>> [e.seq for e in starts], [e.seq for e in seen], recorder.wants("end")
    ([2], [1, 2, 3], True)
"""

from __future__ import annotations

from typing import Any, Callable, Iterable

from petriflow.runtime.kernel import Kernel
from petriflow.runtime.trace import Event, EventKind

__all__ = ["Recorder", "EventHandler"]

EventHandler = Callable[[Event], None]


class Recorder:
    """Numbers a run's events and hands them to its observers, in order.

    Args:
        kernel: the run's kernel (events are stamped with its time).
    """

    def __init__(self, kernel: Kernel) -> None:
        self.kernel = kernel
        self._every: list[EventHandler] = []  # the handlers of every kind
        #: ``{kind: [handler, ...]}``: who receives an event of each kind (a kind not in it
        #: goes to the handlers of every kind).
        self.by_kind: dict[str, list[EventHandler]] = {kind.value: [] for kind in EventKind}
        self.count = 0

    @property
    def active(self) -> bool:
        """Whether anyone listens (event data need only be built then)."""
        return any(self.by_kind.values())

    def wants(self, kind: str) -> bool:
        """Whether anyone listens to events of ``kind``."""
        return bool(self.by_kind.get(kind, self._every))

    def on_event(self, handler: EventHandler, kinds: Iterable[str] | None = None) -> None:
        """Call ``handler(event)`` for every event from now on, in order; only for the
        events of ``kinds`` (:class:`~petriflow.runtime.trace.EventKind` values) when
        given."""
        if kinds is None:
            self._every.append(handler)
            for handlers in self.by_kind.values():
                handlers.append(handler)
            return
        for kind in kinds:
            if kind not in self.by_kind:
                raise ValueError(f"no event kind {kind!r} (kinds: {', '.join(self.by_kind)})")
            self.by_kind[kind].append(handler)

    def skip(self) -> None:
        """An event nobody listens to: only its number is taken."""
        self.count += 1

    def emit(self, kind: str, transition: str | None = None, agent: str | None = None, **data: Any) -> None:
        """Record an event."""
        seq = self.count
        self.count = seq + 1
        handlers = self.by_kind.get(kind, self._every)
        if handlers:
            kernel = self.kernel
            event = Event(seq, round(kernel.tick * kernel.dt, 9), kind, transition, agent, data)
            for handler in handlers:
                handler(event)
