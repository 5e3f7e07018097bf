"""Shared facts of a run as declared, typed resources.

What several actions share that is neither a token nor one agent's state (the office
plan every robot navigates on, the arena the camera sees, which agents are alive) is
a *resource*: a registered type (:meth:`Registry.register_resource
<petriflow.runtime.registry.Registry.register_resource>`) whose factory makes one
object per run from the run's world and configuration. An action declares the
resources it uses by a local name (``resources = {"office": "bidding.office"}``);
binding checks that each type is registered (``file:line``), the run makes each
declared resource once, before the first firing, and the action gets it with
``ctx.resource("office")``. Nothing lives in module globals, on the world object, or
in a free-form dictionary, and a resource dies with its run.

Built in:

* ``core.liveness``: :class:`Liveness`, which agents of the run are running now (what
  a radio's beacon or a heartbeat tells an agent about the others).

Examples:
    >>> from petriflow.runtime.registry import Registry
    >>> registry = Registry(False)
    >>> registry.register_resource("demo.counter", lambda context: {"count": 0})
    >>> made = Resources(registry, ResourceContext(world=None, liveness=None))
    >>> made.need(["demo.counter"])
    >>> made.get("demo.counter")
    {'count': 0}
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Iterable, Mapping, Protocol

from petriflow.errors import PetriflowError

__all__ = ["Liveness", "ResourceContext", "Resources", "ResourceError", "LIVENESS"]

#: The built-in resource type of agents' liveness.
LIVENESS = "core.liveness"


class ResourceError(PetriflowError):
    """A resource cannot be made for this run (its factory refused the world or settings)."""


class Liveness:
    """Which agents of the run are running now (not killed, not waiting to join).

    Args:
        alive: ``agent -> bool`` (the run's faults).
        agents: the run's agents.
    """

    def __init__(self, alive: Callable[[str | None], bool], agents: Iterable[str]) -> None:
        self._alive = alive
        self.agents = list(agents)

    def alive(self, agent: str | None) -> bool:
        """Whether ``agent`` runs now (``None``, no agent, always does)."""
        return self._alive(agent)

    def running(self) -> list[str]:
        """The agents running now, in the net's order."""
        return [a for a in self.agents if self._alive(a)]


@dataclass(frozen=True)
class ResourceContext:
    """What a resource factory gets.

    Attributes:
        world: the run's world (``None`` in a world-less run).
        liveness: the run's :class:`Liveness`.
        config: the run configuration.
        settings: ``{section: {name: value}}``, the world file's settings the bound
            actions declare (:mod:`petriflow.runtime.settings`), checked.
    """

    world: Any
    liveness: Liveness | None
    config: Any = None
    settings: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)


class Factories(Protocol):
    """Where resource types are registered (a :class:`~petriflow.runtime.registry.Registry`)."""

    def resource_factory(self, name: str) -> Callable[..., Any]:
        """The factory of the resource type ``name``."""


class Resources:
    """The resources of one run, made once each (see the module).

    Args:
        registry: where resource types are registered.
        context: what their factories get.
    """

    def __init__(self, registry: Factories, context: ResourceContext) -> None:
        self.registry = registry
        self.context = context
        self._made: dict[str, Any] = {}
        if context.liveness is not None:
            self._made[LIVENESS] = context.liveness

    def need(self, kinds: Iterable[str]) -> None:
        """Make every resource of ``kinds`` not made yet.

        Raises:
            ResourceError: a factory refused (its message says why).
        """
        for kind in kinds:
            if kind in self._made:
                continue
            factory = self.registry.resource_factory(kind)
            try:
                self._made[kind] = factory(self.context)
            except ResourceError:
                raise
            except PetriflowError as exc:
                raise ResourceError(f"resource {kind}: {exc}") from None

    def get(self, kind: str) -> Any:
        """The run's resource of type ``kind`` (made on first use if it was not declared)."""
        if kind not in self._made:
            self.need([kind])
        return self._made[kind]
