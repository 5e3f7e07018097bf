"""The SMART robots Robot3L and Robot4L: their dimensions, in one place, and their URDF.

The paper (seed 003) gives the legs' kinematic structure (§3, Fig. 6, Table 2), the
joint ranges (Table 3: hip and knee within ±π/3 rad, ext 0–100 mm) and the components
(Table 1: HS-475 servos, Firgelli L12 and Faulhaber LM1247 linear actuators); it gives
no lengths or masses. The values below are chosen to be plausible for those parts and
are the only place they are written: :func:`urdf` renders a design as URDF text and
``python -m petriflow.agents.legged.robots`` rewrites ``robots/*.urdf`` from it (a test
checks the shipped files equal the generator's output).

* **Robot4L** (§2.2): a body with four legs, each hip + knee + ext. Its feet splay
  forwards (front legs) and backwards (hind legs) from the hips, so each leg stands on
  one inverse-kinematics branch with ``q1 = 0``; the leg's mount yaw is derived from
  that nominal stance (:func:`mount_yaw`).
* **Robot3L** (§2.1): two front legs (hip + knee + ext) and a hind leg with a knee and
  an ext only (Table 1 counts five rotary servos and three linear motors). The robot
  never lifts a leg while standing on three ("it is absolutely necessary that the
  three legs are resting on the surface. Therefore, the robot moves sliding"): its
  hind foot is a low-friction skid, and a battery box under the front of the body is
  the belly it sets down while the front feet swing forward (see
  :mod:`petriflow.agents.legged.gait`).
* Both carry a flat top plate (wider than the body) for the colour and the two marker
  discs of the overhead camera (§2.4; :func:`petriflow.vision.markers.attach_markers`).
  The body's visuals take ``colour``; :class:`petriflow.world.World` recolours the
  base link with a robot's ``colour:``.

Frames: the body frame has ``x`` forward, ``y`` left, ``z`` up, origin at the body
box's centre. Leg ``i``'s frame sits on its hip joint, turned by ``yaw`` about ``z``
(see :mod:`petriflow.agents.legged.kinematics` for the leg frame).

Examples:
    >>> ROBOT4L.leg_names, ROBOT3L.leg_names
    (('lf', 'rf', 'lh', 'rh'), ('lf', 'rf', 'h'))
    >>> round(ROBOT4L.total_mass, 3), round(ROBOT3L.total_mass, 3)
    (0.83, 0.565)
    >>> text = urdf(ROBOT4L)
    >>> text.count("<joint "), text.count('type="prismatic"')
    (12, 4)
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from petriflow.agents.legged.kinematics import (
    KNEE_BACKWARD,
    KNEE_FORWARD,
    LegGeometry,
    forward,
    solve,
)

__all__ = [
    "DESIGNS",
    "ROBOT3L",
    "ROBOT4L",
    "URDF_FOLDER",
    "Box",
    "LegMount",
    "RobotDesign",
    "mount_yaw",
    "moved_point",
    "urdf",
    "write_urdfs",
]

#: Folder of the shipped URDF files (package data of ``petriflow.agents.legged``).
URDF_FOLDER = Path(__file__).resolve().parent / "robots"

_ALUMINIUM = (0.75, 0.75, 0.78, 1.0)
_SERVO = (0.30, 0.32, 0.40, 1.0)
_RUBBER = (0.25, 0.25, 0.25, 1.0)
_SKID = (0.85, 0.85, 0.55, 1.0)


@dataclass(frozen=True)
class Box:
    """A box part of a link: full extents, centre, mass.

    Attributes:
        size: full extents ``(x, y, z)`` (m).
        centre: centre in the link frame (m).
        mass: kg (0 for a massless visual/collision part).
    """

    size: tuple[float, float, float]
    centre: tuple[float, float, float]
    mass: float = 0.0


@dataclass(frozen=True)
class LegMount:
    """One leg: where it is mounted, its geometry, masses and foot.

    Attributes:
        name: short name, prefix of its joints (``lf_hip``, ``lf_knee``, ``lf_ext``).
        hip: hip joint position in the body frame (m).
        yaw: direction of the leg frame's ``x`` axis in the body frame (rad).
        geometry: link lengths and joint ranges.
        branch: inverse-kinematics branch the gaits keep the leg on.
        nominal: joint values ``(q1, q2, q3)`` of the standing posture.
        masses: kg of the hip link (knee servo and bracket), the knee link (bracket and
            linear actuator housing) and the ext link (rod and foot).
        foot_radius: radius of the spherical foot (m); the leg's foot point is its centre.
        foot_friction: lateral friction coefficient of the foot.
    """

    name: str
    hip: tuple[float, float, float]
    yaw: float
    geometry: LegGeometry
    branch: str
    nominal: tuple[float, float, float]
    masses: tuple[float, float, float]
    foot_radius: float
    foot_friction: float

    def rotation(self) -> np.ndarray:
        """3×3 rotation from the leg frame to the body frame."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])

    def to_body(self, point: Sequence[float]) -> np.ndarray:
        """A leg-frame point in the body frame."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        x, y, z = (float(v) for v in point)
        return np.array([self.hip[0] + c * x - s * y, self.hip[1] + s * x + c * y, self.hip[2] + z])

    def to_leg(self, point: Sequence[float]) -> tuple[float, float, float]:
        """A body-frame point in the leg frame."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        dx, dy, dz = (float(p) - h for p, h in zip(point, self.hip))
        return (c * dx + s * dy, -s * dx + c * dy, dz)

    def foot(self, q: Sequence[float]) -> np.ndarray:
        """Foot centre in the body frame for joints ``q``."""
        return self.to_body(forward(self.geometry, q))


