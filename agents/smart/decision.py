"""What the SMART decision maker reads in a scene: who stands, who has fallen, where.

The image-processing agent (:func:`petriflow.vision.pipeline.process`) reports a robot
only when it finds its black and white discs inside its colour patch. A robot that has
fallen shows the camera its side: its colour is still there (the body's side, the
plate's edge) but the discs are not, or only as a sliver. :func:`assess` tells the
three cases apart:

* ``upright``: found with both discs and a colour blob of at least half the patch's
  area (``L²`` in pixels);
* ``down``: its colour covers at least ``min_area`` pixels but it is not upright;
* ``missing``: not in the image.

A fallen robot's position is the centroid of its colour pixels, taken on the plane of
its visible surface (``height``, the lying body's top, 0.13 m for Robot4L) through the
camera when one is known, so the parallax of a point above the marker plane does not
shift it; the scene's own frame (the marker plane) is used otherwise.

Examples:
    >>> import numpy as np
    >>> from types import SimpleNamespace
    >>> labels = np.zeros((48, 64), np.uint8)
    >>> labels[10:14, 40:52] = 2                    # a red sliver, no discs
    >>> scene = SimpleNamespace(robots={}, segmented=labels, metres_per_pixel=0.01, origin=(0.0, 0.0))
    >>> seen = assess(scene, "red", min_area=20)
    >>> seen.state, seen.pixel, [round(v, 3) for v in seen.position]
    ('down', (45.5, 11.5), [0.455, -0.115])
    >>> assess(scene, "yellow").state
    'missing'
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["LABELS", "Seen", "assess", "draw_obstacle", "robot_id"]

#: Grey-map labels of the robots' colours (also their one-byte ids in SMART commands).
LABELS = {"red": 2, "blue": 3, "yellow": 4, "green": 5}


def robot_id(colour: str) -> int:
    """A robot's id byte in SMART commands: its label in the grey map (red 2 ... green 5).

    Examples:
        >>> robot_id("yellow")
        4
    """
    if colour not in LABELS:
        raise ValueError(f"unknown robot colour {colour!r}; one of {sorted(LABELS)}")
    return LABELS[colour]


@dataclass(frozen=True)
class Seen:
    """How one robot appears in a scene.

    Attributes:
        colour: the robot's colour.
        state: ``upright``, ``down`` or ``missing``.
        pixel: centroid ``(column, row)`` of its colour pixels (or of its discs when
            upright); ``None`` when missing.
        position: world ``(x, y)`` (m): the pose's position when upright, the
            centroid's when down; ``None`` when missing or without a frame.
        heading: world heading (rad) when upright, else ``None``.
        area: pixels of its colour.
    """

    colour: str
    state: str
    pixel: tuple[float, float] | None = None
    position: tuple[float, float] | None = None
    heading: float | None = None
    area: int = 0


def _field(scene: Any, name: str) -> Any:
    if isinstance(scene, Mapping):
        return scene.get(name)
    return getattr(scene, name, None)


def assess(scene: Any, colour: str, *, side: float = 0.26, min_area: int | None = None,
           height: float = 0.13, camera: Any = None) -> Seen:
    """How ``colour``'s robot appears in ``scene`` (a :class:`petriflow.vision.pipeline.Scene`).

    Args:
        scene: the scene (``robots``, ``segmented``, ``metres_per_pixel``, ``origin``).
        colour: the robot's colour.
        side: side ``L`` of its marker patch (m): an upright robot shows at least half
            of ``L²``.
        min_area: fewest colour pixels of a robot that is down (default: a tenth of
            ``L²``, at least 20).
        height: height (m) of a fallen robot's visible surface, for its position.
        camera: the camera that took the frame (for the position of a fallen robot).
    """
    label = robot_id(colour)
    scale = _field(scene, "metres_per_pixel")
    patch = (side / scale) ** 2 if scale else None
    robots = _field(scene, "robots") or {}
    pose = robots.get(colour)
    segmented = _field(scene, "segmented")
    mask = None if segmented is None else (np.asarray(segmented) == label)
    area = int(mask.sum()) if mask is not None else int(getattr(pose, "area", 0) or 0)
    if pose is not None and (patch is None or getattr(pose, "area", 0) >= 0.5 * patch):
        position = getattr(pose, "position", None)
        return Seen(colour, "upright", tuple(float(v) for v in pose.pixel),
                    None if position is None else (float(position[0]), float(position[1])),
                    getattr(pose, "heading", None), area)
    least = min_area if min_area is not None else max(20, int(0.1 * patch) if patch else 20)
    if mask is None or area < least:
        return Seen(colour, "missing", area=area)
    rows, cols = np.nonzero(mask)
    pixel = (float(cols.mean()), float(rows.mean()))
    position = None
    if camera is not None:
        from petriflow.vision.pose import GroundPlane

        x, y = GroundPlane(camera, height).to_world(pixel[0], pixel[1])
        position = (float(x), float(y))
    elif scale:
        origin = _field(scene, "origin") or (0.0, 0.0)
        position = (float(origin[0] + pixel[0] * scale), float(origin[1] - pixel[1] * scale))
    return Seen(colour, "down", pixel, position, None, area)


def draw_obstacle(label_map: np.ndarray, pixel: tuple[float, float], radius_px: float,
                  label: int = 1) -> np.ndarray:
    """A copy of ``label_map`` with a disc of ``label`` (default: obstacle) drawn at
    ``pixel`` = ``(column, row)``.

    Examples:
        >>> out = draw_obstacle(np.zeros((5, 5), np.uint8), (2, 2), 1.0)
        >>> int(out.sum()), int(out[2, 2])
        (5, 1)
    """
    out = np.array(label_map, dtype=np.uint8, copy=True)
    rows, cols = np.ogrid[:out.shape[0], :out.shape[1]]
    disc = (cols - pixel[0]) ** 2 + (rows - pixel[1]) ** 2 <= radius_px ** 2
    out[disc] = label
    return out
