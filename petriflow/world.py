"""A thin pybullet world built from a description, stepped by the scheduler.

The description is plain data (a ``world.yaml`` beside a net)::

    dt: 0.01                 # seconds per physics step
    gravity: -9.81
    plane: true
    boxes:                   # static (mass 0) or dynamic boxes
      - {id: wall, size: [4, 0.1, 0.5], position: [0, 2, 0.25], yaw: 0, colour: grey}
    grid:                    # walls from an occupancy grid ('#' occupied)
      cell: 0.25
      height: 0.4
      origin: [-2, -2]       # world x, y of the grid's lower-left corner
      rows: ["#####", "#...#", "#####"]   # first row is the top (largest y)
    robots:
      - {id: red, urdf: "petriflow.agents:robots/diffdrive.urdf", position: [0, 0],
         yaw: 0, colour: red, agent: robot_red}
      # optional: z (base height), roll and pitch (rad, about the body's x and y
      # axes, applied after yaw): a robot that starts fallen on its side
    meta: {}                 # free-form data the world keeps (``World.meta``) but never reads
    cameras:
      - {id: top, position: [0, 0, 6], target: [0, 0, 0], up: [0, 1, 0], fov: 60,
         width: 640, height: 480}

A ``urdf`` is a path relative to the description file, or ``"package:path"`` naming a
file shipped inside an installed Python package (``pybullet_data:r2d2.urdf``). It is
data; nothing from a world file is imported or evaluated.

pybullet runs in DIRECT mode unless ``gui=True``. Nothing here knows a particular
robot: actions in ``petriflow.agents`` drive the bodies.
"""

from __future__ import annotations

import contextlib
import importlib.util
import math
import os
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from petriflow.errors import DependencyNotInstalled, NetFormatError, PetriflowError, did_you_mean
from petriflow.worldfile import COLOURS, check_box, check_world

__all__ = ["World", "Camera", "load_world", "COLOURS"]


@contextlib.contextmanager
def _quiet_stdout():
    """Silence C-level prints on standard output and error (pybullet announces its
    build time on import)."""
    try:
        sys.stdout.flush()
        sys.stderr.flush()
        saved = (os.dup(1), os.dup(2))
    except (OSError, ValueError):  # no real file descriptors (e.g. captured output)
        yield
        return
    try:
        with open(os.devnull, "w") as devnull:
            os.dup2(devnull.fileno(), 1)
            os.dup2(devnull.fileno(), 2)
            yield
            _flush_c_stdio()  # C's buffered output would otherwise print at exit
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        os.close(saved[0])
        os.close(saved[1])


def _flush_c_stdio() -> None:
    try:
        import ctypes

        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):  # pragma: no cover - no C library to flush
        pass


def _pybullet():
    try:
        with _quiet_stdout():
            import pybullet
    except ImportError:  # pragma: no cover - depends on the installation
        raise DependencyNotInstalled("pybullet is not installed: pip install pybullet") from None
    return pybullet


@dataclass
class Camera:
    """A fixed camera; :meth:`capture` renders an RGB frame (H x W x 3, uint8)."""

    world: "World"
    id: str
    position: tuple[float, float, float]
    target: tuple[float, float, float]
    up: tuple[float, float, float]
    fov: float
    width: int
    height: int
    near: float = 0.05
    far: float = 20.0

    def __post_init__(self) -> None:
        p = self.world.p
        self.view = p.computeViewMatrix(self.position, self.target, self.up)
        self.projection = p.computeProjectionMatrixFOV(self.fov, self.width / self.height, self.near, self.far)

    def capture(self):
        """Render the current scene with pybullet's CPU renderer."""
        import numpy as np

        p = self.world.p
        _, _, rgba, _, _ = p.getCameraImage(
            self.width, self.height, self.view, self.projection,
            renderer=p.ER_TINY_RENDERER, physicsClientId=self.world.client,
        )
        frame = np.asarray(rgba, dtype=np.uint8).reshape(self.height, self.width, 4)
        return frame[:, :, :3].copy()

    def project(self, x: float, y: float, z: float = 0.0) -> tuple[float, float]:
        """Pixel coordinates (column, row) of a world point."""
        import numpy as np

        view = np.asarray(self.view).reshape(4, 4).T
        projection = np.asarray(self.projection).reshape(4, 4).T
        clip = projection @ view @ np.array([x, y, z, 1.0])
        ndc = clip[:3] / clip[3]
        return ((ndc[0] + 1) / 2 * self.width, (1 - ndc[1]) / 2 * self.height)


