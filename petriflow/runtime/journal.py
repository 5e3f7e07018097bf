"""The run journal: an embedded SQLite database (WAL) committed once per firing.

The journal holds what is needed to resume a killed run: the run's inputs (net file
content, world and run configuration, seed, time limit) and every event, in order.
Events are buffered and committed together at each firing boundary, so a kill leaves
the journal at the last complete firing.

Resuming is deterministic re-execution checked against the journal: the scheduler
runs the same inputs again, compares each event it makes with the journaled one
(a mismatch is an error, never silently accepted) and only appends events past the
journal's end. The world resumes with it, since the world is rebuilt by the same
steps. The resumed trace is therefore the uninterrupted trace, event for event.
"""

from __future__ import annotations

import json
import math
import os
import sqlite3
from pathlib import Path
from typing import Any

try:  # POSIX: one writer per journal
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None

from petriflow.errors import PetriflowError
from petriflow.io.files import make_database, parse_json, remove_stale
from petriflow.runtime.trace import Event

__all__ = ["Journal", "JournalError", "ResumeMismatch"]

_SCHEMA = """
CREATE TABLE IF NOT EXISTS run (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS event (
    seq INTEGER PRIMARY KEY,
    line TEXT NOT NULL
);
"""


#: What a journal's run inputs hold, and the type of each.
_INPUTS = {"net_file": (str, "text"), "net_text": (str, "text"), "config": (dict, "an object"),
           "seed": (int, "an integer")}


def _check_inputs(inputs: Any) -> dict[str, Any]:
    """A journal's run inputs, checked (a damaged or foreign file fails here, not later)."""
    if not isinstance(inputs, dict):
        raise ValueError("the run inputs are not an object")
    for key, (kind, what) in _INPUTS.items():
        if not isinstance(inputs.get(key), kind) or isinstance(inputs.get(key), bool):
            raise ValueError(f"the run inputs' {key!r} is missing or not {what}")
    for key in ("until", "max_firings", "outputs"):
        if key not in inputs:
            raise ValueError(f"the run inputs' {key!r} is missing")
    for key in ("world_file", "world_base", "world_text"):
        if inputs.get(key) is not None and not isinstance(inputs[key], str):
            raise ValueError(f"the run inputs' {key!r} is not text")
    until = inputs.get("until")
    if until is not None and (isinstance(until, bool) or not isinstance(until, (int, float))
                              or not 0 <= until < math.inf):
        raise ValueError("the run inputs' 'until' is not a time")
    limit = inputs.get("max_firings")
    if limit is not None and (isinstance(limit, bool) or not isinstance(limit, int) or limit < 0):
        raise ValueError("the run inputs' 'max_firings' is not a firing count")
    outputs = inputs.get("outputs")
    if outputs is not None and (not isinstance(outputs, dict) or not set(outputs) <= {"trace", "xes"}
                                or not all(v is None or (isinstance(v, str) and v) for v in outputs.values())):
        raise ValueError("the run inputs' 'outputs' are not {trace: file, xes: file}")
    if inputs.get("world_text") is not None and not (inputs.get("world_file") and inputs.get("world_base")):
        raise ValueError("the run inputs hold a world without its file")
    return inputs


#: What reading a damaged database file raises: SQLite's errors, and ``ValueError``
#: (``UnicodeDecodeError``) when its bytes are not the text they should be.
_DAMAGE = (sqlite3.Error, ValueError)


class JournalError(PetriflowError):
    """The journal file cannot be used (not a journal, locked, finished...)."""


class ResumeMismatch(JournalError):
    """Re-execution made a different event than the journal holds."""


