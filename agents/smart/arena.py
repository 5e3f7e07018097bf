"""The SMART arena as the overhead camera sees it: a white floor and marker hats.

A SMART robot carries a colour patch with a black and a white disc (seed 003, §2.4);
the floor is white. A ``world.yaml`` says which robot wears which colour under its
``meta`` key (the world keeps that data and never reads it)::

    meta:
      smart:
        floor: white                     # the camera sees a plain white floor
        markers:                         # one marker hat per robot
          - {robot: robot3l, colour: yellow}
          - {robot: robot4l, colour: red}

:func:`dress` puts that on a world once: the floor turns white and each robot gets a
hat (:func:`petriflow.vision.markers.attach_markers`) centred over its body frame
just above its top plate, whatever pose the robot was loaded in (a fallen robot's
hat faces sideways with its plate). The hats are light, collision-free bodies held
by fixed constraints, so they follow the robots while the world steps; no per-step
call is needed (``bench/smart.py`` and the tests measure how closely they follow).
``smart.capture`` (``T0`` of ``nets/smart/smart.yaml``) dresses its world before the
first frame; tests and scripts call :func:`dress` or :func:`load_arena`.

``floor: white`` replaces pybullet's ground plane by an *unrendered* ground with the
same collision box and friction: pybullet's CPU renderer (TinyRenderer) clears every
frame to white (255, 255, 255), which the vision reads as floor like the paper's white
floor, and it spends about three quarters of a 640 x 480 frame rasterising a ground
that covers the image (measured: 110-125 ms a frame with the plane, 25-35 ms without,
the same scene). ``floor: painted`` keeps the plane and paints it white instead
(:func:`petriflow.vision.markers.white_floor`), the slower look-alike.

Examples:
    >>> from petriflow.world import World
    >>> world = World({"robots": [{"id": "cat", "urdf": "petriflow.agents.legged:robots/robot3l.urdf",
    ...                            "z": 0.08}],
    ...                "meta": {"smart": {"markers": [{"robot": "cat", "colour": "yellow"}]}}})
    >>> sorted(dress(world).hats)
    ['cat']
    >>> dress(world).hats["cat"].body == dress(world).hats["cat"].body   # once per world
    True
    >>> robot_colours(world)
    {'cat': 'yellow'}
    >>> world.close()
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from petriflow.capabilities import Bodies, Described, Physics, provides
from petriflow.runtime.settings import Section, Setting, world_section

__all__ = ["SMART", "Arena", "arena_resource", "arena_settings", "colour_robots", "dress", "hat_offset", "load_arena",
           "robot_colours", "unrendered_ground"]

#: The world file's ``meta.smart``: the floor the camera sees and the robots' hats.
SMART = Section("smart", {
    "floor": Setting((str, type(None)), None, "white (an unrendered ground), painted (the plane painted"
                     " white) or none (the floor as loaded)", choices=("white", "painted", None)),
    "markers": Setting(list, [], "one marker hat per robot", items=Setting(dict, doc="a robot's hat", fields={
        "robot": Setting(str, doc="the robot's body name"),
        "colour": Setting(str, doc="the hat's colour (vision.segment's labels)"),
    })),
}, doc="the SMART arena: the floor and the robots' marker hats")


@dataclass
class Arena:
    """What :func:`dress` put on a world.

    Attributes:
        hats: ``{robot body name: MarkerHat}``.
        colours: ``{robot body name: colour}``.
        floor: the floor colour applied (``None``: left as it was).
    """

    hats: dict[str, Any] = field(default_factory=dict)
    colours: dict[str, str] = field(default_factory=dict)
    floor: str | None = None


def arena_settings(world: Described) -> dict[str, Any]:
    """The world's ``meta.smart`` (:data:`SMART`) read and checked, defaults filled in:
    what a run gives its actions as ``ctx.settings`` (errors at the world file's line)."""
    return world_section(world, SMART)


def robot_colours(world: Described, settings: Mapping[str, Any] | None = None) -> dict[str, str]:
    """``{robot body name: colour}`` declared under the world's ``meta.smart.markers``
    (``settings``: the section already read, as ``ctx.settings``)."""
    settings = arena_settings(world) if settings is None else settings
    return {entry["robot"]: entry["colour"] for entry in settings["markers"]}


def colour_robots(world: Described, settings: Mapping[str, Any] | None = None) -> dict[str, str]:
    """``{colour: robot body name}``, the inverse of :func:`robot_colours`."""
    return {colour: robot for robot, colour in robot_colours(world, settings).items()}


def hat_offset(world: Any, body: int) -> tuple[float, float, float]:
    """Where a hat sits in a robot base's centre-of-mass frame: over the body frame's
    origin, 1 mm above the top plate (legged robots) or the base's top (other bodies,
    measured as loaded, so such a body must be upright then)."""
    p, client = world.p, world.client
    inertial = p.getDynamicsInfo(body, -1, physicsClientId=client)[3]
    name = p.getBodyInfo(body, physicsClientId=client)[1].decode()
    try:
        from petriflow.agents.legged.robots import DESIGNS
    except ImportError:  # pragma: no cover - the legged package ships with agents
        DESIGNS = {}
    if name in DESIGNS:
        plate = DESIGNS[name].plate
        top = plate.centre[2] + plate.size[2] / 2 + 0.001
        return (-inertial[0], -inertial[1], top - inertial[2])
    position, _ = p.getBasePositionAndOrientation(body, physicsClientId=client)
    top = p.getAABB(body, -1, physicsClientId=client)[1][2]
    return (0.0, 0.0, top - position[2] + 0.001)


def unrendered_ground(world: Any) -> int:
    """Replace the world's ``plane`` by a ground the camera does not draw: the same
    collision (a 200 m x 200 m x 10 m box, top face at z = 0) and friction, and a
    1 mm visual sphere 90 m away, so the renderer never rasterises it (a body without a
    visual shape would be drawn from its collision shape). Returns the new body id.
    Call before the world first steps."""
    p, client = world.p, world.client
    old = world.bodies.get("plane")
    friction = 1.0
    if old is not None:
        friction = p.getDynamicsInfo(old, -1, physicsClientId=client)[1]
        p.removeBody(old, physicsClientId=client)
    shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=[100.0, 100.0, 5.0], physicsClientId=client)
    speck = p.createVisualShape(p.GEOM_SPHERE, radius=0.001, visualFramePosition=[90.0, 90.0, 0.0],
                                rgbaColor=[1, 1, 1, 1], physicsClientId=client)
    body = p.createMultiBody(0.0, shape, speck, [0.0, 0.0, -5.0], physicsClientId=client)
    p.changeDynamics(body, -1, lateralFriction=friction, physicsClientId=client)
    world.bodies["plane"] = body
    return body


