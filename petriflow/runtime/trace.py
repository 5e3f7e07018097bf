"""Run events and their files: JSON Lines traces and XES event logs.

Every firing, action start and end, message, fault and cancellation of a run is an
:class:`Event` stamped with simulated time and a sequence number. Observers (a trace
file, an XES log, the journal, a progress display) subscribe to the scheduler; none
of them is imported by it, and none keeps the events in memory: a run of any length
holds only what is still in flight (an XES log keeps the firings not yet ended).

Token data can be large (camera frames) or not JSON at all; events carry
:func:`summarize`\\ d data instead: plain JSON kept as it is, anything else replaced by
what its ``to_token()`` returns or a short description, so traces stay small and
compare bit for bit between runs and processes.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable
from xml.sax.saxutils import quoteattr

from petriflow.errors import NetFormatError
from petriflow.io.files import PartialFile
from petriflow.outcome import Name, Outcome

__all__ = ["Event", "EventKind", "summarize", "TraceWriter", "XesWriter", "read_trace", "write_xes",
           "check_event", "EVENT_KINDS", "XES_EPOCH"]


class EventKind(Name):
    """What an :class:`Event` records."""

    RUN = "run"
    """The run starts: net, seed, ``dt``, initial marking, agents."""
    START = "start"
    """A transition fires: its input tokens are consumed and its action starts."""
    END = "end"
    """A firing's action ends with an outcome; its outputs are produced."""
    MESSAGE = "message"
    """A token put into a channel place is sent, delivered or lost."""
    FAULT = "fault"
    """An injected fault: an agent killed or joining, a link dropped or restored."""
    CANCEL = "cancel"
    """A cancellation region withdraws tokens and cancels running actions."""
    CUSTOM = "custom"
    """Something an action reported (``ctx.emit``)."""
    POSE = "pose"
    """Where the world's bodies are (optional sampling, :mod:`petriflow.runtime.poses`)."""
    STOP = "stop"
    """The run ends: why, firings, marking, what was still running."""
    CONTROL = "control"
    """Someone steered the run (:mod:`petriflow.runtime.control`): who, what, when, and
    the tokens it ``added`` or ``removed``; or a breakpoint triggered (``hit``)."""
    FEEDBACK = "feedback"
    """A remote agent reported progress on a running firing's goal (``firing``,
    ``goal``, the remote agent as ``remote_agent``, its ``data``): docs/bridge.md."""


#: The kinds of events a run records, as written in traces.
EVENT_KINDS = tuple(k.value for k in EventKind)

_ENCODER = json.JSONEncoder(sort_keys=True, separators=(",", ":"), allow_nan=False)


@dataclass(frozen=True, slots=True)
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
        return _ENCODER.encode({"agent": self.agent, "data": self.data, "kind": self.kind, "seq": self.seq,
                                "time": self.time, "transition": self.transition})

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> "Event":
        return cls(data["seq"], data["time"], data["kind"], data.get("transition"),
                   data.get("agent"), data.get("data") or {})


def summarize(value: Any, *, depth: int = 0) -> Any:
    """A JSON-able stand-in for token data that is the same in every process.

    Plain JSON is kept as it is (tuples become lists, non-finite floats text); sets are
    sorted; numpy values become lists, or a content digest when large; an object that
    offers ``to_token()`` is recorded as what that returns; any other object as its type
    name only. Nothing depends on memory addresses, ``id()`` or hash randomisation, so
    two runs of the same net, world and seed record the same bytes.

    Examples:
        >>> summarize({"pose": (1.0, 2.0), "seen": {"b", "a"}})
        {'pose': [1.0, 2.0], 'seen': ['a', 'b']}
        >>> summarize(float("nan"))
        'nan'
        >>> summarize(object())
        '<object>'
    """
    if value is None or isinstance(value, (bool, int, str)):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else str(value)
    if depth > 6:
        return f"<{type(value).__name__}>"
    if isinstance(value, dict):
        return {str(k): summarize(v, depth=depth + 1) for k, v in value.items()}
    if isinstance(value, (list, tuple, set, frozenset, deque)):
        items = [summarize(v, depth=depth + 1) for v in value]
        if isinstance(value, (set, frozenset)):
            items.sort(key=_canonical)
        if len(items) > 64:
            return f"<{type(value).__name__} {len(items)} sha1={_sha1(_canonical(items))}>"
        return items
    if hasattr(value, "shape") and hasattr(value, "tobytes"):  # numpy without importing it here
        try:
            if getattr(value, "ndim", 1) == 0:
                return summarize(value.item(), depth=depth + 1)
            if value.size <= 16 or getattr(getattr(value, "dtype", None), "kind", "") == "O":
                return summarize(value.tolist(), depth=depth + 1)
            shape = "x".join(str(s) for s in value.shape)
            return f"<array {shape} {value.dtype} sha1={_sha1(value.tobytes())}>"
        except Exception:  # pragma: no cover - exotic array-likes
            return f"<{type(value).__name__}>"
    to_token = getattr(value, "to_token", None)
    if callable(to_token) and not isinstance(value, type):
        return summarize(to_token(), depth=depth + 1)
    return f"<{type(value).__name__}>"