def _difference(journaled: str, event: Event) -> str:
    """What differs between a journaled event line and a re-executed event, in words.

    Examples:
        >>> old = Event(4, 1.0, "end", "t", None, {"outcome": "ok", "firing": 2}).to_json()
        >>> _difference(old, Event(4, 1.5, "end", "t", None, {"outcome": "failed", "firing": 2}))
        "end of t: data.outcome 'ok' in the journal, 'failed' now; time 1.0 in the journal, 1.5 now"
        >>> _difference(None, Event(4, 1.5, "end", "t", None, {}))
        'the journaled line is not an event'
    """
    try:
        before = json.loads(journaled)
    except (TypeError, ValueError):  # not text (a damaged row holds NULL or a number), or not JSON
        return "the journaled line is not an event"
    now = json.loads(event.to_json())
    found: list[str] = []

    def walk(a: Any, b: Any, where: str) -> None:
        if len(found) >= 3 or a == b:
            return
        if isinstance(a, dict) and isinstance(b, dict):
            for key in sorted(set(a) | set(b), key=lambda k: (k != "data", k)):
                walk(a.get(key), b.get(key), f"{where}.{key}" if where else key)
            return
        shown = [repr(v) if len(repr(v)) <= 80 else repr(v)[:77] + "..." for v in (a, b)]
        found.append(f"{where} {shown[0]} in the journal, {shown[1]} now")

    walk(before, now, "")
    what = f"{event.kind} of {event.transition}" if event.transition else event.kind
    return f"{what}: {'; '.join(found) or 'the same fields, written differently'}"


