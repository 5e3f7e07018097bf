"""Nets drawn in other tools (WoPeD, PM4Py), run as they are: one final-marking rule for
``run`` and ``check``, the tools' names in traces and replays, a warning when nothing is
bound, and actions bound by a run configuration without editing the file."""

from __future__ import annotations

import json
import re
import shutil

import pytest

from petriflow.cli import main
from tests.conftest import ORACLE

INSURANCE = ORACLE / "workflow" / "woped-Insurance" / "Insurance.pnml"  # unsound, no final marking declared
DATA_NET = ORACLE / "dialects" / "pm4py-data_petri_net" / "data_petri_net.pnml"  # labels on PNML ids


def _json(capsys, *argv: str) -> tuple[int, dict]:
    code = main([*argv, "--json"])
    return code, json.loads(capsys.readouterr().out)


def test_run_and_check_end_a_wf_net_without_a_final_marking_at_its_sink(capsys):
    """WoPeD declares no final marking: ``check`` decides soundness for [o] and ``run`` holds
    the run to the same marking, so the unsound net's dead end is a problem (exit 1)."""
    code, checked = _json(capsys, "check", str(INSURANCE))
    assert code == 1 and checked["sound"] is False
    code, ran = _json(capsys, "run", str(INSURANCE))
    assert ran["final_marking"] == checked["final_marking"] == {checked["sink_place"]: 1}
    assert ran["reason"] == "dead" and code == 1
    main(["run", str(INSURANCE)])
    assert "(the file declares none: the WF-net's sink)" in capsys.readouterr().out


def test_a_run_of_a_net_with_nothing_bound_says_so(capsys, tmp_path):
    """A net whose transitions bind no action fires each at once: the run warns, naming
    them by the labels the tool gave (PNML ids alone say nothing)."""
    from petriflow.runtime.session import run_files

    with pytest.warns(UserWarning, match="no transition is bound to an action") as caught:
        run_files(DATA_NET)
    unbound = next(str(w.message) for w in caught if "no transition is bound" in str(w.message))
    assert re.search(r": (\w+, )*[A-Z][\w ]+ \(n\d+\)", unbound)  # a label, its PNML id beside it
    assert main(["run", str(INSURANCE)]) == 1
    assert "no transition is bound to an action" in capsys.readouterr().err


def test_replay_names_transitions_by_their_labels(capsys, tmp_path):
    trace = tmp_path / "t.jsonl"
    assert main(["run", str(DATA_NET), "--trace", str(trace)]) == 0
    capsys.readouterr()
    assert main(["replay", str(trace)]) == 0
    out = capsys.readouterr().out
    assert "fire   Create Fine (n18)" in out


def test_a_run_configuration_binds_a_foreign_nets_transitions_by_label(capsys, tmp_path):
    """``bind:`` puts actions on a net's transitions without editing its file; a label
    names every transition that carries it (WoPeD's XOR split 'send letter' is two)."""
    net = tmp_path / "Insurance.pnml"
    shutil.copy(INSURANCE, net)
    (tmp_path / "run.yaml").write_text("bind:\n  policy: {action: core.wait, params: {seconds: 30}}\n"
                                       "  send letter: {action: core.wait, params: {seconds: 5}}\n")
    code, ran = _json(capsys, "run", str(net))
    assert ran["time"] == 30.0
    trace = tmp_path / "t.jsonl"
    main(["run", str(net), "--trace", str(trace)])
    capsys.readouterr()
    starts = [json.loads(line) for line in trace.read_text().splitlines()]
    assert {e["transition"] for e in starts if e["kind"] == "start"} >= {"t4_op_1"}
    assert main(["info", str(net), "--json"]) == 0
    actions = json.loads(capsys.readouterr().out)["actions"]
    assert actions["t7_op_1"] == actions["t7_op_2"] == "core.wait"


@pytest.mark.parametrize("entry, message", [
    ("polcy: core.wait", "bind: 'polcy' is neither a transition nor a transition's label"),
    ("policy: {action: core.wiat}", "unknown action 'core.wiat' (did you mean 'core.wait'"),
    ("policy: {action: core.wait, params: {secs: 3}}", "no parameter 'secs' (did you mean 'seconds'?)"),
    ("policy: {action: core.wait, every: 3}", "takes an action name"),
])
@pytest.mark.parametrize("command", ["run", "check", "info"])
def test_a_bad_binding_is_refused_at_its_line_in_the_configuration(capsys, tmp_path, entry, message, command):
    net = tmp_path / "Insurance.pnml"
    shutil.copy(INSURANCE, net)
    (tmp_path / "run.yaml").write_text(f"seed: 1\nbind:\n  {entry}\n")
    assert main([command, str(net)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"petriflow: {tmp_path / 'run.yaml'}:3:") and message in err
    assert len(err.splitlines()) == 1
