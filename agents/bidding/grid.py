"""The interface agent's global occupancy grid and the map accuracy of eq. 10 (seed 004).

Every robot sends the world points its laser returned (eq. 7-8,
:mod:`~petriflow.agents.bidding.laser`) to the human/machine interface agent, which
marks the cells they fall in on one global grid (:class:`GlobalMap`), remembering
which robot marked each cell first: the colours of the paper's Fig. 8-10.

A :class:`Grid` is the frame: ``shape = (rows, cols)`` square cells of side
``resolution`` m, cell ``(0, 0)`` with its south-west corner at ``origin``; rows grow
with y, columns with x. Used as a map it carries a bool ``occupied`` array of that
shape (:meth:`petriflow.agents.bidding.office.Office.truth` is one).

**Accuracy** (§4, eq. 10)::

    Accuracy = (1 - ξ / σ) × 100

with ``σ`` the size of the real obstacles and environment limits the team detected and
``ξ`` the size of the fictitious ones, "obstacles that do not exist in the real
worlds" (§4.3: the teammates the lasers saw). Sizes are counts of cells. Two readings:

* :func:`fictitious` (the mission's ``accuracy_pct``): by what the beams hit: a cell
  is real once a return off a wall or a piece of furniture fell in it, fictitious when
  only returns off teammates did. A wall drawn off its place because a robot was not
  where its odometry said is a real wall perceived.
* :func:`accuracy` (``fit_pct``): against the ground truth: an occupied map cell
  within ``tolerance_cells`` (Chebyshev distance) of an occupied ground-truth cell
  counts in ``σ``, any other in ``ξ``. The tolerance absorbs a hit on a wall's face
  falling in the cell beside the wall's rasterised outline; a wall drawn more than a
  cell off its place counts as fictitious. ``coverage``, the fraction of the truth's
  cells with a map cell within the tolerance, says how much of the building was mapped,
  which eq. 10 alone does not.

With exact localisation the two agree but for teammates seen beside a wall.

Examples:
    >>> frame = Grid(origin=(0.0, 0.0), resolution=1.0, shape=(3, 4))
    >>> rows, cols = frame.cell_of([(0.5, 0.5), (3.9, 2.1), (9.0, 0.0)])
    >>> rows.tolist(), cols.tolist()
    ([0, 2], [0, 3])
    >>> team = GlobalMap(frame)
    >>> team.add(0, [(0.5, 0.5), (1.5, 0.5)]), team.add(1, [(1.5, 0.5), (2.5, 0.5)])
    (2, 1)
    >>> team.owner[0].tolist()
    [0, 0, 1, -1]
    >>> truth = np.zeros((3, 4), bool); truth[0, :3] = True
    >>> accuracy(team.occupied, truth)
    Accuracy(sigma=3, xi=0, percent=100.0, coverage=1.0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from numbers import Real
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from petriflow.agents.bidding.errors import BiddingError

if TYPE_CHECKING:  # pragma: no cover - for annotations only
    from petriflow.agents.bidding.office import Office

__all__ = ["Grid", "GlobalMap", "Accuracy", "dilate", "accuracy", "fictitious", "draw_map"]


@dataclass
class Grid:
    """A frame of ``shape = (rows, cols)`` square cells of side ``resolution`` m, the
    south-west corner of cell ``(0, 0)`` at ``origin``; ``occupied`` (bool, ``shape``)
    when it is a map.

    Examples:
        >>> frame = Grid((-1.0, -1.0), 0.5, (4, 4))
        >>> frame.centre(0, 3)
        (0.75, -0.75)
        >>> frame.extent
        (-1.0, 1.0, -1.0, 1.0)
    """

    origin: tuple[float, float]
    resolution: float
    shape: tuple[int, int]
    occupied: np.ndarray | None = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        if isinstance(self.resolution, bool) or not isinstance(self.resolution, Real) \
                or not (math.isfinite(self.resolution) and self.resolution > 0):
            raise BiddingError(f"a grid's resolution must be > 0 m, got {self.resolution!r}")
        if len(self.shape) != 2 or any(int(n) != n or n < 1 for n in self.shape):
            raise BiddingError(f"a grid's shape is (rows, cols) >= 1, got {self.shape!r}")
        self.origin = (float(self.origin[0]), float(self.origin[1]))
        self.resolution = float(self.resolution)
        self.shape = (int(self.shape[0]), int(self.shape[1]))
        if self.occupied is not None and np.shape(self.occupied) != self.shape:
            raise BiddingError(f"occupied has shape {np.shape(self.occupied)}, the grid {self.shape}")

    @classmethod
    def spanning(cls, xmin: float, ymin: float, xmax: float, ymax: float, resolution: float) -> Grid:
        """The smallest grid with its corner at ``(xmin, ymin)`` covering the rectangle.

        Examples:
            >>> Grid.spanning(-16, -11, 16, 11, 0.1).shape
            (220, 320)
        """
        if not (resolution > 0 and xmax > xmin and ymax > ymin):
            raise BiddingError(f"cannot grid [{xmin}, {xmax}] x [{ymin}, {ymax}] at {resolution} m")
        cells = [max(1, math.ceil(extent / resolution - 1e-9)) for extent in (ymax - ymin, xmax - xmin)]
        return cls((xmin, ymin), resolution, (cells[0], cells[1]))

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """``(xmin, xmax, ymin, ymax)`` of the grid (matplotlib's ``imshow`` extent)."""
        x0, y0 = self.origin
        return (x0, x0 + self.shape[1] * self.resolution, y0, y0 + self.shape[0] * self.resolution)

    def empty(self) -> np.ndarray:
        """A bool array of the grid's shape, all False."""
        return np.zeros(self.shape, dtype=bool)

    def cell_of(self, points: Any) -> tuple[np.ndarray, np.ndarray]:
        """``(rows, cols)`` index arrays of the cells holding ``points`` (``(k, 2)``, x and
        y); points outside the grid (or not finite) are dropped."""
        xy = _xy(points)
        cols = np.floor((xy[:, 0] - self.origin[0]) / self.resolution)
        rows = np.floor((xy[:, 1] - self.origin[1]) / self.resolution)
        keep = (rows >= 0) & (rows < self.shape[0]) & (cols >= 0) & (cols < self.shape[1])  # NaN: False
        return rows[keep].astype(np.intp), cols[keep].astype(np.intp)

    def centre(self, row: Any, col: Any) -> tuple[Any, Any]:
        """World ``(x, y)`` of a cell's centre (numbers, or arrays for arrays)."""
        x = self.origin[0] + (np.asarray(col) + 0.5) * self.resolution
        y = self.origin[1] + (np.asarray(row) + 0.5) * self.resolution
        if x.ndim == 0:
            return (float(x), float(y))
        return (x, y)


def _xy(points: Any) -> np.ndarray:
    array = np.asarray(points, dtype=float)
    if array.size == 0:
        return array.reshape(0, 2)
    if array.ndim != 2 or array.shape[1] != 2:
        raise BiddingError(f"points are an array of (x, y) rows, got shape {array.shape}")
    return array


class GlobalMap:
    """The interface agent's occupancy grid over ``frame``: which cells some robot's
    laser hit, and which robot hit each first (``owner``, -1 for none)."""

    def __init__(self, frame: Grid) -> None:
        self.frame = Grid(frame.origin, frame.resolution, frame.shape)
        self._occupied = np.zeros(frame.shape, dtype=bool)
        self._real = np.zeros(frame.shape, dtype=bool)
        self._owner = np.full(frame.shape, -1, dtype=np.int32)

    def add(self, robot_index: int, points: Any, real: Any = None) -> int:
        """Mark the cells of ``points`` (``(k, 2)`` world x, y) as seen by robot
        ``robot_index`` (from 0); returns how many of them were not marked before.

        ``real`` (one bool per point; default all True) says which points are returns
        off a real obstacle and which off a teammate (a fictitious one): a cell is real
        once a real return fell in it (:func:`fictitious`)."""
        if isinstance(robot_index, bool) or not isinstance(robot_index, (int, np.integer)) or robot_index < 0:
            raise BiddingError(f"a robot index is an integer >= 0, got {robot_index!r}")
        rows, cols = self.frame.cell_of(points)
        cells = rows * self.frame.shape[1] + cols
        flat = np.unique(cells)
        occupied, owner = self._occupied.reshape(-1), self._owner.reshape(-1)
        new = flat[~occupied[flat]]
        occupied[new] = True
        owner[new] = robot_index
        if real is None:
            self._real.reshape(-1)[flat] = True
        else:
            labels = np.asarray(real, dtype=bool).reshape(-1)
            if labels.size != _xy(points).shape[0]:
                raise BiddingError(f"{labels.size} labels for {_xy(points).shape[0]} points")
            # cell_of dropped the points outside the frame: keep their labels in step
            self._real.reshape(-1)[cells[labels[self._inside(points)]]] = True
        return int(new.size)

    def _inside(self, points: Any) -> np.ndarray:
        """Which points fall inside the frame (the ones :meth:`Grid.cell_of` keeps)."""
        xy = _xy(points)
        x0, y0 = self.frame.origin
        col = np.floor((xy[:, 0] - x0) / self.frame.resolution)
        row = np.floor((xy[:, 1] - y0) / self.frame.resolution)
        return (row >= 0) & (row < self.frame.shape[0]) & (col >= 0) & (col < self.frame.shape[1])

    @property
    def real(self) -> np.ndarray:
        """Cells some return off a real obstacle fell in (read-only view)."""
        view = self._real.view()
        view.flags.writeable = False
        return view

    @property
    def occupied(self) -> np.ndarray:
        """The occupied cells (a read-only view, shape ``frame.shape``)."""
        view = self._occupied.view()
        view.flags.writeable = False
        return view

    @property
    def owner(self) -> np.ndarray:
        """The robot that marked each cell first, -1 where none did (read-only view)."""
        view = self._owner.view()
        view.flags.writeable = False
        return view

    def count(self, robot_index: int | None = None) -> int:
        """Occupied cells, all or those robot ``robot_index`` marked first."""
        if robot_index is None:
            return int(self._occupied.sum())
        return int((self._owner == robot_index).sum())


@dataclass(frozen=True)
class Accuracy:
    """Eq. 10 of a map: ``sigma`` real cells detected, ``xi`` fictitious cells,
    ``percent`` = (1 - xi / sigma) x 100, and ``coverage``, the fraction of the truth's
    cells the map found (within the tolerance)."""

    sigma: int
    xi: int
    percent: float
    coverage: float


def dilate(mask: Any, radius: int) -> np.ndarray:
    """Every cell within Chebyshev distance ``radius`` of a True cell (a square max
    filter, done as two passes of shifted ORs: no scipy).

    Examples:
        >>> dilate(np.eye(1, 5, 2, dtype=bool), 1).astype(int).tolist()
        [[0, 1, 1, 1, 0]]
    """
    out = np.asarray(mask, dtype=bool).copy()
    if radius < 0 or int(radius) != radius:
        raise BiddingError(f"a dilation radius is a whole number of cells >= 0, got {radius!r}")
    for axis in range(out.ndim):
        source = out.copy()
        moved = np.moveaxis(out, axis, 0)
        src = np.moveaxis(source, axis, 0)
        for shift in range(1, min(int(radius), moved.shape[0] - 1) + 1):
            moved[shift:] |= src[:-shift]
            moved[:-shift] |= src[shift:]
    return out


def fictitious(global_map: GlobalMap) -> Accuracy:
    """Eq. 10 by what the beams hit: ``sigma`` the map cells some return off a real
    obstacle or wall fell in, ``xi`` the cells only returns off teammates fell in (the
    paper's "fictive obstacles ... that do not exist in the real worlds", §4.3);
    ``percent`` = (1 - xi / sigma) x 100 (clipped at 0; 100.0 for an empty map);
    ``coverage`` is not known here (nan). A wall drawn off its place because the robot
    was not where it believed (odometry) is still a real wall perceived.

    Examples:
        >>> team = GlobalMap(Grid((0.0, 0.0), 1.0, (2, 4)))
        >>> team.add(0, [(0.5, 0.5), (1.5, 0.5), (2.5, 0.5), (3.5, 1.5)], real=[True, True, True, False])
        4
        >>> score = fictitious(team)
        >>> score.sigma, score.xi, round(score.percent, 2)
        (3, 1, 66.67)
    """
    occupied = np.asarray(global_map.occupied)
    real = np.asarray(global_map.real) & occupied
    sigma = int(np.count_nonzero(real))
    xi = int(np.count_nonzero(occupied & ~real))
    if sigma == 0:
        percent = 100.0 if xi == 0 else 0.0
    else:
        percent = max(0.0, (1.0 - xi / sigma) * 100.0)
    return Accuracy(sigma, xi, percent, float("nan"))


def accuracy(map_occupied: Any, truth_occupied: Any, tolerance_cells: int = 1) -> Accuracy:
    """Eq. 10 of an occupancy map against the ground truth (same shape).

    ``sigma``: map cells within ``tolerance_cells`` (Chebyshev) of a truth cell; ``xi``:
    the other map cells; ``percent``: ``(1 - xi / sigma) * 100``, clipped at 0 below,
    100.0 for an empty map and 0.0 for one with only fictitious cells; ``coverage``:
    truth cells with a map cell within the tolerance, over all truth cells (1.0 when the
    truth is empty).

    Examples:
        >>> truth = np.zeros((5, 12), bool); truth[2, :10] = True
        >>> seen = truth.copy(); seen[4, 11] = True   # 10 real cells and a robot
        >>> accuracy(seen, truth)
        Accuracy(sigma=10, xi=1, percent=90.0, coverage=1.0)
    """
    seen = np.asarray(map_occupied, dtype=bool)
    truth = np.asarray(truth_occupied, dtype=bool)
    if seen.shape != truth.shape:
        raise BiddingError(f"the map has shape {seen.shape} and the truth {truth.shape}")
    near_truth = dilate(truth, tolerance_cells)
    sigma = int(np.count_nonzero(seen & near_truth))
    xi = int(np.count_nonzero(seen & ~near_truth))
    if sigma == 0:
        percent = 100.0 if xi == 0 else 0.0
    else:
        percent = max(0.0, (1.0 - xi / sigma) * 100.0)
    total = int(np.count_nonzero(truth))
    found = int(np.count_nonzero(truth & dilate(seen, tolerance_cells)))
    return Accuracy(sigma, xi, percent, found / total if total else 1.0)


def draw_map(global_map: GlobalMap, path: str | Path, *, office: Office | None = None,
             title: str | None = None) -> None:
    """A PNG of the map's occupied cells, each in the colour of the robot that marked it
    first (the robot colours of :func:`petriflow.agents.bidding.office.robot_colour`),
    over the office's walls and furniture drawn faintly if ``office`` is given."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from petriflow.agents.bidding.office import draw_boxes, robot_colour

    frame = global_map.frame
    owner = global_map.owner
    image = np.zeros(frame.shape + (4,))
    robots = sorted(int(r) for r in np.unique(owner) if r >= 0)
    for robot in robots:
        image[owner == robot] = robot_colour(robot)
    x0, x1, y0, y1 = frame.extent
    width = 10.0
    figure, axis = plt.subplots(figsize=(width, max(2.5, width * (y1 - y0) / (x1 - x0) + 0.6)))
    if office is not None:
        draw_boxes(axis, office, alpha=0.25)
    axis.imshow(image, origin="lower", extent=frame.extent, interpolation="nearest", zorder=2)
    for robot in robots:
        axis.scatter([], [], s=30, marker="s", color=robot_colour(robot),
                     label=f"robot{robot + 1}: {global_map.count(robot)} cells")
    axis.set_xlim(x0 - 0.5, x1 + 0.5)
    axis.set_ylim(y0 - 0.5, y1 + 0.5)
    axis.set_aspect("equal")
    axis.set_xlabel("x (m)")
    axis.set_ylabel("y (m)")
    axis.set_title(title or f"global map: {global_map.count()} occupied cells of {frame.resolution:g} m")
    if robots:
        axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