@dataclass(frozen=True)
class RobotDesign:
    """A legged robot: body parts, legs, colour.

    Attributes:
        name: URDF robot name (``robot4l``).
        body: the base link's boxes; the first is the body itself.
        plate: the flat top plate (part of the base link) for colour and markers.
        legs: the legs, in the order used everywhere (joint order in the URDF).
        colour: RGBA of the body and plate visuals.
        belly: index in ``body`` of the box the robot may rest on (Robot3L's
            battery box), or ``None``.
        belly_friction: lateral friction of the base link's contacts.
        doc: one line for the URDF comment.
    """

    name: str
    body: tuple[Box, ...]
    plate: Box
    legs: tuple[LegMount, ...]
    colour: tuple[float, float, float, float] = (0.85, 0.85, 0.85, 1.0)
    belly: int | None = None
    belly_friction: float = 0.8
    doc: str = ""

    @property
    def leg_names(self) -> tuple[str, ...]:
        """Leg names in order."""
        return tuple(leg.name for leg in self.legs)

    def leg(self, name: str) -> LegMount:
        """A leg by name."""
        for leg in self.legs:
            if leg.name == name:
                return leg
        raise KeyError(f"{self.name} has no leg {name!r} (it has {', '.join(self.leg_names)})")

    @property
    def body_mass(self) -> float:
        """Mass of the base link (kg)."""
        return sum(part.mass for part in self.body) + self.plate.mass

    @property
    def total_mass(self) -> float:
        """Mass of the whole robot (kg)."""
        return self.body_mass + sum(sum(leg.masses) for leg in self.legs)

    @property
    def body_centre_of_mass(self) -> np.ndarray:
        """Centre of mass of the base link in the body frame."""
        parts = [p for p in (*self.body, self.plate) if p.mass > 0]
        total = sum(p.mass for p in parts)
        return sum(p.mass * np.asarray(p.centre) for p in parts) / total

    def nominal_feet(self) -> dict[str, np.ndarray]:
        """Foot centres of the standing posture, in the body frame."""
        return {leg.name: leg.foot(leg.nominal) for leg in self.legs}

    @property
    def standing_height(self) -> float:
        """Height of the body frame's origin above the ground when standing (m)."""
        leg = self.legs[0]
        return float(-leg.foot(leg.nominal)[2] + leg.foot_radius)

    def centre_of_mass(self, joints: dict[str, Sequence[float]]) -> np.ndarray:
        """The robot's centre of mass in the body frame, for joint values per leg.

        Each leg link's mass sits at the centre of its parts (see :func:`leg_parts`),
        moved by the leg's screw displacements.

        Examples:
            >>> com = ROBOT4L.centre_of_mass({leg.name: leg.nominal for leg in ROBOT4L.legs})
            >>> [round(float(v), 4) + 0.0 for v in com[:2]]
            [0.0, 0.0]
        """
        total = self.body_mass * self.body_centre_of_mass
        mass = self.body_mass
        for leg in self.legs:
            for index, link in enumerate(_leg_links(leg)):
                if link.mass <= 0:
                    continue
                centre = moved_point(leg.geometry, joints[leg.name], link.reference_centre, index)
                total = total + link.mass * leg.to_body(centre)
                mass += link.mass
        return total / mass


