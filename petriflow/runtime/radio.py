"""Radio propagation: one log-distance path-loss model, with walls counted by ray test.

Every radio channel of petriflow (the core ``range`` channel, a scenario's Wi-Fi link
between robots, a ZigBee bus) computes received power the same way::

    RSSI(d, walls) = tx_power_dbm - reference_loss_db - 10 * exponent * log10(max(d, min_distance) / 1 m)
                     - walls_db

:class:`LogDistance` holds that formula; :class:`WallCounter` counts the walls a
straight line between two agents of a pybullet world crosses (a ray test), caching
each pair of places to the centimetre, since walls do not move. What a channel does
with the RSSI (a threshold, a fading margin, bit errors) is the channel's; the two
parts of a link budget that several channels share live here too:
:func:`power_for_range` (the transmit power that puts a threshold at a distance, how a
radio is calibrated from one measured range) and :func:`fade_loss` (a fading margin:
the chance a frame is lost rising linearly to 1 over ``fade_db`` of RSSI).
:meth:`LogDistance.rssi_many` is the same formula over a numpy array of distances, for
code that asks about many links at once.

For many radios at once (a swarm), :func:`pairs_within` finds the pairs closer than
the free-space range with a spatial index (scipy's ``cKDTree`` when scipy is
installed, else a grid of cells one range wide: never all pairs), :func:`walls_along`
counts the walls on many segments with batched ray tests, and :class:`RadioIndex`
puts the two together: who hears whom now, with walls counted only for the candidates.

Examples:
    >>> free = LogDistance(tx_power_dbm=-30.0, exponent=2.0, min_distance=0.01)
    >>> round(free.rssi(2.0), 2), round(free.range(-63.4375), 1)
    (-36.02, 47.0)
    >>> xbee = LogDistance(tx_power_dbm=0.0, reference_loss_db=40.0)
    >>> xbee.rssi(10.0), xbee.rssi(10.0, walls_db=3.0)
    (-60.0, -63.0)
    >>> free.rssi_many([2.0, 0.001]).round(2).tolist()
    [-36.02, 10.0]
    >>> round(power_for_range(-64.0, 5.0), 4), fade_loss(-69.0, floor_dbm=-74.0, fade_db=10.0)
    (-50.0206, 0.5)
    >>> pairs_within([(0, 0), (1, 0), (5, 0), (5.5, 0.5)], 1.0, method="grid").tolist()
    [[0, 1], [2, 3]]
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Iterable

from petriflow.capabilities import Bodies, Physics, Poses, missing

__all__ = ["LogDistance", "power_for_range", "fade_loss", "WallCounter", "walls_between", "pairs_within", "walls_along", "RadioIndex"]


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

    def rssi_many(self, distances: Any, walls_db: Any = 0.0) -> Any:
        """:meth:`rssi` of each of ``distances`` (metres, any array shape) through
        ``walls_db`` (a number or an array of the same shape), as a numpy array."""
        import numpy as np

        d = np.maximum(np.asarray(distances, dtype=float), self.min_distance)
        rssi = self.tx_power_dbm - self.reference_loss_db - 10.0 * self.exponent * np.log10(d)
        return rssi - walls_db if np.any(walls_db) else rssi


def power_for_range(threshold_dbm: float, distance: float, exponent: float = 2.0,
                    reference_loss_db: float = 0.0) -> float:
    """The transmit power (dBm) that puts the RSSI at ``threshold_dbm`` at ``distance``
    metres: what a radio measured to reach that far has (the inverse of
    :meth:`LogDistance.range`)."""
    return threshold_dbm + reference_loss_db + 10.0 * exponent * math.log10(distance)


def fade_loss(rssi: float, floor_dbm: float, fade_db: float) -> float:
    """The chance a frame received at ``rssi`` (dBm) is lost to fading: 1 at or below
    ``floor_dbm`` (where frames stop arriving), 0 at or above ``floor_dbm + fade_db``,
    linear in between (no margin, ``fade_db`` <= 0: a step at the floor)."""
    if rssi <= floor_dbm:
        return 1.0
    if fade_db <= 0 or rssi >= floor_dbm + fade_db:
        return 0.0
    return 1.0 - (rssi - floor_dbm) / fade_db


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
        world: a world with :class:`~petriflow.capabilities.Poses`,
            :class:`~petriflow.capabilities.Bodies` and
            :class:`~petriflow.capabilities.Physics` (a :class:`petriflow.world.World`);
            with another (or ``None``) no pair is measured.
        z: the antennas' height (metres).
    """

    def __init__(self, world: Any, z: float = 0.1) -> None:
        self.world = world if world is not None and not any(missing(world, c) for c in (Poses, Bodies, Physics)) \
            else None
        self.z = z
        self._walls: dict[tuple, int] = {}

    def between(self, a: str, b: str) -> tuple[float, int] | None:
        """``(distance in metres, walls crossed)`` between agents ``a`` and ``b`` now, or
        ``None`` when the world does not know where one of them is."""
        world = self.world
        if world is None:
            return None
        pa, pb = world.position(a), world.position(b)
        if pa is None or pb is None:
            return None
        key = tuple(sorted(((round(pa[0], 2), round(pa[1], 2)), (round(pb[0], 2), round(pb[1], 2)))))
        walls = self._walls.get(key)
        if walls is None:
            robots = [world.body(name) for name in world.agents] or [world.body(a), world.body(b)]
            walls = self._walls[key] = walls_between(world, pa, pb, z=self.z, ignore=robots)
        return math.dist(pa, pb), walls


