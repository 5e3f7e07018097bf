"""Colour segmentation of an overhead frame into the SMART label map (seed 003, §2.4).

Steps, each a function:

1. :func:`to_hsv`: RGB → HSV (OpenCV's 8-bit scale: H in 0..179, S and V in 0..255).
   Hue separates the robots' colours whatever the shading of a face, which only moves
   V (the paper's reason for HSV).
2. :func:`label_pixels`: each pixel gets a label by the HSV :data:`DEFAULT_THRESHOLDS`
   table: ``0`` floor (white, and anything unclassified), ``1`` black, ``2..5`` the
   robots' colours in the order red, blue, yellow, green.
3. :func:`mode_filter`: the 3 x 3 (8-neighbourhood plus centre) mode of the labels,
   which removes loose pixels.
4. :func:`find_blobs`: contours of one label (``cv2.findContours``), outer borders with
   their holes: a robot's black and white discs are holes in its colour blob.
5. :func:`obstacle_mask`: black pixels that are not inside a robot (so a robot's black
   disc is not an obstacle), and :func:`grey_map`: the label map redrawn with the
   obstacles and each robot as a square of side ``L`` (:func:`draw_robot_square`).

Thresholds were measured on pybullet TinyRenderer frames under its default lighting,
with the colours of :data:`petriflow.world.COLOURS` (``bench/vision.py`` renders such
scenes): every face of a robot, lit or in shade, keeps one hue (red 0, yellow 26,
green 65, blue 116) with S 221..230 and V 114..227; black bodies have V 3..4, the
white floor V 239 and white discs (cylinders, smoothly shaded) V 153..251, both with
S 0. The default ranges leave wide margins around these values.

Examples:
    >>> import numpy as np
    >>> frame = np.full((6, 8, 3), 239, np.uint8)       # white floor
    >>> frame[1:5, 1:4] = (215, 23, 23)                 # a red patch
    >>> frame[2:4, 5:7] = (4, 4, 4)                     # a black patch
    >>> label_pixels(to_hsv(frame))
    array([[0, 0, 0, 0, 0, 0, 0, 0],
           [0, 2, 2, 2, 0, 0, 0, 0],
           [0, 2, 2, 2, 0, 1, 1, 0],
           [0, 2, 2, 2, 0, 1, 1, 0],
           [0, 2, 2, 2, 0, 0, 0, 0],
           [0, 0, 0, 0, 0, 0, 0, 0]], dtype=uint8)
"""

from __future__ import annotations

import functools
import math
import sys
from dataclasses import dataclass
from typing import Mapping, Sequence

import cv2
import numpy as np

from petriflow.vision.markers import ROBOT_COLOURS

__all__ = [
    "FLOOR",
    "OBSTACLE",
    "DEFAULT_THRESHOLDS",
    "robot_label",
    "to_hsv",
    "colour_mask",
    "label_pixels",
    "ColourTable",
    "colour_table",
    "mode_filter",
    "Blob",
    "find_blobs",
    "colour_regions",
    "obstacle_mask",
    "obstacle_boxes",
    "draw_robot_square",
    "square_corners",
    "grey_map",
    "to_grey",
]

FLOOR = 0
"""Label of the floor (white) and of anything no threshold claims."""
OBSTACLE = 1
"""Label of black pixels (obstacles, and the robots' black discs before they are told apart)."""

#: HSV ranges per class: ``{name: ((lo_hsv, hi_hsv), ...)}``, inclusive, OpenCV scale
#: (H 0..179). Red wraps around H = 0, so it has two ranges. ``black`` gives label 1;
#: ``white`` documents what the floor and white discs look like (they keep label 0).
DEFAULT_THRESHOLDS: Mapping[str, tuple[tuple[tuple[int, int, int], tuple[int, int, int]], ...]] = {
    "red": (((0, 120, 70), (10, 255, 255)), ((170, 120, 70), (179, 255, 255))),
    "blue": (((100, 120, 70), (130, 255, 255)),),
    "yellow": (((18, 120, 70), (35, 255, 255)),),
    "green": (((45, 120, 70), (85, 255, 255)),),
    "black": (((0, 0, 0), (179, 255, 60)),),
    "white": (((0, 0, 120), (179, 60, 255)),),
}


def robot_label(colour: str, colours: Sequence[str] = ROBOT_COLOURS) -> int:
    """The label of a robot colour in the grey map (2 for the first colour).

    Examples:
        >>> [robot_label(c) for c in ("red", "blue", "yellow", "green")]
        [2, 3, 4, 5]
    """
    return 2 + list(colours).index(colour)