def _canonical(value: Any) -> str:
    """Summarized data as one canonical JSON text (for sorting and digests)."""
    return json.dumps(value, sort_keys=True, separators=(",", ":"), default=str)


def _sha1(data: str | bytes) -> str:
    if isinstance(data, str):
        data = data.encode("utf-8", "replace")
    return hashlib.sha1(data).hexdigest()[:12]


class TraceWriter:
    """Writes events to a JSON Lines file as they happen (an observer).

    The file is written under a unique temporary name in the target folder and
    renamed when the run closes, so an existing trace of the same name is never
    half-overwritten by a failed run, and two runs never share a temporary file.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self._out = PartialFile(path)
        self._write = self._out.file.write

    def __call__(self, event: Event) -> None:
        self._write(event.to_json() + "\n")

    def close(self, keep: bool = True) -> None:
        """Finish the file (rename into place), or drop it when ``keep`` is false."""
        self._out.finish(keep)


def _counts(value: Any) -> bool:
    return isinstance(value, dict) and all(isinstance(k, str) and type(v) is int and v >= 0
                                           for k, v in value.items())


#: What each kind of event must carry for replay, beside the common fields.
_NEEDS = {
    "run": {"marking": _counts},
    "start": {"firing": lambda v: type(v) is int, "consumed": _counts},
    "end": {"firing": lambda v: type(v) is int, "outcome": lambda v: isinstance(v, str) and v in {o.value for o in Outcome},
            "produced": _counts},
    "cancel": {"withdrawn": _counts},
    "message": {"place": lambda v: isinstance(v, str), "fate": lambda v: isinstance(v, str)},
    "pose": {"poses": lambda v: isinstance(v, dict)},
    "control": {"action": lambda v: isinstance(v, str), "point": lambda v: type(v) is int},
    "feedback": {"firing": lambda v: type(v) is int, "goal": lambda v: isinstance(v, str)},
}


def check_event(data: Any) -> Event:
    """An :class:`Event` from one decoded trace line, checked field by field.

    Raises:
        ValueError: saying which field is missing or of the wrong type.
    """
    if not isinstance(data, dict):
        raise ValueError("a trace line is a JSON object")
    for key, wanted, what in (("seq", int, "an integer"), ("time", (int, float), "a number"), ("kind", str, "text")):
        if not isinstance(data.get(key), wanted) or isinstance(data.get(key), bool):
            raise ValueError(f"'{key}' is missing or not {what}")
    if not math.isfinite(data["time"]):
        raise ValueError("'time' is not a finite number")
    if data["kind"] not in EVENT_KINDS:
        raise ValueError(f"unknown kind {data['kind']!r} (one of {', '.join(EVENT_KINDS)})")
    for key in ("transition", "agent"):
        if data.get(key) is not None and not isinstance(data[key], str):
            raise ValueError(f"'{key}' must be text or null")
    details = data.get("data") or {}
    if not isinstance(details, dict):
        raise ValueError("'data' must be an object")
    for key, good in _NEEDS.get(data["kind"], {}).items():
        if key not in details or not good(details[key]):
            raise ValueError(f"a {data['kind']} event's '{key}' is missing or malformed")
    return Event(data["seq"], data["time"], data["kind"], data.get("transition"), data.get("agent"), details)


def read_trace(path: str | Path) -> list[Event]:
    """Read a JSON Lines trace written by :class:`TraceWriter`.

    Raises:
        NetFormatError: the file is unreadable, or a line is not an event (naming the
            file, the line and what is wrong with it).
    """
    from petriflow.io.files import parse_json

    events = []
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise NetFormatError(f"cannot read trace: {getattr(exc, 'strerror', None) or exc}", path=str(path)) from None
    for number, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        try:
            events.append(check_event(parse_json(line)))
        except ValueError as exc:
            raise NetFormatError(f"not a trace event: {exc}", path=str(path), line=number) from None
    return events


_XES_HEAD = [
    '<?xml version="1.0" encoding="UTF-8"?>',
    '<log xes.version="1.0" xes.features="nested-attributes" xmlns="http://www.xes-standard.org/">',
    '  <extension name="Concept" prefix="concept" uri="http://www.xes-standard.org/concept.xesext"/>',
    '  <extension name="Time" prefix="time" uri="http://www.xes-standard.org/time.xesext"/>',
    '  <extension name="Lifecycle" prefix="lifecycle" uri="http://www.xes-standard.org/lifecycle.xesext"/>',
    '  <extension name="Organizational" prefix="org" uri="http://www.xes-standard.org/org.xesext"/>',
]


#: The moment simulated time 0 stands for in XES timestamps (events are stamped with
#: this epoch plus their simulated seconds).
XES_EPOCH = "2000-01-01T00:00:00.000+00:00"


class XesWriter:
    """Writes the completed firings of a run as an XES event log with one trace, as
    the run goes (an observer: ``scheduler.on_event(writer)``).

    One XES event per firing that ended (``lifecycle:transition`` ``complete``), in
    the order the firings ended, stamped with the time it ended (``time:timestamp``)
    and the time it started (``start_timestamp``, the attribute PM4Py reads for
    interval logs, so activity durations and waiting times come out right). Times are
    simulated seconds after :data:`XES_EPOCH` (the log says so in ``petriflow:epoch``).
    ``org:resource`` is the agent that ran the firing (the net's id for transitions
    outside any agent's subnet). Ordered by completion, the log is a firing sequence
    of the net with atomic transitions: a firing's inputs were produced by firings
    that ended before it started. ``concept:name`` is the transition's label (or, for
    a non-ok outcome, the label of its outcome variant ``label@outcome``); silent
    transitions and cancelled firings are left out, as process mining expects. Only
    the firings still running are held in memory; the file is written under a
    temporary name and renamed by :meth:`close`.

    Args:
        path: the ``.xes`` file.
        case: the trace's ``concept:name`` (and the resource of agent-less firings).
        labels: ``{transition: label}`` (default: the id).
        silent: transitions to leave out.
    """

    def __init__(self, path: str | Path, *, case: str = "run", labels: dict[str, str] | None = None,
                 silent: Iterable[str] = ()) -> None:
        self.path = Path(path)
        self.labels = labels or {}
        self.silent = set(silent)
        self.case = case
        self.count = 0
        self._out = PartialFile(path)
        self._file = self._out.file
        self._file.write("\n".join(_XES_HEAD) + "\n")
        self._file.write(f'  <date key="petriflow:epoch" value="{XES_EPOCH}"/>\n')
        self._file.write('  <string key="petriflow:clock" value="simulated seconds after petriflow:epoch"/>\n')
        self._file.write(f'  <trace>\n    <string key="concept:name" value={quoteattr(case)}/>\n')
        self._open: dict[int, Event] = {}  # firing -> its start event, while it runs

    def __call__(self, event: Event) -> None:
        kind = event.kind
        if kind == "start":
            self._open[event.data["firing"]] = event
        elif kind == "end":
            start = self._open.pop(event.data["firing"], None)
            if start is not None and event.data.get("outcome") != Outcome.CANCELLED:
                self._write(start, event)

    def _write(self, start: Event, end: Event) -> None:
        transition = start.transition or ""
        if transition in self.silent:
            return
        name = self.labels.get(transition, transition)
        outcome = end.data.get("outcome", Outcome.OK.value)
        if outcome != Outcome.OK:
            name = f"{name}@{outcome}"
        lines = ["    <event>",
                 f'      <string key="concept:name" value={quoteattr(name)}/>',
                 '      <string key="lifecycle:transition" value="complete"/>',
                 f'      <date key="time:timestamp" value="{_timestamp(end.time)}"/>',
                 f'      <date key="start_timestamp" value="{_timestamp(start.time)}"/>',
                 f'      <string key="org:resource" value={quoteattr(start.agent or self.case)}/>',
                 f'      <string key="petriflow:transition" value={quoteattr(transition)}/>',
                 "    </event>\n"]
        self._file.write("\n".join(lines))
        self.count += 1

    def close(self, keep: bool = True) -> int:
        """Finish the log (firings still running are left out) and rename it into place,
        or drop it when ``keep`` is false. Returns the number of events written."""
        self._open.clear()
        self._file.write("  </trace>\n</log>\n")
        self._out.finish(keep)
        return self.count


def write_xes(events: Iterable[Event], path: str | Path, *, case: str = "run",
              labels: dict[str, str] | None = None, silent: Iterable[str] = ()) -> int:
    """Write the completed firings of recorded ``events`` as an XES log (see :class:`XesWriter`).

    Returns:
        The number of events written.
    """
    writer = XesWriter(path, case=case, labels=labels, silent=silent)
    try:
        for event in events:
            writer(event)
    except BaseException:
        writer.close(keep=False)
        raise
    return writer.close()


def _timestamp(seconds: float) -> str:
    """Simulated seconds as an ISO timestamp counted from :data:`XES_EPOCH`.

    Examples:
        >>> _timestamp(0.0), _timestamp(61.25)
        ('2000-01-01T00:00:00.000+00:00', '2000-01-01T00:01:01.250+00:00')
    """
    from datetime import datetime, timedelta

    moment = datetime.fromisoformat(XES_EPOCH) + timedelta(seconds=seconds)
    return moment.isoformat(timespec="milliseconds")
