"""The second hour of a user: long work in logs, readable sweep reports."""

from __future__ import annotations

import math
import subprocess
import sys

import pytest

from petriflow.sweep.report import deviation, fixed, text_table
from tests.conftest import NETS

TICKER = """petriflow: 1
places: [{id: p, tokens: 1}, count]
transitions:
  - {id: tick, action: core.wait, params: {seconds: 0.01}, in: [p], out: [p, count]}
"""


def _petriflow(*argv, cwd=None) -> subprocess.CompletedProcess:
    """The command line with standard error a pipe (a log, CI), not a terminal."""
    return subprocess.run([sys.executable, "-m", "petriflow.cli", *map(str, argv)], capture_output=True, text=True,
                          timeout=300, cwd=cwd)


def test_a_run_off_a_terminal_prints_progress_lines_unless_quiet(tmp_path):
    net = tmp_path / "ticker.yaml"
    net.write_text(TICKER)
    done = _petriflow("run", net, "--until", "3000", "--progress-every", "0.05")
    assert done.returncode == 0, done.stderr
    lines = [line for line in done.stderr.splitlines() if line.startswith("ticker: t =")]
    assert lines and "firings" in lines[0] and "s wall" in lines[0]
    quiet = _petriflow("run", net, "--until", "3000", "--progress-every", "0.05", "--quiet")
    assert quiet.returncode == 0 and quiet.stderr == ""


def test_a_sweep_off_a_terminal_says_how_far_it_is():
    done = _petriflow("sweep", NETS / "passage" / "experiments" / "speed.yaml", "--trials", "1", "--workers", "2",
                      "--progress-every", "0.2")
    assert done.returncode == 0, done.stderr
    assert "speed: running 6 trials" in done.stderr
    assert "speed: 6/6 trials done (0 failed)" in done.stderr
    assert "6 trials in 6 rows" in done.stdout


def test_report_precision_follows_the_spread_and_deviation_is_shown():
    assert fixed(36.29, 0.00577) == "36.2900 ± 0.0058"
    assert fixed(18.25, 9.342) == "18.2 ± 9.3"
    assert deviation(516.0, 360) == "+156 (+43.3%)"


def test_a_wide_report_wraps_into_blocks_that_fit_100_columns():
    names = [f"metric_number_{i}" for i in range(12)]
    rows = [{"params": {"robots": n}, "trials": 5, "failed": 0, "status": {"ok": 5},
             "metrics": {name: {"mean": 123.456 * n, "sd": 1.5, "n": 5} for name in names},
             "paper": {names[0]: 100.0 * n}} for n in (1, 2)]
    text = text_table(rows, names, ["robots"])
    assert max(len(line) for line in text.splitlines()) <= 100
    assert text.count("robots") >= 3  # the parameter columns repeat in every block
    assert "deviation" in text and "+23.5 (+23.5%)" in text


def test_a_cycle_of_instant_transitions_names_the_file_the_limit_and_the_cycle():
    done = _petriflow("run", NETS / "philosophers" / "philosophers-5.yaml")
    assert done.returncode == 2
    warning, message = done.stderr.strip().splitlines()  # the token game is said first: nothing is bound
    assert "no transition is bound to an action" in warning
    assert message.startswith(f"petriflow: {NETS / 'philosophers' / 'philosophers-5.yaml'}: more than 100,000")
    assert "FIRINGS_PER_INSTANT" in message and "take_" in message and "release_" in message


def test_small_gaps_of_the_command_line(tmp_path):
    passage = NETS / "passage" / "passage.yaml"
    fired = _petriflow("fire", passage, "nope")
    assert fired.returncode == 2 and "(the net has: red_approach, red_enter" in fired.stderr
    exported = _petriflow("export", passage, "-f", "pnml", "-o", tmp_path / "p.pnml")
    assert exported.returncode == 0 and exported.stdout.strip() == f"wrote {tmp_path / 'p.pnml'}"
    moved = _petriflow("run", tmp_path / "p.pnml")
    assert moved.returncode == 2 and "give it with --config" in moved.stderr
    listed = _petriflow("actions", "core.")
    assert listed.returncode == 0 and listed.stdout.lstrip().startswith("core.")
    assert "gait.walk" not in listed.stdout
    net = tmp_path / "quick.yaml"
    net.write_text("petriflow: 1\nplaces: [{id: i, tokens: 1}, o]\n"
                   "transitions: [{id: t, action: core.wait, params: {seconds: 1000}, in: [i], out: [o]}]\n")
    done = _petriflow("run", net)
    assert "too quick to time" in done.stdout and "x real time" not in done.stdout


# run reports the scenario's metrics and draws its picture ------------------------------

def test_run_prints_the_metrics_its_run_configuration_names(tmp_path):
    done = _petriflow("run", NETS / "passage" / "passage.yaml", "--json")
    assert done.returncode == 0, done.stderr
    import json

    summary = json.loads(done.stdout)
    metrics = summary["metrics"]
    assert set(metrics) == {"time_s", "completed", "blue_enters_s", "red_enters_s"}
    assert metrics["completed"] == 1 and metrics["time_s"] == summary["time"]
    assert 0 < metrics["red_enters_s"] < metrics["time_s"]   # a time_of metric, from the run's events
    text = _petriflow("run", NETS / "passage" / "passage.yaml")
    assert "  metrics:" in text.stdout and "blue_enters_s" in text.stdout