def to_hsv(frame: np.ndarray) -> np.ndarray:
    """RGB (H x W x 3, uint8) → HSV in OpenCV's 8-bit scale.

    Examples:
        >>> to_hsv(np.array([[[215, 23, 23], [23, 47, 215]]], np.uint8)).tolist()
        [[[0, 228, 215], [116, 228, 215]]]
    """
    return cv2.cvtColor(frame, cv2.COLOR_RGB2HSV)


def colour_mask(hsv: np.ndarray, ranges: Sequence) -> np.ndarray:
    """255 where a pixel lies in any of the ``(lo, hi)`` HSV ranges, else 0.

    Examples:
        >>> hsv = np.array([[[0, 200, 200], [175, 200, 200], [60, 200, 200]]], np.uint8)
        >>> colour_mask(hsv, DEFAULT_THRESHOLDS["red"]).tolist()
        [[255, 255, 0]]
    """
    mask = None
    for lo, hi in ranges:
        part = cv2.inRange(hsv, np.array(lo, np.uint8), np.array(hi, np.uint8))
        mask = part if mask is None else cv2.bitwise_or(mask, part)
    if mask is None:
        return np.zeros(hsv.shape[:2], np.uint8)
    return mask


def label_pixels(hsv: np.ndarray, thresholds: Mapping = DEFAULT_THRESHOLDS,
                 colours: Sequence[str] = ROBOT_COLOURS) -> np.ndarray:
    """Per-pixel labels: 0 floor, 1 black, ``2 + i`` for ``colours[i]`` (uint8).

    Where ranges overlap the higher label wins (a colour over black).
    """
    labels = cv2.bitwise_and(colour_mask(hsv, thresholds["black"]), OBSTACLE)
    for i, colour in enumerate(colours):
        value = 2 + i
        labels = cv2.max(labels, cv2.bitwise_and(colour_mask(hsv, thresholds[colour]), value))
    return labels


def _key(thresholds: Mapping) -> tuple:
    return tuple(sorted((str(name), tuple((tuple(int(v) for v in lo), tuple(int(v) for v in hi))
                                          for lo, hi in ranges))
                        for name, ranges in thresholds.items()))


class ColourTable:
    """The HSV thresholds compiled into a lookup table over all 2^24 RGB colours.

    :func:`label_pixels` after :func:`to_hsv` costs two passes of colour arithmetic
    per frame; the table runs that same computation once for every possible RGB
    colour (cv2's RGB→HSV, then the thresholds) and stores the label, so classifying
    a frame is one lookup per pixel, giving exactly the labels of the explicit path.
    Building takes about a second and 16 MiB; :func:`colour_table` keeps one per
    thresholds table.

    Args:
        thresholds: the HSV ranges (:data:`DEFAULT_THRESHOLDS`).
        colours: robot colours in label order.

    Examples:
        >>> table = colour_table()
        >>> frame = np.array([[[239, 239, 239], [4, 4, 4], [23, 179, 47]]], np.uint8)
        >>> table(frame)
        array([[0, 1, 5]], dtype=uint8)
        >>> bool((table(frame) == label_pixels(to_hsv(frame))).all())
        True
    """

    def __init__(self, thresholds: Mapping = DEFAULT_THRESHOLDS,
                 colours: Sequence[str] = ROBOT_COLOURS) -> None:
        self.colours = tuple(colours)
        # Pixel i of the build image holds the colour whose bytes, read the way
        # __call__ reads a frame (as a native uint32), give the index i.
        table = np.empty(1 << 24, np.uint8)
        chunk = 1 << 20
        for start in range(0, 1 << 24, chunk):
            index = np.arange(start, start + chunk, dtype=np.uint32)
            rgb = np.ascontiguousarray(index.view(np.uint8).reshape(-1, 4)[:, self._rgb_bytes])
            table[start:start + chunk] = label_pixels(to_hsv(rgb.reshape(1024, 1024, 3)), thresholds,
                                                      colours).ravel()
        self.table = table

    #: Which bytes of a native uint32 hold R, G, B when an RGBA pixel is read as one.
    _rgb_bytes = [0, 1, 2] if sys.byteorder == "little" else [1, 2, 3]
    _mask = 0x00FFFFFF if sys.byteorder == "little" else 0xFFFFFF00

    def __call__(self, frame: np.ndarray) -> np.ndarray:
        """Labels of an RGB frame (H x W x 3, uint8): same as ``label_pixels(to_hsv(frame))``."""
        rgba = cv2.cvtColor(frame, cv2.COLOR_RGB2RGBA)
        index = rgba.view(np.uint32).reshape(frame.shape[:2])
        np.bitwise_and(index, self._mask, out=index)
        if sys.byteorder != "little":
            np.right_shift(index, 8, out=index)
        return np.take(self.table, index)