def moved_point(geometry: LegGeometry, q: Sequence[float], point: Sequence[float], link: int) -> tuple:
    """Where a point of leg link ``link`` (0 hip, 1 knee, 2 ext), given at ``q = 0`` in
    the leg frame, is for joints ``q``: the screw displacements ``A1 [A2 [A3]]`` in closed
    form (equal to :func:`petriflow.agents.legged.kinematics.joint_transforms`, faster).

    Examples:
        >>> from petriflow.agents.legged.kinematics import joint_transforms
        >>> leg = LegGeometry(0.03, 0.01, 0.02, 0.015, 0.07)
        >>> T = joint_transforms(leg, (0.3, -0.2, 0.04))[2]
        >>> p = (0.045, -0.01, -0.09)
        >>> bool(np.allclose(moved_point(leg, (0.3, -0.2, 0.04), p, 2), (T @ np.array([*p, 1.0]))[:3]))
        True
    """
    q1 = float(q[0]) if geometry.has_hip else 0.0
    x, y, z = (float(v) for v in point)
    if link >= 2:
        z -= float(q[2])
    if link >= 1:
        c, s = math.cos(q[1]), math.sin(q[1])
        dy, dz = y + geometry.l1, z + geometry.l2
        y, z = -geometry.l1 + c * dy - s * dz, -geometry.l2 + s * dy + c * dz
    c, s = math.cos(q1), math.sin(q1)
    return (c * x - s * y, s * x + c * y, z)


def mount_yaw(hip: Sequence[float], foot: Sequence[float], geometry: LegGeometry,
              outward: float) -> tuple[float, str, tuple[float, float, float]]:
    """The leg frame's yaw that reaches ``foot`` (body frame) with ``q1 = 0``.

    Of the two mounts (one per branch), the one whose ``x`` axis is nearer the
    ``outward`` direction (rad) is taken. Returns ``(yaw, branch, (0, q2, q3))``,
    yaw rounded to 1e-6 rad so the URDF and the design agree exactly.

    Examples:
        >>> leg = LegGeometry(0.03, 0.01, 0.02, 0.015, 0.07)
        >>> yaw, branch, q = mount_yaw((0.085, 0.07, 0.0), (0.115, 0.13, -0.12), leg, math.pi / 2)
        >>> round(math.degrees(yaw), 1), branch, [round(v, 4) + 0.0 for v in q]
        (111.3, 'knee_forward', [0.0, -0.3783, 0.0376])
    """
    dx, dy, dz = (f - h for f, h in zip(foot, hip))
    if not geometry.has_hip:  # the knee axis points ``outward``; the foot lies under it
        yaw = round(outward, 6)
        c, s = math.cos(yaw), math.sin(yaw)
        q = solve(geometry, (c * dx + s * dy, -s * dx + c * dy, dz), include_out_of_range=True)[0].q
        return yaw, KNEE_FORWARD if q[1] <= 0 else KNEE_BACKWARD, (0.0, round(q[1], 6) + 0.0, round(q[2], 6))
    direction = math.atan2(dy, dx)
    reach = math.hypot(dx, dy)
    alpha = math.acos(min(1.0, geometry.d_oa / reach))
    options = []
    for branch, sign in ((KNEE_FORWARD, 1.0), (KNEE_BACKWARD, -1.0)):
        yaw = round(direction + sign * alpha, 6)
        off = abs(math.atan2(math.sin(yaw - outward), math.cos(yaw - outward)))
        options.append((off, yaw, branch))
    _, yaw, branch = min(options)
    c, s = math.cos(yaw), math.sin(yaw)
    local = (c * dx + s * dy, -s * dx + c * dy, dz)
    q = next(sol for sol in solve(geometry, local, include_out_of_range=True) if sol.branch == branch).q
    return yaw, branch, (0.0, round(q[1], 6), round(q[2], 6))


