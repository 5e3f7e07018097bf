"""Gaits: stability at every instant, transfer ellipses, straight support lines, stride."""

from __future__ import annotations

import math

import numpy as np
import pytest
from petriflow.agents.legged.gait import (
    CrawlGait,
    GaitError,
    SlideGait,
    compose,
    smooth,
    to_body,
    transfer_point,
)
from petriflow.agents.legged.robots import ROBOT3L, ROBOT4L

STEP = 0.01  # sampling period (s)


def cycles(gait, motions):
    """Plan consecutive cycles from the standing state; returns the plans."""
    state = gait.standing()
    plans = []
    for motion in motions:
        plan, state = gait.cycle(state, motion)
        plans.append(plan)
    return plans


CRAWL_MOTIONS = {
    "forward": [(0.06, 0, 0)] * 3 + [(0, 0, 0)],
    "backward": [(-0.06, 0, 0)] * 2 + [(0, 0, 0)],
    "turn left": [(0, 0, 0.35)] * 2 + [(0, 0, 0)],
    "turn right": [(0, 0, -0.35)] * 2 + [(0, 0, 0)],
    "arc": [(0.06, 0, 0.15)] * 2 + [(0, 0, 0)],
    "long stride": [(0.08, 0, 0)] * 2 + [(0, 0, 0)],
}
SLIDE_MOTIONS = {
    "forward": [(0.08, 0, 0)] * 3 + [(0, 0, 0)],
    "backward": [(-0.08, 0, 0)] * 2 + [(0, 0, 0)],
    "turn left": [(0, 0, 0.4)] * 2 + [(0, 0, 0)],
    "turn right": [(0, 0, -0.4)] * 2 + [(0, 0, 0)],
}


@pytest.mark.parametrize("name", sorted(CRAWL_MOTIONS))
def test_crawl_keeps_the_centre_of_gravity_inside_the_support_polygon(name):
    """Robot4L: at every sampled instant, the centre of gravity (from the legs'
    kinematics) lies at least 1 cm inside the polygon of the feet on the ground."""
    gait = CrawlGait(ROBOT4L, stride=0.08)
    for plan in cycles(gait, CRAWL_MOTIONS[name]):
        margins = [plan.margin(sample) for sample in plan.samples(STEP)]
        assert min(margins) > 0.01


@pytest.mark.parametrize("name", sorted(SLIDE_MOTIONS))
def test_slide_keeps_the_centre_of_gravity_inside_the_support_polygon(name):
    """Robot3L: inside the feet's triangle during strokes, inside the belly-and-skid
    polygon while the front feet swing."""
    for plan in cycles(SlideGait(ROBOT3L), SLIDE_MOTIONS[name]):
        assert min(plan.margin(sample) for sample in plan.samples(STEP)) > 0.02


def test_crawl_moves_one_leg_at_a_time_and_the_body_only_on_four_feet():
    """Transfer phases move one leg with the body still; body phases move no leg."""
    for plan in cycles(CrawlGait(ROBOT4L), CRAWL_MOTIONS["forward"]):
        for phase in plan.phases:
            if phase.kind == "transfer":
                assert len(phase.moving) == 1 and phase.body_start == phase.body_end
            else:
                assert phase.moving == ()
        for sample in plan.samples(STEP):
            assert len(sample.support) >= 3


def test_crawl_sequence_is_left_hind_left_front_right_hind_right_front():
    """The crawl's leg order when walking forward."""
    plan = cycles(CrawlGait(ROBOT4L), [(0.06, 0, 0)])[0]
    assert [p.moving[0] for p in plan.phases if p.kind == "transfer"] == ["lh", "lf", "rh", "rf"]


def test_slide_never_lifts_the_hind_skid():
    """Robot3L's hind foot stays on the ground; the front feet swing while the belly rests."""
    for plan in cycles(SlideGait(ROBOT3L), SLIDE_MOTIONS["forward"]):
        for sample in plan.samples(STEP):
            assert "h" in sample.support and abs(sample.feet["h"][2]) < 1e-6
            if sample.moving:
                assert sample.belly and set(sample.moving) == {"lf", "rf"}