@functools.lru_cache(maxsize=4)
def _cached_table(key: tuple, colours: tuple[str, ...]) -> ColourTable:
    thresholds = {name: ranges for name, ranges in key}
    return ColourTable(thresholds, colours)


def colour_table(thresholds: Mapping = DEFAULT_THRESHOLDS,
                 colours: Sequence[str] = ROBOT_COLOURS) -> ColourTable:
    """The :class:`ColourTable` of ``thresholds``, built once and then reused."""
    return _cached_table(_key(thresholds), tuple(colours))


_SQUARE = np.ones((3, 3), np.uint8)


def mode_filter(labels: np.ndarray) -> np.ndarray:
    """Replace each label by the most frequent label of its 3 x 3 neighbourhood.

    This is the paper's non-linear mode filter over the 8-neighbourhood (the pixel and
    its 8 neighbours, the border replicated): a loose pixel, a one-pixel spur or a
    one-pixel line takes its surroundings' label; a blob keeps its straight edges (six
    of the nine pixels there are inside) and loses the tip of each convex corner.
    Ties (e.g. 4-4-1) keep the centre's label if it is among the most frequent, else
    the lowest such label.

    How, fast: nearly every 3 x 3 window holds at most one label besides the floor.
    Whole-image OpenCV operations settle those windows: ``cv2.dilate`` gives the
    largest label around each pixel, ``cv2.boxFilter`` (unnormalised) counts the
    non-floor pixels, and with two labels in nine pixels one of them has at least
    five, so the mode is that label if the count is >= 5, else the floor. A windowed
    minimum (``cv2.erode``) over the non-floor labels detects the rare windows with two
    different non-floor labels (a robot's black disc against its colour, a robot
    touching an obstacle); only those pixels get an exact count of every label
    (:func:`_exact_mode`, NumPy over a few hundred pixels). That is ~10 vectorised
    passes over the image however many labels there are, where counting each label
    with its own box filter costs one pass per label. A median filter is no mode for
    categorical labels (it invents in-between labels at a red-yellow border), and
    morphological opening or closing works on one binary mask at a time and erodes
    corners and thin parts; neither is what the paper describes.

    Args:
        labels: uint8 label image (2-D).

    Examples:
        >>> labels = np.zeros((7, 7), np.uint8)
        >>> labels[1:5, 1:5] = 2                # a 4 x 4 blob
        >>> labels[2, 3] = 1                    # with a pixel of another label inside
        >>> labels[6, 5] = 3                    # a loose pixel
        >>> mode_filter(labels)                 # convex corners lose one pixel
        array([[0, 0, 0, 0, 0, 0, 0],
               [0, 0, 2, 2, 0, 0, 0],
               [0, 2, 2, 2, 2, 0, 0],
               [0, 2, 2, 2, 2, 0, 0],
               [0, 0, 2, 2, 0, 0, 0],
               [0, 0, 0, 0, 0, 0, 0],
               [0, 0, 0, 0, 0, 0, 0]], dtype=uint8)
    """
    if labels.dtype != np.uint8 or labels.ndim != 2:
        raise ValueError("labels must be a 2-D uint8 image")
    border = cv2.BORDER_REPLICATE
    largest = cv2.dilate(labels, _SQUARE, borderType=border)
    floor = cv2.compare(labels, FLOOR, cv2.CMP_EQ)                       # 255 on the floor
    smallest_other = cv2.erode(cv2.add(labels, floor), _SQUARE, borderType=border)  # floor as 255
    others = cv2.boxFilter(cv2.min(labels, 1), -1, (3, 3), normalize=False, borderType=border)
    result = cv2.bitwise_and(largest, cv2.compare(others, 5, cv2.CMP_GE))
    # two different non-floor labels around: the smallest is below the largest (an
    # all-floor window has smallest_other 255 > largest 0)
    mixed = cv2.compare(smallest_other, largest, cv2.CMP_LT)
    rows = np.flatnonzero(mixed.max(axis=1))
    if len(rows):
        r, c = np.nonzero(mixed[rows])
        r = rows[r]
        result[r, c] = _exact_mode(labels, r, c)
    return result


