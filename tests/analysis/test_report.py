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
    result = check_net(dining_philosophers(12), max_states=50, method="explicit")
    assert result["complete"] is False and "max_states=50" in result["error"]
    assert result["states"] is None and result["invariants"]["p_semiflows"]
    assert exit_code(result) == EXIT_UNDECIDED
    assert "UNDECIDED" in format_report(result)
    # --method auto goes on with stubborn sets: no dead marking, bounded: a verdict
    auto = check_net(dining_philosophers(12), max_states=200)     # 322 markings in all
    assert auto["complete"] is False and auto["stuck_markings"] == 0
    assert auto["methods"]["stuck_markings"] == "stubborn" and exit_code(auto) == 0


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
    code = main(["check", str(path), "--json", "--max-states", "20", "--method", "explicit"])
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


# Budgets: invariants, unboundedness first, partial answers ------------------------------

def test_unbounded_net_with_a_large_bounded_part_at_the_default_budget():
    """The pump is three firings away but the bounded part has 2**20 markings: the former
    check found the pump and then built a Python coverability graph with the 2,000,000
    node budget of the state space (minutes, a gigabyte). Now the depth-first search
    answers at the default settings, with the places (exact: the P-semiflows bound all
    the others) and a witness that replays."""
    import time

    from petriflow.engine import fire_sequence
    from petriflow.marking import Marking
    from tests.analysis.nets import pumped_after_bounded

    net = pumped_after_bounded(20, 2)
    started = time.process_time()
    result = check_net(net)
    assert time.process_time() - started < 20
    assert result["bounded"] is False and result["complete"] is True
    assert result["unbounded_places"] == ["heap"] and result["unbounded_places_complete"] is True
    assert result["states"] is None and exit_code(result) == EXIT_PROBLEM
    witness = next(v for v in result["violations"] if v["kind"] == "unbounded")
    assert witness["transitions"] == ["step_0", "step_1", "pump"]
    assert fire_sequence(net, net.initial_marking, witness["transitions"]) == Marking(witness["marking"])
    assert result["coverability"]["budget"] == 100_000
    text = format_report(result)
    assert "UNBOUNDED: places heap" in text and "witness: step_0 step_1 pump" in text


def test_unbounded_places_are_marked_incomplete_when_undecided():
    """Without P-semiflows to bound the rest and with a tiny coverability budget, the
    places named are 'at least' these."""
    from tests.analysis.nets import pumped_after_bounded

    result = check_net(pumped_after_bounded(6, 1), max_coverability=5, invariant_budget=0)
    assert result["bounded"] is False and "heap" in result["unbounded_places"]
    assert result["unbounded_places_complete"] is False
    assert "(at least" in format_report(result)


def test_a_deadlock_found_before_the_limit_is_reported():
    """A deadlock one firing from the start, in a net of 2**16 markings explored to 1000:
    the deadlock, with its witness, is a definite answer (exit 1); what stays undecided
    is listed."""
    from tests.analysis.nets import deadlock_beyond_limit

    result = check_net(deadlock_beyond_limit(16), max_states=1000)
    assert result["complete"] is False and "max_states=1000" in result["error"]
    deadlock = next(v for v in result["violations"] if v["kind"] == "deadlock")
    assert deadlock["transitions"] == ["all_stop"] and deadlock["marking"] == {"stopped": 1}
    assert result["deadlock_free"] is False and result["states"] is None
    assert result["partial"]["states_explored"] == 1000
    assert result["partial"]["deadlock_markings_found"] >= 1
    assert "all_stop" in result["partial"]["not_dead_transitions"]
    assert {"states", "live", "dead_transitions"} <= set(result["undecided"])
    assert "deadlock_free" not in result["undecided"]
    # P-semiflows bound every place by 1: bounded and safe without the state space
    assert result["bounded"] is True and result["safe"] is True
    assert "bounded" not in result["undecided"] and "safe" not in result["undecided"]
    assert exit_code(result) == EXIT_PROBLEM
    text = format_report(result)
    assert "PROBLEM" in text.splitlines()[0] and "found before the limit" in text
    assert "witness: all_stop" in text
    assert "  deadlock-free: no (state space, found before the limit; witness below)" in text
    assert "  live: undecided (state space over --max-states=1000)" in text
    assert text.splitlines()[-1].startswith("  note: live, reversible, dead transitions undecided")


def test_a_place_over_its_bound_found_before_the_limit_is_reported():
    """A buffer that has already held 2 tokens is not safe, whatever is left to explore."""
    result = check_net(producer_consumer(400), max_states=40)
    assert result["complete"] is False and result["safe"] is False
    assert result["partial"]["k_bound_at_least"]["buffer"] >= 2
    assert result["partial"]["max_tokens_place_at_least"] >= 2
    assert result["bounded"] is True and "bounded" not in result["undecided"]   # by P-semiflows
    assert exit_code(result) == EXIT_UNDECIDED
    unproven = check_net(producer_consumer(400), max_states=40, invariant_budget=0,
                         max_coverability=10)
    assert unproven["bounded"] is None and "bounded" in unproven["undecided"]
    assert unproven["safe"] is False
    assert "not safe" in format_report(result)


