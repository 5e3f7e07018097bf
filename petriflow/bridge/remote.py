"""Remote transitions: bound, checked and fired through the run's own paths.

A run configuration's ``bridge:`` names subnets whose agents run elsewhere.
:func:`bind_remote` binds those subnets' transitions to a :class:`RemoteAction`
made for their action (the parameters checked against the action's local declaration
when this process has it), so the run's firing component fires them as any other:
``start`` sends a goal (its id ``run/firing/attempt``), ``poll`` ends the firing when
the result comes (``ok`` with its data as the output tokens', or ``failed``),
``cancel`` sends a cancel and waits for its acknowledgement. The goals go through the
run's :class:`~petriflow.runtime.services.RemoteGoals` service (a
:class:`~petriflow.bridge.dispatcher.Dispatcher`).

:func:`check_announced` checks the remote transitions against what the connected
agents announced (the action served, its parameters), with the net's ``file:line``.
"""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar

from petriflow.bridge import protocol
from petriflow.bridge.calls import answer
from petriflow.bridge.codec import Codec
from petriflow.bridge.dispatcher import Dispatcher, Phase
from petriflow.bridge.held import HeldGuards, held_guards, state_spec
from petriflow.bridge.spec import BridgeSpec
from petriflow.errors import NetFormatError, PetriflowError, did_you_mean
from petriflow.net import Net
from petriflow.runtime.action import Action, ActionContext, Param, Port, Status
from petriflow.runtime.binding import Binding, BoundTransition
from petriflow.runtime.registry import Registry, UnknownActionError
from petriflow.runtime.resources import LIVENESS

__all__ = ["RemoteAction", "RemoteCancelFailed", "bind_remote", "check_announced", "remote_transitions",
           "bridged_subnets", "firing_number"]


class RemoteCancelFailed(PetriflowError):
    """A remote goal's cancel was not acknowledged within ``cancel_timeout``: the run
    gave it up, and its firing ends ``failed`` (what the action did is unknown)."""


def firing_number(ctx: ActionContext) -> int:
    """The firing's number (its seed is ``run seed:number``)."""
    return int(str(ctx.seed).rpartition(":")[2])


