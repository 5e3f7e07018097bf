"""Ray sensors over a pybullet world: distance sensors and a planar laser.

:func:`cast` casts a fan of rays from one point in one ``rayTestBatch`` call and
returns each ray's range (``max_range`` when it hits nothing), ignoring the bodies
given (the robot itself, its teammates when asked). :func:`laser_angles` is the beam
layout of a planar scanner (seed 004: 8 m, 180 degrees, 360 beams).

Examples:
    >>> [round(a, 4) for a in laser_angles(180.0, 3)]
    [-1.5708, 0.0, 1.5708]
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import Any

from petriflow.runtime.radio import walls_between  # the one ray-test wall count, in the core

__all__ = ["cast", "laser_angles", "walls_between"]


def laser_angles(fov_deg: float, beams: int) -> list[float]:
    """Beam angles (rad, robot frame) spread evenly over ``fov_deg``, centred ahead."""
    if beams < 1:
        raise ValueError(f"a laser needs at least one beam, got {beams}")
    if beams == 1:
        return [0.0]
    half = math.radians(fov_deg) / 2.0
    return [-half + i * (2 * half) / (beams - 1) for i in range(beams)]


def cast(world: Any, origin: tuple[float, float], heading: float, angles: Sequence[float], max_range: float,
         *, z: float = 0.1, ignore: Iterable[int] = (), near: float = 0.0) -> list[float]:
    """Ranges (m) of rays from ``origin`` at ``heading + angle`` for each angle.

    Rays start ``near`` metres out (past the sensor's own body: nothing nearer is
    seen, and no ray is cast twice to leave that body); ranges are from ``origin``.

    A ray that hits only ignored bodies (or nothing) reads ``max_range``; one hitting an
    ignored body (each link of a robot: chassis, wheels, caster) is cast again from just
    past the hit, as often as it takes to leave them behind.
    """
    p = world.p
    ignored = set(ignore)
    x, y = origin
    near = min(max(near, 0.0), max_range)
    starts = [(x + near * math.cos(heading + a), y + near * math.sin(heading + a), z) for a in angles]
    ends = [(x + max_range * math.cos(heading + a), y + max_range * math.sin(heading + a), z) for a in angles]
    ranges = [max_range] * len(angles)
    pending = list(range(len(angles)))
    offset = [near] * len(angles)
    for _ in range(64):
        if not pending:
            break
        hits = p.rayTestBatch([starts[i] for i in pending], [ends[i] for i in pending],
                              physicsClientId=world.client)
        again = []
        for i, hit in zip(pending, hits):
            body, fraction = hit[0], hit[2]
            if body < 0:
                continue
            length = math.dist(starts[i], ends[i])
            if body in ignored:
                advance = fraction * length + 0.02
                offset[i] += advance
                sx, sy, _ = starts[i]
                a = heading + angles[i]
                starts[i] = (sx + advance * math.cos(a), sy + advance * math.sin(a), z)
                if offset[i] < max_range:
                    again.append(i)
                continue
            ranges[i] = min(max_range, offset[i] + fraction * length)
        pending = again
    return ranges


