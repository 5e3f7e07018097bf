"""Leg kinematics: screw-theory forward kinematics, both inverse branches, Jacobian."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from petriflow.agents.legged.kinematics import (
    KNEE_BACKWARD,
    KNEE_FORWARD,
    LegGeometry,
    UnreachableError,
    forward,
    inverse,
    jacobian,
    joint_rates,
    solve,
    twists,
)
from petriflow.agents.legged.robots import ROBOT3L, ROBOT4L

LEG = ROBOT4L.leg("lf").geometry            # l1 > 0
MIRRORED = ROBOT4L.leg("rf").geometry       # l1 < 0 (mirror-image leg)
SHORT = ROBOT3L.leg("lf").geometry          # Robot3L's shorter lower leg
HIND = ROBOT3L.leg("h").geometry            # knee and ext only
LEGS = [LEG, MIRRORED, SHORT]

angles = st.floats(-math.pi / 3, math.pi / 3, allow_nan=False)
extensions = st.floats(0.0, 0.1, allow_nan=False)


def closed_form(leg: LegGeometry, q) -> np.ndarray:
    """p = Rz(q1) (l0 + l3, -l1 + L sin q2, -l2 - L cos q2), L = l4 + q3."""
    q1, q2, q3 = q
    length = leg.l4 + q3
    local = np.array([leg.d_oa, -leg.l1 + length * math.sin(q2), -leg.l2 - length * math.cos(q2)])
    c, s = math.cos(q1), math.sin(q1)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ local


def test_reference_configuration_puts_the_foot_at_p0():
    """At q = 0 the foot is at (l0 + l3, -l1, -l2 - l4) (Fig. 6)."""
    assert np.allclose(forward(LEG, (0, 0, 0)), [LEG.l0 + LEG.l3, -LEG.l1, -LEG.l2 - LEG.l4])


@pytest.mark.parametrize("leg", LEGS, ids=["left", "mirrored", "robot3l"])
@given(q1=angles, q2=angles, q3=extensions)
def test_screw_displacements_match_the_closed_form(leg, q1, q2, q3):
    """A1 A2 A3 p0 equals the leg's closed-form position."""
    assert np.allclose(forward(leg, (q1, q2, q3)), closed_form(leg, (q1, q2, q3)), atol=1e-12)


@pytest.mark.parametrize("leg", LEGS, ids=["left", "mirrored", "robot3l"])
@settings(max_examples=300)
@given(q1=angles, q2=angles, q3=extensions)
def test_inverse_of_forward_contains_the_joints(leg, q1, q2, q3):
    """IK of FK(q) returns q among its in-range solutions; each solution maps back."""
    foot = forward(leg, (q1, q2, q3))
    solutions = solve(leg, foot)
    assert any(np.allclose(s.q, (q1, q2, q3), atol=1e-7) for s in solutions)
    for solution in solutions:
        assert solution.in_range
        assert np.allclose(forward(leg, solution.q), foot, atol=1e-9)


def test_both_branches_round_trip_over_random_reachable_points():
    """Random points of the workspace: both knee branches, when in range, reach the
    point (FK∘IK = identity), and both are found over the sample."""
    rng = random.Random(3)
    seen = {KNEE_FORWARD: 0, KNEE_BACKWARD: 0}
    checked = 0
    while checked < 2000:
        foot = (rng.uniform(-0.15, 0.15), rng.uniform(-0.15, 0.15), rng.uniform(-0.22, -0.05))
        solutions = solve(LEG, foot)
        for solution in solutions:
            assert np.allclose(forward(LEG, solution.q), foot, atol=1e-9)
            seen[solution.branch] += 1
        checked += bool(solutions)
    assert seen[KNEE_FORWARD] > 500 and seen[KNEE_BACKWARD] > 500


def test_branches_differ_by_twice_alpha():
    """q1 = θ + α (knee forward) and θ - α (knee backward), cos α = d_OA / d_OP (eq. 5)."""
    foot = (0.07, 0.02, -0.12)
    forward_knee, backward_knee = solve(LEG, foot, include_out_of_range=True)
    theta = math.atan2(foot[1], foot[0])
    alpha = math.acos(LEG.d_oa / math.hypot(foot[0], foot[1]))
    assert forward_knee.branch == KNEE_FORWARD and backward_knee.branch == KNEE_BACKWARD
    assert forward_knee.q[0] == pytest.approx(theta + alpha)
    assert backward_knee.q[0] == pytest.approx(theta - alpha)


