"""The discrete-event scheduler: the net decides when agents act.

One loop, readable in a sitting (after SimPy):

1. **Fire** every transition that can fire at the current instant, one at a time:
   among the enabled ones (enough tokens, guard true, agent alive, its action not
   already running) the highest ``priority`` wins, ties are broken by the run's
   seeded random generator. Firing consumes the input tokens, applies the
   cancellation region, and starts the bound action.
2. **Advance** simulated time by one tick (the world's ``dt``) when an action that
   needs the world is running, or jump straight to the next wake-up, delivery or
   fault otherwise; the world is stepped to the new time either way.
3. **Poll** running actions; an action that ends produces the output tokens of its
   outcome (``ok``, ``failed``, ``timeout``, ``cancelled``). Tokens put into a channel
   place go through the channel's model and appear on delivery, or never.

Time is an integer count of ticks, so the same net, world, configuration and seed give
the same events bit for bit. Each transition runs one action at a time (a robot walks
one walk at a time): a transition whose action is running is not enabled.

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> net = loads_net('''
    ... petriflow: 1
    ... places: [{id: i, tokens: 1}, o]
    ... transitions: [{id: rest, action: core.wait, params: {seconds: 2}, in: [i], out: [o]}]
    ... ''')
    >>> run = Scheduler(net, seed=1)
    >>> result = run.run()
    >>> result.reason, result.time, result.marking
    ('dead', 2.0, Marking({'o': 1}))
"""

from __future__ import annotations

import math
import random
import time as wallclock
from collections import deque
from dataclasses import dataclass, field
from typing import Any, Callable

from petriflow.errors import PetriflowError
from petriflow.marking import Marking
from petriflow.net import Net
from petriflow.runtime.action import Action, ActionContext, ActionFailed, Outcome, Status
from petriflow.runtime.channels import ChannelModel, IdealChannel, Message
from petriflow.runtime.config import Fault, RunConfig
from petriflow.runtime.registry import Registry, default_registry
from petriflow.runtime.trace import Event, summarize

__all__ = ["Scheduler", "RunResult", "ZenoError"]

#: Firings allowed at one instant before the run is declared Zeno (an endless
#: cascade of instant transitions).
MAX_FIRINGS_PER_INSTANT = 100_000

EventHandler = Callable[[Event], None]


class ZenoError(PetriflowError):
    """Instant transitions keep firing without simulated time passing."""


@dataclass
class RunResult:
    """How a run ended.

    Attributes:
        reason: ``"final"`` (the net's final marking was reached), ``"dead"`` (no
            transition can fire and nothing is running or pending, without reaching
            a declared final marking), ``"until"`` (the
            time limit), ``"firings"`` (the firing limit), or ``"failed"`` (an action
            failed with no failure route; see ``error``).
        time: simulated seconds at the end.
        firings: transitions fired.
        marking: token counts at the end.
        events: number of events recorded.
        error: the unrouted failure, if any.
    """

    reason: str
    time: float
    firings: int
    marking: Marking
    events: int
    error: str | None = None
    tokens: dict[str, list[Any]] = field(default_factory=dict)


@dataclass
class _Running:
    firing: int
    transition: str
    action: Action
    ctx: ActionContext
    deadline: float | None
    cancelling: str | None = None  # outcome being cancelled towards (timeout/cancelled)


