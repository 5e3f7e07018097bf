"""Path tracking and correction (seed 003 §4.2): is the robot still on its path?

After every move the robot's distance ``dc`` to its planned path (a polyline of world
points) decides what it does next:

* ``dc < dmin`` (``dmin``: the length of one standard move): on track, keep going;
* ``dmin ≤ dc ≤ r`` (``r``: the robot's radius): *reinsertion*: head for the path
  point farthest along the path among those reachable in one move (within the
  search radius ``reach``, the longest move the robot can make, and, if a map is
  given, in straight line of sight), so the return to the path also makes progress
  toward the goal (the paper's Fig. 14b);
* ``dc > r``: stop and plan again.

:func:`check_track` is the pure decision; :class:`PathTracker` keeps one robot's path
and how far along it the robot has come.

Examples:
    >>> path = densify([(0.0, 0.0), (1.0, 0.0)], spacing=0.02)
    >>> check_track(path, (0.5, 0.01), step=0.05, radius=0.12).kind
    <Track.ON_TRACK: 'on_track'>
    >>> decision = check_track(path, (0.5, 0.07), step=0.05, radius=0.12, reach=0.1)
    >>> decision.kind.value, [round(v, 3) for v in decision.point]
    ('reinsert', [0.56, 0.0])
    >>> check_track(path, (0.5, 0.3), step=0.05, radius=0.12).kind.value
    'replan'
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from petriflow.agents.planning.errors import PlanningError

__all__ = ["Track", "TrackDecision", "distance_to_path", "reinsertion_index", "check_track", "PathTracker",
           "densify"]

#: ``line_free(a, b) -> bool``: whether the straight move from world point a to b is free.
LineFree = Callable[[Sequence[float], Sequence[float]], bool]


class Track(str, enum.Enum):
    """What path correction tells the robot to do after a move."""

    ON_TRACK = "on_track"
    REINSERT = "reinsert"
    REPLAN = "replan"


@dataclass(frozen=True)
class TrackDecision:
    """The verdict of :func:`check_track`.

    Attributes:
        kind: on track, reinsert, or re-plan.
        distance: ``dc``, the distance from the robot to the path (m).
        nearest: index of the path segment nearest to the robot (segment ``i`` joins
            points ``i`` and ``i + 1``).
        point: where to head to rejoin the path (``REINSERT`` only).
        index: index of that point in the path, or of the segment whose foot point
            it is when no path point is reachable (``REINSERT`` only).
    """

    kind: Track
    distance: float
    nearest: int
    point: tuple[float, float] | None = None
    index: int | None = None


def _as_path(path: Sequence[Sequence[float]]) -> np.ndarray:
    points = np.asarray(path, dtype=float)
    if points.ndim != 2 or points.shape[1] != 2 or len(points) == 0:
        raise PlanningError(f"a path is a non-empty list of [x, y] points, got shape {points.shape}")
    return points


def distance_to_path(path: Sequence[Sequence[float]],
                     position: Sequence[float]) -> tuple[float, int, np.ndarray]:
    """Distance from ``position`` to the polyline ``path``, the nearest segment's index
    (the first of equally near ones) and the nearest point on it.

    Examples:
        >>> distance, segment, foot = distance_to_path([(0, 0), (1, 0), (1, 1)], (1.2, 0.5))
        >>> round(distance, 3), segment, foot.tolist()
        (0.2, 1, [1.0, 0.5])
        >>> distance_to_path([(2, 2)], (2, 3))[0]
        1.0
    """
    points = _as_path(path)
    p = np.asarray(position, dtype=float)[:2]
    if len(points) == 1:
        return float(np.hypot(*(p - points[0]))), 0, points[0].copy()
    a, b = points[:-1], points[1:]
    ab = b - a
    length2 = np.einsum("ij,ij->i", ab, ab)
    t = np.where(length2 > 0, np.einsum("ij,ij->i", p - a, ab) / np.where(length2 > 0, length2, 1.0), 0.0)
    t = np.clip(t, 0.0, 1.0)
    feet = a + t[:, None] * ab
    distances = np.hypot(*(p - feet).T)
    nearest = int(np.argmin(distances))
    return float(distances[nearest]), nearest, feet[nearest]


def reinsertion_index(path: Sequence[Sequence[float]], position: Sequence[float], reach: float,
                      first: int = 0, line_free: LineFree | None = None) -> int | None:
    """Index of the path point farthest along the path among those within ``reach`` of
    ``position`` (and in line of sight, if ``line_free`` is given), from index ``first``
    on; ``None`` if there is none.

    Examples:
        >>> path = [(x / 10, 0.0) for x in range(11)]
        >>> reinsertion_index(path, (0.3, 0.05), reach=0.16)
        4
        >>> reinsertion_index(path, (0.3, 0.5), reach=0.16) is None
        True
    """
    points = _as_path(path)
    p = np.asarray(position, dtype=float)[:2]
    within = np.hypot(*(points[first:] - p).T) <= reach + 1e-12
    for index in (first + np.nonzero(within)[0])[::-1]:
        if line_free is None or line_free(tuple(p), tuple(points[index])):
            return int(index)
    return None


def check_track(path: Sequence[Sequence[float]], position: Sequence[float], *, step: float, radius: float,
                reach: float | None = None, line_free: LineFree | None = None) -> TrackDecision:
    """Path correction after one move (seed 003 §4.2).

    Args:
        path: the planned path, world ``[x, y]`` points from start to goal.
        position: the robot's position ``(x, y)`` (extra items such as a heading are
            ignored).
        step: ``dmin``, the length of one standard move (m).
        radius: ``r``, the robot's radius (m); farther than this from the path, re-plan.
        reach: the longest move the robot can make (the reinsertion search radius);
            default two standard moves. When the path is farther than that, the
            search radius grows to ``dc`` (the robot needs more than one move).
        line_free: optional check that a straight move is collision-free (see
            :func:`petriflow.agents.planning.maps.segment_free`); a reinsertion point
            behind an obstacle is never chosen.

    Returns:
        A :class:`TrackDecision`.

    Examples:
        A sparse path offers no point within reach; the robot heads for the foot of
        the perpendicular instead:

        >>> decision = check_track([(0.0, 0.0), (1.0, 0.0)], (0.2, 0.06), step=0.05, radius=0.1)
        >>> decision.kind.value, decision.point, decision.index
        ('reinsert', (0.2, 0.0), 0)
    """
    if step <= 0 or radius <= 0:
        raise PlanningError(f"step and radius must be > 0, got step={step}, radius={radius}")
    points = _as_path(path)
    distance, nearest, foot = distance_to_path(points, position)
    if distance < step:
        return TrackDecision(Track.ON_TRACK, distance, nearest)
    if distance > radius:
        return TrackDecision(Track.REPLAN, distance, nearest)
    search = max(2.0 * step if reach is None else reach, distance)
    index = reinsertion_index(points, position, search, first=nearest + 1, line_free=line_free)
    if index is None:  # no path point reachable: rejoin at the foot of the perpendicular
        return TrackDecision(Track.REINSERT, distance, nearest, (float(foot[0]), float(foot[1])), nearest)
    point = (float(points[index][0]), float(points[index][1]))
    return TrackDecision(Track.REINSERT, distance, nearest, point, index)


def densify(path: Sequence[Sequence[float]], spacing: float) -> np.ndarray:
    """The path with extra points so that consecutive points are at most ``spacing`` apart
    (reinsertion chooses among path points, so a sparse path gets few choices).

    Examples:
        >>> densify([(0, 0), (1, 0)], 0.3).tolist()
        [[0.0, 0.0], [0.25, 0.0], [0.5, 0.0], [0.75, 0.0], [1.0, 0.0]]
    """
    points = _as_path(path)
    if spacing <= 0:
        raise PlanningError(f"spacing must be > 0, got {spacing}")
    out = [points[:1]]
    for a, b in zip(points[:-1], points[1:]):
        pieces = max(1, math.ceil(float(np.hypot(*(b - a))) / spacing))
        out.append(a + np.arange(1, pieces + 1)[:, None] / pieces * (b - a))
    return np.concatenate(out)


class PathTracker:
    """One robot's path and its progress along it; :meth:`check` after every move.

    Args:
        path: the planned path (world ``[x, y]`` points).
        step: length of one standard move, ``dmin`` (m).
        radius: the robot's radius, ``r`` (m).
        reach: the longest single move (default two standard moves).
        line_free: optional straight-move collision check.

    Attributes:
        path: the path being followed (``(k, 2)`` array).
        progress: index of the farthest path segment the robot has been on.
        last: the last decision.

    Examples:
        >>> tracker = PathTracker([(0, 0), (1, 0)], step=0.05, radius=0.1)
        >>> tracker.check((0.3, 0.0)).kind.value, tracker.check((0.4, 0.07)).kind.value
        ('on_track', 'reinsert')
        >>> tracker.check((0.4, 0.5)).kind.value
        'replan'
        >>> tracker.replace([(0.4, 0.5), (1, 0)]); tracker.check((0.4, 0.5)).kind.value
        'on_track'
    """

    def __init__(self, path: Sequence[Sequence[float]], step: float, radius: float,
                 reach: float | None = None, line_free: LineFree | None = None) -> None:
        self.step, self.radius, self.reach, self.line_free = step, radius, reach, line_free
        self.path = _as_path(path)
        self.progress = 0
        self.last: TrackDecision | None = None

    def replace(self, path: Sequence[Sequence[float]]) -> None:
        """Follow a new path (after a re-plan), from its start."""
        self.path = _as_path(path)
        self.progress = 0
        self.last = None

    def check(self, position: Sequence[float]) -> TrackDecision:
        """Decide after a move; on track, the progress moves to the nearest segment."""
        decision = check_track(self.path, position, step=self.step, radius=self.radius, reach=self.reach,
                               line_free=self.line_free)
        if decision.kind is Track.ON_TRACK:
            self.progress = max(self.progress, decision.nearest)
        elif decision.kind is Track.REINSERT and decision.index is not None:
            self.progress = max(self.progress, min(decision.index, len(self.path) - 2))
        self.last = decision
        return decision

    def remaining(self) -> np.ndarray:
        """The path points not yet passed."""
        return self.path[self.progress + 1:]
