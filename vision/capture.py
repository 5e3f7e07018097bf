"""Frames from a world's camera, and the ``vision.capture`` action (the paper's IP camera).

A camera of a :class:`petriflow.world.World` renders with pybullet's CPU renderer
(TinyRenderer); a frame is an ``H x W x 3`` uint8 RGB array, 640 x 480 by default
(the paper's camera), 320 x 240 or any other size on request: :func:`camera_for`
makes a copy of the camera with the same pose and field of view at the new size.

``vision.capture`` renders exactly once, when its transition fires (in
:meth:`Capture.start`); nothing is rendered at set-up or while other transitions
run. The frame is the data of its output tokens: a :class:`Frame`, an image array
that also knows the camera that took it, so ``vision.locate`` downstream measures in
that camera's geometry with nothing shared beside the net::

    - {id: capture, action: vision.capture, params: {camera: top}, in: [standby], out: [captured]}

Examples:
    >>> from petriflow.world import World
    >>> world = World({"cameras": [{"id": "top", "position": [0, 0, 3], "target": [0, 0, 0]}]})
    >>> capture(world, "top", 64, 48).shape
    (48, 64, 3)
    >>> world.close()
"""

from __future__ import annotations

import dataclasses
from typing import Any

from petriflow.capabilities import Cameras
from petriflow.errors import PetriflowError
from petriflow.runtime.action import Action, ActionContext, ActionFailure, Param, Status

import numpy as np

__all__ = ["camera_for", "capture", "Capture", "Frame"]


class Frame(np.ndarray):
    """An H x W x 3 uint8 RGB image that remembers the camera that took it (``camera``).

    It is an array in every other way (traces summarise it as one), so a frame token
    can travel through any transition and still be located in world coordinates.

    Examples:
        >>> frame = Frame.of(np.zeros((2, 3, 3), np.uint8), camera="top")
        >>> frame.shape, frame.camera, isinstance(frame, np.ndarray)
        ((2, 3, 3), 'top', True)
    """

    camera: Any = None

    @classmethod
    def of(cls, image: np.ndarray, camera: Any) -> "Frame":
        """``image`` (not copied) as a frame taken by ``camera``."""
        frame = np.asarray(image).view(cls)
        frame.camera = camera
        return frame

    def __array_finalize__(self, obj: Any) -> None:
        self.camera = getattr(obj, "camera", None)


def camera_for(world: Cameras, camera: str | None = None, width: int | None = None,
               height: int | None = None) -> Any:
    """A world's camera, resized if ``width``/``height`` differ from its own.

    Args:
        world: the :class:`petriflow.world.World`.
        camera: camera id; ``None`` means the world's only camera.
        width: image width in pixels (default: the camera's).
        height: image height in pixels (default: the camera's, or ``width`` scaled by
            the camera's aspect ratio when only ``width`` is given).

    Raises:
        ValueError: no camera id given and the world has none or several; or a size
            that is not positive.
        petriflow.errors.NetFormatError: the world has no camera of that id.

    Examples:
        >>> from petriflow.world import World
        >>> world = World({"plane": False, "cameras": [{"id": "top"}]})
        >>> small = camera_for(world, width=320)
        >>> small.width, small.height, small.position == world.camera("top").position
        (320, 240, True)
        >>> world.close()
    """
    if camera is None:
        cameras = list(world.cameras)
        if len(cameras) != 1:
            names = ", ".join(cameras) or "none"
            raise ValueError(f"say which camera: the world has {len(cameras)} ({names})")
        camera = cameras[0]
    base = world.camera(camera)
    if width is None and height is None:
        return base
    width = int(width if width is not None else round(height * base.width / base.height))
    height = int(height if height is not None else round(width * base.height / base.width))
    if width <= 0 or height <= 0:
        raise ValueError(f"image size must be positive, got {width} x {height}")
    if (width, height) == (base.width, base.height):
        return base
    return dataclasses.replace(base, width=width, height=height)


def capture(world: Any, camera: str | None = None, width: int | None = None, height: int | None = None):
    """Render one frame (H x W x 3 uint8 RGB) from a world's camera."""
    return camera_for(world, camera, width, height).capture()


class Capture(Action):
    """Render one camera frame when the transition fires (the frame is the token data)."""

    params = {
        "camera": Param((str, type(None)), None, "camera id (default: the world's only camera)"),
        "width": Param((int, type(None)), None, "image width in pixels (default: the camera's, 640)"),
        "height": Param((int, type(None)), None, "image height in pixels (default: the camera's, 480)"),
    }
    needs_world = False
    requires = frozenset({"world"})
    uses = (Cameras,)

    def setup(self, world: Any) -> None:
        self.world = world
        self._camera = None

    def start(self, ctx: ActionContext) -> None:
        world = ctx.world if ctx.world is not None else self.world
        if world is None:
            raise ActionFailure("vision.capture needs a world with a camera (run with --world)")
        if self._camera is None or self._camera.world is not world:
            try:
                self._camera = camera_for(world, self.params["camera"], self.params["width"],
                                          self.params["height"])
            except (ValueError, PetriflowError) as exc:  # unknown camera, bad size
                raise ActionFailure(str(exc)) from None
        with ctx.stopwatch.measure("render", keep=True):
            image = self._camera.capture()
        ctx.result = Frame.of(image, self._camera)

    def poll(self, ctx: ActionContext) -> Status:
        return Status.OK