def _leg(name: str, hip: tuple[float, float, float], foot: tuple[float, float, float], geometry: LegGeometry,
         outward: float, masses: tuple[float, float, float], foot_radius: float,
         foot_friction: float) -> LegMount:
    yaw, branch, nominal = mount_yaw(hip, foot, geometry, outward)
    if branch == KNEE_BACKWARD and geometry.has_hip:
        # a mirror-image leg: its knee bracket is offset the other way along y (l1 < 0)
        geometry = replace(geometry, l1=-geometry.l1)
        yaw, branch, nominal = mount_yaw(hip, foot, geometry, outward)
    return LegMount(name, hip, yaw, geometry, branch, nominal, masses, foot_radius, foot_friction)


# --- Robot4L -------------------------------------------------------------------------
# Body 240 x 140 x 50 mm holding the four hip servos, the Pololu board and the LiPo
# (0.45 kg); per leg a knee servo with its bracket (HS-475, ~40 g: 45 g), an L12
# actuator housing (40 g) and its rod and rubber foot (10 g). Hips at the body's
# corners; feet splayed 20 mm forwards/backwards and 80 mm out from the hips, their
# centres 120 mm below the hips (ext half out: room to lift and to push).
_LEG4 = LegGeometry(l0=0.030, l1=0.010, l2=0.020, l3=0.015, l4=0.070)
_HIP4 = (0.085, 0.070)
_FOOT4 = (0.020, 0.080, 0.120)

ROBOT4L = RobotDesign(
    name="robot4l",
    body=(Box((0.24, 0.14, 0.05), (0.0, 0.0, 0.0), 0.45),),
    plate=Box((0.26, 0.26, 0.004), (0.0, 0.0, 0.027), 0.0),
    legs=tuple(
        _leg(name, (fx * _HIP4[0], side * _HIP4[1], 0.0),
             (fx * (_HIP4[0] + _FOOT4[0]), side * (_HIP4[1] + _FOOT4[1]), -_FOOT4[2]),
             _LEG4, side * math.pi / 2, (0.045, 0.040, 0.010), 0.012, 1.0)
        for name, fx, side in (("lf", 1, 1), ("rf", 1, -1), ("lh", -1, 1), ("rh", -1, -1))
    ),
    doc="SMART Robot4L: four legs, each hip (revolute), knee (revolute), ext (prismatic)",
)

# --- Robot3L -------------------------------------------------------------------------
# Body 220 x 140 x 60 mm (0.22 kg) with the LiPo in a 80 x 100 x 30 mm box under its
# front (0.08 kg), the belly the robot rests on while its front feet swing. Front legs
# as Robot4L's with a shorter lower leg (LM1247 rod, l4 = 40 mm), hips 20 mm above the
# body's centre; hind leg: knee servo and ext only, on the body's centre line, its foot
# a low-friction skid. Feet centres 80 mm below the hips; the belly then clears the
# ground by 12 mm.
_LEG3 = LegGeometry(l0=0.030, l1=0.010, l2=0.020, l3=0.015, l4=0.040)
_HIND3 = LegGeometry(l0=0.0, l1=0.0, l2=0.020, l3=0.0, l4=0.040, has_hip=False)

