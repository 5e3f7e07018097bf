"""Agent-held state: a bridged subnet's agent state lives on its agent, and its guards
are evaluated where the state is.

A subnet may keep an agent state (:mod:`petriflow.runtime.agents`: an object its
actions set and change through ``ctx.state``, read by guards ``f(state, params)`` that
declare the keys they read). When the subnet is bridged, that state is the robot's
own memory: it lives on the agent, never in the run.

* **On the agent** (:class:`AgentMemory`): one state per run and agent name (``None``
  until an action sets it, as in a local run), given as ``ctx.state`` to the actions of
  that agent's goals, checked against the type the subnet declares (by its registry
  name, as a local run checks it). After each goal's step the agent evaluates the
  subnet's state guards on it (:meth:`Held.snapshot`): a goal's ``result`` carries
  their values ``{transition: bool}`` with a snapshot number ``seq``, and so does a
  ``feedback`` when the state changed while the goal goes on.
* **In the run** (:class:`HeldGuards`): the agent's state is a cache of those values,
  the newest snapshot winning; each state guard of the subnet is a :class:`RemoteGuard`
  that answers from it and reads the key ``guard/TRANSITION``, so the kernel's "asked
  again only when its keys changed" machinery asks it again exactly when a snapshot
  changed its value. Before the first snapshot the agent has no state, and the guard is
  the guard itself on no state (``guard(None, params)``), as in a local run.

What the goal tells the agent (:func:`state_spec`): ``{"type": NAME, "guards":
{transition: [guard, params]}}``, in the goal's ``state`` field.

Examples:
    >>> held = HeldGuards("robot1")
    >>> touched = []
    >>> held.attach(lambda keys: touched.extend(keys))
    >>> held.update(1, {"go": True, "stop": False}); touched
    ['guard/go', 'guard/stop']
    >>> held.update(1, {"go": False}); held.values["go"]       # an older or equal snapshot: ignored
    True
    >>> held.update(2, {"go": True, "stop": True}); touched[2:]
    ['guard/stop']
"""

from __future__ import annotations

import dataclasses
from collections import OrderedDict
from dataclasses import dataclass, field
from typing import Any, Callable

from petriflow.errors import NetFormatError, PetriflowError
from petriflow.net import Net
from petriflow.runtime.action import ANY_KEY, type_names
from petriflow.runtime.agents import RUNNING, AgentState
from petriflow.runtime.binding import BoundTransition
from petriflow.runtime.registry import Registry, UnknownActionError

__all__ = ["HeldGuards", "RemoteGuard", "guard_key", "state_spec", "held_guards", "AgentMemory", "Held",
           "HeldStates", "check_spec"]

#: Runs whose states an agent keeps (the oldest are forgotten).
KEPT_RUNS = 8


def guard_key(transition: str) -> str:
    """The key a remote state guard reads in the run: its transition's snapshot value."""
    return f"guard/{transition}"


class HeldGuards(AgentState):
    """The run's side of a remote agent's state: the values of its subnet's state
    guards, as the agent last sent them (see the module)."""

    def __init__(self, agent: str) -> None:
        super().__init__()
        self.agent = agent
        self.seq = 0
        self.values: dict[str, bool] = {}

    def update(self, seq: int, values: dict[str, bool]) -> None:
        """A snapshot from the agent: newer than the last one, it replaces it and
        touches the keys of the guards whose value changed."""
        if seq <= self.seq:
            return
        old = self.values
        changed = [t for t in dict.fromkeys([*values, *old]) if values.get(t) != old.get(t)]
        self.seq, self.values = seq, dict(values)
        if changed:
            self.touch(*(guard_key(t) for t in changed))

    def to_token(self) -> dict[str, Any]:
        return {"agent": self.agent, "held": "remote", "seq": self.seq}


class RemoteGuard:
    """A state guard of a bridged subnet, answered from its agent's snapshot
    (:class:`HeldGuards`); with no snapshot yet, the guard itself on no state."""

    def __init__(self, transition: str, name: str, guard: Callable[[Any, dict[str, Any]], Any]) -> None:
        self.transition = transition
        self.name = name
        self.guard = guard
        self.__name__ = f"remote:{name}"

    def __call__(self, state: Any, params: dict[str, Any]) -> bool:
        if isinstance(state, HeldGuards):
            return state.values.get(self.transition, False)
        return bool(self.guard(None, params))


