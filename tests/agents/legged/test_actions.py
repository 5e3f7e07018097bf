"""Gait actions over a real pybullet world: walking, turning, bracing, standing up.

Each action is fired with ``petriflow.testing.fire_one`` on a one-transition net (the
helping task also as a two-agent net), and moves the robots only through their joint
motors.
"""

from __future__ import annotations

import math

import pytest
from petriflow.agents.legged.actions import Brace, StandUp, Turn, Walk
from petriflow.agents.legged.control import LeggedRobot

from petriflow.errors import NetFormatError
from petriflow.io.yaml import loads_net
from petriflow.runtime.registry import default_registry
from petriflow.runtime.binding import bind
from petriflow.runtime.scheduler import Scheduler
from petriflow.testing import check_action, fire_one

pytestmark = pytest.mark.slow


def lay_down(world, name: str, roll: float, settle: int = 250) -> LeggedRobot:
    """Turn a robot onto its side (roll ±π/2) or back (π) and let it come to rest; the
    world's YAML sets only position and yaw."""
    p = world.p
    robot = LeggedRobot(world, name)
    x, y, yaw = robot.pose()
    p.resetBasePositionAndOrientation(robot.body, [x, y, 0.14], p.getQuaternionFromEuler([roll, 0, yaw]),
                                      physicsClientId=world.client)
    for _ in range(settle):
        world.step()
    return robot


class NoTeleport:
    """A pybullet module stand-in that refuses to set poses or joint states directly."""

    def __init__(self, module):
        self._module = module

    def __getattr__(self, name):
        if name.startswith("resetBase") or name == "resetJointState":
            raise AssertionError(f"an action called {name}: robots must move by their motors")
        return getattr(self._module, name)


def test_plugin_registers_the_gait_actions():
    """The ``legged`` entry point registers the four gait actions lazily."""
    assert {"gait.walk", "gait.turn", "gait.brace", "gait.stand_up"} <= set(default_registry.names())
    assert default_registry.resolve("gait.walk") is Walk
    assert all(cls.needs_world for cls in (Walk, Turn, Brace, StandUp))


@pytest.mark.parametrize("params, match", [
    ("{distance: 0.5, x: 1, y: 0}", "either 'distance'"),
    ("{x: 1}", "both 'x' and 'y'"),
    ("{}", "either 'distance'"),
    ("{distance: 0.5, stride: -0.1}", "must be > 0"),
    ("{distance: 0.5, strid: 0.1}", "did you mean 'stride'"),
])
def test_walk_parameters_are_checked_when_the_net_is_bound(net_for, params, match):
    """A bad combination of parameters fails when the net is bound, before anything moves."""
    with pytest.raises(NetFormatError, match=match):
        bind(net_for("gait.walk", params))


@pytest.mark.parametrize("cls, params", [
    (Walk, {"robot": "cat", "distance": 0.05}),
    (Turn, {"robot": "cat", "angle": 0.3}),
    (StandUp, {"robot": "dog"}),
])
def test_actions_pass_the_conformance_check(world_of, cls, params):
    """petriflow.testing.check_action: one full lifecycle, Status values, it ends."""
    world = world_of(dog=(0, 0), cat=(0, 0.6))
    assert check_action(cls, params, world=world) == []


def test_brace_passes_the_conformance_check(world_of):
    """gait.brace's lifecycle, with a fallen robot to brace."""
    world = world_of(dog=(0, 0), cat=(0.0, -0.45))
    lay_down(world, "dog", math.pi / 2)
    assert check_action(Brace, {"robot": "cat", "target": "dog"}, world=world) == []


def test_robot4l_walks_forward_by_its_legs(world_of, net_for):
    """Robot4L crawls at least 0.2 m forward within 30 simulated seconds, straight and
    upright, moved only by its motors."""
    world = world_of(dog=(0, 0))
    world.p = NoTeleport(world.p)
    fired = fire_one(net_for("gait.walk", "{robot: dog, distance: 0.25}"), "t", world=world, timeout=30)
    assert fired.outcome == "ok", fired.reason
    assert fired.time <= 30
    robot = LeggedRobot(world, "dog")
    x, y, yaw = robot.pose()
    assert x >= 0.2 and abs(y) < 0.03 and abs(yaw) < 0.1
    assert robot.upright() and robot.height() == pytest.approx(robot.design.standing_height, abs=0.005)
    assert fired.marking == {"b": 1}


def test_robot3l_slides_to_a_point_faster_than_robot4l_walks(world_of, net_for):
    """Robot3L reaches a point 0.3 m away (turning first) and its straight walk beats
    Robot4L's (the paper: "the agent with three legs is faster")."""
    world = world_of(dog=(0, 0), cat=(0, 0.6))
    world.p = NoTeleport(world.p)
    cat = fire_one(net_for("gait.walk", "{robot: cat, distance: 0.25}"), "t", world=world, timeout=30)
    dog = fire_one(net_for("gait.walk", "{robot: dog, distance: 0.25}"), "t", world=world, timeout=30)
    assert cat.outcome == dog.outcome == "ok"
    assert cat.result["travelled"] / cat.time > 1.5 * dog.result["travelled"] / dog.time
    fired = fire_one(net_for("gait.walk", "{robot: cat, x: 0.3, y: 0.8}"), "t", world=world, timeout=40)
    assert fired.outcome == "ok", fired.reason
    x, y, _ = LeggedRobot(world, "cat").pose()
    assert math.hypot(x - 0.3, y - 0.8) < 0.05