ROBOT3L = RobotDesign(
    name="robot3l",
    body=(Box((0.22, 0.14, 0.06), (0.0, 0.0, 0.0), 0.22), Box((0.08, 0.10, 0.03), (0.05, 0.0, -0.045), 0.08)),
    plate=Box((0.22, 0.20, 0.004), (0.0, 0.0, 0.032), 0.0),
    legs=(
        _leg("lf", (0.07, 0.07, 0.02), (0.09, 0.13, -0.06), _LEG3, math.pi / 2, (0.045, 0.040, 0.010), 0.012, 1.0),
        _leg("rf", (0.07, -0.07, 0.02), (0.09, -0.13, -0.06), _LEG3, -math.pi / 2, (0.045, 0.040, 0.010), 0.012,
             1.0),
        _leg("h", (-0.09, 0.0, 0.02), (-0.09, 0.0, -0.06), _HIND3, math.pi / 2, (0.045, 0.020, 0.010), 0.012,
             0.05),
    ),
    belly=1,
    doc="SMART Robot3L: front legs hip/knee/ext, hind leg knee/ext with a sliding skid",
)

DESIGNS = {ROBOT4L.name: ROBOT4L, ROBOT3L.name: ROBOT3L}
"""The designs by URDF name."""


# --- URDF rendering --------------------------------------------------------------------
@dataclass(frozen=True)
class _Part:
    shape: str                      # "box", "cylinder" (along z) or "sphere"
    size: tuple[float, ...]         # box extents, (radius, length) or (radius,)
    centre: tuple[float, float, float]
    mass: float
    rgba: tuple[float, float, float, float]
    collide: bool = True


@dataclass(frozen=True)
class _LinkModel:
    parts: tuple[_Part, ...]
    reference_centre: np.ndarray   # centre of mass at q = 0, in the leg frame

    @property
    def mass(self) -> float:
        return sum(p.mass for p in self.parts)


@functools.cache
def _leg_links(leg: LegMount) -> tuple[_LinkModel, _LinkModel, _LinkModel]:
    """The hip, knee and ext links' parts, each in its own joint frame, with the
    links' centres of mass at ``q = 0`` in the leg frame."""
    g = leg.geometry
    m_hip, m_knee, m_ext = leg.masses
    r = leg.foot_radius
    skid = leg.foot_friction < 0.5
    # hip link: frame on the hip joint; knee servo case around the knee axis at x = l0
    hip_parts = (
        _Part("box", (max(g.l0, 0.02), 0.024, 0.006), (max(g.l0, 0.02) / 2 - 0.01 * (g.l0 == 0), 0.0, 0.0), 0.0,
              _ALUMINIUM, False),
        _Part("box", (0.030, 0.022, 0.032), (g.l0 - 0.012, -g.l1, -g.l2), m_hip, _SERVO),
    )
    housing = g.l4 - r - 0.006
    # knee link: frame on the knee axis at (l0, -l1, -l2); bracket to x = l3, actuator housing
    knee_parts = (
        _Part("box", (max(g.l3, 0.004) + 0.012, 0.020, 0.004), (g.l3 / 2, 0.0, 0.0), 0.0, _ALUMINIUM, False),
        _Part("box", (0.018, 0.018, housing), (g.l3, 0.0, -housing / 2), m_knee, _SERVO),
    )
    rod = g.l4 + 0.8 * g.l2   # its top stays below the hip link when retracted
    # ext link: frame on the ext joint at (l0 + l3, -l1, -l2); rod and foot at z = -l4
    ext_parts = (
        _Part("cylinder", (0.004, rod), (0.0, 0.0, -g.l4 + rod / 2), 0.0, _ALUMINIUM, False),
        _Part("cylinder", (0.006, g.l4 - housing), (0.0, 0.0, -g.l4 + (g.l4 - housing) / 2), 0.0, _ALUMINIUM),
        _Part("sphere", (r,), (0.0, 0.0, -g.l4), m_ext, _SKID if skid else _RUBBER),
    )
    knee_origin = np.array([g.l0, -g.l1, -g.l2])
    ext_origin = np.array([g.d_oa, -g.l1, -g.l2])
    links = []
    for parts, origin in ((hip_parts, np.zeros(3)), (knee_parts, knee_origin), (ext_parts, ext_origin)):
        massive = [p for p in parts if p.mass > 0]
        total = sum(p.mass for p in massive)
        centre = sum(p.mass * np.asarray(p.centre) for p in massive) / total
        links.append(_LinkModel(parts, origin + centre))
    return links[0], links[1], links[2]


