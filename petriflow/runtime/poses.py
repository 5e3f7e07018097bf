"""Pose sampling: where the world's bodies are, recorded in the run's events.

A :class:`PoseSampler` watches the scheduler's instants and, at most once every
``every`` simulated seconds, records a ``pose`` event: ``{"poses": {name: [x, y, yaw]}}``
for the bodies that moved since they were last recorded (by more than a millimetre or
a milliradian; every one at the first sample). A body is named by the agent whose robot
it is, else by its id in the world. The first sample also carries ``outlines``: the
fixed bodies (walls, furniture) as polygons in the ground plane, so a trace alone is
enough to draw the world from above (``petriflow view``).

The world is anything with ``agents`` (``{agent: body name}``) and ``pose(name)``
(``(x, y, yaw)``): a :class:`Posed` one; a pybullet :class:`petriflow.world.World`
(:class:`~petriflow.capabilities.Bodies`, :class:`~petriflow.capabilities.Physics`) also
gives its other movable bodies and its fixed outlines. A run without a world records nothing. Like
every event, a pose event takes its number whether or not anyone listens, so a run
with a trace and one without still number their events the same.

Examples:
    >>> from types import SimpleNamespace
    >>> seen = []
    >>> world = SimpleNamespace(agents={"r1": "body1"}, pose=lambda name: (1.0, 2.0, 0.5))
    >>> run = SimpleNamespace(world=world, now=0.0, emit=lambda kind, t, a, **data: seen.append(data))
    >>> sample = PoseSampler(every=1.0)
    >>> sample(run); run.now = 0.5; sample(run); run.now = 1.0; sample(run)
    >>> seen
    [{'poses': {'r1': [1.0, 2.0, 0.5]}}]
"""

from __future__ import annotations

import math
from typing import Any, Protocol

from petriflow.capabilities import Bodies, Physics, missing

__all__ = ["PoseSampler", "outlines"]


class PoseSampler:
    """Records the world's body poses as ``pose`` events (see the module).

    Args:
        every: simulated seconds between samples (> 0).
    """

    def __init__(self, every: float = 1.0) -> None:
        if not (isinstance(every, (int, float)) and math.isfinite(every) and every > 0):
            raise ValueError(f"the pose sampling interval must be a number of seconds > 0, got {every!r}")
        self.every = float(every)
        self._next = 0.0
        self._last: dict[str, tuple[float, float, float]] = {}
        self._movable: dict[str, str] | None = None  # shown name -> body name

    def __call__(self, scheduler: Any) -> None:
        world = scheduler.world
        now = scheduler.now
        if world is None or now < self._next:
            return
        self._next = now + self.every
        first = self._movable is None
        if first:
            self._movable = _movable(world)
        poses = {}
        for name, body in self._movable.items():
            try:
                x, y, yaw = world.pose(body)
            except Exception:  # removed from the world since (a robot a scenario does not deploy)
                continue
            pose = (round(float(x), 3), round(float(y), 3), round(float(yaw), 3))
            if self._last.get(name) != pose:
                self._last[name] = pose
                poses[name] = list(pose)
        if not poses and not first:
            return
        data: dict[str, Any] = {"poses": poses}
        if first:
            shapes = outlines(world)
            if shapes:
                data["outlines"] = shapes
        scheduler.emit("pose", None, None, **data)


class Posed(Protocol):
    """What a sampler reads of a world: its agents' robots and their poses."""

    agents: dict[str, str]
    """``{agent: body name}``."""

    def pose(self, name: str) -> tuple[float, float, float]:
        """``(x, y, yaw)`` of a body or an agent's robot."""


def _has(world: Any, *capabilities: type) -> bool:
    return world is not None and not any(missing(world, capability) for capability in capabilities)


def _movable(world: Any) -> dict[str, str]:
    """``{shown name: body name}``: the agents' robots (a :class:`Posed` world), then any
    other body that can move (with :class:`~petriflow.capabilities.Bodies` and
    :class:`~petriflow.capabilities.Physics`)."""
    if not _has(world, Posed):
        return {}
    named = dict(world.agents)
    if _has(world, Bodies, Physics):
        p, client = world.p, world.client
        robots = set(named.values())
        for name, body in world.bodies.items():
            if name in robots or name == "plane":
                continue
            try:
                mass = p.getDynamicsInfo(body, -1, physicsClientId=client)[0]
            except Exception:
                continue
            if mass > 0:
                named[name] = name
    return named


def outlines(world: Any) -> list[dict[str, Any]]:
    """The fixed bodies of a pybullet world as ``{"id", "points": [[x, y], ...], "colour"}``
    (a box as its rotated rectangle, anything else as its bounding box; the ground plane
    and the robots left out); ``[]`` for a world that is not a pybullet one (without
    :class:`~petriflow.capabilities.Bodies` and :class:`~petriflow.capabilities.Physics`)."""
    if not _has(world, Bodies, Physics):
        return []
    p, client = world.p, world.client
    robots = set(world.agents.values())
    shapes = []
    for name, body in world.bodies.items():
        if name in robots or name == "plane":
            continue
        try:
            if p.getDynamicsInfo(body, -1, physicsClientId=client)[0] > 0:
                continue  # it moves: sampled as a pose instead
            data = p.getCollisionShapeData(body, -1, physicsClientId=client)
            visual = p.getVisualShapeData(body, physicsClientId=client)
            colour = [round(c, 3) for c in visual[0][7][:3]] if visual else [0.5, 0.5, 0.5]
            if p.getNumJoints(body, physicsClientId=client) == 0 and len(data) == 1 and data[0][2] == p.GEOM_BOX:
                sx, sy = data[0][3][0] / 2, data[0][3][1] / 2
                (cx, cy, _), orientation = p.getBasePositionAndOrientation(body, physicsClientId=client)
                yaw = p.getEulerFromQuaternion(orientation)[2]
                c, s = math.cos(yaw), math.sin(yaw)
                points = [[cx + c * dx - s * dy, cy + s * dx + c * dy]
                          for dx, dy in ((-sx, -sy), (sx, -sy), (sx, sy), (-sx, sy))]
            else:
                (x0, y0, _), (x1, y1, _) = p.getAABB(body, physicsClientId=client)
                points = [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
        except Exception:  # a body pybullet cannot describe: left out of the picture
            continue
        shapes.append({"id": name, "points": [[round(x, 3), round(y, 3)] for x, y in points], "colour": colour})
    return shapes