@pytest.mark.parametrize("robot, angle", [("dog", math.pi / 2), ("cat", -2.0), ("dog", -math.pi)])
def test_turn_changes_the_heading_by_the_angle(world_of, net_for, robot, angle):
    """Turning on the spot changes the yaw by the asked angle, within tolerance, and
    leaves the robot about where it was."""
    world = world_of(dog=(0, 0), cat=(0, 0.6))
    legged = LeggedRobot(world, robot)
    x0, y0, yaw0 = legged.pose()
    fired = fire_one(net_for("gait.turn", f"{{robot: {robot}, angle: {angle}, tolerance: 0.05}}"), "t",
                     world=world, timeout=60)
    assert fired.outcome == "ok", fired.reason
    x, y, yaw = legged.pose()
    assert abs(math.remainder(yaw - yaw0 - angle, 2 * math.pi)) <= 0.06
    assert math.hypot(x - x0, y - y0) < 0.06


def test_walk_refuses_a_speed_beyond_the_motors(world_of, net_for):
    """Asking a gait faster than twice its default pace fails, naming the limit."""
    world = world_of(cat=(0, 0))
    fired = fire_one(net_for("gait.walk", "{robot: cat, distance: 0.2, speed: 1.0}"), "t", world=world)
    assert fired.outcome == "failed" and "walks at most" in fired.reason


def test_walk_refuses_a_fallen_robot(world_of, net_for):
    """A robot on its side cannot walk: the action fails saying so."""
    world = world_of(dog=(0, 0))
    lay_down(world, "dog", math.pi / 2)
    fired = fire_one(net_for("gait.walk", "{robot: dog, distance: 0.2}"), "t", world=world)
    assert fired.outcome == "failed" and "not upright" in fired.reason


@pytest.mark.parametrize("roll", [math.pi / 2, -math.pi / 2], ids=["right side down", "left side down"])
def test_robot4l_stands_up_from_its_side(world_of, net_for, roll):
    """A Robot4L lying on either side rolls onto its feet and stands in its posture."""
    world = world_of(dog=(0, 0))
    robot = lay_down(world, "dog", roll)
    assert robot.tilt() > math.radians(60)
    world.p = NoTeleport(world.p)
    fired = fire_one(net_for("gait.stand_up", "{robot: dog}"), "t", world=world, timeout=20)
    assert fired.outcome == "ok", fired.reason
    assert robot.upright(tolerance=math.radians(5))
    assert robot.height() == pytest.approx(robot.design.standing_height, abs=0.005)
    assert fired.result["from"] == ("right" if roll > 0 else "left")


def test_robot4l_on_its_back_cannot_stand_up(world_of, net_for):
    """On its back its legs point up: stand_up fails, naming why."""
    world = world_of(dog=(0, 0))
    lay_down(world, "dog", math.pi)
    fired = fire_one(net_for("gait.stand_up", "{robot: dog}"), "t", world=world)
    assert fired.outcome == "failed" and "on its back" in fired.reason


def test_stand_up_with_a_helper_needs_it_braced(world_of, net_for):
    """Named helper not behind the fallen robot: stand_up fails and says to brace first."""
    world = world_of(dog=(0, 0), cat=(0.8, 0.8))
    lay_down(world, "dog", math.pi / 2)
    fired = fire_one(net_for("gait.stand_up", "{robot: dog, helper: cat}"), "t", world=world)
    assert fired.outcome == "failed" and "brace it first" in fired.reason


HELPING = """
petriflow: 1
net: helping
label: Robot3L helps a fallen Robot4L stand up (seed 003, Fig. 17, cooperation subnet)
subnets:
  - id: helper
    agent: cat
    places: [{id: start_helping, tokens: 1}, holding]
    transitions:
      - {id: go_brace, action: gait.brace, params: {robot: cat, target: dog}, in: [start_helping],
         out: [helper_arrived, holding]}
  - id: crashed
    agent: dog
    places: [{id: wait_for_help, tokens: 1}, stood_up]
    transitions:
      - {id: stand_up, action: gait.stand_up, params: {robot: dog, helper: cat},
         in: [wait_for_help, helper_arrived], out: [stood_up]}
places: [helper_arrived]
final: {holding: 1, stood_up: 1}
"""


def test_helping_task_brace_then_stand_up(world_of):
    """The helping task as a net: the helper walks behind the fallen robot and holds
    it; then the fallen robot stands up leaning on it."""
    world = world_of(dog=(0, 0), cat=(0.5, -0.5))
    dog = lay_down(world, "dog", math.pi / 2)
    world.p = NoTeleport(world.p)
    result = Scheduler(loads_net(HELPING), world=world, seed=1).run(until=90)
    assert result.reason == "final", result.error
    assert dog.upright(tolerance=math.radians(5))
    cat = LeggedRobot(world, "cat")
    assert cat.upright()
    assert math.dist(cat.pose()[:2], dog.pose()[:2]) < 0.35
