"""Frames from a world's camera, and the ``vision.capture`` action (the paper's IP camera).

A camera of a :class:`petriflow.world.World` renders with pybullet's CPU renderer
(TinyRenderer); a frame is an ``H x W x 3`` uint8 RGB array, 640 x 480 by default
(the paper's camera), 320 x 240 or any other size on request: :func:`camera_for`
makes a copy of the camera with the same pose and field of view at the new size.

``vision.capture`` renders exactly once, when its transition fires (in
:meth:`Capture.start`); nothing is rendered at set-up or while other transitions
run. The frame is the data of its output tokens and is also left on the run's
blackboard, with the camera that took it, for ``vision.locate``::

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

from petriflow.runtime.action import Action, ActionContext, Param, Status

__all__ = ["camera_for", "capture", "Capture", "FRAME_KEY", "CAMERA_KEY"]

#: Blackboard key of the last captured frame.
FRAME_KEY = "frame"
#: Blackboard key of the camera (at the frame's size) that took it.
CAMERA_KEY = "camera"


def camera_for(world: Any, camera: str | None = None, width: int | None = None,
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
        cameras = list(getattr(world, "cameras", {}))
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

    def setup(self, world: Any) -> None:
        self.world = world
        self._camera = None

    def start(self, ctx: ActionContext) -> None:
        self._error = ""
        world = ctx.world if ctx.world is not None else self.world
        if world is None or not hasattr(world, "cameras"):
            self._error = "vision.capture needs a world with a camera (run with --world)"
            return
        try:
            if self._camera is None or self._camera.world is not world:
                self._camera = camera_for(world, self.params["camera"], self.params["width"],
                                          self.params["height"])
        except Exception as exc:  # unknown camera, bad size: a failed outcome with the reason
            self._error = str(exc)
            return
        frame = self._camera.capture()
        ctx.blackboard[FRAME_KEY] = frame
        ctx.blackboard[CAMERA_KEY] = self._camera
        ctx.result = frame

    def poll(self, ctx: ActionContext) -> Status:
        if self._error:
            ctx.reason = self._error
            return Status.FAILED
        return Status.OK
