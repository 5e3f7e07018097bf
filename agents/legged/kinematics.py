"""Kinematics of one SMART leg (hip, knee, ext) by the successive screw displacement method.

A SMART leg (seed 003, §3, Fig. 6) has two revolute joints, the *hip* (``q1``, vertical
axis) and the *knee* (``q2``), and a prismatic joint, *ext* (``q3``), that lengthens
the lower leg. Robot3L's hind leg has only the knee and the ext (``has_hip=False``).

Conventions (those of the paper, Table 2):

* The leg frame ``O xyz`` sits on the hip joint: ``z`` up along the hip axis, ``x``
  along the leg's first link (outwards, the leg's mount direction), ``y = z × x``.
* In the reference configuration ``q = 0`` the foot centre is at
  ``p0 = (l0 + l3, -l1, -l2 - l4)``: ``l0 + l3`` outwards (hip link ``l0`` plus knee
  bracket ``l3``), ``l1`` and ``l2`` the knee axis' offsets back and down, ``l4`` the
  lower leg with the ext retracted.
* Screw axes ``$i = (s, s0)``: hip ``s = (0, 0, 1)`` through ``(0, 0, 0)``; knee
  ``s = (1, 0, 0)`` through ``(0, -l1, -l2)``; ext ``s = (0, 0, -1)`` (prismatic) through
  ``(l0 + l3, -l1, 0)``.
* ``p = A1(q1) A2(q2) A3(q3) p0``, each ``Ai`` the 4×4 screw displacement about ``$i``
  (eq. 1). In closed form, with ``L = l4 + q3`` the lower leg's length,
  ``p = Rz(q1) (l0 + l3, -l1 + L sin q2, -l2 - L cos q2)``.
* Joint ranges (Table 3): ``q1, q2 ∈ [-π/3, π/3]`` rad, ``q3 ∈ [0, 0.1]`` m.

Inverse kinematics (§3.2, Fig. 7): the foot always lies on the plane of the lower leg,
at the distance ``d_OA = l0 + l3`` from the hip axis once the hip turns, so a foot at
horizontal distance ``d_OP`` from the hip axis, in direction ``θ``, is reached with
``q1 = θ + α`` (*knee forward*: the lower leg leans towards ``-y``, ``q2 ≤ 0`` when
``l1 = 0``) or ``q1 = θ - α`` (*knee backward*), where ``cos α = d_OA / d_OP``. The two
branches meet where ``d_OP = d_OA`` (the paper's "blind gap"). Points nearer the hip
axis than ``d_OA`` cannot be reached.

Instantaneous kinematics (§3.4): the Jacobian's columns are the joints' unit twists
(eq. 12); the foot velocity is ``ṗ = J_f(q) q̇`` (eq. 15).

Examples:
    >>> leg = LegGeometry(l0=0.03, l1=0.01, l2=0.02, l3=0.015, l4=0.07)
    >>> [round(float(v), 3) for v in forward(leg, (0.0, 0.0, 0.0))]
    [0.045, -0.01, -0.09]
    >>> solutions = solve(leg, (0.06, 0.0, -0.10))
    >>> [s.branch for s in solutions]
    ['knee_forward', 'knee_backward']
    >>> [round(float(v), 6) + 0.0 for v in forward(leg, solutions[0].q)]
    [0.06, 0.0, -0.1]
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = [
    "KNEE_BACKWARD",
    "KNEE_FORWARD",
    "LegGeometry",
    "LegSolution",
    "UnreachableError",
    "forward",
    "inverse",
    "jacobian",
    "joint_rates",
    "joint_transforms",
    "screw_axes",
    "screw_displacement",
    "solve",
    "twists",
]

KNEE_FORWARD = "knee_forward"
"""The branch ``q1 = θ + α`` (the lower leg leans towards the leg frame's ``-y``)."""
KNEE_BACKWARD = "knee_backward"
"""The branch ``q1 = θ - α`` (the lower leg leans towards ``+y``)."""

_TOLERANCE = 1e-9


class UnreachableError(ValueError):
    """A foot position that no joint configuration within the joint ranges reaches."""


@dataclass(frozen=True)
class LegGeometry:
    """Link lengths (m) and joint ranges of one leg (seed 003, Fig. 6, Tables 2 and 3).

    Attributes:
        l0: hip axis to the knee servo, along ``x``.
        l1: knee axis offset along ``-y``.
        l2: knee axis offset below the hip, along ``-z``.
        l3: knee servo to the lower leg (the knee bracket), along ``x``.
        l4: knee axis to the foot centre with the ext retracted (``q3 = 0``).
        q1_range: hip range (rad).
        q2_range: knee range (rad).
        q3_range: ext range (m).
        has_hip: ``False`` for a two-joint leg (knee and ext; Robot3L's hind leg),
            whose ``q1`` is always 0.

    Examples:
        >>> leg = LegGeometry(0.03, 0.01, 0.02, 0.015, 0.07)
        >>> leg.d_oa, [round(v, 4) for v in leg.q1_range]
        (0.045, [-1.0472, 1.0472])
    """

    l0: float
    l1: float
    l2: float
    l3: float
    l4: float
    q1_range: tuple[float, float] = (-math.pi / 3, math.pi / 3)
    q2_range: tuple[float, float] = (-math.pi / 3, math.pi / 3)
    q3_range: tuple[float, float] = (0.0, 0.100)
    has_hip: bool = True

    @property
    def d_oa(self) -> float:
        """Distance from the hip axis to the lower leg's plane, ``l0 + l3``."""
        return self.l0 + self.l3

    @property
    def p0(self) -> np.ndarray:
        """Foot centre in the reference configuration ``q = 0`` (homogeneous)."""
        return np.array([self.l0 + self.l3, -self.l1, -self.l2 - self.l4, 1.0])

    @property
    def ranges(self) -> tuple[tuple[float, float], ...]:
        """The three joint ranges, ``q1`` fixed at 0 for a leg without hip."""
        return ((0.0, 0.0) if not self.has_hip else self.q1_range, self.q2_range, self.q3_range)

    def in_range(self, q: Sequence[float]) -> bool:
        """Whether every joint value lies within its range (Table 3).

        Examples:
            >>> leg = LegGeometry(0.03, 0.01, 0.02, 0.015, 0.07)
            >>> leg.in_range((0.0, 0.5, 0.05)), leg.in_range((0.0, 1.2, 0.05))
            (True, False)
        """
        return self._inside(q)

    def _inside(self, q: Sequence[float]) -> bool:
        for value, (low, high) in zip(q, self.ranges):
            if value < low - _TOLERANCE or value > high + _TOLERANCE:
                return False
        return True

    def violations(self, q: Sequence[float]) -> list[str]:
        """Names of the joints outside their ranges, with the value and range."""
        found = []
        for name, value, (low, high) in zip(("q1", "q2", "q3"), q, self.ranges):
            if value < low - _TOLERANCE or value > high + _TOLERANCE:
                found.append(f"{name}={value:.4g} not in [{low:.4g}, {high:.4g}]")
        return found


@dataclass(frozen=True)
class LegSolution:
    """One inverse-kinematics solution.

    Attributes:
        q: ``(q1, q2, q3)`` in rad, rad, m.
        branch: :data:`KNEE_FORWARD` or :data:`KNEE_BACKWARD`.
        in_range: whether all joints lie within the ranges of Table 3.
    """

    q: tuple[float, float, float]
    branch: str
    in_range: bool


def screw_axes(leg: LegGeometry) -> list[tuple[np.ndarray, np.ndarray, bool]]:
    """The leg's screw axes ``(s, s0, revolute)`` in the reference configuration (Table 2).

    Examples:
        >>> leg = LegGeometry(0.03, 0.01, 0.02, 0.015, 0.07)
        >>> [(s.tolist(), [round(float(v), 3) + 0.0 for v in s0], r) for s, s0, r in screw_axes(leg)]  # doctest: +NORMALIZE_WHITESPACE
        [([0.0, 0.0, 1.0], [0.0, 0.0, 0.0], True),
         ([1.0, 0.0, 0.0], [0.0, -0.01, -0.02], True),
         ([0.0, 0.0, -1.0], [0.045, -0.01, 0.0], False)]
    """
    return [
        (np.array([0.0, 0.0, 1.0]), np.zeros(3), True),
        (np.array([1.0, 0.0, 0.0]), np.array([0.0, -leg.l1, -leg.l2]), True),
        (np.array([0.0, 0.0, -1.0]), np.array([leg.d_oa, -leg.l1, 0.0]), False),
    ]


def screw_displacement(s: Sequence[float], s0: Sequence[float], theta: float, d: float) -> np.ndarray:
    """The 4×4 transform of a rotation ``theta`` about, and a translation ``d`` along, the
    line through ``s0`` with unit direction ``s`` (Tsai 1999, the screw displacement).

    Examples:
        >>> A = screw_displacement((0, 0, 1), (1, 0, 0), math.pi / 2, 0.5)
        >>> [round(float(v), 6) + 0.0 for v in A @ np.array([2.0, 0.0, 0.0, 1.0])][:3]
        [1.0, 1.0, 0.5]
    """
    s = np.asarray(s, dtype=float)
    s0 = np.asarray(s0, dtype=float)
    k = np.array([[0.0, -s[2], s[1]], [s[2], 0.0, -s[0]], [-s[1], s[0], 0.0]])
    rotation = np.eye(3) + math.sin(theta) * k + (1.0 - math.cos(theta)) * (k @ k)
    transform = np.eye(4)
    transform[:3, :3] = rotation
    transform[:3, 3] = (np.eye(3) - rotation) @ s0 + d * s
    return transform


def joint_transforms(leg: LegGeometry, q: Sequence[float]) -> list[np.ndarray]:
    """The cumulative displacements ``[A1, A1 A2, A1 A2 A3]``: where each link has moved
    from its reference pose (a point ``r`` of link ``i`` at ``q = 0`` is at ``T_i r``).

    Examples:
        >>> leg = LegGeometry(0.03, 0.01, 0.02, 0.015, 0.07)
        >>> [T.shape for T in joint_transforms(leg, (0.1, 0.2, 0.03))]
        [(4, 4), (4, 4), (4, 4)]
    """
    q1, q2, q3 = (0.0 if not leg.has_hip else float(q[0])), float(q[1]), float(q[2])
    (s1, o1, _), (s2, o2, _), (s3, o3, _) = screw_axes(leg)
    a1 = screw_displacement(s1, o1, q1, 0.0)
    a12 = a1 @ screw_displacement(s2, o2, q2, 0.0)
    return [a1, a12, a12 @ screw_displacement(s3, o3, 0.0, q3)]


def forward(leg: LegGeometry, q: Sequence[float]) -> np.ndarray:
    """Foot centre ``(x, y, z)`` in the leg frame for joints ``q = (q1, q2, q3)`` (eq. 1).

    Examples:
        >>> leg = LegGeometry(0.03, 0.01, 0.02, 0.015, 0.07)
        >>> [round(float(v), 4) for v in forward(leg, (math.pi / 2, 0.0, 0.05))]
        [0.01, 0.045, -0.14]
    """
    return (joint_transforms(leg, q)[2] @ leg.p0)[:3]


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


def solve(leg: LegGeometry, foot: Sequence[float], *, include_out_of_range: bool = False) -> list[LegSolution]:
    """Both inverse-kinematics branches for a foot position in the leg frame (§3.2).

    Args:
        leg: the leg.
        foot: ``(Fx, Fy, Fz)`` in the leg frame (m).
        include_out_of_range: also return solutions outside the joint ranges, flagged
            ``in_range=False``.

    Returns:
        The solutions, knee forward first; empty when the point cannot be reached (too
        near the hip axis, or no branch within the ranges).

    Examples:
        >>> leg = LegGeometry(0.03, 0.01, 0.02, 0.015, 0.07)
        >>> solve(leg, (0.01, 0.0, -0.1))       # nearer the hip axis than l0 + l3
        []
        >>> [s.in_range for s in solve(leg, (0.045, 0.15, -0.03), include_out_of_range=True)]
        [False, False]
    """
    fx, fy, fz = (float(v) for v in foot)
    d_oa = leg.d_oa
    if leg.has_hip:
        d_op = math.hypot(fx, fy)
        if d_op < d_oa - 1e-12:
            return []
        s = math.sqrt(max(d_op * d_op - d_oa * d_oa, 0.0))
        theta = math.atan2(fy, fx)
        alpha = math.atan2(s, d_oa)
        candidates = [(KNEE_FORWARD, _wrap(theta + alpha), -s), (KNEE_BACKWARD, _wrap(theta - alpha), s)]
    else:
        if abs(fx - d_oa) > 1e-9:
            return []
        candidates = [(KNEE_FORWARD if fy + leg.l1 < 0 else KNEE_BACKWARD, 0.0, fy)]
    solutions = []
    for branch, q1, y_plane in candidates:
        # the lower leg, from the knee axis point (d_oa, -l1, -l2) to the foot, in the leg plane
        dy, dz = y_plane + leg.l1, fz + leg.l2
        length = math.hypot(dy, dz)
        q2 = math.atan2(dy, -dz)
        q3 = length - leg.l4
        q = (q1, q2, q3)
        ok = leg._inside(q)
        if ok or include_out_of_range:
            solutions.append(LegSolution(q, branch, ok))
    return solutions


def inverse(leg: LegGeometry, foot: Sequence[float], *, branch: str | None = None,
            near: Sequence[float] | None = None) -> tuple[float, float, float]:
    """One joint configuration reaching ``foot``, within the joint ranges.

    Args:
        leg: the leg.
        foot: ``(Fx, Fy, Fz)`` in the leg frame (m).
        branch: :data:`KNEE_FORWARD` or :data:`KNEE_BACKWARD`; ``None`` for either
            (ignored for a leg without hip, which has one solution).
        near: among the allowed solutions, take the one nearest these joints (keeps a
            trajectory on one branch); default: the first.

    Raises:
        UnreachableError: no allowed solution, saying why.

    Examples:
        >>> leg = LegGeometry(0.03, 0.01, 0.02, 0.015, 0.07)
        >>> [round(v, 4) + 0.0 for v in inverse(leg, (0.045, -0.01, -0.12))]
        [0.0, 0.0, 0.03]
        >>> try:
        ...     inverse(leg, (0.0, 0.02, -0.1))
        ... except UnreachableError as error:
        ...     print(error)
        foot (0, 0.02, -0.1) is 0.02 m from the hip axis, nearer than l0 + l3 = 0.045 m
    """
    every = solve(leg, foot, include_out_of_range=True)
    if near is not None and branch is not None and len(every) == 2 and leg.has_hip:
        every = [s for s in every if s.branch == branch]  # the common case, kept fast
        if every[0].in_range:
            return every[0].q
    where = "(" + ", ".join(f"{float(v):.4g}" for v in foot) + ")"
    if not every:
        if leg.has_hip:
            raise UnreachableError(
                f"foot {where} is {math.hypot(foot[0], foot[1]):.4g} m from the hip axis,"
                f" nearer than l0 + l3 = {leg.d_oa:.4g} m")
        raise UnreachableError(f"foot {where} is off the plane x = {leg.d_oa:.4g} of a leg without hip")
    if branch is not None and leg.has_hip:
        every = [s for s in every if s.branch == branch]
    allowed = [s for s in every if s.in_range]
    if not allowed:
        reasons = "; ".join(f"{s.branch}: {', '.join(leg.violations(s.q))}" for s in every)
        raise UnreachableError(f"foot {where} is outside the joint ranges ({reasons})")
    if near is None:
        return allowed[0].q
    return min(allowed, key=lambda s: sum((a - b) ** 2 for a, b in zip(s.q, near))).q


def twists(leg: LegGeometry, q: Sequence[float]) -> np.ndarray:
    """The 6×3 Jacobian of eq. 12: column ``i`` is joint ``i``'s unit twist
    ``(ω; v0)`` at the leg frame's origin (``ω = s``, ``v0 = s0 × s`` for a revolute
    joint; ``ω = 0``, ``v0 = s`` for the prismatic one), in the current configuration.

    Examples:
        >>> leg = LegGeometry(0.03, 0.01, 0.02, 0.015, 0.07)
        >>> J = twists(leg, (0.0, 0.0, 0.0))
        >>> [round(float(v), 3) + 0.0 for v in J[:, 1]]   # knee: (c1, s1, 0; l2 s1, -l2 c1, l1)
        [1.0, 0.0, 0.0, 0.0, -0.02, 0.01]
    """
    transforms = [np.eye(4)] + joint_transforms(leg, q)[:2]
    columns = []
    for (s, s0, revolute), T in zip(screw_axes(leg), transforms):
        s_now = T[:3, :3] @ s
        s0_now = (T @ np.append(s0, 1.0))[:3]
        if revolute:
            columns.append(np.concatenate([s_now, np.cross(s0_now, s_now)]))
        else:
            columns.append(np.concatenate([np.zeros(3), s_now]))
    jac = np.array(columns).T
    if not leg.has_hip:
        jac[:, 0] = 0.0
    return jac


def jacobian(leg: LegGeometry, q: Sequence[float]) -> np.ndarray:
    """The 3×3 foot Jacobian ``J_f`` (eq. 15): foot velocity ``ṗ = J_f q̇``, from
    ``v_foot = v0 + ω × p`` for each twist.

    Examples:
        >>> leg = LegGeometry(0.03, 0.01, 0.02, 0.015, 0.07)
        >>> J = jacobian(leg, (0.0, 0.0, 0.0))
        >>> [round(float(v), 3) + 0.0 for v in J[:, 2]]    # ext: straight down
        [0.0, 0.0, -1.0]
    """
    foot = forward(leg, q)
    full = twists(leg, q)
    return full[3:] + np.cross(full[:3].T, foot).T


def joint_rates(leg: LegGeometry, q: Sequence[float], foot_velocity: Sequence[float]) -> np.ndarray:
    """Joint velocities that move the foot at ``foot_velocity`` (solves ``J_f q̇ = ṗ``;
    least squares near a singularity, and for a leg without hip).

    Examples:
        >>> leg = LegGeometry(0.03, 0.01, 0.02, 0.015, 0.07)
        >>> [round(float(v), 4) + 0.0 for v in joint_rates(leg, (0.0, 0.0, 0.03), (0.0, 0.0, -0.01))]
        [0.0, 0.0, 0.01]
    """
    jac = jacobian(leg, q)
    rates, *_ = np.linalg.lstsq(jac, np.asarray(foot_velocity, dtype=float), rcond=None)
    return rates
