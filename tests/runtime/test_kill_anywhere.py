"""Kill a run or a sweep at any moment (SIGKILL: no handler runs), then resume it.

What docs/runtime.md promises ("What a kill leaves on disk"): the resumed run's trace is
the uninterrupted run's, byte for byte; its exit code is the same; and the folder holds
exactly the files an uninterrupted run leaves, no temporary file of the dead process. A
sweep resumed after a kill records every trial exactly once and leaves no temporary file.

The probe over every scenario's shipped net kills each run at eight points: 0.1 s after
it was started (before its journal exists), when its journal first holds the run's inputs,
at one sixth, two sixths ... five sixths of its journaled events, and when its last event
is journaled. The points are found by watching the journal from outside (a read-only
SQLite connection), as an operator's kill would land, so the kill lands at or just after
each point.
"""

from __future__ import annotations

import os
import signal
import sqlite3
import subprocess
import sys
import textwrap
import time
from concurrent.futures import ThreadPoolExecutor
from contextlib import closing
from pathlib import Path

import pytest

from tests.conftest import NETS

pytestmark = pytest.mark.skipif(not hasattr(signal, "SIGKILL"), reason="POSIX signals")

PETRIFLOW = [sys.executable, "-m", "petriflow.cli"]

#: Each scenario's shipped net, with the options that keep its run short enough for the
#: probe (SMART's legged robots simulate at about 3x real time: a third of its mission).
SCENARIOS = {
    "passage": ("passage/passage.yaml", []),
    "smart": ("smart/smart.yaml", ["--until", "15"]),
    "comm": ("comm/comm-centralised-2.yaml", []),
    "bidding": ("bidding/bidding-autonomous-1.yaml", []),
    "bus": ("bus/bus-algorithm1-3.yaml", []),
    "slam": ("slam/slam-centralised.yaml", []),
    "swarm": ("swarm/swarm-3.yaml", []),
}


def _run(folder: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([*PETRIFLOW, *args], cwd=folder, capture_output=True, text=True, timeout=600)


def _journaled(db: Path) -> int | None:
    """The events a journal holds now (``None``: no journal with its inputs yet)."""
    if not db.exists():
        return None
    try:
        with closing(sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=0.05)) as reader:
            if reader.execute("SELECT count(*) FROM run WHERE key = 'inputs'").fetchone()[0] == 0:
                return None
            return reader.execute("SELECT count(*) FROM event").fetchone()[0]
    except sqlite3.Error:
        return None