def _fmt(value: float) -> str:
    text = f"{value:.9g}"
    return "0" if text in ("-0", "0") else text


def _vec(values: Sequence[float]) -> str:
    return " ".join(_fmt(float(v)) for v in values)


def _part_inertia(part: _Part) -> np.ndarray:
    m = part.mass
    if part.shape == "box":
        x, y, z = part.size
        return m / 12.0 * np.diag([y * y + z * z, x * x + z * z, x * x + y * y])
    if part.shape == "cylinder":
        radius, length = part.size
        side = m / 12.0 * (3 * radius * radius + length * length)
        return np.diag([side, side, m * radius * radius / 2])
    radius = part.size[0]
    return np.eye(3) * 0.4 * m * radius * radius


def _inertial(parts: Sequence[_Part]) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, centre of mass and inertia tensor (about the centre) of a link's parts."""
    massive = [p for p in parts if p.mass > 0]
    mass = sum(p.mass for p in massive)
    centre = sum(p.mass * np.asarray(p.centre) for p in massive) / mass
    inertia = np.zeros((3, 3))
    for p in massive:
        d = np.asarray(p.centre) - centre
        inertia += _part_inertia(p) + p.mass * (float(d @ d) * np.eye(3) - np.outer(d, d))
    return mass, centre, inertia


def _geometry(part: _Part) -> str:
    if part.shape == "box":
        return f'<box size="{_vec(part.size)}"/>'
    if part.shape == "cylinder":
        return f'<cylinder radius="{_fmt(part.size[0])}" length="{_fmt(part.size[1])}"/>'
    return f'<sphere radius="{_fmt(part.size[0])}"/>'


def _link(name: str, parts: Sequence[_Part], friction: float | None = None) -> list[str]:
    mass, centre, inertia = _inertial(parts)
    lines = [f'  <link name="{name}">', "    <contact>"]
    if friction is not None:
        lines += [f'      <lateral_friction value="{_fmt(friction)}"/>',
                  '      <rolling_friction value="0"/>', '      <spinning_friction value="0"/>']
    # friction anchors: without them a robot standing still on its motors creeps (mm/s)
    lines += ["      <friction_anchor/>", "    </contact>"]
    lines += [
        "    <inertial>",
        f'      <origin xyz="{_vec(centre)}" rpy="0 0 0"/>',
        f'      <mass value="{_fmt(mass)}"/>',
        (f'      <inertia ixx="{_fmt(inertia[0, 0])}" ixy="{_fmt(inertia[0, 1])}" ixz="{_fmt(inertia[0, 2])}"'
         f' iyy="{_fmt(inertia[1, 1])}" iyz="{_fmt(inertia[1, 2])}" izz="{_fmt(inertia[2, 2])}"/>'),
        "    </inertial>",
    ]
    for part in parts:
        lines += [
            "    <visual>",
            f'      <origin xyz="{_vec(part.centre)}" rpy="0 0 0"/>',
            f"      <geometry>{_geometry(part)}</geometry>",
            (f'      <material name="rgba_{_vec(part.rgba).replace(" ", "_")}"><color rgba="{_vec(part.rgba)}"/>'
             "</material>"),
            "    </visual>",
        ]
    for part in parts:
        if part.collide:
            lines += [
                "    <collision>",
                f'      <origin xyz="{_vec(part.centre)}" rpy="0 0 0"/>',
                f"      <geometry>{_geometry(part)}</geometry>",
                "    </collision>",
            ]
    lines.append("  </link>")
    return lines


