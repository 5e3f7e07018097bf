"""Each transition of nets/smart/smart.yaml fired on its own with its real action
(petriflow.testing.fire_one), over the SMART arena where the action needs a world."""

from __future__ import annotations

from petriflow.agents.smart.arena import dress

import math

import numpy as np
import pytest
from petriflow.agents.legged.control import LeggedRobot
from petriflow.agents.legged.righting import brace_point
from petriflow.agents.smart.messages import ActionId, decode

from petriflow.errors import PetriflowError
from petriflow.testing import fire_one
from tests.agents.smart.conftest import place, scene_of

HELPER_START = (-0.8, -0.55)


def frames_of(fired):
    """The SMART frames a firing recorded in the trace, decoded from their bytes."""
    out = []
    for event in fired.events:
        if event.kind == "custom" and event.data["name"] == "smart.frame":
            out.extend(decode(bytes.fromhex(event.data["data"]["hex"])))
    return out


def test_t0_dresses_the_arena_and_takes_the_first_image(net, arena):
    """T0 (smart.capture): white floor, hats on, one 320 x 240 frame in P1; marks M0
    (and the latest-scene place S)."""
    world = arena(settle=0.0)
    fired = fire_one(net, "T0", world=world)
    assert fired.outcome == "ok"
    assert fired.marking == {"P1": 1, "P5": 1, "P13": 1, "S": 1}
    frame = fired.tokens["P1"][0]
    assert frame.shape == (240, 320, 3) and frame.dtype == np.uint8
    assert (frame[5, 5] == 255).all()                      # the floor is white
    assert set(dress(world).hats) == {"robot3l", "robot4l"}


def test_t1_sends_the_image_in_a_frame_time(net):
    """T1 (core.wait 1/15 s): the frame goes on to processing, the camera to standby."""
    frame = np.zeros((4, 4, 3), np.uint8)
    fired = fire_one(net, "T1", tokens={"P1": [frame]})
    assert fired.outcome == "ok" and fired.marking == {"P2": 1, "P3": 1}
    assert fired.time == pytest.approx(1 / 15, abs=0.011)
    assert fired.tokens["P3"][0] is frame


def test_t2_captures_a_new_image_when_the_decision_maker_asks(net, arena):
    """T2 (vision.capture) needs the camera standby P2 and the decision token P6."""
    world = arena()
    fired = fire_one(net, "T2", tokens={"P2": [None], "P6": [None]}, world=world)
    assert fired.outcome == "ok" and fired.marking == {"P1": 1}
    assert fired.tokens["P1"][0].shape == (240, 320, 3)


def test_t3_locates_the_helper_and_not_the_fallen_robot(net, arena):
    """T3 (vision.locate): the standing Robot3L is found where it is; the fallen Robot4L
    shows no discs, so it is not among the located robots. The scene also replaces the
    latest scene in S."""
    world = arena()
    frame = world.camera("top").capture()
    fired = fire_one(net, "T3", tokens={"P3": [frame], "P5": [None], "S": [None]}, world=world)
    assert fired.outcome == "ok" and fired.marking == {"P4": 1, "S": 1}
    scene = fired.tokens["P4"][0]
    assert fired.tokens["S"] == [scene]
    x, y, _ = world.pose("robot3l")
    seen = scene.robots["yellow"].position
    assert math.dist(seen, (x, y)) < 0.03
    assert "red" in scene.missing


def test_t4_sends_the_results_to_the_decision_maker(net):
    """T4 (core.wait 0.1 s): the scene goes to P6, processing back to standby P5."""
    fired = fire_one(net, "T4", tokens={"P4": [{"scene": 1}]})
    assert fired.outcome == "ok" and fired.marking == {"P5": 1, "P6": 1}
    assert fired.tokens["P6"] == [{"scene": 1}]
    assert fired.time == pytest.approx(0.1, abs=0.005)


def test_t5_dispatches_the_helper_behind_the_fallen_robots_back(net, arena):
    """T5 (smart.dispatch, guard smart.help_needed): STOP to Robot4L, HELP with the final
    point to Robot3L; the final point lies behind the fallen robot's back; the planner's
    map has the fallen robot as an obstacle."""
    world = arena()
    scene = scene_of(world)
    fired = fire_one(net, "T5", tokens={"P6": [scene], "P13": [None]}, world=world)
    assert fired.outcome == "ok", fired.reason
    assert fired.marking == {"P6": 1, "P7": 1, "P8": 1}
    decision = fired.tokens["P8"][0]
    robot = LeggedRobot(world, "robot4l")
    position, rotation = robot.frame()
    truth = brace_point(position, rotation, 0.17 + 0.15)
    assert math.dist(decision["goal"]["yellow"], truth[:2]) < 0.04
    assert decision["fallen"]["side"] in ("left", "right")
    commands = frames_of(fired)
    assert [(c.action, c.robot) for c in commands] == [(ActionId.STOP, 2), (ActionId.HELP, 4)]
    cx, cy = commands[1].params
    assert math.dist((-1.25 + cx * 0.01, -0.95 + cy * 0.01), decision["goal"]["yellow"]) <= 0.01
    fallen = decision["label_map"] == 1
    assert fallen.sum() > (scene.labels == 1).sum()        # the fallen robot was added


