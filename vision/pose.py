"""A robot's pose from its two marker discs, in pixels and in world metres (seed 003, §2.4).

Each robot carries a black and a white disc inside its colour patch
(:mod:`petriflow.vision.markers`); in the label image they are holes of the colour
blob. The robot's position is the midpoint of the two disc centroids; its heading is
the segment joining them turned by 90°:

    heading = direction(black → white) + 90° (counter-clockwise seen from above),

so, looking along the heading, the black disc is on the left and the white disc on
the right. Angles are radians in (-pi, pi], counter-clockwise from +x. In pixels the
same rule is applied with the image's row axis flipped (rows grow downwards), so
``heading_px`` is the on-screen angle from the image's +column axis, counter-clockwise;
for a top-down camera whose ``up`` is +y it equals the world heading.

Pixel coordinates are ``(column, row)`` array indices of pixel centres (``frame[row,
column]``). Pixels map to world points on a horizontal plane (the discs' top faces,
``z = marker_z``) through :class:`GroundPlane`, the plane's exact homography built from
:meth:`petriflow.world.Camera.project`.

Examples:
    >>> heading_from_discs((0.0, 1.0), (0.0, -1.0))      # black at +y, white at -y: facing +x
    0.0
    >>> round(heading_from_discs((-1.0, 0.0), (1.0, 0.0)), 4)  # black at -x: facing +y
    1.5708
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

import cv2
import numpy as np

from petriflow.vision.segment import FLOOR, OBSTACLE, Blob

__all__ = [
    "TINY_RENDERER_OFFSET",
    "GroundPlane",
    "Discs",
    "RobotPose",
    "find_discs",
    "heading_from_discs",
    "robot_pose",
]

#: Where pixel ``(column, row)`` of a pybullet TinyRenderer frame lies in
#: :meth:`petriflow.world.Camera.project` coordinates: ``(column + 0, row + 1)``.
#: Measured on rendered frames (centroids of squares at known positions, 320 x 240
#: to 640 x 480): TinyRenderer samples pixel centres at whole coordinates counted from
#: the image's bottom, so rows are off by one against ``project``'s top-down
#: ``(1 - y) / 2 * height``.
TINY_RENDERER_OFFSET = (0.0, 1.0)


def _homography(source: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The 3 x 3 projective map taking 4 source points to 4 target points (float64)."""
    rows, rhs = [], []
    for (x, y), (u, v) in zip(source, target):
        rows.append([x, y, 1, 0, 0, 0, -u * x, -u * y])
        rows.append([0, 0, 0, x, y, 1, -v * x, -v * y])
        rhs += [u, v]
    h = np.linalg.solve(np.array(rows, np.float64), np.array(rhs, np.float64))
    return np.append(h, 1.0).reshape(3, 3)


