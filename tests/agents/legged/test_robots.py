"""The robots' URDFs: generated from one design, Table 3 limits, kinematics, physics."""

from __future__ import annotations

import math
from xml.etree import ElementTree

import numpy as np
import pytest
from petriflow.agents.legged.control import LeggedRobot
from petriflow.agents.legged.robots import DESIGNS, ROBOT3L, ROBOT4L, URDF_FOLDER, urdf


@pytest.mark.parametrize("name", sorted(DESIGNS))
def test_shipped_urdf_equals_the_generator_output(name):
    """robots/<name>.urdf is exactly what robots.urdf(design) writes (regenerate with
    ``python -m petriflow.agents.legged.robots``)."""
    assert (URDF_FOLDER / f"{name}.urdf").read_text(encoding="utf-8") == urdf(DESIGNS[name])


@pytest.mark.parametrize("name", sorted(DESIGNS))
def test_joint_limits_follow_table_3(name):
    """Hips and knees within ±π/3 rad, ext prismatic within [0, 100] mm."""
    root = ElementTree.fromstring(urdf(DESIGNS[name]))
    kinds = {}
    for joint in root.iter("joint"):
        kind = joint.get("type")
        kinds[kind] = kinds.get(kind, 0) + 1
        if kind == "fixed":
            continue
        limit = joint.find("limit")
        low, high = float(limit.get("lower")), float(limit.get("upper"))
        if kind == "revolute":
            assert (low, high) == pytest.approx((-math.pi / 3, math.pi / 3))
        else:
            assert (low, high) == (0.0, 0.1)
    legs = len(DESIGNS[name].legs)
    assert kinds["prismatic"] == legs
    assert kinds["revolute"] == {4: 8, 3: 5}[legs]   # Table 1: 8 servos (Robot4L), 5 (Robot3L)


def test_robot3l_hind_leg_has_two_joints_and_a_sliding_skid():
    """Robot3L's hind leg: knee and ext only; its foot slides (low friction)."""
    hind = ROBOT3L.leg("h")
    assert not hind.geometry.has_hip
    assert hind.foot_friction < 0.1 < min(leg.foot_friction for leg in ROBOT3L.legs if leg.name != "h")


def test_top_plates_carry_the_marker_discs():
    """The plate fits the vision's two discs (centre ± offset, radius) with colour around."""
    markers = pytest.importorskip("petriflow.vision.markers")
    geometry = markers.DEFAULT_GEOMETRY
    for design in DESIGNS.values():
        assert design.plate.size[1] / 2 > geometry.disc_offset + geometry.disc_radius
        assert design.plate.size[0] / 2 > geometry.disc_radius


@pytest.mark.parametrize("design", [ROBOT4L, ROBOT3L], ids=["robot4l", "robot3l"])
def test_pybullet_feet_match_the_screw_kinematics(world_of, design):
    """pybullet's foot positions (from the URDF) equal the design's kinematics for
    random joint values."""
    world = world_of(**{"dog" if design is ROBOT4L else "cat": (0, 0)}, gravity=0)
    p, client = world.p, world.client
    robot = LeggedRobot(world, "dog" if design is ROBOT4L else "cat")
    links = {p.getJointInfo(robot.body, j, physicsClientId=client)[12].decode(): j
             for j in range(p.getNumJoints(robot.body, physicsClientId=client))}
    rng = np.random.default_rng(1)
    for _ in range(10):
        for leg in design.legs:
            q = rng.uniform([r[0] for r in leg.geometry.ranges], [r[1] for r in leg.geometry.ranges])
            for joint, value in zip(robot.joints_of[leg.name], q):
                if joint is not None:
                    p.resetJointState(robot.body, joint, value, physicsClientId=client)
        position, rotation = robot.frame()
        joints = robot.joints()
        for leg in design.legs:
            state = p.getLinkState(robot.body, links[f"{leg.name}_ext_link"], computeForwardKinematics=True,
                                   physicsClientId=client)
            link_rotation = np.array(p.getMatrixFromQuaternion(state[5])).reshape(3, 3)
            foot = np.array(state[4]) + link_rotation @ np.array([0.0, 0.0, -leg.geometry.l4])
            assert np.allclose(foot, position + rotation @ leg.foot(joints[leg.name]), atol=1e-6)


def test_robots_stand_still_without_sinking_or_drifting(world_of):
    """Both robots, holding their standing posture for 3 s: at their standing height,
    level, at rest."""
    world = world_of(dog=(0, 0), cat=(0, 0.6))
    robots = [LeggedRobot(world, "dog"), LeggedRobot(world, "cat")]
    for robot in robots:
        robot.hold(robot.nominal())
    for _ in range(750):
        world.step()
    for robot in robots:
        assert robot.height() == pytest.approx(robot.design.standing_height, abs=0.004)
        assert robot.tilt() < math.radians(2)
        linear, angular = world.p.getBaseVelocity(robot.body, physicsClientId=world.client)
        assert np.linalg.norm(linear) < 1e-3 and np.linalg.norm(angular) < 1e-2


def test_world_colour_paints_the_body_and_plate(world_of):
    """World's ``colour`` (changeVisualShape on link -1) colours the body and its plate."""
    world = world_of(dog=(0, 0))
    shapes = world.p.getVisualShapeData(world.body("dog"), physicsClientId=world.client)
    base = [shape for shape in shapes if shape[1] == -1]
    assert len(base) == 2
    assert all(tuple(round(c, 2) for c in shape[7]) == (0.9, 0.1, 0.1, 1.0) for shape in base)


def test_centre_of_mass_follows_the_legs():
    """The robot's centre of mass moves when a leg swings forward (legs have mass)."""
    joints = {leg.name: leg.nominal for leg in ROBOT4L.legs}
    still = ROBOT4L.centre_of_mass(joints)
    joints["lf"] = (0.6, joints["lf"][1], joints["lf"][2])
    assert not np.allclose(ROBOT4L.centre_of_mass(joints), still)
    assert ROBOT4L.total_mass == pytest.approx(0.83)
