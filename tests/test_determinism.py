"""Same net, world and seed, same trace, byte for byte, in any process; a run killed
mid-way and resumed in another process writes the uninterrupted trace.

Every shipped net runs in two separate Python processes with different hash seeds
(``PYTHONHASHSEED``), so a trace that depended on ``id()``, memory addresses or the
order of a set of strings would differ. Runs are bounded (simulated time and firings)
so the whole file stays quick; the bound is part of the journaled inputs, so a resumed
run stops at the same place.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import NETS, net_files

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="runs child processes with their own hash seeds")

SEED, UNTIL, FIRINGS = 3, 40.0, 200

#: Runs every net given on the command line into the folder given first; one process
#: for all of them, so the file costs two interpreter start-ups, not two per net.
RUN_ALL = """
import sys
from pathlib import Path
from petriflow.runtime.session import run_files
out = Path(sys.argv[1])
for i, net in enumerate(sys.argv[2:]):
    try:
        run_files(net, seed=%d, until=%r, max_firings=%d, trace=out / f"{i}.jsonl")
    except Exception as exc:
        (out / f"{i}.error").write_text(f"{type(exc).__name__}: {exc}")
""" % (SEED, UNTIL, FIRINGS)

#: Runs one net with a journal and dies without clean-up (``os._exit``) at the journal
#: commit that first holds at least the given number of events: a kill mid-run.
KILL_AT = """
import os, sys
from petriflow.cli import main
from petriflow.runtime.journal import Journal
at = int(sys.argv[1])
commit = Journal.commit
def dying_commit(self):
    commit(self)
    if self.journaled >= at:
        os._exit(9)
Journal.commit = dying_commit
sys.exit(main(sys.argv[2:]))
"""


def _python(code: str, *argv: object, hash_seed: int) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONHASHSEED": str(hash_seed)}
    return subprocess.run([sys.executable, "-c", code, *map(str, argv)], env=env, capture_output=True, text=True,
                          timeout=900)


def _runnable(path: Path) -> bool:
    return "experiments" not in path.parts


NETS_RUN = [p for p in net_files() if _runnable(p)]


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory):
    """Every shipped net run in two processes with different hash seeds."""
    folders, children = [], []
    for hash_seed in (1, 2):  # side by side: two processes, two cores
        out = tmp_path_factory.mktemp(f"hash{hash_seed}")
        env = {**os.environ, "PYTHONHASHSEED": str(hash_seed)}
        children.append(subprocess.Popen([sys.executable, "-c", RUN_ALL, str(out), *map(str, NETS_RUN)], env=env,
                                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True))
        folders.append(out)
    for child in children:
        _, err = child.communicate(timeout=900)
        assert child.returncode == 0, err[-2000:]
    return folders


@pytest.mark.parametrize("index", range(len(NETS_RUN)), ids=[str(p.relative_to(NETS)) for p in NETS_RUN])
def test_two_processes_write_the_same_trace_bytes(two_runs, index):
    first, second = (folder / f"{index}.jsonl" for folder in two_runs)
    errors = [(folder / f"{index}.error") for folder in two_runs]
    if errors[0].exists():  # a net that does not run (say, a stall) must fail the same way in both
        assert errors[1].exists() and errors[0].read_text() == errors[1].read_text()
        return
    assert first.read_bytes() == second.read_bytes()
    assert not any(".partial" in p.name for folder in two_runs for p in folder.iterdir())


def test_no_object_addresses_or_process_digests_in_traces(two_runs):
    """What made traces differ between processes: reprs with memory addresses."""
    for trace in two_runs[0].glob("*.jsonl"):
        text = trace.read_text()
        assert " object at 0x" not in text, trace


#: One net per scenario, killed mid-way and resumed (the philosophers and the inspection
#: example are nets to analyse: they stall at once, or need a camera world they lack).
SCENARIOS = sorted({p.parent.name: p for p in reversed(NETS_RUN) if p.suffix == ".yaml"
                    and p.parent.name not in ("philosophers", "examples")}.items())


@pytest.mark.parametrize("net", [p for _, p in SCENARIOS], ids=[name for name, _ in SCENARIOS])
def test_a_run_killed_mid_way_resumes_in_another_process_to_the_same_trace(two_runs, tmp_path, net):
    """The uninterrupted trace is the first process's run of the same options."""
    options = ["--seed", SEED, "--until", UNTIL, "--max-firings", FIRINGS]
    whole = two_runs[0] / f"{NETS_RUN.index(net)}.jsonl"
    events = len(whole.read_text().splitlines())
    assert events >= 4
    db, trace = tmp_path / "run.sqlite", tmp_path / "run.jsonl"
    killed = _python(KILL_AT, events // 2, "run", net, *options, "--trace", trace, "--db", db, hash_seed=2)
    assert killed.returncode == 9, killed.stderr
    assert not trace.exists()
    resumed = _python(KILL_AT, 10**9, "run", "--resume", "--db", db, hash_seed=3)
    assert resumed.returncode in (0, 1), resumed.stderr
    assert trace.read_bytes() == whole.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.jsonl", "run.sqlite"]


def test_a_resume_that_diverges_says_where_and_changes_nothing(tmp_path):
    """A journal whose events a re-execution cannot reproduce (here, edited): the resume
    names the event and the field, exits 2, and leaves the journal and the trace already
    there exactly as they were, with no temporary file (not even the killed run's)."""
    import sqlite3

    net = NETS / "passage" / "passage.yaml"
    db, trace = tmp_path / "run.sqlite", tmp_path / "run.jsonl"
    killed = _python(KILL_AT, 6, "run", net, "--seed", SEED, "--trace", trace, "--db", db, hash_seed=1)
    assert killed.returncode == 9
    with sqlite3.connect(db) as con:
        line = json.loads(con.execute("SELECT line FROM event WHERE seq = 3").fetchone()[0])
        line["time"] += 1.0
        con.execute("UPDATE event SET line = ? WHERE seq = 3", (json.dumps(line, sort_keys=True),))
    con.close()
    trace.write_text("an older trace\n")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir() if ".partial" not in p.name}
    resumed = _python(KILL_AT, 10**9, "run", "--resume", "--db", db, hash_seed=2)
    assert resumed.returncode == 2
    message = resumed.stderr.strip()
    assert len(message.splitlines()) == 1 and "Traceback" not in message
    assert "event 3 differs" in message and "time" in message and "in the journal" in message
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    again = _python(KILL_AT, 10**9, "run", "--resume", "--db", db, hash_seed=2)
    assert again.returncode == 2 and again.stderr.strip() == message