class Journal:
    """A run journal in a SQLite file.

    Args:
        path: the database file.
        inputs: for a new run, the run's inputs (JSON-able); for a resume, ``None``
            (they are read from the file).

    Attributes:
        inputs: the run's inputs.
        journaled: number of events already in the journal when opened.
    """

    def __init__(self, path: str | Path, inputs: dict[str, Any] | None = None) -> None:
        self.path = Path(path)
        resuming = inputs is None
        if resuming:
            self._open_existing()
        else:
            self._create(inputs)
        try:
            self._db = sqlite3.connect(str(self.path), isolation_level=None)
            self._db.execute("PRAGMA journal_mode=WAL")
            self._db.execute("PRAGMA synchronous=NORMAL")
            self._db.executescript(_SCHEMA)
        except _DAMAGE as exc:
            self._release()
            raise JournalError(f"{self.path}: not a petriflow journal ({exc})") from None
        self._pending: list[Event] = []
        if resuming:
            try:
                rows = dict(self._db.execute("SELECT key, value FROM run"))
                self.journaled = self._db.execute("SELECT count(*) FROM event").fetchone()[0]
                self.inputs = _check_inputs(parse_json(rows["inputs"])) if "inputs" in rows else None
            except (*_DAMAGE, TypeError) as exc:
                self.close()
                raise JournalError(f"{self.path}: not a petriflow journal, or a damaged one ({exc})") from None
            if self.inputs is None:
                self.close()
                raise JournalError(f"{self.path}: not a petriflow journal (no run inputs)")
            self.finished = rows.get("finished") == "1"
        else:
            self.inputs = inputs
            self.finished = False
            self.journaled = 0
        # Re-executed events are checked against the journal in chunks read on demand,
        # so neither a new run nor a resumed one holds the whole journal in memory.
        self._chunk: list[str] = []
        self._chunk_start = 0

    def _open_existing(self) -> None:
        """Open a journal to resume, holding its lock (one writer at a time)."""
        if not self.path.is_file():
            raise JournalError(f"{self.path}: no such journal")
        try:
            self._lock = os.open(self.path, os.O_RDWR)
        except OSError as exc:
            raise JournalError(f"{self.path}: cannot open: {exc.strerror or exc}") from None
        if fcntl is not None:
            try:
                fcntl.flock(self._lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                self._release()
                raise JournalError(f"{self.path}: in use by another run (one writer at a time)") from None
        remove_stale(self.path)  # a creation killed between putting the journal in place and tidying up

    def _create(self, inputs: dict[str, Any]) -> None:
        """Make a new journal whole or not at all: its schema and the run's inputs are
        written to a temporary file beside it, which is then linked into place only if no
        file of that name exists (two runs never share a new journal). A kill at any
        moment leaves either no journal or one that can be resumed; a killed creation's
        temporary file is removed by the next run that writes this journal."""
        if self.path.exists():
            raise JournalError(f"{self.path}: already exists; use --resume to continue it or pick a new file")
        try:
            self._lock = make_database(self.path, _SCHEMA, lambda db: db.execute(
                "INSERT INTO run VALUES ('inputs', ?)", (json.dumps(inputs, sort_keys=True),)))
        except FileExistsError:
            raise JournalError(f"{self.path}: already exists; use --resume to continue it or pick a new file") \
                from None
        except (OSError, sqlite3.Error) as exc:
            raise JournalError(f"{self.path}: cannot create: {getattr(exc, 'strerror', None) or exc}") from None

    def events(self) -> list[Event]:
        """The events in the journal (committed ones only)."""
        return [Event.from_dict(json.loads(line))
                for (line,) in self._db.execute("SELECT line FROM event ORDER BY seq")]

    def controls(self) -> list[Event]:
        """The journaled ``control`` events (a steered run's interventions and
        breakpoint hits), in order: what a resumed run applies again."""
        try:
            rows = self._db.execute("SELECT line FROM event WHERE line LIKE '%\"kind\":\"control\"%' ORDER BY seq")
            events = [Event.from_dict(parse_json(line)) for (line,) in rows]
        except (*_DAMAGE, TypeError, KeyError) as exc:
            raise JournalError(f"{self.path}: a damaged journal ({exc})") from None
        return [e for e in events if e.kind == "control"]

    def _journaled_line(self, seq: int) -> str:
        offset = seq - self._chunk_start
        if not 0 <= offset < len(self._chunk):
            self._chunk_start = seq
            try:
                self._chunk = [line for (line,) in self._db.execute(
                    "SELECT line FROM event WHERE seq >= ? ORDER BY seq LIMIT 4096", (seq,))]
            except _DAMAGE as exc:
                raise JournalError(f"{self.path}: a damaged journal ({exc})") from None
            offset = 0
        if offset >= len(self._chunk):
            raise JournalError(f"{self.path}: a damaged journal (event {seq} is missing)")
        return self._chunk[offset]

    def record(self, event: Event) -> None:
        """Check a re-executed event against the journal, or buffer a new one."""
        line = event.to_json()
        if event.seq < self.journaled:
            journaled = self._journaled_line(event.seq)
            if journaled != line:
                raise ResumeMismatch(f"{self.path}: event {event.seq} differs on re-execution "
                                     f"({_difference(journaled, event)}); the journal and outputs are left "
                                     "as they were")
            return
        self._chunk = []
        self._pending.append(event)

    def commit(self) -> None:
        """Write the buffered events in one transaction (a firing boundary)."""
        if not self._pending:
            return
        try:
            with self._db:
                self._db.execute("BEGIN")
                self._db.executemany(
                    "INSERT INTO event (seq, line) VALUES (?, ?)",
                    [(e.seq, e.to_json()) for e in self._pending],
                )
        except sqlite3.Error as exc:
            raise JournalError(f"{self.path}: cannot write the journal: {exc}") from None
        self.journaled += len(self._pending)
        self._pending.clear()

    def finish(self) -> None:
        """Commit the rest and mark the run finished."""
        self.commit()
        try:
            with self._db:
                self._db.execute("BEGIN")
                self._db.execute("INSERT OR REPLACE INTO run VALUES ('finished', '1')")
        except sqlite3.Error as exc:
            raise JournalError(f"{self.path}: cannot write the journal: {exc}") from None
        self.finished = True

    def close(self) -> None:
        """Close the database and release the journal's lock."""
        try:
            self._db.close()
        finally:
            self._release()

    def __enter__(self) -> "Journal":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def discard(self) -> None:
        """Remove the journal's files (a run that never started; call after :meth:`close`)."""
        for suffix in ("", "-wal", "-shm"):
            try:
                os.unlink(f"{self.path}{suffix}")
            except FileNotFoundError:
                pass

    def _release(self) -> None:
        if getattr(self, "_lock", None) is not None:
            os.close(self._lock)  # closing the descriptor releases its flock
            self._lock = None