class Scheduler:
    """Runs a net's transitions as agent actions over an optional world.

    Args:
        net: the net to run (loaded and bound: unknown actions fail here).
        world: a :class:`petriflow.world.World` or any object with ``dt``,
            ``step()`` and optionally ``position(agent)``; ``None`` for a world-less run.
        config: faults, channel models, limits (:class:`RunConfig`).
        seed: seed of conflict resolution, action randomness and channel losses
            (overrides ``config.seed`` when given).
        registry: where action and guard names are looked up.
        path: the net's file, named in errors.
    """

    def __init__(
        self,
        net: Net,
        *,
        world: Any = None,
        config: RunConfig | None = None,
        seed: int | None = None,
        registry: Registry | None = None,
        path: str | None = None,
    ) -> None:
        self.net = net
        self.world = world
        self.config = config or RunConfig()
        self.seed = self.config.seed if seed is None else seed
        self.registry = registry or default_registry
        self.bound = self.registry.bind(net, path)
        self.config.check(net)
        self.dt = float(getattr(world, "dt", None) or self.config.dt)
        self._tick = 0
        self._handlers: list[EventHandler] = []
        self._seq = 0
        self._firings = 0
        self._rng = random.Random(f"{self.seed}:conflicts")
        self._channel_rng = random.Random(f"{self.seed}:channels")
        self.tokens: dict[str, deque] = {p: deque() for p in net.places}
        for place, count in net.initial_marking.items():
            self.tokens[place].extend([None] * count)
        self._agent_of = {
            t.id: (net.subnets[t.subnet].agent or t.subnet) if t.subnet else None
            for t in net.transitions.values()
        }
        self._place_agent = {
            p.id: (net.subnets[p.subnet].agent or p.subnet) if p.subnet else None
            for p in net.places.values()
        }
        self._consumers: dict[str, list[str]] = {p: [] for p in net.places}
        for t in net.transitions:
            for p in net.preset(t):
                self._consumers[p].append(t)
        self._preset = {t: net.preset(t) for t in net.transitions}
        self._guarded = [t.id for t in net.transitions.values() if t.guard is not None]
        # per transition: {route: [(place, weight, is channel)]}, route "ok" or an outcome
        self._outputs = {
            t: {route: [(p, w, net.places[p].channel is not None)
                        for p, w in net.postset(t, None if route == "ok" else route).items()]
                for route in ("ok", *net.outcomes(t))}
            for t in net.transitions
        }
        # per transition: besides consumers of touched places, what to re-check after
        # it fires: itself (its action may be running now) and the actions it cancels
        self._recheck = {
            t: {t, *(n for n in net.transitions[t].cancels if n in net.transitions)}
            for t in net.transitions
        }
        self._order = {t: i for i, t in enumerate(net.transitions)}
        self._actions: dict[str, Action] = {}
        self._running: dict[str, _Running] = {}
        self._pending: list[tuple[int, int, str, Any]] = []  # (tick, order, kind, payload)
        self._pending_order = 0
        self.alive: dict[str, bool] = {a: True for a in self.agents()}
        self._down_links: set[frozenset[str]] = set()
        self._channels: dict[str, ChannelModel] = dict(self.config.channel_models())
        self.blackboard: dict[str, Any] = {}
        self._started = False
        self._max_firings: int | None = None
        self._finished: RunResult | None = None
        self._wall_start = 0.0
        for fault in self.config.faults:
            self._schedule(self._ticks_at(fault.at), "fault", fault)
            if fault.kind == "join":
                self.alive[fault.agent] = False

    # Observers ----------------------------------------------------------------------
    def on_event(self, handler: EventHandler) -> None:
        """Call ``handler(event)`` for every event, in order."""
        self._handlers.append(handler)

    def _emit(self, kind: str, transition: str | None = None, agent: str | None = None,
              **data: Any) -> Event:
        event = Event(self._seq, round(self.now, 9), kind, transition, agent, data)
        self._seq += 1
        for handler in self._handlers:
            handler(event)
        return event

    # Clock --------------------------------------------------------------------------
    @property
    def now(self) -> float:
        """Current simulated time in seconds."""
        return self._tick * self.dt

    def _ticks_at(self, seconds: float) -> int:
        return max(0, math.ceil(seconds / self.dt - 1e-9))

    def _schedule(self, tick: int, kind: str, payload: Any) -> None:
        self._pending.append((tick, self._pending_order, kind, payload))
        self._pending_order += 1
        self._pending.sort(key=lambda item: (item[0], item[1]))

    # Queries ------------------------------------------------------------------------
    def agents(self) -> list[str]:
        """Agent names of the net's subnets, in declaration order."""
        seen: list[str] = []
        for subnet in self.net.subnets.values():
            agent = subnet.agent or subnet.id
            if agent not in seen:
                seen.append(agent)
        return seen

    def marking(self) -> Marking:
        """Token counts now."""
        return Marking({p: len(q) for p, q in self.tokens.items() if q})

    def running(self) -> list[str]:
        """Transitions whose actions are running, in firing order."""
        return [r.transition for r in sorted(self._running.values(), key=lambda r: r.firing)]

    def _can_fire(self, t: str) -> bool:
        if t in self._running:
            return False
        agent = self._agent_of[t]
        if agent is not None and not self.alive.get(agent, True):
            return False
        tokens = self.tokens
        for place, weight in self._preset[t].items():
            if len(tokens[place]) < weight:
                return False
        guard = self.net.transitions[t].guard
        if guard is not None:
            offered = {p: list(tokens[p])[:w] for p, w in self._preset[t].items()}
            if not self.registry.guard(guard)(offered, self.net.transitions[t].params, self.blackboard):
                return False
        return True

    def enabled(self) -> list[str]:
        """Transitions that may fire now, in the net's order."""
        return [t for t in self.net.transitions if self._can_fire(t)]

    # Firing ------------------------------------------------------------------------
    def _choose(self, candidates: list[str]) -> str:
        best = max(self.net.transitions[t].priority for t in candidates)
        top = [t for t in candidates if self.net.transitions[t].priority == best]
        if len(top) == 1:
            return top[0]
        return top[int(self._rng.random() * len(top))]

    def _fire_instant(self) -> None:
        """Fire until nothing more can fire at this instant.

        The enabled set is kept up to date incrementally: after a firing only the
        consumers of the places it touched, the transition itself, its cancellation
        region and guarded transitions (whose guards may read any data) are re-checked.
        """
        fired_here = 0
        enabled = {t for t in self.net.transitions if self._can_fire(t)}
        while enabled and (self._max_firings is None or self._firings < self._max_firings):
            t = self._choose(sorted(enabled, key=self._order.__getitem__))
            touched = self._fire(t)
            fired_here += 1
            if fired_here > MAX_FIRINGS_PER_INSTANT:
                raise ZenoError(
                    f"more than {MAX_FIRINGS_PER_INSTANT} firings at t={self.now:g}s without time"
                    " passing (a cycle of instant transitions?)"
                )
            dirty = {u for p in touched for u in self._consumers[p]}
            dirty |= self._recheck[t]
            for u in (*dirty, *self._guarded):
                if self._can_fire(u):
                    enabled.add(u)
                else:
                    enabled.discard(u)

    def _fire(self, t: str) -> set[str]:
        """Fire ``t`` now: consume, cancel its region, start its action. Returns the
        places whose tokens changed."""
        transition = self.net.transitions[t]
        self._firings += 1
        firing = self._firings
        inputs: dict[str, list[Any]] = {}
        for place, weight in self._preset[t].items():
            queue = self.tokens[place]
            inputs[place] = [queue.popleft() for _ in range(weight)]
        touched = set(inputs)
        agent = self._agent_of[t]
        details: dict[str, Any] = {"firing": firing, "consumed": {p: len(v) for p, v in inputs.items()}}
        carried = {p: [summarize(d) for d in v] for p, v in inputs.items() if any(d is not None for d in v)}
        if carried:
            details["inputs"] = carried
        self._emit("start", t, agent, **details)
        if transition.cancels:
            touched |= self._cancel_region(transition, firing)
        bound = self.bound.get(t)
        now = self.now
        ctx = ActionContext(
            transition=t, agent=agent, params=bound[1] if bound else dict(transition.params),
            inputs=inputs, world=self.world, seed=f"{self.seed}:{firing}",
            started=now, now=now, blackboard=self.blackboard,
        )
        if bound is None:
            ctx.result = ctx.token()
            touched |= self._finish(firing, t, ctx, Outcome.OK)
            return touched
        action = self._action(t)
        deadline = None if transition.timeout is None else self.now + transition.timeout
        running = _Running(firing, t, action, ctx, deadline)
        self._running[t] = running
        try:
            action.start(ctx)
        except Exception as exc:  # an action's error is a failed outcome, never lost
            ctx.reason = _reason(exc)
            del self._running[t]
            touched |= self._finish(firing, t, ctx, Outcome.FAILED)
            return touched
        touched |= self._poll(running)
        return touched

    def _action(self, t: str) -> Action:
        if t not in self._actions:
            cls, params = self.bound[t]
            action = cls(params)
            action.setup(self.world)
            self._actions[t] = action
        return self._actions[t]

    def _cancel_region(self, transition, firing: int) -> set[str]:
        touched: set[str] = set()
        withdrawn: dict[str, int] = {}
        for node in transition.cancels:
            if node in self.tokens and self.tokens[node]:
                withdrawn[node] = len(self.tokens[node])
                self.tokens[node].clear()
                touched.add(node)
            elif node in self._running:
                self._running[node].cancelling = Outcome.CANCELLED.value
        if withdrawn or any(n in self._running for n in transition.cancels):
            self._emit("cancel", transition.id, self._agent_of[transition.id], firing=firing,
                       withdrawn=withdrawn,
                       actions=[n for n in transition.cancels if n in self._running])
        for node in transition.cancels:
            if node in self._running:
                touched |= self._poll(self._running[node])
        return touched

    def _poll(self, running: _Running) -> set[str]:
        """Poll one running action (or drive its cancellation); finish it if it ended."""
        ctx, action = running.ctx, running.action
        ctx.now = self.now
        if running.cancelling is None and running.deadline is not None and self.now >= running.deadline - 1e-9:
            running.cancelling = Outcome.TIMEOUT.value
        if running.cancelling is not None:
            try:
                done = action.cancel(ctx)
            except Exception as exc:
                ctx.reason = _reason(exc)
                done = True
            if not done:
                return set()
            del self._running[running.transition]
            return self._finish(running.firing, running.transition, ctx, Outcome(running.cancelling))
        try:
            status = action.poll(ctx)
        except Exception as exc:
            ctx.reason = _reason(exc)
            status = Status.FAILED
        if status is Status.RUNNING:
            return set()
        if not isinstance(status, Status):
            ctx.reason = f"poll() returned {status!r}, not a Status"
            status = Status.FAILED
        del self._running[running.transition]
        outcome = Outcome.OK if status is Status.OK else Outcome.FAILED
        return self._finish(running.firing, running.transition, ctx, outcome)

    def _finish(self, firing: int, t: str, ctx: ActionContext, outcome: Outcome) -> set[str]:
        """Produce the outputs of ``outcome`` and record the end of the firing."""
        net = self.net
        route = outcome.value
        routes = self._outputs[t]
        if outcome is Outcome.TIMEOUT and "timeout" not in routes and "failed" in routes:
            route = "failed"  # a timeout is a failure when the net routes only failures
        if outcome in (Outcome.FAILED, Outcome.TIMEOUT) and route not in routes:
            reason = ctx.reason or outcome.value
            self._emit("end", t, self._agent_of[t], firing=firing, outcome=outcome.value,
                       produced={}, reason=reason)
            raise ActionFailed(net.id, t, net.transitions[t].action or "-", reason)
        produced: dict[str, int] = {}
        sent: list[tuple[str, Any]] = []
        per_place = ctx.per_place and isinstance(ctx.result, dict)
        for place, weight, channel in routes.get(route, ()):
            data = ctx.result.get(place) if per_place else ctx.result
            if channel:
                sent.extend([(place, data)] * weight)
            else:
                self.tokens[place].extend([data] * weight)
                produced[place] = weight
        for kind, data in ctx.emitted:
            self._emit("custom", t, ctx.agent, firing=firing, name=kind, data=summarize(data))
        ctx.emitted.clear()
        details: dict[str, Any] = {"firing": firing, "outcome": outcome.value, "produced": produced}
        if ctx.result is not None:
            details["result"] = summarize(ctx.result)
        if ctx.reason:
            details["reason"] = ctx.reason
        self._emit("end", t, ctx.agent, **details)
        for place, data in sent:
            self._send(place, data, ctx.agent)
        return set(produced)

    # Channels -----------------------------------------------------------------------
    def _receiver(self, place: str) -> str | None:
        if self._place_agent[place] is not None:
            return self._place_agent[place]
        for t in self._consumers[place]:
            if self._agent_of[t] is not None:
                return self._agent_of[t]
        return None

    def _send(self, place: str, data: Any, sender: str | None) -> None:
        channel = self.net.places[place].channel
        receiver = self._receiver(place)
        model = self._channels.setdefault(channel, IdealChannel())
        distance = None
        if sender and receiver and hasattr(self.world, "distance"):
            distance = self.world.distance(sender, receiver)
        size = int(getattr(data, "size", 0) or 0) if not isinstance(data, (dict, list)) else 0
        if isinstance(data, dict) and isinstance(data.get("size"), int):
            size = data["size"]
        message = Message(place, sender, receiver, data, self.now, size or 16, distance)
        link = frozenset(a for a in (sender, receiver) if a)
        if link in self._down_links:
            delay, why = None, "link down"
        elif receiver is not None and not self.alive.get(receiver, True):
            delay, why = None, "receiver not running"
        else:
            delay, why = model.deliver(message, self._channel_rng), "channel model"
        info: dict[str, Any] = {"place": place, "channel": channel, "receiver": receiver,
                                "size": message.size}
        if distance is not None:
            info["distance"] = round(distance, 6)
        if delay is None:
            self._emit("message", None, sender, fate="lost", why=why, **info)
            return
        arrival = self._ticks_at(self.now + delay)
        self._emit("message", None, sender, fate="sent", arrival=round(arrival * self.dt, 9), **info)
        self._schedule(arrival, "deliver", (place, data, sender))

    # Faults --------------------------------------------------------------------------
    def _apply(self, kind: str, payload: Any) -> set[str]:
        if kind == "deliver":
            place, data, sender = payload
            self.tokens[place].append(data)
            self._emit("message", None, sender, fate="delivered", place=place,
                       channel=self.net.places[place].channel)
            return {place}
        fault: Fault = payload
        touched: set[str] = set()
        if fault.kind == "kill":
            self.alive[fault.agent] = False
            self._emit("fault", None, fault.agent, fault="kill")
            for running in sorted(self._running.values(), key=lambda r: r.firing):
                if self._agent_of[running.transition] == fault.agent:
                    running.cancelling = Outcome.CANCELLED.value
                    touched |= self._poll(running)
        elif fault.kind == "join":
            self.alive[fault.agent] = True
            self._emit("fault", None, fault.agent, fault="join")
        elif fault.kind == "drop_link":
            self._down_links.add(frozenset(fault.link))
            self._emit("fault", None, None, fault="drop_link", link=list(fault.link))
            if fault.until is not None:
                self._schedule(self._ticks_at(fault.until), "restore", fault)
        return touched

    def _restore(self, fault: Fault) -> None:
        self._down_links.discard(frozenset(fault.link))
        self._emit("fault", None, None, fault="restore_link", link=list(fault.link))

    def _apply_due(self) -> None:
        while self._pending and self._pending[0][0] <= self._tick:
            _, _, kind, payload = self._pending.pop(0)
            if kind == "restore":
                self._restore(payload)
            else:
                self._apply(kind, payload)

    def set_tokens(self, tokens: dict[str, list[Any]]) -> None:
        """Replace the tokens (with their data) before the run starts.

        Args:
            tokens: ``{place: [data, ...]}``; places not named keep no token.
        """
        if self._started:
            raise PetriflowError("tokens can only be set before the run starts")
        for place in tokens:
            self.net.place(place)
        for place in self.tokens:
            self.tokens[place] = deque(tokens.get(place, []))

    def fire_one(self, transition: str, timeout: float = 60.0) -> RunResult:
        """Fire ``transition`` now and run only its action until it ends.

        No other transition fires; the world steps as the action needs. This is what
        :func:`petriflow.testing.fire_one` uses to test one transition on its own.

        Raises:
            NotEnabledError: the transition cannot fire in the current marking.
            ActionFailed: its action failed and the net has no failure route.
        """
        from petriflow.engine import fire as fire_counts

        self.net.transition(transition)
        self.start()
        if not self._can_fire(transition):
            fire_counts(self.net, self.marking(), transition)  # raises naming short places
            raise PetriflowError(f"transition {transition!r} cannot fire now (guard false or agent down)")
        self._fire(transition)
        limit = self._ticks_at(self.now + timeout)
        while transition in self._running:
            target = self._next_tick()
            if target is None or target > limit:
                return self._end("until")
            self._advance_to(target, False)
            self._apply_due()
            for running in sorted(self._running.values(), key=lambda r: r.firing):
                if running.transition in self._running:
                    self._poll(running)
        return self._end("fired")

    # Main loop ----------------------------------------------------------------------
    def start(self) -> None:
        """Record the run's start (called by :meth:`run` if needed)."""
        if self._started:
            return
        self._started = True
        self._wall_start = wallclock.perf_counter()
        self._emit("run", None, None, net=self.net.id, seed=self.seed, dt=self.dt,
                   marking=self.marking().to_dict(), agents=self.agents())

    def _next_tick(self) -> int | None:
        """The tick at which something next needs attention, or ``None``."""
        if any(r.action.needs_world or r.cancelling for r in self._running.values()):
            return self._tick + 1
        candidates = [self._pending[0][0]] if self._pending else []
        for running in self._running.values():
            wake = running.action.wake_at
            candidates.append(self._tick + 1 if wake is None else max(self._tick + 1, self._ticks_at(wake)))
            if running.deadline is not None:
                candidates.append(max(self._tick + 1, self._ticks_at(running.deadline)))
        return min(candidates) if candidates else None

    def _advance_to(self, tick: int, realtime: bool) -> None:
        world = self.world
        while self._tick < tick:
            if world is not None:
                world.step()
            self._tick += 1
            if realtime:
                ahead = self.now - (wallclock.perf_counter() - self._wall_start)
                if ahead > 0:
                    wallclock.sleep(ahead)

    def run(self, until: float | None = None, *, max_firings: int | None = None,
            realtime: bool = False) -> RunResult:
        """Run until the net finishes, deadlocks, or a limit is reached.

        Args:
            until: simulated-time limit in seconds (default: the configuration's).
            max_firings: stop after this many firings.
            realtime: pace simulated time to the wall clock.

        Raises:
            ActionFailed: an action failed and its transition has no failure route
                (the failure is also recorded in the trace before this is raised).
        """
        until = self.config.until if until is None else until
        limit_tick = None if until is None else self._ticks_at(until)
        self._max_firings = max_firings
        self.start()
        try:
            while True:
                self._apply_due()
                self._fire_instant()
                if max_firings is not None and self._firings >= max_firings:
                    return self._end("firings")
                if not self._running and not self.enabled() and self._at_final():
                    return self._end("final")
                target = self._next_tick()
                if target is None:
                    return self._end("dead")
                if limit_tick is not None and target > limit_tick:
                    self._advance_to(limit_tick, realtime)
                    return self._end("until")
                self._advance_to(target, realtime)
                for running in sorted(self._running.values(), key=lambda r: r.firing):
                    if running.transition in self._running:
                        self._poll(running)
        except ActionFailed as exc:
            return self._end("failed", str(exc))

    def _at_final(self) -> bool:
        final = self.net.final_marking
        return final is not None and self.marking() == final and not self._pending

    def _end(self, reason: str, error: str | None = None) -> RunResult:
        data: dict[str, Any] = {"reason": reason, "firings": self._firings,
                                "marking": self.marking().to_dict(), "running": self.running()}
        if error:
            data["error"] = error
        self._emit("stop", None, None, **data)
        for action in self._actions.values():
            action.teardown()
        self._actions.clear()
        self._finished = RunResult(reason, round(self.now, 9), self._firings, self.marking(),
                                   self._seq, error,
                                   {p: list(q) for p, q in self.tokens.items() if q})
        return self._finished


def _reason(exc: BaseException) -> str:
    text = str(exc) or type(exc).__name__
    return text if isinstance(exc, PetriflowError) else f"{type(exc).__name__}: {text}"
