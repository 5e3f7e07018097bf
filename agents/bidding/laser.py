"""A robot's laser returns as world points: eq. 7-8 of seed 004 (§2.2).

Robot ``r_i`` at pose ``(x_i, y_i, θ_i)`` reads range ``radius_ik`` on beam ``k``,
which points ``φ_ik`` off the robot's heading. The obstacle (or environment limit) it
hit is at::

    x_k = radius_ik · cos(θ_i + φ_ik) + x_i        (7)
    y_k = radius_ik · sin(θ_i + φ_ik) + y_i        (8)

in the global frame. A beam that reads the laser's maximum range hit nothing and gives
no point (:func:`world_points`). :func:`scan` reads the ranges in a pybullet world
with the planar laser of :mod:`petriflow.agents.mobile.sensors` (Table 1: 8 m,
180°, 360 beams), never seeing the robot's own body and, when asked, not its
teammates' either (the paper's robots see each other: those are the fictitious
obstacles ``ξ`` of eq. 10).

Examples:
    >>> world_points((1.0, 2.0, math.pi / 2), [3.0, 8.0], [0.0, 0.5], max_range=8.0).round(9).tolist()
    [[1.0, 5.0]]
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from petriflow.agents.bidding.errors import BiddingError
from petriflow.agents.mobile.sensors import cast, laser_angles

__all__ = ["RANGE_M", "FOV_DEG", "BEAMS", "world_points", "scan"]

#: Table 1: the laser's range (m), field of view (degrees) and number of beams.
RANGE_M, FOV_DEG, BEAMS = 8.0, 180.0, 360


def _pose(pose: Any) -> tuple[float, float, float]:
    values = np.asarray(pose, dtype=float).reshape(-1)
    if values.shape != (3,) or not np.all(np.isfinite(values)):
        raise BiddingError(f"a pose is (x, y, heading) as 3 finite numbers, got {pose!r}")
    return (float(values[0]), float(values[1]), float(values[2]))


def world_points(pose: Any, ranges: Any, angles: Any, max_range: float) -> np.ndarray:
    """Eq. 7-8: the ``(k, 2)`` world points of the beams that hit something.

    Args:
        pose: the robot's ``(x_i, y_i, θ_i)`` (m, m, rad).
        ranges: ``radius_ik``, one range per beam (m).
        angles: ``φ_ik``, each beam's angle off the heading (rad), as many as ``ranges``.
        max_range: the laser's range; beams reading it (or more) returned nothing.

    Examples:
        >>> world_points((0, 0, 0), [1.0, 2.0], [0.0, math.pi / 2], 5.0).round(9).tolist()
        [[1.0, 0.0], [0.0, 2.0]]
        >>> world_points((0, 0, 0), [1.0, 2.0], [0.0], 5.0)
        Traceback (most recent call last):
        ...
        petriflow.agents.bidding.errors.BiddingError: 2 ranges for 1 beam angles
    """
    x, y, theta = _pose(pose)
    radius = np.asarray(ranges, dtype=float)
    phi = np.asarray(angles, dtype=float)
    if radius.ndim != 1 or phi.ndim != 1:
        raise BiddingError(f"ranges and angles are 1-D, got shapes {radius.shape} and {phi.shape}")
    if radius.shape != phi.shape:
        raise BiddingError(f"{radius.size} ranges for {phi.size} beam angles")
    if not (math.isfinite(max_range) and max_range > 0):
        raise BiddingError(f"the laser's range must be > 0 m, got {max_range!r}")
    hit = np.isfinite(radius) & (radius >= 0) & (radius < max_range) & np.isfinite(phi)
    r, heading = radius[hit], theta + phi[hit]
    return np.column_stack((r * np.cos(heading) + x, r * np.sin(heading) + y))


def scan(world: Any, agent: str, pose: Any, *, max_range: float = RANGE_M, fov_deg: float = FOV_DEG,
         beams: int = BEAMS, z: float = 0.1, ignore_teammates: bool = False,
         hits: bool = False) -> tuple[np.ndarray, np.ndarray] | tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One sweep of ``agent``'s laser in a :class:`petriflow.world.World`.

    Args:
        world: the world (its ``p``, ``client``, ``body`` and ``agents``).
        agent: the robot's agent (or body) name; its own body is never seen.
        pose: ``(x, y, heading)`` the laser is cast from (the robot's localised pose),
            or ``None`` for the body's pose in the world.
        max_range, fov_deg, beams: the laser (Table 1 by default).
        z: the height of the scanning plane (m).
        ignore_teammates: see through every robot of ``world.agents``.
        hits: also return what each beam hit.

    Returns:
        ``(ranges, angles)``: float arrays of ``beams`` ranges (``max_range`` where a
        beam hit nothing) and beam angles off the heading (rad), for :func:`world_points`;
        with ``hits``, ``(ranges, angles, bodies)``, ``bodies`` the pybullet body each
        beam hit (-1: nothing). What a beam hit is the simulator's knowledge, not the
        robot's: it tells eq. 10's real obstacles from the fictitious ones (teammates).

    It runs pybullet's collision detection first (no time passes), so the rays see the
    bodies where they are even in a world not stepped since they were placed.
    """
    if not (math.isfinite(max_range) and max_range > 0):
        raise BiddingError(f"the laser's range must be > 0 m, got {max_range!r}")
    if isinstance(beams, bool) or not isinstance(beams, int) or beams < 1:
        raise BiddingError(f"a laser needs a whole number of beams >= 1, got {beams!r}")
    if not 0 < fov_deg <= 360:
        raise BiddingError(f"the field of view must be from 0 (excluded) to 360 degrees, got {fov_deg!r}")
    x, y, theta = _pose(world.pose(agent) if pose is None else pose)
    ignore = {world.body(agent)}
    if ignore_teammates:
        ignore.update(world.body(name) for name in world.agents)
    angles = laser_angles(fov_deg, beams)
    # bring the bodies' bounding boxes up to date (a world not stepped since it was built or
    # since robots were placed has stale ones, and the rays would pass through the robots)
    world.p.performCollisionDetection(physicsClientId=world.client)
    body = world.body(agent)
    low, high = world.p.getAABB(body, physicsClientId=world.client)
    hx, hy = (high[0] - low[0]) / 2.0, (high[1] - low[1]) / 2.0
    near = math.hypot(hx, hy) + 0.01 if pose is None or math.hypot(x - (low[0] + hx), y - (low[1] + hy)) < 0.05 else 0.0
    if not hits:
        ranges = cast(world, (x, y), theta, angles, max_range, z=z, ignore=ignore, near=near)
        return np.asarray(ranges, dtype=float), np.asarray(angles, dtype=float)
    ranges, bodies = _cast_hits(world, (x, y), theta, angles, max_range, z=z, ignore=ignore, near=near)
    return ranges, np.asarray(angles, dtype=float), bodies