def _kdtree():
    try:
        from scipy.spatial import cKDTree
    except ImportError:  # scipy is optional: the grid does the same
        return None
    return cKDTree


def pairs_within(points: Any, radius: float, *, method: str = "auto") -> Any:
    """Index pairs ``(i, j)``, ``i < j``, of points (``(N, 2)``) at most ``radius`` apart,
    sorted, as an ``(K, 2)`` integer array. ``method``: ``kdtree`` (scipy), ``grid``
    (numpy: cells ``radius`` wide, each point compared with the points of its own and
    the neighbouring cells), ``auto`` (the k-d tree when scipy is installed), or
    ``all`` (every pair: the reference the others are tested against)."""
    import numpy as np

    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    n = len(pts)
    empty = np.zeros((0, 2), dtype=np.int64)
    if n < 2 or not radius > 0:
        return empty
    if method == "auto":
        method = "kdtree" if _kdtree() is not None else "grid"
    if method == "kdtree":
        tree = _kdtree()(pts)
        pairs = tree.query_pairs(radius, output_type="ndarray").astype(np.int64)
    elif method == "all":
        i, j = np.triu_indices(n, 1)
        keep = np.hypot(*(pts[i] - pts[j]).T) <= radius
        pairs = np.stack([i[keep], j[keep]], axis=1)
    elif method == "grid":
        cells = np.floor((pts - pts.min(axis=0)) / radius).astype(np.int64)
        width = int(cells[:, 0].max()) + 3
        key = (cells[:, 1] + 1) * width + (cells[:, 0] + 1)
        order = np.argsort(key, kind="stable")
        sorted_keys = key[order]
        found = []
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                target = key + dy * width + dx
                lo = np.searchsorted(sorted_keys, target, "left")
                hi = np.searchsorted(sorted_keys, target, "right")
                counts = hi - lo
                if not counts.any():
                    continue
                i = np.repeat(np.arange(n), counts)
                starts = np.repeat(lo - np.cumsum(counts) + counts, counts)
                j = order[np.arange(len(i)) + starts]
                keep = i < j
                found.append(np.stack([i[keep], j[keep]], axis=1))
        pairs = np.concatenate(found) if found else empty
        if len(pairs):
            d = np.hypot(*(pts[pairs[:, 0]] - pts[pairs[:, 1]]).T)
            pairs = pairs[d <= radius]
    else:
        raise ValueError(f"method is auto, kdtree, grid or all, not {method!r}")
    if not len(pairs):
        return empty
    pairs = pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]
    return pairs


def walls_along(world: Any, starts: Any, ends: Any, *, z: float = 0.1, most: int = 16) -> list[int]:
    """Walls (solid bodies that are not kinematic robots) each segment ``starts[k]`` to
    ``ends[k]`` (``(x, y)`` points) crosses at height ``z``, at most ``most``: what
    :func:`walls_between` counts, for many segments at once, by rounds of one
    ``rayTestBatch`` each (round k casts on from beyond the k-th wall of the segments
    that hit one). ``world`` is a :class:`petriflow.world.World`."""
    segments = [((a[0], a[1]), (b[0], b[1])) for a, b in zip(starts, ends)]
    counts = [0] * len(segments)
    travelled = [0.0] * len(segments)
    current = [a for a, _ in segments]
    todo = list(range(len(segments)))
    while todo:
        hits = world.rays([(current[k][0], current[k][1], z) for k in todo],
                          [(segments[k][1][0], segments[k][1][1], z) for k in todo], robots=False)
        later = []
        for k, (body, fraction, _) in zip(todo, hits):
            if body < 0:
                continue
            counts[k] += 1
            (ax, ay), (bx, by) = current[k], segments[k][1]
            length = max(math.hypot(bx - ax, by - ay), 1e-9)
            advance = fraction * length + 0.05  # on from just beyond the body's far side
            travelled[k] += advance
            current[k] = (ax + (bx - ax) / length * advance, ay + (by - ay) / length * advance)
            total = math.dist(*segments[k])
            if counts[k] < most and travelled[k] < total:
                later.append(k)
        todo = later
    return counts