@pytest.mark.parametrize("gait", [CrawlGait(ROBOT4L), SlideGait(ROBOT3L)], ids=["crawl", "slide"])
def test_transfer_paths_are_half_ellipses(gait):
    """Each transfer: the foot stays in the vertical plane through lift-off and
    touch-down, on the ellipse with semi-axes half the step and the lift height."""
    for plan in cycles(gait, [(gait.stride, 0, 0)] * 2 + [(0, 0, 0), (0, 0, gait.max_turn)]):
        start = 0.0
        for phase in plan.phases:
            if phase.kind == "transfer":
                for leg in phase.moving:
                    p0, p1 = np.asarray(phase.feet_start[leg]), np.asarray(phase.feet_end[leg])
                    half = np.linalg.norm(p1 - p0) / 2
                    along = (p1 - p0) / (2 * half) if half > 0 else np.zeros(3)
                    for i in range(1, 50):
                        foot = plan.sample(start + phase.duration * i / 50).feet[leg]
                        offset = foot - p0
                        u = float(offset @ along)
                        w = float(offset[2])
                        sideways = offset - u * along - np.array([0, 0, w])
                        assert np.linalg.norm(sideways) < 1e-9
                        if half < 1e-9:  # stepping in place: straight up and down
                            assert 0 <= w <= phase.lift + 1e-12
                            continue
                        assert ((u - half) / half) ** 2 + (w / phase.lift) ** 2 == pytest.approx(1.0, abs=1e-9)
                        assert w >= 0
            start += phase.duration


def _support_tracks(gait, motions):
    """Body-frame foot positions of each leg, one list per uninterrupted support period."""
    tracks: dict[str, list[list[np.ndarray]]] = {leg: [[]] for leg in gait.design.leg_names}
    for plan in cycles(gait, motions):
        for sample in plan.samples(STEP):
            for leg in gait.design.leg_names:
                if leg in sample.moving:
                    if tracks[leg][-1]:
                        tracks[leg].append([])
                else:
                    tracks[leg][-1].append(np.asarray(sample.feet_body[leg]))
    return {leg: [np.array(t) for t in periods if len(t) > 5] for leg, periods in tracks.items()}


@pytest.mark.parametrize("gait", [CrawlGait(ROBOT4L), SlideGait(ROBOT3L)], ids=["crawl", "slide"])
def test_support_paths_are_straight_lines_parallel_to_the_body(gait):
    """Walking straight, a supporting foot moves relative to the body along a straight
    line parallel to the body's axis (constant y and z); the crawl's stability shifts
    move the body to and fro along that line."""
    tracks = _support_tracks(gait, [(gait.stride, 0, 0)] * 3)
    for leg, periods in tracks.items():
        if leg in gait.carried:
            continue
        for track in periods:
            assert np.ptp(track[:, 1]) < 1e-9 and np.ptp(track[:, 2]) < 1e-9


def test_turning_support_paths_are_arcs_about_the_body_centre():
    """Turning on the spot (Robot3L's strokes rotate the body about its origin), a
    supporting foot keeps its distance from the body centre: its path is tangent to
    the rotation."""
    gait = SlideGait(ROBOT3L)
    tracks = _support_tracks(gait, [(0, 0, 0.4)] * 2)
    for leg, periods in tracks.items():
        if leg in gait.carried:
            continue
        swept = 0.0
        for track in periods:
            radius = np.hypot(track[:, 0], track[:, 1])
            assert np.ptp(radius) < 1e-9
            angles = np.unwrap(np.arctan2(track[:, 1], track[:, 0]))
            swept = max(swept, abs(angles[-1] - angles[0]))
        assert swept == pytest.approx(0.4, abs=1e-3)


def test_crawl_turns_the_path_by_the_asked_angle():
    """Each turning cycle of the crawl rotates the path by its motion; the feet land
    half a cycle ahead of their nominal places."""
    gait = CrawlGait(ROBOT4L)
    state = gait.standing()
    for k in range(1, 4):
        _, state = gait.cycle(state, (0, 0, 0.3))
        assert state.path[2] == pytest.approx(0.3 * k)


