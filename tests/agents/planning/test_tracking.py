"""Path tracking and correction (seed 003 §4.2): on track, reinsertion, re-plan."""

from __future__ import annotations

import math

import numpy as np
import pytest

from petriflow.agents.planning.errors import PlanningError
from petriflow.agents.planning.maps import GridFrame, segment_free
from petriflow.agents.planning.tracking import (
    PathTracker,
    Track,
    check_track,
    densify,
    distance_to_path,
    reinsertion_index,
)

STEP, RADIUS, REACH = 0.05, 0.12, 0.1


def walk(position, path, index, step):
    """Move ``step`` along ``path`` from ``position``, heading for ``path[index]``."""
    position = np.asarray(position, float)
    left = step
    while left > 1e-12 and index < len(path):
        target = np.asarray(path[index], float)
        gap = float(np.hypot(*(target - position)))
        if gap <= left:
            position, left, index = target, left - gap, index + 1
        else:
            position, left = position + (target - position) * left / gap, 0.0
    return position, index


def test_distance_to_a_polyline():
    """dc is the distance to the nearest segment (not just the nearest vertex)."""
    distance, segment, foot = distance_to_path([(0, 0), (2, 0), (2, 2)], (1.0, 0.3))
    assert distance == pytest.approx(0.3) and segment == 0 and foot.tolist() == [1.0, 0.0]
    distance, segment, _ = distance_to_path([(0, 0), (2, 0), (2, 2)], (2.5, 1.0))
    assert distance == pytest.approx(0.5) and segment == 1
    assert distance_to_path([(0, 0), (0, 0), (1, 0)], (0.5, 0.1))[0] == pytest.approx(0.1)


@pytest.mark.parametrize("offset, kind", [
    (0.0, Track.ON_TRACK), (0.049, Track.ON_TRACK), (0.05, Track.REINSERT), (0.09, Track.REINSERT),
    (0.12, Track.REINSERT), (0.121, Track.REPLAN), (0.5, Track.REPLAN),
])
def test_thresholds_dmin_and_r(offset, kind):
    """dc < dmin: on track; dmin ≤ dc ≤ r: reinsert; dc > r: re-plan."""
    path = densify([(0, 0), (1, 0)], 0.01)
    assert check_track(path, (0.5, offset), step=STEP, radius=RADIUS).kind is kind


def test_reinsertion_picks_the_farthest_point_within_one_move():
    """The reinsertion point is the path point farthest along the path within reach."""
    path = densify([(0, 0), (1, 0)], 0.01)
    decision = check_track(path, (0.3, 0.08), step=STEP, radius=RADIUS, reach=REACH)
    assert decision.kind is Track.REINSERT
    assert decision.point == pytest.approx((0.36, 0.0))
    assert math.dist(decision.point, (0.3, 0.08)) <= REACH
    farther = [p for p in path[decision.index + 1:] if math.dist(p, (0.3, 0.08)) <= REACH]
    assert farther == []


def test_reinsertion_takes_the_point_farthest_along_the_path():
    """Farthest means by path index, not by distance: when the path doubles back near
    the robot, the point on the return leg wins; none before ``first`` qualifies."""
    path = densify([(0, 0), (1, 0), (1, 0.2), (0, 0.2)], 0.01)
    index = reinsertion_index(path, (0.5, 0.1), reach=0.11, first=51)
    assert index > 120 and path[index].tolist() == pytest.approx([0.46, 0.2])
    assert reinsertion_index(path, (0.5, 0.1), reach=0.11, first=index + 1) is None


def test_reinsertion_point_must_be_in_line_of_sight():
    """With a map, a path point behind a wall is never chosen, however far along it is."""
    grid = np.zeros((100, 100), bool)
    grid[50:, 49:52] = True  # a thin wall x ≈ 0.5, from the bottom up to y = 0
    frame = GridFrame(0.01, origin=(0.0, 0.5))
    path = densify([(0.45, -0.45), (0.45, 0.1), (0.55, 0.1), (0.55, -0.45)], 0.01)
    robot = (0.38, -0.1)
    blind = check_track(path, robot, step=STEP, radius=RADIUS, reach=0.25)
    assert not segment_free(grid, frame, robot, blind.point)  # it would walk into the wall

    def line_free(a, b):
        return segment_free(grid, frame, a, b)

    seeing = check_track(path, robot, step=STEP, radius=RADIUS, reach=0.25, line_free=line_free)
    assert seeing.kind is Track.REINSERT and seeing.index < blind.index
    assert segment_free(grid, frame, robot, seeing.point)


def test_far_path_rejoined_at_the_perpendicular_foot():
    """No path point within reach (sparse path): head for the nearest point of the path."""
    decision = check_track([(0, 0), (1, 0)], (0.4, 0.1), step=STEP, radius=RADIUS, reach=REACH)
    assert decision.kind is Track.REINSERT and decision.point == pytest.approx((0.4, 0.0))


def test_robot_pushed_off_its_path_is_reinserted():
    """Scripted experiment 1: a robot walking its path is pushed sideways between dmin
    and r; the tracker sends it to a point ahead on the path, reached in one move,
    after which it is on track again to the end."""
    path = densify([(0.0, 0.0), (1.0, 0.0), (1.0, 0.5)], 0.0125)
    tracker = PathTracker(path, step=STEP, radius=RADIUS, reach=REACH)
    position, index, log = np.array(path[0]), 1, []
    for move in range(60):
        if move == 6:
            position = position + (0.0, 0.08)  # pushed
        decision = tracker.check(position)
        log.append(decision.kind)
        if decision.kind is Track.REINSERT:
            assert math.dist(decision.point, position) <= REACH + 1e-9
            assert decision.point[0] > position[0]  # ahead, toward the goal
            position, index = np.array(decision.point), decision.index + 1
            continue
        assert decision.kind is Track.ON_TRACK
        if index >= len(path):
            break
        position, index = walk(position, path, index, STEP)
    assert log.count(Track.REINSERT) == 1 and log[6] is Track.REINSERT
    assert position.tolist() == pytest.approx([1.0, 0.5])
    assert tracker.progress == len(path) - 2


def test_robot_pushed_far_must_replan():
    """Pushed farther than its radius, the robot stops for a re-plan; the new path
    starting where it stands puts it back on track."""
    tracker = PathTracker(densify([(0, 0), (1, 0)], 0.01), step=STEP, radius=RADIUS)
    tracker.check((0.2, 0.0))
    assert tracker.check((0.2, 0.3)).kind is Track.REPLAN
    tracker.replace(densify([(0.2, 0.3), (1.0, 0.0)], 0.01))
    assert tracker.check((0.2, 0.3)).kind is Track.ON_TRACK and tracker.progress == 0


def test_progress_only_grows():
    """The tracker's progress index never goes back."""
    tracker = PathTracker(densify([(0, 0), (1, 0)], 0.1), step=STEP, radius=RADIUS)
    tracker.check((0.55, 0.0))
    assert tracker.progress == 5
    tracker.check((0.25, 0.0))
    assert tracker.progress == 5
    assert tracker.remaining()[0].tolist() == pytest.approx([0.6, 0.0])


def test_bad_inputs_raise():
    """An empty path, a non-positive step or radius are PlanningErrors."""
    with pytest.raises(PlanningError):
        check_track([], (0, 0), step=STEP, radius=RADIUS)
    with pytest.raises(PlanningError):
        check_track([(0, 0)], (0, 0), step=0.0, radius=RADIUS)
    with pytest.raises(PlanningError):
        densify([(0, 0), (1, 0)], 0)