class GroundPlane:
    """Exact pixel ↔ world mapping of the plane ``z = height`` seen by a camera.

    A pinhole camera maps a plane to the image by a homography; four points projected
    with :meth:`petriflow.world.Camera.project` determine it, so both directions are
    exact (to rounding) for any camera pose that sees the plane.

    Args:
        camera: a :class:`petriflow.world.Camera` (anything with ``project``,
            ``target``, ``width`` and ``height``).
        height: the plane's ``z`` (m); for marker discs, their top faces.
        offset: :data:`TINY_RENDERER_OFFSET`, pixel index → ``project`` coordinates.

    Examples:
        >>> from petriflow.world import World
        >>> world = World({"plane": False, "cameras": [
        ...     {"id": "top", "position": [0, 0, 3], "target": [0, 0, 0], "up": [0, 1, 0]}]})
        >>> plane = GroundPlane(world.camera("top"), height=0.1)
        >>> col, row = plane.to_pixel(0.5, -0.25)
        >>> [round(float(v), 6) for v in plane.to_world(col, row)]
        [0.5, -0.25]
        >>> world.close()
    """

    def __init__(self, camera: Any, height: float = 0.0,
                 offset: Sequence[float] = TINY_RENDERER_OFFSET) -> None:
        self.height = float(height)
        self.offset = (float(offset[0]), float(offset[1]))
        cx, cy = float(camera.target[0]), float(camera.target[1])
        world = np.array([[cx - 1, cy - 1], [cx + 1, cy - 1], [cx + 1, cy + 1], [cx - 1, cy + 1]], np.float64)
        pixels = np.array([camera.project(x, y, self.height) for x, y in world], np.float64)
        pixels -= self.offset
        self.to_pixel_matrix = _homography(world, pixels)
        self.to_world_matrix = np.linalg.inv(self.to_pixel_matrix)
        self.size = (int(camera.width), int(camera.height))
        #: :meth:`grid_frame`, computed once.
        self.grid = self.grid_frame()

    def grid_frame(self, tolerance: float = 1e-6) -> tuple[float, tuple[float, float]] | None:
        """``(metres_per_pixel, origin)`` if the image is this plane scaled, else ``None``.

        That holds for a camera looking straight down with ``up`` = +y: world
        ``x = origin_x + column * metres_per_pixel`` and
        ``y = origin_y - row * metres_per_pixel``, ``origin`` being the world point of
        the centre of pixel ``(0, 0)`` (what ``planning.astar`` reads from a scene).

        Examples:
            >>> from petriflow.world import World
            >>> world = World({"plane": False, "cameras": [
            ...     {"id": "top", "position": [0, 0, 3], "target": [0, 0, 0], "up": [0, 1, 0]}]})
            >>> scale, origin = GroundPlane(world.camera("top")).grid_frame()
            >>> round(scale * 480, 4), [round(v, 3) for v in origin]
            (3.4641, [-2.309, 1.725])
            >>> world.close()
        """
        m = self.to_world_matrix / self.to_world_matrix[2, 2]
        scale = m[0, 0]
        if not scale > 0:
            return None
        projective = abs(m[2, 0]) + abs(m[2, 1])
        rotated = abs(m[0, 1]) + abs(m[1, 0])
        if projective + rotated + abs(m[1, 1] + scale) >= tolerance * scale:
            return None
        return float(scale), (float(m[0, 2]), float(m[1, 2]))

    @staticmethod
    def _apply(matrix: np.ndarray, a: Any, b: Any) -> tuple[Any, Any]:
        if isinstance(a, (int, float)) and isinstance(b, (int, float)):
            (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = matrix.tolist()
            w = m20 * a + m21 * b + m22
            return (m00 * a + m01 * b + m02) / w, (m10 * a + m11 * b + m12) / w
        a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
        w = matrix[2, 0] * a + matrix[2, 1] * b + matrix[2, 2]
        return ((matrix[0, 0] * a + matrix[0, 1] * b + matrix[0, 2]) / w,
                (matrix[1, 0] * a + matrix[1, 1] * b + matrix[1, 2]) / w)

    def to_world(self, column: Any, row: Any) -> tuple[Any, Any]:
        """World ``(x, y)`` on the plane of pixel ``(column, row)`` (floats or arrays)."""
        return self._apply(self.to_world_matrix, column, row)

    def to_pixel(self, x: Any, y: Any) -> tuple[Any, Any]:
        """Pixel ``(column, row)`` of world point ``(x, y, height)`` (floats or arrays)."""
        return self._apply(self.to_pixel_matrix, x, y)


@dataclass(frozen=True)
class Discs:
    """The two marker discs found in a robot's blob (pixel centroids, areas in pixels)."""

    black: tuple[float, float]
    white: tuple[float, float]
    black_area: int
    white_area: int


def _largest_centroid(mask: np.ndarray, min_area: int) -> tuple[tuple[float, float], int] | None:
    count, _, stats, centroids = cv2.connectedComponentsWithStats(mask, connectivity=8)
    if count <= 1:
        return None
    best = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    area = int(stats[best, cv2.CC_STAT_AREA])
    if area < min_area:
        return None
    return (float(centroids[best][0]), float(centroids[best][1])), area


def find_discs(labels: np.ndarray, blob: Blob, min_area: int = 3) -> Discs | None:
    """The black and the white disc inside a robot's blob, or ``None`` if one is missing.

    The discs are the blob's holes (:attr:`Blob.holes`): black pixels (label 1) in
    them form the black disc, floor-labelled pixels (label 0, white) the white one;
    of each, the largest 8-connected part counts, with its centroid.

    Examples:
        >>> from petriflow.vision.segment import find_blobs
        >>> labels = np.zeros((12, 12), np.uint8)
        >>> labels[1:11, 1:11] = 3
        >>> labels[3:6, 3:6] = 1                 # black disc
        >>> labels[3:6, 7:9] = 0                 # white disc
        >>> find_discs(labels, find_blobs(labels, 3)[0])
        Discs(black=(4.0, 4.0), white=(7.5, 4.0), black_area=9, white_area=6)
    """
    if not blob.holes:
        return None
    x, y, w, h = blob.bbox
    roi = labels[y:y + h, x:x + w]
    holes = np.zeros((h, w), np.uint8)
    cv2.drawContours(holes, list(blob.holes), -1, 255, thickness=cv2.FILLED, offset=(-x, -y))
    found = []
    for value in (OBSTACLE, FLOOR):
        mask = cv2.bitwise_and(holes, cv2.compare(roi, value, cv2.CMP_EQ))
        disc = _largest_centroid(mask, min_area)
        if disc is None:
            return None
        found.append(((disc[0][0] + x, disc[0][1] + y), disc[1]))
    (black, black_area), (white, white_area) = found
    return Discs(black, white, black_area, white_area)


def heading_from_discs(black: Sequence[float], white: Sequence[float]) -> float:
    """Heading (rad) of a robot from its disc centres in a frame with y up.

    The black → white direction turned by +90°: ``atan2(dx, -dy)`` with
    ``(dx, dy) = white - black``.

    Examples:
        >>> round(math.degrees(heading_from_discs((1.0, 0.0), (-1.0, 0.0))), 1)   # facing -y
        -90.0
    """
    dx, dy = white[0] - black[0], white[1] - black[1]
    return math.atan2(dx, -dy) + 0.0


@dataclass(frozen=True)
class RobotPose:
    """Where one robot is.

    Attributes:
        colour: its colour name.
        label: its label in the grey map (2..5).
        pixel: ``(column, row)`` of the midpoint of its discs.
        heading_px: on-screen heading (rad, counter-clockwise from the +column axis).
        position: world ``(x, y)`` on the marker plane (m); ``None`` without a camera.
        heading: world heading (rad, counter-clockwise from +x); ``None`` without a camera.
        discs: the discs it was computed from.
        area: pixels of its colour blob.
    """

    colour: str
    label: int
    pixel: tuple[float, float]
    heading_px: float
    position: tuple[float, float] | None
    heading: float | None
    discs: Discs
    area: float

    def to_token(self) -> dict[str, Any]:
        """A JSON-able summary (metres and radians to 4 decimals, pixels to 2).

        Examples:
            >>> pose = RobotPose("red", 2, (10.0, 20.0), 0.5, (1.23456, -0.5), 0.5,
            ...                  Discs((10.0, 15.0), (10.0, 25.0), 9, 9), 400.0)
            >>> pose.to_token()
            {'x': 1.2346, 'y': -0.5, 'heading': 0.5, 'u': 10.0, 'v': 20.0, 'heading_px': 0.5}
        """
        return {
            "x": None if self.position is None else round(self.position[0], 4),
            "y": None if self.position is None else round(self.position[1], 4),
            "heading": None if self.heading is None else round(self.heading, 4),
            "u": round(self.pixel[0], 2),
            "v": round(self.pixel[1], 2),
            "heading_px": round(self.heading_px, 4),
        }


def robot_pose(colour: str, label: int, discs: Discs, area: float = 0.0,
               plane: GroundPlane | None = None) -> RobotPose:
    """A robot's pose from its discs; in world units too when the marker ``plane`` is given.

    Examples:
        >>> pose = robot_pose("blue", 3, Discs((10.0, 5.0), (10.0, 15.0), 9, 9))
        >>> pose.pixel, pose.heading_px, pose.position
        ((10.0, 10.0), 0.0, None)
    """
    (bc, br), (wc, wr) = discs.black, discs.white
    pixel = ((bc + wc) / 2, (br + wr) / 2)
    heading_px = heading_from_discs((bc, -br), (wc, -wr))
    position = heading = None
    if plane is not None:
        black = plane.to_world(bc, br)
        white = plane.to_world(wc, wr)
        position = ((black[0] + white[0]) / 2, (black[1] + white[1]) / 2)
        heading = heading_from_discs(black, white)
    return RobotPose(colour, label, pixel, heading_px, position, heading, discs, float(area))
