"""The robot's side of the bridge: ``petriflow agent`` serves registry actions to a run.

An :class:`AgentServer` connects to the router or broker under one or more agent
names, announces the actions of its registry with their parameters, and executes the
goals sent to those names with the very :class:`~petriflow.runtime.action.Action`
classes (and ``@action`` functions) a local run uses, in wall-clock time: ``start``
when the goal comes, ``poll`` at every step of its own world (``--world``, a pybullet
stand-in for the hardware) or when the action asked (``wake_at``), ``cancel`` when
the run cancels the goal. Its context has the goal's transition, agent, parameters,
input tokens and seed (so ``ctx.rng`` draws as in a local run), its world, and the
world file's settings the action declares (``ctx.settings``), and the run's services
that are served over the bridge (``ctx.read``/``ctx.latest`` of its ports,
``ctx.running``): each use sends a ``call`` and waits for the run's ``reply``
(:mod:`petriflow.bridge.calls`), heartbeats going on meanwhile; a service that is not
served fails the goal with its reason.

Goals are de-duplicated by id: a goal sent again (the run re-sends after a broker
restart) is answered from what the server holds of that id (``accepted`` while it
runs, the same ``result`` once it ended) and never executed twice. ``log`` gets one
JSON line per goal executed, for the operator (and the tests) to count executions.

``speed`` runs the agent's clock faster than the wall clock (2: twice as fast), for
demonstrations and tests; a robot runs at 1.

Threads: the goals are executed on one thread, the one that calls :meth:`AgentServer.serve`
(every ``setup``, ``start``, ``poll``, ``cancel`` and ``teardown``, one at a time, in the
order the messages came: action code is never concurrent with itself). A second thread
sends the heartbeats (and an announcement every four) of every name served, listing the
goals held, whatever the action thread does: an action computing for a minute inside
``start`` or ``poll`` leaves its agent alive to the run. What comes in meanwhile (goals,
cancels) waits in the inbox for the action thread: a cancel is carried out, and
acknowledged, when the computing call returns.
"""

from __future__ import annotations

import json
import logging
import queue
import threading
import time
import uuid
from dataclasses import dataclass
from typing import Any, Callable, TextIO

from petriflow.bridge import protocol
from petriflow.bridge.calls import CallRefused, calling_services
from petriflow.bridge.codec import Codec, CodecError
from petriflow.bridge.held import KEPT_RUNS, AgentMemory, Held, HeldStates, check_spec, memory_error
from petriflow.bridge.protocol import Refused
from petriflow.bridge.transport import Transport, agent_of, from_agent, to_agent
from petriflow.errors import NetFormatError, PetriflowError
from petriflow.runtime.action import REQUIRED, Action, ActionContext, Status, first_data, type_names
from petriflow.runtime.registry import Registry, UnknownActionError, default_registry
from petriflow.runtime.resources import ResourceContext, ResourceError
from petriflow.runtime.settings import read_settings

__all__ = ["AgentServer", "announcement"]

log = logging.getLogger("petriflow.bridge.agent")
#: Ended goals remembered per server (to answer a goal sent again); the oldest are forgotten.
REMEMBERED = 100_000
#: Seconds an action waits for the run to answer a call, by default.
CALL_TIMEOUT = 60.0


def announcement(registry: Registry) -> dict[str, dict[str, Any]]:
    """``{action: {parameter: {"type": ..., "default": ...}}}`` of every action of
    ``registry`` (a required parameter has no ``default``).

    Examples:
        >>> announcement(default_registry)["core.wait"]["seconds"]["type"]
        'float'
    """
    actions: dict[str, dict[str, Any]] = {}
    for name in registry.names():
        try:
            cls = registry.resolve(name)
        except Exception:  # an action whose module does not import is not served
            continue
        declared = {}
        for pname, param in getattr(cls, "params", {}).items():
            entry: dict[str, Any] = {"type": type_names(param.type)}
            if param.default is not REQUIRED:
                entry["default"] = protocol.to_data(param.default)
            declared[pname] = entry
        actions[name] = declared
    return actions


@dataclass
class _Running:
    """A goal being executed."""

    goal: protocol.Goal
    action: Action
    ctx: ActionContext
    ends_at: float | None = None  # an action that only waits: when it ends
    cancelling: bool = False
    held: Held | None = None  # its agent's state, when the agent holds it (:mod:`~.held`)
    seen: int = 0  # the state's changes when it was last polled (an action asleep on it wakes)


