"""Run events and their files: JSON Lines traces and XES event logs.

Every firing, action start and end, message, fault and cancellation of a run is an
:class:`Event` stamped with simulated time and a sequence number. Observers (a trace
file, the journal, a progress display) subscribe to the scheduler; none of them is
imported by it.

Token data can be large (camera frames) or not JSON at all; events carry
:func:`summarize`\\ d data instead: plain JSON kept as it is, anything else replaced by
a short description with a content digest, so traces stay small and still compare
bit for bit between runs.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Iterable, Iterator
from xml.sax.saxutils import quoteattr

from petriflow.errors import NetFormatError

__all__ = ["Event", "summarize", "TraceWriter", "read_trace", "write_xes", "EVENT_KINDS"]

#: The kinds of events a run records.
EVENT_KINDS = ("run", "start", "end", "message", "fault", "cancel", "custom", "stop")


@dataclass(frozen=True)
class Event:
    """One thing that happened in a run.

    Attributes:
        seq: 0-based position in the run.
        time: simulated seconds since the run started.
        kind: one of :data:`EVENT_KINDS`.
        transition: the transition concerned, if any.
        agent: the agent concerned, if any.
        data: JSON-able details (outcome, consumed/produced tokens, message fate...).
    """

    seq: int
    time: float
    kind: str
    transition: str | None = None
    agent: str | None = None
    data: dict[str, Any] = field(default_factory=dict)

    def to_json(self) -> str:
        """One line of JSON, keys in a fixed order (so equal events give equal lines)."""
        return json.dumps(asdict(self), sort_keys=True, separators=(",", ":"), allow_nan=False)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> "Event":
        return cls(data["seq"], data["time"], data["kind"], data.get("transition"),
                   data.get("agent"), data.get("data") or {})


def summarize(value: Any, *, depth: int = 0) -> Any:
    """A JSON-able, deterministic stand-in for token data.

    Examples:
        >>> summarize({"pose": (1.0, 2.0)})
        {'pose': [1.0, 2.0]}
        >>> summarize(float("nan"))
        'nan'
    """
    if value is None or isinstance(value, (bool, int, str)):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else str(value)
    if depth > 6:
        return f"<{type(value).__name__}>"
    if isinstance(value, dict):
        return {str(k): summarize(v, depth=depth + 1) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        if len(value) > 64:
            return _digest(value)
        return [summarize(v, depth=depth + 1) for v in value]
    try:  # numpy scalars and arrays without importing numpy here
        if hasattr(value, "shape") and hasattr(value, "tobytes"):
            if getattr(value, "ndim", 1) == 0:
                return summarize(value.item())
            if value.size <= 16:
                return summarize(value.tolist(), depth=depth + 1)
            shape = "x".join(str(s) for s in value.shape)
            sha = hashlib.sha1(value.tobytes()).hexdigest()[:12]
            return f"<array {shape} {value.dtype} sha1={sha}>"
    except Exception:  # pragma: no cover - exotic array-likes
        pass
    if hasattr(value, "to_token"):
        return summarize(value.to_token(), depth=depth + 1)
    return _digest(value)


def _digest(value: Any) -> str:
    text = repr(value).encode("utf-8", "replace")
    return f"<{type(value).__name__} sha1={hashlib.sha1(text).hexdigest()[:12]}>"


class TraceWriter:
    """Writes events to a JSON Lines file as they happen (flushing each line).

    The file is first written as ``NAME.partial`` and renamed when the run closes, so
    an existing trace of the same name is never half-overwritten by a failed run.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self._partial = self.path.with_name(self.path.name + ".partial")
        self._file = self._partial.open("w", encoding="utf-8")

    def __call__(self, event: Event) -> None:
        self._file.write(event.to_json() + "\n")
        self._file.flush()

    def close(self, keep: bool = True) -> None:
        """Finish the file (rename into place), or drop it when ``keep`` is false."""
        self._file.close()
        if keep:
            self._partial.replace(self.path)
        else:
            self._partial.unlink(missing_ok=True)


def read_trace(path: str | Path) -> list[Event]:
    """Read a JSON Lines trace written by :class:`TraceWriter`.

    Raises:
        NetFormatError: a line is not an event (naming the file and line).
    """
    events = []
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise NetFormatError(f"cannot read trace: {exc}", path=str(path)) from None
    for number, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        try:
            events.append(Event.from_dict(json.loads(line)))
        except (json.JSONDecodeError, KeyError, TypeError) as exc:
            raise NetFormatError(f"not a trace event: {exc}", path=str(path), line=number) from None
    return events


def _completed(events: Iterable[Event]) -> Iterator[tuple[Event, Event]]:
    """Pairs (start, end) of firings that completed, in start order."""
    starts: dict[int, Event] = {}
    pairs = []
    for event in events:
        if event.kind == "start":
            starts[event.data["firing"]] = event
        elif event.kind == "end" and event.data.get("outcome") != "cancelled":
            start = starts.get(event.data["firing"])
            if start is not None:
                pairs.append((start, event))
    pairs.sort(key=lambda pair: pair[0].seq)
    return iter(pairs)


def write_xes(events: Iterable[Event], path: str | Path, *, case: str = "run",
              labels: dict[str, str] | None = None, silent: Iterable[str] = ()) -> int:
    """Write the completed firings of a run as an XES event log with one trace.

    Events are ordered by the time their transition fired (started), which is a
    firing sequence of the net with atomic transitions. Each event's ``concept:name``
    is the transition's label (or, for a non-ok outcome, the label of its outcome
    variant ``label@outcome``); silent transitions are left out, as process mining
    expects.

    Returns:
        The number of events written.
    """
    from petriflow.io.files import write_atomic

    labels = labels or {}
    silent = set(silent)
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        '<log xes.version="1.0" xes.features="nested-attributes" xmlns="http://www.xes-standard.org/">',
        '  <extension name="Concept" prefix="concept" uri="http://www.xes-standard.org/concept.xesext"/>',
        '  <extension name="Time" prefix="time" uri="http://www.xes-standard.org/time.xesext"/>',
        '  <extension name="Lifecycle" prefix="lifecycle" uri="http://www.xes-standard.org/lifecycle.xesext"/>',
        '  <extension name="Organizational" prefix="org" uri="http://www.xes-standard.org/org.xesext"/>',
        f'  <trace>\n    <string key="concept:name" value={quoteattr(case)}/>',
    ]
    count = 0
    for start, end in _completed(events):
        transition = start.transition or ""
        if transition in silent:
            continue
        name = labels.get(transition, transition)
        outcome = end.data.get("outcome", "ok")
        if outcome != "ok":
            name = f"{name}@{outcome}"
        stamp = _timestamp(start.time)
        lines.append("    <event>")
        lines.append(f'      <string key="concept:name" value={quoteattr(name)}/>')
        lines.append('      <string key="lifecycle:transition" value="complete"/>')
        lines.append(f'      <date key="time:timestamp" value="{stamp}"/>')
        lines.append(f'      <float key="petriflow:end" value="{end.time!r}"/>')
        if start.agent:
            lines.append(f'      <string key="org:resource" value={quoteattr(start.agent)}/>')
        lines.append("    </event>")
        count += 1
    lines.append("  </trace>\n</log>\n")
    write_atomic(path, "\n".join(lines))
    return count


def _timestamp(seconds: float) -> str:
    """Simulated seconds as an ISO timestamp counted from 2000-01-01T00:00:00Z."""
    from datetime import datetime, timedelta, timezone

    moment = datetime(2000, 1, 1, tzinfo=timezone.utc) + timedelta(seconds=seconds)
    return moment.isoformat(timespec="milliseconds")

