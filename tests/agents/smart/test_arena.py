"""The SMART arena as the camera sees it: white floor, marker hats that follow the robots."""

from __future__ import annotations

import numpy as np
import pytest
from petriflow.agents.legged.control import LeggedRobot
from petriflow.agents.smart.arena import colour_robots, dress, robot_colours

from petriflow.errors import NetFormatError, PetriflowError
from petriflow.io.yaml import loads_net
from petriflow.testing import fire_one
from petriflow.world import World

WALK = """
petriflow: 1
places: [{id: a, tokens: 1}, b]
transitions: [{id: t, action: gait.walk, params: {robot: robot3l, distance: 0.12}, in: [a], out: [b]}]
"""


def hat_error(world, name: str) -> float:
    """Distance (m) between a robot's hat and where it belongs: over the body frame's
    origin, 1 mm above the top plate, along the body's z axis."""
    robot = LeggedRobot(world, name)
    position, rotation = robot.frame()
    plate = robot.design.plate
    expected = position + rotation @ np.array([0.0, 0.0, plate.centre[2] + plate.size[2] / 2 + 0.001])
    hat = dress(world).hats[name]
    actual, _ = world.p.getBasePositionAndOrientation(hat.body, physicsClientId=world.client)
    return float(np.linalg.norm(np.asarray(actual) - expected))


def test_dress_puts_one_hat_per_declared_robot_once(arena):
    world = arena(settle=0.0)
    first = dress(world)
    again = dress(world)  # found in the scene, not dressed twice
    assert {r: h.body for r, h in again.hats.items()} == {r: h.body for r, h in first.hats.items()}
    assert first.colours == {"robot3l": "yellow", "robot4l": "red"}
    assert robot_colours(world) == first.colours
    assert colour_robots(world) == {"yellow": "robot3l", "red": "robot4l"}


def test_the_floor_renders_white_and_holds_robots_like_the_plane(arena):
    """floor: white: the camera's background (255) shows; the ground has the plane's
    collision and friction, so a robot rests at the same height on it."""
    dressed = arena(settle=1.0)
    frame = dressed.camera("top").capture()
    assert (frame[5, 5] == 255).all() and (frame[120, 300] == 255).all()
    p = dressed.p
    assert p.getDynamicsInfo(dressed.bodies["plane"], -1, physicsClientId=dressed.client)[1] == 1.0
    plain = World({"dt": dressed.dt, "robots": [{"id": "robot3l", "z": 0.08, "position": [-0.8, -0.55],
                                                 "urdf": "petriflow.agents.legged:robots/robot3l.urdf"}]})
    try:
        for _ in range(int(1.0 / plain.dt)):
            plain.step()
        assert LeggedRobot(dressed, "robot3l").height() == pytest.approx(LeggedRobot(plain, "robot3l").height(),
                                                                         abs=0.001)
    finally:
        plain.close()


def test_hats_sit_on_the_robots_whatever_their_pose(arena):
    """Upright Robot3L and Robot4L lying on its side: each hat is over its body frame."""
    world = arena(settle=0.5)
    assert hat_error(world, "robot3l") < 0.001
    assert hat_error(world, "robot4l") < 0.002
    _, rotation = LeggedRobot(world, "robot4l").frame()
    hat = dress(world).hats["robot4l"]
    _, orientation = world.p.getBasePositionAndOrientation(hat.body, physicsClientId=world.client)
    hat_up = np.array(world.p.getMatrixFromQuaternion(orientation)).reshape(3, 3)[:, 2]
    assert hat_up @ rotation[:, 2] > 0.999          # the fallen robot's hat faces sideways with its plate


def test_hats_follow_a_walking_robot_without_a_per_step_sync(arena):
    """The fixed constraints carry the hats: after a walk, still within a millimetre."""
    world = arena(settle=0.2)
    fired = fire_one(loads_net(WALK), "t", world=world, timeout=30)
    assert fired.outcome == "ok", fired.reason
    assert fired.result["travelled"] > 0.08
    assert hat_error(world, "robot3l") < 0.001


@pytest.mark.parametrize("meta, match", [
    ({"smart": {"floor": "blue"}}, "setting 'floor' must be one of"),
    ({"smart": {"markers": [{"robot": "robot3l"}]}}, r"'meta.smart.markers\[0\]': missing setting 'colour'"),
    ({"smart": [1]}, "meta.smart is a mapping"),
])
def test_malformed_arena_data_is_an_error(meta, match):
    world = World({"plane": True, "meta": meta})
    try:
        with pytest.raises(NetFormatError, match=match):
            dress(world)
    finally:
        world.close()


def test_bad_arena_data_stops_the_run_before_it_starts():
    """smart.capture uses the smart.arena resource, which declares meta.smart: a
    malformed meta.smart is bad input, one error naming the setting, before the run."""
    net = loads_net("""
petriflow: 1
places: [{id: a, tokens: 1}, b, bad]
transitions: [{id: t, action: smart.capture, in: [a], out: [b], outcomes: {failed: [bad]}}]
""")
    world = World({"meta": {"smart": {"floor": "blue"}}, "cameras": [{"id": "top", "width": 32, "height": 24}]})
    try:
        with pytest.raises(PetriflowError, match="'meta.smart': setting 'floor' must be one of"):
            fire_one(net, "t", world=world)
    finally:
        world.close()
