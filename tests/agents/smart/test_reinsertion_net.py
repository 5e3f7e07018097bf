"""nets/smart/reinsertion.yaml's route for a re-plan that finds no path: the planner's
failure leaves the robot detained (a STOP frame) and the run ends at its final marking,
so a sweep measures the trial (arrived 0) instead of recording an unrouted failure."""

from __future__ import annotations

import numpy as np

from petriflow.agents.planning.maps import OBSTACLE, ROBOT_LABELS, draw_disc
from petriflow.agents.smart.messages import ActionId, decode
from petriflow.io import load_net
from petriflow.testing import fire_one
from tests.agents.smart.conftest import SMART

MPP = 0.02  # a 130 x 100 pixel map of the 2.6 m x 2.0 m floor


def walled_off_scene() -> dict:
    """Robot3L (yellow) west of a wall that runs the floor's whole height: the goal
    (0.95, 0.05) lies beyond it."""
    label = np.zeros((100, 130), np.uint8)
    label[:, 88:91] = OBSTACLE                      # x = 0.46 .. 0.52 m
    label = draw_disc(label, (77, 25), 6, ROBOT_LABELS["yellow"])
    return {"label_map": label, "metres_per_pixel": MPP, "origin": [-1.3, 1.0]}


def test_a_plan_with_no_path_detains_the_robot_and_ends_the_run():
    """plan fails with no path: its outcome arc marks `stranded` and gives the decision
    token back; `stop` sends STOP to Robot3L and puts the final token in `o`."""
    net = load_net(SMART / "reinsertion.yaml")
    planned = fire_one(net, "plan", tokens={"go": [None], "P6": [walled_off_scene()]})
    assert planned.outcome == "failed" and "no path" in planned.reason
    assert planned.marking == {"stranded": 1, "P6": 1}
    stopped = fire_one(net, "stop", tokens={"stranded": [planned.result], "pushed": [None], "P2": [None],
                                            "P5": [None], "P6": [None], "S": [None]})
    assert stopped.outcome == "ok" and stopped.marking == {"o": 1}
    frames = [command for event in stopped.events
              if event.kind == "custom" and event.data["name"] == "smart.frame"
              for command in decode(bytes.fromhex(event.data["data"]["hex"]))]
    assert [(c.action, c.robot) for c in frames] == [(ActionId.STOP, ROBOT_LABELS["yellow"])]
