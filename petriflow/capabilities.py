"""What a world can do for an action: typed capabilities, declared and checked at binding.

A run's world is any object that steps (:class:`Stepped`); what else it offers an
action is one of the capabilities below, each a :class:`typing.Protocol` naming the
methods and attributes an action may then use. An action declares the capabilities
it uses (:attr:`Action.uses <petriflow.runtime.action.Action.uses>`); binding checks
that the run's world provides every one (``file:line`` and the missing members), as
it checks parameters and places, so an action never probes its world with
``getattr``/``hasattr``: what it declared is there.

=======================  ======================================================================  ===============================
capability               what the action may use                                                 :class:`~petriflow.world.World`
=======================  ======================================================================  ===============================
:class:`Distances`       ``distance``                                                            yes
:class:`Positions`       ``position`` (and ``distance``)                                         yes
:class:`Poses`           ``pose`` (and ``position``, ``distance``)                               yes
:class:`Bodies`          ``bodies``, ``agents``, ``body``, ``remove``                            yes
:class:`RayTests`        ``rays``, ``request_rays``, ``flush_sensors``                           yes
:class:`Cameras`         ``cameras``, ``camera``                                                 yes
:class:`KinematicDrive`  ``command``, ``set_pose``, ``is_kinematic``                             yes
:class:`Physics`         ``p`` (the pybullet module), ``client``, ``sync``                       yes
:class:`PoseArrays`      ``mode``, ``poses``, ``active``, ``agents``, ``row``, ``is_kinematic``  yes
:class:`Described`       ``meta``, ``path`` (settings: :mod:`petriflow.runtime.settings`)        yes
=======================  ======================================================================  ===============================

A world made in code (a test double, another simulator) provides what its class
defines; :func:`missing` says what it lacks. Code that works with and without a
capability (a channel model that counts walls only where the world places its agents)
asks once, with :func:`provides` (or ``isinstance(world, Poses)``: the protocols are
runtime-checkable), and keeps the answer; it never probes the world member by member.

Examples:
    >>> class Flatland:
    ...     dt = 0.1
    ...     def step(self): pass
    ...     def pose(self, name): return (0.0, 0.0, 0.0)
    >>> missing(Flatland, Poses)
    ['position', 'distance']
    >>> missing(Flatland(), Stepped), name_of(RayTests)
    ([], 'ray tests')
    >>> provides(Flatland(), Stepped), provides(Flatland(), Poses), provides(None, Stepped)
    (True, False, False)
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

__all__ = ["Stepped", "Distances", "Positions", "Poses", "Bodies", "RayTests", "Cameras", "KinematicDrive", "Physics", "Described",
           "PoseArrays", "missing", "provides", "name_of", "CAPABILITIES"]


@runtime_checkable
class Stepped(Protocol):
    """What every world gives a run: its physics step and a way to advance it."""

    dt: float
    """Seconds per step (the run's tick)."""

    def step(self) -> None:
        """Advance the world by ``dt``."""


@runtime_checkable
class Distances(Protocol):
    """How far apart agents' robots are (what a radio channel model reads)."""

    def distance(self, a: str, b: str) -> float | None:
        """Metres between two agents' robots (``None`` if either has none)."""


@runtime_checkable
class Positions(Distances, Protocol):
    """Where agents' robots stand on the ground (and so how far apart: :class:`Distances`)."""

    def position(self, agent: str) -> tuple[float, float] | None:
        """``(x, y)`` of an agent's robot, ``None`` if the agent has no body."""


@runtime_checkable
class Poses(Positions, Protocol):
    """Where bodies and agents' robots are, and which way they face (and where they
    stand: :class:`Positions`)."""

    def pose(self, name: str) -> tuple[float, float, float]:
        """``(x, y, yaw)`` of a body or an agent's robot."""


@runtime_checkable
class Bodies(Protocol):
    """The world's bodies by name."""

    bodies: dict[str, int]
    """``{body name: simulator body id}``."""
    agents: dict[str, str]
    """``{agent: body name}`` of the agents' robots."""

    def body(self, name: str) -> int:
        """The simulator's id of a body or of an agent's robot."""

    def remove(self, name: str) -> None:
        """Take a body (or an agent's robot) out of the scene."""


@runtime_checkable
class RayTests(Protocol):
    """Rays cast into the scene (range sensors, line of sight)."""

    def rays(self, starts: Any, ends: Any, *, robots: bool = True) -> list[tuple[int, float, tuple]]:
        """Cast rays now: one ``(body, fraction, hit point)`` per ray."""

    def request_rays(self, starts: Any, ends: Any, *, robots: bool = False) -> Any:
        """Ask for rays cast with the others of this tick at the world's next step."""

    def flush_sensors(self) -> int:
        """Cast every pending ray request now."""


@runtime_checkable
class Cameras(Protocol):
    """Fixed cameras that render frames."""

    cameras: dict[str, Any]
    """``{camera id: camera}``."""

    def camera(self, name: str = "camera") -> Any:
        """A camera by id."""


@runtime_checkable
class KinematicDrive(Protocol):
    """Robots driven by commanded velocities."""

    def command(self, name: str, v: float = 0.0, w: float = 0.0, vy: float = 0.0) -> None:
        """Drive a robot at forward speed ``v``, turn rate ``w`` (and sideways ``vy``)."""

    def set_pose(self, name: str, x: float, y: float, yaw: float) -> None:
        """Put a kinematic robot at ``(x, y, yaw)``."""

    def is_kinematic(self, name: str) -> bool:
        """Whether a body (or an agent's robot) moves kinematically."""


@runtime_checkable
class Physics(Protocol):
    """The physics simulator itself, for actions that call pybullet directly."""

    p: Any
    """The pybullet module."""
    client: int
    """This world's physics client (``physicsClientId=``)."""

    def sync(self) -> None:
        """Write the kinematic robots' poses to the simulator before reading it."""


@runtime_checkable
class Described(Protocol):
    """A world built from a world file, which keeps the file's ``meta`` (its scenario
    settings, read through declared sections: :mod:`petriflow.runtime.settings`)."""

    meta: dict[str, Any]
    """The world file's ``meta``."""
    path: str | None
    """The world file (named in errors)."""


@runtime_checkable
class PoseArrays(Protocol):
    """The kinematic robots' poses as arrays, one row per robot (what vectorised code,
    such as a radio that finds who hears whom for every robot at once, reads)."""

    mode: str
    """``kinematic`` (the arrays are the robots' poses) or ``dynamic``."""
    poses: Any
    """``(robots, 3)`` array of ``x, y, yaw``."""
    active: Any
    """``(robots,)`` boolean array: the rows of robots still in the scene."""
    agents: dict[str, str]
    """``{agent: body name}`` of the agents' robots."""

    def row(self, name: str) -> int:
        """The row of a kinematic robot (a body or an agent's)."""

    def is_kinematic(self, name: str) -> bool:
        """Whether a body (or an agent's robot) moves kinematically."""


#: The capabilities an action may declare, with the words errors use for them.
CAPABILITIES: dict[type, str] = {
    Stepped: "steps", Distances: "distances", Positions: "positions", Poses: "poses", Bodies: "bodies", RayTests: "ray tests", Cameras: "cameras",
    KinematicDrive: "kinematic drive", Physics: "physics", Described: "world file", PoseArrays: "pose arrays",
}


def _members(capability: type) -> list[str]:
    """The methods and attributes ``capability`` declares (its own, then those of the
    capabilities it extends), in the order it declares them."""
    names: list[str] = []
    for klass in capability.__mro__:
        if klass is Protocol or klass is object or not getattr(klass, "_is_protocol", False):
            continue
        for name in [*vars(klass).get("__annotations__", {}),
                     *(n for n, value in vars(klass).items() if not n.startswith("_") and callable(value))]:
            if name not in names:
                names.append(name)
    return names


def missing(world: Any, capability: type) -> list[str]:
    """The members of ``capability`` that ``world`` (an object, or a class whose
    instances a run will have) lacks; empty when it provides them all.

    A class provides an attribute it defines or annotates (``bodies: dict[str, int]``
    in its body), an object one it has.
    """
    if isinstance(world, type):
        annotated: set[str] = set()
        for klass in world.__mro__:
            annotated.update(getattr(klass, "__annotations__", {}))
        return [name for name in _members(capability) if not hasattr(world, name) and name not in annotated]
    return [name for name in _members(capability) if not hasattr(world, name)]


def provides(world: Any, *capabilities: type) -> bool:
    """Whether ``world`` (an object or a class; ``None``: no world) provides every one of
    ``capabilities``: the one check of an optional capability.

    Examples:
        >>> from petriflow.world import World
        >>> provides(World, Poses, RayTests, Cameras), provides(None, Poses)
        (True, False)
    """
    return world is not None and all(not missing(world, capability) for capability in capabilities)


def name_of(capability: type) -> str:
    """The words for ``capability`` in messages (``ray tests``)."""
    return CAPABILITIES.get(capability, capability.__name__)
