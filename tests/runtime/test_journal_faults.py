"""The journal under crashes and concurrent writers: a run killed at any of its journal
writes resumes to the uninterrupted run, event for event; two processes never write
one journal."""

from __future__ import annotations

import os
import signal
import sqlite3
import subprocess
import sys
import time

import pytest

from petriflow.runtime.journal import Journal
from petriflow.runtime.session import resume, run_files
from petriflow.runtime.trace import read_trace

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="crash injection forks a child process")

#: Two agents, a channel, a link fault, a kill, a timeout and a cancellation: a journal
#: with every kind of event.
RADIO = """petriflow: 1
net: radio
run: {seed: 3, until: 6, faults: [{kill: r2, at: 1.5}, {drop_link: [r1, r2], at: 0.2, until: 0.9}],
      channels: {radio: {model: range, latency: 0.1, loss: 0.2}}}
subnets:
  - {id: r1, places: [{id: a, tokens: 3}, done], transitions: [
      {id: go, action: core.fail, params: {seconds: 0.4, probability: 0.3}, timeout: 2, in: [a], out: [done, box],
       outcomes: {failed: [a], timeout: [a]}}]}
  - {id: r2, places: [{id: box, channel: radio}, got], transitions: [{id: take, in: [box], out: [got]}]}
places: [{id: alarm, tokens: 1}]
transitions:
  - {id: stop, action: core.wait, params: {seconds: 2.5}, in: [alarm], cancels: [go]}
"""

TICKER = """petriflow: 1
places: [{id: p, tokens: 1}, count]
transitions:
  - {id: tick, action: core.wait, params: {seconds: 0.05}, in: [p], out: [p, count]}
"""


def _write_points_crash(write: int, inside: bool, net, db, trace) -> int:
    """Run ``net`` in a forked child that dies (``os._exit``, no clean-up) at its
    ``write``-th journal write: before the write, or ``inside`` its transaction (the
    rows inserted, never committed). Returns the child's exit status: 9 when it died,
    0 when the run ended before that write."""
    pid = os.fork()
    if pid == 0:  # the child: never returns into pytest
        status = 1
        try:
            writes = 0
            commit, finish = Journal.commit, Journal.finish

            def die_at_write(self, rows):
                nonlocal writes
                writes += 1
                if writes == write:
                    if inside:
                        self._db.execute("BEGIN")
                        self._db.executemany("INSERT OR REPLACE INTO event (seq, line) VALUES (?, ?)", rows)
                    os._exit(9)

            def crashing_commit(self):
                if self._pending:
                    die_at_write(self, [(e.seq, e.to_json()) for e in self._pending])
                commit(self)

            def crashing_finish(self):
                crashing_commit(self)
                die_at_write(self, [])
                finish(self)

            Journal.commit, Journal.finish = crashing_commit, crashing_finish
            run_files(net, db=db, trace=trace)
            status = 0
        finally:
            os._exit(status)
    _, status = os.waitpid(pid, 0)
    return os.waitstatus_to_exitcode(status)


def _journal_seqs(db) -> list[int]:
    with sqlite3.connect(db) as con:
        return [s for (s,) in con.execute("SELECT seq FROM event ORDER BY seq")]


@pytest.mark.parametrize("inside", [False, True], ids=["between-writes", "inside-a-write"])
def test_a_run_killed_at_any_journal_write_resumes_to_the_uninterrupted_run(tmp_path, inside):
    net = tmp_path / "radio.yaml"
    net.write_text(RADIO)
    run_files(net, trace=tmp_path / "whole.jsonl")
    whole = (tmp_path / "whole.jsonl").read_text().splitlines()
    kinds = {e.kind for e in read_trace(tmp_path / "whole.jsonl")}
    assert {"start", "end", "cancel", "message", "fault", "stop"} <= kinds
    crashed = 0
    for write in range(1, 1000):
        db, trace = tmp_path / f"run{write}.sqlite", tmp_path / f"run{write}.jsonl"
        if _write_points_crash(write, inside, net, db, trace) == 0:
            break  # the run ended before this write: every write point has been tried
        crashed += 1
        if trace.exists():  # killed at the final mark: the outputs were complete before it
            assert trace.read_text().splitlines() == whole, "a half trace under the final name"
        with Journal(db) as journal:
            assert not journal.finished and journal.journaled <= len(whole)
        resume(db)  # writes the trace the run was started with
        assert trace.read_text().splitlines() == whole, f"killed at write {write}"
        assert _journal_seqs(db) == list(range(len(whole)))
    assert crashed >= 5, crashed  # commits at firing boundaries, and the final mark


def _wait_for_events(db, at_least: int, child) -> None:
    for _ in range(500):
        if child.poll() is not None:
            break
        try:
            with sqlite3.connect(f"file:{db}?mode=ro", uri=True) as con:
                if con.execute("SELECT COUNT(*) FROM event").fetchone()[0] >= at_least:
                    return
        except sqlite3.Error:
            pass
        time.sleep(0.01)
    raise AssertionError("the first writer never journaled")


def _petriflow(*argv) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "petriflow.cli", *map(str, argv)], stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)


def test_two_processes_never_write_one_journal(tmp_path):
    """A second process on a journal in use (a new run on its file, or a second resume)
    gets one line and exit 2; the journal, resumed alone, ends event for event as the
    whole run."""
    net = tmp_path / "ticker.yaml"
    net.write_text(TICKER)
    # 60 s of real time: the rivals start while it runs however busy the machine is; the
    # real-time processes are killed once the rivals have been refused, and a last resume
    # (simulated time) finishes the run in a moment
    run_files(net, until=60.0, trace=tmp_path / "whole.jsonl")
    whole = (tmp_path / "whole.jsonl").read_text().splitlines()
    db = tmp_path / "run.sqlite"
    first = _petriflow("run", net, "--until", "60", "--db", db, "--realtime", "--trace", tmp_path / "a.jsonl")
    try:
        _wait_for_events(db, 4, first)
        second = _petriflow("run", net, "--until", "1", "--db", db, "--trace", tmp_path / "b.jsonl")
        assert second.wait(60) == 2 and "already exists" in second.stderr.read()
    finally:
        os.kill(first.pid, signal.SIGKILL)  # killed mid-run: now two resumes race
        first.wait(60)
    resumed = _petriflow("run", "--resume", "--db", db, "--realtime")
    try:
        _wait_for_events(db, _journal_count(db) + 2, resumed)
        rival = _petriflow("run", "--resume", "--db", db)
        err = rival.communicate(timeout=60)[1]
        assert rival.returncode == 2 and "in use by another run" in err and err.count("\n") == 1, err
    finally:
        os.kill(resumed.pid, signal.SIGKILL)
        resumed.wait(60)
    last = _petriflow("run", "--resume", "--db", db)
    assert last.wait(120) == 0, last.stderr.read()
    assert (tmp_path / "a.jsonl").read_text().splitlines() == whole
    assert _journal_seqs(db) == list(range(len(whole)))
    assert not (tmp_path / "b.jsonl").exists()


def _journal_count(db) -> int:
    return len(_journal_seqs(db))
