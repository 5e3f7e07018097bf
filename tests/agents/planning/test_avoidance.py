"""Collision detection and priority-based avoidance (seed 003 §4.2, experiment 2)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from petriflow.agents.planning.actions import plan_world_path
from petriflow.agents.planning.avoidance import CollisionAvoidance, Directive, Order, conflicts, gap
from petriflow.agents.planning.errors import PlanningError
from petriflow.agents.planning.maps import ROBOT_LABELS, GridFrame, draw_disc

STEP, RADIUS = 0.05, 0.08


def test_conflict_below_two_steps_of_gap():
    """Robots conflict when the gap between their discs is under two standard steps."""
    positions = {"red": (0.0, 0.0), "blue": (0.25, 0.0), "green": (1.0, 0.0)}
    assert conflicts(positions, step=STEP) == []
    assert [(a, b) for a, b, _ in conflicts(positions, step=STEP, radius=RADIUS)] == [("blue", "red")]
    assert gap(positions["red"], positions["blue"], RADIUS, RADIUS) == pytest.approx(0.09)


def test_conflict_distance_with_per_robot_steps():
    """Different step lengths: one step of each makes the conflict distance."""
    positions = {"a": (0.0, 0.0), "b": (0.14, 0.0)}
    assert conflicts(positions, step={"a": 0.05, "b": 0.1})
    assert not conflicts(positions, step={"a": 0.02, "b": 0.1})
    with pytest.raises(PlanningError, match="no step given for robot 'b'"):
        conflicts(positions, step={"a": 0.05})


def test_higher_priority_replans_and_lower_holds():
    """In a conflict both stop: the higher priority re-plans around the other, the lower holds."""
    avoid = CollisionAvoidance({"red": 1, "blue": 5}, step=STEP)
    orders = avoid.update({"red": (0, 0), "blue": (0.05, 0.05)})
    assert orders == {"blue": Directive(Order.REPLAN, ("red",)), "red": Directive(Order.HOLD, ("blue",))}
    assert avoid.held() == {"red": ("blue",)}


def test_replan_is_ordered_once_then_go():
    """The leader re-plans once, then goes on while the follower still holds."""
    avoid = CollisionAvoidance({"red": 2, "blue": 1}, step=STEP)
    avoid.update({"red": (0, 0), "blue": (0.05, 0)})
    orders = avoid.update({"red": (0, -0.02), "blue": (0.05, 0)})
    assert orders["red"].order is Order.GO and orders["blue"].order is Order.HOLD


def test_follower_released_only_once_the_leader_has_passed():
    """The hold ends when the gap is back above two steps and growing, not before."""
    avoid = CollisionAvoidance({"red": 2, "blue": 1}, step=STEP)
    avoid.update({"red": (0.0, 0.0), "blue": (0.09, 0.0)})
    # the leader moves around the follower: still close, then far but coming closer
    assert avoid.update({"red": (0.05, -0.06), "blue": (0.09, 0.0)})["blue"].order is Order.HOLD
    assert avoid.update({"red": (0.09, -0.095), "blue": (0.09, 0.0)})["blue"].order is Order.HOLD
    assert avoid.update({"red": (0.2, -0.1), "blue": (0.09, 0.0)})["blue"].order is Order.GO
    assert avoid.held() == {}


def test_leader_gone_releases_the_follower():
    """A leader that leaves the positions (arrived, removed) no longer holds anyone."""
    avoid = CollisionAvoidance({"red": 2, "blue": 1}, step=STEP)
    avoid.update({"red": (0, 0), "blue": (0.05, 0)})
    assert avoid.update({"blue": (0.05, 0)})["blue"].order is Order.GO


def test_equal_priorities_break_by_name():
    """Equal priorities: the robot whose name sorts first leads."""
    avoid = CollisionAvoidance({"yellow": 1, "green": 1}, step=STEP)
    orders = avoid.update({"yellow": (0, 0), "green": (0.05, 0)})
    assert orders["green"].order is Order.REPLAN and orders["yellow"].order is Order.HOLD


def test_held_leader_replans_when_released():
    """A robot that must re-plan but is itself held first waits, then re-plans."""
    avoid = CollisionAvoidance({"a": 3, "b": 2, "c": 1}, step=STEP)
    orders = avoid.update({"a": (0.0, 0.0), "b": (0.08, 0.0), "c": (0.16, 0.0)})
    assert orders["a"] == Directive(Order.REPLAN, ("b",))
    assert orders["b"] == Directive(Order.HOLD, ("a",)) and orders["c"] == Directive(Order.HOLD, ("b",))
    orders = avoid.update({"a": (-0.5, 0.0), "b": (0.08, 0.0), "c": (0.16, 0.0)})
    assert orders["b"] == Directive(Order.REPLAN, ("c",)) and orders["c"].order is Order.HOLD


def test_unknown_priority_raises():
    """Every robot in a conflict needs a priority."""
    avoid = CollisionAvoidance({"red": 1}, step=STEP)
    with pytest.raises(PlanningError, match="no priority"):
        avoid.update({"red": (0, 0), "blue": (0.01, 0)})


# --- experiment 2: two robots on crossing paths -----------------------------------------
MPP = 0.0125
SHAPE = (120, 160)  # a 2.0 m x 1.5 m floor
FRAME = GridFrame(MPP, origin=(-(SHAPE[1] - 1) / 2 * MPP, (SHAPE[0] - 1) / 2 * MPP), cell=2)


def scene(positions):
    """The label map the camera would give: each robot a disc of its colour."""
    label = np.zeros(SHAPE, np.uint8)
    for colour, xy in positions.items():
        label = draw_disc(label, FRAME.world_to_pixel(xy), RADIUS / MPP, ROBOT_LABELS[colour])
    return label


def walk(position, path, index, step):
    position = np.asarray(position, float)
    left = step
    while left > 1e-12 and index < len(path):
        target = np.asarray(path[index], float)
        apart = float(np.hypot(*(target - position)))
        if apart <= left:
            position, left, index = target, left - apart, index + 1
        else:
            position, left = position + (target - position) * left / apart, 0.0
    return position, index


def test_crossing_paths_lower_priority_holds_and_the_other_replans():
    """Scripted experiment 2: red (priority) and blue walk crossing paths; when they get
    within two steps both stop, red re-plans around blue as a fixed obstacle and goes
    on, blue holds until red has passed, then finishes its own path. The discs never
    touch and both arrive."""
    goals = {"red": (0.8, 0.0), "blue": (0.0, -0.6)}
    positions = {"red": np.array([-0.8, 0.0]), "blue": np.array([0.0, 0.6])}
    paths, index = {}, {}
    for colour in positions:
        start = tuple(positions[colour])
        plan = plan_world_path(scene(positions), FRAME, colour, goals[colour], start, RADIUS)
        paths[colour], index[colour] = plan["path"], 1
    avoid = CollisionAvoidance({"red": 2, "blue": 1}, step=STEP, radius=RADIUS)
    orders = {c: Directive(Order.GO) for c in positions}
    counts = {(c, o): 0 for c in positions for o in Order}
    closest = math.inf
    for _ in range(200):
        for colour in positions:
            counts[colour, orders[colour].order] += 1
            if orders[colour].order is Order.REPLAN:  # stopped: plan around the others, as they stand
                fixed = {c: tuple(positions[c]) for c in orders[colour].others}
                label = scene({colour: tuple(positions[colour]), **fixed})
                plan = plan_world_path(label, FRAME, colour, goals[colour], tuple(positions[colour]), RADIUS)
                assert plan["found"]
                paths[colour], index[colour] = plan["path"], 1
            elif orders[colour].order is Order.GO:
                positions[colour], index[colour] = walk(positions[colour], paths[colour], index[colour], STEP)
        closest = min(closest, float(np.hypot(*(positions["red"] - positions["blue"]))))
        arrived = all(index[c] >= len(paths[c]) for c in positions)
        if arrived:
            break
        orders = avoid.update({c: tuple(p) for c, p in positions.items()})
    assert arrived
    assert counts["red", Order.REPLAN] == 1 and counts["red", Order.HOLD] == 0
    assert counts["blue", Order.REPLAN] == 0 and counts["blue", Order.HOLD] >= 3
    assert closest >= 2 * RADIUS - MPP  # the discs never overlap (to a pixel)
    assert positions["red"].tolist() == pytest.approx(goals["red"])
    assert positions["blue"].tolist() == pytest.approx(goals["blue"])
