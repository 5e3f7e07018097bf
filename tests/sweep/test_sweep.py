"""Running sweeps: results per row, determinism, crash isolation, resume, reports, backends."""

from __future__ import annotations

import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest

from petriflow.cli import main
from petriflow.sweep import load_sweep, run_sweep
from petriflow.sweep.trial import run_trial

from .conftest import write


def random_sweep(folder: Path, tmp_path: Path, trials: int = 3, extra: str = "") -> Path:
    """Two rows of the misbehaving net that behave: a random wait with mean 1 or 4."""
    return write(tmp_path, "random.yaml", f"""\
        petriflow-sweep: 1
        net: {folder}/odd.yaml
        trials: {trials}
        matrix: {{mean: [1.0, 4.0]}}
        set: {{net.transitions.wait.params.mean: "${{mean}}"}}
        metrics:
          time_s: core.end_time
          waited: {{metric: core.reported, name: waited, field: seconds}}
          outcome: core.outcome
          firings: core.firings
        {extra}""")


def test_each_trial_is_measured_and_rows_are_summarised(folder, tmp_path):
    sweep = load_sweep(random_sweep(folder, tmp_path, trials=4))
    result = run_sweep(sweep, workers=2)
    assert [row["params"] for row in result.rows] == [{"mean": 1.0}, {"mean": 4.0}]
    assert [row["trials"] for row in result.rows] == [4, 4]
    for row in result.rows:
        assert row["failed"] == 0
        assert row["metrics"]["outcome"]["counts"] == {"final": 4}
        assert row["metrics"]["firings"] == {"mean": 4.0, "sd": 0.0, "n": 4}
        times = [t["metrics"]["time_s"] for t in result.trials if t["row"] == row["params"]["mean"] // 4]
        assert row["metrics"]["time_s"]["mean"] == pytest.approx(sum(times) / len(times), abs=1e-6)
        assert row["metrics"]["waited"]["mean"] == pytest.approx(row["metrics"]["time_s"]["mean"], abs=1e-6)
    # the seeds differ, so the waits do; each trial's wait is its seed's, whatever the row order
    first = [t["metrics"]["time_s"] for t in result.trials if t["row"] == 0]
    assert len(set(first)) == 4


def test_a_trial_depends_only_on_sweep_parameters_and_seed(folder, tmp_path):
    sweep = load_sweep(random_sweep(folder, tmp_path, trials=3))
    once = run_sweep(sweep, workers=1).trials
    again = run_sweep(sweep, workers=2).trials
    strip = lambda trials: [(t["row"], t["seed"], t["metrics"], t["outcome"]) for t in trials]  # noqa: E731
    assert strip(once) == strip(again)
    payload = sweep.payload(sweep.trials()[4])
    assert run_trial(payload)["metrics"] == once[4]["metrics"]


def test_crashes_timeouts_and_exceptions_are_rows_and_the_sweep_goes_on(folder, tmp_path):
    path = write(tmp_path, "odd.yaml", f"""\
        petriflow-sweep: 1
        net: {folder}/odd.yaml
        timeout: 5
        rows:
          - {{crash: 0, sleep: 0, raise: 0}}
          - {{crash: 1, sleep: 0, raise: 0}}
          - {{crash: 0, sleep: 600, raise: 0}}
          - {{crash: 0, sleep: 0, raise: 1}}
          - {{crash: 0, sleep: 0, raise: 0.5}}
        set:
          net.transitions.crash.params.when: "${{crash}}"
          net.transitions.sleep.params.wall: "${{sleep}}"
          net.transitions.raise.params.when: "${{raise}}"
        metrics: [core.outcome]
        """)
    result = run_sweep(load_sweep(path), workers=2)
    status = {t["row"]: (t["status"], t["outcome"]) for t in result.trials}
    assert status[0] == ("ok", "final")
    assert status[1][0] == "crashed"
    assert status[2][0] == "timeout"
    assert status[3] == ("ok", "failed")  # an action's exception is the run's failed outcome
    assert status[4] == ("ok", "failed")
    # a trial whose run ended failed counts as failed (status "run failed"), its metrics kept
    assert [row["failed"] for row in result.rows] == [0, 1, 1, 1, 1]
    assert [row["status"] for row in result.rows] == [{"ok": 1}, {"crashed": 1}, {"timeout": 1},
                                                       {"run failed": 1}, {"run failed": 1}]
    crashed = next(t for t in result.trials if t["row"] == 1)
    assert "exit code 3" in crashed["error"]
    slept = next(t for t in result.trials if t["row"] == 2)
    assert slept["wall"] < 600  # stopped at its timeout, not waited for


def test_a_trials_timeout_counts_from_its_start_not_from_the_queue(folder, tmp_path):
    """Five trials of 1 s on one worker with a 3 s timeout: the last waits over 4 s in
    the queue (plus the worker's start), yet none is recorded as a timeout."""
    path = write(tmp_path, "queue.yaml", f"""\
        petriflow-sweep: 1
        net: {folder}/odd.yaml
        timeout: 3
        trials: 5
        set: {{net.transitions.sleep.params.wall: 1.0}}
        metrics: [core.outcome]
        """)
    result = run_sweep(load_sweep(path), workers=1)
    assert [t["status"] for t in result.trials] == ["ok"] * 5


def test_cli_report_json_csv_and_plot(folder, tmp_path, capsys):
    path = random_sweep(folder, tmp_path, trials=2, extra="paper: {source: Table 0, rows: [{params: {mean: 4.0}, values: {time_s: 3.5}}]}\n")
    code = main(["sweep", str(path), "--json", "--workers", "2", "--csv", str(tmp_path / "r.csv"),
                 "--plot", str(tmp_path / "r.png")])
    assert code == 0
    report = json.loads(capsys.readouterr().out)
    assert report["spec"] == str(path.resolve())
    assert [set(row) for row in report["rows"]] == [{"params", "trials", "failed", "status", "metrics", "paper", "paper_status"}] * 2
    assert report["rows"][1]["paper"] == {"time_s": 3.5}
    assert set(report["rows"][0]["metrics"]["time_s"]) == {"mean", "sd", "n"}
    lines = (tmp_path / "r.csv").read_text().splitlines()
    assert lines[0].startswith("mean,trials,failed,time_s_mean,time_s_sd,time_s_n,time_s_paper")
    assert lines[2].split(",")[5:7] == ["2", "3.5"]
    import cv2

    picture = cv2.imread(str(tmp_path / "r.png"))
    assert picture is not None and picture.shape[0] > 200 and picture.shape[1] > 400
    assert (picture < 250).mean() > 0.02  # something is drawn


def test_cli_text_report_puts_the_paper_beside_the_measured_value(folder, tmp_path, capsys):
    path = random_sweep(folder, tmp_path, trials=2, extra="paper: {rows: [{params: {mean: 4.0}, values: {time_s: 3.5}}]}\n")
    assert main(["sweep", str(path), "--workers", "1"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[1].split()[:5] == ["mean", "trials", "failed", "time_s", "paper"]
    assert out[3].split()[6] == "-" and out[4].split()[6] == "3.5"  # mean, trials, failed, a ± b, paper


def test_failed_trials_make_exit_1_and_are_listed(folder, tmp_path, capsys):
    path = write(tmp_path, "crash.yaml", f"""\
        petriflow-sweep: 1
        net: {folder}/odd.yaml
        set: {{net.transitions.crash.params.when: 1}}
        """)
    assert main(["sweep", str(path), "--workers", "1"]) == 1
    assert "failed: row 1 seed 1: crashed: the worker process died (exit code 3)" in capsys.readouterr().out


def test_results_database_refuses_reuse_and_other_sweeps(folder, tmp_path, capsys):
    path = random_sweep(folder, tmp_path, trials=1)
    db = tmp_path / "results.sqlite"
    assert main(["sweep", str(path), "--db", str(db), "--workers", "1"]) == 0
    capsys.readouterr()
    assert main(["sweep", str(path), "--db", str(db)]) == 2
    assert "already exists; use --resume" in capsys.readouterr().err
    other = write(tmp_path, "other.yaml", path.read_text().replace("time_s: core.end_time", "t: core.end_time"))
    assert main(["sweep", str(other), "--db", str(db), "--resume"]) == 2
    assert "holds the results of another sweep" in capsys.readouterr().err
    (tmp_path / "junk.sqlite").write_text("not a database at all, just text" * 100)
    assert main(["sweep", str(path), "--db", str(tmp_path / "junk.sqlite"), "--resume"]) == 2
    assert "not a petriflow sweep results database" in capsys.readouterr().err
    # more seeds later: only the new trials run
    assert main(["sweep", str(path), "--db", str(db), "--resume", "--trials", "3", "--workers", "1"]) == 0
    assert "4 run now" in capsys.readouterr().out
    with sqlite3.connect(db) as connection:
        assert connection.execute("SELECT COUNT(*), COUNT(DISTINCT params || seed) FROM trials").fetchone() == (6, 6)


def test_as_a_ray_jobs_entrypoint_outputs_need_absolute_paths(folder, tmp_path, capsys, monkeypatch):
    """Under ``ray job submit --working-dir``, the current folder is Ray's temporary
    copy of the working directory: a relative --db, --csv or --plot is refused, one
    line, before any trial runs; absolute ones are written."""
    path = random_sweep(folder, tmp_path, trials=1)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("RAY_JOB_CONFIG_JSON_ENV_VAR", json.dumps(
        {"runtime_env": {"working_dir": "gcs://_ray_pkg_0123456789abcdef.zip"}, "metadata": {}}))
    for flag, name in (("--db", "results.sqlite"), ("--csv", "r.csv"), ("--plot", "r.png")):
        assert main(["sweep", str(path), flag, name, "--workers", "1"]) == 2
        err = capsys.readouterr().err.strip()
        assert err.splitlines() == [err]
        assert f"{flag} {name}: under `ray job submit --working-dir`" in err and f"{flag} /data/{name}" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]
    assert main(["sweep", str(path), "--db", str(tmp_path / "results.sqlite"), "--workers", "1"]) == 0
    assert (tmp_path / "results.sqlite").is_file()
    monkeypatch.setenv("RAY_JOB_CONFIG_JSON_ENV_VAR", json.dumps({"runtime_env": {}, "metadata": {}}))
    assert main(["sweep", str(path), "--db", "again.sqlite", "--workers", "1"]) == 0  # no working_dir: as ever
    assert (tmp_path / "again.sqlite").is_file()


@pytest.mark.parametrize("argv, fragment", [
    (["--workers", "0"], "--workers must be at least 1"),
    (["--trials", "0"], "--trials must be from 1"),
    (["--resume"], "--resume needs --db"),
    (["--plot", "x.svg"], "--plot writes a PNG picture"),
    (["--backend", "slurm"], "invalid choice: 'slurm'"),
])
def test_bad_options_are_exit_2(folder, tmp_path, capsys, argv, fragment):
    path = random_sweep(folder, tmp_path, trials=1)
    with pytest.raises(SystemExit) if "slurm" in argv else _nothing():
        assert main(["sweep", str(path), *argv]) == 2
    assert fragment in capsys.readouterr().err


class _nothing:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def test_resume_after_a_kill_runs_every_trial_exactly_once(folder, tmp_path):
    """SIGKILL to the whole sweep (driver and workers) mid-way; --resume finishes it."""
    path = write(tmp_path, "slow.yaml", f"""\
        petriflow-sweep: 1
        net: {folder}/odd.yaml
        trials: 12
        set: {{net.transitions.sleep.params.wall: 0.25}}
        metrics: [core.end_time]
        """)
    db = tmp_path / "slow.sqlite"
    command = [sys.executable, "-m", "petriflow.cli", "sweep", str(path), "--db", str(db), "--workers", "2"]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True)
    deadline = time.monotonic() + 60
    done = 0
    while time.monotonic() < deadline and done < 3:
        time.sleep(0.1)
        if db.exists():
            try:
                with sqlite3.connect(db) as connection:
                    done = connection.execute("SELECT COUNT(*) FROM trials").fetchone()[0]
            except sqlite3.Error:
                pass
    os.killpg(process.pid, signal.SIGKILL)
    process.wait()
    assert 3 <= done < 12
    finished = subprocess.run(command + ["--resume"], capture_output=True, text=True, timeout=120)
    assert finished.returncode == 0, finished.stderr
    with sqlite3.connect(db) as connection:
        rows = connection.execute("SELECT seed, COUNT(*) FROM trials GROUP BY seed ORDER BY seed").fetchall()
    assert rows == [(seed, 1) for seed in range(1, 13)]


def test_resume_refuses_with_one_line_when_a_file_the_trials_read_changed(folder, tmp_path, capsys):
    """The fingerprint is the files' content: an edited net refuses, a moved project resumes."""
    import shutil

    project = tmp_path / "project"
    project.mkdir()
    (project / "net.yaml").write_text("petriflow: 1\nrun: run.yaml\nplaces: [{id: i, tokens: 1}, o]\ntransitions:"
                                      " [{id: rest, action: core.wait, params: {seconds: 1}, in: [i], out: [o]}]\n")
    (project / "run.yaml").write_text("seed: 0\nuntil: 100\n")
    path = write(project, "edit.yaml", """\
        petriflow-sweep: 1
        net: net.yaml
        trials: 2
        metrics: [core.end_time]
        """)
    db = tmp_path / "results.sqlite"
    assert main(["sweep", str(path), "--db", str(db), "--workers", "1", "--trials", "1"]) == 0
    capsys.readouterr()
    moved = tmp_path / "moved"
    shutil.copytree(project, moved)
    assert main(["sweep", str(moved / "edit.yaml"), "--db", str(db), "--resume", "--workers", "1"]) == 0
    assert "1 run now" in capsys.readouterr().out
    net = moved / "net.yaml"
    net.write_text(net.read_text().replace("seconds: 1", "seconds: 2"))
    assert main(["sweep", str(moved / "edit.yaml"), "--db", str(db), "--resume", "--trials", "3"]) == 2
    err = capsys.readouterr().err
    assert err.strip().splitlines() == [
        f"petriflow: {db}: net.yaml changed since these results were recorded; restore it, or use another --db"]
    (moved / "run.yaml").write_text((moved / "run.yaml").read_text() + "\n")  # the run configuration too
    net.write_text(net.read_text().replace("seconds: 2", "seconds: 1"))
    assert main(["sweep", str(moved / "edit.yaml"), "--db", str(db), "--resume"]) == 2
    assert "run.yaml changed since" in capsys.readouterr().err


def test_resume_runs_crashed_trials_again_and_keeps_the_others(folder, tmp_path, capsys):
    path = random_sweep(folder, tmp_path, trials=2)
    db = tmp_path / "results.sqlite"
    assert main(["sweep", str(path), "--db", str(db), "--workers", "2"]) == 0
    with sqlite3.connect(db) as connection:
        clean = connection.execute("SELECT row, seed, status, metrics FROM trials ORDER BY row, seed").fetchall()
        connection.execute("UPDATE trials SET status = 'crashed', metrics = '{}' WHERE seed = 2")
        connection.execute("UPDATE trials SET wall = -1 WHERE seed = 1")
    capsys.readouterr()
    assert main(["sweep", str(path), "--db", str(db), "--resume", "--workers", "2"]) == 0
    assert "2 run now" in capsys.readouterr().out
    with sqlite3.connect(db) as connection:
        assert connection.execute("SELECT row, seed, status, metrics FROM trials ORDER BY row, seed").fetchall() == clean
        assert connection.execute("SELECT COUNT(*) FROM trials WHERE wall = -1").fetchone() == (2,)  # kept


def test_json_is_the_only_thing_on_standard_output_even_when_a_trial_prints(folder, tmp_path):
    (tmp_path / "chatty_actions.py").write_text(
        "from petriflow import action\n\n@action('chatty.say')\ndef say(ctx):\n"
        "    print('hello from a trial', flush=True)\n    yield 1.0\n")
    (tmp_path / "chatty.yaml").write_text(
        "petriflow: 1\nrun: {actions: [chatty_actions.py]}\nplaces: [{id: i, tokens: 1}, o]\n"
        "transitions: [{id: t, action: chatty.say, in: [i], out: [o]}]\n")
    path = write(tmp_path, "s.yaml", """\
        petriflow-sweep: 1
        net: chatty.yaml
        trials: 2
        metrics: [core.end_time]
        """)
    done = subprocess.run([sys.executable, "-m", "petriflow.cli", "sweep", str(path), "--json", "--workers", "2"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["rows"][0]["trials"] == 2
    assert "hello from a trial" in done.stderr


def test_a_row_parameter_that_is_a_list_is_shown_as_data(tmp_path):
    """A row may set a list (faults of a run configuration); the report prints it as JSON."""
    from petriflow.sweep.report import _number

    assert _number([{"kill": "central", "at": 110}]) == '[{"at":110,"kill":"central"}]'
    assert _number({"a": 1}) == '{"a":1}' and _number(2.5) == "2.5"
