"""A run's events and who listens to them.

Every event of a run gets the next sequence number whether or not anyone listens, so
a run with a trace and one without make the same numbers; an event object is built
only when an observer is subscribed to its kind (:meth:`Recorder.wants`), so a run
nobody watches pays one counter increment per event, and one whose metrics read only
custom events builds no event for the firings.

An observer may also narrow what it hears to what it is about
(``on_event(handler, kinds, transitions=..., places=..., fields=...)``): an event
naming a transition (a firing's start or end, a cancellation, a custom event) reaches
it only when that transition is one of ``transitions``; an event with a data field
named in ``fields`` only when its value there is one of those given (``places`` is
``fields={"place": places}``: a ``message`` event's place); an event naming none of
them reaches it always. An event that reaches no one is not built (:meth:`Recorder.wants`
answers for a transition and field values), so a property monitor reading a few places
costs nothing on the firings and messages that touch none of them. Narrowed handlers
receive an event after the handlers of all its events.

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
    >>> narrowed = Recorder(Kernel(dt=0.5)); about = []
    >>> narrowed.on_event(about.append, kinds=["end", "message"], transitions={"t"}, places={"box"},
    ...                   fields={"fate": ["delivered"]})
    >>> narrowed.emit("end", "u", None); narrowed.emit("end", "t", None)
    >>> narrowed.emit("message", None, None, place="other", fate="delivered")
    >>> narrowed.emit("message", None, None, place="box", fate="sent")
    >>> narrowed.emit("message", None, None, place="box", fate="delivered")
    >>> [(e.seq, e.kind) for e in about], narrowed.wants("end", "u"), narrowed.wants("message", place="box")
    ([(1, 'end'), (4, 'message')], False, True)
    >>> narrowed.wants("message", place="box", fate="sent"), narrowed.wants("message", place="box", fate="delivered")
    (False, True)
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Callable, Iterable

from petriflow.runtime.kernel import Kernel
from petriflow.runtime.trace import Event, EventKind

__all__ = ["Recorder", "EventHandler"]

EventHandler = Callable[[Event], None]
#: A handler narrowed to transitions (``None``: any) and to values of data fields.
Narrowed = tuple[EventHandler, "frozenset[str] | None", "tuple[tuple[str, frozenset[Any]], ...]"]


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
        #: ``{kind: [(handler, transitions, ((field, values), ...)), ...]}``: the narrowed
        #: handlers (transitions ``None``: any).
        self.narrow: dict[str, list[Narrowed]] = {kind.value: [] for kind in EventKind}
        self.count = 0

    @property
    def active(self) -> bool:
        """Whether anyone listens (event data need only be built then)."""
        return any(self.by_kind.values()) or any(self.narrow.values())

    def wants(self, kind: str, transition: str | None = None, **fields: Any) -> bool:
        """Whether anyone listens to events of ``kind`` (about ``transition`` and with
        these ``fields`` values, when given: a narrowed handler about others does not count)."""
        if self.by_kind.get(kind, self._every):
            return True
        return any(_about(narrowed, transition, fields) for narrowed in self.narrow.get(kind, ()))

    def on_event(self, handler: EventHandler, kinds: Iterable[str] | None = None, *,
                 transitions: Iterable[str] | None = None, places: Iterable[str] | None = None,
                 fields: Mapping[str, Iterable[Any]] | None = None) -> None:
        """Call ``handler(event)`` for every event from now on, in order; only for the
        events of ``kinds`` (:class:`~petriflow.runtime.trace.EventKind` values) when
        given, and only for those about ``transitions``, ``places`` and ``fields`` when
        given (see the module documentation)."""
        values = dict(fields or {})
        if places is not None:
            values["place"] = places
        if transitions is not None or values:
            narrowed = (handler, None if transitions is None else frozenset(transitions),
                        tuple((name, frozenset(allowed)) for name, allowed in values.items()))
            for kind in self.by_kind if kinds is None else kinds:
                if kind not in self.by_kind:
                    raise ValueError(f"no event kind {kind!r} (kinds: {', '.join(self.by_kind)})")
                self.narrow[kind].append(narrowed)
            return
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
        narrow = self.narrow.get(kind)
        if narrow:
            narrow = [narrowed[0] for narrowed in narrow if _about(narrowed, transition, data)]
        if handlers or narrow:
            kernel = self.kernel
            event = Event(seq, round(kernel.tick * kernel.dt, 9), kind, transition, agent, data)
            for handler in handlers:
                handler(event)
            if narrow:
                for handler in narrow:
                    handler(event)


def _about(narrowed: Narrowed, transition: str | None, data: Mapping[str, Any]) -> bool:
    """Whether an event naming ``transition`` with ``data`` reaches a narrowed handler
    (a field the event does not have does not narrow it)."""
    _, transitions, values = narrowed
    if transition is not None and transitions is not None and transition not in transitions:
        return False
    for name, allowed in values:
        value = data.get(name)
        if value is not None and value not in allowed:
            return False
    return True
