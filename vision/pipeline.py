"""The image-processing agent: frame → robots' poses, obstacles and grey map (seed 003, §2.4).

:func:`process` runs the paper's steps on one RGB frame and returns a :class:`Scene`:

1. ``classify``: RGB → HSV → labels by the HSV thresholds
   (:class:`petriflow.vision.segment.ColourTable`, the same computation tabulated per
   RGB colour; ``VisionConfig(use_table=False)`` runs :func:`~petriflow.vision.segment.to_hsv`
   and :func:`~petriflow.vision.segment.label_pixels` on the frame instead);
2. ``mode``: the 8-neighbourhood mode filter;
3. ``contours``: colour regions and, in each, every robot colour's blobs with their
   holes; the obstacle mask (black outside robots) and its contours;
4. ``pose``: the discs in each robot's blob, pose in pixels and, with a camera, in
   world metres on the marker plane;
5. ``map``: the grey label map, obstacles plus each robot as a square of side ``L``.

``Scene.timings`` has the wall-clock seconds of each stage. ``vision.locate`` is the
action: it takes the frame from its input token (a
:class:`~petriflow.vision.capture.Frame` knows the camera that took it) and returns
the :class:`Scene` as token data; the scene keeps that camera for the decisions made
on it::

    - {id: locate, action: vision.locate, in: [captured], out: [identified]}

Examples:
    >>> import numpy as np
    >>> frame = np.full((48, 64, 3), 239, np.uint8)           # white floor
    >>> frame[10:30, 10:30] = (215, 23, 23)                   # a red robot
    >>> frame[14:19, 17:23] = (4, 4, 4)                       # its black disc
    >>> frame[21:26, 17:23] = (239, 239, 239)                 # its white disc
    >>> frame[35:45, 40:60] = (4, 4, 4)                       # an obstacle
    >>> scene = process(frame)
    >>> scene.to_token()["robots"]["red"]
    {'x': None, 'y': None, 'heading': None, 'u': 19.5, 'v': 19.5, 'heading_px': 0.0}
    >>> scene.missing, scene.obstacle_boxes
    (('blue', 'yellow', 'green'), [(40, 35, 20, 10)])
    >>> sorted(np.unique(scene.labels).tolist())
    [0, 1, 2]
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

import numpy as np

from petriflow.capabilities import Cameras, provides
from petriflow.runtime.action import Action, ActionContext, ActionFailure, Param, Status
from petriflow.vision.capture import camera_for
from petriflow.vision.markers import DEFAULT_GEOMETRY, ROBOT_COLOURS
from petriflow.vision.pose import TINY_RENDERER_OFFSET, GroundPlane, RobotPose, find_discs, robot_pose
from petriflow.vision.segment import (
    DEFAULT_THRESHOLDS,
    colour_regions,
    colour_table,
    find_blobs,
    grey_map,
    label_pixels,
    mode_filter,
    obstacle_boxes,
    obstacle_mask,
    square_corners,
    to_hsv,
)

__all__ = ["VisionConfig", "Scene", "process", "Locate", "STAGES"]

#: The stages timed in :attr:`Scene.timings`, in order.
STAGES = ("classify", "mode", "contours", "pose", "map")
#: Frame size the pixel-area settings of :class:`VisionConfig` are given for.
_REFERENCE_PIXELS = 640 * 480


@dataclass(frozen=True)
class VisionConfig:
    """Settings of :func:`process`.

    Attributes:
        thresholds: HSV ranges per class (:data:`petriflow.vision.segment.DEFAULT_THRESHOLDS`).
        colours: robot colours in label order (label 2, 3, ...).
        mode_filter: run the mode filter.
        use_table: classify through the precomputed RGB → label table.
        min_robot_area: smallest robot blob, in pixels of a 640 x 480 frame (scaled
            with the frame's pixel count).
        min_disc_area: smallest disc, same scale (at least 2 pixels).
        min_obstacle_area: smallest obstacle, same scale.
        marker_z: height of the discs' top faces (m): the plane poses are measured on.
        robot_side: side ``L`` of a robot's square in the grey map (m), drawn on the
            marker plane; used when a camera is known.
        robot_side_px: the square's side in pixels when there is no camera.
        pixel_offset: pixel index → ``Camera.project`` coordinates
            (:data:`petriflow.vision.pose.TINY_RENDERER_OFFSET`).
    """

    thresholds: Mapping = field(default_factory=lambda: dict(DEFAULT_THRESHOLDS))
    colours: tuple[str, ...] = ROBOT_COLOURS
    mode_filter: bool = True
    use_table: bool = True
    min_robot_area: float = 150.0
    min_disc_area: float = 6.0
    min_obstacle_area: float = 30.0
    marker_z: float = DEFAULT_GEOMETRY.marker_z
    robot_side: float = DEFAULT_GEOMETRY.side
    robot_side_px: float = 36.0
    pixel_offset: tuple[float, float] = TINY_RENDERER_OFFSET

    def scaled(self, area: float, shape: Sequence[int]) -> float:
        """A 640 x 480 pixel area scaled to a frame of ``shape`` (rows, columns)."""
        return area * shape[0] * shape[1] / _REFERENCE_PIXELS


DEFAULT_CONFIG = VisionConfig()


@dataclass
class Scene:
    """What the image-processing agent saw in one frame.

    Attributes:
        robots: ``{colour: RobotPose}`` for the robots found with both discs.
        missing: colours of :attr:`VisionConfig.colours` not found.
        labels: the grey label map (uint8, H x W): 0 floor, 1 obstacle, 2..5 robots
            as squares of side ``L``.
        segmented: per-pixel labels after the mode filter (robots as seen).
        obstacles: obstacle mask (uint8, 255 = obstacle).
        obstacle_boxes: ``(x, y, w, h)`` of each obstacle region, largest first.
        timings: wall-clock seconds per stage (:data:`STAGES`) and ``total``.
        size: ``(width, height)`` of the frame.
        metres_per_pixel: pixel size on the marker plane, when the camera looks
            straight down with ``up`` = +y (else ``None``).
        origin: world ``(x, y)`` of the centre of pixel ``(0, 0)`` on the marker plane,
            rows running toward -y (with ``metres_per_pixel``; else ``None``).
        camera: the camera that took the frame (at its size), when known.

    ``label_map`` (the grey map), ``poses``, ``metres_per_pixel`` and ``origin`` are
    the names ``planning.astar`` reads from a scene.
    """

    robots: dict[str, RobotPose]
    missing: tuple[str, ...]
    labels: np.ndarray
    segmented: np.ndarray
    obstacles: np.ndarray
    obstacle_boxes: list[tuple[int, int, int, int]]
    timings: dict[str, float]
    size: tuple[int, int]
    metres_per_pixel: float | None = None
    origin: tuple[float, float] | None = None
    camera: Any = field(default=None, repr=False, compare=False)

    @property
    def label_map(self) -> np.ndarray:
        """The grey label map (same as :attr:`labels`)."""
        return self.labels

    @property
    def poses(self) -> dict[str, list[float]]:
        """``{colour: [x, y, heading]}`` in world units, for robots located in metres."""
        return {colour: [pose.position[0], pose.position[1], pose.heading]
                for colour, pose in self.robots.items() if pose.position is not None}

    def to_token(self) -> dict[str, Any]:
        """A JSON-able summary: poses, missing colours, obstacle boxes, the pixel frame; no images.

        Timings are left out (they differ from run to run; traces must not).
        """
        return {
            "size": list(self.size),
            "robots": {colour: pose.to_token() for colour, pose in self.robots.items()},
            "missing": list(self.missing),
            "obstacles": [list(box) for box in self.obstacle_boxes],
            "metres_per_pixel": None if self.metres_per_pixel is None else round(self.metres_per_pixel, 8),
            "origin": None if self.origin is None else [round(v, 6) for v in self.origin],
        }


def _plane(camera: Any, config: VisionConfig, shape: Sequence[int]) -> GroundPlane | None:
    if camera is None:
        return None
    if (camera.width, camera.height) != (shape[1], shape[0]):
        raise ValueError(f"the frame is {shape[1]} x {shape[0]} but the camera renders "
                         f"{camera.width} x {camera.height}")
    key = (tuple(camera.view), tuple(camera.projection), camera.width, camera.height,
           config.marker_z, tuple(config.pixel_offset))
    cache = _plane.cache  # type: ignore[attr-defined]
    plane = cache.get(key)
    if plane is None:
        if len(cache) > 32:
            cache.clear()
        plane = cache[key] = GroundPlane(camera, config.marker_z, config.pixel_offset)
    return plane


_plane.cache = {}  # type: ignore[attr-defined]


def process(frame: np.ndarray, camera: Any = None, config: VisionConfig = DEFAULT_CONFIG) -> Scene:
    """Find the robots and obstacles in an RGB frame.

    Args:
        frame: H x W x 3 uint8 RGB.
        camera: the :class:`petriflow.world.Camera` that took it (at the frame's size),
            for world coordinates; ``None`` gives pixels only.
        config: the settings.

    Raises:
        ValueError: a frame that is not H x W x 3 uint8, or a camera of another size.
    """
    if not (isinstance(frame, np.ndarray) and frame.dtype == np.uint8 and frame.ndim == 3
            and frame.shape[2] == 3):
        raise ValueError(f"a frame is an H x W x 3 uint8 array, got {getattr(frame, 'shape', type(frame))}")
    shape = frame.shape[:2]
    plane = _plane(camera, config, shape)
    clock = time.perf_counter
    timings: dict[str, float] = {}
    started = last = clock()

    # 1. RGB -> HSV -> labels
    if config.use_table:
        labels = colour_table(config.thresholds, config.colours)(frame)
    else:
        labels = label_pixels(to_hsv(frame), config.thresholds, config.colours)
    now = clock(); timings["classify"] = now - last; last = now

    # 2. mode filter
    if config.mode_filter:
        labels = mode_filter(labels)
    now = clock(); timings["mode"] = now - last; last = now

    # 3. contours: robots' blobs (with holes), then obstacles
    min_robot = config.scaled(config.min_robot_area, shape)
    first_robot_label = 2
    candidates: dict[int, list] = {}
    for x, y, w, h in colour_regions(labels, first_robot_label, min_robot):
        left, top = max(x - 1, 0), max(y - 1, 0)                    # one pixel of margin
        roi = (left, top, min(x + w + 1, shape[1]) - left, min(y + h + 1, shape[0]) - top)
        present = np.bincount(labels[top:top + roi[3], left:left + roi[2]].ravel(), minlength=256)
        for label in np.flatnonzero(present[first_robot_label:first_robot_label + len(config.colours)]):
            label = int(label) + first_robot_label
            candidates.setdefault(label, []).extend(find_blobs(labels, label, min_robot, roi))
    every_blob = [blob for blobs in candidates.values() for blob in blobs]
    obstacles = obstacle_mask(labels, every_blob)
    boxes = obstacle_boxes(obstacles, config.scaled(config.min_obstacle_area, shape))
    now = clock(); timings["contours"] = now - last; last = now

    # 4. poses from the discs
    min_disc = max(2, int(round(config.scaled(config.min_disc_area, shape))))
    robots: dict[str, RobotPose] = {}
    for i, colour in enumerate(config.colours):
        label = first_robot_label + i
        for blob in sorted(candidates.get(label, []), key=lambda b: -b.area):
            discs = find_discs(labels, blob, min_disc)
            if discs is not None:
                robots[colour] = robot_pose(colour, label, discs, blob.area, plane)
                break
    missing = tuple(c for c in config.colours if c not in robots)
    now = clock(); timings["pose"] = now - last; last = now

    # 5. grey map: obstacles, then each robot as a square of side L
    squares = {}
    for pose in robots.values():
        if plane is not None:
            corners = square_corners(pose.position, pose.heading, config.robot_side)
            squares[pose.label] = np.stack(plane.to_pixel(corners[:, 0], corners[:, 1]), axis=1)
        else:
            corners = square_corners((pose.pixel[0], -pose.pixel[1]), pose.heading_px, config.robot_side_px)
            squares[pose.label] = corners * (1, -1)
    grey = grey_map(shape, obstacles, squares)
    now = clock(); timings["map"] = now - last
    timings["total"] = now - started
    scale, origin = (plane.grid or (None, None)) if plane is not None else (None, None)
    return Scene(robots, missing, grey, labels, obstacles, boxes, timings, (shape[1], shape[0]),
                 scale, origin, camera)


class Locate(Action):
    """Find the robots' poses and the obstacles in the last camera frame (token data: a Scene)."""

    params = {
        "camera": Param((str, type(None)), None,
                        "camera for world coordinates (default: the one that took the frame)"),
        "marker_z": Param(float, DEFAULT_GEOMETRY.marker_z, "height of the marker discs' tops (m)"),
        "robot_side": Param(float, DEFAULT_GEOMETRY.side, "side L of a robot's square in the map (m)",
                            low=1e-9),
        "mode_filter": Param(bool, True, "remove loose pixels with the 8-neighbourhood mode filter"),
        "require": Param(list, [], "colours that must be found, else the action fails"),
    }
    needs_world = False

    def setup(self, world: Any) -> None:
        self.world = world

    def _frame_and_camera(self, ctx: ActionContext) -> tuple[np.ndarray, Any]:
        frame = ctx.token()
        if not isinstance(frame, np.ndarray):
            raise ActionFailure("vision.locate: no frame in the input tokens (fire vision.capture first)")
        height, width = frame.shape[:2]
        world = ctx.world if ctx.world is not None else self.world
        taken = getattr(frame, "camera", None)
        try:
            if self.params["camera"] is not None:
                camera = camera_for(world, self.params["camera"], width, height)
            elif taken is not None:
                same = (taken.width, taken.height) == (width, height)
                camera = taken if same else dataclasses.replace(taken, width=width, height=height)
            elif provides(world, Cameras) and len(world.cameras) == 1:  # a world is optional here
                camera = camera_for(world, None, width, height)
            else:
                camera = None
        except Exception as exc:  # unknown camera
            raise ActionFailure(str(exc)) from None
        return np.asarray(frame), camera

    def start(self, ctx: ActionContext) -> None:
        frame, camera = self._frame_and_camera(ctx)
        config = VisionConfig(mode_filter=self.params["mode_filter"], marker_z=self.params["marker_z"],
                              robot_side=self.params["robot_side"])
        try:
            with ctx.stopwatch.measure("vision", keep=True):
                scene = process(frame, camera, config)
        except ValueError as exc:
            raise ActionFailure(str(exc)) from None
        ctx.result = scene
        lost = [c for c in self.params["require"] if c not in scene.robots]
        if lost:
            raise ActionFailure(f"vision.locate: not found: {', '.join(map(str, lost))}")

    def poll(self, ctx: ActionContext) -> Status:
        return Status.OK