def test_points_nearer_the_hip_axis_than_d_oa_are_unreachable():
    """Within l0 + l3 of the hip axis: no solution, and a clear error."""
    assert solve(LEG, (0.01, 0.02, -0.1), include_out_of_range=True) == []
    with pytest.raises(UnreachableError, match="nearer than l0 \\+ l3"):
        inverse(LEG, (0.01, 0.02, -0.1))


def test_points_beyond_the_joint_ranges_are_flagged_or_refused():
    """Too far (ext over 100 mm) or too high (knee over π/3): flagged out of range,
    not returned by default, and inverse names the joint."""
    far = (LEG.d_oa, -LEG.l1, -0.3)
    assert solve(LEG, far) == []
    assert [s.in_range for s in solve(LEG, far, include_out_of_range=True)] == [False, False]
    with pytest.raises(UnreachableError, match="q3="):
        inverse(LEG, far)
    high = (LEG.d_oa, 0.15, -0.05)
    with pytest.raises(UnreachableError, match="outside the joint ranges"):
        inverse(LEG, high)


def test_one_branch_can_be_out_of_range_while_the_other_is_in():
    """A foot far to one side: only one branch keeps the hip within ±π/3."""
    solutions = solve(LEG, (0.05, 0.09, -0.12), include_out_of_range=True)
    assert sorted(s.in_range for s in solutions) == [False, True]
    assert len(solve(LEG, (0.05, 0.09, -0.12))) == 1


def test_inverse_near_keeps_the_closest_solution():
    """With ``near``, the solution nearest the given joints wins."""
    foot = forward(LEG, (0.3, -0.2, 0.05))
    for branch_q in (s.q for s in solve(LEG, foot)):
        assert np.allclose(inverse(LEG, foot, near=branch_q), branch_q)


def test_leg_without_hip_round_trips_and_rejects_points_off_its_plane():
    """Robot3L's hind leg (knee and ext): FK∘IK in its plane; points off it are unreachable."""
    for q in ((0, 0.3, 0.02), (0, -0.5, 0.07)):
        foot = forward(HIND, q)
        assert np.allclose(inverse(HIND, foot), q)
    with pytest.raises(UnreachableError, match="off the plane"):
        inverse(HIND, (0.02, 0.0, -0.08))


@pytest.mark.parametrize("leg", LEGS + [HIND], ids=["left", "mirrored", "robot3l", "hind"])
def test_jacobian_matches_finite_differences(leg):
    """J_f q̇ equals the central difference of the forward kinematics."""
    rng = np.random.default_rng(5)
    h = 1e-6
    for _ in range(50):
        q = rng.uniform([-1, -1, 0.0], [1, 1, 0.1])
        if not leg.has_hip:
            q[0] = 0.0
        numeric = np.zeros((3, 3))
        for i in range(3):
            step = np.zeros(3)
            step[i] = h
            numeric[:, i] = (forward(leg, q + step) - forward(leg, q - step)) / (2 * h)
        if not leg.has_hip:
            numeric[:, 0] = 0.0
        assert np.allclose(jacobian(leg, q), numeric, atol=1e-7)


def test_twists_follow_eq_12():
    """Columns of J0: hip (0,0,1; 0,0,0), knee (c1, s1, 0; l2 s1, -l2 c1, l1), ext
    (0; -s1 s2, c1 s2, -c2)."""
    q1, q2 = 0.4, -0.3
    c1, s1, c2, s2 = math.cos(q1), math.sin(q1), math.cos(q2), math.sin(q2)
    expected = np.array([
        [0, 0, 1, 0, 0, 0],
        [c1, s1, 0, LEG.l2 * s1, -LEG.l2 * c1, LEG.l1],
        [0, 0, 0, -s1 * s2, c1 * s2, -c2],
    ]).T
    assert np.allclose(twists(LEG, (q1, q2, 0.05)), expected)


def test_joint_rates_invert_the_jacobian():
    """q̇ = J_f⁻¹ ṗ moves the foot at ṗ."""
    q = (0.2, -0.4, 0.05)
    velocity = np.array([0.01, -0.02, 0.005])
    assert np.allclose(jacobian(LEG, q) @ joint_rates(LEG, q, velocity), velocity)
