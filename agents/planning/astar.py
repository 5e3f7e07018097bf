"""A* on an 8-connected occupancy grid, as in seed 003 §4.1, with a compiled inner loop.

The search keeps every cell in one of three lists, as the paper does: *null* (never
reached), *open* (reached, waiting to be expanded) and *closed* (expanded; never
reopened). It expands the open cell of least ``f = g + h``; among equal ``f`` the one
nearer the target (smaller ``h``: the paper's "toward the direction of the target
node"), then the smaller row-major index, so the result never depends on the order
of the heap. A cell already open keeps the smaller ``g``. (The paper's own "closed
list" is the current path and its "null list" the dead ends; both are cells that are
never re-expanded, which is what closed means here.)

Two variants, chosen per call:

``"optimal"`` (default; the one a scenario should use)
    A straight step costs 1 and a diagonal step √2, ``h`` is the octile distance
    (exact on an empty grid, consistent), so the path is a shortest 8-connected path:
    its cost equals Dijkstra's.
``"paper"``
    The paper's costs: ``g`` counts the cells travelled (a diagonal step costs 1) and
    ``h`` is the Euclidean distance. On diagonals ``h`` can overestimate (√2 for one
    step), so the path need not have the fewest steps; ``h = √2 · (Euclidean / √2)``
    with ``Euclidean / √2`` consistent for unit steps makes it weighted A* with
    ε = √2, whose path has at most √2 times the fewest possible steps. On open floors
    it expands several times fewer cells (on mazes about as many), and its paths hug
    the straight line to the target.

Diagonal steps do not cut corners by default: a diagonal move needs both cells it
passes between to be free (``cut_corners=True`` allows it, as pyastar2d does).

The loop runs compiled by numba when numba is installed (compiled once, cached on
disk); without numba the same code runs as plain Python, with the same results but
about 200 times slower, seconds on a 320 × 240 maze (:data:`COMPILED` says which).

Examples:
    >>> import numpy as np
    >>> grid = np.zeros((5, 7), bool)
    >>> grid[1:4, 3] = True                      # a short wall
    >>> plan = astar(grid, (2, 0), (2, 6))
    >>> plan.found, plan.steps, round(plan.cost, 3)
    (True, 6, 7.657)
    >>> plan.cells[[0, -1]].tolist()
    [[2, 0], [2, 6]]
    >>> astar(grid, (2, 0), (2, 6), variant="paper").steps
    6
    >>> walled = np.zeros((3, 3), bool); walled[:, 1] = True
    >>> astar(walled, (0, 0), (0, 2)).found
    False
"""

from __future__ import annotations

import math
import threading
import time
import warnings
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from petriflow.agents.planning.errors import PlanningError

__all__ = ["astar", "Plan", "VARIANTS", "COMPILED", "warm_up", "path_steps"]

#: The selectable cost models (see the module documentation).
VARIANTS = ("optimal", "paper")

try:  # numba is what makes A* fast enough (< 30 ms on 320 × 240); without it, same code
    import numba

    # numba's on-disk cache is keyed by source file but re-imports the module by name
    # when it loads; a second import name of this file (pytest --doctest-modules on
    # agents/ imports it as agents.planning.astar) would load a cache it cannot use,
    # so only the installed name caches.
    _cache = __name__ == "petriflow.agents.planning.astar"
    _jit = numba.njit(cache=_cache, nogil=True)
    _jit_inline = numba.njit(cache=_cache, nogil=True, inline="always")
    COMPILED = True
except ImportError:  # pragma: no cover - exercised only where numba is missing
    def _jit(function):
        return function

    _jit_inline = _jit

    COMPILED = False

_SQRT2 = math.sqrt(2.0)

_NULL, _OPEN, _CLOSED = 0, 1, 2


