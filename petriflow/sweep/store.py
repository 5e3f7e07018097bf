"""A sweep's results in SQLite: one row per trial, committed as it arrives.

Tables: ``sweep`` (``key``, ``value``: the sweep file, its digest, the format) and
``trials`` (``row``, ``params`` as canonical JSON, ``seed``, ``status`` ok / error /
timeout / crashed, ``outcome``, ``metrics`` as JSON, ``wall`` seconds, ``error``, ``cpu``
seconds of the worker process: the trial's own cost, whatever else the machine runs), with
one trial per (params, seed): a sweep resumed after a kill runs only what is missing,
and never records a trial twice.

Examples:
    >>> store = Store(None)
    >>> store.begin({"file": "s.yaml", "digest": "abc"}, resume=False)
    >>> store.add(0, {"a": 1}, 1, {"status": "ok", "metrics": {"m": 2.0}, "outcome": "final",
    ...                            "error": None, "wall": 0.1})
    >>> store.done()
    {('{"a":1}', 1)}
    >>> store.results()[0]["metrics"]
    {'m': 2.0}
"""

from __future__ import annotations

import json
import os
import sqlite3
import warnings
from pathlib import Path
from typing import Any

from petriflow.errors import NetFormatError, PetriflowError
from petriflow.sweep.spec import canonical

__all__ = ["Store", "StoreError"]

_SCHEMA = """
CREATE TABLE IF NOT EXISTS sweep (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS trials (
    row INTEGER NOT NULL, params TEXT NOT NULL, seed INTEGER NOT NULL, status TEXT NOT NULL,
    outcome TEXT, metrics TEXT NOT NULL, wall REAL, error TEXT, cpu REAL,
    PRIMARY KEY (params, seed)
);
"""
#: What a results database says it is (``sweep.format``).
FORMAT = "petriflow-sweep-results 1"


class StoreError(PetriflowError):
    """A results database cannot be used (exists without --resume, another sweep, damaged)."""


