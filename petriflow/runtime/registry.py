"""Actions and guard predicates found by name.

A net names actions (``action: vision.capture``) and guards (``guard: path_free``); it
never names code. Names resolve only through a :class:`Registry`, which knows:

* actions registered in code (:meth:`Registry.register`, :meth:`Registry.action`);
* lazy ``"module:attribute"`` targets, imported the first time they are resolved;
* the ``petriflow.actions`` entry points of installed packages (a function that
  registers its package's actions; ``petriflow.agents`` and ``petriflow.vision`` ship
  one). So the core finds robot actions without importing robotics code.

A net is bound against a registry when it is loaded to run, check or show
(:func:`petriflow.runtime.binding.bind`): an unknown action, a misspelt parameter or a
missing guard fails before anything moves, naming the file and line.

Examples:
    >>> registry = Registry(load_plugins=False)
    >>> @registry.action("demo.hello", params={"name": Param(str, "robot")})
    ... def hello(ctx):
    ...     return "hello " + ctx.params["name"]
    >>> registry.names()   # the core actions are in every registry
    ['core.fail', 'core.noop', 'core.set', 'core.wait', 'demo.hello']
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
from typing import Any, Callable, Iterable

from petriflow.errors import PetriflowError, did_you_mean
from petriflow.runtime.action import Action, Param, generator_action
from petriflow.runtime.trace import EventKind

__all__ = ["Registry", "ActionSpec", "MetricSpec", "UnknownActionError", "default_registry", "ENTRY_POINT_GROUP",
           "action", "guard", "metric"]

log = logging.getLogger(__name__)

#: Entry-point group through which installed packages register their actions.
ENTRY_POINT_GROUP = "petriflow.actions"

Predicate = Callable[..., bool]
"""A guard: ``f(tokens, params) -> bool`` over ``{place: [data, ...]}`` of the tokens a
firing would take and the guarded transition's parameters; or, registered with
``reads=``, ``f(state, params) -> bool`` over the agent's state (see
:mod:`petriflow.runtime.agents`)."""


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


@dataclass
class MetricSpec:
    """A registered metric: a function of a finished run (see :mod:`petriflow.runtime.metrics`).

    Attributes:
        name: the name sweep files use (``core.firings``, ``bidding.time_s``).
        target: ``f(record, **params)``, or a lazy ``"module:function"`` string.
        events: whether it reads the run's events (the run then keeps them in memory):
            ``True`` for every kind, or the kinds it reads (``("custom",)``,
            :class:`~petriflow.runtime.trace.EventKind` values: only those are kept).
        doc: one line of documentation.
        wall_clock: it measures wall-clock time (or anything else outside the simulation),
            so it differs between runs of the same trial; reports mark it.
    """

    name: str
    target: Callable[..., Any] | str
    events: bool | tuple[str, ...] = False
    doc: str = ""
    wall_clock: bool = False

    def load(self) -> Callable[..., Any]:
        """The metric function, importing a lazy target once."""
        if isinstance(self.target, str):
            module_name, _, attribute = self.target.partition(":")
            try:
                self.target = getattr(importlib.import_module(module_name), attribute)
            except (ImportError, AttributeError) as exc:
                raise UnknownActionError(f"metric {self.name!r}: cannot load {self.target!r}: {exc}") from exc
            if not callable(self.target):
                raise UnknownActionError(f"metric {self.name!r}: {self.target!r} is not callable")
        return self.target


def _identity(target: Any) -> str:
    """Where code comes from: ``module.qualname`` of a class or function (a function
    action: of its function), or a lazy ``"module:Class"`` string as it is."""
    if isinstance(target, str):
        return target.replace(":", ".")
    target = getattr(target, "function", target)
    return f"{getattr(target, '__module__', '?')}.{getattr(target, '__qualname__', repr(target))}"


class Registry:
    """Maps action, guard and metric names to code.

    Args:
        load_plugins: read the ``petriflow.actions`` entry points when first needed: a
            listing, or a name not registered without them (a net of ``core.*`` actions
            loads no plugin).
    """

    def __init__(self, load_plugins: bool = True) -> None:
        self._actions: dict[str, ActionSpec] = {}
        self._predicates: dict[str, Predicate] = {}
        self._reads: dict[str, tuple[str, ...]] = {}
        self._states: dict[str, type] = {}
        self._resources: dict[str, Callable[..., Any]] = {}
        self._resource_settings: dict[str, Any] = {}
        self._per_world: set[str] = set()
        self._data_types: dict[str, type] = {}
        self._metrics: dict[str, MetricSpec] = {}
        self._channels: dict[str, Any] = {}
        self._plugins_pending = load_plugins
        #: ``{entry point: error}`` of the plugins that failed to load.
        self.broken: dict[str, str] = {}
        _register_core(self)  # core.wait, core.fail, ... and the core metrics: in every registry

    # Registering --------------------------------------------------------------------
    def register(self, name: str, target: type[Action] | str, *, doc: str = "",
                 replace: bool = False) -> None:
        """Register an Action class (or a lazy ``"module:Class"`` string) under ``name``.

        Registering the same code again (the same module and name: a notebook cell run
        twice, a module reloaded) replaces the old registration; other code under a
        taken name needs ``replace=True``.
        """
        old = self._actions.get(name)
        if old is not None and not replace and _identity(old.target) != _identity(target):
            raise PetriflowError(f"action {name!r} is already registered (by {_identity(old.target)})")
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

    def predicate(self, name: str, *, replace: bool = False,
                  reads: tuple[str, ...] | list[str] | None = None) -> Callable[[Predicate], Predicate]:
        """Decorator registering a guard predicate ``f(tokens, params) -> bool``, or with
        ``reads`` (the agent-state keys it reads, ``"{param}"`` placeholders allowed,
        ``"*"`` for anything) a guard ``f(state, params) -> bool`` over its agent's state
        whose answer is kept until one of those keys changes.

        ``tokens`` is ``{place: [data, ...]}`` of the tokens the firing would consume
        and ``params`` the guarded transition's parameters. A guard sees nothing else:
        what it decides on travels in tokens, so the net shows it.
        """

        def decorate(function: Predicate) -> Predicate:
            old = self._predicates.get(name)
            if old is not None and not replace and _identity(old) != _identity(function):
                raise PetriflowError(f"guard {name!r} is already registered (by {_identity(old)})")
            self._predicates[name] = function
            if reads is None:
                self._reads.pop(name, None)
            else:
                if isinstance(reads, str) or not all(isinstance(k, str) and k for k in reads):
                    raise PetriflowError(f"guard {name!r}: reads is a list of state keys, got {reads!r}")
                self._reads[name] = tuple(reads)
            return function

        return decorate

    def register_metric(self, name: str, target: Callable[..., Any] | str, *,
                        events: bool | Iterable[str] = False, doc: str = "", replace: bool = False,
                        wall_clock: bool = False) -> None:
        """Register a metric ``f(record, **params)`` (or a lazy ``"module:function"``);
        ``events``: it reads the run's events, all (``True``) or of these kinds;
        ``wall_clock``: it is not reproducible between runs (see :class:`MetricSpec`)."""
        if name in self._metrics and not replace:
            raise PetriflowError(f"metric {name!r} is already registered")
        if not isinstance(events, bool):
            events = tuple(events)
            unknown = sorted(set(events) - {kind.value for kind in EventKind})
            if unknown or not events:
                raise PetriflowError(f"metric {name!r}: events names no event kind: {unknown or events}")
        if not doc and not isinstance(target, str) and target.__doc__:
            doc = target.__doc__.strip().splitlines()[0]
        self._metrics[name] = MetricSpec(name, target, events, doc, wall_clock)

    def register_channel(self, name: str, target: type | str, *, replace: bool = False) -> None:
        """Register a channel model class (a :class:`~petriflow.runtime.channels.ChannelModel`
        subclass, or a lazy ``"module:Class"``) that run configurations name as
        ``channels: {bus: {model: NAME, ...}}``."""
        if name in self._channels and not replace:
            raise PetriflowError(f"channel model {name!r} is already registered")
        self._channels[name] = target

    def channel_model(self, name: str) -> type | None:
        """The channel model class registered as ``name``, or ``None``."""
        if name not in self._channels:
            self.load_plugins()
        target = self._channels.get(name)
        if isinstance(target, str):
            module_name, _, attribute = target.partition(":")
            try:
                target = self._channels[name] = getattr(importlib.import_module(module_name), attribute)
            except (ImportError, AttributeError) as exc:
                raise UnknownActionError(f"channel model {name!r}: cannot load {target!r}: {exc}") from exc
        return target

    def channel_names(self) -> list[str]:
        """Registered channel model names, sorted."""
        self.load_plugins()
        return sorted(self._channels)

    def metric(self, name: str, *, events: bool | Iterable[str] = False, replace: bool = False) -> Callable:
        """Decorator registering a metric; ``events``: it reads the run's events (all, or
        of these kinds)."""

        def decorate(function: Callable[..., Any]) -> Callable[..., Any]:
            self.register_metric(name, function, events=events, replace=replace)
            return function

        return decorate

    # Looking up ---------------------------------------------------------------------
    def load_plugins(self) -> None:
        """Load the installed plugins (the ``petriflow.actions`` entry points), once; a
        name not registered in code loads them the first time it is looked up."""
        if not self._plugins_pending:
            return
        self._plugins_pending = False
        for entry in entry_points(group=ENTRY_POINT_GROUP):
            try:
                entry.load()(self)
            except Exception as exc:  # a broken plugin must not hide the others
                self.broken[entry.name] = f"{type(exc).__name__}: {exc}"
                log.warning("action plugin %s failed to load: %s", entry.name, exc)

    def unknown(self, kind: str, name: str, known: Iterable[str]) -> UnknownActionError:
        """The error for an unknown ``name`` of ``kind`` (``action``, ``guard``...): close
        matches among ``known``, and any plugin that failed to load (its names may be the
        one asked for)."""
        message = f"unknown {kind} {name!r}{did_you_mean(name, known)}"
        if self.broken:
            failed = "; ".join(f"plugin {plugin!r} failed to load: {why}" for plugin, why in self.broken.items())
            message += f" ({failed})"
        return UnknownActionError(message)

    def names(self) -> list[str]:
        """Registered action names, sorted."""
        self.load_plugins()
        return sorted(self._actions)

    def names_of(self, kind: str) -> list[str]:
        """The names registered of ``kind``: ``action``, ``guard``, ``agent state``,
        ``resource`` (the built-in ``core.liveness`` included), ``metric`` or
        ``channel model``; what an error offers as close matches.

        Examples:
            >>> Registry(False).names_of("resource")
            ['core.liveness']
        """
        self.load_plugins()
        if kind == "resource":
            from petriflow.runtime.resources import LIVENESS

            return [*self._resources, LIVENESS]  # made by the run itself
        table = {"action": self._actions, "guard": self._predicates, "agent state": self._states,
                 "metric": self._metrics, "channel model": self._channels}[kind]
        return list(table)

    def specs(self) -> list[ActionSpec]:
        """Registered actions, sorted by name."""
        self.load_plugins()
        return [self._actions[n] for n in sorted(self._actions)]

    def resolve(self, name: str) -> type[Action]:
        """The Action class registered as ``name``.

        Raises:
            UnknownActionError: nothing is registered under that name (with close matches).
        """
        if name not in self._actions:  # the plugins load when a name is not known without them
            self.load_plugins()
        spec = self._actions.get(name)
        if spec is None:
            raise self.unknown("action", name, self._actions)
        return spec.load()

    def metric_spec(self, name: str) -> MetricSpec:
        """The metric registered as ``name`` (UnknownActionError with hints if none)."""
        if name not in self._metrics:
            self.load_plugins()
        if name not in self._metrics:
            raise self.unknown("metric", name, self._metrics)
        return self._metrics[name]

    def metric_specs(self) -> list[MetricSpec]:
        """Registered metrics, sorted by name."""
        self.load_plugins()
        return [self._metrics[n] for n in sorted(self._metrics)]

    def guard(self, name: str) -> Predicate:
        """The predicate registered as ``name`` (UnknownActionError with hints if none)."""
        if name not in self._predicates:
            self.load_plugins()
        if name not in self._predicates:
            raise self.unknown("guard", name, self._predicates)
        return self._predicates[name]

    def guard_reads(self, name: str) -> tuple[str, ...] | None:
        """The state keys the guard ``name`` declares it reads (``None``: it reads tokens)."""
        return self._reads.get(name)

    def register_resource(self, name: str, factory: Callable[..., Any] | str, *, replace: bool = False,
                          settings: Any = None, per_world: bool = False) -> None:
        """Register a resource type: ``factory(context) -> object`` (or a lazy
        ``"module:function"``) makes the run's one instance (see
        :mod:`petriflow.runtime.resources`); ``settings``: the world file's settings
        section it reads (a :class:`~petriflow.runtime.settings.Section`), read as the
        actions' are for a run whose actions use it (``context.settings``).
        ``per_world``: the resource is made from a world alone (its file's settings,
        its bodies), never from the run's tokens or configuration, so wherever actions
        run against a world of their own (a remote agent's ``--world``) it is made
        there, by the same factory (docs/bridge.md, *Resources on the agent*)."""
        old = self._resources.get(name)
        if old is not None and not replace and _identity(old) != _identity(factory):
            raise PetriflowError(f"resource {name!r} is already registered")
        if not callable(factory) and not (isinstance(factory, str) and ":" in factory):
            raise PetriflowError(f"resource {name!r}: the factory must be callable or 'module:function',"
                                 f" got {factory!r}")
        self._resources[name] = factory
        self._resource_settings[name] = settings
        if per_world:
            self._per_world.add(name)
        else:
            self._per_world.discard(name)

    def per_world(self, name: str) -> bool:
        """Whether the resource type ``name`` is made from a world alone (``per_world``
        when registered), so an agent with a world of its own makes it there."""
        self.load_plugins()
        return name in self._per_world

    def register_data_type(self, name: str, cls: type, *, replace: bool = False) -> None:
        """Register a dataclass that token data carries (a message's payload) under
        ``name``, so the bridge sends it as tagged JSON (``{"$type": NAME, field: value,
        ...}``) and the other side rebuilds it (:mod:`petriflow.bridge.codec`)."""
        import dataclasses

        if name in self._data_types and not replace and self._data_types[name] is not cls:
            raise PetriflowError(f"data type {name!r} is already registered")
        if not (isinstance(cls, type) and dataclasses.is_dataclass(cls)):
            raise PetriflowError(f"data type {name!r} must be a dataclass, got {cls!r}")
        self._data_types[name] = cls

    def data_types(self) -> dict[str, type]:
        """``{name: dataclass}`` of the registered data types."""
        self.load_plugins()
        return dict(self._data_types)

    def resource_settings(self, name: str) -> Any:
        """The settings section the resource type ``name`` reads (``None``: none)."""
        return self._resource_settings.get(name)

    def resource_factory(self, name: str) -> Callable[..., Any]:
        """The factory of the resource type ``name`` (UnknownActionError with hints if none)."""
        self.load_plugins()
        if name not in self._resources:
            from petriflow.runtime.resources import LIVENESS

            if name == LIVENESS:  # made by the run itself
                return lambda context: context.liveness
            raise self.unknown("resource", name, [*self._resources, LIVENESS])
        factory = self._resources[name]
        if isinstance(factory, str):
            module_name, _, attribute = factory.partition(":")
            try:
                factory = self._resources[name] = getattr(importlib.import_module(module_name), attribute)
            except (ImportError, AttributeError) as exc:
                raise UnknownActionError(f"resource {name!r}: cannot load {factory!r}: {exc}") from None
        return factory

    def register_state(self, name: str, cls: type, *, replace: bool = False) -> None:
        """Register an agent-state type that subnets declare as ``state: NAME``."""
        if name in self._states and not replace and self._states[name] is not cls:
            raise PetriflowError(f"agent state {name!r} is already registered")
        if not isinstance(cls, type):
            raise PetriflowError(f"agent state {name!r} must be a class, got {cls!r}")
        self._states[name] = cls

    def state_type(self, name: str) -> type:
        """The agent-state type registered as ``name`` (UnknownActionError with hints if none)."""
        self.load_plugins()
        if name not in self._states:
            raise self.unknown("agent state", name, self._states)
        return self._states[name]

def _register_core(registry: "Registry") -> None:
    """Register the core actions and metrics (every registry has them)."""
    from petriflow.runtime import builtin, metrics

    builtin.register(registry)
    metrics.register(registry)


default_registry = Registry()
"""The registry ``petriflow run`` uses: built-in core actions plus installed plugins."""





def action(name: str, params: dict[str, Param] | None = None, *, needs_world: bool = False,
           replace: bool = False, registry: Registry | None = None) -> Callable:
    """Decorator registering an action under ``name`` (in the run registry by default).

    It takes a function ``f(ctx)`` (done at once, its return value the result), a
    generator function (``yield`` waits one world step, ``yield seconds`` waits that
    much simulated time, ``return value`` finishes), or an :class:`Action` subclass
    (which declares its own ``params``). Raise
    :class:`~petriflow.runtime.action.ActionFailure` to fail.

    Args:
        name: the name nets use (``action: name``).
        params: the declared parameters of a function (``{name: Param}``).
        needs_world: poll a generator at every world step (it moves something).
        replace: replace an action already registered under ``name``.
        registry: the registry (default: the one ``petriflow run`` uses).

    Examples:
        >>> from petriflow import Param, action
        >>> @action("demo.charge", params={"minutes": Param(float, 5.0)}, registry=Registry(False))
        ... def charge(ctx):
        ...     yield ctx.params["minutes"] * 60
        ...     return {"battery": 1.0}
    """
    target_registry = registry or default_registry

    def decorate(target: Any) -> Any:
        if isinstance(target, type) and issubclass(target, Action):
            if params is not None:
                raise PetriflowError(f"action {name!r}: an Action class declares its own params")
            target_registry.register(name, target, replace=replace)
        else:
            target_registry.action(name, params, needs_world=needs_world, replace=replace)(target)
        return target

    return decorate


def guard(name: str, *, replace: bool = False, registry: Registry | None = None,
          reads: tuple[str, ...] | list[str] | None = None) -> Callable:
    """Decorator registering a guard ``f(tokens, params) -> bool`` under ``name``
    (in the run registry by default), or with ``reads`` a guard ``f(state, params)``
    over its agent's state; see :meth:`Registry.predicate`."""
    return (registry or default_registry).predicate(name, replace=replace, reads=reads)


def metric(name: str, *, events: bool | Iterable[str] = False, replace: bool = False,
           registry: Registry | None = None) -> Callable:
    """Decorator registering a metric ``f(record, **params)`` under ``name`` (in the run
    registry by default); see :mod:`petriflow.runtime.metrics`."""
    return (registry or default_registry).metric(name, events=events, replace=replace)