def test_a_workflow_net_improper_completion_found_before_the_limit():
    """A WF-net whose improper completion is near [i] but whose state space is large:
    unsound (exit 1) from what was explored."""
    lines = ["petriflow: 1", "places: [i, o, done, " + ", ".join(f"a{k}, b{k}" for k in range(14)) + "]",
             "transitions:",
             "  - {id: split, in: [i], out: [done, " + ", ".join(f"a{k}" for k in range(14)) + "]}",
             "  - {id: early, in: [done], out: [o]}",
             "  - {id: finish, in: [" + ", ".join(f"a{k}" for k in range(14)) + "], out: [o]}"]
    for k in range(14):
        lines += [f"  - {{id: go{k}, in: [a{k}], out: [b{k}]}}", f"  - {{id: back{k}, in: [b{k}], out: [a{k}]}}"]
    result = check_net(loads_net("\n".join(lines) + "\n"), max_states=200)
    assert result["complete"] is False and result["workflow_net"]
    assert result["sound"] is False and "sound" not in result["undecided"]
    improper = next(v for v in result["violations"] if v["kind"] == "improper_completion")
    assert improper["transitions"] == ["split", "early"]
    assert exit_code(result) == EXIT_PROBLEM


def test_invariants_over_budget_are_not_computed_and_check_goes_on():
    """Lamport's fast mutex for 3 processes: T-semiflows over budget, said so; the state
    space and every other answer are there."""
    from tests.analysis.nets import lamport_fast_mutex

    result = check_net(lamport_fast_mutex(3))
    assert result["states"] == 9737 and result["deadlock_free"] is True
    assert result["invariants"]["t_semiflows"] is None
    assert result["invariants"]["not_computed"]["t_semiflows"] == "over budget"
    assert result["invariants"]["covered_by_p_semiflows"] is True
    assert "T-semiflows: not computed (over budget)" in format_report(result)
    skipped = check_net(lamport_fast_mutex(2), invariant_budget=0)
    assert skipped["invariants"]["p_semiflows"] is None and skipped["states"] == 310
    assert "P-semiflows: not computed (skipped)" in format_report(skipped)


def test_check_command_budget_options(tmp_path, capsys):
    """--max-coverability and --invariant-budget reach check_net; negative values are bad input."""
    path = tmp_path / "mailbox.yaml"
    path.write_text(UNBOUNDED)
    assert main(["check", str(path), "--json", "--max-coverability", "0", "--invariant-budget", "0"]) == EXIT_PROBLEM
    result = json.loads(capsys.readouterr().out)
    assert result["coverability"] is None and result["bounded"] is False
    assert result["invariants"]["not_computed"] == {"p_semiflows": "skipped", "t_semiflows": "skipped"}
    assert main(["check", str(path), "--max-coverability", "-1"]) == 2
    assert "--max-coverability must be >= 0" in capsys.readouterr().err


# The text names each verdict with the method that decided it -------------------------

SEQUENCE = """
petriflow: 1
net: sequence
places: [i, a, o]
transitions: [{id: t1, in: [i], out: [a]}, {id: t2, in: [a], out: [o]}]
"""


def test_check_text_of_a_deadlock_decided_past_the_state_limit(tmp_path, capsys):
    """Issue 40: the textbook philosophers (not a WF-net, a deadlock 30 firings deep) with
    the exploration stopped at --max-states: stubborn sets decide the deadlock. The text
    gives each verdict with its method (no line reads as 'sound' or 'deadlock_free'), the
    exit code is 1 and the limit is a note on the last line, not an error on stderr."""
    from petriflow.io.yaml import dumps_net
    from tests.analysis.nets import philosophers_one_fork

    path = tmp_path / "philosophers.yaml"
    path.write_text(dumps_net(philosophers_one_fork(30)))
    code = main(["check", str(path), "--max-states", "2000"])
    captured = capsys.readouterr()
    assert code == EXIT_PROBLEM and captured.err == ""
    lines = captured.out.splitlines()
    assert lines[0].endswith("-- PROBLEM")
    for expected in ("  sound: no (WF-net structure)",
                     "  bounded: yes (P-semiflows), safe",
                     "  deadlock-free: no (stubborn sets; witness below)",
                     "  live: undecided (state space over --max-states=2000)",
                     "  reversible: undecided (state space over --max-states=2000)"):
        assert expected in lines
    assert any(line.startswith("  dead transitions: undecided (state space over --max-states=2000)")
               for line in lines)
    # nothing reads as a verdict the net does not have
    assert "deadlock_free" not in captured.out and "method (" not in captured.out
    assert all(line.startswith("  sound: no") for line in lines if "sound" in line)
    assert lines[-1] == ("  note: live, reversible, dead transitions undecided (state space over"
                         " --max-states=2000); the verdict (a deadlock) does not depend on them")
    deadlock = next(k for k, line in enumerate(lines) if line.startswith("  - deadlock: "))
    assert lines[deadlock + 1].startswith("      witness: take_left_0")
    # --json: the same verdicts, nothing on stderr either
    assert main(["check", str(path), "--max-states", "2000", "--json"]) == EXIT_PROBLEM
    captured = capsys.readouterr()
    result = json.loads(captured.out)
    assert captured.err == "" and result["complete"] is False
    assert (result["sound"], result["deadlock_free"], result["methods"]["deadlock_free"]) == (
        False, False, "stubborn")


