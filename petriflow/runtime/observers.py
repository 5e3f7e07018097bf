"""A run watched: trace file, XES log, journal and progress line as observers.

Observers subscribe to the scheduler's events (:meth:`Scheduler.on_event
<petriflow.runtime.scheduler.Scheduler.on_event>`) or instants; none of them keeps
events in memory, so a run's memory does not grow with its length unless it is asked
to keep the event list. :func:`run_observed` runs a scheduler with the observers a
command asked for and returns the :class:`~petriflow.runtime.result.RunResult`, with
what it wrote: the trace and XES files are moved into place when the run ends, and
dropped when it raises.

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> from petriflow.runtime.scheduler import Scheduler
    >>> nap = "{petriflow: 1, places: [{id: i, tokens: 1}, o], transitions: [{id: nap, action: core.wait, in: [i], out: [o]}]}"
    >>> result = run_observed(Scheduler(loads_net(nap)), keep_events=True)
    >>> result.time, [e.kind for e in result.events], result.written
    (1.0, ['run', 'start', 'end', 'stop'], [])
"""

from __future__ import annotations

import sys
import time as wallclock
from pathlib import Path
from typing import Any, TextIO

from petriflow.runtime.journal import Journal
from petriflow.runtime.result import RunResult
from petriflow.runtime.scheduler import Scheduler
from petriflow.runtime.trace import Event, TraceWriter, XesWriter

__all__ = ["Progress", "observe", "run_observed"]

#: Events after which the journal commits: each firing's start and end.
COMMIT_KINDS = frozenset({"run", "start", "end", "stop"})


class Progress:
    """Progress of a run on standard error: a live line on a terminal, or, off a
    terminal (a log, CI), a line every ``interval`` wall seconds, so a long run is never
    silent. Simulated time, firings and agents alive.

    Args:
        scheduler: the run.
        stream: where to write (default: standard error).
        delay: on a terminal, seconds before the line first appears.
        interval: off a terminal, seconds between lines (``None``: nothing off a terminal).
    """

    def __init__(self, scheduler: Scheduler, stream: TextIO | None = None, delay: float = 1.0,
                 interval: float | None = 30.0) -> None:
        self.scheduler = scheduler
        self.stream = stream = sys.stderr if stream is None else stream  # the one at the run's start
        self.delay = delay
        self.start = wallclock.perf_counter()
        self.last = 0.0
        self.shown = False
        self.terminal = hasattr(stream, "isatty") and stream.isatty()
        self.interval = interval
        self.active = self.terminal or interval is not None

    def _text(self, time: float) -> str:
        alive = sum(self.scheduler.alive.values())
        total = len(self.scheduler.alive)
        agents = f"  agents alive {alive}/{total}" if total else ""
        return f"t = {time:9.2f} s  firings {self.scheduler.firings:7d}{agents}"

    def __call__(self, scheduler: Scheduler) -> None:
        """After an instant (``Scheduler.on_instant``): no event needs building for it."""
        if not self.active:
            return
        now = wallclock.perf_counter()
        if self.terminal:
            if now - self.start < self.delay or now - self.last < 0.2:
                return
            self.last = now
            self.stream.write(f"\r  {self._text(scheduler.now)}   ")
            self.stream.flush()
            self.shown = True
        elif now - max(self.last, self.start) >= self.interval:
            self.last = now
            self.stream.write(f"{self.scheduler.net.id}: {self._text(scheduler.now)}"
                              f"  ({now - self.start:.0f} s wall)\n")
            self.stream.flush()

    def close(self) -> None:
        if self.shown:
            self.stream.write("\n")
            self.stream.flush()


def observe(scheduler: Scheduler, *, journal: Journal | None = None, trace: Path | None = None,
            xes: Path | None = None, progress: bool | float = False, keep_events: bool = False,
            kinds: list[str] | None = None) -> dict[str, Any]:
    """Subscribe the requested observers to ``scheduler`` (the events kept: of ``kinds``,
    or all); returns them by name (``events``, ``trace``, ``xes``, ``progress``)."""
    observers: dict[str, Any] = {}
    net = scheduler.net
    if keep_events:
        observers["events"] = events = []
        scheduler.on_event(events.append, kinds)
    if journal is not None:
        def journal_event(event: Event) -> None:
            journal.record(event)
            if event.kind in COMMIT_KINDS:
                journal.commit()

        scheduler.on_event(journal_event)
    if trace is not None:
        observers["trace"] = TraceWriter(trace)
        scheduler.on_event(observers["trace"])
    if xes is not None:
        labels = {t.id: t.label or t.id for t in net.transitions.values()}
        silent = [t.id for t in net.transitions.values() if t.silent]
        observers["xes"] = XesWriter(xes, case=net.id, labels=labels, silent=silent)
        scheduler.on_event(observers["xes"])
    if progress:
        display = Progress(scheduler, interval=None if progress is True else float(progress))
        if display.active:  # watches instants: no event is built for it
            observers["progress"] = display
            scheduler.on_instant(display)
    return observers


def run_observed(scheduler: Scheduler, *, journal: Journal | None = None, trace: Path | None = None,
                 xes: Path | None = None, progress: bool | float = False, keep_events: bool = False,
                 kinds: list[str] | None = None, until: float | None = None,
                 max_firings: int | None = None) -> RunResult:
    """Run ``scheduler`` with the requested observers (see :func:`observe`) up to the
    limits; the result holds the kept events, the wall-clock time and the files written."""
    observers: dict[str, Any] = {}
    try:
        observers = observe(scheduler, journal=journal, trace=trace, xes=xes, progress=progress,
                            keep_events=keep_events, kinds=kinds)
        started = wallclock.perf_counter()
        with scheduler:
            result = scheduler.run(until, max_firings=max_firings)
        wall = wallclock.perf_counter() - started
    except BaseException:
        for name in ("trace", "xes"):
            if name in observers:
                observers[name].close(keep=False)
        raise
    finally:
        if "progress" in observers:
            observers["progress"].close()
    result.events = observers.get("events", [])
    result.wall = wall
    for name, path in (("trace", trace), ("xes", xes)):
        if name in observers:
            observers[name].close()
            result.written.append(str(path))
    return result
