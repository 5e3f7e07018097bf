"""Joint-level control of a legged robot's body in a pybullet world.

:class:`LeggedRobot` binds a world body (loaded from one of the URDFs of
:mod:`petriflow.agents.legged.robots`) to its design: it reads the body's pose and
joints, and commands joint positions through pybullet's position motors, within the
motor limits of the design (servo torque and speed, actuator force and speed). The
physics moves the body; nothing here sets a body's pose.

pybullet reports a base's pose at its centre of mass; :meth:`LeggedRobot.pose` gives
the pose of the body frame (the design's), which is what the gaits plan.

Examples:
    >>> from petriflow.world import World
    >>> world = World({"robots": [{"id": "dog", "urdf": "petriflow.agents.legged:robots/robot4l.urdf",
    ...                            "z": 0.11}]})
    >>> robot = LeggedRobot(world, "dog")
    >>> robot.design.name, robot.leg_names
    ('robot4l', ('lf', 'rf', 'lh', 'rh'))
    >>> robot.hold(robot.nominal())
    >>> for _ in range(300):
    ...     world.step()
    >>> robot.upright(), round(robot.height(), 2)
    (True, 0.13)
    >>> world.close()
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from petriflow.agents.legged.robots import (
    ACTUATOR_FORCE,
    ACTUATOR_SPEED,
    DESIGNS,
    SERVO_SPEED,
    SERVO_TORQUE,
    RobotDesign,
)

__all__ = ["LeggedRobot", "NotLeggedError"]

Joints = dict[str, tuple[float, float, float]]


class NotLeggedError(ValueError):
    """The body is not one of the legged robots (its URDF names no known design)."""


class LeggedRobot:
    """A legged robot in a world: pose, joints, position commands.

    Args:
        world: the :class:`petriflow.world.World`.
        name: the robot's body id or agent name.
        design: the design; by default the one named by the URDF's ``<robot name>``.
        position_gain: pybullet position-motor gain (``Kp`` of its constraint).
    """

    def __init__(self, world: Any, name: str, design: RobotDesign | None = None,
                 position_gain: float = 0.3) -> None:
        self.world = world
        self.p = world.p
        self.client = world.client
        self.name = name
        self.body = world.body(name)
        if design is None:
            robot_name = self.p.getBodyInfo(self.body, physicsClientId=self.client)[1].decode()
            if robot_name not in DESIGNS:
                raise NotLeggedError(f"body {name!r} is a {robot_name!r}, not one of {sorted(DESIGNS)}")
            design = DESIGNS[robot_name]
        self.design = design
        self.position_gain = position_gain
        index = {}
        for j in range(self.p.getNumJoints(self.body, physicsClientId=self.client)):
            info = self.p.getJointInfo(self.body, j, physicsClientId=self.client)
            index[info[1].decode()] = j
        self.joints_of: dict[str, tuple[int | None, int, int]] = {}
        for leg in design.legs:
            try:
                self.joints_of[leg.name] = (index.get(f"{leg.name}_hip"), index[f"{leg.name}_knee"],
                                            index[f"{leg.name}_ext"])
            except KeyError as exc:
                raise NotLeggedError(f"body {name!r} has no joint {exc.args[0]!r}") from None
        dynamics = self.p.getDynamicsInfo(self.body, -1, physicsClientId=self.client)
        self._inertial_position = dynamics[3]
        self._inertial_orientation = dynamics[4]

    @property
    def leg_names(self) -> tuple[str, ...]:
        """The legs' names."""
        return self.design.leg_names

    # Reading --------------------------------------------------------------------------
    def frame(self) -> tuple[np.ndarray, np.ndarray]:
        """Position and 3×3 rotation of the body frame in the world."""
        p = self.p
        com, orientation = p.getBasePositionAndOrientation(self.body, physicsClientId=self.client)
        inverse = p.invertTransform(self._inertial_position, self._inertial_orientation)
        position, orientation = p.multiplyTransforms(com, orientation, *inverse)
        rotation = np.array(p.getMatrixFromQuaternion(orientation)).reshape(3, 3)
        return np.array(position), rotation

    def pose(self) -> tuple[float, float, float]:
        """``(x, y, yaw)`` of the body frame; yaw of its ``x`` axis seen from above."""
        position, rotation = self.frame()
        return (float(position[0]), float(position[1]), math.atan2(rotation[1, 0], rotation[0, 0]))

    def height(self) -> float:
        """Height of the body frame's origin above the ground plane (z = 0)."""
        return float(self.frame()[0][2])

    def tilt(self) -> float:
        """Angle (rad) between the body's ``z`` axis and the vertical: 0 upright, π/2 on
        its side, π on its back."""
        _, rotation = self.frame()
        return math.acos(max(-1.0, min(1.0, float(rotation[2, 2]))))

    def upright(self, tolerance: float = 0.35) -> bool:
        """Whether the body's tilt is within ``tolerance`` rad (20° by default)."""
        return self.tilt() <= tolerance

    def joints(self) -> Joints:
        """Current joint values per leg (``q1`` is 0 for a leg without hip)."""
        values = {}
        for leg, (hip, knee, ext) in self.joints_of.items():
            q1 = 0.0 if hip is None else self.p.getJointState(self.body, hip, physicsClientId=self.client)[0]
            q2 = self.p.getJointState(self.body, knee, physicsClientId=self.client)[0]
            q3 = self.p.getJointState(self.body, ext, physicsClientId=self.client)[0]
            values[leg] = (q1, q2, q3)
        return values

    def nominal(self) -> Joints:
        """The standing posture's joints."""
        return {leg.name: leg.nominal for leg in self.design.legs}

    def feet(self) -> dict[str, np.ndarray]:
        """World positions of the foot centres (from the joints and the body frame)."""
        position, rotation = self.frame()
        joints = self.joints()
        return {leg.name: position + rotation @ leg.foot(joints[leg.name]) for leg in self.design.legs}

    # Commanding -----------------------------------------------------------------------
    def command(self, targets: Joints, speed_scale: float = 1.0, force_scale: float = 1.0) -> None:
        """Drive every joint towards its target with the position motors.

        Args:
            targets: ``(q1, q2, q3)`` per leg (legs left out keep their last command).
            speed_scale: fraction of the motors' top speed allowed.
            force_scale: fraction of the motors' torque or force allowed.
        """
        p = self.p
        for leg, values in targets.items():
            hip, knee, ext = self.joints_of[leg]
            for joint, value, force, speed in (
                (hip, values[0], SERVO_TORQUE, SERVO_SPEED),
                (knee, values[1], SERVO_TORQUE, SERVO_SPEED),
                (ext, values[2], ACTUATOR_FORCE, ACTUATOR_SPEED),
            ):
                if joint is None:
                    continue
                p.setJointMotorControl2(self.body, joint, p.POSITION_CONTROL, targetPosition=float(value),
                                        force=force * force_scale, maxVelocity=speed * speed_scale,
                                        positionGain=self.position_gain, physicsClientId=self.client)

    def hold(self, targets: Joints | None = None) -> None:
        """Hold ``targets`` (default: the current joints)."""
        self.command(self.joints() if targets is None else targets)

    def relax(self, legs: Sequence[str] | None = None) -> None:
        """Let the joints of ``legs`` (default all) go limp (motors off)."""
        p = self.p
        for leg in legs or self.leg_names:
            for joint in self.joints_of[leg]:
                if joint is not None:
                    p.setJointMotorControl2(self.body, joint, p.VELOCITY_CONTROL, targetVelocity=0.0, force=0.0,
                                            physicsClientId=self.client)