class Store:
    """Results of one sweep; ``path`` ``None`` keeps them in memory."""

    def __init__(self, path: str | Path | None) -> None:
        self.path = None if path is None else Path(path)
        self.db: sqlite3.Connection | None = None
        self._noted = False

    def _refuse(self, resume: bool) -> bool:
        """Whether the database exists; refuses one that exists without ``resume``, or a
        folder (one missing with ``resume`` is made, with a warning)."""
        where = str(self.path)
        exists = self.path.exists()
        if exists and not resume:
            raise StoreError(f"{where}: already exists; use --resume to finish that sweep, or another --db")
        if not exists and resume and not self._noted:  # killed before it was made: nothing to keep
            warnings.warn(f"{where}: no results database yet (the sweep was stopped before it began);"
                          " running the sweep from its beginning", stacklevel=3)
            self._noted = True
        if self.path.is_dir():
            raise NetFormatError("--db names a folder, not a file", path=where)
        return exists

    def check(self, meta: dict[str, str], resume: bool) -> None:
        """Refuse early, creating nothing: ``path`` exists without ``resume``, or holds
        another sweep (see :meth:`begin`)."""
        if self.path is None:
            return
        if self._refuse(resume):
            self.begin(meta, resume=True)
            self.close()

    def begin(self, meta: dict[str, str], resume: bool) -> None:
        """Open (``resume``: an existing database of the same sweep) or create the database.

        ``meta`` holds ``file``, ``digest`` (the sweep's fingerprint) and, optionally,
        ``files`` (JSON ``{file: content digest}``, so a refusal names the file that changed).

        Raises:
            StoreError: it exists and ``resume`` is false; it holds another sweep; it is
                not a results database.
        """
        if self.path is None:
            self.db = sqlite3.connect(":memory:")
            self.db.executescript(_SCHEMA)
            self._meta({"format": FORMAT, **meta})
            return
        where, exists = str(self.path), self._refuse(resume)
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            if not exists:
                self._create(meta)
            self.db = sqlite3.connect(where, timeout=5.0, isolation_level=None)
            known = dict(self.db.execute("SELECT key, value FROM sweep").fetchall())
            if known.get("format") != FORMAT:
                raise StoreError(f"{where}: not a petriflow sweep results database")
            if known.get("digest") != meta["digest"]:
                raise StoreError(f"{where}: {_changed(known, meta)}")
            self.db.execute("SELECT row, params, seed, status, outcome, metrics, wall, error FROM trials LIMIT 1")
            if "cpu" not in {column[1] for column in self.db.execute("PRAGMA table_info(trials)")}:
                self.db.execute("ALTER TABLE trials ADD COLUMN cpu REAL")  # recorded before CPU seconds were
        except sqlite3.Error as exc:
            self.close()
            raise StoreError(f"{where}: not a petriflow sweep results database ({exc})") from None
        except OSError as exc:
            self.close()
            raise StoreError(f"{where}: {exc.strerror or exc}") from None
        except StoreError:
            self.close()
            raise

    def _create(self, meta: dict[str, str]) -> None:
        """Make the database whole or not at all: its tables and what it says it is are
        written to a temporary file beside it, linked into place only if nothing of that
        name exists, so a kill at any moment leaves no database or one that resumes."""
        from petriflow.io.files import make_database

        assert self.path is not None
        try:
            lock = make_database(self.path, _SCHEMA, lambda db: db.executemany(
                "INSERT OR REPLACE INTO sweep VALUES (?, ?)", sorted({"format": FORMAT, **meta}.items())))
        except FileExistsError:
            raise StoreError(f"{self.path}: already exists; use --resume to finish that sweep, or another --db") \
                from None
        os.close(lock)  # the sweep's driver is its one writer; SQLite's own locking suffices

    def _meta(self, meta: dict[str, str]) -> None:
        assert self.db is not None
        with self.db:
            self.db.executemany("INSERT OR REPLACE INTO sweep VALUES (?, ?)", sorted(meta.items()))

    def done(self) -> set[tuple[str, int]]:
        """``{(params, seed)}`` of the trials recorded, less the ``crashed`` ones (their
        process or node died: a resumed sweep runs them again)."""
        assert self.db is not None
        return set(self.db.execute("SELECT params, seed FROM trials WHERE status != 'crashed'").fetchall())

    def add(self, row: int, params: dict[str, Any], seed: int, result: dict[str, Any]) -> None:
        """Record one trial's result (committed at once; it replaces a ``crashed`` one)."""
        assert self.db is not None
        with self.db:
            self.db.execute(
                "INSERT OR REPLACE INTO trials (row, params, seed, status, outcome, metrics, wall, error, cpu)"
                " VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)",
                (row, canonical(params), seed, result["status"], result.get("outcome"),
                 json.dumps(result.get("metrics", {}), sort_keys=True), result.get("wall"), result.get("error"),
                 result.get("cpu")),
            )

    def results(self) -> list[dict[str, Any]]:
        """Every recorded trial, by row and seed."""
        assert self.db is not None
        out = []
        try:
            for row, params, seed, status, outcome, metrics, wall, error, cpu in self.db.execute(
                    "SELECT row, params, seed, status, outcome, metrics, wall, error, cpu FROM trials"
                    " ORDER BY row, seed"):
                out.append({"row": row, "params": json.loads(params), "seed": seed, "status": status,
                            "outcome": outcome, "metrics": json.loads(metrics), "wall": wall, "error": error,
                            "cpu": cpu})
        except (sqlite3.Error, ValueError) as exc:
            raise StoreError(f"{self.path}: damaged results ({exc})") from None
        return out

    def close(self) -> None:
        if self.db is not None:
            self.db.close()
            self.db = None


def _changed(known: dict[str, str], meta: dict[str, str]) -> str:
    """Why a database's sweep differs from this one, in a few words."""
    try:
        before, now = json.loads(known.get("files") or "null"), json.loads(meta.get("files") or "null")
    except ValueError:
        before = now = None
    if isinstance(before, dict) and isinstance(now, dict):
        edited = sorted(f for f in now if f in before and before[f] != now[f])
        if edited:
            return (f"{', '.join(edited[:3])}{' and more' if len(edited) > 3 else ''} changed since these results"
                    f" were recorded; restore {'it' if len(edited) == 1 else 'them'}, or use another --db")
        if before != now:
            return "the sweep reads other files than when these results were recorded; use another --db"
    return f"holds the results of another sweep ({known.get('file')}, or this file before it changed); use another --db"
