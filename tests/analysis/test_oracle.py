"""The analyses on real-world PNML files with known answers (tests/data/oracle).

Each folder holds a net and an ``answer.json``: MCC models with the contest's published
StateSpace answers, dialect samples, workflow nets with a soundness verdict, and an
unbounded net. The few nets that may not be copied into the tests run when the shared
corpus is beside the project, and skip saying so otherwise.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import pytest

from petriflow.analysis.report import check_net

from tests.conftest import oracle_cases

CASES = oracle_cases(legal_only=True)


def load(case: Path):
    pytest.importorskip("petriflow.io.pnml")
    from petriflow.io import load_net

    answer = json.loads((case / "answer.json").read_text())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")   # dialect warnings (GSPN timing, data guards...)
        net = load_net(case / answer["file"])
    return net, answer


def published_state_space(case: Path) -> dict[str, int]:
    """The MCC StateSpace lines of oracle-StateSpace.out: STATES, TRANSITIONS, ..."""
    values = {}
    for line in (case / "oracle-StateSpace.out").read_text().splitlines():
        parts = line.split()
        if len(parts) >= 3 and parts[0] == "STATE_SPACE":
            values[parts[1]] = int(parts[2])
    return values


@pytest.mark.parametrize("case", CASES)
def test_answers_match(case):
    """states, edges, max tokens, safe, bounded, sound, WF-ness as in answer.json."""
    net, answer = load(case)
    result = check_net(net)
    details = answer.get("details") or {}
    expected = {k: answer[k] for k in ("states", "edges", "max_tokens_place",
                                       "max_tokens_marking", "safe", "bounded", "sound",
                                       "unbounded_places") if k in answer}
    expected.update({k: details[k] for k in ("states", "edges", "safe", "bounded",
                                             "max_tokens_place") if k in details})
    if "is_wf_net" in answer:
        expected["workflow_net"] = answer["is_wf_net"]
    if "deadlock_reachable" in answer:
        expected["deadlock_free"] = not answer["deadlock_reachable"]
    if "live" in answer:
        expected["live"] = answer["live"]
    if "dead_transitions" in details:
        expected["dead_transitions"] = details["dead_transitions"]
    got = {k: result[k] for k in expected}
    assert got == expected


MCC = [c for c in CASES if c.id.startswith("mcc/")]


@pytest.mark.parametrize("case", MCC)
def test_mcc_published_state_space(case):
    """The Model Checking Contest's StateSpace answers, straight from oracle-StateSpace.out."""
    net, _ = load(case)
    result = check_net(net)
    published = published_state_space(case)
    assert (result["states"], result["edges"], result["max_tokens_place"],
            result["max_tokens_marking"]) == (
        published["STATES"], published["TRANSITIONS"], published["MAX_TOKEN_IN_PLACE"],
        published["MAX_TOKEN_PER_MARKING"])


UNSOUND_WORKFLOWS = [c for c in CASES if c.id.startswith("workflow/")]


@pytest.mark.parametrize("case", UNSOUND_WORKFLOWS)
def test_workflow_violations_have_replayable_witnesses(case):
    """Every violation witness of an oracle workflow net fires from [i] to its marking."""
    from petriflow.engine import fire_sequence
    from petriflow.marking import Marking

    net, answer = load(case)
    result = check_net(net)
    for violation in result["violations"]:
        if violation["transitions"]:
            start = Marking(result["initial_marking"])
            assert fire_sequence(net, start, violation["transitions"]) == Marking(
                violation["marking"])
    if answer.get("reason") and "improper completion" in answer["reason"]:
        assert "improper_completion" in {v["kind"] for v in result["violations"]}