@pytest.mark.parametrize("gait", [CrawlGait(ROBOT4L), SlideGait(ROBOT3L)], ids=["crawl", "slide"])
def test_stride_length(gait):
    """In steady state each transfer moves a foot one stride forward and each cycle
    moves the body one stride."""
    state = gait.standing()
    plan, state = gait.cycle(state, (gait.stride, 0, 0))      # start-up cycle
    before = state
    plan, state = gait.cycle(state, (gait.stride, 0, 0))
    assert state.path[0] - before.path[0] == pytest.approx(gait.stride)
    assert state.body[0] - before.body[0] == pytest.approx(gait.stride, abs=1e-6)
    for phase in plan.phases:
        for leg in phase.moving:
            step = np.asarray(phase.feet_end[leg]) - np.asarray(phase.feet_start[leg])
            assert step[0] == pytest.approx(gait.stride) and abs(step[1]) < 1e-9


def test_crawl_shifts_the_body_only_along_its_axis_when_walking_straight():
    """The stability shift adjusts the step along the body's axis (Fig. 8(b)), never sideways."""
    for plan in cycles(CrawlGait(ROBOT4L), CRAWL_MOTIONS["forward"]):
        for sample in plan.samples(STEP):
            assert abs(sample.body[1]) < 1e-12 and abs(sample.body[2]) < 1e-12


def test_joints_stay_within_table_3():
    """Every sampled posture of every gait solves within the joint ranges."""
    for gait, motions in ((CrawlGait(ROBOT4L, stride=0.08), CRAWL_MOTIONS), (SlideGait(ROBOT3L), SLIDE_MOTIONS)):
        for sequence in motions.values():
            for plan in cycles(gait, sequence):
                for sample in plan.samples(0.05):
                    for leg, q in plan.joints(sample).items():
                        assert gait.design.leg(leg).geometry.in_range(q)


def test_zero_motion_brings_the_feet_back_to_the_standing_posture():
    """After walking, a zero-motion cycle leaves every foot at its nominal place under
    a centred body."""
    for gait in (CrawlGait(ROBOT4L), SlideGait(ROBOT3L)):
        plan = cycles(gait, [(gait.stride, 0, 0)] * 2 + [(0, 0, 0)])[-1]
        end = plan.sample(plan.duration)
        for leg, nominal in gait.nominal.items():
            assert np.allclose(end.feet_body[leg], nominal, atol=1e-9)


def test_motions_beyond_the_gait_limits_are_refused():
    """A cycle longer than the stride or turning more than the limit raises GaitError."""
    gait = CrawlGait(ROBOT4L)
    with pytest.raises(GaitError, match="at most"):
        gait.cycle(gait.standing(), (0.2, 0, 0))
    with pytest.raises(GaitError, match="turns at most"):
        gait.cycle(gait.standing(), (0, 0, 1.0))
    with pytest.raises(GaitError):
        CrawlGait(ROBOT4L, stride=0.3).cycle(CrawlGait(ROBOT4L).standing(), (0.3, 0, 0))


def test_robot3l_is_faster_than_robot4l():
    """As in the paper (§2): the three-legged robot is the faster one."""
    assert SlideGait(ROBOT3L).speed > CrawlGait(ROBOT4L).speed


def test_time_scaling_and_ellipse_are_smooth_at_their_ends():
    """Zero velocity at both ends of the time scaling; the transfer starts and ends on
    the ground, straight up and down."""
    h = 1e-5
    assert (smooth(h) - smooth(0)) / h == pytest.approx(0, abs=1e-4)
    assert (smooth(1) - smooth(1 - h)) / h == pytest.approx(0, abs=1e-4)
    start, end = (0, 0, 0), (0.06, 0, 0)
    rise = transfer_point(start, end, 0.03, 1e-4) - np.array(start)
    assert rise[2] > 50 * rise[0]


def test_pose_helpers_invert_each_other():
    """to_body undoes compose's frame change for a point."""
    pose = compose((0.3, -0.2, 0.4), (0.1, 0.05, -0.2))
    point = np.array([1.0, 2.0, 0.0])
    c, s = math.cos(pose[2]), math.sin(pose[2])
    back = to_body(pose, 0.1, point)
    assert np.allclose([pose[0] + c * back[0] - s * back[1], pose[1] + s * back[0] + c * back[1]], point[:2])