def _joint(name: str, kind: str, parent: str, child: str, xyz: Sequence[float], yaw: float = 0.0,
           axis: Sequence[float] = (0, 0, 1), limits: tuple[float, float] | None = None,
           effort: float = 0.0, velocity: float = 0.0) -> list[str]:
    lines = [
        f'  <joint name="{name}" type="{kind}">',
        f'    <parent link="{parent}"/>',
        f'    <child link="{child}"/>',
        f'    <origin xyz="{_vec(xyz)}" rpy="0 0 {_fmt(yaw)}"/>',
    ]
    if kind != "fixed":
        lines.append(f'    <axis xyz="{_vec(axis)}"/>')
        lines.append(f'    <limit lower="{_fmt(limits[0])}" upper="{_fmt(limits[1])}" effort="{_fmt(effort)}"'
                     f' velocity="{_fmt(velocity)}"/>')
        lines.append('    <dynamics damping="0.01" friction="0"/>')
    lines.append("  </joint>")
    return lines


#: Motor limits written into the URDF and used by the controller: HS-475 servos
#: (0.54 N m stall at 6 V; 0.2 s per 60° ~ 5 rad/s) and the linear actuators (40 N;
#: 0.1 m/s, faster than the L12's 23 mm/s so that a simulated gait cycle takes seconds).
SERVO_TORQUE, SERVO_SPEED = 0.6, 5.0
ACTUATOR_FORCE, ACTUATOR_SPEED = 40.0, 0.1


def urdf(design: RobotDesign) -> str:
    """The URDF text of a design (deterministic: same design, same text).

    Examples:
        >>> text = urdf(ROBOT3L)
        >>> text.splitlines()[1]
        '<!-- Generated by petriflow.agents.legged.robots from the ROBOT3L design; do not edit. -->'
        >>> 'name="h_hip"' in text, 'name="h_mount"' in text
        (False, True)
    """
    lines = [
        '<?xml version="1.0"?>',
        f"<!-- Generated by petriflow.agents.legged.robots from the {design.name.upper()} design; do not edit. -->",
        f"<!-- {design.doc}. Lengths in m, masses in kg. -->",
        f'<robot name="{design.name}">',
    ]
    body_parts = [
        _Part("box", box.size, box.centre, box.mass, design.colour) for box in design.body
    ] + [_Part("box", design.plate.size, design.plate.centre, design.plate.mass, design.colour)]
    lines += _link("body", body_parts, friction=design.belly_friction)
    for leg in design.legs:
        g = leg.geometry
        hip, knee, ext = _leg_links(leg)
        n = leg.name
        lines += _link(f"{n}_hip_link", hip.parts)
        if g.has_hip:
            lines += _joint(f"{n}_hip", "revolute", "body", f"{n}_hip_link", leg.hip, leg.yaw, (0, 0, 1),
                            g.q1_range, SERVO_TORQUE, SERVO_SPEED)
        else:
            lines += _joint(f"{n}_mount", "fixed", "body", f"{n}_hip_link", leg.hip, leg.yaw)
        lines += _link(f"{n}_knee_link", knee.parts)
        lines += _joint(f"{n}_knee", "revolute", f"{n}_hip_link", f"{n}_knee_link", (g.l0, -g.l1, -g.l2), 0.0,
                        (1, 0, 0), g.q2_range, SERVO_TORQUE, SERVO_SPEED)
        lines += _link(f"{n}_ext_link", ext.parts, friction=leg.foot_friction)
        lines += _joint(f"{n}_ext", "prismatic", f"{n}_knee_link", f"{n}_ext_link", (g.l3, 0, 0), 0.0, (0, 0, -1),
                        g.q3_range, ACTUATOR_FORCE, ACTUATOR_SPEED)
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def write_urdfs(folder: str | Path = URDF_FOLDER) -> list[Path]:
    """Write ``<name>.urdf`` for every design into ``folder``; returns the paths."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for design in DESIGNS.values():
        path = folder / f"{design.name}.urdf"
        path.write_text(urdf(design), encoding="utf-8")
        written.append(path)
    return written


if __name__ == "__main__":  # pragma: no cover - maintenance command
    for written_path in write_urdfs():
        print(written_path.name)
