"""Top-view pictures of the SMART experiments, drawn with OpenCV (a dependency).

:class:`TopView` draws a world description (``world.yaml`` as data: its boxes are
the walls and obstacles) at a fixed scale, then paths on it: planned (dashed) and
driven (solid), points, arrows and labels, in world metres. No rendering engine and
no matplotlib: the picture is a map, like the paper's Fig. 14 and 15.

Examples:
    >>> view = TopView({"boxes": [{"id": "floor", "size": [2, 2, 0.1], "position": [0, 0, 0.05],
    ...                            "colour": "grey"}]}, scale=50)
    >>> view.path([(-1, 0), (1, 0)], "red", dashed=True)
    >>> view.image.shape                     # 2 m + 2 x 5 cm margin at 50 px/m
    (105, 105, 3)
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["BGR", "TopView"]

#: Drawing colours (B, G, R).
BGR = {
    "red": (40, 40, 220), "blue": (200, 80, 30), "yellow": (0, 170, 230), "green": (60, 170, 40),
    "black": (20, 20, 20), "grey": (150, 150, 150), "white": (255, 255, 255), "orange": (0, 130, 255),
    "purple": (160, 50, 140), "dark": (70, 70, 70), "light": (225, 225, 225),
}


def _bgr(colour: Any) -> tuple[int, int, int]:
    if isinstance(colour, str):
        return BGR[colour]
    return tuple(int(c) for c in colour)  # type: ignore[return-value]


class TopView:
    """A canvas showing a world from above; +x to the right, +y up.

    Args:
        world: the world description (a mapping, as in ``world.yaml``).
        scale: pixels per metre.
        margin: extra metres around the boxes' extent.
        bounds: ``(xmin, ymin, xmax, ymax)`` to show instead of the boxes' extent.
    """

    def __init__(self, world: dict[str, Any], scale: float = 300.0, margin: float = 0.05,
                 bounds: Sequence[float] | None = None) -> None:
        boxes = list(world.get("boxes") or [])
        if bounds is None:
            if boxes:
                corners = np.concatenate([self._corners(b) for b in boxes])
                bounds = (*(corners.min(axis=0) - margin), *(corners.max(axis=0) + margin))
            else:
                bounds = (-1.0, -1.0, 1.0, 1.0)
        self.bounds = tuple(float(v) for v in bounds)
        self.scale = float(scale)
        width = int(math.ceil((self.bounds[2] - self.bounds[0]) * scale))
        height = int(math.ceil((self.bounds[3] - self.bounds[1]) * scale))
        self.image = np.full((height, width, 3), 255, np.uint8)
        for box in boxes:
            colour = box.get("colour", "grey")
            self.polygon(self._corners(box), colour if isinstance(colour, str) and colour in BGR else "grey")

    @staticmethod
    def _corners(box: dict[str, Any]) -> np.ndarray:
        sx, sy = float(box["size"][0]) / 2, float(box["size"][1]) / 2
        x, y = float(box["position"][0]), float(box["position"][1])
        yaw = float(box.get("yaw", 0.0))
        c, s = math.cos(yaw), math.sin(yaw)
        local = np.array([[-sx, -sy], [sx, -sy], [sx, sy], [-sx, sy]])
        return local @ np.array([[c, s], [-s, c]]) + (x, y)

    def px(self, points: Any) -> np.ndarray:
        """Pixel coordinates (integer column, row) of world points ``(x, y)``."""
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        col = (pts[:, 0] - self.bounds[0]) * self.scale
        row = (self.bounds[3] - pts[:, 1]) * self.scale
        return np.round(np.stack([col, row], axis=1)).astype(np.int32)

    def polygon(self, corners: Any, colour: Any) -> None:
        import cv2

        cv2.fillPoly(self.image, [self.px(corners)], _bgr(colour), lineType=cv2.LINE_AA)

    def path(self, points: Iterable[Sequence[float]], colour: Any, thickness: int = 2,
             dashed: bool = False) -> None:
        """A polyline through world points; ``dashed`` for a planned path."""
        import cv2

        pts = self.px(list(points))
        if len(pts) < 2:
            return
        if not dashed:
            cv2.polylines(self.image, [pts], False, _bgr(colour), thickness, lineType=cv2.LINE_AA)
            return
        dash = max(4.0, 3.0 * thickness)
        for a, b in zip(pts[:-1], pts[1:]):
            length = float(np.hypot(*(b - a)))
            pieces = max(1, int(length // dash))
            for k in range(0, pieces, 2):
                p = a + (b - a) * (k / pieces)
                q = a + (b - a) * (min(k + 1, pieces) / pieces)
                cv2.line(self.image, tuple(int(v) for v in p), tuple(int(v) for v in q), _bgr(colour),
                         thickness, lineType=cv2.LINE_AA)

    def disc(self, point: Sequence[float], radius: float, colour: Any, thickness: int = -1) -> None:
        """A circle of ``radius`` metres (filled unless ``thickness`` > 0)."""
        import cv2

        centre = tuple(int(v) for v in self.px(point)[0])
        cv2.circle(self.image, centre, max(1, int(round(radius * self.scale))), _bgr(colour), thickness,
                   lineType=cv2.LINE_AA)

    def mark(self, point: Sequence[float], colour: Any, size: int = 7) -> None:
        """A cross at a world point."""
        import cv2

        centre = tuple(int(v) for v in self.px(point)[0])
        cv2.drawMarker(self.image, centre, _bgr(colour), cv2.MARKER_TILTED_CROSS, size * 2, 2, cv2.LINE_AA)

    def arrow(self, start: Sequence[float], end: Sequence[float], colour: Any, thickness: int = 2) -> None:
        import cv2

        a, b = self.px([start, end])
        cv2.arrowedLine(self.image, tuple(int(v) for v in a), tuple(int(v) for v in b), _bgr(colour),
                        thickness, line_type=cv2.LINE_AA, tipLength=0.25)

    def square(self, pose: Sequence[float], side: float, colour: Any, thickness: int = 1) -> None:
        """A robot's square of side ``side`` at ``(x, y, heading)``."""
        import cv2

        x, y, heading = pose
        corners = self._corners({"size": [side, side], "position": [x, y], "yaw": heading})
        cv2.polylines(self.image, [self.px(corners)], True, _bgr(colour), thickness, lineType=cv2.LINE_AA)

    def text(self, point: Sequence[float], words: str, colour: Any = "dark", size: float = 0.45) -> None:
        import cv2

        corner = tuple(int(v) for v in self.px(point)[0])
        cv2.putText(self.image, words, corner, cv2.FONT_HERSHEY_SIMPLEX, size, _bgr(colour), 1, cv2.LINE_AA)

    def legend(self, entries: Sequence[tuple[str, Any, bool]]) -> None:
        """Lines of ``(words, colour, dashed)`` in the top-left corner, over a white box."""
        import cv2

        height = 18 * len(entries) + 8
        width = 12 + max((len(w) for w, _, _ in entries), default=0) * 8 + 40
        cv2.rectangle(self.image, (4, 4), (4 + width, 4 + height), (255, 255, 255), -1)
        cv2.rectangle(self.image, (4, 4), (4 + width, 4 + height), BGR["grey"], 1)
        for k, (words, colour, dashed) in enumerate(entries):
            y = 20 + 18 * k
            if dashed:
                for x in range(12, 40, 8):
                    cv2.line(self.image, (x, y - 4), (x + 4, y - 4), _bgr(colour), 2, cv2.LINE_AA)
            else:
                cv2.line(self.image, (12, y - 4), (40, y - 4), _bgr(colour), 2, cv2.LINE_AA)
            cv2.putText(self.image, words, (46, y), cv2.FONT_HERSHEY_SIMPLEX, 0.42, BGR["dark"], 1, cv2.LINE_AA)

    def save(self, path: str | Path) -> str:
        """Write a PNG; returns its path."""
        import cv2

        Path(path).parent.mkdir(parents=True, exist_ok=True)
        if not cv2.imwrite(str(path), self.image):
            raise OSError(f"cannot write {path}")
        return str(path)
