"""A run's events and who listens to them.

Every event of a run gets the next sequence number whether or not anyone listens, so
a run with a trace and one without make the same numbers; an event object is built
only when an observer is subscribed (:attr:`Recorder.active`), so a run nobody
watches pays one counter increment per event.

Examples:
    >>> from petriflow.runtime.kernel import Kernel
    >>> recorder = Recorder(Kernel(dt=0.5))
    >>> recorder.emit("custom")  # nobody listens: only the count moves
    >>> seen = []; recorder.on_event(seen.append)
    >>> recorder.emit("custom", "t", None, name="x")
    >>> [(e.seq, e.kind, e.transition) for e in seen], recorder.count
    ([(1, 'custom', 't')], 2)
"""

from __future__ import annotations

from typing import Any, Callable

from petriflow.runtime.kernel import Kernel
from petriflow.runtime.trace import Event

__all__ = ["Recorder", "EventHandler"]

EventHandler = Callable[[Event], None]


class Recorder:
    """Numbers a run's events and hands them to its observers, in order.

    Args:
        kernel: the run's kernel (events are stamped with its time).
    """

    def __init__(self, kernel: Kernel) -> None:
        self.kernel = kernel
        self.handlers: list[EventHandler] = []
        self.count = 0

    @property
    def active(self) -> bool:
        """Whether anyone listens (event data need only be built then)."""
        return bool(self.handlers)

    def on_event(self, handler: EventHandler) -> None:
        """Call ``handler(event)`` for every event from now on, in order."""
        self.handlers.append(handler)

    def skip(self) -> None:
        """An event nobody listens to: only its number is taken."""
        self.count += 1

    def emit(self, kind: str, transition: str | None = None, agent: str | None = None, **data: Any) -> None:
        """Record an event."""
        seq = self.count
        self.count = seq + 1
        if self.handlers:
            kernel = self.kernel
            event = Event(seq, round(kernel.tick * kernel.dt, 9), kind, transition, agent, data)
            for handler in self.handlers:
                handler(event)