def test_t5_does_not_fire_while_no_robot_has_fallen(net, arena):
    """With Robot4L standing, the guard smart.help_needed keeps T5 from firing (T2 asks
    for another image instead)."""
    def upright(robots):
        for robot in robots:
            robot.pop("roll", None)
        return robots

    world = arena(robots=upright)
    with pytest.raises(PetriflowError, match="guard false"):
        fire_one(net, "T5", tokens={"P6": [scene_of(world)], "P13": [None]}, world=world)


def test_t7_plans_the_helpers_path_around_the_fallen_robot(net, arena):
    """T7 (planning.astar): a path from Robot3L to the final point that keeps its radius
    clear of the fallen robot drawn in the map."""
    world = arena()
    dispatched = fire_one(net, "T5", tokens={"P6": [scene_of(world)], "P13": [None]}, world=world)
    decision = dispatched.tokens["P8"][0]
    fired = fire_one(net, "T7", tokens={"P8": [decision]}, world=world)
    assert fired.outcome == "ok" and fired.marking == {"P9": 1}
    path = np.asarray(fired.tokens["P9"][0]["path"])
    assert math.dist(path[0], world.pose("robot3l")[:2]) < 0.03
    assert path[-1].tolist() == decision["goal"]["yellow"]
    fallen = (decision["fallen"]["x"], decision["fallen"]["y"])
    assert np.hypot(*(path - fallen).T).min() > 0.15 + 0.15 - 0.02


@pytest.mark.slow
def test_t8_walks_the_path_by_its_legs_and_braces(net, arena):
    """T8 (smart.follow with brace): Robot3L, set 0.3 m before the final point, walks
    the last stretch of a path and braces behind the fallen robot's back."""
    world = arena()
    robot = LeggedRobot(world, "robot4l")
    position, rotation = robot.frame()
    ax, ay, facing = brace_point(position, rotation, 0.17 + 0.15)
    start = (ax - 0.3, ay)
    place(world, "robot3l", *start, 0.0)
    fire_one(net, "T2", tokens={"P2": [None], "P6": [None]}, world=world)   # an image for tracking
    fired = fire_one(net, "T8", tokens={"P9": [{"path": [list(start), [ax, ay]]}]}, world=world, timeout=60)
    assert fired.outcome == "ok", fired.reason
    assert fired.marking == {"P10": 1}
    bx, by, _ = brace_point(position, rotation, 0.17)
    x, y, yaw = world.pose("robot3l")
    assert math.dist((x, y), (bx, by)) < 0.06
    assert abs(math.remainder(yaw - facing, math.tau)) < 0.15
    moves = frames_of(fired)
    assert moves and all(c.action is ActionId.MOVE_TO and c.robot == 4 for c in moves)


def test_t6_the_fallen_robot_stands_up_leaning_on_the_helper(net, arena):
    """T6 (gait.stand_up with the helper braced): Robot4L rolls onto its feet; the
    helper stays (P12, holds its position)."""
    world = arena()
    robot = LeggedRobot(world, "robot4l")
    position, rotation = robot.frame()
    bx, by, facing = brace_point(position, rotation, 0.17)
    place(world, "robot3l", bx, by, facing)
    fired = fire_one(net, "T6", tokens={"P7": [None], "P10": [None]}, world=world, timeout=30)
    assert fired.outcome == "ok", fired.reason
    assert fired.marking == {"P11": 1, "P12": 1}
    assert robot.upright(tolerance=math.radians(5))


def test_t9_the_helper_holds_and_the_net_ends(net):
    """T9 (smart.send HOLD to Robot3L) collects the helper's, the fallen robot's and the
    camera loop's tokens into o."""
    fired = fire_one(net, "T9", marking={"P11": 1, "P12": 1, "P2": 1, "P5": 1, "P6": 1, "S": 1})
    assert fired.outcome == "ok" and fired.marking == {"o": 1}
    assert [(c.action, c.robot) for c in frames_of(fired)] == [(ActionId.HOLD, 4)]