class WorldResources:
    """The resources an agent makes from its own world for one run: those registered
    ``per_world`` (:meth:`~petriflow.runtime.registry.Registry.register_resource`), each
    made once, on first use, by the factory a local run uses, from the agent's world
    and its file's settings (no liveness, no configuration: a per-world resource reads
    neither; the run's ``core.liveness`` is served by calls).

    Examples:
        >>> registry = Registry(False)
        >>> registry.register_resource("demo.size", lambda context: len(context.world), per_world=True)
        >>> made = WorldResources(registry, [1, 2, 3])
        >>> made.get("demo.size"), made.get("demo.size") is made.get("demo.size")
        (3, True)
    """

    def __init__(self, registry: Registry, world: Any) -> None:
        self.registry = registry
        self.world = world
        self.made: dict[str, Any] = {}

    def get(self, kind: str) -> Any:
        """The run's resource of type ``kind``, made here on first use.

        Raises:
            ResourceError: its settings do not check, or its factory refused.
        """
        if kind not in self.made:
            section = self.registry.resource_settings(kind)
            try:
                settings = {} if section is None else read_settings(getattr(self.world, "meta", None),
                                                                     {section.name: section})
                self.made[kind] = self.registry.resource_factory(kind)(
                    ResourceContext(self.world, None, None, settings))
            except ResourceError:
                raise
            except PetriflowError as exc:
                raise ResourceError(f"resource {kind} (made on the agent): {exc}") from None
        return self.made[kind]


