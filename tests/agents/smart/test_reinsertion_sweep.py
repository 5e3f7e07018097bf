"""The reinsertion sweep's hardest row (nets/smart/experiments/reinsertion.yaml): a 9 N
push shoves Robot3L against the arena's north wall, inside the wall's margin grown by
its radius; the re-plan leads it out of the margin and the trial ends as a measured run."""

from __future__ import annotations

import pytest

from petriflow.examples import path as example_path

pytestmark = pytest.mark.slow


def test_a_9n_push_trial_ends_without_error_and_the_robot_arrives():
    """The 9 N trial runs to the net's final marking: the robot is re-planned from where it
    lies against the wall (dc > r) and walks to its goal."""
    from petriflow.sweep import load_sweep
    from petriflow.sweep.trial import run_trial

    sweep = load_sweep(example_path("smart", "experiments/reinsertion.yaml"))
    trial = [t for t in sweep.trials() if t.params["push_n"] == 9.0 and t.seed == 1][0]
    result = run_trial(sweep.payload(trial))
    assert result["status"] == "ok" and result["error"] is None, result["error"]
    assert result["outcome"] == "final"
    metrics = result["metrics"]
    assert metrics["arrived"] == 1 and metrics["replans"] >= 1
    assert metrics["max_dc_m"] > 0.15   # farther than r from the path: the re-plan rule, not a reinsertion
