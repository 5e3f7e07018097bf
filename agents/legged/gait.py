"""Gaits: foot and body trajectories for Robot4L's crawl and Robot3L's sliding gait.

The walking pattern of seed 003 (§3.5, after Estremera 2003): every leg alternates a
*transfer phase* (foot in the air, from a lift-off point to a touch-down point on an
elliptical path whose top is set by the ext actuator) and a *support phase* (foot on
the ground; relative to the body it moves along the straight line joining those two
points, parallel to the body when walking straight, tangent to the turn when turning).
The centre of gravity must stay inside the polygon of the supporting feet; the step is
adjusted to guarantee it.

A gait here is a *plan*: a list of :class:`Phase` objects in a plan frame on the ground
(feet centres at ``z = 0``, the body origin at its standing height), which
:meth:`GaitPlan.sample` turns into body pose, foot positions (ground and body frame)
and supporting legs at any instant. Both gaits are *discontinuous* (two-phase): the
body moves only while every leg supports, and legs move only while the body stands
still, so the feet on the ground never slip in the plan.

* :class:`CrawlGait` (Robot4L): one leg in transfer at a time, in the order left hind,
  left front, right hind, right front (reversed front-to-back when walking
  backwards). Before each transfer the body moves a quarter of the cycle's motion and
  shifts along its own x axis (the paper adjusts the step, Fig. 8(b)) by just enough
  for the centre of gravity to lie ``margin`` inside the triangle of the other three
  feet for the whole transfer. Each foot lands half a cycle ahead of its nominal
  position, so in steady state every foot sweeps the stride symmetrically about it.
* :class:`SlideGait` (Robot3L, §2.1: "it is absolutely necessary that the three legs
  are resting on the surface. Therefore, the robot moves sliding"): the hind skid
  never lifts. A *stroke* moves the body one stride while the front feet stay on the
  ground and the hind skid slides along with the body; then both front feet move
  forwards together while the robot rests on its belly (the battery box) and the skid.

A cycle's motion is ``(dx, dy, dyaw)`` in the body frame: ``(stride, 0, 0)`` walks
straight, ``(0, 0, angle)`` turns on the spot, ``(0, 0, 0)`` brings the feet back to the
standing posture.

Examples:
    >>> from petriflow.agents.legged.robots import ROBOT4L
    >>> gait = CrawlGait(ROBOT4L)
    >>> state = gait.standing()
    >>> plan, state = gait.cycle(state, (0.06, 0.0, 0.0))
    >>> len(plan.phases), round(plan.duration, 2)
    (8, 3.6)
    >>> [round(v, 3) for v in state.path]
    [0.06, 0.0, 0.0]
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field

import numpy as np
from petriflow.agents.legged.kinematics import UnreachableError, inverse
from petriflow.agents.legged.robots import RobotDesign
from petriflow.agents.legged.stability import stability_margin

__all__ = [
    "CrawlGait",
    "GaitError",
    "GaitPlan",
    "GaitSample",
    "GaitState",
    "Phase",
    "Pose",
    "SlideGait",
    "compose",
    "gait_for",
    "smooth",
    "to_body",
    "to_ground",
    "transfer_point",
]

Pose = tuple[float, float, float]
"""A planar pose ``(x, y, yaw)``."""


class GaitError(ValueError):
    """A motion the gait cannot plan (a foot out of reach, no stable body position)."""


def compose(a: Pose, b: Pose) -> Pose:
    """The pose ``b`` (given in ``a``'s frame) in ``a``'s parent frame.

    Examples:
        >>> [round(v, 6) + 0.0 for v in compose((1.0, 0.0, math.pi / 2), (1.0, 0.0, 0.0))]
        [1.0, 1.0, 1.570796]
    """
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], a[2] + b[2])


def to_ground(body: Pose, height: float, point: Sequence[float]) -> np.ndarray:
    """A body-frame point in the plan (ground) frame, the body at ``height``."""
    c, s = math.cos(body[2]), math.sin(body[2])
    x, y, z = point
    return np.array([body[0] + c * x - s * y, body[1] + s * x + c * y, height + z])


def to_body(body: Pose, height: float, point: Sequence[float]) -> np.ndarray:
    """A ground-frame point in the body frame, the body at ``height``.

    Examples:
        >>> p = to_ground((0.2, 0.1, 0.5), 0.12, (0.1, -0.1, -0.12))
        >>> [round(float(v), 9) + 0.0 for v in to_body((0.2, 0.1, 0.5), 0.12, p)]
        [0.1, -0.1, -0.12]
    """
    c, s = math.cos(body[2]), math.sin(body[2])
    dx, dy = point[0] - body[0], point[1] - body[1]
    return np.array([c * dx + s * dy, -s * dx + c * dy, point[2] - height])


def smooth(tau: float) -> float:
    """Cycloidal time scaling of ``tau ∈ [0, 1]``: starts and ends with zero velocity
    and acceleration, so foot and body paths are second-order smooth (§3.5).

    Examples:
        >>> smooth(0.0), smooth(0.5), smooth(1.0)
        (0.0, 0.5, 1.0)
    """
    tau = min(1.0, max(0.0, tau))
    return tau - math.sin(2 * math.pi * tau) / (2 * math.pi)


def transfer_point(start: Sequence[float], end: Sequence[float], height: float, s: float) -> np.ndarray:
    """Point ``s ∈ [0, 1]`` of the transfer path: half an ellipse in the vertical plane
    through ``start`` and ``end``, semi-axes half the step and ``height``.

    Examples:
        >>> [round(float(v), 4) + 0.0 for v in transfer_point((0, 0, 0), (0.06, 0, 0), 0.03, 0.5)]
        [0.03, 0.0, 0.03]
    """
    angle = math.pi * min(1.0, max(0.0, s))
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    along = (1 - math.cos(angle)) / 2
    return start + along * (end - start) + np.array([0.0, 0.0, height * math.sin(angle)])


@dataclass(frozen=True)
class Phase:
    """One phase of a plan: the body moves (every foot supports) or legs transfer (the
    body stands still).

    Attributes:
        kind: ``"body"`` or ``"transfer"``.
        duration: seconds.
        body_start, body_end: body poses at the phase's start and end.
        feet_start, feet_end: ground positions of the (not carried) feet.
        moving: the legs in transfer.
        carried: legs whose feet stay fixed to the body and slide (Robot3L's skid).
        lift: transfer height (m).
        belly: whether the robot rests on its belly during the phase.
    """

    kind: str
    duration: float
    body_start: Pose
    body_end: Pose
    feet_start: dict
    feet_end: dict
    moving: tuple[str, ...] = ()
    carried: tuple[str, ...] = ()
    lift: float = 0.0
    belly: bool = False


@dataclass(frozen=True)
class GaitSample:
    """The plan at one instant.

    Attributes:
        time: seconds since the plan's start.
        body: body pose in the plan frame.
        feet: foot centres in the plan frame (``z = 0`` on the ground).
        feet_body: foot centres in the body frame.
        support: legs whose feet are on the ground (standing or sliding).
        moving: legs in transfer.
        belly: whether the robot rests on its belly.
        phase: index of the phase.
    """

    time: float
    body: Pose
    feet: dict
    feet_body: dict
    support: tuple[str, ...]
    moving: tuple[str, ...]
    belly: bool
    phase: int


@dataclass
class GaitPlan:
    """A sequence of phases, sampled at any time.

    Attributes:
        design: the robot.
        height: body origin's height above the feet centres' plane.
        carried_feet: body-frame positions of carried (sliding) feet.
        phases: the phases in order.
    """

    design: RobotDesign
    height: float
    carried_feet: dict
    phases: list[Phase] = field(default_factory=list)

    @property
    def duration(self) -> float:
        """Seconds the plan lasts."""
        return sum(p.duration for p in self.phases)

    def sample(self, t: float) -> GaitSample:
        """The plan at time ``t`` (clamped to ``[0, duration]``)."""
        if not self.phases:
            raise GaitError("empty plan")
        t = min(max(t, 0.0), self.duration)
        start = 0.0
        for index, phase in enumerate(self.phases):
            if t <= start + phase.duration or index == len(self.phases) - 1:
                tau = (t - start) / phase.duration if phase.duration > 0 else 1.0
                return self._sample(phase, index, t, smooth(tau))
            start += phase.duration
        raise AssertionError("unreachable")  # pragma: no cover

    def samples(self, dt: float) -> Iterator[GaitSample]:
        """Samples every ``dt`` seconds from 0 to the end (inclusive)."""
        steps = math.ceil(self.duration / dt - 1e-9)
        for i in range(steps + 1):
            yield self.sample(min(i * dt, self.duration))

    def _sample(self, phase: Phase, index: int, t: float, s: float) -> GaitSample:
        a, b = phase.body_start, phase.body_end
        body = (a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]), a[2] + s * (b[2] - a[2]))
        feet, feet_body = {}, {}
        for leg in self.design.leg_names:
            if leg in phase.carried:
                feet_body[leg] = np.asarray(self.carried_feet[leg], dtype=float)
                feet[leg] = to_ground(body, self.height, feet_body[leg])
                continue
            if leg in phase.moving:
                feet[leg] = transfer_point(phase.feet_start[leg], phase.feet_end[leg], phase.lift, s)
            else:
                feet[leg] = np.asarray(phase.feet_start[leg], dtype=float)
            feet_body[leg] = to_body(body, self.height, feet[leg])
        support = tuple(leg for leg in self.design.leg_names if leg not in phase.moving)
        return GaitSample(t, body, feet, feet_body, support, phase.moving, phase.belly, index)

    def joints(self, sample: GaitSample, near: dict | None = None) -> dict[str, tuple[float, float, float]]:
        """Joint values of every leg at a sample (each leg on its own branch).

        Raises:
            GaitError: a foot out of reach.
        """
        return _joints(self.design, sample.feet_body, near)

    def support_points(self, sample: GaitSample) -> list[tuple[float, float]]:
        """Ground contacts at a sample: supporting feet, and the belly's footprint when
        the robot rests on it."""
        points = [(float(sample.feet[leg][0]), float(sample.feet[leg][1])) for leg in sample.support]
        if sample.belly and self.design.belly is not None:
            box = self.design.body[self.design.belly]
            for sx in (-1, 1):
                for sy in (-1, 1):
                    corner = (box.centre[0] + sx * box.size[0] / 2, box.centre[1] + sy * box.size[1] / 2, 0.0)
                    g = to_ground(sample.body, self.height, corner)
                    points.append((float(g[0]), float(g[1])))
        return points

    def centre_of_gravity(self, sample: GaitSample) -> np.ndarray:
        """Centre of gravity in the plan frame at a sample (from the legs' kinematics)."""
        com = self.design.centre_of_mass(self.joints(sample))
        return to_ground(sample.body, self.height, com)

    def margin(self, sample: GaitSample) -> float:
        """Stability margin of the centre of gravity at a sample (m, positive inside)."""
        cog = self.centre_of_gravity(sample)
        return stability_margin(cog[:2], self.support_points(sample))


def _joints(design: RobotDesign, feet_body: dict, near: dict | None = None) -> dict[str, tuple[float, float, float]]:
    joints = {}
    for leg in design.legs:
        try:
            joints[leg.name] = inverse(leg.geometry, leg.to_leg(feet_body[leg.name]), branch=leg.branch,
                                       near=None if near is None else near.get(leg.name))
        except UnreachableError as exc:
            raise GaitError(f"{design.name} leg {leg.name}: {exc}") from None
    return joints


@dataclass(frozen=True)
class GaitState:
    """Where a gait stands between cycles.

    Attributes:
        path: the body's pose on its path, without the stability shift.
        body: the body's pose.
        feet: ground positions of the feet (carried feet excluded).
    """

    path: Pose
    body: Pose
    feet: dict


def _scaled(motion: Sequence[float], factor: float) -> Pose:
    return (motion[0] * factor, motion[1] * factor, motion[2] * factor)


class _Gait:
    """What both gaits share: the design, the standing posture, checks."""

    carried: tuple[str, ...] = ()

    def __init__(self, design: RobotDesign, *, stride: float, lift: float, transfer_time: float,
                 body_time: float, max_turn: float) -> None:
        self.design = design
        self.stride = stride
        self.lift = lift
        self.transfer_time = transfer_time
        self.body_time = body_time
        self.max_turn = max_turn
        self.nominal = design.nominal_feet()
        self.height = float(-self.nominal[design.legs[0].name][2])

    def standing(self, pose: Pose = (0.0, 0.0, 0.0)) -> GaitState:
        """The state of the robot standing in its nominal posture at ``pose``."""
        feet = {leg: self._nominal_ground(pose, leg) for leg in self.design.leg_names if leg not in self.carried}
        return GaitState(pose, pose, feet)

    def _nominal_ground(self, pose: Pose, leg: str) -> np.ndarray:
        point = to_ground(pose, self.height, self.nominal[leg])
        point[2] = 0.0
        return point

    def _plan(self) -> GaitPlan:
        return GaitPlan(self.design, self.height, {leg: self.nominal[leg] for leg in self.carried})

    def check(self, motion: Sequence[float]) -> None:
        """Raise :class:`GaitError` if a cycle's motion exceeds the gait's limits."""
        if math.hypot(motion[0], motion[1]) > self.stride + 1e-9:
            raise GaitError(f"a cycle moves at most {self.stride} m, asked {math.hypot(motion[0], motion[1]):.3g}")
        if abs(motion[2]) > self.max_turn + 1e-9:
            raise GaitError(f"a cycle turns at most {self.max_turn} rad, asked {motion[2]:.3g}")

    def _validate(self, plan: GaitPlan, points: int = 6) -> None:
        """Every phase reachable at a few instants (raises GaitError otherwise)."""
        start = 0.0
        for phase in plan.phases:
            for i in range(points + 1):
                plan.joints(plan.sample(start + phase.duration * i / points))
            start += phase.duration

    @property
    def cycle_time(self) -> float:
        """Seconds per cycle."""
        raise NotImplementedError

    @property
    def speed(self) -> float:
        """Planned walking speed at full stride (m/s)."""
        return self.stride / self.cycle_time


class CrawlGait(_Gait):
    """Robot4L's crawl: one leg in transfer at a time, body shifted for stability.

    Args:
        design: the robot (four legs named ``lf``, ``rf``, ``lh``, ``rh``).
        stride: body travel per cycle (m).
        lift: foot lift in transfer (m).
        transfer_time: seconds per leg transfer.
        body_time: seconds per body move.
        margin: stability margin kept during transfers (m).
        max_turn: largest turn per cycle (rad).

    Examples:
        >>> from petriflow.agents.legged.robots import ROBOT4L
        >>> gait = CrawlGait(ROBOT4L)
        >>> round(gait.speed, 4), gait.cycle_time
        (0.0167, 3.6)
    """

    ORDER = ("lh", "lf", "rh", "rf")
    BACKWARDS = ("lf", "lh", "rf", "rh")

    def __init__(self, design: RobotDesign, *, stride: float = 0.06, lift: float = 0.03, transfer_time: float = 0.5,
                 body_time: float = 0.4, margin: float = 0.015, max_turn: float = 0.35) -> None:
        super().__init__(design, stride=stride, lift=lift, transfer_time=transfer_time, body_time=body_time,
                         max_turn=max_turn)
        self.margin_required = margin

    @property
    def cycle_time(self) -> float:
        return 4 * (self.transfer_time + self.body_time)

    def cycle(self, state: GaitState, motion: Sequence[float]) -> tuple[GaitPlan, GaitState]:
        """Plan one cycle moving the path by ``motion`` (body frame); returns the plan and
        the state after it. A zero motion steps every foot back to its nominal place
        and re-centres the body.

        Raises:
            GaitError: the motion is too large, or no stable, reachable body position.
        """
        self.check(motion)
        order = self.BACKWARDS if motion[0] < 0 else self.ORDER
        plan = self._plan()
        path, body, feet = state.path, state.body, {k: np.asarray(v, dtype=float) for k, v in state.feet.items()}
        for leg in order:
            path = compose(path, _scaled(motion, 0.25))
            target = self._nominal_ground(compose(path, _scaled(motion, 0.5)), leg)
            placed = self._place_body(path, feet, leg, target)
            plan.phases.append(Phase("body", self.body_time, body, placed, dict(feet), dict(feet)))
            after = dict(feet)
            after[leg] = target
            plan.phases.append(Phase("transfer", self.transfer_time, placed, placed, dict(feet), after, (leg,),
                                     lift=self.lift))
            feet, body = after, placed
        if not any(motion):
            plan.phases.append(Phase("body", self.body_time, body, path, dict(feet), dict(feet)))
            body = path
        self._validate(plan)
        return plan, GaitState(path, body, feet)

    def _place_body(self, path: Pose, feet: dict, leg: str, target: np.ndarray) -> Pose:
        """The body pose ``path ∘ (dx, 0, 0)`` with the smallest ``|dx|`` that keeps the
        centre of gravity ``margin`` inside the other feet's triangle while ``leg``
        transfers (checked at lift-off, top and touch-down)."""
        others = [(float(feet[k][0]), float(feet[k][1])) for k in feet if k != leg]
        offset = 0.0
        for _ in range(4):  # the legs' masses move with the body: iterate to a fixed point
            body = compose(path, (offset, 0.0, 0.0))
            axis = np.array([math.cos(body[2]), math.sin(body[2])])
            low, high = -math.inf, math.inf
            for s in (0.0, 0.5, 1.0):
                swing = dict(feet)
                swing[leg] = transfer_point(feet[leg], target, self.lift, s)
                feet_body = {k: to_body(body, self.height, v) for k, v in swing.items()}
                try:
                    cog = to_ground(body, self.height, self.design.centre_of_mass(_joints(self.design, feet_body)))
                except GaitError:
                    cog = to_ground(body, self.height, self.design.body_centre_of_mass)
                for i in range(3):
                    a, b = others[i], others[(i + 1) % 3]
                    edge = np.array([b[0] - a[0], b[1] - a[1]])
                    normal = np.array([-edge[1], edge[0]]) / np.linalg.norm(edge)
                    if normal @ (np.array(others[(i + 2) % 3]) - np.array(a)) < 0:
                        normal = -normal
                    distance = float(normal @ (cog[:2] - np.array(a)))
                    rate = float(normal @ axis)
                    need = self.margin_required - distance  # rate * extra >= need
                    if abs(rate) < 1e-12:
                        if need > 0:
                            low, high = math.inf, -math.inf
                    elif rate > 0:
                        low = max(low, need / rate)
                    else:
                        high = min(high, need / rate)
            if low > high:
                raise GaitError(f"no stable body position for lifting leg {leg} (margin {self.margin_required} m)")
            extra = 0.0 if low <= 0.0 <= high else (low if low > 0 else high)
            if abs(extra) < 1e-9:
                break
            offset += extra
        return compose(path, (offset, 0.0, 0.0))


class SlideGait(_Gait):
    """Robot3L's sliding gait: the hind skid never lifts.

    A cycle is a transfer of both front feet (the robot rests on its belly and skid),
    then a stroke moving the body by the cycle's motion while the front feet stay on
    the ground and the skid slides.

    Args:
        design: the robot (front legs ``lf``, ``rf``; hind leg ``h`` carried).
        stride: body travel per cycle (m).
        lift: front feet lift in the body frame (the belly takes the load first).
        transfer_time: seconds of the front feet transfer.
        body_time: seconds of the stroke.
        max_turn: largest turn per cycle (rad).

    Examples:
        >>> from petriflow.agents.legged.robots import ROBOT3L
        >>> gait = SlideGait(ROBOT3L)
        >>> round(gait.speed, 4), gait.cycle_time
        (0.0667, 1.2)
    """

    carried = ("h",)

    def __init__(self, design: RobotDesign, *, stride: float = 0.08, lift: float = 0.025, transfer_time: float = 0.5,
                 body_time: float = 0.7, max_turn: float = 0.4) -> None:
        super().__init__(design, stride=stride, lift=lift, transfer_time=transfer_time, body_time=body_time,
                         max_turn=max_turn)

    @property
    def cycle_time(self) -> float:
        return self.transfer_time + self.body_time

    def cycle(self, state: GaitState, motion: Sequence[float]) -> tuple[GaitPlan, GaitState]:
        """Plan one cycle (see :meth:`CrawlGait.cycle`)."""
        self.check(motion)
        plan = self._plan()
        feet = {k: np.asarray(v, dtype=float) for k, v in state.feet.items()}
        front = tuple(k for k in feet)
        ahead = compose(state.path, _scaled(motion, 0.5))
        targets = {leg: self._nominal_ground(ahead, leg) for leg in front}
        plan.phases.append(Phase("transfer", self.transfer_time, state.body, state.body, dict(feet), targets, front,
                                 self.carried, self.lift, belly=True))
        path = compose(state.path, motion)
        if any(motion):
            plan.phases.append(Phase("body", self.body_time, state.body, path, dict(targets), dict(targets),
                                     carried=self.carried))
        self._validate(plan)
        return plan, GaitState(path, path, targets)


def gait_for(design: RobotDesign, **options) -> CrawlGait | SlideGait:
    """The gait of a design: :class:`SlideGait` if it has a carried hind leg ``h``.

    Examples:
        >>> from petriflow.agents.legged.robots import ROBOT3L, ROBOT4L
        >>> type(gait_for(ROBOT4L)).__name__, type(gait_for(ROBOT3L)).__name__
        ('CrawlGait', 'SlideGait')
    """
    if "h" in design.leg_names:
        return SlideGait(design, **options)
    return CrawlGait(design, **options)