def _kill_at(folder: Path, command: list[str], *, seconds: float | None = None,
             events: int | None = None) -> tuple[bool, subprocess.Popen]:
    """Start ``command`` in ``folder`` and SIGKILL it after ``seconds``, or once its journal
    ``r.sqlite`` holds ``events`` events (0: once it exists with its inputs). Returns
    whether the kill landed (else the run had ended first) and the dead process, which the
    caller reaps only after it has resumed the run (as a shell's kill leaves it a moment)."""
    child = subprocess.Popen([*PETRIFLOW, *command], cwd=folder, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
    started = time.monotonic()
    while child.poll() is None:
        if seconds is not None and time.monotonic() - started >= seconds:
            break
        if events is not None:
            count = _journaled(folder / "r.sqlite")
            if count is not None and count >= events:
                break
        time.sleep(0.002)
    landed = child.poll() is None
    child.kill()
    return landed, child


def _kill_and_resume(folder: Path, command: list[str], point: dict) -> tuple[bool, subprocess.CompletedProcess]:
    folder.mkdir()
    landed, child = _kill_at(folder, command, **point)
    try:
        return landed, _run(folder, *command, "--resume")
    finally:
        child.wait()


@pytest.mark.slow
@pytest.mark.parametrize("scenario", sorted(SCENARIOS))
def test_a_run_killed_anywhere_resumes_to_the_uninterrupted_run(tmp_path, scenario):
    net, options = SCENARIOS[scenario]
    command = ["run", str(NETS / net), "--seed", "3", *options, "--db", "r.sqlite", "--trace", "c.jsonl",
               "--quiet"]
    whole = tmp_path / "whole"
    whole.mkdir()
    clean = _run(whole, *command)
    assert clean.returncode in (0, 1), clean.stderr
    expected = (whole / "c.jsonl").read_bytes()
    leaves = sorted(os.listdir(whole))
    total = _journaled(whole / "r.sqlite")
    assert leaves == ["c.jsonl", "r.sqlite"] and total
    points = [("0.1 s", {"seconds": 0.1}), ("journal made", {"events": 0})]
    points += [(f"{k}/6 of the events", {"events": total * k // 6}) for k in range(1, 6)]
    points += [("the last event", {"events": total})]
    # two kills at a time (one a core): each is a process of its own
    with ThreadPoolExecutor(max_workers=2) as pool:
        done = {name: pool.submit(_kill_and_resume, tmp_path / name.replace("/", "-").replace(" ", "_"), command,
                                  point) for name, point in points}
    landed = 0
    for name, future in done.items():
        hit, resumed = future.result()
        landed += hit
        folder = tmp_path / name.replace("/", "-").replace(" ", "_")
        assert resumed.returncode == clean.returncode, f"killed at {name}: {resumed.stderr}"
        assert "Traceback" not in resumed.stderr
        assert (folder / "c.jsonl").read_bytes() == expected, f"killed at {name}: the trace differs"
        assert sorted(os.listdir(folder)) == leaves, f"killed at {name}"
    assert landed >= 6, "most kills should land before the run ends"


def test_a_dead_writers_temporary_file_is_removed_before_its_parent_reaps_it(tmp_path):
    """A killed writer's temporary trace is removed by the next writer of the same file,
    even while the dead process is a zombie (killed, not yet reaped: its process id still
    answers, its lock is gone)."""
    target = tmp_path / "c.jsonl"
    child = subprocess.Popen([sys.executable, "-c", textwrap.dedent(f"""
        import sys, time
        from petriflow.runtime.trace import TraceWriter
        writer = TraceWriter({str(target)!r})
        print("open", flush=True)
        time.sleep(60)
        """)], stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout.readline().strip() == "open"
        os.kill(child.pid, signal.SIGKILL)
        while not _zombie(child.pid):
            time.sleep(0.01)
        assert len(list(tmp_path.iterdir())) == 1  # the dead writer's temporary file
        from petriflow.runtime.trace import TraceWriter

        TraceWriter(target).close()
        assert sorted(p.name for p in tmp_path.iterdir()) == ["c.jsonl"]
    finally:
        child.kill()
        child.wait()


def _zombie(pid: int) -> bool:
    """Whether ``pid`` is dead but not reaped: its main thread a zombie and no other thread
    left (a process's files, and their locks, go with its last thread)."""
    proc = Path(f"/proc/{pid}")
    try:
        return proc.joinpath("stat").read_text().rsplit(")", 1)[1].split()[0] == "Z" \
            and len(os.listdir(proc / "task")) <= 1
    except OSError:
        return False


def test_a_live_writers_temporary_file_is_left_alone(tmp_path):
    """Two writers of the same file at once: neither removes the other's temporary file."""
    from petriflow.runtime.trace import TraceWriter

    first = TraceWriter(tmp_path / "c.jsonl")
    second = TraceWriter(tmp_path / "c.jsonl")
    second.close()
    assert len(list(tmp_path.iterdir())) == 2
    first.close()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.jsonl"]


def test_a_run_killed_while_making_its_journal_leaves_none_and_resumes_from_the_start(tmp_path):
    """A kill while the journal is being made (here: as the run's inputs are written into
    it) leaves no journal, only a temporary file; ``--resume`` with the net then runs from
    the beginning, says so, and leaves what an uninterrupted run leaves."""
    net = NETS / "passage" / "passage.yaml"
    killed = subprocess.run([sys.executable, "-c", textwrap.dedent(f"""
        import json, os, signal, sys
        from petriflow.runtime import journal
        real = journal.json.dumps
        def dumps(value, **kw):
            if isinstance(value, dict) and "net_text" in value:
                os.kill(os.getpid(), signal.SIGKILL)
            return real(value, **kw)
        journal.json.dumps = dumps
        from petriflow.cli import main
        sys.exit(main(["run", {str(net)!r}, "--db", "r.sqlite", "--trace", "c.jsonl"]))
        """)], cwd=tmp_path, capture_output=True, text=True)
    assert killed.returncode == -signal.SIGKILL
    assert not (tmp_path / "r.sqlite").exists()
    resumed = _run(tmp_path, "run", str(net), "--db", "r.sqlite", "--trace", "c.jsonl", "--resume")
    assert resumed.returncode == 0, resumed.stderr
    assert "running" in resumed.stderr and "from its beginning" in resumed.stderr
    assert sorted(os.listdir(tmp_path)) == ["c.jsonl", "r.sqlite"]


SWEEP = """\
petriflow-sweep: 1
name: killed
net: {net}
seeds: [1, 2, 3]
matrix:
  seconds: [1, 2]
set:
  net.transitions.rest.params.seconds: "${{seconds}}"
metrics: [core.end_time]
"""


@pytest.mark.slow
def test_a_sweep_killed_midway_resumes_each_trial_exactly_once(tmp_path):
    """A sweep killed while its trials run, then resumed: every trial recorded once, the
    resumed results equal an uninterrupted sweep's, and no temporary file is left."""
    net = tmp_path / "wait.yaml"
    net.write_text(textwrap.dedent("""\
        petriflow: 1
        net: wait
        places: [{id: i, tokens: 1}, o]
        transitions:
          - {id: rest, action: core.wait, params: {seconds: 1}, in: [i], out: [o]}
        final: {o: 1}
        """))
    spec = tmp_path / "sweep.yaml"
    spec.write_text(SWEEP.format(net=net.name))
    whole = _run(tmp_path, "sweep", "sweep.yaml", "--db", "whole.db", "--workers", "1", "--json")
    assert whole.returncode == 0, whole.stderr
    child = subprocess.Popen([*PETRIFLOW, "sweep", "sweep.yaml", "--db", "s.db", "--workers", "1", "--csv",
                              "s.csv"], cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        while child.poll() is None:
            try:
                with closing(sqlite3.connect(f"file:{tmp_path / 's.db'}?mode=ro", uri=True, timeout=0.05)) as reader:
                    if reader.execute("SELECT count(*) FROM trials").fetchone()[0] >= 2:
                        break
            except sqlite3.Error:
                pass
            time.sleep(0.002)
        os.kill(child.pid, signal.SIGKILL)
        resumed = _run(tmp_path, "sweep", "sweep.yaml", "--db", "s.db", "--workers", "1", "--csv", "s.csv",
                       "--resume")
    finally:
        child.wait()
    assert resumed.returncode == 0, resumed.stderr
    with closing(sqlite3.connect(tmp_path / "s.db")) as db:
        trials = db.execute("SELECT params, seed, status FROM trials ORDER BY params, seed").fetchall()
    with closing(sqlite3.connect(tmp_path / "whole.db")) as db:
        expected = db.execute("SELECT params, seed, status FROM trials ORDER BY params, seed").fetchall()
    assert trials == expected and len(trials) == 6
    assert sorted(os.listdir(tmp_path)) == sorted(["s.csv", "s.db", "sweep.yaml", "wait.yaml", "whole.db"])
