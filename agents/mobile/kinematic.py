"""A kinematic differential-drive robot with wheel encoders, in a pybullet world.

The wheels' speeds set the body's motion by the differential-drive kinematics about the
instantaneous centre of curvature (ICC; seed 000 eq. 1): for wheel speeds ``vl, vr``
(m/s) and track ``L``, ``v = (vr + vl) / 2``, ``w = (vr - vl) / L``, and over ``dt``
the pose turns by ``w dt`` about the ICC at distance ``R = v / w`` (a straight line
when ``w = 0``). pybullet is used for geometry, ray casts and contacts, as Stage does:
the body is placed at the integrated pose each step (no wheel dynamics), which keeps
multi-robot runs fast. Encoders count ``ppr`` pulses per wheel turn; the robot's own
estimate of where it is (odometry) comes from those counts alone, each pulse being
``dpp = 2 pi r / ppr`` of travel (seed 000 eq. 2).

Examples:
    >>> pose = icc_step((0.0, 0.0, 0.0), 0.1, 0.1, 0.2, 1.0)
    >>> [round(v, 6) for v in pose]
    [0.1, 0.0, 0.0]
    >>> x, y, yaw = icc_step((0.0, 0.0, 0.0), -0.1, 0.1, 0.2, 1.0)   # spin in place
    >>> round(x, 9), round(y, 9), round(yaw, 6)
    (0.0, 0.0, 1.0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

__all__ = ["Encoders", "KinematicRobot", "icc_step"]


def icc_step(pose: tuple[float, float, float], left: float, right: float, track: float,
             dt: float) -> tuple[float, float, float]:
    """The pose after ``dt`` s with wheel speeds ``left`` and ``right`` (m/s), eq. 1."""
    x, y, yaw = pose
    v = (right + left) / 2.0
    w = (right - left) / track
    if abs(w) < 1e-12:
        return (x + v * dt * math.cos(yaw), y + v * dt * math.sin(yaw), yaw)
    radius = v / w
    icc_x, icc_y = x - radius * math.sin(yaw), y + radius * math.cos(yaw)
    turn = w * dt
    cos_t, sin_t = math.cos(turn), math.sin(turn)
    nx = cos_t * (x - icc_x) - sin_t * (y - icc_y) + icc_x
    ny = sin_t * (x - icc_x) + cos_t * (y - icc_y) + icc_y
    yaw = math.atan2(math.sin(yaw + turn), math.cos(yaw + turn))
    return (nx, ny, yaw)


@dataclass
class Encoders:
    """Wheel encoders: whole pulses counted per wheel, the odometry they give.

    Args:
        radius: wheel radius (m).
        ppr: pulses per wheel revolution.
        track: distance between the wheels (m).
    """

    radius: float
    ppr: int
    track: float
    left_pulses: int = 0
    right_pulses: int = 0
    _left: float = 0.0
    _right: float = 0.0

    @property
    def dpp(self) -> float:
        """Travel per pulse (m), eq. 2."""
        return 2.0 * math.pi * self.radius / self.ppr

    def advance(self, left: float, right: float) -> tuple[int, int]:
        """Wheels travelled ``left`` and ``right`` metres: the new whole pulses of each."""
        self._left += left / self.dpp
        self._right += right / self.dpp
        new_left, new_right = int(self._left) - self.left_pulses, int(self._right) - self.right_pulses
        self.left_pulses += new_left
        self.right_pulses += new_right
        return new_left, new_right


class KinematicRobot:
    """One agent's robot body moved by wheel speeds (see the module).

    Args:
        world: the :class:`petriflow.world.World`.
        agent: the agent (or body) name.
        radius, ppr, track: wheel radius (m), encoder pulses per turn, wheel track (m).
        z: height the body is kept at.
    """

    def __init__(self, world: Any, agent: str, *, radius: float = 0.025, ppr: int = 200, track: float = 0.2,
                 z: float | None = None) -> None:
        self.world = world
        self.agent = agent
        self.body = world.body(agent)
        self.p = world.p
        position, orientation = self.p.getBasePositionAndOrientation(self.body, physicsClientId=world.client)
        self.z = position[2] if z is None else z
        self.orientation = orientation
        self.pose = (position[0], position[1], self.p.getEulerFromQuaternion(orientation)[2])
        self.encoders = Encoders(radius, ppr, track)
        self.odometry = self.pose
        self.travelled = 0.0

    def drive(self, left: float, right: float, dt: float) -> None:
        """Turn the wheels at ``left``, ``right`` m/s for ``dt`` s: move the body,
        count pulses, dead-reckon the odometry from the pulses."""
        track = self.encoders.track
        self.pose = icc_step(self.pose, left, right, track, dt)
        self.travelled += abs(left + right) / 2.0 * dt
        pulses_left, pulses_right = self.encoders.advance(left * dt, right * dt)
        dpp = self.encoders.dpp
        self.odometry = icc_step(self.odometry, pulses_left * dpp, pulses_right * dpp, track, 1.0)
        x, y, yaw = self.pose
        self.p.resetBasePositionAndOrientation(self.body, (x, y, self.z), self.p.getQuaternionFromEuler((0, 0, yaw)),
                                               physicsClientId=self.world.client)

    def step_towards(self, goal: tuple[float, float], speed: float, turn_rate: float, dt: float,
                     tolerance: float = 0.01) -> bool:
        """One ``dt`` of turning on the spot to face ``goal``, then driving straight
        at it; ``True`` once within ``tolerance``."""
        x, y, yaw = self.pose
        dx, dy = goal[0] - x, goal[1] - y
        distance = math.hypot(dx, dy)
        if distance <= tolerance:
            return True
        error = math.atan2(dy, dx) - yaw
        error = math.atan2(math.sin(error), math.cos(error))
        half = self.encoders.track / 2.0
        if abs(error) > 0.02:
            w = math.copysign(min(turn_rate, abs(error) / dt), error)
            self.drive(-w * half, w * half, dt)
            return False
        v = min(speed, distance / dt)
        w = error / dt * 0.5
        self.drive(v - w * half, v + w * half, dt)
        return math.hypot(goal[0] - self.pose[0], goal[1] - self.pose[1]) <= tolerance
