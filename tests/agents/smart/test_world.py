"""The world options the SMART arena needs (petriflow/world.py): a robot loaded with a
roll or pitch (a fallen robot), and free ``meta`` data kept for other components."""

from __future__ import annotations

import math

import pytest

from petriflow.errors import NetFormatError
from petriflow.world import World

ROBOT4L = "petriflow.agents.legged:robots/robot4l.urdf"


@pytest.fixture
def worlds():
    made = []

    def build(description):
        world = World(description)
        made.append(world)
        return world

    yield build
    for world in made:
        world.close()


def test_roll_loads_a_robot_on_its_side(worlds):
    """roll = π/2: the body's z axis is horizontal, and it stays down once settled."""
    from petriflow.agents.legged.control import LeggedRobot

    world = worlds({"robots": [{"id": "dog", "urdf": ROBOT4L, "position": [0, 0], "z": 0.14,
                                "yaw": 0.5, "roll": math.pi / 2}]})
    robot = LeggedRobot(world, "dog")
    assert robot.tilt() == pytest.approx(math.pi / 2, abs=1e-6)
    for _ in range(240):
        world.step()
    assert robot.tilt() > math.radians(60)


def test_pitch_and_roll_default_to_upright(worlds):
    """Without roll or pitch a robot loads as before (yaw only)."""
    world = worlds({"robots": [{"id": "dog", "urdf": ROBOT4L, "position": [1, 2], "z": 0.2, "yaw": 0.3}]})
    p = world.p
    _, orientation = p.getBasePositionAndOrientation(world.body("dog"), physicsClientId=world.client)
    roll, pitch, yaw = p.getEulerFromQuaternion(orientation)
    assert (round(roll, 6), round(pitch, 6), round(yaw, 6)) == (0.0, 0.0, 0.3)


def test_pitch_turns_about_the_bodys_y_axis(worlds):
    """pitch = π/2 after yaw = π/2: the body's x axis points down."""
    world = worlds({"gravity": 0, "plane": False,
                    "robots": [{"id": "dog", "urdf": ROBOT4L, "yaw": math.pi / 2, "pitch": math.pi / 2}]})
    p = world.p
    _, orientation = p.getBasePositionAndOrientation(world.body("dog"), physicsClientId=world.client)
    matrix = p.getMatrixFromQuaternion(orientation)
    x_axis = (matrix[0], matrix[3], matrix[6])
    assert x_axis == pytest.approx((0.0, 0.0, -1.0), abs=1e-6)


def test_meta_is_kept_and_unread(worlds):
    """meta: free data (the SMART arena's marker colours), kept as World.meta."""
    world = worlds({"plane": False, "meta": {"smart": {"floor": "white", "markers": []}}})
    assert world.meta == {"smart": {"floor": "white", "markers": []}}
    assert worlds({"plane": False}).meta == {}


def test_meta_must_be_a_mapping():
    with pytest.raises(NetFormatError, match="meta is a mapping"):
        World({"plane": False, "meta": [1, 2]})


def test_unknown_robot_keys_are_still_errors():
    with pytest.raises(NetFormatError, match="unknown key 'rol'"):
        World({"plane": False, "robots": [{"id": "dog", "urdf": ROBOT4L, "rol": 1.0}]})
