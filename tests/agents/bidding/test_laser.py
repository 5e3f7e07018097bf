"""Eq. 7-8 (laser returns to world points) and the laser scan in a pybullet world."""

from __future__ import annotations

import math

import numpy as np
import pytest

from petriflow.agents.bidding.errors import BiddingError
from petriflow.agents.bidding.grid import GlobalMap, accuracy
from petriflow.agents.bidding.laser import scan, world_points
from petriflow.agents.bidding.office import paper_office

URDF = "petriflow.agents:robots/diffdrive.urdf"


def test_eq_7_8_on_a_hand_made_case():
    points = world_points((1.0, 2.0, math.pi / 2), [3.0], [0.0], max_range=8.0)
    assert points.shape == (1, 2) and points[0] == pytest.approx((1.0, 5.0))
    # beam 90 degrees right of a robot facing north points east
    points = world_points((1.0, 2.0, math.pi / 2), [2.0, 1.0], [-math.pi / 2, math.pi], max_range=8.0)
    assert points == pytest.approx(np.array([[3.0, 2.0], [1.0, 1.0]]))


def test_eq_7_8_matches_the_formula_for_random_beams():
    rng = np.random.default_rng(4)
    x, y, theta = 0.3, -1.2, 2.1
    ranges, angles = rng.uniform(0, 7.9, 50), rng.uniform(-math.pi / 2, math.pi / 2, 50)
    points = world_points((x, y, theta), ranges, angles, 8.0)
    assert points[:, 0] == pytest.approx(ranges * np.cos(theta + angles) + x)
    assert points[:, 1] == pytest.approx(ranges * np.sin(theta + angles) + y)


def test_max_range_beams_return_nothing():
    ranges = [8.0, 2.0, 9.0, math.inf, math.nan]
    points = world_points((0.0, 0.0, 0.0), ranges, [0.0, 0.0, 0.1, 0.2, 0.3], 8.0)
    assert points.tolist() == [[2.0, 0.0]]
    assert world_points((0, 0, 0), [8.0] * 3, [0.0, 0.1, 0.2], 8.0).shape == (0, 2)
    assert world_points((0, 0, 0), [], [], 8.0).shape == (0, 2)


@pytest.mark.parametrize("pose, ranges, angles, max_range", [
    ((0, 0), [1.0], [0.0], 8.0),
    ((0, 0, math.nan), [1.0], [0.0], 8.0),
    ((0, 0, 0), [1.0, 2.0], [0.0], 8.0),
    ((0, 0, 0), [[1.0]], [[0.0]], 8.0),
    ((0, 0, 0), [1.0], [0.0], 0.0),
])
def test_world_points_rejects_bad_shapes(pose, ranges, angles, max_range):
    with pytest.raises(BiddingError):
        world_points(pose, ranges, angles, max_range)


@pytest.fixture(scope="module")
def corridor_world():
    """A robot at the origin facing east, a teammate 1 m ahead, a wall whose face is 1.95 m ahead."""
    from petriflow.world import World

    world = World({"dt": 0.1, "gravity": 0.0, "plane": True,
                   "boxes": [{"id": "wall", "size": [0.1, 4.0, 0.5], "position": [2.0, 0.0, 0.25]}],
                   "robots": [{"id": "robot1", "urdf": URDF, "position": [0.0, 0.0], "z": 0.05},
                              {"id": "robot2", "urdf": URDF, "position": [1.0, 0.0], "z": 0.05}]})
    yield world
    world.close()


def test_a_scan_reads_the_distance_to_a_wall(corridor_world):
    ranges, angles = scan(corridor_world, "robot2", (1.0, 0.0, 0.0), beams=181)
    assert ranges.shape == angles.shape == (181,)
    assert angles[90] == pytest.approx(0.0) and angles[0] == pytest.approx(-math.pi / 2)
    assert ranges[90] == pytest.approx(0.95, abs=0.01)              # its own body is never seen
    assert ranges[0] == 8.0 and ranges[-1] == 8.0                    # nothing to either side
    points = world_points((1.0, 0.0, 0.0), ranges, angles, 8.0)
    assert np.all(np.abs(points[:, 0] - 1.95) < 0.01)               # every return lies on the wall's face


def test_teammates_are_seen_unless_ignored(corridor_world):
    ranges, _ = scan(corridor_world, "robot1", (0.0, 0.0, 0.0), beams=3, max_range=5.0)
    assert ranges[1] == pytest.approx(0.85, abs=0.01)               # robot2's body, radius 0.15 m
    ranges, _ = scan(corridor_world, "robot1", (0.0, 0.0, 0.0), beams=3, max_range=5.0, ignore_teammates=True)
    assert ranges[1] == pytest.approx(1.95, abs=0.01)
    assert ranges[0] == ranges[2] == 5.0
    # a pose of None is the body's own pose
    ranges, _ = scan(corridor_world, "robot1", None, beams=3, ignore_teammates=True)
    assert ranges[1] == pytest.approx(1.95, abs=0.01)


def test_scan_rejects_a_bad_laser(corridor_world):
    for kwargs in ({"beams": 0}, {"max_range": -1.0}, {"fov_deg": 0.0}):
        with pytest.raises(BiddingError):
            scan(corridor_world, "robot1", (0, 0, 0), **kwargs)


def test_scans_in_the_paper_office_land_on_its_walls():
    """From robot1's start, the returns are real obstacles; with the team visible, the
    teammates beside it are fictitious obstacles (xi of eq. 10)."""
    from petriflow.world import World

    office = paper_office()
    world = World(office.world(5))
    try:
        truth = office.truth()
        pose = world.pose("robot1")
        alone, team = GlobalMap(truth), GlobalMap(truth)
        ranges, angles = scan(world, "robot1", pose, ignore_teammates=True)
        assert ranges.shape == (360,) and (ranges < 8.0).sum() > 100
        alone.add(0, world_points(pose, ranges, angles, 8.0))
        ranges, angles = scan(world, "robot1", pose)
        team.add(0, world_points(pose, ranges, angles, 8.0))
        clean, seen = accuracy(alone.occupied, truth.occupied), accuracy(team.occupied, truth.occupied)
        assert clean.xi == 0 and clean.percent == 100.0 and clean.sigma > 50
        assert seen.xi > 0 and seen.percent < 100.0
    finally:
        world.close()


def test_a_teammate_moved_without_a_physics_step_is_seen_where_it_now_is():
    from petriflow.world import World

    world = World({"dt": 0.1, "gravity": 0.0, "plane": True,
                   "robots": [{"id": "robot1", "urdf": URDF, "position": [0.0, 0.0], "z": 0.05},
                              {"id": "robot2", "urdf": URDF, "position": [5.0, 5.0], "z": 0.05}]})
    try:
        p, body = world.p, world.body("robot2")
        position, orientation = p.getBasePositionAndOrientation(body, physicsClientId=world.client)
        p.resetBasePositionAndOrientation(body, (2.0, 0.0, position[2]), orientation,
                                          physicsClientId=world.client)
        ranges, _ = scan(world, "robot1", (0.0, 0.0, 0.0), beams=3)
        assert ranges[1] == pytest.approx(1.85, abs=0.01)
    finally:
        world.close()
