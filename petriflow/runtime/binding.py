"""Binding a net to code: every action, parameter, port and guard resolved at load time.

A net names actions and guards; it never names code. :func:`bind` resolves each bound
transition against a :class:`~petriflow.runtime.registry.Registry` once, before a
run, a check or an ``info`` shows it, so a typo fails before a robot moves (as
BehaviorTree.CPP checks a tree's ports against its node manifest when it loads):

* the action name must be registered (close matches are suggested);
* its parameters are checked against the action's declared :class:`Param`\\ s
  (unknown, missing, ill-typed: close matches again);
* its :class:`Port`\\ s must name places of the net;
* the guard name must be registered.

Errors name the file and the line the loader recorded (``net.lines``), location first.

A command that only looks at a net (``info``, ``check``) binds it without importing
the action modules its run configuration names (``unimported``): a name the registry
lacks is then looked up in what those modules declare, read from their source
(:mod:`petriflow.runtime.declared`), and checked against a stand-in made of the
declaration by the same code as a run, so the errors are the same. ``core.*`` and the
installed plugins' namespaces are closed: a name there that they lack is an error even
so. What the source cannot tell is listed in :attr:`Binding.unchecked`, with the reason.

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> net = loads_net('''
    ... petriflow: 1
    ... places: [{id: a, tokens: 1}, b]
    ... transitions:
    ...   - {id: rest, action: core.wait, params: {seconds: 2}, in: [a], out: [b]}
    ... ''', path="demo.yaml")
    >>> bind(net).transitions["rest"].params
    {'seconds': 2.0}
    >>> net = loads_net('''
    ... petriflow: 1
    ... places: [{id: a, tokens: 1}, b]
    ... transitions:
    ...   - id: rest
    ...     action: core.wait
    ...     params: {secnds: 2}
    ...     in: [a]
    ...     out: [b]
    ... ''', path="demo.yaml")
    >>> bind(net)
    Traceback (most recent call last):
    ...
    petriflow.errors.NetFormatError: demo.yaml:7: 'rest': action has no parameter 'secnds' (did you mean 'seconds'?) (it takes: seconds)
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from petriflow import limits
from petriflow.capabilities import missing, name_of
from petriflow.errors import NetFormatError, did_you_mean
from petriflow.net import Net
from petriflow.runtime.action import Action, Port, type_names
from petriflow.runtime.declared import ActionDeclaration, Declarations, GuardDeclaration, read_declarations
from petriflow.runtime.registry import Predicate, Registry, UnknownActionError, default_registry
from petriflow.runtime.settings import Section

__all__ = ["Binding", "BoundTransition", "Unchecked", "bind", "check_sizes", "check_world", "closed_namespaces"]


@dataclass(frozen=True)
class BoundTransition:
    """One transition resolved to code.

    Attributes:
        id: the transition.
        action: the :class:`Action` class, or ``None`` for a transition with no action
            (it fires and ends in the same instant, passing its input data on).
        params: the checked parameters (defaults filled in).
        guard: the guard predicate, or ``None``.
        ports: ``{port: place}`` of the action's ports that name a place.
        reads: the agent-state keys the guard reads (its ``reads`` formatted with the
            transition's parameters), or ``None`` for a guard over tokens (or none).
    """

    id: str
    action: type[Action] | None
    params: dict[str, Any]
    guard: Predicate | None = None
    ports: dict[str, str] | None = None
    reads: tuple[str, ...] | None = None


@dataclass(frozen=True)
class Unchecked:
    """What a static command could not check: a name only an action module named in the
    run configuration (which looking at a net never imports) may provide, that its source
    does not show; or a part of a declaration read from source that only running it tells.

    Attributes:
        transition: the transition naming it.
        kind: ``action``, ``guard`` or ``agent state``.
        name: the action, guard or agent-state name.
        line: where the net names it.
        reason: why it could not be checked.
        partly: the name was found (declared in a module's source) and checked; only
            what ``reason`` says was not.
    """

    transition: str
    kind: str
    name: str
    line: int | None
    reason: str = "an action module that was not imported may provide it"
    partly: bool = False

    def describe(self) -> str:
        """``action 'x' not checked: why`` (``partly checked`` when :attr:`partly`)."""
        return f"{self.kind} {self.name!r} {'partly checked' if self.partly else 'not checked'}: {self.reason}"


@dataclass(frozen=True)
class Binding:
    """A net whose transitions are all resolved: what a run needs before it starts.

    Attributes:
        net: the net.
        registry: where the names were resolved.
        transitions: ``{transition id: BoundTransition}`` for every transition.
        unchecked: what a static command could not check (see :class:`Unchecked`).
        checked: whether :func:`petriflow.runtime.validation.validate` checked the run's
            inputs against this binding (so nothing checks them again).
        sections: ``{name: Section}``: the world file's settings the bound actions read
            (:mod:`petriflow.runtime.settings`), read when the world is loaded.
    """

    net: Net
    registry: Registry
    transitions: dict[str, BoundTransition]
    unchecked: tuple["Unchecked", ...] = ()
    checked: bool = False
    sections: dict[str, Section] = field(default_factory=dict)

    def actions(self) -> dict[str, type[Action]]:
        """``{transition id: Action class}`` of the bound transitions."""
        return {t: b.action for t, b in self.transitions.items() if b.action is not None}


def _line(net: Net, *keys: str) -> int | None:
    for key in keys:
        line = net.lines.get(key)
        if line is not None:
            return line
    return None


def check_sizes(net: Net, path: str | None = None) -> None:
    """Refuse counts a run cannot hold (it keeps one entry per token; the token game
    and the analysis only count, and take them).

    Raises:
        NetFormatError: ``file:line: 'element': ...`` for an initial marking or an arc
            weight beyond :data:`~petriflow.limits.RUN_TOKENS`.
    """
    path = path or net.path
    for place, tokens in net.initial_marking.items():
        if tokens > limits.RUN_TOKENS:
            raise NetFormatError(f"starts with {tokens} tokens; a run holds at most {limits.RUN_TOKENS:,} "
                                 "in one place (each token carries data)",
                                 path=path, line=_line(net, place), element=place)
    for arc in net.arcs:
        if arc.weight > limits.RUN_TOKENS:
            transition = arc.target if arc.target in net.transitions else arc.source
            raise NetFormatError(f"arc {arc.source!r} -> {arc.target!r} has weight {arc.weight}; a run moves "
                                 f"at most {limits.RUN_TOKENS:,} tokens per arc",
                                 path=path, line=_line(net, transition), element=transition)


def bind(net: Net, registry: Registry | None = None, *, path: str | None = None,
         unimported: bool | Sequence[str] = False) -> Binding:
    """Resolve every transition of ``net`` against ``registry`` (default: the run registry).

    Args:
        net: the net, as loaded (its ``lines`` give error lines).
        registry: where action and guard names are looked up.
        path: the file named in errors (default: the file the net was read from).
        unimported: the action modules the net's run configuration names that were not
            imported (a static command; entries as :attr:`RunConfig.actions` keeps them):
            a name the registry lacks is checked against what their source declares
            (module docstring); what cannot be known that way is recorded in
            :attr:`Binding.unchecked` with the reason. ``True``: modules not imported
            and not to be read (every such name unchecked).

    Raises:
        NetFormatError: ``file:line: 'transition': ...`` for an unknown action or guard,
            a bad parameter, or a port that names no place (with close matches).
    """
    binder = _Binder(net, registry or default_registry, path or net.path, unimported)
    bound = {t.id: binder.transition(t) for t in net.transitions.values()}
    return Binding(net, binder.registry, bound, tuple(binder.unchecked), sections=binder.sections)


class _Binder:
    """Binds one net's transitions, one at a time (see :func:`bind`)."""

    def __init__(self, net: Net, registry: Registry, path: str | None,
                 unimported: bool | Sequence[str]) -> None:
        self.net, self.registry, self.path, self.unimported = net, registry, path, unimported
        self.unchecked: list[Unchecked] = []
        self.sections: dict[str, Section] = {}
        self._sections_by: dict[str, str] = {}  # section name -> the transition that declared it first
        self.cache: dict[tuple[str, str], tuple[Any, str | None]] = {}
        self._declared: Declarations | None = None
        self.noted: set[tuple[str, str, bool]] = set()

    def fail(self, tid: str, message: str, *keys: str) -> NetFormatError:
        return NetFormatError(message, path=self.path, line=_line(self.net, *keys, tid), element=tid)

    @property
    def declared(self) -> Declarations:
        """What the modules not imported declare, read from their source the first time
        a name is not registered."""
        if self._declared is None:
            if self.unimported is True:
                self._declared = Declarations(hidden={"*": [("", ("an action module that was not imported"
                                                                   " may provide it"))]})
            else:
                self._declared = read_declarations(list(self.unimported or ()))
        return self._declared

    def find(self, kind: str, name: str) -> tuple[Any, str | None]:
        """What ``name`` of ``kind`` (``action``, ``guard``, ``agent state``, ``resource``)
        is: the registered code, or what a module not imported declares in its source;
        and, when neither tells, why (then the thing is ``None``).

        Raises:
            UnknownActionError: nothing provides it: the registry's message, with close
                matches among the registered and the declared names (as a run gives).
        """
        if (kind, name) in self.cache:
            return self.cache[kind, name]
        find = {"action": self.registry.resolve, "guard": self.registry.guard,
                "agent state": self.registry.state_type, "resource": self.registry.resource_factory}[kind]
        try:
            self.cache[kind, name] = (find(name), None)
        except UnknownActionError as exc:
            if not self.unimported:
                raise
            declared = self.declared.names(kind).get(name)
            if declared is not None:
                found = declared.action_class() if kind == "action" else declared
                self.cache[kind, name] = (found, None)
                return self.cache[kind, name]
            closed = "." in name and name.partition(".")[0] in closed_namespaces()
            reason = None if closed else self.declared.missing(kind, name)
            if reason is None:
                known = [*self.registry.names_of(kind), *self.declared.names(kind)]
                raise self.registry.unknown(kind, name, known) from exc
            self.cache[kind, name] = (None, reason)
        return self.cache[kind, name]

    def note(self, tid: str, kind: str, name: str, reason: str | None, *, partly: bool = False,
             once: bool = False) -> None:
        """List what was not checked (``once``: for the first transition only)."""
        if reason and not (once and (kind, name, partly) in self.noted):
            self.noted.add((kind, name, partly))
            self.unchecked.append(Unchecked(tid, kind, name, _line(self.net, f"{tid}/{kind}", tid), reason, partly))

    def lookup(self, tid: str, kind: str, name: str) -> Any:
        """The action class or guard named ``name`` (``None``: not checked, see ``unimported``)."""
        try:
            found, reason = self.find(kind, name)
        except UnknownActionError as exc:
            raise self.fail(tid, str(exc), f"{tid}/{kind}") from None
        self.note(tid, kind, name, reason)
        declared = getattr(found, "declaration", found)
        if isinstance(declared, (ActionDeclaration, GuardDeclaration)):
            self.note(tid, kind, name, "; ".join(declared.gaps), partly=True)
        return found

    def transition(self, transition: Any) -> BoundTransition:
        tid = transition.id
        guard = None if transition.guard is None else self.lookup(tid, "guard", transition.guard)
        cls = None if transition.action is None else self.lookup(tid, "action", transition.action)
        if cls is None:  # no action, or not checked (its module was not imported)
            params = dict(transition.params)
            return BoundTransition(tid, None, params, guard, None, self.reads(transition, guard, params))
        declared = getattr(cls, "declaration", None)
        if declared is not None and declared.params is None:  # read from source, parameters unknown
            params = dict(transition.params)
        else:
            try:
                params = cls.check_params(transition.params, tid)
            except NetFormatError as exc:
                param = getattr(exc, "param", None)
                raise self.fail(tid, exc.message, f"{tid}/params/{param}", f"{tid}/params") from None
        ports = self.ports(tid, cls, params)
        self.requirements(tid, transition.action, cls.requirements(params), params)
        self.state(tid, transition.action, cls)
        self.settings(tid, transition.action, getattr(cls, "settings", None))
        for name, kind in getattr(cls, "resources", {}).items():
            try:
                self.find("resource", kind)
            except UnknownActionError as exc:
                raise self.fail(tid, f"action {transition.action} uses resource {name!r}: {exc}",
                                f"{tid}/action") from None
            self.settings(tid, f"{transition.action} (its resource {kind})", self.registry.resource_settings(kind))
        return BoundTransition(tid, cls, params, guard, ports, self.reads(transition, guard, params))

    def reads(self, transition: Any, guard: Any, params: dict[str, Any]) -> tuple[str, ...] | None:
        """The state keys the transition's guard reads, its placeholders filled in."""
        if guard is None:
            return None
        if isinstance(guard, GuardDeclaration):  # read from a module's source
            declared = guard.reads
        else:
            declared = self.registry.guard_reads(transition.guard)
        if declared is None:
            return None
        tid = transition.id
        if _agent_of(self.net, tid) is None:
            raise self.fail(tid, f"guard {transition.guard} reads its agent's state: put the transition in an"
                            " agent subnet", f"{tid}/guard")
        try:
            return tuple(key.format(**params) for key in declared)
        except (KeyError, IndexError, ValueError) as exc:
            raise self.fail(tid, f"guard {transition.guard} reads {declared!r}, which needs the parameter"
                            f" {exc} the transition does not give", f"{tid}/guard") from None

    def state(self, tid: str, action: str, cls: type[Action]) -> None:
        """An action that reads an agent state must run in a subnet declaring a state of its type."""
        wanted = getattr(cls, "agent_state", None)
        subnet = self.net.transitions[tid].subnet
        declared = None if subnet is None else self.net.subnets[subnet].state
        if declared is not None:
            try:
                kind, reason = self.find("agent state", declared)
            except UnknownActionError as exc:
                raise self.fail(tid, f"subnet {subnet!r}: {exc}", tid) from None
            self.note(tid, "agent state", declared, reason, once=True)
            if not isinstance(kind, type):  # declared in a module's source: what it is is not known
                if wanted is not None:
                    self.note(tid, "agent state", declared, f"action {action} reads a {type_names(wanted)}"
                              f" state, and what {declared!r} is cannot be known without importing the module"
                              " that registers it", partly=True, once=True)
            elif wanted is not None and not issubclass(kind, wanted):
                raise self.fail(tid, f"action {action} reads a {type_names(wanted)} state, but subnet"
                                f" {subnet!r} declares state {declared!r} ({kind.__name__})", f"{tid}/action")
        elif wanted is not None:
            raise self.fail(tid, f"action {action} reads its agent's {type_names(wanted)} state: declare it on"
                            f" the subnet (state: ...)" if subnet else f"action {action} reads an agent state:"
                            " put the transition in an agent subnet", f"{tid}/action")

    def settings(self, tid: str, action: str, section: Any) -> None:
        """A world settings section the action (or a resource it uses) reads: one
        declaration per name."""
        if section is None:
            return
        if not isinstance(section, Section):
            raise self.fail(tid, f"action {action} declares settings {section!r}: a Section"
                            " (petriflow.runtime.settings) is expected", f"{tid}/action")
        known = self.sections.setdefault(section.name, section)
        first = self._sections_by.setdefault(section.name, tid)
        if known != section:
            raise self.fail(tid, f"action {action} reads the world's settings {section.name!r} declared otherwise"
                            f" by the action of {first!r}: one section, one declaration", f"{tid}/action")

    def ports(self, tid: str, cls: type[Action], params: dict[str, Any]) -> dict[str, str]:
        """``{port: place}`` of the action's ports that name a place; each must exist."""
        ports = {}
        places = self.net.places
        for name, declared in cls.params.items():
            if isinstance(declared, Port) and params.get(name) is not None:
                named = [params[name]]
            else:
                named = declared.place_names(params.get(name))
            for place in named:
                if not isinstance(place, str) or place not in places:
                    hint = did_you_mean(place, places) if isinstance(place, str) else ""
                    what = "port" if isinstance(declared, Port) else "parameter"
                    raise self.fail(tid, f"{what} {name!r} names unknown place {place!r}{hint}",
                                    f"{tid}/params/{name}", f"{tid}/params")
            if isinstance(declared, Port) and named:
                ports[name] = named[0]
        return ports

    def requirements(self, tid: str, action: str, needs: frozenset[str], params: dict[str, Any]) -> None:
        agent = _agent_of(self.net, tid)
        if "agent" in needs and agent is None:
            raise self.fail(tid, f"action {action} runs as an agent: put the transition in an agent subnet",
                            f"{tid}/action")
        if "robot" in needs and params.get("robot") is None and agent is None:
            raise self.fail(tid, f"action {action} moves a robot: give params.robot or put the transition in"
                            " an agent subnet", f"{tid}/action")


@functools.lru_cache(maxsize=1)
def closed_namespaces() -> frozenset[str]:
    """The namespaces (``core`` of ``core.wait``) of the core's and the installed plugins'
    actions, guards and agent states: trusted installed code (the ``petriflow.actions``
    entry points), loaded by any registry. A name under one of them that they lack is an
    error even when action modules were not imported."""
    installed = Registry()  # the core and the entry points only, whatever this process imported
    names = [*installed.names(), *installed.names_of("guard"), *installed.names_of("agent state")]
    return frozenset({"core"} | {name.partition(".")[0] for name in names if "." in name})



def _agent_of(net: Net, tid: str) -> str | None:
    subnet = net.transitions[tid].subnet
    if subnet is None:
        return None
    return net.subnets[subnet].agent or subnet


def check_world(binding: Binding, world: Any, path: str | None = None) -> None:
    """Refuse a run whose world lacks what a bound action needs: a world at all
    (:attr:`Action.requires` ``"world"``), or a capability it uses (:attr:`Action.uses`).

    Args:
        binding: the net bound.
        world: the world the run will have: an object, or its class; ``True`` for a
            world file (a :class:`petriflow.world.World`); ``False`` or ``None`` for none.
        path: the net's file, named in errors.

    Raises:
        NetFormatError: ``file:line: 'transition': action X needs a world ...``, or
            ``... uses the world's cameras (Cameras), which ... lacks: camera``.
    """
    if world is True:
        from petriflow.world import World

        world = World
    elif world is False:
        world = None
    net = binding.net
    for tid, bound in binding.transitions.items():
        cls = bound.action
        if cls is None:
            continue
        where = {"path": path or net.path, "line": _line(net, f"{tid}/action", tid), "element": tid}
        if world is None:
            if cls.uses or "world" in cls.requirements(bound.params):
                raise NetFormatError(f"action {net.transitions[tid].action} needs a world: run with --world or"
                                     " name one in the run configuration (world: FILE)", **where)
            continue
        for capability in cls.uses:
            lacking = missing(world, capability)
            if lacking:
                kind = world if isinstance(world, type) else type(world)
                raise NetFormatError(f"action {net.transitions[tid].action} uses the world's {name_of(capability)}"
                                     f" ({capability.__name__}), which this run's world ({kind.__name__}) lacks:"
                                     f" {', '.join(lacking)}", **where)
