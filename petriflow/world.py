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
    meta: {}                 # scenario settings: sections the actions declare and read
    cameras:
      - {id: top, position: [0, 0, 6], target: [0, 0, 0], up: [0, 1, 0], fov: 60,
         width: 640, height: 480}
    mode: dynamic            # or kinematic (below)

**Kinematic mode** (``mode: kinematic``): robots are bodies without mass whose poses
the world holds in numpy arrays and integrates together at each step from the
velocities actions command (:meth:`World.command`; a robot's ``drive`` is ``diff``,
``unicycle`` or ``holonomic``). A pose is written back to pybullet only when
something reads pybullet (a ray test that may hit robots, a camera, :meth:`World.sync`
for code that calls pybullet itself) or for drawing in the GUI, and
``stepSimulation`` runs only when a body still has dynamics (a robot with
``motion: dynamic``, a box with mass): legged and chain robots keep full dynamics in
a kinematic world. While nothing has read them, the robots' bodies are out of the
scene's way: at the first ray test that sees the scene only, in a world with nothing
to step and no GUI, they are **parked**, each on its own spot of a lot far below and
beside the scene (a ray test walks pybullet's tree of bounding boxes, robots it then
leaves out included, so bodies near the rays cost every ray), and the first
:meth:`World.sync` puts them back where the arrays say (after which they stay).

**Sensors on demand**: :meth:`World.request_rays` records rays an action asks for; the
world casts every request of a tick in one ``rayTestBatch`` at its next step (or at
:meth:`World.flush_sensors`), and the request then holds the hits.

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
from petriflow.worldfile import COLOURS, DRIVES, WorldDescription, check_box, check_world

__all__ = ["World", "Camera", "RayRequest", "load_world", "COLOURS", "DRIVES", "ROBOT_GROUP"]

#: The collision filter group of kinematic robots: ray tests that should see only the
#: scene (walls, boxes) leave it out of their mask.
ROBOT_GROUP = 1 << 5
#: Where parked kinematic robots' bodies start (metres): far below and beside any scene.
_LOT = (-1.0e4, -1.0e4, -1.0e3)
#: Rays per ``rayTestBatch`` call (pybullet's own limit is 16,384).
_RAY_BATCH = 16384


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

        self.world.sync()
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


class RayRequest:
    """Rays an action asked for (:meth:`World.request_rays`): ``hits`` is ``None`` until
    the world casts them, then one ``(body, fraction, (x, y, z))`` per ray (body ``-1``
    and fraction ``1.0`` for a ray that hits nothing)."""

    __slots__ = ("starts", "ends", "robots", "hits")

    def __init__(self, starts: list, ends: list, robots: bool) -> None:
        self.starts = starts
        self.ends = ends
        self.robots = robots
        self.hits: list[tuple[int, float, tuple[float, float, float]]] | None = None

    @property
    def ready(self) -> bool:
        """Whether the rays were cast."""
        return self.hits is not None