def dress(world: Any, settings: Mapping[str, Any] | None = None) -> Arena:
    """Whiten the floor and put a marker hat on every robot named in the world's
    ``meta.smart`` (``settings``: that section already read, as a run's resource has
    it), once per world: a world already dressed (its hats are found in the pybullet
    scene, where each records itself) is not dressed again, and the same
    :class:`Arena` is described again."""
    from petriflow.vision.markers import attach_markers, markers_on, white_floor

    settings = arena_settings(world) if settings is None else settings
    colours = robot_colours(world, settings)
    floor = settings["floor"]
    worn = {robot: markers_on(world, world.body(robot)) for robot in colours}
    if colours and all(worn.values()):
        return Arena({robot: hats[0] for robot, hats in worn.items()}, dict(colours), floor)
    arena = Arena()
    if floor == "white":
        unrendered_ground(world)
    elif floor == "painted":
        white_floor(world)
    arena.floor = floor
    for robot, colour in colours.items():
        body = world.body(robot)
        arena.hats[robot] = attach_markers(world, body, colour=colour, offset=hat_offset(world, body))
        arena.colours[robot] = colour
    return arena


def arena_resource(context: Any) -> Arena | None:
    """The ``smart.arena`` resource: the run's world dressed once by its checked
    ``meta.smart`` (``None`` when the world is not a physics scene with bodies:
    nothing to dress)."""
    world = context.world
    if not provides(world, Physics, Bodies):
        return None
    return dress(world, context.settings[SMART.name])


def load_arena(path: str | Path, gui: bool = False, camera_size: tuple[int, int] | None = None) -> Any:
    """Load a world file and :func:`dress` it; ``camera_size`` (width, height) resizes
    every camera (e.g. ``(320, 240)``)."""
    from petriflow.world import load_world

    world = load_world(path, gui=gui)
    if camera_size is not None:
        import dataclasses

        for name, camera in list(world.cameras.items()):
            world.cameras[name] = dataclasses.replace(camera, width=int(camera_size[0]),
                                                      height=int(camera_size[1]))
    dress(world)
    return world