def test_run_metrics_chosen_on_the_command_line_or_none(tmp_path):
    chosen = _petriflow("run", NETS / "passage" / "passage.yaml", "--metrics", "core.firings", "--json")
    assert chosen.returncode == 0, chosen.stderr
    import json

    assert json.loads(chosen.stdout)["metrics"] == {"core.firings": 6}
    none = _petriflow("run", NETS / "passage" / "passage.yaml", "--metrics", "none")
    assert none.returncode == 0 and "metrics:" not in none.stdout


def test_an_unknown_metric_is_one_line_naming_the_file_and_nothing_is_written(tmp_path):
    net = tmp_path / "ticker.yaml"
    net.write_text(TICKER)
    (tmp_path / "run.yaml").write_text("until: 1\nmetrics:\n  - core.firngs\n")
    trace = tmp_path / "out" / "t.jsonl"
    done = _petriflow("run", net, "--trace", trace)
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and "run.yaml:2" in done.stderr and "core.firings" in done.stderr
    assert not trace.exists()
    flag = _petriflow("run", net, "--metrics", "bogus.metric")
    assert flag.returncode == 2 and "unknown metric 'bogus.metric'" in flag.stderr


def test_picture_draws_the_world_and_where_the_robots_went(tmp_path):
    from petriflow.runtime.session import run_files

    out = tmp_path / "pictures" / "passage.png"
    outcome = run_files(NETS / "passage" / "passage.yaml", picture=out)
    assert str(out) in outcome.written and out.stat().st_size > 10_000
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not [p for p in out.parent.iterdir() if p.name != out.name]   # no partial file left


def test_trajectories_follow_the_robots(tmp_path):
    from petriflow.runtime.assembly import open_run, validate
    from petriflow.runtime.session import prepare
    from petriflow.runtime.trajectories import Trajectories
    from petriflow.world import load_world

    prepared = prepare(NETS / "passage" / "passage.yaml")
    world = load_world(prepared.world)
    try:
        binding = validate(prepared.net, prepared.config, binding=prepared.binding, has_world=True)
        track = Trajectories(every=0.25)
        with open_run(prepared.net, binding, prepared.config, seed=1, world=world) as scheduler:
            scheduler.on_instant(track)
            scheduler.run()
            track.sample(world, scheduler.now)
            ends = {agent: world.position(agent) for agent in world.agents}
        assert set(track.paths) == set(world.agents)
        for agent, path in track.paths.items():
            assert path[-1][1:] == pytest.approx(ends[agent])
            steps = [b[0] - a[0] for a, b in zip(path, path[1:])]
            assert all(s > 0 for s in steps) and min(steps[:-1]) >= 0.25 - 1e-9
            assert math.dist(path[0][1:], path[-1][1:]) > 1.0   # they crossed the passage
    finally:
        world.close()


def test_a_picture_without_a_world_is_refused(tmp_path):
    net = tmp_path / "ticker.yaml"
    net.write_text(TICKER)
    done = _petriflow("run", net, "--until", "1", "--picture", tmp_path / "p.png")
    assert done.returncode == 2 and "has none" in done.stderr and not (tmp_path / "p.png").exists()


def test_the_inspection_example_runs_on_its_shipped_site():
    """nets/examples/inspection.yaml needs a camera and two marked robots: its run.yaml
    names the shipped site, so it runs as it is (the camera finds both robots)."""
    from petriflow.runtime.session import run_files

    outcome = run_files(NETS / "examples" / "inspection.yaml", until=2.0, keep_events=True)
    assert outcome.result.error is None and outcome.result.reason == "until"
    ended = {e.transition for e in outcome.events if e.kind == "end" and e.data.get("outcome", "ok") == "ok"}
    assert {"capture", "segment", "dispatch"} <= ended


def test_a_picture_that_cannot_be_written_is_one_error_and_the_trace_is_kept(tmp_path, monkeypatch):
    import petriflow.picture
    from petriflow.errors import NetFormatError
    from petriflow.runtime.session import run_files

    def refuse(world, paths, out, title=""):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(petriflow.picture, "draw_run", refuse)
    trace = tmp_path / "run.jsonl"
    with pytest.raises(NetFormatError, match="cannot write the picture: Permission denied"):
        run_files(NETS / "passage" / "passage.yaml", picture=tmp_path / "p.png", trace=trace)
    assert trace.stat().st_size > 0 and not (tmp_path / "p.png").exists()
    assert [p.name for p in tmp_path.iterdir()] == ["run.jsonl"]


def test_an_output_on_a_file_system_that_refuses_files_is_refused_before_the_run(tmp_path, monkeypatch):
    """Permission bits do not tell everything (the superuser, read-only mounts): the
    check tries to make a file where each output goes, before anything runs."""
    import tempfile

    from petriflow.errors import NetFormatError
    from petriflow.runtime.session import run_files

    made = tempfile.TemporaryFile

    def refusing(*args, dir=None, **kwargs):
        if dir is not None and str(dir).startswith(str(tmp_path / "ro")):
            raise OSError(30, "Read-only file system")
        return made(*args, dir=dir, **kwargs)

    (tmp_path / "ro").mkdir()
    monkeypatch.setattr(tempfile, "TemporaryFile", refusing)
    with pytest.raises(NetFormatError, match="--trace: cannot write into"):
        run_files(NETS / "passage" / "passage.yaml", trace=tmp_path / "ro" / "t.jsonl",
                  db=tmp_path / "run.sqlite")
    assert not (tmp_path / "run.sqlite").exists()
