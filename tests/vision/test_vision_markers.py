"""Marker bodies: stand-in robots, hats on real robots, the white floor."""

from __future__ import annotations

import math

import numpy as np
import pytest

from petriflow.agents.drive import DiffDrive
from petriflow.vision.markers import (
    MarkerGeometry,
    add_marker_robot,
    attach_markers,
    move_marker_robot,
    white_floor,
)
from petriflow.vision.pipeline import VisionConfig, process
from petriflow.world import World

TOP = {"id": "top", "position": [0, 0, 3], "target": [0, 0, 0], "up": [0, 1, 0], "fov": 60,
       "width": 320, "height": 240}


def test_white_floor_renders_one_colour():
    world = World({"cameras": [TOP]})
    try:
        assert len(np.unique(world.camera("top").capture().reshape(-1, 3), axis=0)) > 1   # checker
        white_floor(world)
        frame = world.camera("top").capture()
        assert (frame == 239).all()
    finally:
        world.close()


def test_white_floor_without_a_plane_adds_one():
    world = World({"plane": False, "cameras": [TOP]})
    try:
        white_floor(world)
        assert "floor" in world.bodies
        assert (world.camera("top").capture() == 239).all()
    finally:
        world.close()


def test_marker_robot_moves_and_is_seen_where_it_is():
    world = World({"cameras": [TOP]})
    try:
        white_floor(world)
        name = add_marker_robot(world, "yellow", 0.0, 0.0)
        move_marker_robot(world, name, -0.7, 0.4, 2.0)
        assert [round(v, 6) for v in world.pose(name)] == [-0.7, 0.4, 2.0]
        pose = process(world.camera("top").capture(), world.camera("top")).robots["yellow"]
        assert math.hypot(pose.position[0] + 0.7, pose.position[1] - 0.4) < 0.01
        assert abs(pose.heading - 2.0) < math.radians(5)
        with pytest.raises(ValueError, match="duplicate"):
            add_marker_robot(world, "yellow", 1.0, 1.0)
    finally:
        world.close()


def test_geometry_is_checked():
    with pytest.raises(ValueError, match="inside"):
        MarkerGeometry(side=0.15).check()
    assert MarkerGeometry().marker_z == 0.104


def test_hat_follows_a_driving_robot_and_vision_sees_it():
    """A marker hat on the differential-drive robot of nets/passage: it rides along while
    the physics steps, and the vision finds the robot where pybullet has it."""
    world = World({
        "dt": 0.01,
        "robots": [{"id": "red", "urdf": "petriflow.agents:robots/diffdrive.urdf", "position": [0.3, -0.2],
                    "yaw": 0.7, "colour": "red"}],
        "cameras": [TOP],
    })
    try:
        white_floor(world)
        hat = attach_markers(world, "red", colour="red")
        drive = DiffDrive(world, "red")
        drive.command(0.3, 0.6)
        for _ in range(200):
            world.step()
        x, y, yaw = world.pose("red")
        hx, hy, hyaw = hat.pose()
        assert math.hypot(hx - x, hy - y) < 0.002 and abs(hyaw - yaw) < 0.01
        assert math.hypot(x - 0.3, y + 0.2) > 0.3                       # it did move
        camera = world.camera("top")
        scene = process(camera.capture(), camera, VisionConfig(marker_z=hat.marker_z))
        pose = scene.robots["red"]
        assert math.hypot(pose.position[0] - x, pose.position[1] - y) < 0.01
        assert abs((pose.heading - yaw + math.pi) % (2 * math.pi) - math.pi) < math.radians(5)
        p = world.p
        position, orientation = p.getBasePositionAndOrientation(world.body("red"),
                                                                physicsClientId=world.client)
        expected, _ = p.multiplyTransforms(position, orientation, hat.offset, [0, 0, 0, 1])
        hat.sync()                                                      # exactly on the link now
        assert math.hypot(hat.pose()[0] - expected[0], hat.pose()[1] - expected[1]) < 1e-6
        hat.remove()
    finally:
        world.close()
