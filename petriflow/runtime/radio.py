"""Radio propagation: one log-distance path-loss model, with walls counted by ray test.

Every radio channel of petriflow (the core ``range`` channel, seed 000's Wi-Fi, seed
002's ZigBee bus) computes received power the same way::

    RSSI(d, walls) = tx_power_dbm - reference_loss_db - 10 * exponent * log10(max(d, min_distance) / 1 m)
                     - walls_db

:class:`LogDistance` holds that formula; :class:`WallCounter` counts the walls a
straight line between two agents of a pybullet world crosses (a ray test), caching
each pair of places to the centimetre, since walls do not move. What a channel does
with the RSSI (a threshold, a fading margin, bit errors) is the channel's.

Examples:
    >>> free = LogDistance(tx_power_dbm=-30.0, exponent=2.0, min_distance=0.01)
    >>> round(free.rssi(2.0), 2), round(free.range(-63.4375), 1)
    (-36.02, 47.0)
    >>> xbee = LogDistance(tx_power_dbm=0.0, reference_loss_db=40.0)
    >>> xbee.rssi(10.0), xbee.rssi(10.0, walls_db=3.0)
    (-60.0, -63.0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Iterable

__all__ = ["LogDistance", "WallCounter", "walls_between"]


@dataclass(frozen=True)
class LogDistance:
    """Log-distance path loss (see the module).

    Attributes:
        tx_power_dbm: transmit power (dBm).
        reference_loss_db: path loss at 1 m (dB).
        exponent: path-loss exponent.
        min_distance: distances below this count as this (metres): the log law means
            nothing in the antennas' near field.
    """

    tx_power_dbm: float = 0.0
    reference_loss_db: float = 0.0
    exponent: float = 2.0
    min_distance: float = 0.05

    def rssi(self, distance: float, walls_db: float = 0.0) -> float:
        """Mean received power (dBm) at ``distance`` metres through ``walls_db`` of walls."""
        d = max(distance, self.min_distance)
        return self.tx_power_dbm - self.reference_loss_db - 10.0 * self.exponent * math.log10(d) - walls_db

    def range(self, threshold_dbm: float, walls_db: float = 0.0) -> float:
        """The distance (metres) at which the RSSI falls to ``threshold_dbm``."""
        margin = self.tx_power_dbm - self.reference_loss_db - walls_db - threshold_dbm
        return round(10 ** (margin / (10.0 * self.exponent)), 6)


def walls_between(world: Any, a: tuple[float, float], b: tuple[float, float], *, z: float = 0.1,
                  ignore: Iterable[int] = (), most: int = 16) -> int:
    """How many solid bodies (walls) a straight line from ``a`` to ``b`` crosses at
    height ``z``, not counting the ``ignore`` bodies (the two radios' robots), at most
    ``most`` (pybullet ray tests, one per wall crossed)."""
    p = world.p
    ignored = set(ignore)
    count = 0
    start = (a[0], a[1], z)
    end = (b[0], b[1], z)
    total = math.dist(start, end)
    travelled = 0.0
    while count < most and travelled < total:
        hit = p.rayTest(start, end, physicsClientId=world.client)[0]
        if hit[0] < 0:
            break
        if hit[0] not in ignored:
            count += 1
        length = max(math.dist(start, end), 1e-9)
        direction = ((end[0] - start[0]) / length, (end[1] - start[1]) / length)
        advance = hit[2] * length + 0.05  # on from just beyond the body's far side
        travelled += advance
        start = (start[0] + direction[0] * advance, start[1] + direction[1] * advance, z)
    return count


class WallCounter:
    """Distance and walls between two agents of a world (see the module).

    Args:
        world: a :class:`petriflow.world.World` (positions by agent, ray tests).
        z: the antennas' height (metres).
    """

    def __init__(self, world: Any, z: float = 0.1) -> None:
        self.world = world
        self.z = z
        self._walls: dict[tuple, int] = {}

    def between(self, a: str, b: str) -> tuple[float, int] | None:
        """``(distance in metres, walls crossed)`` between agents ``a`` and ``b`` now, or
        ``None`` when the world does not know where one of them is."""
        world = self.world
        if world is None or not hasattr(world, "position"):
            return None
        pa, pb = world.position(a), world.position(b)
        if pa is None or pb is None:
            return None
        key = tuple(sorted(((round(pa[0], 2), round(pa[1], 2)), (round(pb[0], 2), round(pb[1], 2)))))
        walls = self._walls.get(key)
        if walls is None:
            robots = [world.body(name) for name in getattr(world, "agents", {})] or [world.body(a), world.body(b)]
            walls = self._walls[key] = walls_between(world, pa, pb, z=self.z, ignore=robots)
        return math.dist(pa, pb), walls
