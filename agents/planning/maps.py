"""From the camera's grey label map to the occupancy grid one robot plans on (seed 003 §4).

The image agent draws the scene as a label map (``uint8``, 480 rows × 640 columns):
0 floor, 1 obstacle, 2..5 the robots red, blue, yellow and green. Planning for one
robot takes three steps, each a function here:

1. :func:`binary_map`: occupied = obstacles and every *other* robot; the robot itself
   is free (paper step 3).
2. :func:`configuration_space`: the robots are discs, so the C-space slice is the same
   for every heading and its obstacles are the occupied pixels dilated by the robot
   radius (a disc kernel, :func:`disc_kernel`). Outside the image counts as occupied:
   a robot whose centre is less than a radius from the border would leave the
   camera's view.
3. :func:`cell_grid`: cells of n × n pixels, a cell occupied if any of its pixels is;
   640 × 480 with n = 2 gives the 320 × 240 planning grid.

:func:`planning_grid` chains them. :class:`GridFrame` converts between pixels, cells
and world metres. Arrays are indexed ``[row, column]`` throughout; a cell or pixel is a
``(row, column)`` pair and a world point an ``(x, y)`` pair.

Examples:
    >>> import numpy as np
    >>> label = np.zeros((8, 12), np.uint8)
    >>> label[:, 6] = OBSTACLE              # a wall
    >>> label[2, 2] = ROBOT_LABELS["red"]   # red robot (one pixel here)
    >>> label[5, 9] = ROBOT_LABELS["blue"]
    >>> grid = planning_grid(label, "red", radius_px=1, cell=2, border=False)
    >>> grid.shape
    (4, 6)
    >>> grid.astype(int)
    array([[0, 0, 1, 1, 0, 0],
           [0, 0, 1, 1, 0, 0],
           [0, 0, 1, 1, 1, 1],
           [0, 0, 1, 1, 1, 0]])
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from petriflow.agents.planning.errors import PlanningError

__all__ = [
    "FLOOR",
    "OBSTACLE",
    "ROBOT_LABELS",
    "robot_label",
    "robot_mask",
    "robot_centre",
    "binary_map",
    "disc_kernel",
    "configuration_space",
    "cell_grid",
    "planning_grid",
    "nearest_free",
    "free_cells_near",
    "free_region",
    "draw_disc",
    "segment_free",
    "GridFrame",
]

#: Label of free floor in the label map.
FLOOR = 0
#: Label of a fixed obstacle.
OBSTACLE = 1
#: Labels of the robots, by the colour of their marker (seed 003 §2.4).
ROBOT_LABELS = {"red": 2, "blue": 3, "yellow": 4, "green": 5}


def robot_label(robot: str | int) -> int:
    """The label of a robot given by colour name or by label number.

    Examples:
        >>> robot_label("yellow"), robot_label(3)
        (4, 3)
        >>> robot_label("purple")
        Traceback (most recent call last):
        ...
        petriflow.agents.planning.errors.PlanningError: unknown robot 'purple' (robots: ...)
    """
    if isinstance(robot, str) and robot.lower() in ROBOT_LABELS:
        return ROBOT_LABELS[robot.lower()]
    is_number = isinstance(robot, (int, np.integer)) and not isinstance(robot, bool)
    if is_number and int(robot) in ROBOT_LABELS.values():
        return int(robot)
    raise PlanningError(f"unknown robot {robot!r} (robots: {', '.join(ROBOT_LABELS)} or labels 2..5)")


def robot_mask(label_map: np.ndarray, robot: str | int) -> np.ndarray:
    """Boolean mask of the robot's pixels.

    Examples:
        >>> label = np.array([[0, 2, 2], [0, 3, 1]], np.uint8)
        >>> robot_mask(label, "red").astype(int)
        array([[0, 1, 1],
               [0, 0, 0]])
    """
    return np.asarray(label_map) == robot_label(robot)


def robot_centre(label_map: np.ndarray, robot: str | int) -> tuple[float, float] | None:
    """Centroid ``(row, column)`` of the robot's pixels, or ``None`` if it is not on the map.

    Examples:
        >>> label = np.zeros((5, 5), np.uint8); label[1:3, 2:4] = ROBOT_LABELS["green"]
        >>> robot_centre(label, "green")
        (1.5, 2.5)
        >>> robot_centre(label, "red") is None
        True
    """
    rows, cols = np.nonzero(robot_mask(label_map, robot))
    if rows.size == 0:
        return None
    return float(rows.mean()), float(cols.mean())


def binary_map(label_map: np.ndarray, robot: str | int | None = None) -> np.ndarray:
    """Occupied pixels for one robot: obstacles and all other robots (paper 0 free, 1 occupied).

    Args:
        label_map: the grey label map (0 floor, 1 obstacle, 2..5 robots).
        robot: the robot planning; ``None`` treats every robot as an obstacle.

    Returns:
        A boolean array, ``True`` where occupied.

    Examples:
        >>> label = np.array([[0, 1, 2, 3]], np.uint8)
        >>> binary_map(label, "red").astype(int)
        array([[0, 1, 0, 1]])
        >>> binary_map(label, "blue").astype(int)
        array([[0, 1, 1, 0]])
    """
    label_map = np.asarray(label_map)
    if label_map.ndim != 2:
        raise PlanningError(f"a label map is a 2-D array, got shape {label_map.shape}")
    occupied = label_map != FLOOR
    if robot is not None:
        occupied &= label_map != robot_label(robot)
    return occupied


def disc_kernel(radius_px: float) -> np.ndarray:
    """A disc structuring element: the pixels within ``radius_px`` of the centre pixel.

    Examples:
        >>> disc_kernel(1.5)
        array([[1, 1, 1],
               [1, 1, 1],
               [1, 1, 1]], dtype=uint8)
        >>> disc_kernel(1)
        array([[0, 1, 0],
               [1, 1, 1],
               [0, 1, 0]], dtype=uint8)
    """
    if radius_px < 0:
        raise PlanningError(f"radius must be >= 0, got {radius_px}")
    half = math.floor(radius_px)
    offsets = np.arange(-half, half + 1)
    rows, cols = np.meshgrid(offsets, offsets, indexing="ij")
    return (rows * rows + cols * cols <= radius_px * radius_px + 1e-9).astype(np.uint8)


def configuration_space(occupied: np.ndarray, radius_px: float, border: bool = True) -> np.ndarray:
    """Occupied positions of a disc robot's centre: obstacles dilated by its radius.

    Args:
        occupied: boolean obstacle map (``True`` occupied).
        radius_px: robot radius in pixels (a pixel within this distance of an
            obstacle pixel becomes occupied).
        border: treat everything outside the map as an obstacle too.

    Examples:
        >>> occupied = np.zeros((5, 7), bool); occupied[2, 3] = True
        >>> configuration_space(occupied, 1, border=False).astype(int)
        array([[0, 0, 0, 0, 0, 0, 0],
               [0, 0, 0, 1, 0, 0, 0],
               [0, 0, 1, 1, 1, 0, 0],
               [0, 0, 0, 1, 0, 0, 0],
               [0, 0, 0, 0, 0, 0, 0]])
        >>> configuration_space(np.zeros((3, 4), bool), 1).astype(int)
        array([[1, 1, 1, 1],
               [1, 0, 0, 1],
               [1, 1, 1, 1]])
    """
    import cv2  # heavy dependency, only where dilation happens

    occupied = np.asarray(occupied, dtype=bool)
    kernel = disc_kernel(radius_px)
    half = kernel.shape[0] // 2
    if half == 0:  # a radius under one pixel reaches no other pixel centre
        return occupied.copy()
    # Pad by the kernel's half size so that the border (outside = obstacle, or free)
    # is seen by the dilation exactly like pixels of the map.
    image = cv2.copyMakeBorder(occupied.astype(np.uint8), half, half, half, half, cv2.BORDER_CONSTANT,
                               value=1 if border else 0)
    dilated = cv2.dilate(image, kernel, borderType=cv2.BORDER_CONSTANT, borderValue=0)
    return dilated[half:-half, half:-half].astype(bool)


def cell_grid(occupied: np.ndarray, cell: int) -> np.ndarray:
    """Cell decomposition: ``cell`` × ``cell`` pixels per cell, occupied if any pixel is.

    A map whose size is not a multiple of ``cell`` gets partial cells at its bottom and
    right edges (judged on the pixels they have).

    Examples:
        >>> occupied = np.zeros((4, 6), bool); occupied[3, 0] = True
        >>> cell_grid(occupied, 2).astype(int)
        array([[0, 0, 0],
               [1, 0, 0]])
        >>> cell_grid(np.zeros((480, 640), bool), 2).shape
        (240, 320)
    """
    if cell < 1:
        raise PlanningError(f"cell size must be >= 1 pixel, got {cell}")
    occupied = np.asarray(occupied, dtype=bool)
    if cell == 1:
        return occupied.copy()
    rows, cols = occupied.shape
    pad_rows, pad_cols = (-rows) % cell, (-cols) % cell
    if pad_rows or pad_cols:
        occupied = np.pad(occupied, ((0, pad_rows), (0, pad_cols)), constant_values=False)
    blocks = occupied.reshape(occupied.shape[0] // cell, cell, occupied.shape[1] // cell, cell)
    return blocks.any(axis=(1, 3))


def planning_grid(label_map: np.ndarray, robot: str | int | None, radius_px: float, cell: int = 2,
                  border: bool = True) -> np.ndarray:
    """The whole pipeline: binary map for ``robot``, C-space, cell decomposition.

    Examples:
        >>> planning_grid(np.zeros((480, 640), np.uint8), "red", radius_px=4, cell=2).shape
        (240, 320)
    """
    occupied = binary_map(label_map, robot)
    return cell_grid(configuration_space(occupied, radius_px, border=border), cell)


def free_region(grid: np.ndarray, cell: Sequence[int], cut_corners: bool = False) -> np.ndarray:
    """The free cells the planner can reach from ``cell``: a boolean mask, all ``False``
    when ``cell`` is occupied or off the map.

    The planner's moves decide what is connected: without ``cut_corners`` a diagonal
    step needs both cells it passes between free, so it never joins two cells that
    straight steps do not already join (4-connectivity); with ``cut_corners`` diagonal
    neighbours are joined too (8-connectivity).

    Examples:
        >>> grid = np.zeros((3, 5), bool); grid[:, 2] = True; grid[1, 2] = False
        >>> free_region(grid, (0, 0)).astype(int)
        array([[1, 1, 0, 1, 1],
               [1, 1, 1, 1, 1],
               [1, 1, 0, 1, 1]])
        >>> diagonal = np.array([[0, 1], [1, 0]], bool)
        >>> free_region(diagonal, (0, 0)).sum(), free_region(diagonal, (0, 0), cut_corners=True).sum()
        (np.int64(1), np.int64(2))
    """
    import cv2  # heavy dependency, only where regions are labelled

    grid = np.asarray(grid, dtype=bool)
    row, col = int(cell[0]), int(cell[1])
    if not (0 <= row < grid.shape[0] and 0 <= col < grid.shape[1]) or grid[row, col]:
        return np.zeros(grid.shape, bool)
    _, labels = cv2.connectedComponents((~grid).astype(np.uint8), connectivity=8 if cut_corners else 4)
    return labels == labels[row, col]


def free_cells_near(grid: np.ndarray, cell: Sequence[int], max_distance: float,
                    region: np.ndarray | None = None) -> np.ndarray:
    """The free cells within ``max_distance`` of ``cell`` (Euclidean, in cells), nearest
    first, equally near ones in row-major order: an ``(n, 2)`` array of ``(row, col)``.

    Args:
        grid: the occupancy grid (``True`` occupied).
        cell: ``(row, col)``, on the map or off it.
        max_distance: the farthest a cell may be (cells).
        region: only cells where this mask is ``True`` count (e.g. :func:`free_region`
            of the goal: the cells from which the goal can be reached).

    Examples:
        >>> grid = np.ones((5, 5), bool); grid[4, 4] = False; grid[0, 3] = False
        >>> free_cells_near(grid, (2, 2), 3).tolist()
        [[0, 3], [4, 4]]
        >>> region = np.zeros((5, 5), bool); region[4, 4] = True
        >>> free_cells_near(grid, (2, 2), 3, region).tolist()
        [[4, 4]]
    """
    grid = np.asarray(grid, dtype=bool)
    row, col = int(cell[0]), int(cell[1])
    reach = math.floor(max_distance)
    r0, r1 = max(row - reach, 0), min(row + reach + 1, grid.shape[0])
    c0, c1 = max(col - reach, 0), min(col + reach + 1, grid.shape[1])
    if r0 >= r1 or c0 >= c1:
        return np.zeros((0, 2), np.int64)
    free = ~grid[r0:r1, c0:c1]
    if region is not None:
        free &= np.asarray(region, dtype=bool)[r0:r1, c0:c1]
    rows, cols = np.nonzero(free)  # row-major
    rows, cols = rows + r0, cols + c0
    distance2 = (rows - row) ** 2 + (cols - col) ** 2
    keep = distance2 <= max_distance * max_distance + 1e-9
    order = np.argsort(distance2[keep], kind="stable")  # stable: row-major among equals
    return np.stack([rows[keep][order], cols[keep][order]], axis=1).astype(np.int64)


def nearest_free(grid: np.ndarray, cell: Sequence[int], max_distance: float,
                 region: np.ndarray | None = None) -> tuple[int, int] | None:
    """The free cell nearest to ``cell`` (Euclidean, in cells), or ``None`` if none lies
    within ``max_distance``. Equally near cells are chosen in row-major order; with
    ``region``, only cells where that mask is ``True`` count (:func:`free_cells_near`).

    Examples:
        >>> grid = np.ones((5, 5), bool); grid[4, 4] = False; grid[0, 3] = False
        >>> nearest_free(grid, (2, 2), 3)
        (0, 3)
        >>> nearest_free(grid, (2, 2), 1) is None
        True
    """
    grid = np.asarray(grid, dtype=bool)
    row, col = int(cell[0]), int(cell[1])
    on_map = 0 <= row < grid.shape[0] and 0 <= col < grid.shape[1]
    if on_map and not grid[row, col] and (region is None or region[row, col]):
        return row, col
    cells = free_cells_near(grid, cell, max_distance, region)
    return None if len(cells) == 0 else (int(cells[0][0]), int(cells[0][1]))


def draw_disc(label_map: np.ndarray, centre: Sequence[float], radius_px: float, label: int) -> np.ndarray:
    """A copy of ``label_map`` with a disc of ``label`` drawn at pixel ``centre`` (row, col).

    Used to hold a stopped robot as a fixed obstacle while another re-plans.

    Examples:
        >>> draw_disc(np.zeros((3, 5), np.uint8), (1, 2), 1, OBSTACLE)
        array([[0, 0, 1, 0, 0],
               [0, 1, 1, 1, 0],
               [0, 0, 1, 0, 0]], dtype=uint8)
    """
    result = np.array(label_map, copy=True)
    rows, cols = np.ogrid[: result.shape[0], : result.shape[1]]
    inside = (rows - centre[0]) ** 2 + (cols - centre[1]) ** 2 <= radius_px * radius_px + 1e-9
    result[inside] = label
    return result


def segment_free(grid: np.ndarray, frame: "GridFrame", a: Sequence[float], b: Sequence[float]) -> bool:
    """Whether the straight segment between world points ``a`` and ``b`` crosses only
    free cells of ``grid`` inside the map (sampled every half cell).

    Examples:
        >>> grid = np.zeros((3, 5), bool); grid[:, 2] = True
        >>> frame = GridFrame(1.0, origin=(0.0, 0.0), flip_y=False)
        >>> segment_free(grid, frame, (0, 0), (1, 2)), segment_free(grid, frame, (0, 0), (4, 0))
        (True, False)
    """
    grid = np.asarray(grid, dtype=bool)
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    samples = max(2, math.ceil(2 * float(np.hypot(*(b - a))) / frame.metres_per_cell) + 1)
    points = a + np.linspace(0.0, 1.0, samples)[:, None] * (b - a)
    cells = frame.world_to_cell(points)
    inside = ((cells[:, 0] >= 0) & (cells[:, 0] < grid.shape[0]) & (cells[:, 1] >= 0)
              & (cells[:, 1] < grid.shape[1]))
    if not inside.all():
        return False
    return not grid[cells[:, 0], cells[:, 1]].any()


@dataclass(frozen=True)
class GridFrame:
    """Where the label map lies in the world: pixel ↔ cell ↔ world conversions.

    Pixel ``(row, col)`` has its centre at world
    ``x = origin_x + col * metres_per_pixel`` and
    ``y = origin_y - row * metres_per_pixel`` (image rows run toward −y, as a camera
    looking down on a right-handed world sees it; ``flip_y=False`` makes them run
    toward +y). Cell ``(i, j)`` covers pixel rows ``i*cell .. i*cell + cell - 1`` and
    the same columns; its centre is the centre of that block.

    All conversions take one point or an array of points (last axis of size 2) and
    return float arrays, except the ``*_to_cell`` ones, which return integers.

    Attributes:
        metres_per_pixel: side of a pixel on the floor (m).
        origin: world ``(x, y)`` of the centre of pixel ``(0, 0)``.
        cell: cell side in pixels (n).
        flip_y: image rows run toward −y (default) or +y.

    Examples:
        >>> frame = GridFrame(0.01, origin=(-3.2, 2.4), cell=2)
        >>> frame.pixel_to_world((0, 0)).tolist()
        [-3.2, 2.4]
        >>> frame.world_to_cell((0.0, 0.0)).tolist()
        [120, 160]
        >>> frame.cell_to_world((120, 160)).round(3).tolist()
        [0.005, -0.005]
        >>> frame.world_to_cell([[0.0, 0.0], [-3.2, 2.4]]).tolist()
        [[120, 160], [0, 0]]
        >>> frame.metres_per_cell
        0.02
    """

    metres_per_pixel: float
    origin: tuple[float, float] = (0.0, 0.0)
    cell: int = 1
    flip_y: bool = True

    def __post_init__(self) -> None:
        if not self.metres_per_pixel > 0:
            raise PlanningError(f"metres_per_pixel must be > 0, got {self.metres_per_pixel}")
        if int(self.cell) != self.cell or self.cell < 1:
            raise PlanningError(f"cell must be a whole number of pixels >= 1, got {self.cell}")
        object.__setattr__(self, "origin", (float(self.origin[0]), float(self.origin[1])))

    @property
    def metres_per_cell(self) -> float:
        """Side of a cell on the floor (m)."""
        return self.metres_per_pixel * self.cell

    def with_cell(self, cell: int) -> "GridFrame":
        """The same frame with another cell size."""
        return GridFrame(self.metres_per_pixel, self.origin, cell, self.flip_y)

    def pixel_to_world(self, pixel) -> np.ndarray:
        """World ``(x, y)`` of pixel ``(row, col)`` (fractional pixels allowed)."""
        pixel = np.asarray(pixel, dtype=float)
        sign = -1.0 if self.flip_y else 1.0
        x = self.origin[0] + pixel[..., 1] * self.metres_per_pixel
        y = self.origin[1] + sign * pixel[..., 0] * self.metres_per_pixel
        return np.stack([x, y], axis=-1)

    def world_to_pixel(self, point) -> np.ndarray:
        """Fractional pixel ``(row, col)`` of world point ``(x, y)``."""
        point = np.asarray(point, dtype=float)
        sign = -1.0 if self.flip_y else 1.0
        col = (point[..., 0] - self.origin[0]) / self.metres_per_pixel
        row = sign * (point[..., 1] - self.origin[1]) / self.metres_per_pixel
        return np.stack([row, col], axis=-1)

    def pixel_to_cell(self, pixel) -> np.ndarray:
        """Cell ``(i, j)`` holding pixel ``(row, col)`` (fractional pixels allowed)."""
        pixel = np.asarray(pixel, dtype=float)
        return np.floor((pixel + 0.5) / self.cell).astype(np.int64)

    def cell_to_pixel(self, cell) -> np.ndarray:
        """Fractional pixel ``(row, col)`` of the centre of cell ``(i, j)``."""
        cell = np.asarray(cell, dtype=float)
        return cell * self.cell + (self.cell - 1) / 2.0

    def world_to_cell(self, point) -> np.ndarray:
        """Cell ``(i, j)`` holding world point ``(x, y)``."""
        return self.pixel_to_cell(self.world_to_pixel(point))

    def cell_to_world(self, cell) -> np.ndarray:
        """World ``(x, y)`` of the centre of cell ``(i, j)``."""
        return self.pixel_to_world(self.cell_to_pixel(cell))


def grid_edges(grid: np.ndarray, *, diagonal_cost: float = math.sqrt(2.0),
               cut_corners: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The free cells of ``grid`` as an 8-connected directed graph, as edge arrays.

    The planner's rules: straight moves cost 1, diagonal ones ``diagonal_cost``, and a
    diagonal move needs both cells it passes between free unless ``cut_corners``. Cell
    ``(r, c)`` is node ``r * cols + c``; feed the arrays to
    ``scipy.sparse.csr_matrix`` for an exact shortest-path reference.

    Returns:
        ``(sources, targets, costs)``.

    Examples:
        >>> sources, targets, costs = grid_edges(np.zeros((2, 2), bool))
        >>> len(sources), sorted(set(np.round(costs, 3).tolist()))
        (12, [1.0, 1.414])
    """
    rows, cols = grid.shape
    free = ~np.asarray(grid, bool)
    index = np.arange(rows * cols).reshape(rows, cols)
    sources, targets, costs = [], [], []
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            if dr == 0 and dc == 0:
                continue
            r0, r1 = max(0, -dr), rows - max(0, dr)
            c0, c1 = max(0, -dc), cols - max(0, dc)
            ok = free[r0:r1, c0:c1] & free[r0 + dr:r1 + dr, c0 + dc:c1 + dc]
            if dr and dc and not cut_corners:
                ok &= free[r0 + dr:r1 + dr, c0:c1] & free[r0:r1, c0 + dc:c1 + dc]
            sources.append(index[r0:r1, c0:c1][ok])
            targets.append(index[r0 + dr:r1 + dr, c0 + dc:c1 + dc][ok])
            costs.append(np.full(int(ok.sum()), diagonal_cost if dr and dc else 1.0))
    return np.concatenate(sources), np.concatenate(targets), np.concatenate(costs)
