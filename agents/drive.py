"""Differential-drive robots: wheel control and go-to-goal actions.

The robots are pybullet bodies with two driven wheel joints (``left_wheel`` and
``right_wheel``, as in ``robots/diffdrive.urdf``). Actions command wheel velocities and
let the physics move the robot; nothing here sets a body's pose directly.

Kinematics: for forward speed ``v`` and turn rate ``w``, the wheels turn at
``(v -/+ w * track / 2) / radius``.
"""

from __future__ import annotations

import math
from typing import Any

from petriflow.capabilities import Bodies, Physics, Poses
from petriflow.runtime.action import Action, ActionFailure, Param, Status

__all__ = ["DiffDrive", "GoTo", "wheel_speeds", "heading_error"]


def wheel_speeds(v: float, w: float, track: float, radius: float) -> tuple[float, float]:
    """Left and right wheel angular speeds (rad/s) for body speed ``v`` and turn rate ``w``.

    Examples:
        >>> wheel_speeds(0.5, 0.0, 0.26, 0.05)
        (10.0, 10.0)
        >>> left, right = wheel_speeds(0.0, 1.0, 0.26, 0.05); round(left, 1), round(right, 1)
        (-2.6, 2.6)
    """
    return ((v - w * track / 2) / radius, (v + w * track / 2) / radius)


def heading_error(x: float, y: float, yaw: float, goal_x: float, goal_y: float) -> float:
    """Angle (rad, in [-pi, pi]) to turn to face the goal.

    Examples:
        >>> round(heading_error(0, 0, 0, 0, 1), 4)
        1.5708
    """
    error = math.atan2(goal_y - y, goal_x - x) - yaw
    return math.atan2(math.sin(error), math.cos(error))


class DiffDrive:
    """Wheel-level control of one differential-drive body in a world.

    Args:
        world: the :class:`petriflow.world.World`.
        name: the robot's body id or agent name.
        track: distance between the wheels (m).
        radius: wheel radius (m).
        max_force: motor torque limit (N m).
    """

    def __init__(self, world: Any, name: str, track: float = 0.26, radius: float = 0.05,
                 max_force: float = 5.0) -> None:
        self.world = world
        self.p = world.p
        self.body = world.body(name)
        self.name = name
        self.track, self.radius, self.max_force = track, radius, max_force
        joints = {}
        for j in range(self.p.getNumJoints(self.body, physicsClientId=world.client)):
            info = self.p.getJointInfo(self.body, j, physicsClientId=world.client)
            joints[info[1].decode()] = j
            if "caster" in info[12].decode():
                # casters slide: no friction, so they do not fight the wheels
                self.p.changeDynamics(self.body, j, lateralFriction=0.0, rollingFriction=0.0,
                                      spinningFriction=0.0, physicsClientId=world.client)
        if "left_wheel" not in joints or "right_wheel" not in joints:
            raise ActionFailure(f"robot {name!r} has no left_wheel/right_wheel joints")
        self.left, self.right = joints["left_wheel"], joints["right_wheel"]

    def command(self, v: float, w: float) -> None:
        """Drive at forward speed ``v`` (m/s) and turn rate ``w`` (rad/s)."""
        left, right = wheel_speeds(v, w, self.track, self.radius)
        for joint, speed in ((self.left, left), (self.right, right)):
            self.p.setJointMotorControl2(self.body, joint, self.p.VELOCITY_CONTROL, targetVelocity=speed,
                                         force=self.max_force, physicsClientId=self.world.client)

    def stop(self) -> None:
        """Hold the wheels still."""
        self.command(0.0, 0.0)

    def pose(self) -> tuple[float, float, float]:
        """``(x, y, yaw)`` of the robot."""
        return self.world.pose(self.name)


class GoTo(Action):
    """Drive a differential robot through waypoints to a goal, turning on the spot
    when a waypoint is far off its heading. Ends ``ok`` within ``tolerance`` metres of
    the last point.

    The goal is ``x``/``y``, preceded by the optional ``path`` of ``[x, y]`` waypoints.
    """

    params = {
        "x": Param(float, doc="goal x (m)"),
        "y": Param(float, doc="goal y (m)"),
        "path": Param(list, [], "waypoints [[x, y], ...] driven through before the goal"),
        "robot": Param((str, type(None)), None, "body or agent to drive (default: the agent)"),
        "speed": Param(float, 0.4, "cruise speed (m/s)", low=1e-9),
        "tolerance": Param(float, 0.05, "arrival distance (m)", low=1e-9),
        "turn_gain": Param(float, 3.0, "turn rate per radian of heading error", low=1e-9),
    }
    needs_world = True
    requires = frozenset({"world", "robot"})
    uses = (Physics, Bodies, Poses)

    def setup(self, world: Any) -> None:
        if world is None:
            raise ActionFailure("drive.goto needs a world (run with --world)")
        self.world = world
        self.drive: DiffDrive | None = None

    def start(self, ctx) -> None:
        name = self.params["robot"] or ctx.agent
        if name is None:
            raise ActionFailure("no robot: give params.robot or put the transition in an agent subnet")
        if self.drive is None or self.drive.name != name:
            self.drive = DiffDrive(self.world, name)
        try:
            points = [(float(px), float(py)) for px, py in self.params["path"]]
        except (TypeError, ValueError):
            raise ActionFailure(f"path must be a list of [x, y] points, got {self.params['path']!r}") from None
        self.points = points + [(self.params["x"], self.params["y"])]

    def poll(self, ctx) -> Status:
        x, y, yaw = self.drive.pose()
        gx, gy = self.points[0]
        distance = math.hypot(gx - x, gy - y)
        while distance < self.params["tolerance"] * (3 if len(self.points) > 1 else 1):
            self.points.pop(0)
            if not self.points:
                self.drive.stop()
                ctx.result = {"x": round(x, 4), "y": round(y, 4), "yaw": round(yaw, 4)}
                return Status.OK
            gx, gy = self.points[0]
            distance = math.hypot(gx - x, gy - y)
        error = heading_error(x, y, yaw, gx, gy)
        w = max(-2.5, min(2.5, self.params["turn_gain"] * error))
        v = 0.0 if abs(error) > 0.6 else min(self.params["speed"], 1.5 * distance) * math.cos(error)
        self.drive.command(v, w)
        return Status.RUNNING

    def cancel(self, ctx) -> bool:
        if self.drive is not None:
            self.drive.stop()
        return True