class World:
    """A pybullet physics client built from a description.

    It provides every capability of :mod:`petriflow.capabilities` (poses, bodies, ray
    tests, cameras, kinematic drive, physics, a world file's ``meta``), so any action
    may declare them for a run over a world file.

    Args:
        description: the world as plain data (see the module docstring).
        base: folder that relative URDF paths start from.
        gui: open pybullet's GUI instead of DIRECT mode.
        path: the description's file, named in errors.
    """

    #: Seconds per physics step.
    dt: float
    #: The pybullet module, and this world's physics client.
    p: Any
    client: int
    #: ``{body name: pybullet body id}`` and ``{agent: its robot's body name}``.
    bodies: dict[str, int]
    agents: dict[str, str]
    #: ``{camera id: Camera}``.
    cameras: dict[str, Camera]
    #: The description's ``meta``: scenario settings, read through declared sections
    #: (:mod:`petriflow.runtime.settings`).
    meta: dict[str, Any]
    #: The description's file (``None``: built in code).
    path: str | None
    #: ``dynamic`` or ``kinematic`` (see the module).
    mode: str
    #: ``(robots, 3)``: the kinematic robots' ``x, y, yaw``, one row each.
    poses: Any

    def __init__(self, description: dict[str, Any] | None = None, *, base: str | Path = ".",
                 gui: bool = False, path: str | None = None) -> None:
        self.path = path
        self.base = Path(base)
        if not isinstance(description, WorldDescription):  # every field, before pybullet is touched
            description = check_world(description, path)
        self.p = _pybullet()
        self.dt = description["dt"]
        self.meta = dict(description["meta"])
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
        #: ``dynamic`` or ``kinematic`` (see the module).
        self.mode: str = description["mode"]
        self._kin: dict[str, int] = {}          # kinematic robot's body id -> row of the arrays
        self._kin_rows: list[dict[str, Any]] = []
        self._dynamic = 0                       # bodies pybullet must step (mass > 0)
        self._commanded: dict[int, tuple[float, float, float]] = {}  # dynamic bodies driven by velocity
        self._requests: list[RayRequest] = []
        self._gui = gui
        self._parked = False                    # kinematic robots' bodies on the lot (see the module)
        self._stay = description["mode"] != "kinematic" or gui  # robots stay in the scene
        if description["plane"]:
            self.bodies["plane"] = self._load_urdf("pybullet_data:plane.urdf", (0, 0, 0), 0.0, fixed=True)
        for box in description["boxes"]:
            self._box(box)
        if description["grid"]:
            self._add_grid(description["grid"])
        for robot in description["robots"]:
            self._add_robot(robot)
        for camera in description["cameras"]:
            self._add_camera(camera)
        self._arrays()

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
        return self._box(check_box({"id": id, "size": size, "position": position, "yaw": yaw, "colour": colour,
                                    "mass": mass}, self.path))

    def _box(self, box: dict[str, Any]) -> int:
        """Add a checked box (:func:`~petriflow.worldfile.check_box`'s output)."""
        id = box["id"]
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
        self._dynamic += box["mass"] > 0
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
                self._box({"id": f"grid_{r}_{start}", "size": (float((c - start) * cell), float(cell), float(height)),
                           "position": (float(x), float(y), float(height / 2)), "yaw": 0.0, "colour": grid["colour"],
                           "mass": 0.0})

    def _add_robot(self, robot: dict[str, Any]) -> None:
        x, y = robot["position"]
        body = self._load_urdf(robot["urdf"], (x, y, robot["z"]), robot["yaw"], roll=robot["roll"],
                               pitch=robot["pitch"])
        self.bodies[robot["id"]] = body
        self.agents[robot["agent"]] = robot["id"]
        if "colour" in robot:
            self.p.changeVisualShape(body, -1, rgbaColor=robot["colour"], physicsClientId=self.client)
        if robot.get("motion", "dynamic") == "kinematic":
            p, client = self.p, self.client
            for link in range(-1, p.getNumJoints(body, physicsClientId=client)):
                # no mass: pybullet never integrates it; its own group: scene-only rays skip it
                p.changeDynamics(body, link, mass=0.0, physicsClientId=client)
                p.setCollisionFilterGroupMask(body, link, ROBOT_GROUP, 0xFFFF, physicsClientId=client)
            self._kin[body] = len(self._kin_rows)
            # pybullet places a body by its base's centre of mass: the base link's frame to it
            inertial = p.getDynamicsInfo(body, -1, physicsClientId=client)[3:5]
            self._kin_rows.append({"body": body, "x": x, "y": y, "yaw": robot["yaw"], "z": robot["z"],
                                   "roll": robot["roll"], "pitch": robot["pitch"], "inertial": inertial,
                                   "drive": DRIVES.index(robot.get("drive", "diff"))})
        else:
            self._dynamic += 1

    def _arrays(self) -> None:
        """The kinematic robots' poses and commands as arrays (one row per robot)."""
        import numpy as np

        rows = self._kin_rows
        #: ``(N, 3)`` x, y, yaw of the kinematic robots (row order: :attr:`kinematic_bodies`).
        self.poses = np.array([[r["x"], r["y"], r["yaw"]] for r in rows], dtype=float).reshape(-1, 3)
        #: ``(N, 3)`` commanded forward speed (m/s), sideways speed (m/s), turn rate (rad/s).
        self.velocities = np.zeros((len(rows), 3))
        self._z = np.array([r["z"] for r in rows], dtype=float)
        self._tilt = [(r["roll"], r["pitch"]) for r in rows]
        self._inertial = [r["inertial"] for r in rows]
        self._drive = np.array([r["drive"] for r in rows], dtype=np.int8)
        self._live = np.ones(len(rows), dtype=bool)
        self._moving = np.zeros(len(rows), dtype=bool)
        self._stale = np.zeros(len(rows), dtype=bool)      # pose changed since written to pybullet
        #: pybullet body ids of the kinematic robots, in row order.
        self.kinematic_bodies = [r["body"] for r in rows]
        del self._kin_rows
    def _add_camera(self, camera: dict[str, Any]) -> None:
        self.cameras[camera["id"]] = Camera(self, camera["id"], camera["position"], camera["target"], camera["up"],
                                            camera["fov"], camera["width"], camera["height"])

    # Running ------------------------------------------------------------------------
    def step(self) -> None:
        """Advance the world by one ``dt``: cast the rays asked for since the last step
        (at the poses they were asked at), move the kinematic robots, and step pybullet
        when a body has dynamics (always in the dynamic mode)."""
        if self._requests:
            self.flush_sensors()
        if self._moving.any():
            self._integrate(self.dt)
        if self._commanded:
            self._apply_commands()
        if self.mode == "dynamic" or self._dynamic:
            if self._parked:  # a body with mass added since: it meets the robots where they are
                self.sync()
            self.p.stepSimulation(physicsClientId=self.client)
        if self._gui:
            self.sync()
        self.steps += 1

    # Kinematic robots ---------------------------------------------------------------
    @property
    def active(self):
        """``(N,)`` booleans: which kinematic robots are in the scene (not removed)."""
        return self._live

    def is_kinematic(self, name: str) -> bool:
        """Whether a body (or an agent's robot) moves kinematically."""
        return self.body(name) in self._kin

    def row(self, name: str) -> int:
        """A kinematic robot's row in :attr:`poses` and :attr:`velocities`.

        Raises:
            PetriflowError: the body is not a kinematic robot.
        """
        row = self._kin.get(self.body(name))
        if row is None:
            raise PetriflowError(f"{name!r} is not a kinematic robot (its world's mode is {self.mode})")
        return row

    def command(self, name: str, v: float = 0.0, w: float = 0.0, vy: float = 0.0) -> None:
        """Drive a robot at forward speed ``v`` (m/s), turn rate ``w`` (rad/s) and, for a
        ``holonomic`` drive, sideways speed ``vy`` (m/s), until the next command. A
        kinematic robot is moved by the world's integration; a dynamic body gets the
        velocity before each physics step (it still collides and, on a floor, rubs)."""
        body = self.body(name)
        row = self._kin.get(body)
        if row is None:
            if not (v or w or vy):
                self._commanded.pop(body, None)
                self.p.resetBaseVelocity(body, (0, 0, 0), (0, 0, 0), physicsClientId=self.client)
                return
            if body not in self._commanded:
                self.p.changeDynamics(body, -1, linearDamping=0.0, angularDamping=0.0, physicsClientId=self.client)
            self._commanded[body] = (float(v), float(vy), float(w))
            return
        if vy and self._drive[row] != DRIVES.index("holonomic"):
            raise PetriflowError(f"{name!r} has a {DRIVES[self._drive[row]]} drive: it cannot move sideways")
        self.velocities[row] = (v, vy, w)
        self._moving[row] = bool(v or w or vy) and self._live[row]

    def set_pose(self, name: str, x: float, y: float, yaw: float) -> None:
        """Put a kinematic robot at ``(x, y, yaw)`` (written to pybullet when read)."""
        row = self.row(name)
        self.poses[row] = (x, y, yaw)
        self._stale[row] = True

    def _integrate(self, dt: float) -> None:
        """Every moving kinematic robot's pose after ``dt`` at its commanded velocity: the
        exact arc for constant speeds (one formula for all drives: a holonomic robot's
        body-frame velocity turns with it)."""
        import numpy as np

        rows = np.flatnonzero(self._moving)
        x, y, th = self.poses[rows, 0], self.poses[rows, 1], self.poses[rows, 2]
        v, vy, w = self.velocities[rows, 0], self.velocities[rows, 1], self.velocities[rows, 2]
        th1 = th + w * dt
        turning = np.abs(w) > 1e-12
        safe = np.where(turning, w, 1.0)
        # integrals of cos and sin of the heading over the step
        ic = np.where(turning, (np.sin(th1) - np.sin(th)) / safe, np.cos(th) * dt)
        is_ = np.where(turning, (np.cos(th) - np.cos(th1)) / safe, np.sin(th) * dt)
        self.poses[rows, 0] = x + v * ic - vy * is_
        self.poses[rows, 1] = y + v * is_ + vy * ic
        self.poses[rows, 2] = np.arctan2(np.sin(th1), np.cos(th1))
        self._stale[rows] = True

    def _apply_commands(self) -> None:
        """Dynamic bodies driven by :meth:`command`: the world-frame velocity along the
        step's mean heading (the chord of the arc the kinematic mode follows)."""
        p, client = self.p, self.client
        for body, (v, vy, w) in self._commanded.items():
            _, orientation = p.getBasePositionAndOrientation(body, physicsClientId=client)
            yaw = p.getEulerFromQuaternion(orientation)[2]
            half = w * self.dt / 2
            scale = math.sin(half) / half if abs(half) > 1e-12 else 1.0  # chord over arc
            mid = yaw + half
            c, s = math.cos(mid), math.sin(mid)
            p.resetBaseVelocity(body, ((v * c - vy * s) * scale, (v * s + vy * c) * scale, 0.0), (0.0, 0.0, w),
                                physicsClientId=client)

    def sync(self) -> None:
        """Write the kinematic robots' poses that changed to pybullet (what reads
        pybullet directly needs first; ray tests that see robots, cameras and the GUI
        call it themselves)."""
        import numpy as np

        self._stay = True
        if self._parked:  # every robot back from the lot
            self._parked = False
            self._stale[:] = True
        rows = np.flatnonzero(self._stale & self._live)
        if not len(rows):
            return
        p, client = self.p, self.client
        for row in rows.tolist():
            x, y, yaw = self.poses[row]
            roll, pitch = self._tilt[row]
            at, turned = p.multiplyTransforms((x, y, self._z[row]), p.getQuaternionFromEuler((roll, pitch, yaw)),
                                              *self._inertial[row])
            p.resetBasePositionAndOrientation(self.kinematic_bodies[row], at, turned, physicsClientId=client)
        self._stale[rows] = False

    def _park(self) -> None:
        """The kinematic robots' bodies to the lot (see the module), if nothing can
        need them where they are: no GUI, nothing to step."""
        import numpy as np

        live = np.flatnonzero(self._live).tolist()
        if self._dynamic or not live:
            self._stay = True
            return
        p, client = self.p, self.client
        extent = 1.0
        for row in live:  # the lot's spots apart by the largest body: parked bodies never overlap
            body = self.kinematic_bodies[row]
            for link in range(-1, p.getNumJoints(body, physicsClientId=client)):
                low, high = p.getAABB(body, link, physicsClientId=client)
                extent = max(extent, *(b - a for a, b in zip(low, high)))
        spacing, side = 2.0 * extent, math.ceil(math.sqrt(len(live)))
        x0, y0, z0 = _LOT
        for k, row in enumerate(live):
            p.resetBasePositionAndOrientation(self.kinematic_bodies[row],
                                              (x0 - spacing * (k % side), y0 - spacing * (k // side), z0),
                                              (0.0, 0.0, 0.0, 1.0), physicsClientId=client)
        self._parked = True

    # Sensors ------------------------------------------------------------------------
    def rays(self, starts, ends, *, robots: bool = True) -> list[tuple[int, float, tuple[float, float, float]]]:
        """Cast rays now, in batches of pybullet's ``rayTestBatch``: one ``(body,
        fraction, (x, y, z))`` per ray. ``robots=False`` leaves kinematic robots out (the
        rays see the scene only, and no pose needs writing back)."""
        if robots:
            self.sync()
        elif not self._stay and not self._parked:
            self._park()
        p = self.p
        mask = 0xFFFF & ~ROBOT_GROUP if not robots else 0xFFFF
        out: list[tuple[int, float, tuple[float, float, float]]] = []
        starts, ends = list(starts), list(ends)
        if len(starts) != len(ends):
            raise PetriflowError(f"{len(starts)} ray starts but {len(ends)} ray ends")
        for first in range(0, len(starts), _RAY_BATCH):
            batch = p.rayTestBatch(starts[first:first + _RAY_BATCH], ends[first:first + _RAY_BATCH],
                                   collisionFilterMask=mask, physicsClientId=self.client)
            out.extend((hit[0], hit[2], hit[3]) for hit in batch)
        return out

    def request_rays(self, starts, ends, *, robots: bool = False) -> RayRequest:
        """Ask for rays (a sensor event): they are cast with every other request of this
        tick in one batch at the world's next step (or :meth:`flush_sensors`), at the
        poses of now; the returned request then holds the hits."""
        request = RayRequest([tuple(map(float, s)) for s in starts], [tuple(map(float, e)) for e in ends],
                             robots)
        if len(request.starts) != len(request.ends):
            raise PetriflowError(f"{len(request.starts)} ray starts but {len(request.ends)} ray ends")
        self._requests.append(request)
        return request

    def flush_sensors(self) -> int:
        """Cast every pending ray request now, one batch for those that see robots and
        one for those that see the scene only; returns the number of rays cast."""
        pending, self._requests = self._requests, []
        cast = 0
        for robots in (False, True):
            group = [r for r in pending if r.robots == robots]
            if not group:
                continue
            starts = [s for r in group for s in r.starts]
            ends = [e for r in group for e in r.ends]
            hits = self.rays(starts, ends, robots=robots)
            cast += len(hits)
            at = 0
            for request in group:
                request.hits = hits[at:at + len(request.starts)]
                at += len(request.starts)
        return cast

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
        body = self.body(name)
        row = self._kin.get(body)
        if row is not None:
            x, y, yaw = self.poses[row].tolist()
            return (x, y, yaw)
        position, orientation = self.p.getBasePositionAndOrientation(body, physicsClientId=self.client)
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
        row = self._kin.pop(body, None)
        if row is not None:
            self._live[row] = self._moving[row] = self._stale[row] = False
        self._commanded.pop(body, None)
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