@dataclass(frozen=True)
class Plan:
    """The answer of :func:`astar`.

    Attributes:
        found: whether a path exists.
        cells: the path as ``(row, col)`` cells from start to goal (shape ``(k, 2)``;
            empty when not found).
        variant: the cost model searched (``"optimal"`` or ``"paper"``).
        steps: moves along the path (cells travelled, the paper's ``g``).
        diagonal: how many of those moves are diagonal.
        expanded: cells closed by the search.
        visited: cells ever put on the open list.
        seconds: wall-clock time of the search (not of the input checks; the first
            search in a process also pays numba's compile or cache load).
    """

    found: bool
    cells: np.ndarray
    variant: str
    steps: int
    diagonal: int
    expanded: int
    visited: int
    seconds: float = field(default=0.0, compare=False)

    @property
    def length(self) -> float:
        """Euclidean length of the path in cells (√2 per diagonal move); ``inf`` if none."""
        if not self.found:
            return math.inf
        return (self.steps - self.diagonal) + _SQRT2 * self.diagonal

    @property
    def cost(self) -> float:
        """The path's cost in the variant's own metric: :attr:`length` for
        ``"optimal"``, :attr:`steps` for ``"paper"``; ``inf`` if no path."""
        if not self.found:
            return math.inf
        return self.length if self.variant == "optimal" else float(self.steps)


def path_steps(cells: np.ndarray) -> tuple[int, int]:
    """Moves and diagonal moves of an 8-connected cell path.

    Examples:
        >>> path_steps(np.array([[0, 0], [1, 1], [1, 2]]))
        (2, 1)
    """
    cells = np.asarray(cells)
    if len(cells) < 2:
        return 0, 0
    delta = np.abs(np.diff(cells, axis=0))
    return len(delta), int(np.count_nonzero((delta[:, 0] == 1) & (delta[:, 1] == 1)))


# --- the compiled search ----------------------------------------------------------------
# The open list is a binary heap whose entries carry their keys (f, h, cell) side by
# side, so comparisons read neighbouring memory; ``position[cell]`` finds an open cell's
# entry when a smaller g lowers its f. Helpers are inlined into the search loop.
@_jit_inline
def _before(f_a, h_a, a, f_b, h_b, b):
    """Whether entry a is expanded before entry b: smaller f, then h, then cell index."""
    if f_a != f_b:
        return f_a < f_b
    if h_a != h_b:
        return h_a < h_b
    return a < b


@_jit_inline
def _sift_up(heap_f, heap_h, heap_cell, position, index):
    f, h, cell = heap_f[index], heap_h[index], heap_cell[index]
    while index > 0:
        parent = (index - 1) >> 1
        if not _before(f, h, cell, heap_f[parent], heap_h[parent], heap_cell[parent]):
            break
        heap_f[index], heap_h[index], heap_cell[index] = heap_f[parent], heap_h[parent], heap_cell[parent]
        position[heap_cell[index]] = index
        index = parent
    heap_f[index], heap_h[index], heap_cell[index] = f, h, cell
    position[cell] = index


@_jit_inline
def _sift_down(heap_f, heap_h, heap_cell, position, index, size):
    f, h, cell = heap_f[index], heap_h[index], heap_cell[index]
    while True:
        child = 2 * index + 1
        if child >= size:
            break
        right = child + 1
        if right < size and _before(heap_f[right], heap_h[right], heap_cell[right],
                                    heap_f[child], heap_h[child], heap_cell[child]):
            child = right
        if not _before(heap_f[child], heap_h[child], heap_cell[child], f, h, cell):
            break
        heap_f[index], heap_h[index], heap_cell[index] = heap_f[child], heap_h[child], heap_cell[child]
        position[heap_cell[index]] = index
        index = child
    heap_f[index], heap_h[index], heap_cell[index] = f, h, cell
    position[cell] = index


@_jit_inline
def _octile_parts(row, col, goal_row, goal_col):
    """The octile distance as (straight moves, diagonal moves)."""
    dr = abs(goal_row - row)
    dc = abs(goal_col - col)
    small = min(dr, dc)
    return max(dr, dc) - small, small