class RemoteAction(Action):
    """A transition's action executed by a remote agent (see the module).

    Subclasses (made by :func:`bind_remote`) set :attr:`remote_agent` and
    :attr:`remote_action`.
    """

    needs_world: ClassVar[bool] = False
    remote_agent: ClassVar[str] = ""
    remote_action: ClassVar[str] = ""
    #: How token data crosses the bridge (:mod:`~.codec`: messages and registered payloads tagged).
    codec: ClassVar[Codec] = Codec()
    #: What the goals carry of the subnet's agent-held state (:mod:`~.held`; ``{}``: none).
    remote_state: ClassVar[dict[str, Any]] = {}
    params: ClassVar[dict[str, Param]] = {}

    def __init__(self, params: dict[str, Any] | None = None) -> None:
        super().__init__(params)
        self.goal_id = ""
        self.cancel_asked = False

    def _dispatcher(self, ctx: ActionContext) -> Dispatcher:
        remote = None if ctx.services is None else ctx.services.remote
        if remote is None:
            raise RuntimeError(f"{ctx.transition!r} runs on remote agent {self.remote_agent!r}, and this run has"
                               " no bridge connection")
        return remote

    def start(self, ctx: ActionContext) -> None:
        dispatcher = self._dispatcher(ctx)
        if dispatcher.is_lost(self.remote_agent):
            raise RuntimeError(f"agent {self.remote_agent!r} is lost")
        self.goal_id = protocol.goal_id(dispatcher.run, firing_number(ctx))
        self.cancel_asked = False
        inputs = {place: [self.codec.encode(d) for d in data] for place, data in ctx.inputs.items()}
        dispatcher.send(protocol.Goal(self.goal_id, self.remote_agent, self.remote_action,
                                      protocol.to_data(dict(ctx.params)), ctx.transition, inputs, str(ctx.seed),
                                      self.remote_state))
        self.wake_at = None

    def poll(self, ctx: ActionContext) -> Status:
        dispatcher = self._dispatcher(ctx)
        self._answer(ctx, dispatcher)
        state = dispatcher.goal(self.goal_id)
        if state is not None and state.at is not None:  # a resume replays the journaled ending
            return self._replayed(ctx, state)
        if state is not None and state.snapshot is not None:
            self._held(ctx, state.snapshot)
        if state is not None and state.ended:
            self._record(ctx, state)
            dispatcher.done(self.goal_id)
            if state.phase == Phase.OK:
                self._ok(ctx, state)
                return Status.OK
            ctx.reason = f"{self.remote_agent}: {state.reason or state.phase}"
            return Status.FAILED
        if dispatcher.is_lost(self.remote_agent):
            dispatcher.forget(self.goal_id)
            ctx.reason = self._lost_reason(dispatcher)
            return Status.FAILED
        return Status.RUNNING

    def cancel(self, ctx: ActionContext) -> bool:
        dispatcher = self._dispatcher(ctx)
        state = dispatcher.goal(self.goal_id)
        if state is not None and state.at is not None:  # a resume replays the journaled ending
            return self._replayed(ctx, state) is not Status.RUNNING
        if dispatcher.is_lost(self.remote_agent):  # nobody to ask: the outcome is unknown
            dispatcher.forget(self.goal_id)
            ctx.reason = self._lost_reason(dispatcher)
            return True
        if not self.cancel_asked:
            self.cancel_asked = True
            dispatcher.cancel(self.goal_id)
        dispatcher.refuse_calls(self.goal_id, "the goal is being cancelled")
        state = dispatcher.goal(self.goal_id)
        if state is not None and state.ended:
            self._record(ctx, state)
            dispatcher.done(self.goal_id)
            if state.phase == Phase.ABANDONED:  # the kernel's path for a cancel that failed: `failed`
                raise RemoteCancelFailed(f"{self.remote_agent}: {state.reason}")
            return True
        return False

    def _ok(self, ctx: ActionContext, state: Any) -> None:
        """The output tokens' data of a goal ended ``ok`` (its places given apart: ``ctx.put``
        on the agent), its messages and payloads rebuilt (:mod:`~.codec`).

        Raises:
            CodecError: a tagged object does not rebuild (the firing fails with it).
        """
        ctx.result, ctx.per_place = self.codec.decode(state.data), state.per_place
        for place, data in state.outputs.items():
            ctx.put(place, self.codec.decode(data))

    def _held(self, ctx: ActionContext, snapshot: tuple[int, dict[str, bool]]) -> None:
        """The agent's newest values of the subnet's state guards into the run's cache
        of its state (:class:`~petriflow.bridge.held.HeldGuards`), on the kernel's thread."""
        agents = ctx.services.agents
        held = agents.state(ctx.agent)
        if not isinstance(held, HeldGuards):
            held = HeldGuards(ctx.agent or self.remote_agent)
            agents.set_state(ctx.agent, held, HeldGuards)
        held.update(*snapshot)

    def _answer(self, ctx: ActionContext, dispatcher: Any) -> None:
        """Answer the goal's calls from the run's services, now: on the kernel's thread,
        at this firing's poll (:mod:`petriflow.bridge.calls`)."""
        calls = dispatcher.take_calls(self.goal_id)
        if not calls:
            return
        ports = {ctx.params.get(name) for name, declared in type(self).params.items() if isinstance(declared, Port)}
        services = ctx.services
        for call in calls:
            dispatcher.reply(answer(call, services, {p for p in ports if isinstance(p, str)}, self.codec))

    def _replayed(self, ctx: ActionContext, state: Any) -> Status:
        """The journaled ending of a resumed run's firing, at its journaled time."""
        if ctx.now < state.at - 1e-9:
            return Status.RUNNING
        if state.snapshot is not None:
            self._held(ctx, state.snapshot)
        if state.answered is not None or state.resent:
            self._record(ctx, state)
        if state.phase == Phase.OK:
            self._ok(ctx, state)
            return Status.OK
        ctx.reason = state.reason
        return Status.FAILED

    def _lost_reason(self, dispatcher: Dispatcher) -> str:
        return f"agent {self.remote_agent!r} lost: {dispatcher.why_lost(self.remote_agent)}"

    def _record(self, ctx: ActionContext, state: Any) -> None:
        """Which agent executed the firing, and the goal's round trip (a custom event)."""
        for name, data in state.events:  # what the action emitted on the agent, as a local one's
            ctx.emit(name, **data)
        trip = state.round_trip
        held = {} if state.snapshot is None else {"seq": state.snapshot[0], "guards": state.snapshot[1]}
        if state.outputs or state.per_place:  # journaled, so a resume replays them
            held.update(outputs=state.outputs, per_place=state.per_place)
        ctx.emit("remote", agent=self.remote_agent, goal=state.goal.id, phase=state.phase, resent=state.resent,
                 round_trip_ms=None if trip is None else round(trip * 1e3, 3), calls=state.answered_calls,
                 **held)


