"""Whole runs from files: trace, XES, journal, resume after a kill, determinism."""

import os
import signal
import sqlite3
import subprocess
import sys
import time

import pytest

from petriflow.cli import main
from petriflow.runtime.scheduler import Scheduler
from petriflow.runtime.journal import Journal, JournalError
from petriflow.runtime.session import resume, run_files
from petriflow.runtime.trace import read_trace
from tests.conftest import NETS

PASSAGE = NETS / "passage" / "passage.yaml"

TICKER = """
petriflow: 1
places: [{id: p, tokens: 1}, {id: count}]
transitions:
  - {id: tick, action: core.wait, params: {seconds: 0.05}, in: [p], out: [p, count]}
"""


@pytest.fixture
def ticker(tmp_path):
    path = tmp_path / "ticker.yaml"
    path.write_text(TICKER)
    return path


def lines(path):
    return path.read_text().splitlines()


def test_world_run_is_deterministic(tmp_path):
    """Two runs of the passage net with one seed write identical traces."""
    run_files(PASSAGE, trace=tmp_path / "a.jsonl", seed=3)
    run_files(PASSAGE, trace=tmp_path / "b.jsonl", seed=3)
    assert lines(tmp_path / "a.jsonl") == lines(tmp_path / "b.jsonl")


def test_passage_robots_move_through_the_passage_by_physics(tmp_path):
    """Both robots end on the other side of the wall, taking turns in the passage."""
    outcome = run_files(PASSAGE, trace=tmp_path / "t.jsonl", keep_events=True)
    assert outcome.result.reason == "final"
    ends = {e.transition: e for e in outcome.events if e.kind == "end"}
    assert ends["red_leave"].data["result"]["x"] > 1.0
    assert ends["blue_leave"].data["result"]["x"] < -1.0
    starts = {e.transition: e.time for e in outcome.events if e.kind == "start"}
    # mutual exclusion: blue enters only after red left the passage
    assert starts["blue_enter"] >= ends["red_leave"].time


def test_xes_log_replays_on_the_net_without_deviations(tmp_path):
    """PM4Py reads the XES log and token-replays it on the net with fitness 1."""
    pm4py = pytest.importorskip("pm4py")
    from petriflow.io.pnml import save_pnml

    outcome = run_files(PASSAGE, xes=tmp_path / "run.xes")
    save_pnml(outcome.net, tmp_path / "net.pnml")
    log = pm4py.read_xes(str(tmp_path / "run.xes"))
    net, im, fm = pm4py.read_pnml(str(tmp_path / "net.pnml"))
    fitness = pm4py.fitness_token_based_replay(log, net, im, fm)
    assert len(log) == 6
    assert fitness["log_fitness"] == 1.0 and fitness["perc_fit_traces"] == 100.0


def test_crash_mid_run_then_resume_gives_the_uninterrupted_trace(tmp_path, monkeypatch):
    """A run that dies after some firings resumes from its journal, event for event."""
    run_files(PASSAGE, trace=tmp_path / "whole.jsonl", seed=2)

    class Crash(Exception):
        pass

    original = Scheduler.on_event

    def crash_after(self, handler, kinds=None):
        original(self, handler, kinds)
        if not getattr(self, "_crash_installed", False):
            self._crash_installed = True

            def crash(event):
                if event.seq == 7:
                    raise Crash()

            original(self, crash)

    monkeypatch.setattr(Scheduler, "on_event", crash_after)
    with pytest.raises(Crash):
        run_files(PASSAGE, db=tmp_path / "run.sqlite", seed=2)
    monkeypatch.undo()
    with Journal(tmp_path / "run.sqlite") as journal:
        journaled = journal.journaled
    assert 0 < journaled < len(lines(tmp_path / "whole.jsonl"))
    resume(tmp_path / "run.sqlite", trace=tmp_path / "resumed.jsonl")
    assert lines(tmp_path / "resumed.jsonl") == lines(tmp_path / "whole.jsonl")
    with sqlite3.connect(tmp_path / "run.sqlite") as db:
        seqs = [s for (s,) in db.execute("SELECT seq FROM event ORDER BY seq")]
    assert seqs == list(range(len(seqs))) and len(seqs) == len(lines(tmp_path / "whole.jsonl"))