class AgentServer:
    """Executes goals for ``names`` (see the module).

    Args:
        names: the agent names served.
        transport: an open transport.
        registry: where actions are found (default: the run registry).
        world: the world actions run in (``None``: none).
        speed: agent seconds per wall-clock second.
        heartbeat: seconds between heartbeats (an announcement every four).
        log_file: where to write one JSON line per goal executed.
        now: the wall clock.
        call_timeout: seconds an action waits for the run to answer a call (a run
            paused longer: the call fails, and the action with it).
    """

    def __init__(self, names: list[str], transport: Transport, *, registry: Registry | None = None,
                 world: Any = None, speed: float = 1.0, heartbeat: float = 0.5, log_file: TextIO | None = None,
                 now: Callable[[], float] = time.perf_counter, call_timeout: float = CALL_TIMEOUT) -> None:
        self.names = list(dict.fromkeys(names))
        self.transport = transport
        self.registry = registry or default_registry
        self.world = world
        self.speed = speed
        self.heartbeat = heartbeat
        self.log_file = log_file
        self.wall = now
        self.instance = uuid.uuid4().hex[:12]
        self.actions = announcement(self.registry)
        self.inbox: queue.SimpleQueue[tuple[str, bytes]] = queue.SimpleQueue()
        self.replies: queue.SimpleQueue[protocol.Reply] = queue.SimpleQueue()
        self.call_timeout = call_timeout
        self.calls: dict[str, int] = {}  # goal id -> calls its action made
        self.running: dict[str, _Running] = {}
        self.ended: dict[str, protocol.BridgeMessage] = {}
        self.instances: dict[tuple[str, str, str], Action] = {}
        self.memory = AgentMemory(self.registry)  # the agent states it holds (:mod:`petriflow.bridge.held`)
        self.codec = Codec(self.registry.data_types())  # token data's messages and payloads (:mod:`~.codec`)
        self.own: dict[str, WorldResources] = {}  # per run: the resources made from its world
        self.executed = 0
        self.dropped = 0
        self._stop = threading.Event()
        self._held = threading.Lock()  # self.running, between the action thread and the heartbeats
        self._start = now()
        self._dt = float(getattr(world, "dt", None) or 0.01)
        for name in self.names:
            transport.subscribe(to_agent(name), self._receive)

    @property
    def now(self) -> float:
        """The agent's time: wall-clock seconds since it started, times :attr:`speed`."""
        return (self.wall() - self._start) * self.speed

    def _receive(self, topic: str, payload: bytes) -> None:
        if payload[:40].replace(b" ", b"").find(b'"type":"reply"') >= 0:  # for an action waiting on a call
            try:
                message = protocol.decode(payload)
            except Refused:
                message = None
            if isinstance(message, protocol.Reply) and message.agent == agent_of(topic):
                self.replies.put(message)
                return
        self.inbox.put((topic, payload))

    def call(self, goal: protocol.Goal, service: str, method: str, args: list[Any]) -> Any:
        """Ask the run's ``service`` for a running goal and wait for its reply (sent again
        every two heartbeats; the heartbeat thread goes on meanwhile).

        Raises:
            CallRefused: the run refused it (the reply's error), or no reply came within
                :attr:`call_timeout` seconds.
        """
        number = self.calls[goal.id] = self.calls.get(goal.id, 0) + 1
        message = protocol.Call(goal.id, goal.agent, number, service, method, protocol.to_data(args))
        self._send(goal.agent, message)
        start = resend = self.wall()
        while True:
            wall = self.wall()
            if wall - start > self.call_timeout:
                raise CallRefused(f"{service}.{method}: no reply from the run within {self.call_timeout:g} s")
            if wall - resend >= 2 * self.heartbeat:
                resend = wall
                self._send(goal.agent, message)
            try:
                reply = self.replies.get(timeout=max(0.0, resend + 2 * self.heartbeat - wall))
            except queue.Empty:
                continue
            if reply.id != goal.id or reply.call != number:
                continue  # an answer to a call given up, or sent twice
            if reply.error:
                raise CallRefused(f"{service}.{method}: the run refused: {reply.error}")
            return reply.value

    def _send(self, agent: str, message: protocol.BridgeMessage) -> None:
        self.transport.publish(from_agent(agent), protocol.encode(message))

    def announce(self) -> None:
        """Announce every name served."""
        for name in self.names:
            self._send(name, protocol.Announce(name, self.actions, self.instance))

    def stop(self) -> None:
        """Make :meth:`serve` return (from another thread or a signal handler)."""
        self._stop.set()
        self.inbox.put(("", b""))

    def serve(self, until: Callable[[], bool] | None = None) -> None:
        """Serve goals until :meth:`stop` (or ``until()`` is true), on this thread, with
        the heartbeats on a thread of their own (see the module); running goals are
        cancelled and every action torn down at the end."""
        self.announce()
        beating = threading.Event()
        beats = threading.Thread(target=self._heartbeats, args=(beating,), name="petriflow-agent-heartbeat",
                                 daemon=True)
        beats.start()
        next_step = self.wall()
        try:
            while not self._stop.is_set() and not (until is not None and until()):
                wall = self.wall()
                if wall >= next_step:
                    next_step += self._dt / self.speed
                    if next_step < wall:
                        next_step = wall  # behind: never try to catch up a burst of steps
                    if self.world is not None and self.running:
                        self.world.step()
                    self._poll_all()
                wait = max(0.0, next_step - self.wall()) if self.running else self.heartbeat
                try:
                    topic, payload = self.inbox.get(timeout=wait)
                except queue.Empty:
                    continue
                if topic:
                    self.handle(agent_of(topic), payload)
                while True:  # what else came in meanwhile
                    try:
                        topic, payload = self.inbox.get_nowait()
                    except queue.Empty:
                        break
                    if topic:
                        self.handle(agent_of(topic), payload)
        finally:
            beating.set()
            beats.join(timeout=10)
            for goal_id in list(self.running):
                self._finish_cancel(goal_id, force=True)
            for action in self.instances.values():
                try:
                    action.teardown()
                except Exception as exc:
                    log.warning("teardown failed: %s", exc)

    def _heartbeats(self, done: threading.Event) -> None:
        """The heartbeat thread: every :attr:`heartbeat` seconds until ``done``, one
        heartbeat per name served (listing its goals held), an announcement every four."""
        beats = 0
        while not done.wait(self.heartbeat):
            beats += 1
            try:
                self._beat(announce=beats % 4 == 0)
            except Exception as exc:  # a transport error must not end the heartbeats
                log.warning("heartbeat failed: %s", exc)

    def _beat(self, announce: bool) -> None:
        if announce:
            self.announce()
        with self._held:
            held = [(g, r.goal.agent) for g, r in self.running.items()]
        for name in self.names:
            goals = [goal_id for goal_id, agent in held if agent == name]
            self._send(name, protocol.Heartbeat(name, goals, self.instance))

    def _hold(self, running: _Running) -> None:
        with self._held:
            self.running[running.goal.id] = running

    def _release(self, goal_id: str) -> None:
        with self._held:
            del self.running[goal_id]

    # one message -----------------------------------------------------------------------------
    def handle(self, agent: str, payload: bytes) -> None:
        """One message for ``agent`` (a name served): checked, then acted on."""
        try:
            message = protocol.decode(payload)
        except Refused as exc:
            self.dropped += 1
            log.warning("dropped a message for %s: %s", agent, exc)
            return
        if isinstance(message, protocol.Heartbeat):
            return
        if not isinstance(message, (protocol.Goal, protocol.Cancel)) or message.agent != agent:
            self.dropped += 1
            log.warning("dropped a %s for %s", message.kind.value, agent)
            return
        if isinstance(message, protocol.Cancel):
            self.cancel(message)
            return
        done = self.ended.get(message.id)
        if done is not None:  # sent again: the same answer, never a second execution
            self._send(agent, done)
        elif message.id in self.running:
            self._send(agent, protocol.Accepted(message.id, agent))
        else:
            self.execute(message)

    def cancel(self, message: protocol.Cancel) -> None:
        """Stop a running goal (its action's ``cancel`` until it is done); acknowledge."""
        running = self.running.get(message.id)
        if running is None:
            done = self.ended.get(message.id)
            if isinstance(done, protocol.Result):  # it had ended: the run learns how
                self._send(message.agent, done)
            else:
                self._send(message.agent, protocol.Cancelled(message.id, message.agent))
            return
        running.cancelling = True
        self._finish_cancel(message.id)

    def _finish_cancel(self, goal_id: str, force: bool = False) -> None:
        running = self.running[goal_id]
        running.ctx.now = self.now
        try:
            done = running.ends_at is not None or running.action.cancel(running.ctx)
        except Exception as exc:
            log.warning("cancel of %s raised %s", goal_id, exc)
            done = True
        if done or force:
            self._release(goal_id)
            self._remember(goal_id, protocol.Cancelled(goal_id, running.goal.agent))

    def _remember(self, goal_id: str, answer: protocol.BridgeMessage) -> None:
        self.calls.pop(goal_id, None)
        self.ended[goal_id] = answer
        if len(self.ended) > REMEMBERED:
            del self.ended[next(iter(self.ended))]
        self._send(answer.agent, answer)

    def _own(self, run: str) -> WorldResources:
        """The resources made from this agent's world for ``run`` (the last runs' kept)."""
        own = self.own.get(run)
        if own is None:
            own = self.own[run] = WorldResources(self.registry, self.world)
            while len(self.own) > KEPT_RUNS:
                del self.own[next(iter(self.own))]
        return own

    def execute(self, goal: protocol.Goal) -> None:
        """Start executing ``goal``: reject it if its action or parameters do not check."""
        try:
            cls = self.registry.resolve(goal.action)
            params = cls.check_params(goal.params, goal.transition or goal.action)
        except (UnknownActionError, NetFormatError) as exc:
            self._remember(goal.id, protocol.Rejected(goal.id, goal.agent, str(exc)))
            return
        held = None
        if goal.state:  # the subnet's state lives here: made on its first goal, given as ctx.state
            why = check_spec(goal.state)
            try:
                held = None if why else self.memory.held(goal.id.partition("/")[0], goal.agent, goal.state)
            except Exception as exc:
                why = memory_error(exc)
            if why:
                self._remember(goal.id, protocol.Rejected(goal.id, goal.agent, why))
                return
        key = (goal.agent, goal.transition, json.dumps(protocol.to_data(params), sort_keys=True))
        action = self.instances.get(key)
        setup_error = None
        if action is None:
            action = self.instances[key] = cls(params)
            try:
                action.setup(self.world)
            except Exception as exc:
                setup_error = f"setup: {type(exc).__name__}: {exc}"
        section = getattr(cls, "settings", None)
        try:  # the world file's settings the action declares, as a local run reads them
            settings = {} if section is None else read_settings(getattr(self.world, "meta", None),
                                                                 {section.name: section})
        except NetFormatError as exc:
            self._remember(goal.id, protocol.Rejected(goal.id, goal.agent, f"the world's settings: {exc}"))
            return
        try:
            inputs = {place: [self.codec.decode(d) for d in data] for place, data in goal.inputs.items()}
        except CodecError as exc:
            self._remember(goal.id, protocol.Rejected(goal.id, goal.agent, str(exc)))
            return
        now = self.now
        ctx = ActionContext(goal.transition or goal.action, goal.agent, params, inputs, self.world,
                            goal.seed or goal.id, now, now, action=cls,
                            services=calling_services(settings, lambda *asked: self.call(goal, *asked),
                                                      None if held is None else HeldStates(held),
                                                      self._own(goal.id.partition("/")[0]), self.registry.per_world,
                                                      self.codec))
        self.executed += 1
        if self.log_file is not None:
            self.log_file.write(json.dumps({"goal": goal.id, "agent": goal.agent, "action": goal.action,
                                            "transition": goal.transition, "at": round(now, 6)}) + "\n")
            self.log_file.flush()
        self._send(goal.agent, protocol.Accepted(goal.id, goal.agent))
        if setup_error is not None:
            self._end(goal, ctx, Status.FAILED, setup_error, held)
            return
        running = _Running(goal, action, ctx, held=held)
        self._hold(running)
        try:
            seconds = action.delay()
        except Exception:
            seconds = None
        if seconds is not None:
            running.ends_at = now + seconds
            self._poll(running)
            return
        try:
            action.start(ctx)
        except Exception as exc:
            self._release(goal.id)
            self._end(goal, ctx, Status.FAILED, f"{type(exc).__name__}: {exc}", held)
            return
        wake = action.wake_at
        if action.needs_world or wake is None or wake <= now:
            self._poll(running)
        else:
            self._changed(running)

    def _poll_all(self) -> None:
        for running in list(self.running.values()):
            if running.cancelling:
                self._finish_cancel(running.goal.id)
                continue
            action = running.action
            if running.ends_at is None and not action.needs_world and action.wake_at is not None \
                    and action.wake_at > self.now and not (action.wake_on and running.held is not None
                                                           and running.held.changes != running.seen):
                continue  # asleep until its time, or (wake_on) until its agent's state changes
            self._poll(running)

    def _poll(self, running: _Running) -> None:
        ctx = running.ctx
        ctx.now = now = self.now
        if running.ends_at is not None:
            if now + 1e-9 < running.ends_at:
                return
            ctx.result = first_data(ctx.inputs)
            status = Status.OK
        else:
            try:
                status = running.action.poll(ctx)
            except Exception as exc:
                ctx.reason = f"{type(exc).__name__}: {exc}"
                status = Status.FAILED
        if status is Status.RUNNING:
            self._changed(running)
            return
        self._release(running.goal.id)
        self._end(running.goal, ctx, status if status in (Status.OK, Status.FAILED) else Status.FAILED,
                  ctx.reason or ("" if status in (Status.OK, Status.FAILED) else f"poll() returned {status!r}"),
                  running.held)

    def _changed(self, running: _Running) -> None:
        """A goal goes on: when its agent's state changed since the last snapshot, the
        guards' values go to the run now (a ``feedback``)."""
        held = running.held
        if held is None:
            return
        running.seen = held.changes
        if held.changes == held.sent_at:
            return
        try:
            seq, values = held.snapshot()
        except Exception as exc:
            log.warning("goal %s: %s", running.goal.id, exc)
            return
        self._send(running.goal.agent, protocol.Feedback(running.goal.id, running.goal.agent, None, values, seq))

    def _end(self, goal: protocol.Goal, ctx: ActionContext, status: Status, reason: str = "",
             held: Held | None = None) -> None:
        events = [[kind, protocol.to_data(data)] for kind, data in ctx.emitted or ()]
        seq, values = 0, {}
        if held is not None:  # the subnet's state guards, evaluated where the state is
            try:
                seq, values = held.snapshot()
            except Exception as exc:
                status, reason = Status.FAILED, str(exc)
        if status is Status.OK:
            data = ctx.result
            per_place = bool(ctx.per_place and isinstance(data, dict))
            try:
                answer = protocol.Result(goal.id, goal.agent, "ok", self.codec.encode(data), "", values, seq,
                                         events, self.codec.encode(ctx.outputs or {}), per_place)
            except ValueError as exc:
                answer = protocol.Result(goal.id, goal.agent, "failed", None, f"the output tokens: {exc}", values,
                                         seq, events)
        else:
            answer = protocol.Result(goal.id, goal.agent, "failed", None, reason or ctx.reason or "failed", values,
                                     seq, events)
        self._remember(goal.id, answer)
