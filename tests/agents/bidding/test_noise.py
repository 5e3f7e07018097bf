"""Seed 004's simulator noise: Stage 3.2's odometry error model, the robots' belief
against the truth in a mission, and eq. 10 by what the beams hit."""

from __future__ import annotations

import math
import random

import pytest
import yaml

from petriflow import examples
from petriflow.agents.bidding.errors import BiddingError
from petriflow.agents.bidding.grid import GlobalMap, Grid, accuracy, fictitious
from petriflow.agents.bidding.nets import build
from petriflow.agents.bidding.odometry import STAGE_ODOM_ERROR, Odometry, draw_errors
from petriflow.io.yaml import dumps_net

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")


def test_errors_are_drawn_uniformly_within_half_the_limits_from_the_seed():
    draws = [draw_errors(STAGE_ODOM_ERROR, random.Random(seed)) for seed in range(400)]
    for axis, limit in enumerate(STAGE_ODOM_ERROR):
        values = [d[axis] for d in draws]
        assert all(-limit / 2 <= v <= limit / 2 for v in values)
        # spread over the whole interval, both signs (uniform, not a constant)
        assert min(values) < -0.4 * limit and max(values) > 0.4 * limit
    assert draw_errors(STAGE_ODOM_ERROR, random.Random(7)) == draw_errors(STAGE_ODOM_ERROR, random.Random(7))
    assert draw_errors(STAGE_ODOM_ERROR, random.Random(7)) != draw_errors(STAGE_ODOM_ERROR, random.Random(8))
    with pytest.raises(BiddingError, match="odom_error"):
        draw_errors((0.03, 0.03), random.Random(1))


def test_odometry_scales_the_integrated_distance_and_turn_by_its_errors():
    odo = Odometry((0.0, 0.0, 0.0), errors=(0.02, 0.0, 0.0))
    for _ in range(100):
        odo.integrate(0.4, 0.0, 0.1)   # 4 m straight ahead
    assert odo.pose[0] == pytest.approx(4.0 * 1.02) and odo.pose[1] == pytest.approx(0.0)
    turn = Odometry((1.0, 1.0, 0.0), errors=(0.0, 0.0, -0.05))
    for _ in range(10):
        turn.integrate(0.0, 1.0, 0.1)  # a turn of 1 rad on the spot
    assert turn.pose == pytest.approx((1.0, 1.0, 0.95))
    # a differential drive never moves sideways: the y error does nothing
    sideways = Odometry((0.0, 0.0, 0.3), errors=(0.0, 0.5, 0.0))
    sideways.integrate(1.0, 0.0, 2.0)
    assert sideways.pose == pytest.approx((2 * math.cos(0.3), 2 * math.sin(0.3), 0.3))
    # wheel speeds: (left + right) / 2 forward, (right - left) / track turning
    wheels = Odometry((0.0, 0.0, 0.0))
    wheels.wheels(-0.165, 0.165, 0.33, 1.0)
    assert wheels.pose == pytest.approx((0.0, 0.0, 1.0))


def _run(tmp_path, robots, seed, **options):
    from petriflow.agents.bidding import metrics
    from petriflow.runtime.metrics import RunRecord
    from petriflow.runtime.session import run_files

    folder = tmp_path / f"{robots}-{seed}-{'-'.join(f'{k}{v}' for k, v in sorted(options.items()))}"
    folder.mkdir()
    (folder / "net.yaml").write_text(dumps_net(build(robots, "autonomous", **options)))
    (folder / "world.yaml").write_text(examples.path("bidding", "world.yaml").read_text())
    config = {"seed": seed, "until": 900, "world": "world.yaml", "stall": 120,
              "channels": {"lan": {"model": "ideal", "latency": 0.0}}}
    (folder / "run.yaml").write_text(yaml.safe_dump(config))
    outcome = run_files(folder / "net.yaml", config=folder / "run.yaml", keep_events=True)
    assert outcome.result.reason == "final"
    record = RunRecord(outcome.result, outcome.events)
    return outcome, {name: getattr(metrics, name)(record)
                     for name in ("time_s", "accuracy_pct", "fit_pct", "drift_m", "messages")}


def test_odometry_gives_every_trial_its_own_mission_and_exact_localisation_none(tmp_path):
    gps = [_run(tmp_path, 2, seed, localization="gps")[1] for seed in (1, 2)]
    odom = [_run(tmp_path, 2, seed)[1] for seed in (1, 2)]
    # exact localisation: the auction, the paths and the lasers are exact, so two seeds
    # map alike; with odometry every robot drifts its own way
    assert gps[0]["time_s"] == pytest.approx(gps[1]["time_s"], abs=0.11)
    assert gps[0]["drift_m"] == 0.0 and gps[1]["drift_m"] == 0.0
    assert odom[0]["drift_m"] > 0.02 and odom[1]["drift_m"] > 0.02
    assert odom[0]["time_s"] != odom[1]["time_s"] or odom[0]["accuracy_pct"] != odom[1]["accuracy_pct"]


def test_a_drifted_robots_walls_are_real_to_eq10_but_off_the_ground_truth(tmp_path):
    outcome, got = _run(tmp_path, 1, 1, until="reached")
    ready = [e for e in outcome.events if e.kind == "custom" and e.data.get("name") == "bidding.ready"]
    assert ready and any(abs(v) > 0 for v in ready[0].data["data"]["odometry"])
    # one robot sees no teammate: every return is off a real wall (eq. 10: 100 %), but
    # the walls it drew where it believed it was are off the truth by more than a cell
    assert got["accuracy_pct"] == 100.0
    assert got["fit_pct"] < 99.0 and got["drift_m"] > 0.05


def test_eq10_by_what_the_beams_hit():
    frame = Grid((0.0, 0.0), 1.0, (3, 6))
    team = GlobalMap(frame)
    team.add(0, [(0.5, 0.5), (1.5, 0.5), (2.5, 0.5), (3.5, 0.5)])               # a wall, real by default
    team.add(1, [(0.5, 2.5), (5.5, 2.5), (4.5, 1.5)], real=[True, False, False])  # a wall cell and a robot
    team.add(1, [(4.5, 1.5)], real=[True])                                        # a real return there later
    score = fictitious(team)
    assert (score.sigma, score.xi) == (6, 1) and score.percent == pytest.approx(100 * (1 - 1 / 6))
    # against a truth of the bottom row only, the top row's wall cell is fictitious too
    truth = frame.empty()
    truth[0, :] = True
    assert accuracy(team.occupied, truth).xi == 2
    # points outside the frame keep their labels in step with the points inside
    edge = GlobalMap(frame)
    edge.add(0, [(-5.0, 0.5), (0.5, 0.5)], real=[True, False])
    assert fictitious(edge).xi == 1
    with pytest.raises(BiddingError, match="labels"):
        edge.add(0, [(0.5, 0.5)], real=[True, False])
