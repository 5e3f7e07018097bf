"""Going somewhere in a known floor plan: an A* path on a free-space grid, cut down to
the corners a robot has to turn at.

:class:`Navigator` holds a boolean grid (``True`` = a robot's centre may be there: the
floor minus the obstacles grown by the robot's radius) and where it lies in the world
(``origin`` = world ``(x, y)`` of cell ``(0, 0)``'s south-west corner, rows along +y,
``resolution`` metres per cell). :meth:`Navigator.route` plans with
:func:`petriflow.agents.planning.astar.astar` (shortest 8-connected path, no corner
cutting) and keeps only the points where the straight line of sight ends
(string pulling), so a robot drives a few straight legs.

Examples:
    >>> import numpy as np
    >>> free = np.ones((10, 10), bool); free[:8, 5] = False   # a wall with a gap at the top
    >>> nav = Navigator(free, origin=(0.0, 0.0), resolution=1.0)
    >>> [tuple(round(v, 1) for v in p) for p in nav.route((1.5, 1.5), (8.5, 1.5))]
    [(4.5, 8.5), (7.5, 7.5), (8.5, 1.5)]
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from petriflow.agents.planning.astar import astar
from petriflow.agents.planning.maps import nearest_free

__all__ = ["Navigator"]


class Navigator:
    """Routes on a free-space grid (see the module)."""

    def __init__(self, free: np.ndarray, origin: Sequence[float], resolution: float) -> None:
        self.free = np.asarray(free, dtype=bool)
        self.blocked = ~self.free
        self.origin = (float(origin[0]), float(origin[1]))
        self.resolution = float(resolution)

    def cell(self, point: Sequence[float]) -> tuple[int, int]:
        return (int(math.floor((point[1] - self.origin[1]) / self.resolution)),
                int(math.floor((point[0] - self.origin[0]) / self.resolution)))

    def centre(self, cell: Sequence[int]) -> tuple[float, float]:
        return (self.origin[0] + (int(cell[1]) + 0.5) * self.resolution,
                self.origin[1] + (int(cell[0]) + 0.5) * self.resolution)

    def _free_cell(self, point: Sequence[float]) -> tuple[int, int] | None:
        row, col = self.cell(point)
        return nearest_free(self.blocked, (row, col), 2.0 / self.resolution)

    def clear(self, a: Sequence[float], b: Sequence[float]) -> bool:
        """Whether the straight segment ``a``-``b`` stays on free cells."""
        length = math.dist(a[:2], b[:2])
        samples = max(2, math.ceil(3 * length / self.resolution) + 1)
        t = np.linspace(0.0, 1.0, samples)
        xs = a[0] + t * (b[0] - a[0])
        ys = a[1] + t * (b[1] - a[1])
        rows = np.floor((ys - self.origin[1]) / self.resolution).astype(int)
        cols = np.floor((xs - self.origin[0]) / self.resolution).astype(int)
        inside = (rows >= 0) & (rows < self.free.shape[0]) & (cols >= 0) & (cols < self.free.shape[1])
        return bool(inside.all() and self.free[rows, cols].all())

    def around(self, discs: Sequence[tuple[float, float, float]]) -> "Navigator":
        """A navigator on the same grid with discs ``(x, y, radius)`` blocked too
        (robots standing in the way), e.g. to plan a detour."""
        free = self.free.copy()
        rows, cols = np.ogrid[: free.shape[0], : free.shape[1]]
        for x, y, radius in discs:
            cx = (x - self.origin[0]) / self.resolution - 0.5
            cy = (y - self.origin[1]) / self.resolution - 0.5
            r = radius / self.resolution
            free[(rows - cy) ** 2 + (cols - cx) ** 2 <= r * r] = False
        return Navigator(free, self.origin, self.resolution)

    def route(self, start: Sequence[float], goal: Sequence[float]) -> list[tuple[float, float]] | None:
        """Points to drive through from ``start`` to ``goal`` (the goal last), or
        ``None`` when no path exists. A start or goal inside an obstacle's margin is
        moved to the nearest free cell (within 2 m)."""
        if self.clear(start, goal):
            return [(float(goal[0]), float(goal[1]))]
        a, b = self._free_cell(start), self._free_cell(goal)
        if a is None or b is None:
            return None
        plan = astar(self.blocked, a, b)
        if not plan.found:
            return None
        points = [self.centre(c) for c in plan.cells]
        if self._inside(goal) and self.free[self.cell(goal)]:
            points[-1] = (float(goal[0]), float(goal[1]))
        legs: list[tuple[float, float]] = []
        here = (float(start[0]), float(start[1]))
        i = 0
        while i < len(points) - 1:
            j = len(points) - 1
            while j > i + 1 and not self.clear(here, points[j]):
                j -= 1
            legs.append(points[j])
            here = points[j]
            i = j
        if not legs or legs[-1] != points[-1]:
            legs.append(points[-1])
        return legs

    def _inside(self, point: Sequence[float]) -> bool:
        row, col = self.cell(point)
        return 0 <= row < self.free.shape[0] and 0 <= col < self.free.shape[1]
