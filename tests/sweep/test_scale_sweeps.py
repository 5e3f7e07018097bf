"""The growth sweeps shipped in nets/: every row builds, with its own generated world, and
every row simulates the same window. (Running them takes minutes: see their headers.)"""

from __future__ import annotations

import math

import pytest

from petriflow import examples
from petriflow.io.files import read_yaml_file
from petriflow.sweep import load_sweep
from petriflow.sweep.trial import build


@pytest.mark.parametrize("scenario, robots, until, main", [
    ("comm", [5, 10, 25], 1000, "maps_complete"),
    pytest.param("bidding", [5, 10, 20, 40, 100], 50, "zones_mapped", marks=pytest.mark.slow),  # ~15 s to build
])
def test_scale_sweeps_pick_a_world_per_row_and_one_window(scenario, robots, until, main):
    sweep = load_sweep(examples.path(scenario, "experiments/scale.yaml"))  # builds (not runs) every row
    trials = sweep.trials()
    assert [t.params["robots"] for t in trials] == robots  # one trial a row
    names = [ref.name for ref in sweep.metrics]
    assert {"cpu_s_per_sim_s", "completed", main} <= set(names)
    for trial in trials:
        built = build(sweep.payload(trial)["sweep"], trial.params, trial.seed)
        assert built.config.until == until
        world = read_yaml_file(built.config.world)
        team = [body["agent"] for body in world["robots"] if body["agent"].startswith("robot")]
        assert team == [f"robot{i + 1}" for i in range(trial.params["robots"])]
        if scenario == "comm":  # the net's maze is the world's
            maze = world["meta"]["maze"]
            assert maze["cols"] == trial.params["cols"] == math.ceil(math.sqrt(12 * trial.params["robots"]))
            assert maze["cell"] == pytest.approx(trial.params["cell"])
