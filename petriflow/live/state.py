r"""What a live page shows of a run, kept up to date from samples and a few events.

A run at full speed makes tens of thousands of events a second; building each one for
a page that shows 20 updates a second would cost the run a third more CPU. So
:class:`LiveState` takes :class:`Sample`\ s of the run's state instead (the token
counts, the firings running, the time: taken by the run's thread at most 20 times a
second of wall time, and whenever the run stops to wait), and only the rare events
(``run``, ``control``, ``stop``), which it applies with the rule of
:func:`petriflow.runtime.replay.markings`. The firings that started or ended between
two samples appear in the window of latest lines as ``fired`` and ``ended``; one that
did both between two samples is in the trace only. It keeps the current state and a
bounded window of lines, so it costs the same memory after an hour as after a minute.
A page that connects gets its :meth:`~LiveState.snapshot`; then batches of what
changed (:meth:`~LiveState.batch`).

Examples:
    >>> from petriflow.runtime.trace import Event
    >>> state = LiveState(window=5)
    >>> state.apply(Event(0, 0.0, "run", None, None, {"marking": {"i": 1}, "net": "n"}))
    >>> state.take(Sample(0.5, {"i": 0}, ({"t": "t", "agent": None, "firing": 1, "since": 0.0},)))
    >>> state.snapshot()["marking"], [f["t"] for f in state.snapshot()["running"]]
    ({}, ['t'])
    >>> state.take(Sample(1.5, {"o": 1}, ()))
    >>> batch = state.batch()
    >>> batch["marking"], batch["time"], [e["kind"] for e in batch["events"]]
    ({'i': 0, 'o': 1}, 1.5, ['run', 'fired', 'ended'])
"""

from __future__ import annotations

import json
from collections import deque
from dataclasses import dataclass
from typing import Any

from petriflow.runtime.trace import Event

__all__ = ["LiveState", "Sample", "WINDOW"]


@dataclass(frozen=True)
class Sample:
    """The run's state at one moment, taken by its own thread.

    Attributes:
        time: simulated time.
        changed: ``{place: count}`` of the places whose count changed since the last sample.
        running: the firings running, ``{"t", "agent", "firing", "since"}`` each.
    """

    time: float
    changed: dict[str, int]
    running: tuple[dict[str, Any], ...]

#: Events a page is sent on connecting and keeps at most (the rest is in the trace).
WINDOW = 400


class LiveState:
    """A run's current state, as a page shows it (see the module).

    Args:
        window: the most recent events kept.
    """

    def __init__(self, window: int = WINDOW) -> None:
        self.window = window
        self.run: dict[str, Any] = {}
        self.counts: dict[str, int] = {}
        self.running: dict[int, dict[str, Any]] = {}
        self.failures: deque[dict[str, Any]] = deque(maxlen=64)
        self.recent: deque[dict[str, Any]] = deque(maxlen=window)
        self.time = 0.0
        self.seq = -1
        self.stop: dict[str, Any] | None = None
        self.control: dict[str, Any] = {}
        self._changed: set[str] = set()
        self._new: list[dict[str, Any]] = []

    def apply(self, event: Event) -> None:
        """Take one event in (in order)."""
        data, counts, changed = event.data, self.counts, self._changed
        kind = event.kind
        if kind == "run":
            self.run = {k: data.get(k) for k in ("net", "seed", "dt", "agents", "labels") if k in data}
            counts.clear()
            counts.update(data.get("marking", {}))
            changed.update(counts)
        elif kind == "start":
            for place, n in data.get("consumed", {}).items():
                counts[place] = counts.get(place, 0) - n
                changed.add(place)
            self.running[data.get("firing")] = {"t": event.transition, "agent": event.agent,
                                                "firing": data.get("firing"), "since": event.time}
        elif kind == "end":
            for place, n in data.get("produced", {}).items():
                counts[place] = counts.get(place, 0) + n
                changed.add(place)
            self.running.pop(data.get("firing"), None)
            if data.get("outcome") != "ok":
                self.failures.append({"t": event.transition, "outcome": data.get("outcome"),
                                      "reason": data.get("reason"), "time": event.time})
        elif kind == "cancel":
            for place in data.get("withdrawn", {}):
                counts[place] = 0
                changed.add(place)
        elif kind == "message" and data.get("fate") in ("delivered", "noticed"):
            place = data.get("place")
            counts[place] = counts.get(place, 0) + 1
            changed.add(place)
        elif kind == "control":
            for place, n in (data.get("added") or {}).items():
                counts[place] = counts.get(place, 0) + n
                changed.add(place)
            for place, n in (data.get("removed") or {}).items():
                counts[place] = counts.get(place, 0) - n
                changed.add(place)
        elif kind == "stop":
            self.stop = dict(data)
            final = data.get("marking", {})
            for place in set(counts) | set(final):
                if counts.get(place, 0) != final.get(place, 0):
                    counts[place] = final.get(place, 0)
                    changed.add(place)
            self.running = {}
        self.time = max(self.time, event.time)
        self.seq = event.seq
        if kind == "pose":  # the world panel is not live: poses are left out of the window
            return
        self._line(json.loads(event.to_json()))

    def take(self, sample: Sample) -> None:
        """Take in a sample of the run's state."""
        self.counts.update(sample.changed)
        self._changed.update(sample.changed)
        now = {f["firing"]: f for f in sample.running}
        lines = [{"seq": None, "time": sample.time, "kind": "ended", "transition": f["t"], "agent": f["agent"],
                  "data": {"firing": n}} for n, f in self.running.items() if n not in now]
        lines += [{"seq": None, "time": f["since"], "kind": "fired", "transition": f["t"], "agent": f["agent"],
                   "data": {"firing": n}} for n, f in now.items() if n not in self.running]
        self.running = now
        self.time = max(self.time, sample.time)
        for record in lines:
            self._line(record)

    def _line(self, record: dict[str, Any]) -> None:
        self.recent.append(record)
        self._new.append(record)
        if len(self._new) > self.window:  # nobody took them in time: the window is all a page keeps
            del self._new[: len(self._new) - self.window]

    def snapshot(self) -> dict[str, Any]:
        """Everything a page needs on connecting: the run, the marking, the firings
        running, the recent failures and events, the controls, the end if it came
        (take the pending :meth:`batch` first: the snapshot includes it)."""
        return {"type": "snapshot", "run": self.run, "time": self.time, "seq": self.seq,
                "marking": {p: n for p, n in self.counts.items() if n}, "running": list(self.running.values()),
                "failures": list(self.failures), "events": list(self.recent), "control": self.control,
                "stop": self.stop, "window": self.window}

    def batch(self) -> dict[str, Any] | None:
        """What changed since the last batch (or snapshot); ``None`` if nothing did."""
        if not self._new and not self._changed:
            return None
        out = {"type": "events", "time": self.time, "seq": self.seq, "events": self._new,
               "marking": {p: self.counts.get(p, 0) for p in sorted(self._changed)},
               "running": list(self.running.values()), "failures": list(self.failures)[-8:],
               "stop": self.stop}
        self._new = []
        self._changed = set()
        return out