class RadioIndex:
    """Who hears whom among many radios: pairs within the free-space range of the
    threshold by a spatial index (:func:`pairs_within`), then walls counted by ray
    only for those candidates (cached per pair of places to the centimetre, as
    :class:`WallCounter` does), and the pair kept when its RSSI through the walls is at
    least the threshold.

    Args:
        model: the path-loss model.
        threshold_dbm: the weakest signal a receiver decodes.
        wall_db: loss per wall crossed (0: walls are not counted).
        world: a :class:`petriflow.world.World` for the walls (``None``: free space).
        z: the antennas' height (m).
        method: the index (see :func:`pairs_within`).
        wall_cell: count walls between the centres of the square cells (of this side,
            from ``(0, 0)``) the two radios are in rather than between the radios
            themselves (``None``: the radios), so the counts cached per pair of places
            serve every robot in those cells (robots that stand in a maze's cells).

    Examples:
        >>> index = RadioIndex(LogDistance(-30.0, 0.0, 2.0, 0.01), threshold_dbm=-50.0)
        >>> index.links([(0, 0), (9, 0), (30, 0)]).tolist()
        [[0, 1]]
    """

    def __init__(self, model: LogDistance, threshold_dbm: float, wall_db: float = 0.0, world: Any = None,
                 z: float = 0.1, method: str = "auto", wall_cell: float | None = None) -> None:
        self.model = model
        self.wall_cell = wall_cell
        self.threshold_dbm = threshold_dbm
        self.wall_db = wall_db
        self.world = world
        self.z = z
        self.method = method
        self.radius = model.range(threshold_dbm)
        self._walls: dict[tuple, int] = {}
        # the k-d tree (scipy's, imported now: at the first query it would cost that query)
        self._tree_class = _kdtree() if method in ("auto", "kdtree") else None
        #: Ray-tested candidate pairs so far (the cost the index saves is the rest).
        self.tested = 0

    def links(self, points: Any) -> Any:
        """The pairs ``(i, j)``, ``i < j``, of points (``(N, 2)``) that hear each other."""
        import numpy as np

        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        pairs = pairs_within(pts, self.radius, method=self.method)
        return pairs[self._clear(pts, pairs)] if len(pairs) else pairs

    def tree(self, points: Any) -> Any:
        """A k-d tree of ``points`` for :meth:`heard_by` (``None`` without scipy): build
        it once for all the radios asking while nothing moves."""
        import numpy as np

        tree = self._tree_class
        if tree is None or self.method not in ("auto", "kdtree"):
            return None
        return tree(np.asarray(points, dtype=float).reshape(-1, 2))

    def heard_by(self, points: Any, asker: int, tree: Any = None) -> list[int]:
        """The indices of the points that hear point ``asker`` (and that it hears), by
        the index: a query of ``tree`` (:meth:`tree` of the same points) or of a tree
        built now when scipy is installed, else one vectorised distance row."""
        import numpy as np

        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        if tree is None:
            tree = self.tree(pts)
        if tree is not None:
            near = np.asarray(sorted(tree.query_ball_point(pts[asker], self.radius)), dtype=np.int64)
        else:
            near = np.flatnonzero(np.hypot(*(pts - pts[asker]).T) <= self.radius)
        near = near[near != asker]
        if not len(near):
            return []
        pairs = np.stack([np.full(len(near), asker), near], axis=1)
        return near[self._clear(pts, pairs)].tolist()

    def _clear(self, pts: Any, pairs: Any) -> Any:
        """Which candidate pairs' RSSI through the walls between reaches the threshold."""
        import numpy as np

        rssi = self.model.rssi_many(np.hypot(*(pts[pairs[:, 0]] - pts[pairs[:, 1]]).T))
        if self.world is None or not self.wall_db > 0:
            return rssi >= self.threshold_dbm
        # only the pairs' own points: a radio asking alone has a few candidates among many points
        at_a, at_b = pts[pairs[:, 0]], pts[pairs[:, 1]]
        if self.wall_cell:
            c = self.wall_cell
            at_a, at_b = (np.floor(at_a / c) + 0.5) * c, (np.floor(at_b / c) + 0.5) * c
        # a place to the centimetre as one integer (within 10 km: 2e6 cm a side)
        cm_a = np.round(at_a * 100.0).astype(np.int64) + 1_000_000
        cm_b = np.round(at_b * 100.0).astype(np.int64) + 1_000_000
        a, b = cm_a[:, 0] * 4_000_000 + cm_a[:, 1], cm_b[:, 0] * 4_000_000 + cm_b[:, 1]
        low, high = np.minimum(a, b), np.maximum(a, b)
        keys = list(zip(low.tolist(), high.tolist()))
        cache = self._walls
        missing = [k for k, key in enumerate(keys) if key not in cache]
        if missing:
            unknown: dict[tuple, tuple] = {}
            for k in missing:
                if keys[k] not in unknown:
                    unknown[keys[k]] = (at_a[k], at_b[k])
            self.tested += len(unknown)
            counted = walls_along(self.world, [a for a, _ in unknown.values()], [b for _, b in unknown.values()],
                                  z=self.z)
            cache.update(zip(unknown, counted))
        walls = np.fromiter(map(cache.__getitem__, keys), dtype=float, count=len(keys))
        return rssi - walls * self.wall_db >= self.threshold_dbm