def held_guards(net: Net, transitions: dict[str, BoundTransition], subnets: dict[str, str], path: str | None) \
        -> dict[str, dict[str, Any]]:
    """``{remote agent: its goals' state spec}`` for the bridged ``subnets`` (``{subnet
    id: remote agent}``) that declare a state or have state guards; their state guards
    in ``transitions`` (a binding's, by transition) are replaced by :class:`RemoteGuard`.

    Raises:
        NetFormatError: a state guard reads which agents run (``running``), which an
            agent cannot see (``file:line``).
    """
    specs: dict[str, dict[str, Any]] = {}
    for subnet_id, agent in subnets.items():
        subnet = net.subnets[subnet_id]
        guards: dict[str, list[Any]] = {}
        for tid, transition in net.transitions.items():
            bound = transitions.get(tid)
            if transition.subnet != subnet_id or bound is None or bound.reads is None or bound.guard is None:
                continue
            if RUNNING in bound.reads:
                line = net.lines.get(f"{tid}/guard") or net.lines.get(tid)
                raise NetFormatError(f"guard {transition.guard} reads which agents run ({RUNNING!r}), which remote"
                                     f" agent {agent!r} cannot see (leave subnet {subnet_id!r} local)",
                                     path=path or net.path, line=line, element=tid)
            guards[tid] = [transition.guard, dict(bound.params)]
            reads = (guard_key(tid), ANY_KEY) if ANY_KEY in bound.reads else (guard_key(tid),)
            transitions[tid] = dataclasses.replace(bound, guard=RemoteGuard(tid, transition.guard, bound.guard),
                                                   reads=reads)
        if subnet.state is None and not guards:
            continue
        spec = specs.setdefault(agent, {"type": subnet.state or "", "guards": {}})
        if spec["type"] != (subnet.state or ""):
            raise NetFormatError(f"bridge: subnets with states {spec['type']!r} and {subnet.state!r} are both on"
                                 f" remote agent {agent!r}, which holds one state", path=path or net.path)
        spec["guards"].update(guards)
    return specs


def state_spec(specs: dict[str, dict[str, Any]], agent: str) -> dict[str, Any]:
    """What the goals for ``agent`` carry in their ``state`` field (``{}``: nothing held)."""
    return specs.get(agent, {})


def check_spec(spec: Any) -> str:
    """Why a goal's ``state`` field does not check (``""``: it does).

    Examples:
        >>> check_spec({"type": "demo.counter", "guards": {"t": ["demo.more", {}]}})
        ''
        >>> check_spec({"type": 3})
        'state: type is the name of an agent-state type'
    """
    if not isinstance(spec, dict) or set(spec) - {"type", "guards"}:
        return "state: {type, guards} expected"
    if not isinstance(spec.get("type", ""), str):
        return "state: type is the name of an agent-state type"
    guards = spec.get("guards", {})
    if not isinstance(guards, dict) or not all(
            isinstance(g, list) and len(g) == 2 and isinstance(g[0], str) and isinstance(g[1], dict)
            for g in guards.values()):
        return "state: guards maps transitions to [guard, params]"
    return ""


@dataclass
class Held:
    """One agent's state on the agent, for one run."""

    agent: str
    type: Any = None
    state: Any = None
    guards: dict[str, tuple[Callable[..., Any], dict[str, Any], str]] = field(default_factory=dict)
    seq: int = 0
    #: How many times the state was touched or replaced (a goal asleep on it is polled
    #: when this moved; a snapshot is sent when it moved since the last one).
    changes: int = 0
    sent_at: int = -1

    def touched(self, keys: tuple[str, ...]) -> None:
        self.changes += 1

    def snapshot(self) -> tuple[int, dict[str, bool]]:
        """The values of the subnet's state guards now, numbered.

        Raises:
            PetriflowError: a guard raised (naming its transition and guard).
        """
        values = {}
        for tid, (guard, params, name) in self.guards.items():
            try:
                values[tid] = bool(guard(self.state, params))
            except Exception as exc:
                raise PetriflowError(f"transition {tid!r}: guard {name!r} raised {type(exc).__name__}: {exc}")\
                    from exc
        self.seq += 1
        self.sent_at = self.changes
        return self.seq, values


class HeldStates:
    """``ctx.state`` on the agent: the one :class:`Held` state of the goal's agent (the
    context's ``services.agents``)."""

    def __init__(self, held: Held) -> None:
        self.held = held

    def state(self, agent: str | None) -> Any:
        return self.held.state

    def set_state(self, agent: str | None, state: Any, expected: Any = None) -> None:
        held = self.held
        expected = expected if expected is not None else held.type
        if expected is not None and state is not None and not isinstance(state, expected):
            raise PetriflowError(f"agent {held.agent!r}: its state must be a {type_names(expected)}, not"
                                 f" {type(state).__name__}")
        old = held.state
        if isinstance(old, AgentState) and old is not state:
            old.attach(None)
        held.state = state
        if isinstance(state, AgentState):
            state.attach(held.touched)
        held.changes += 1


class AgentMemory:
    """The states an agent process holds: one per run and agent name (see the module)."""

    def __init__(self, registry: Registry) -> None:
        self.registry = registry
        self.runs: OrderedDict[str, dict[str, Held]] = OrderedDict()

    def held(self, run: str, agent: str, spec: dict[str, Any]) -> Held:
        """The state of ``agent`` in ``run`` (made on its first goal), its guards from ``spec``.

        Raises:
            UnknownActionError: the spec names a state type or guard this agent's
                registry lacks.
        """
        states = self.runs.get(run)
        if states is None:
            states = self.runs[run] = {}
            while len(self.runs) > KEPT_RUNS:
                self.runs.popitem(last=False)
        held = states.get(agent)
        if held is None:
            kind = self.registry.state_type(spec["type"]) if spec.get("type") else None
            held = states[agent] = Held(agent, kind)
        for tid, (name, params) in spec.get("guards", {}).items():
            if tid not in held.guards:
                held.guards[tid] = (self.registry.guard(name), params, name)
        return held


def memory_error(exc: Exception) -> str:
    """A one-line reason for a goal whose state spec this agent cannot serve."""
    if isinstance(exc, UnknownActionError):
        return f"state: {exc}"
    return f"state: {type(exc).__name__}: {exc}"
