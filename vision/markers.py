"""Marker robots for the overhead camera: a colour patch carrying a black and a white disc.

The SMART robots (seed 003, §2.4) are told apart by colour and carry two discs, one
black and one white, whose midpoint is the robot's position and whose joining segment,
turned by 90°, is its heading. This module builds such markers out of pybullet
primitives so that the vision can be tested on rendered frames:

* :func:`add_marker_robot` adds a stand-in robot: a coloured box (side ``L``) with the
  two discs on its top face, as one static multibody that :func:`move_marker_robot`
  teleports;
* :func:`attach_markers` decorates an existing body (a real robot's base or any link)
  with a *marker hat*: an optional coloured plate plus the two discs, as a separate,
  light, collision-free body held on the link by a fixed constraint, so it follows the
  robot while the physics steps; :meth:`MarkerHat.sync` snaps it exactly onto the
  link (after a teleport, or when the world is not stepped);
* :func:`white_floor` makes the ground plane plain white (the paper's floor) instead
  of pybullet's checker texture;
* :class:`MarkerScene` is a ready test arena: white floor, four marker robots (red,
  blue, yellow, green), black box obstacles and a top-down camera.

Convention (used by :mod:`petriflow.vision.pose`): in the robot's own frame (x
forward, y left) the black disc is at ``(0, +offset)`` and the white disc at
``(0, -offset)``. Looking along the heading, black is on the left and white on the
right; the heading is the direction black → white turned by +90° (counter-clockwise
seen from above).

Examples:
    >>> from petriflow.world import World
    >>> world = World({"plane": False})
    >>> body = add_marker_robot(world, "red", 0.5, -0.2, yaw=1.0)
    >>> x, y, yaw = world.pose(body)
    >>> round(x, 3), round(y, 3), round(yaw, 3)
    (0.5, -0.2, 1.0)
    >>> world.close()
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

__all__ = [
    "MarkerGeometry",
    "DEFAULT_GEOMETRY",
    "ROBOT_COLOURS",
    "add_marker_robot",
    "move_marker_robot",
    "attach_markers",
    "markers_on",
    "MarkerHat",
    "white_floor",
    "MarkerScene",
]

#: The robots' colours in label order (label 2, 3, 4, 5 of the grey map).
ROBOT_COLOURS = ("red", "blue", "yellow", "green")


@dataclass(frozen=True)
class MarkerGeometry:
    """Sizes of a marker robot, in metres.

    Attributes:
        side: side ``L`` of the coloured square (the robot's footprint in the map).
        height: height of the coloured box (its top face carries the discs).
        disc_radius: radius of each disc.
        disc_offset: distance from the robot centre to each disc centre.
        disc_thickness: thickness of the discs.
    """

    side: float = 0.26
    height: float = 0.10
    disc_radius: float = 0.035
    disc_offset: float = 0.055
    disc_thickness: float = 0.004

    @property
    def marker_z(self) -> float:
        """Height of the discs' top faces above the box's bottom (the plane the camera reads).

        Examples:
            >>> round(MarkerGeometry().marker_z, 3)
            0.104
        """
        return round(self.height + self.disc_thickness, 9)

    def check(self) -> None:
        """Raise ``ValueError`` if the discs overlap or do not fit inside the square.

        The vision finds the discs as holes in the robot's colour blob, so each disc
        must be surrounded by colour.

        Examples:
            >>> MarkerGeometry(disc_offset=0.02).check()
            Traceback (most recent call last):
            ...
            ValueError: the discs overlap: offset 0.02 <= radius 0.035
        """
        if self.disc_offset <= self.disc_radius:
            raise ValueError(f"the discs overlap: offset {self.disc_offset} <= radius {self.disc_radius}")
        if self.disc_offset + self.disc_radius >= self.side / 2:
            raise ValueError("the discs must lie inside the coloured square")


DEFAULT_GEOMETRY = MarkerGeometry()
_PLATE = 0.002  # thickness of a marker hat's colour plate (m)


def _rgba(colour: Any) -> tuple[float, float, float, float]:
    from petriflow.world import COLOURS

    if isinstance(colour, str):
        if colour not in COLOURS:
            raise ValueError(f"unknown colour {colour!r}; one of {sorted(COLOURS)}")
        return tuple(COLOURS[colour])  # type: ignore[return-value]
    values = tuple(float(c) for c in colour)
    if len(values) == 3:
        values += (1.0,)
    if len(values) != 4:
        raise ValueError(f"a colour is a name or (r, g, b[, a]), got {colour!r}")
    return values  # type: ignore[return-value]


def _disc_links(world: Any, geometry: MarkerGeometry, z: float, mass: float) -> dict[str, list]:
    """createMultiBody keyword arguments for the two disc links at height ``z`` (their centre)."""
    p, client = world.p, world.client
    shapes = [
        p.createVisualShape(p.GEOM_CYLINDER, radius=geometry.disc_radius, length=geometry.disc_thickness,
                            rgbaColor=_rgba(name), physicsClientId=client)
        for name in ("black", "white")
    ]
    return {
        "linkMasses": [mass, mass],
        "linkCollisionShapeIndices": [-1, -1],
        "linkVisualShapeIndices": shapes,
        "linkPositions": [[0.0, geometry.disc_offset, z], [0.0, -geometry.disc_offset, z]],
        "linkOrientations": [[0, 0, 0, 1], [0, 0, 0, 1]],
        "linkInertialFramePositions": [[0, 0, 0], [0, 0, 0]],
        "linkInertialFrameOrientations": [[0, 0, 0, 1], [0, 0, 0, 1]],
        "linkParentIndices": [0, 0],
        "linkJointTypes": [p.JOINT_FIXED, p.JOINT_FIXED],
        "linkJointAxis": [[0, 0, 1], [0, 0, 1]],
    }


def add_marker_robot(world: Any, colour: Any, x: float, y: float, yaw: float = 0.0, *,
                     id: str | None = None, geometry: MarkerGeometry = DEFAULT_GEOMETRY,
                     z: float = 0.0) -> str:
    """Add a stand-in robot: a coloured box with a black and a white disc on top.

    The robot is one static (mass 0) multibody whose base frame is the box centre; it
    collides like a box and is moved with :func:`move_marker_robot`.

    Args:
        world: a :class:`petriflow.world.World`.
        colour: a name of :data:`petriflow.world.COLOURS` or ``(r, g, b[, a])``.
        x: position of the robot centre (m).
        y: position of the robot centre (m).
        yaw: heading (rad, counter-clockwise from +x).
        id: its name in ``world.bodies`` (default: ``marker_<colour>``).
        geometry: the sizes.
        z: height of the box's bottom face (the floor's top).

    Returns:
        The body's name in ``world.bodies`` (``world.pose(name)`` is its ground truth).

    Examples:
        >>> from petriflow.world import World
        >>> world = World({"plane": False})
        >>> add_marker_robot(world, "blue", 0.0, 0.0)
        'marker_blue'
        >>> world.close()
    """
    geometry.check()
    p, client = world.p, world.client
    name = id or f"marker_{colour if isinstance(colour, str) else len(world.bodies)}"
    if name in world.bodies:
        raise ValueError(f"duplicate body id {name!r}")
    half = [geometry.side / 2, geometry.side / 2, geometry.height / 2]
    collision = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
    visual = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=_rgba(colour),
                                 physicsClientId=client)
    links = _disc_links(world, geometry, geometry.height / 2 + geometry.disc_thickness / 2, 0.0)
    body = p.createMultiBody(0.0, collision, visual, [x, y, z + geometry.height / 2],
                             p.getQuaternionFromEuler((0, 0, yaw)), physicsClientId=client, **links)
    world.bodies[name] = body
    return name


def move_marker_robot(world: Any, name: str, x: float, y: float, yaw: float = 0.0) -> None:
    """Teleport a robot made by :func:`add_marker_robot` to ``(x, y, yaw)``, keeping its height.

    Examples:
        >>> from petriflow.world import World
        >>> world = World({"plane": False})
        >>> name = add_marker_robot(world, "green", 0.0, 0.0)
        >>> move_marker_robot(world, name, 1.0, 2.0, -0.5)
        >>> [round(v, 3) for v in world.pose(name)]
        [1.0, 2.0, -0.5]
        >>> world.close()
    """
    p, client, body = world.p, world.client, world.body(name)
    z = p.getBasePositionAndOrientation(body, physicsClientId=client)[0][2]
    p.resetBasePositionAndOrientation(body, [x, y, z], p.getQuaternionFromEuler((0, 0, yaw)),
                                      physicsClientId=client)


@dataclass
class MarkerHat:
    """Marker discs (and an optional colour plate) fixed on another body's link.

    Attributes:
        world: the world.
        body: pybullet id of the hat.
        parent: pybullet id of the decorated body.
        link: the decorated link (``-1``: the base).
        offset: hat position in the link's frame (its centre of mass frame, as pybullet
            constraints use), metres.
        yaw: hat rotation about the link's z axis (rad): the robot's forward axis in
            the link frame.
        constraint: the fixed constraint's id.
        geometry: the sizes.
    """

    world: Any
    body: int
    parent: int
    link: int
    offset: tuple[float, float, float]
    yaw: float
    constraint: int
    geometry: MarkerGeometry = field(default=DEFAULT_GEOMETRY)

    def _link_frame(self):
        p, client = self.world.p, self.world.client
        if self.link == -1:
            return p.getBasePositionAndOrientation(self.parent, physicsClientId=client)
        state = p.getLinkState(self.parent, self.link, computeForwardKinematics=1, physicsClientId=client)
        return state[0], state[1]

    def sync(self) -> None:
        """Snap the hat exactly onto its link (no physics step needed)."""
        p, client = self.world.p, self.world.client
        position, orientation = self._link_frame()
        position, orientation = p.multiplyTransforms(position, orientation, self.offset,
                                                     p.getQuaternionFromEuler((0, 0, self.yaw)))
        p.resetBasePositionAndOrientation(self.body, position, orientation, physicsClientId=client)
        p.resetBaseVelocity(self.body, [0, 0, 0], [0, 0, 0], physicsClientId=client)

    def pose(self) -> tuple[float, float, float]:
        """``(x, y, yaw)`` of the hat: where the vision should see the robot."""
        p, client = self.world.p, self.world.client
        position, orientation = p.getBasePositionAndOrientation(self.body, physicsClientId=client)
        return position[0], position[1], p.getEulerFromQuaternion(orientation)[2]

    @property
    def marker_z(self) -> float:
        """World height of the discs' top faces now (``vision.locate``'s ``marker_z``)."""
        p, client = self.world.p, self.world.client
        z = p.getBasePositionAndOrientation(self.body, physicsClientId=client)[0][2]
        return z + _PLATE / 2 + self.geometry.disc_thickness

    def remove(self) -> None:
        """Take the hat off."""
        p, client = self.world.p, self.world.client
        p.removeConstraint(self.constraint, physicsClientId=client)
        p.removeBody(self.body, physicsClientId=client)


def attach_markers(world: Any, body: int | str, link: int = -1, *, colour: Any = None,
                   offset: Sequence[float] | None = None, yaw: float = 0.0,
                   geometry: MarkerGeometry = DEFAULT_GEOMETRY, mass: float = 1e-3) -> MarkerHat:
    """Put a marker hat on an existing body's link.

    The hat is a separate multibody with no collision shape and a tiny mass, held by a
    fixed constraint (``JOINT_FIXED``), so it moves with the link while the world
    steps and does not disturb the robot. Its base is a coloured plate of side
    ``geometry.side`` (when ``colour`` is given) under the two discs; without a plate,
    the link itself must be that colour all around the discs, since the vision finds
    the discs as holes in the colour blob.

    Args:
        world: the :class:`petriflow.world.World`.
        body: a body name (``world.body`` resolves agents too) or pybullet id.
        link: the link to decorate (``-1``: the base).
        colour: colour of the plate; ``None`` for no plate.
        offset: hat position in the link's centre-of-mass frame; default: centred, just
            above the link's bounding box.
        yaw: rotation of the hat about the link's z axis (the robot's forward direction).
        geometry: the sizes (``height`` is unused; the plate is 2 mm thick).
        mass: mass of each part of the hat (kg).

    Examples:
        >>> from petriflow.world import World
        >>> world = World({"plane": False, "gravity": 0})
        >>> crate = world.add_box("crate", [0.3, 0.3, 0.2], [1.0, 0.0, 0.1], mass=1.0)
        >>> hat = attach_markers(world, "crate", colour="yellow")
        >>> for _ in range(10):
        ...     world.step()
        >>> [round(v, 3) for v in hat.pose()]
        [1.0, 0.0, 0.0]
        >>> world.close()
    """
    geometry.check()
    p, client = world.p, world.client
    parent = world.body(body) if isinstance(body, str) else int(body)
    if offset is None:
        if link == -1:
            position, _ = p.getBasePositionAndOrientation(parent, physicsClientId=client)
        else:
            position = p.getLinkState(parent, link, computeForwardKinematics=1, physicsClientId=client)[0]
        top = p.getAABB(parent, link, physicsClientId=client)[1][2]
        offset = (0.0, 0.0, top - position[2] + 0.001)
    offset = tuple(float(v) for v in offset)
    plate = _PLATE
    visual = -1
    if colour is not None:
        half = [geometry.side / 2, geometry.side / 2, plate / 2]
        visual = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=_rgba(colour),
                                     physicsClientId=client)
    links = _disc_links(world, geometry, plate / 2 + geometry.disc_thickness / 2, mass)
    hat = p.createMultiBody(mass, -1, visual, [0, 0, 0], [0, 0, 0, 1], physicsClientId=client, **links)
    constraint = p.createConstraint(parent, link, hat, -1, p.JOINT_FIXED, [0, 0, 0], offset, [0, 0, 0],
                                    parentFrameOrientation=p.getQuaternionFromEuler((0, 0, yaw)),
                                    physicsClientId=client)
    p.changeConstraint(constraint, maxForce=1000.0, physicsClientId=client)
    marker = MarkerHat(world, hat, parent, link, offset, float(yaw), constraint, geometry)
    marker.sync()
    record = {"parent": parent, "link": link, "offset": list(offset), "yaw": float(yaw), "constraint": constraint,
              "geometry": dataclasses.asdict(geometry)}
    p.addUserData(hat, _HAT_KEY, json.dumps(record), physicsClientId=client)
    return marker


#: The user-data key under which a hat's pybullet body records what it is.
_HAT_KEY = "petriflow.marker_hat"


def markers_on(world: Any, body: int | str) -> list[MarkerHat]:
    """The marker hats fixed on ``body`` (a name or pybullet id), as
    :func:`attach_markers` put them: each hat records itself on its own pybullet body,
    so they are found in the scene, never in attributes kept beside it."""
    p, client = world.p, world.client
    parent = world.body(body) if isinstance(body, str) else int(body)
    found = []
    for index in range(p.getNumBodies(physicsClientId=client)):
        hat = p.getBodyUniqueId(index, physicsClientId=client)
        key = p.getUserDataId(hat, _HAT_KEY, physicsClientId=client)
        if key < 0:
            continue
        record = json.loads(p.getUserData(key, physicsClientId=client))
        if record["parent"] == parent:
            found.append(MarkerHat(world, hat, parent, record["link"], tuple(record["offset"]), record["yaw"],
                                   record["constraint"], MarkerGeometry(**record["geometry"])))
    return found


def white_floor(world: Any) -> None:
    """Make the ground plane plain white (no checker texture), as the paper's floor.

    Recolours the world's ``plane`` body; a world without one gets a large thin white
    box at z < 0 instead (its top face at z = 0).

    Examples:
        >>> from petriflow.world import World
        >>> world = World()
        >>> white_floor(world)
        >>> world.close()
    """
    p, client = world.p, world.client
    if "plane" in world.bodies:
        p.changeVisualShape(world.bodies["plane"], -1, textureUniqueId=-1, rgbaColor=[1, 1, 1, 1],
                            physicsClientId=client)
    else:
        world.add_box("floor", [40.0, 40.0, 0.01], [0.0, 0.0, -0.005], colour="white")


class MarkerScene:
    """A test arena: white floor, four marker robots, black obstacles, a top-down camera.

    Args:
        width: camera image width (pixels).
        height: camera image height (pixels).
        obstacles: number of black box obstacles.
        camera_height: height of the camera above the floor (m); at 3 m with a 60°
            vertical field of view the image covers about 4.6 m x 3.5 m.
        geometry: the marker robots' sizes.
        colours: the robots' colours.

    Attributes:
        world: the :class:`petriflow.world.World` (camera id ``"top"``).
        camera: its camera.
        robots: ``{colour: body name}``.
        truth: ``{colour: (x, y, yaw)}`` as last placed.

    Examples:
        >>> import random
        >>> scene = MarkerScene(64, 48, obstacles=2)
        >>> truth = scene.randomize(random.Random(1))
        >>> sorted(truth)
        ['blue', 'green', 'red', 'yellow']
        >>> scene.capture().shape
        (48, 64, 3)
        >>> scene.close()
    """

    #: Robots are placed inside ``|x| <= X_RANGE`` and ``|y| <= Y_RANGE`` (m).
    X_RANGE = 1.7
    Y_RANGE = 1.2
    #: Obstacle sizes (x, y, z) in metres.
    OBSTACLE_SIZES = ((0.4, 0.2, 0.15), (0.25, 0.25, 0.2), (0.6, 0.15, 0.1), (0.3, 0.4, 0.12),
                      (0.2, 0.5, 0.18), (0.35, 0.3, 0.08))

    def __init__(self, width: int = 640, height: int = 480, *, obstacles: int = 4,
                 camera_height: float = 3.0, geometry: MarkerGeometry = DEFAULT_GEOMETRY,
                 colours: Sequence[str] = ROBOT_COLOURS) -> None:
        from petriflow.world import World

        self.world = World({
            "gravity": 0.0,
            "cameras": [{"id": "top", "position": [0, 0, camera_height], "target": [0, 0, 0],
                         "up": [0, 1, 0], "fov": 60, "width": width, "height": height}],
        })
        white_floor(self.world)
        self.camera = self.world.camera("top")
        self.geometry = geometry
        self.robots: dict[str, str] = {}
        self.truth: dict[str, tuple[float, float, float]] = {}
        for i, colour in enumerate(colours):
            x = -1.2 + 0.8 * i
            self.robots[colour] = add_marker_robot(self.world, colour, x, 0.0, 0.0, geometry=geometry)
            self.truth[colour] = (x, 0.0, 0.0)
        self.obstacles: list[tuple[str, tuple[float, float, float]]] = []
        for i in range(obstacles):
            size = self.OBSTACLE_SIZES[i % len(self.OBSTACLE_SIZES)]
            name = f"obstacle_{i}"
            self.world.add_box(name, size, (-1.5 + 0.6 * i, 1.4, size[2] / 2), colour="black")
            self.obstacles.append((name, size))

    def place(self, poses: Mapping[str, tuple[float, float, float]],
              obstacles: Sequence[tuple[float, float, float]] = ()) -> None:
        """Move robots to ``{colour: (x, y, yaw)}`` and obstacles to ``[(x, y, yaw), ...]``."""
        for colour, (x, y, yaw) in poses.items():
            move_marker_robot(self.world, self.robots[colour], x, y, yaw)
            self.truth[colour] = (float(x), float(y), float(yaw))
        p, client = self.world.p, self.world.client
        for (name, size), (x, y, yaw) in zip(self.obstacles, obstacles):
            p.resetBasePositionAndOrientation(self.world.body(name), [x, y, size[2] / 2],
                                              p.getQuaternionFromEuler((0, 0, yaw)), physicsClientId=client)

    def randomize(self, rng: Any) -> dict[str, tuple[float, float, float]]:
        """Place robots and obstacles at random, apart from each other (``rng``: a ``random.Random``).

        Returns:
            The robots' true poses ``{colour: (x, y, yaw)}``.
        """
        clearance = self.geometry.side * 0.75 * 2 ** 0.5 + 0.1
        robots: dict[str, tuple[float, float, float]] = {}
        taken: list[tuple[float, float, float]] = []  # (x, y, radius)

        def free(x: float, y: float, radius: float) -> bool:
            return all(math.hypot(x - a, y - b) > radius + r for a, b, r in taken)

        for colour in self.robots:
            for _ in range(1000):
                x = rng.uniform(-self.X_RANGE, self.X_RANGE)
                y = rng.uniform(-self.Y_RANGE, self.Y_RANGE)
                if free(x, y, clearance / 2):
                    break
            robots[colour] = (x, y, rng.uniform(-math.pi, math.pi))
            taken.append((x, y, clearance / 2))
        obstacles = []
        for _, size in self.obstacles:
            radius = math.hypot(size[0], size[1]) / 2 + 0.05
            for _ in range(1000):
                x = rng.uniform(-self.X_RANGE - 0.2, self.X_RANGE + 0.2)
                y = rng.uniform(-self.Y_RANGE - 0.2, self.Y_RANGE + 0.2)
                if free(x, y, radius):
                    break
            obstacles.append((x, y, rng.uniform(-math.pi, math.pi)))
            taken.append((x, y, radius))
        self.place(robots, obstacles)
        return dict(robots)

    def capture(self):
        """Render the camera's frame (H x W x 3, uint8 RGB)."""
        return self.camera.capture()

    def close(self) -> None:
        """Disconnect the world."""
        self.world.close()