class World:
    """A pybullet physics client built from a description.

    Args:
        description: the world as plain data (see the module docstring).
        base: folder that relative URDF paths start from.
        gui: open pybullet's GUI instead of DIRECT mode.
        path: the description's file, named in errors.
    """

    def __init__(self, description: dict[str, Any] | None = None, *, base: str | Path = ".",
                 gui: bool = False, path: str | None = None) -> None:
        self.path = path
        self.base = Path(base)
        description = check_world(description, path)  # every field, before pybullet is touched
        self.p = _pybullet()
        self.dt = description["dt"]
        #: Free-form data from the description's ``meta`` (kept for other components, unread here).
        self.meta: dict[str, Any] = dict(description["meta"])
        p = self.p
        if gui and sys.platform.startswith("linux") and not os.environ.get("DISPLAY"):
            # pybullet would end the whole process (exit 1, no message) without an X display
            raise PetriflowError("--gui needs a display, and DISPLAY is not set; run without --gui")
        with _quiet_stdout():
            self.client = p.connect(p.GUI if gui else p.DIRECT)
        if self.client < 0:
            raise PetriflowError("cannot open pybullet's GUI; run without --gui")
        p.resetSimulation(physicsClientId=self.client)
        p.setPhysicsEngineParameter(fixedTimeStep=self.dt, deterministicOverlappingPairs=1,
                                    physicsClientId=self.client)
        p.setGravity(0, 0, description["gravity"], physicsClientId=self.client)
        self.bodies: dict[str, int] = {}
        self.agents: dict[str, str] = {}
        self.cameras: dict[str, Camera] = {}
        self.steps = 0
        if description["plane"]:
            self.bodies["plane"] = self._load_urdf("pybullet_data:plane.urdf", (0, 0, 0), 0.0, fixed=True)
        for box in description["boxes"]:
            self.add_box(**box)
        if description["grid"]:
            self._add_grid(description["grid"])
        for robot in description["robots"]:
            self._add_robot(robot)
        for camera in description["cameras"]:
            self._add_camera(camera)

    # Building -----------------------------------------------------------------------
    def _fail(self, message: str, element: str | None = None):
        raise NetFormatError(message, path=self.path, element=element)

    def _resolve(self, reference: str) -> str:
        package, sep, relative = reference.partition(":")
        if sep and not Path(reference).exists() and "/" not in package and "\\" not in package:
            try:
                spec = importlib.util.find_spec(package)
            except (ImportError, ValueError):  # a parent package that does not exist, a bad name
                spec = None
            if spec is None or not spec.submodule_search_locations:
                self._fail(f"unknown package {package!r} in {reference!r}")
            candidate = Path(list(spec.submodule_search_locations)[0]) / relative
        else:
            candidate = self.base / reference
        if not candidate.is_file():
            self._fail(f"URDF not found: {reference!r}")
        return str(candidate)

    def _load_urdf(self, reference: str, position, yaw: float, fixed: bool = False,
                   roll: float = 0.0, pitch: float = 0.0) -> int:
        p = self.p
        orientation = p.getQuaternionFromEuler((roll, pitch, yaw))
        try:
            return p.loadURDF(self._resolve(reference), position, orientation, useFixedBase=fixed,
                              physicsClientId=self.client)
        except p.error as exc:
            self._fail(f"cannot load URDF {reference!r}: {exc}")

    def add_box(self, id: str, size, position, yaw: float = 0.0, colour: Any = "grey",
                mass: float = 0.0) -> int:
        """Add a box of full extents ``size`` centred at ``position`` (checked as a
        world file's box is; ``colour`` is a name or ``[r, g, b(, a)]``)."""
        box = check_box({"id": id, "size": size, "position": position, "yaw": yaw, "colour": colour,
                         "mass": mass}, self.path)
        if id in self.bodies:
            self._fail("duplicate body id", id)
        p = self.p
        half = [s / 2 for s in box["size"]]
        shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=self.client)
        visual = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=box["colour"],
                                     physicsClientId=self.client)
        body = p.createMultiBody(box["mass"], shape, visual, box["position"],
                                 p.getQuaternionFromEuler((0, 0, box["yaw"])), physicsClientId=self.client)
        self.bodies[id] = body
        return body

    def _add_grid(self, grid: dict[str, Any]) -> None:
        cell, height, rows = grid["cell"], grid["height"], grid["rows"]
        ox, oy = grid["origin"]
        for r, row in enumerate(rows):
            y = oy + (len(rows) - r - 0.5) * cell
            c = 0
            while c < len(row):  # merge runs of occupied cells into one box per run
                if row[c] != "#":
                    c += 1
                    continue
                start = c
                while c < len(row) and row[c] == "#":
                    c += 1
                x = ox + (start + c) / 2 * cell
                self.add_box(f"grid_{r}_{start}", ((c - start) * cell, cell, height), (x, y, height / 2),
                             colour=grid["colour"])

    def _add_robot(self, robot: dict[str, Any]) -> None:
        x, y = robot["position"]
        body = self._load_urdf(robot["urdf"], (x, y, robot["z"]), robot["yaw"], roll=robot["roll"],
                               pitch=robot["pitch"])
        self.bodies[robot["id"]] = body
        self.agents[robot["agent"]] = robot["id"]
        if "colour" in robot:
            self.p.changeVisualShape(body, -1, rgbaColor=robot["colour"], physicsClientId=self.client)

    def _add_camera(self, camera: dict[str, Any]) -> None:
        self.cameras[camera["id"]] = Camera(self, camera["id"], camera["position"], camera["target"], camera["up"],
                                            camera["fov"], camera["width"], camera["height"])

    # Running ------------------------------------------------------------------------
    def step(self) -> None:
        """Advance physics by one ``dt``."""
        self.p.stepSimulation(physicsClientId=self.client)
        self.steps += 1

    @property
    def time(self) -> float:
        """Simulated seconds stepped so far."""
        return self.steps * self.dt

    def body(self, name: str) -> int:
        """The pybullet body id of a body or of an agent's robot."""
        name = self.agents.get(name, name)
        if name not in self.bodies:
            raise NetFormatError(f"world has no body or agent {name!r}{did_you_mean(name, self.bodies)}",
                                 path=self.path)
        return self.bodies[name]

    def pose(self, name: str) -> tuple[float, float, float]:
        """``(x, y, yaw)`` of a body or agent's robot."""
        position, orientation = self.p.getBasePositionAndOrientation(self.body(name), physicsClientId=self.client)
        yaw = self.p.getEulerFromQuaternion(orientation)[2]
        return (position[0], position[1], yaw)

    def position(self, agent: str) -> tuple[float, float] | None:
        """``(x, y)`` of an agent's robot, or ``None`` if the agent has no body."""
        name = self.agents.get(agent, agent)
        if name not in self.bodies:
            return None
        x, y, _ = self.pose(name)
        return (x, y)

    def distance(self, a: str, b: str) -> float | None:
        """Distance in metres between two agents' robots (``None`` if either has none)."""
        pa, pb = self.position(a), self.position(b)
        if pa is None or pb is None:
            return None
        return math.hypot(pa[0] - pb[0], pa[1] - pb[1])

    def remove(self, name: str) -> None:
        """Take a body (or an agent's robot) out of the scene, e.g. a robot a scenario
        does not deploy; the agent then has no body (:meth:`position` is ``None``)."""
        body = self.body(name)
        name = self.agents.get(name, name)
        self.p.removeBody(body, physicsClientId=self.client)
        del self.bodies[name]
        for agent in [a for a, b in self.agents.items() if b == name]:
            del self.agents[agent]

    def camera(self, name: str = "camera") -> Camera:
        """A camera by id."""
        if name not in self.cameras:
            raise NetFormatError(f"world has no camera {name!r}{did_you_mean(name, self.cameras)}",
                                 path=self.path)
        return self.cameras[name]

    def close(self) -> None:
        """Disconnect from pybullet."""
        try:
            self.p.disconnect(physicsClientId=self.client)
        except self.p.error:
            pass


def load_world(path: str | Path, gui: bool = False) -> World:
    """Build a :class:`World` from a YAML description file (safe loader)."""
    from petriflow.io.files import read_yaml_file

    path = Path(path)
    data = read_yaml_file(path)
    if data is not None and not isinstance(data, dict):
        raise NetFormatError("a world description is a mapping", path=str(path))
    return World(data, base=path.parent, gui=gui, path=str(path))