def test_check_text_of_a_sound_workflow_net_says_why_it_is_not_live():
    """A sound WF-net deadlocks, is not live and not reversible, as given: the final
    marking is dead. The text says so beside each verdict, and that the short-circuited
    net (o back to i) is deadlock-free, live and reversible; the JSON keeps the verdicts
    for the net as given."""
    result = check_net(loads_net(SEQUENCE))
    assert (result["sound"], result["deadlock_free"], result["live"], result["reversible"]) == (
        True, False, False, False)
    assert result["final_marking"] == {"o": 1}
    lines = format_report(result).splitlines()
    assert lines[0] == "sequence: 3 places, 2 transitions -- OK"
    for expected in (
            "  sound: yes (state space; the Rank Theorem agrees)",
            "  deadlock-free: no (state space) -- only at the final marking o=1, where a run ends",
            "  live: no (state space) -- no transition fires again once the final marking o=1 is reached",
            "  reversible: no (state space) -- the initial marking i=1 is not reached again from the"
            " final marking o=1",
            "    (short-circuited, o connected back to i as WF-net tools analyse it: deadlock-free,"
            " live and reversible, as soundness implies)",
            "  dead transitions: none (state space)"):
        assert expected in lines
    # decided on the stubborn-set graph alone: the same reasons, exit 0, no error line
    stubborn = check_net(loads_net(SEQUENCE), method="stubborn")
    text = format_report(stubborn)
    assert exit_code(stubborn) == EXIT_OK and stubborn["complete"] is False
    assert "  deadlock-free: no (stubborn sets) -- only at the final marking o=1, where a run ends" in text
    assert text.splitlines()[-1] == ("  note: --method stubborn builds no full state space; every"
                                     " property above was decided without it")


def test_check_command_with_method_stubborn_on_a_sound_net_prints_no_error(tmp_path, capsys):
    """A verdict reached without the full state space is an answer: exit 0, stderr empty."""
    path = tmp_path / "sequence.yaml"
    path.write_text(SEQUENCE)
    assert main(["check", str(path), "--method", "stubborn"]) == EXIT_OK
    captured = capsys.readouterr()
    assert captured.err == "" and "  sound: yes (stubborn sets)" in captured.out


def test_an_unsound_workflow_net_gets_no_run_end_reasons():
    """The reasons beside deadlock-free, live and reversible are only for sound WF-nets
    (and nets whose one dead marking is their declared final marking)."""
    text = format_report(check_net(loads_net(WORKFLOW)))
    assert "  sound: no (state space; the Rank Theorem agrees; witnesses below)" in text
    assert "where a run ends" not in text and "short-circuited" not in text


def test_a_net_ending_in_its_declared_final_marking_says_so():
    """Not a WF-net; its only dead marking is its declared final marking (exit 0)."""
    from petriflow.io import load_net

    result = check_net(load_net("nets/passage/passage.yaml"))
    text = format_report(result)
    assert exit_code(result) == EXIT_OK and result["final_marking"] == {
        "red_done": 1, "blue_done": 1, "mutex": 1}
    assert ("  deadlock-free: no (state space up to symmetry) -- only at the declared final marking"
            " blue_done=1, mutex=1, red_done=1, where a run ends") in text.splitlines()
    assert "short-circuited" not in text


def test_check_text_when_nothing_decisive_was_found(tmp_path, capsys):
    """Deadlocks undecided at --max-states (explicit, no stubborn sets): exit 2, each open
    property says undecided and why, the last line says there is no verdict, and the limit
    is the one line on stderr."""
    from petriflow.io.yaml import dumps_net

    path = tmp_path / "philosophers.yaml"
    path.write_text(dumps_net(dining_philosophers(12)))
    code = main(["check", str(path), "--max-states", "50", "--method", "explicit"])
    captured = capsys.readouterr()
    assert code == EXIT_UNDECIDED
    lines = captured.out.splitlines()
    assert lines[0].endswith("-- UNDECIDED")
    assert "  deadlock-free: undecided (state space over --max-states=50)" in lines
    assert "  live: undecided (state space over --max-states=50)" in lines
    assert lines[-1] == "  no verdict: deadlock-free undecided (state space over --max-states=50)"
    error_lines = captured.err.strip().splitlines()
    assert len(error_lines) == 1 and "max_states=50" in error_lines[0]


def test_every_verdict_line_without_the_methods_key():
    """check_net(method=None) (the explicit exploration, no ``methods``) still names one."""
    text = format_report(check_net(producer_consumer(2), method=None))
    assert "  bounded: yes (P-semiflows), 2-bounded" in text
    assert "  deadlock-free: yes (state space)" in text and "  live: yes (state space)" in text