def _cast_hits(world: Any, origin: tuple[float, float], heading: float, angles: list[float], max_range: float, *,
               z: float, ignore: set[int], near: float) -> tuple[np.ndarray, np.ndarray]:
    """Ranges and hit bodies of rays fanned from ``origin`` (one ``rayTestBatch`` per
    round; a ray that hits an ignored body goes on from just past it)."""
    p = world.p
    x, y = origin
    near = min(max(near, 0.0), max_range)
    a = heading + np.asarray(angles, dtype=float)
    c, s = np.cos(a), np.sin(a)
    n = len(angles)
    ranges = np.full(n, max_range, dtype=float)
    bodies = np.full(n, -1, dtype=np.int64)
    offset = np.full(n, near, dtype=float)
    pending = list(range(n))
    for _ in range(64):
        if not pending:
            break
        starts = [(x + offset[i] * c[i], y + offset[i] * s[i], z) for i in pending]
        ends = [(x + max_range * c[i], y + max_range * s[i], z) for i in pending]
        again = []
        for i, hit in zip(pending, p.rayTestBatch(starts, ends, physicsClientId=world.client)):
            body, fraction = hit[0], hit[2]
            if body < 0:
                continue
            length = max_range - offset[i]
            if body in ignore:
                offset[i] += fraction * length + 0.02
                if offset[i] < max_range:
                    again.append(i)
                continue
            ranges[i] = min(max_range, offset[i] + fraction * length)
            bodies[i] = body
        pending = again
    return ranges, bodies