@_jit
def _search(occupied, cols, start, goal, paper, cut_corners, state, parent, straight, diagonal, position,
            heap_f, heap_h, heap_cell):
    """A* over ``occupied``: the flattened grid (uint8, nonzero occupied) framed by a
    one-cell border of occupied cells, ``cols`` wide, so no move needs a bounds check.
    ``start`` and ``goal`` are flat indices. The work arrays (one entry per cell) are
    the caller's, reused between calls; only ``state`` must come zeroed."""
    goal_row = goal // cols
    goal_col = goal - goal_row * cols
    # the 8-neighbourhood: four straight moves, then four diagonal ones
    offsets = (-cols, cols, -1, 1, -cols - 1, -cols + 1, cols - 1, cols + 1)
    d_rows = (-1, 1, 0, 0, -1, -1, 1, 1)
    d_cols = (0, 0, -1, 1, -1, 1, -1, 1)
    straight[start] = 0
    diagonal[start] = 0
    parent[start] = -1
    state[start] = _OPEN
    start_row = start // cols
    start_col = start - start_row * cols
    if paper:
        h0 = math.sqrt((goal_row - start_row) ** 2 + (goal_col - start_col) ** 2)
    else:
        hs, hd = _octile_parts(start_row, start_col, goal_row, goal_col)
        h0 = hs + _SQRT2 * hd
    heap_f[0], heap_h[0], heap_cell[0] = h0, h0, start
    position[start] = 0
    size = 1
    visited = 1
    expanded = 0
    found = False

    while size > 0:
        node = heap_cell[0]
        size -= 1
        if size > 0:
            heap_f[0], heap_h[0], heap_cell[0] = heap_f[size], heap_h[size], heap_cell[size]
            _sift_down(heap_f, heap_h, heap_cell, position, 0, size)
        state[node] = _CLOSED
        expanded += 1
        if node == goal:
            found = True
            break
        row = node // cols
        col = node - row * cols
        for k in range(8):
            child = node + offsets[k]
            if occupied[child]:
                continue
            is_diagonal = k >= 4
            if is_diagonal and not cut_corners and (
                    occupied[node + d_cols[k]] or occupied[node + d_rows[k] * cols]):
                continue
            seen = state[child]
            if seen == _CLOSED:
                continue
            s = straight[node]
            d = diagonal[node]
            if is_diagonal:
                d += 1
            else:
                s += 1
            if seen == _OPEN:  # keep the entry with the smaller g
                if paper:
                    better = s + d < straight[child] + diagonal[child]
                else:
                    better = s + _SQRT2 * d < straight[child] + _SQRT2 * diagonal[child]
                if not better:
                    continue
            straight[child] = s
            diagonal[child] = d
            parent[child] = node
            r = row + d_rows[k]
            c = col + d_cols[k]
            # f is rebuilt from integers every time, so equal f values are bit-identical
            # and the tie-break toward the target sees every real tie.
            if paper:
                h = math.sqrt((goal_row - r) ** 2 + (goal_col - c) ** 2)
                f = (s + d) + h
            else:
                hs, hd = _octile_parts(r, c, goal_row, goal_col)
                h = hs + _SQRT2 * hd
                f = (s + hs) + _SQRT2 * (d + hd)
            if seen == _NULL:
                state[child] = _OPEN
                index = size
                size += 1
                visited += 1
                heap_h[index] = h
                heap_cell[index] = child
            else:
                index = position[child]
            heap_f[index] = f
            _sift_up(heap_f, heap_h, heap_cell, position, index)

    if not found:
        return False, expanded, visited, np.empty((0, 2), np.int64)
    length = 1
    node = goal
    while parent[node] >= 0:
        node = parent[node]
        length += 1
    path = np.empty((length, 2), np.int64)
    node = goal
    for i in range(length - 1, -1, -1):
        path[i, 0] = node // cols - 1  # back to unframed (row, col)
        path[i, 1] = node % cols - 1
        node = parent[node]
    return True, expanded, visited, path


class _Workspace(threading.local):
    """Work arrays reused between searches on grids of the same size (per thread).

    Fresh large arrays cost a page fault on every first touch; reusing them keeps a
    320 × 240 search from paying that each call.
    """

    def __init__(self) -> None:
        self.cells = -1
        self.arrays: tuple[np.ndarray, ...] = ()

    def get(self, cells: int) -> tuple[np.ndarray, ...]:
        if cells != self.cells:
            self.cells = cells
            self.arrays = (
                np.zeros(cells, np.int8),     # state: null, open, closed
                np.empty(cells, np.int32),    # parent
                np.empty(cells, np.int32),    # straight moves from the start
                np.empty(cells, np.int32),    # diagonal moves from the start
                np.empty(cells, np.int32),    # position in the heap
                np.empty(cells, np.float64),  # heap: f
                np.empty(cells, np.float64),  # heap: h
                np.empty(cells, np.int32),    # heap: cell
            )
        else:
            self.arrays[0].fill(0)
        return self.arrays


