"""Actions and guard predicates found by name.

A net names actions (``action: vision.capture``) and guards (``guard: path_free``); it
never names code. Names resolve only through a :class:`Registry`, which knows:

* actions registered in code (:meth:`Registry.register`, :meth:`Registry.action`);
* lazy ``"module:attribute"`` targets, imported the first time they are resolved;
* the ``petriflow.actions`` entry points of installed packages (a function that
  registers its package's actions; ``petriflow.agents`` and ``petriflow.vision`` ship
  one). So the core finds robot actions without importing robotics code.

Binding is checked when a net is loaded (:meth:`Registry.bind`): an unknown action, a
misspelt parameter or a missing guard fails before anything moves.

Examples:
    >>> registry = Registry(load_plugins=False)
    >>> @registry.action("demo.hello", params={"name": Param(str, "robot")})
    ... def hello(ctx):
    ...     return "hello " + ctx.params["name"]
    >>> registry.names()
    ['demo.hello']
    >>> registry.resolve("demo.helo")
    Traceback (most recent call last):
    ...
    petriflow.runtime.registry.UnknownActionError: unknown action 'demo.helo' (did you mean 'demo.hello'?)
"""

from __future__ import annotations

import importlib
import logging
from dataclasses import dataclass
from importlib.metadata import entry_points
from typing import Any, Callable

from petriflow.errors import NetFormatError, PetriflowError, did_you_mean
from petriflow.net import Net
from petriflow.runtime.action import Action, Param, generator_action

__all__ = ["Registry", "ActionSpec", "UnknownActionError", "default_registry", "ENTRY_POINT_GROUP"]

log = logging.getLogger(__name__)

#: Entry-point group through which installed packages register their actions.
ENTRY_POINT_GROUP = "petriflow.actions"

Predicate = Callable[..., bool]


class UnknownActionError(PetriflowError):
    """A net names an action or guard that no registry entry provides."""


@dataclass
class ActionSpec:
    """A registered action: its name, where it comes from, its documentation."""

    name: str
    target: type[Action] | str
    doc: str = ""

    def load(self) -> type[Action]:
        """The Action class, importing a lazy ``"module:attribute"`` target once."""
        if isinstance(self.target, str):
            module_name, _, attribute = self.target.partition(":")
            try:
                loaded = getattr(importlib.import_module(module_name), attribute)
            except (ImportError, AttributeError) as exc:
                raise UnknownActionError(
                    f"action {self.name!r}: cannot load {self.target!r}: {exc}"
                ) from exc
            if not (isinstance(loaded, type) and issubclass(loaded, Action)):
                raise UnknownActionError(f"action {self.name!r}: {self.target!r} is not an Action class")
            self.target = loaded
        return self.target


class Registry:
    """Maps action and guard names to code.

    Args:
        load_plugins: read the ``petriflow.actions`` entry points on first use.
    """

    def __init__(self, load_plugins: bool = True) -> None:
        self._actions: dict[str, ActionSpec] = {}
        self._predicates: dict[str, Predicate] = {}
        self._plugins_pending = load_plugins

    # Registering --------------------------------------------------------------------
    def register(self, name: str, target: type[Action] | str, *, doc: str = "",
                 replace: bool = False) -> None:
        """Register an Action class (or a lazy ``"module:Class"`` string) under ``name``."""
        if name in self._actions and not replace:
            raise PetriflowError(f"action {name!r} is already registered")
        if not doc and not isinstance(target, str):
            doc = (target.__doc__ or "").strip().splitlines()[0] if target.__doc__ else ""
        self._actions[name] = ActionSpec(name, target, doc)

    def action(self, name: str, params: dict[str, Param] | None = None, *,
               needs_world: bool = False, replace: bool = False) -> Callable:
        """Decorator registering a function or generator function as an action."""

        def decorate(function: Callable) -> Callable:
            cls = generator_action(function, params, needs_world)
            self.register(name, cls, replace=replace)
            return function

        return decorate

    def predicate(self, name: str, *, replace: bool = False) -> Callable[[Predicate], Predicate]:
        """Decorator registering a guard predicate ``f(tokens, params, blackboard) -> bool``.

        ``tokens`` is ``{place: [data, ...]}`` of the tokens the firing would consume.
        """

        def decorate(function: Predicate) -> Predicate:
            if name in self._predicates and not replace:
                raise PetriflowError(f"guard {name!r} is already registered")
            self._predicates[name] = function
            return function

        return decorate

    # Looking up ---------------------------------------------------------------------
    def _load_plugins(self) -> None:
        if not self._plugins_pending:
            return
        self._plugins_pending = False
        for entry in entry_points(group=ENTRY_POINT_GROUP):
            try:
                entry.load()(self)
            except Exception as exc:  # a broken plugin must not hide the others
                log.warning("action plugin %s failed to load: %s", entry.name, exc)

    def names(self) -> list[str]:
        """Registered action names, sorted."""
        self._load_plugins()
        return sorted(self._actions)

    def specs(self) -> list[ActionSpec]:
        """Registered actions, sorted by name."""
        self._load_plugins()
        return [self._actions[n] for n in sorted(self._actions)]

    def resolve(self, name: str) -> type[Action]:
        """The Action class registered as ``name``.

        Raises:
            UnknownActionError: nothing is registered under that name (with close matches).
        """
        self._load_plugins()
        spec = self._actions.get(name)
        if spec is None:
            raise UnknownActionError(f"unknown action {name!r}{did_you_mean(name, self._actions)}")
        return spec.load()

    def guard(self, name: str) -> Predicate:
        """The predicate registered as ``name`` (UnknownActionError with hints if none)."""
        self._load_plugins()
        if name not in self._predicates:
            raise UnknownActionError(f"unknown guard {name!r}{did_you_mean(name, self._predicates)}")
        return self._predicates[name]

    def bind(self, net: Net, path: str | None = None) -> dict[str, tuple[type[Action], dict[str, Any]]]:
        """Resolve every bound transition of ``net`` and check its parameters.

        Returns:
            ``{transition id: (Action class, checked params)}`` for bound transitions.

        Raises:
            NetFormatError: naming the file (``path``) and transition, for an unknown
                action or guard or a bad parameter.
        """
        bound: dict[str, tuple[type[Action], dict[str, Any]]] = {}
        for transition in net.transitions.values():
            try:
                if transition.guard is not None:
                    self.guard(transition.guard)
                if transition.action is None:
                    continue
                cls = self.resolve(transition.action)
                bound[transition.id] = (cls, cls.check_params(transition.params, transition.id))
            except UnknownActionError as exc:
                raise NetFormatError(str(exc), path=path, element=transition.id) from None
            except NetFormatError as exc:
                raise NetFormatError(exc.message, path=path, element=transition.id) from None
        return bound


default_registry = Registry()
"""The registry ``petriflow run`` uses: built-in core actions plus installed plugins."""


def _register_core(registry: Registry) -> None:
    from petriflow.runtime import builtin

    builtin.register(registry)


_register_core(default_registry)
