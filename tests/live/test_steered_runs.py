"""A run steered through ``petriflow ctl``: the interventions are in the trace and the
journal, ``petriflow view`` and ``replay`` show them, and ``--resume`` of the steered
run's journal re-executes it event for event."""

from __future__ import annotations

import json
import time

import pytest

from petriflow.cli import main
from petriflow.runtime.replay import markings
from petriflow.runtime.trace import read_trace

pytest.importorskip("websockets")


def ctl(capsys, url: str, *words: str) -> tuple[int, str]:
    code = main(["ctl", url, *words, "--by", "tester"])
    return code, capsys.readouterr().out.strip()


def test_a_steered_run_is_in_its_trace_and_resumes_identically(live_run, capsys, tmp_path):
    """Step, inject, force-fail, a breakpoint, resume: each a control event; the trace
    replays to the run's final marking, the page holds the events, and resuming the
    journal re-executes the run to the same trace, byte for byte."""
    run = live_run("--paused")
    assert ctl(capsys, run.url, "step") == (0, "step applied at t=0 s")
    assert ctl(capsys, run.url, "inject", "spare", "2")[0] == 0
    assert ctl(capsys, run.url, "force", "work", "failed")[0] == 0
    assert ctl(capsys, run.url, "break", "place", "done", ">=", "2")[0] == 0
    code, said = ctl(capsys, run.url, "remove", "spare", "7")
    assert code == 1 and said == "refused: place 'spare' holds 2 tokens, not 7"
    assert ctl(capsys, run.url, "resume")[0] == 0
    deadline = time.monotonic() + 60
    while "paused" not in ctl(capsys, run.url, "status")[1]:
        assert time.monotonic() < deadline, "the breakpoint did not pause the run"
        time.sleep(0.1)
    assert ctl(capsys, run.url, "resume")[0] == 0
    run.finish()
    events = read_trace(run.trace)
    actions = [e.data["action"] for e in events if e.kind == "control"]
    assert actions == ["step", "inject", "force", "break", "resume", "hit", "resume"]
    assert all(e.data["by"] == "tester" for e in events if e.kind == "control" and e.data["action"] != "hit")
    final = list(markings(events))[-1][1].to_dict()
    assert final == events[-1].data["marking"] == {"bad": 1, "done": 4}

    resumed = tmp_path / "resumed.jsonl"
    copy = tmp_path / "copy.db"
    copy.write_bytes(run.db.read_bytes())
    assert main(["run", "--resume", "--db", str(copy), "--trace", str(resumed), "--quiet"]) in (0, 1)
    assert "re-executing it, checked against the journal" in capsys.readouterr().err
    assert resumed.read_bytes() == run.trace.read_bytes()

    page = tmp_path / "page.html"
    assert main(["view", str(run.trace), "-o", str(page)]) == 0
    from petriflow.view.run_page import model

    replayed = model(events)
    counts: dict[str, int] = {}
    for p, n in zip(replayed["d_place"], replayed["d_n"]):
        counts[replayed["places"][p]] = counts.get(replayed["places"][p], 0) + n
    assert {p: n for p, n in counts.items() if n} == final


def test_ctl_errors_are_one_line_with_exit_2(capsys):
    """A malformed command or URL, or a run not there: one line, exit 2."""
    for words in (["http://127.0.0.1:9/?token=x", "jump"], ["not a url", "pause"],
                  ["http://127.0.0.1:9/?token=x", "inject"], ["http://127.0.0.1:9/?token=x", "pause"]):
        assert main(["ctl", *words]) == 2
        err = capsys.readouterr().err
        assert err.startswith("petriflow: ctl") and err.count("\n") == 1, err


def test_breakpoints_in_the_run_configuration_are_checked(tmp_path, capsys):
    """`breakpoints:` naming nothing in the net is a file:line error before the run."""
    (tmp_path / "net.yaml").write_text(
        "petriflow: 1\nrun:\n  breakpoints: [failed, place dne >= 1]\nplaces: [{id: i, tokens: 1}, o]\n"
        "transitions: [{id: t, in: [i], out: [o]}]\n")
    assert main(["run", str(tmp_path / "net.yaml"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "no place 'dne'" in err and "net.yaml:" in err, err
    (tmp_path / "net.yaml").write_text(
        "petriflow: 1\nrun:\n  breakpoints: [place o >= 1]\nplaces: [{id: i, tokens: 1}, o]\n"
        "transitions: [{id: t, in: [i], out: [o]}]\n")
    assert main(["run", str(tmp_path / "net.yaml"), "--quiet", "--trace", str(tmp_path / "t.jsonl"), "--json"]) == 0
    hits = [e for e in read_trace(tmp_path / "t.jsonl") if e.kind == "control"]
    assert [e.data["spec"] for e in hits] == ["place o >= 1"]  # recorded; nobody to pause for
    json.loads(capsys.readouterr().out)


def test_a_bad_breakpoint_in_an_inline_run_section_names_its_own_line(tmp_path, capsys):
    """A net's inline ``run:`` section: a breakpoint of bad syntax, or naming no place, is
    reported at its own line (not the ``run:`` line); so is one in a run file."""
    head = "petriflow: 1\nplaces: [{id: i, tokens: 1}, o]\ntransitions: [{id: t, in: [i], out: [o]}]\n"
    for bad, message in (("when done", "not a breakpoint: 'when done'"), ("place dne >= 1", "no place 'dne'")):
        (tmp_path / "net.yaml").write_text(head + f"run:\n  seed: 1\n  breakpoints:\n    - failed\n    - {bad}\n")
        assert main(["run", str(tmp_path / "net.yaml"), "--quiet"]) == 2
        err = capsys.readouterr().err
        assert "net.yaml:8: " in err and message in err and err.count("\n") == 1, err
        (tmp_path / "run.yaml").write_text(f"seed: 1\nbreakpoints: [failed,\n  {bad}]\n")
        (tmp_path / "net.yaml").write_text(head)
        assert main(["run", str(tmp_path / "net.yaml"), "--config", str(tmp_path / "run.yaml"), "--quiet"]) == 2
        err = capsys.readouterr().err
        assert "run.yaml:3: " in err and message in err, err