def test_killed_process_resumes_without_lost_or_duplicated_firings(tmp_path, ticker):
    """SIGKILL a paced run mid-way; --resume completes it with each firing once."""
    run_files(ticker, until=1.0, trace=tmp_path / "whole.jsonl")
    db = tmp_path / "run.sqlite"
    child = subprocess.Popen([sys.executable, "-m", "petriflow.cli", "run", str(ticker), "--until", "1",
                              "--db", str(db), "--realtime"], stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
    try:
        for _ in range(400):
            time.sleep(0.01)
            try:
                with sqlite3.connect(f"file:{db}?mode=ro", uri=True) as check:
                    if check.execute("SELECT COUNT(*) FROM event").fetchone()[0] >= 8:
                        break
            except sqlite3.Error:
                continue
        os.kill(child.pid, signal.SIGKILL)
    finally:
        child.wait()
    with Journal(db) as journal:
        partial = journal.journaled
    assert 8 <= partial < len(lines(tmp_path / "whole.jsonl"))
    assert main(["run", "--resume", "--db", str(db), "--trace", str(tmp_path / "resumed.jsonl")]) == 0
    assert lines(tmp_path / "resumed.jsonl") == lines(tmp_path / "whole.jsonl")
    firings = [e.data["firing"] for e in read_trace(tmp_path / "resumed.jsonl") if e.kind == "start"]
    assert firings == list(range(1, len(firings) + 1))


def test_resume_of_a_finished_run_writes_its_outputs_again(tmp_path, ticker):
    """A finished journal (a run killed while writing its outputs) is re-executed against
    the journal, with a warning, and writes the uninterrupted run's trace."""
    run_files(ticker, until=0.2, db=tmp_path / "run.sqlite", trace=tmp_path / "whole.jsonl")
    with pytest.warns(UserWarning, match="already finished"):
        outcome = resume(tmp_path / "run.sqlite", trace=tmp_path / "again.jsonl")
    assert outcome.result.reason == run_files(ticker, until=0.2).result.reason
    assert lines(tmp_path / "again.jsonl") == lines(tmp_path / "whole.jsonl")


def test_existing_journal_is_never_overwritten(tmp_path, ticker):
    """A new run refuses a journal file that exists."""
    (tmp_path / "run.sqlite").write_text("keep me")
    with pytest.raises(JournalError, match="already exists"):
        run_files(ticker, db=tmp_path / "run.sqlite")
    assert (tmp_path / "run.sqlite").read_text() == "keep me"


def test_cli_run_prints_summary_and_writes_files(tmp_path, ticker, capsys):
    """petriflow run writes trace, XES and journal and summarises the run."""
    code = main(["run", str(ticker), "--until", "0.5", "--trace", str(tmp_path / "t.jsonl"),
                 "--xes", str(tmp_path / "t.xes"), "--db", str(tmp_path / "t.sqlite"), "--json"])
    import json

    summary = json.loads(capsys.readouterr().out)
    assert code == 0 and summary["reason"] == "until" and summary["firings"] == 11
    assert all((tmp_path / name).exists() for name in ("t.jsonl", "t.xes", "t.sqlite"))


def test_cli_run_unknown_action_exits_2_with_one_line(tmp_path, capsys):
    """An unknown action is bad input: one line, exit 2, no file written."""
    path = tmp_path / "bad.yaml"
    path.write_text("petriflow: 1\nplaces: [{id: a, tokens: 1}]\n"
                    "transitions: [{id: go, action: drive.gotoo, in: [a]}]\n")
    code = main(["run", str(path), "--trace", str(tmp_path / "t.jsonl")])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1
    assert "'go': unknown action 'drive.gotoo' (did you mean 'drive.goto'" in err
    assert not (tmp_path / "t.jsonl").exists()


def test_replay_prints_the_token_game(tmp_path, ticker, capsys):
    """replay prints each event with the marking after it."""
    run_files(ticker, until=0.1, trace=tmp_path / "t.jsonl")
    capsys.readouterr()
    assert main(["replay", str(tmp_path / "t.jsonl")]) == 0
    out = capsys.readouterr().out.splitlines()
    assert "fire   tick" in out[1] and out[-1].endswith("count=2")


def test_output_folders_are_made(tmp_path, ticker):
    """--trace/--xes/--db into folders that do not exist yet: the folders are made."""
    out = tmp_path / "out" / "smart"
    code = main(["run", str(ticker), "--until", "0.2", "--trace", str(out / "run.jsonl"),
                 "--xes", str(out / "run.xes"), "--db", str(out / "run.sqlite")])
    assert code == 0
    assert sorted(p.name for p in out.iterdir()) == ["run.jsonl", "run.sqlite", "run.xes"]


def test_resume_writes_the_outputs_the_run_was_started_with(tmp_path, ticker, monkeypatch):
    """Killed mid-way, the run resumed with only --db rewrites its trace and XES, keeps its
    firing limit, and leaves no temporary file behind."""
    whole = tmp_path / "whole"
    run_files(ticker, max_firings=12, trace=whole / "t.jsonl")

    class Crash(Exception):
        pass

    original = Scheduler.on_event

    def crash_after(self, handler, kinds=None):
        original(self, handler, kinds)
        if not getattr(self, "_crash_installed", False):
            self._crash_installed = True
            original(self, lambda event: (_ for _ in ()).throw(Crash()) if event.seq == 9 else None)

    monkeypatch.setattr(Scheduler, "on_event", crash_after)
    out = tmp_path / "out"
    with pytest.raises(Crash):
        run_files(ticker, max_firings=12, trace=out / "t.jsonl", xes=out / "t.xes", db=out / "t.sqlite")
    monkeypatch.undo()
    assert not (out / "t.jsonl").exists()
    assert main(["run", "--resume", "--db", str(out / "t.sqlite")]) == 0
    assert lines(out / "t.jsonl") == lines(whole / "t.jsonl")
    assert read_trace(out / "t.jsonl")[-1].data["firings"] == 12
    assert (out / "t.xes").exists()
    assert sorted(p.name for p in out.iterdir()) == ["t.jsonl", "t.sqlite", "t.xes"]


def test_a_killed_writers_temporary_file_is_cleaned_up(tmp_path, ticker):
    """A trace's temporary file left by a killed run goes once a later run's trace is in place."""
    import os

    stale = tmp_path / ".t.jsonl.abc123.partial"
    stale.write_text("half a trace")
    os.utime(stale, (1, 1))
    run_files(ticker, until=0.1, trace=tmp_path / "t.jsonl")
    assert sorted(p.name for p in tmp_path.iterdir() if p.suffix != ".yaml") == ["t.jsonl"]


def test_xes_durations_are_what_the_run_took(tmp_path):
    """PM4Py reads activity durations (start_timestamp to time:timestamp) and the
    performance DFG's waiting times as the run had them; every event names its agent."""
    pm4py = pytest.importorskip("pm4py")
    import warnings

    outcome = run_files(PASSAGE, xes=tmp_path / "run.xes", keep_events=True)
    starts = {e.data["firing"]: e for e in outcome.events if e.kind == "start"}
    took = {starts[e.data["firing"]].transition: round(e.time - starts[e.data["firing"]].time, 6)
            for e in outcome.events if e.kind == "end"}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        log = pm4py.read_xes(str(tmp_path / "run.xes"))
        service = pm4py.get_service_time(log, start_timestamp_key="start_timestamp", aggregation_measure="mean")
        dfg, _, _ = pm4py.discover_performance_dfg(log)
    assert {t: round(v, 6) for t, v in service.items()} == took
    ends = {e.transition: e.time for e in outcome.events if e.kind == "end"}
    begins = {e.transition: e.time for e in outcome.events if e.kind == "start"}
    assert dfg[("red_enter", "red_leave")]["mean"] == pytest.approx(begins["red_leave"] - ends["red_enter"])
    assert set(log["org:resource"]) == {"red", "blue"}