def _exact_mode(labels: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """The 3 x 3 mode at the given pixels, counting every label (ties: centre, then lowest)."""
    height, width = labels.shape
    padded = cv2.copyMakeBorder(labels, 1, 1, 1, 1, cv2.BORDER_REPLICATE).ravel()
    stride = width + 2
    centre = (rows + 1) * stride + (cols + 1)
    offsets = np.array([-stride - 1, -stride, -stride + 1, -1, 0, 1, stride - 1, stride, stride + 1])
    around = padded[centre[None, :] + offsets[:, None]]                  # 9 x n
    n = len(rows)
    n_labels = int(around.max()) + 1
    index = np.arange(n)
    counts = np.bincount((around.astype(np.intp) * n + index).ravel(), minlength=n_labels * n)
    counts = counts.reshape(n_labels, n) * 2
    counts[around[4], index] += 1                                        # the centre wins ties
    return counts.argmax(axis=0).astype(np.uint8)


@dataclass(frozen=True)
class Blob:
    """A connected region of one label, with the holes inside it.

    Attributes:
        contour: outer border (``cv2.findContours`` points, N x 1 x 2, int32).
        holes: borders of the holes inside it.
        area: pixels inside the outer border, border and holes included (from
            ``cv2.contourArea`` and ``cv2.arcLength``; exact for axis-aligned rectangles).
        bbox: ``(x, y, w, h)`` bounding box of the outer border.
    """

    contour: np.ndarray
    holes: tuple[np.ndarray, ...]
    area: float
    bbox: tuple[int, int, int, int]


def _pixel_area(contour: np.ndarray) -> float:
    """Pixels enclosed by a contour through pixel centres, its border included (about)."""
    return cv2.contourArea(contour) + cv2.arcLength(contour, True) / 2 + 1


def find_blobs(labels: np.ndarray, label: int, min_area: float = 0.0,
               roi: tuple[int, int, int, int] | None = None) -> list[Blob]:
    """Blobs of ``label`` with their holes, largest first (``cv2.RETR_CCOMP``).

    Args:
        labels: the label image.
        label: which label.
        min_area: smallest blob kept (pixels, holes included).
        roi: ``(x, y, w, h)`` to search only there; contours are in image coordinates.

    Examples:
        >>> labels = np.zeros((9, 9), np.uint8)
        >>> labels[1:8, 1:8] = 2
        >>> labels[3:5, 3:5] = 1                # a hole
        >>> [(b.bbox, b.area, len(b.holes)) for b in find_blobs(labels, 2)]
        [((1, 1, 7, 7), 49.0, 1)]
    """
    x, y = 0, 0
    if roi is not None:
        x, y, w, h = roi
        labels = labels[y:y + h, x:x + w]
    mask = cv2.compare(labels, int(label), cv2.CMP_EQ)
    contours, hierarchy = cv2.findContours(mask, cv2.RETR_CCOMP, cv2.CHAIN_APPROX_SIMPLE, offset=(x, y))
    if hierarchy is None:
        return []
    hierarchy = hierarchy[0]
    blobs = []
    for i, contour in enumerate(contours):
        if hierarchy[i][3] != -1:  # a hole: listed under its parent
            continue
        area = _pixel_area(contour)
        if area < min_area:
            continue
        holes = []
        child = hierarchy[i][2]
        while child != -1:
            holes.append(contours[child])
            child = hierarchy[child][0]
        bbox = tuple(int(v) for v in cv2.boundingRect(contour))
        blobs.append(Blob(contour, tuple(holes), float(area), bbox))
    blobs.sort(key=lambda b: -b.area)
    return blobs


def colour_regions(labels: np.ndarray, first: int = 2,
                   min_area: float = 0.0) -> list[tuple[int, int, int, int]]:
    """Bounding boxes ``(x, y, w, h)`` of the regions of labels ``>= first`` (the robots' colours).

    One outer-contour pass over the whole image; :func:`find_blobs` then looks at
    each colour inside these boxes only.

    Examples:
        >>> labels = np.zeros((6, 9), np.uint8)
        >>> labels[1:4, 1:3] = 2; labels[1:4, 3:5] = 3; labels[5, 8] = 4
        >>> colour_regions(labels, min_area=2)
        [(1, 1, 4, 3)]
    """
    mask = cv2.compare(labels, int(first), cv2.CMP_GE)
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    return [tuple(int(v) for v in cv2.boundingRect(c)) for c in contours if _pixel_area(c) >= min_area]


def obstacle_mask(labels: np.ndarray, robots: Sequence[Blob] = ()) -> np.ndarray:
    """255 where a pixel is black and not inside a robot's outer border, else 0.

    Examples:
        >>> labels = np.zeros((6, 10), np.uint8)
        >>> labels[1:5, 1:5] = 2; labels[2:4, 2:4] = 1      # a robot with a black disc
        >>> labels[1:5, 7:9] = 1                            # an obstacle
        >>> robots = find_blobs(labels, 2)
        >>> (obstacle_mask(labels, robots) // 255)[2]
        array([0, 0, 0, 0, 0, 0, 0, 1, 1, 0], dtype=uint8)
    """
    mask = cv2.compare(labels, OBSTACLE, cv2.CMP_EQ)
    if robots:
        cv2.drawContours(mask, [b.contour for b in robots], -1, 0, thickness=cv2.FILLED)
    return mask


def obstacle_boxes(mask: np.ndarray, min_area: float = 0.0) -> list[tuple[int, int, int, int]]:
    """Bounding boxes ``(x, y, w, h)`` of the obstacle mask's regions, largest first.

    Examples:
        >>> mask = np.zeros((6, 10), np.uint8); mask[1:5, 7:9] = 255; mask[0, 0] = 255
        >>> obstacle_boxes(mask, min_area=2)
        [(7, 1, 2, 4)]
    """
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    kept = [(_pixel_area(c), c) for c in contours]
    kept = [(a, c) for a, c in kept if a >= min_area]
    kept.sort(key=lambda item: -item[0])
    return [tuple(int(v) for v in cv2.boundingRect(c)) for _, c in kept]


def draw_robot_square(labels: np.ndarray, corners: np.ndarray, value: int) -> None:
    """Fill a robot's square (4 x 2 pixel corners, any order around it) with ``value``.

    Examples:
        >>> labels = np.zeros((6, 6), np.uint8)
        >>> draw_robot_square(labels, square_corners((2.5, 2.5), 0.0, 3), 4)
        >>> labels[1:5, 1:5]
        array([[4, 4, 4, 4],
               [4, 4, 4, 4],
               [4, 4, 4, 4],
               [4, 4, 4, 4]], dtype=uint8)
    """
    points = np.round(np.asarray(corners, np.float64) * 16).astype(np.int32)
    cv2.fillConvexPoly(labels, points, int(value), lineType=cv2.LINE_8, shift=4)


def square_corners(centre: Sequence[float], heading: float, side: float) -> np.ndarray:
    """Corners of a square of ``side`` centred at ``centre`` and turned by ``heading``.

    ``heading`` is counter-clockwise with the second axis pointing up (world
    convention); for pixel coordinates, whose rows grow downwards, pass the
    on-screen angle (:attr:`petriflow.vision.pose.RobotPose.heading_px`) and the
    rows are flipped accordingly.

    Examples:
        >>> square_corners((0.0, 0.0), 0.0, 2.0).tolist()
        [[1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0], [1.0, -1.0]]
    """
    c, s = math.cos(heading), math.sin(heading)
    half = side / 2
    local = np.array([[half, half], [-half, half], [-half, -half], [half, -half]])
    rotation = np.array([[c, -s], [s, c]])
    return np.asarray(centre, np.float64) + local @ rotation.T


def grey_map(shape: tuple[int, int], obstacles: np.ndarray,
             squares: Mapping[int, np.ndarray] | None = None) -> np.ndarray:
    """The paper's grey model of the scene: 0 floor, 1 obstacles, robots as squares.

    Args:
        shape: ``(height, width)``.
        obstacles: obstacle mask (non-zero: obstacle).
        squares: ``{label: 4 x 2 pixel corners}``; drawn over the obstacles.

    Examples:
        >>> grey = grey_map((4, 4), np.eye(4, dtype=np.uint8), {3: [[0, 0], [1, 0], [1, 1], [0, 1]]})
        >>> grey
        array([[3, 3, 0, 0],
               [3, 3, 0, 0],
               [0, 0, 1, 0],
               [0, 0, 0, 1]], dtype=uint8)
    """
    grey = cv2.min(obstacles.astype(np.uint8, copy=False), OBSTACLE)
    if grey.shape != tuple(shape):
        raise ValueError(f"obstacle mask is {grey.shape}, not {tuple(shape)}")
    for value, corners in (squares or {}).items():
        draw_robot_square(grey, np.asarray(corners), value)
    return grey


#: Display levels of :func:`to_grey`: white floor, black obstacles, four greys.
GREY_LEVELS = np.array([255, 0, 200, 150, 100, 50] + [128] * 250, np.uint8)


def to_grey(labels: np.ndarray) -> np.ndarray:
    """A viewable grey picture of a label map (floor white, obstacles black).

    Examples:
        >>> to_grey(np.array([[0, 1, 2, 5]], np.uint8)).tolist()
        [[255, 0, 200, 50]]
    """
    return GREY_LEVELS[labels]