def bridged_subnets(net: Net, spec: BridgeSpec) -> dict[str, str]:
    """``{subnet id: remote agent}`` of the subnets ``spec`` lists (by id or agent).

    Raises:
        NetFormatError: ``spec`` names a subnet the net lacks.
    """
    out = {}
    by_agent = {(s.agent or s.id): s for s in net.subnets.values()}
    for subnet, agent in spec.agents.items():
        found = net.subnets.get(subnet) or by_agent.get(subnet)
        if found is None:
            names = sorted({*net.subnets, *by_agent})
            raise NetFormatError(f"bridge: agents: {subnet!r} is no subnet of net {net.id!r}"
                                 f"{did_you_mean(subnet, names)}", path=net.path)
        out[found.id] = agent
    return out


def remote_transitions(net: Net, spec: BridgeSpec) -> dict[str, str]:
    """``{transition: remote agent}`` of the transitions in the subnets ``spec`` lists.

    Raises:
        NetFormatError: ``spec`` names a subnet the net lacks.
    """
    subnets = bridged_subnets(net, spec)
    return {t.id: subnets[t.subnet] for t in net.transitions.values()
            if t.subnet in subnets and t.action is not None}


def bind_remote(net: Net, spec: BridgeSpec, registry: Registry, bind_local: Any, path: str | None) -> Binding:
    """Bind ``net``: the transitions of ``spec``'s subnets to remote actions, the others
    with ``bind_local(net)`` (the run's own binding).

    Raises:
        NetFormatError: a parameter does not check against the action's local
            declaration (``file:line``), a subnet is unknown.
    """
    remote = remote_transitions(net, spec)
    local_net = net.copy()
    for tid in remote:
        local_net.transitions[tid] = dataclasses.replace(local_net.transitions[tid], action=None)
    binding: Binding = bind_local(local_net)
    transitions = dict(binding.transitions)
    codec = Codec(registry.data_types())
    classes: dict[tuple[str, str], type[RemoteAction]] = {}
    for tid, agent in remote.items():
        transition = net.transitions[tid]
        name = transition.action
        try:
            local = registry.resolve(name)
        except UnknownActionError:
            local = None
        params = dict(transition.params)
        if local is not None:  # checked here as a local run would, with the net's line
            try:
                params = local.check_params(transition.params, tid)
            except NetFormatError as exc:
                raise _at(net, tid, path, exc.message, getattr(exc, "param", None)) from None
            _check_places(net, tid, path, name, local, params, registry)
        cls = classes.get((agent, name))
        if cls is None:
            cls = classes[agent, name] = type(f"Remote[{agent}:{name}]", (RemoteAction,),
                                              {"remote_agent": agent, "remote_action": name, "codec": codec,
                                               "params": dict(getattr(local, "params", {}) or {}),
                                               "__module__": __name__})
        old = transitions[tid]
        transitions[tid] = BoundTransition(tid, cls, params, old.guard, None, old.reads)
    held = held_guards(net, transitions, bridged_subnets(net, spec), path)  # the subnets' agent-held states
    for (agent, _), cls in classes.items():
        cls.remote_state = state_spec(held, agent)
    return dataclasses.replace(binding, net=net, transitions=transitions)