_workspace = _Workspace()


# --- the public function ----------------------------------------------------------------
def _check_cell(grid: np.ndarray, cell: Sequence[int], what: str) -> tuple[int, int]:
    try:
        row, col = (int(v) for v in cell)
    except (TypeError, ValueError):
        raise PlanningError(f"{what} must be a (row, col) cell, got {cell!r}") from None
    if not (0 <= row < grid.shape[0] and 0 <= col < grid.shape[1]):
        raise PlanningError(f"{what} {(row, col)} lies outside the {grid.shape[0]}x{grid.shape[1]} grid")
    if grid[row, col]:
        raise PlanningError(f"{what} {(row, col)} is inside an obstacle")
    return row, col


def astar(grid: np.ndarray, start: Sequence[int], goal: Sequence[int], *, variant: str = "optimal",
          cut_corners: bool = False) -> Plan:
    """Plan a path of cells from ``start`` to ``goal`` on an occupancy grid.

    Args:
        grid: 2-D occupancy grid, nonzero (``True``) where occupied; indexed
            ``[row, col]``.
        start: ``(row, col)`` of the start cell.
        goal: ``(row, col)`` of the goal cell.
        variant: ``"optimal"`` (shortest path, √2 diagonals, octile h) or ``"paper"``
            (cells travelled, Euclidean h, as in seed 003).
        cut_corners: allow a diagonal move between two occupied cells.

    Returns:
        A :class:`Plan`; ``plan.found`` is ``False`` (and ``plan.cells`` empty) when no
        path exists.

    Raises:
        PlanningError: start or goal outside the grid or inside an obstacle, an unknown
            variant, a grid that is not 2-D.

    Examples:
        >>> grid = np.zeros((3, 4), bool)
        >>> astar(grid, (0, 0), (2, 3)).cells.tolist()
        [[0, 0], [1, 1], [2, 2], [2, 3]]
        >>> astar(grid, (1, 1), (1, 1)).cells.tolist()
        [[1, 1]]
        >>> grid[0, 0] = True
        >>> astar(grid, (0, 0), (2, 3))
        Traceback (most recent call last):
        ...
        petriflow.agents.planning.errors.PlanningError: start (0, 0) is inside an obstacle
    """
    if variant not in VARIANTS:
        raise PlanningError(f"unknown A* variant {variant!r} (variants: {', '.join(VARIANTS)})")
    grid = np.asarray(grid)
    if grid.ndim != 2 or grid.size == 0:
        raise PlanningError(f"the grid must be a non-empty 2-D array, got shape {grid.shape}")
    occupied = grid != 0
    start_cell = _check_cell(occupied, start, "start")
    goal_cell = _check_cell(occupied, goal, "goal")
    framed = np.ones((occupied.shape[0] + 2, occupied.shape[1] + 2), np.uint8)
    framed[1:-1, 1:-1] = occupied
    cols = framed.shape[1]
    work = _workspace.get(framed.size)
    began = time.perf_counter()
    start_index = (start_cell[0] + 1) * cols + start_cell[1] + 1
    goal_index = (goal_cell[0] + 1) * cols + goal_cell[1] + 1
    found, expanded, visited, cells = _search(framed.ravel(), cols, start_index, goal_index,
                                              variant == "paper", bool(cut_corners), *work)
    seconds = time.perf_counter() - began
    steps, diagonal = path_steps(cells)
    return Plan(bool(found), cells, variant, steps, diagonal, int(expanded), int(visited), seconds)


def warm_up() -> float:
    """Compile (or load from numba's cache) the search for both variants; seconds taken.

    Examples:
        >>> warm_up() >= 0.0
        True
    """
    began = time.perf_counter()
    grid = np.zeros((4, 4), bool)
    for variant in VARIANTS:
        astar(grid, (0, 0), (3, 3), variant=variant)
    return time.perf_counter() - began


if not COMPILED:  # pragma: no cover
    warnings.warn("numba is not installed: petriflow.agents.planning.astar runs as plain Python "
                  "(correct but slow); pip install numba", RuntimeWarning, stacklevel=2)
