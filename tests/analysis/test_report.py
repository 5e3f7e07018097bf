"""``check_net``, its text report, exit codes, and ``petriflow check`` printing them."""

from __future__ import annotations

import json

import pytest

from petriflow.analysis.report import (
    EXIT_OK,
    EXIT_PROBLEM,
    EXIT_UNDECIDED,
    check_net,
    exit_code,
    format_report,
)
from petriflow.classic import dining_philosophers, producer_consumer
from petriflow.cli import main
from petriflow.io.yaml import loads_net

KEYS = {"places", "transitions", "workflow_net", "sound", "bounded", "safe", "deadlock_free",
        "dead_transitions", "live", "states", "edges", "max_tokens_place",
        "max_tokens_marking", "unbounded_places", "violations", "invariants", "algorithm",
        "free_choice", "reversible", "k_bound", "complete"}

WORKFLOW = """
petriflow: 1
net: order
places: [i, p, q, o]
transitions:
  - {id: split, in: [i], out: [p, q]}
  - {id: left, in: [p], out: [o]}
  - {id: right, in: [q], out: [o]}
"""

UNBOUNDED = """
petriflow: 1
net: mailbox
places: [{id: idle, tokens: 1}, mailbox]
transitions:
  - {id: send, in: [idle], out: [idle, mailbox]}
  - {id: read, in: [mailbox], out: []}
"""


def test_result_has_every_key_and_is_json():
    """The result carries the documented keys and serialises to JSON as is."""
    result = check_net(dining_philosophers(5))
    assert KEYS <= set(result)
    assert json.loads(json.dumps(result))["states"] == 11


def test_bounded_net_numbers_follow_the_mcc_meaning():
    """states/edges/max tokens for a 3-slot buffer (4(c+1) states, 8c+4 edges)."""
    result = check_net(producer_consumer(3))
    assert (result["states"], result["edges"]) == (16, 28)
    assert result["max_tokens_place"] == 3 and result["max_tokens_marking"] == 5
    assert result["bounded"] and not result["safe"] and result["k_bound"]["buffer"] == 3
    assert result["deadlock_free"] and result["live"] and result["reversible"]
    assert result["invariants"]["covered_by_p_semiflows"]
    assert exit_code(result) == EXIT_OK


def test_unbounded_net_has_null_counts_and_names_places():
    """An unbounded net: bounded false, counts null, the unbounded places, exit 1."""
    result = check_net(loads_net(UNBOUNDED))
    assert result["bounded"] is False and result["unbounded_places"] == ["mailbox"]
    assert result["states"] is None and result["edges"] is None
    assert result["max_tokens_place"] is None and result["max_tokens_marking"] is None
    kinds = [v["kind"] for v in result["violations"]]
    assert "unbounded" in kinds and exit_code(result) == EXIT_PROBLEM
    assert result["k_bound"] == {"idle": 1, "mailbox": None}


def test_workflow_net_soundness_and_violations():
    """An AND split into an XOR join: unsound, with witnesses, exit 1."""
    result = check_net(loads_net(WORKFLOW))
    assert result["workflow_net"] and result["sound"] is False
    assert result["initial_marking"] == {"i": 1}
    kinds = {v["kind"] for v in result["violations"]}
    assert kinds == {"improper_completion", "no_option_to_complete"}
    witness = next(v for v in result["violations"] if v["kind"] == "improper_completion")
    assert witness["transitions"] == ["split", "left"]
    assert exit_code(result) == EXIT_PROBLEM


def test_deadlock_in_a_plain_net_is_a_violation():
    """A non-WF net with a deadlock: deadlock_free false, a 'deadlock' witness, exit 1."""
    net = loads_net("""
petriflow: 1
places: [{id: a, tokens: 1}, b, c]
transitions: [{id: go, in: [a], out: [b]}, {id: back, in: [b], out: [a]}, {id: stop, in: [b], out: [c]}]
""")
    result = check_net(net)
    deadlock = next(v for v in result["violations"] if v["kind"] == "deadlock")
    assert deadlock["transitions"] == ["go", "stop"] and deadlock["marking"] == {"c": 1}
    assert result["deadlock_free"] is False and exit_code(result) == EXIT_PROBLEM


def test_state_limit_gives_an_incomplete_result_and_exit_2():
    """Beyond max_states: complete false, an error message, exit 2; structure still there."""
    result = check_net(dining_philosophers(12), max_states=50)
    assert result["complete"] is False and "max_states=50" in result["error"]
    assert result["states"] is None and result["invariants"]["p_semiflows"]
    assert exit_code(result) == EXIT_UNDECIDED
    assert "UNDECIDED" in format_report(result)


def test_format_report_is_short_and_readable():
    """The text report starts with the verdict and lists violations with witnesses."""
    text = format_report(check_net(loads_net(WORKFLOW)))
    lines = text.splitlines()
    assert lines[0] == "order: 4 places, 3 transitions -- PROBLEM"
    assert any("witness: split left" in line for line in lines)
    assert len(lines) < 20


def test_format_report_of_an_unbounded_net():
    """The text report names the unbounded places."""
    assert "UNBOUNDED: places mailbox" in format_report(check_net(loads_net(UNBOUNDED)))


@pytest.mark.parametrize("as_json", [False, True])
def test_check_command_prints_and_returns_the_exit_code(tmp_path, capsys, as_json):
    """petriflow check loads the file, prints the report (or JSON) and returns the exit code."""
    path = tmp_path / "order.yaml"
    path.write_text(WORKFLOW)
    code = main(["check", str(path)] + (["--json"] if as_json else []))
    out = capsys.readouterr().out
    assert code == EXIT_PROBLEM
    if as_json:
        assert json.loads(out)["sound"] is False
    else:
        assert out.startswith("order:")


def test_check_command_state_limit_message(tmp_path, capsys):
    """With --max-states too small: one line on stderr, exit 2, JSON with complete false."""
    path = tmp_path / "big.yaml"
    from petriflow.io.yaml import dumps_net

    path.write_text(dumps_net(dining_philosophers(10)))
    code = main(["check", str(path), "--json", "--max-states", "20"])
    captured = capsys.readouterr()
    assert code == EXIT_UNDECIDED
    assert json.loads(captured.out)["complete"] is False
    error_lines = captured.err.strip().splitlines()
    assert len(error_lines) == 1 and "max_states=20" in error_lines[0]


def test_check_command_rejects_a_bad_limit(tmp_path, capsys):
    """--max-states 0 is bad input: one line, exit 2."""
    path = tmp_path / "order.yaml"
    path.write_text(WORKFLOW)
    assert main(["check", str(path), "--max-states", "0"]) == 2
    assert "max-states" in capsys.readouterr().err


def test_check_command_json_counts_states(tmp_path, capsys):
    path = tmp_path / "philosophers.yaml"
    from petriflow.io.yaml import dumps_net

    path.write_text(dumps_net(dining_philosophers(4)))
    assert main(["check", str(path), "--json", "--max-states", "1000"]) == EXIT_OK
    assert json.loads(capsys.readouterr().out)["states"] == 7