def _at(net: Net, tid: str, path: str | None, message: str, param: str | None = None) -> NetFormatError:
    """An error about transition ``tid`` (its parameter ``param``) at the net's line."""
    line = net.lines.get(f"{tid}/params/{param}") or net.lines.get(f"{tid}/params") or net.lines.get(tid)
    return NetFormatError(message, path=path or net.path, line=line, element=tid)


def _check_places(net: Net, tid: str, path: str | None, name: str, local: type[Action],
                  params: dict[str, Any], registry: Registry) -> None:
    """The places a remote action's parameters name must be the net's (its ports are
    read through the bridge, :mod:`petriflow.bridge.calls`); the resources it declares
    must be ``core.liveness`` (served by calls) or made per world (registered
    ``per_world``: the agent makes them from its own world), never the run's own."""
    resources = getattr(local, "resources", None) or {}
    unserved = sorted(r for r, kind in resources.items()
                      if kind != LIVENESS and not registry.per_world(kind))
    if unserved:
        raise _at(net, tid, path, f"action {name} takes the run's resource(s) {', '.join(unserved)}, which are"
                  f" not served to remote agents (served: {LIVENESS}, by calls; a resource registered per_world,"
                  " made on the agent from its own world; leave its subnet out of bridge: agents)",)
    for pname, declared in getattr(local, "params", {}).items():
        for place in declared.place_names(params.get(pname)):
            if not isinstance(place, str) or place not in net.places:
                hint = did_you_mean(place, net.places) if isinstance(place, str) else ""
                raise _at(net, tid, path, f"parameter {pname!r} names unknown place {place!r}{hint}", pname)


def check_announced(binding: Binding, dispatcher: Dispatcher, path: str | None = None) -> None:
    """Check each remote transition against what its agent announced.

    Raises:
        NetFormatError: ``file:line: 'transition': ...``: the agent did not announce
            itself, does not serve the action, or takes other parameters.
    """
    net = binding.net
    for tid, bound in binding.transitions.items():
        cls = bound.action
        if not (isinstance(cls, type) and issubclass(cls, RemoteAction)):
            continue

        def fail(message: str, *keys: str) -> NetFormatError:
            line = next((net.lines[k] for k in (*keys, tid) if net.lines.get(k) is not None), None)
            return NetFormatError(message, path=path or net.path, line=line, element=tid)

        served = dispatcher.announced(cls.remote_agent)
        if served is None:
            raise fail(f"remote agent {cls.remote_agent!r} did not announce itself within"
                       f" {dispatcher.spec.wait:g} s (is `petriflow agent --name {cls.remote_agent}` running and"
                       f" connected to {dispatcher.spec.connect}?)")
        declared = served.get(cls.remote_action)
        if declared is None:
            raise fail(f"remote agent {cls.remote_agent!r} does not serve action {cls.remote_action!r}"
                       f"{did_you_mean(cls.remote_action, served)}", f"{tid}/action")
        given = net.transitions[tid].params
        for name in given:
            if name not in declared:
                raise fail(f"action {cls.remote_action} on agent {cls.remote_agent!r} has no parameter {name!r}"
                           f"{did_you_mean(name, declared)} (it takes: {', '.join(declared) or 'nothing'})",
                           f"{tid}/params/{name}", f"{tid}/params")
        for name, entry in declared.items():
            if isinstance(entry, dict) and "default" not in entry and name not in given:
                raise fail(f"action {cls.remote_action} on agent {cls.remote_agent!r} needs parameter {name!r}",
                           f"{tid}/params")
