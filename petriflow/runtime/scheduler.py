"""The scheduler: the net decides when agents act.

A run is a sequence of *instants*, each at a tick of the :class:`~.kernel.Kernel`'s
clock. At an instant, in this order:

1. **Advance**: the world steps up to the instant's tick (a run with no world jumps).
2. **Poll**: the running actions due now are polled, in firing order: those that asked
   for this time (``wake_at``), those that step with the world (``needs_world``),
   those cleaning up after a cancellation, and those whose transition's ``timeout``
   ran out (:meth:`Action.cancel` instead of :meth:`Action.poll`). An action that ends
   produces the output tokens of its outcome (``ok``, ``failed``, ``timeout``,
   ``cancelled``) by the net's outcome arcs.
3. **Apply**: events from outside the firings apply in the order they were scheduled:
   messages delivered into channel places (:class:`~.channels.Channels`), faults
   (:class:`~.faults.Faults`).
4. **Fire**: every transition that can fire now fires, one at a time: among the
   enabled ones (enough tokens, guard true, agent alive, its action not already
   running) the highest ``priority`` wins, ties are broken by one draw of the run's
   seeded generator. Firing consumes the input tokens, applies the cancellation
   region, and starts the bound action (which may end in the same instant).

Enabling and firing follow :mod:`petriflow.engine`'s rule (the compiled net's
``consume`` at the start of a firing, ``produce`` at its end). The enabled set is
kept up to date incrementally: only the transitions that read a place whose tokens
changed, or whose own state changed, are checked again. So the work per firing, per
poll and per message does not grow with the number of agents.

Time is an integer count of ticks, so the same net, world, configuration and seed
give the same events bit for bit. Each transition runs one action at a time (a robot
walks one walk at a time): a transition whose action is running is not enabled.

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
    (<StopReason.DEAD: 'dead'>, 2.0, Marking({'o': 1}))
    >>> run = Scheduler(net, seed=1)
    >>> run.peek(), run.step(), run.peek(), run.running()
    (0.0, None, 2.0, ['rest'])
"""

from __future__ import annotations

import random
import time as wallclock
from dataclasses import dataclass, field
from typing import Any, Callable

from petriflow import limits
from petriflow.engine import CompiledNet
from petriflow.errors import PetriflowError
from petriflow.marking import Marking
from petriflow.net import Net
from petriflow.outcome import Outcome, StopReason
from petriflow.runtime.action import Action, ActionContext, ActionFailure, Status
from petriflow.runtime.binding import Binding, bind, check_sizes
from petriflow.runtime.channels import Channels
from petriflow.runtime.config import RunConfig
from petriflow.runtime.faults import Faults
from petriflow.runtime.kernel import POLL, Deadline, Kernel, Scheduled
from petriflow.runtime.registry import Registry
from petriflow.runtime.tokens import Agenda, TokenStore
from petriflow.runtime.trace import Event, EventKind, summarize

__all__ = ["Scheduler", "RunResult", "ZenoError", "EmptySchedule"]

EventHandler = Callable[[Event], None]

_RUN, _START, _END, _CANCEL, _CUSTOM, _STOP = (EventKind.RUN.value, EventKind.START.value, EventKind.END.value,
                                               EventKind.CANCEL.value, EventKind.CUSTOM.value, EventKind.STOP.value)


class ZenoError(PetriflowError):
    """Instant transitions keep firing without simulated time passing."""


class EmptySchedule(PetriflowError):
    """:meth:`Scheduler.step` was asked for an instant but nothing more can happen."""


class _Unrouted(Exception):
    """A failure with no ``failed`` arcs: the run stops (internal)."""

    def __init__(self, failure: ActionFailure) -> None:
        super().__init__(str(failure))
        self.failure = failure


@dataclass
class RunResult:
    """How a run ended.

    Attributes:
        reason: why it ended (:class:`~petriflow.outcome.StopReason`): ``final`` (the
            net's final marking was reached with nothing running or pending),
            ``dead`` (nothing can fire, run or arrive any more), ``until`` (the time
            limit), ``firings`` (the firing limit), ``failed`` (an action failed with
            no failure route; see ``error``), ``stalled`` (actions stepped tick by tick
            for the configuration's ``stall`` seconds with no firing starting or
            ending; see ``error``) or ``fired`` (:meth:`Scheduler.fire_one`).
        time: simulated seconds at the end.
        firings: transitions fired.
        marking: token counts at the end.
        events: number of events recorded.
        error: the unrouted failure, if any.
        tokens: ``{place: [data, ...]}`` at the end.
    """

    reason: StopReason
    time: float
    firings: int
    marking: Marking
    events: int
    error: str | None = None
    tokens: dict[str, list[Any]] = field(default_factory=dict)


class _Firing(Scheduled):
    """The running firing of one transition (a transition runs one at a time, so one
    record per transition serves all its firings); scheduled on the kernel, it is its
    own wake-up (the poll it asked for last)."""

    __slots__ = ("run", "number", "index", "action", "ctx", "deadline", "cancelling", "wake", "polled",
                 "running")
    phase = POLL

    def __init__(self, run: "Scheduler", index: int, action: Action) -> None:
        self.run = run
        self.index = index
        self.action = action
        self.number = 0
        self.ctx: ActionContext | None = None
        self.deadline: float | None = None
        self.cancelling: Outcome | None = None
        self.wake = -1
        self.polled = -1
        self.running = False

    def start(self, number: int, ctx: ActionContext, deadline: float | None) -> None:
        """Begin firing ``number`` (the transition's previous firing has ended)."""
        self.number = number
        self.ctx = ctx
        self.deadline = deadline
        self.cancelling = None
        self.wake = -1
        self.polled = -1
        self.running = True

    def live(self, tick: int) -> bool:
        return self.running and self.wake == tick

    def apply(self, tick: int) -> None:
        if self.polled != self.run.kernel.tick:  # once per tick, whichever entry comes first
            self.run._poll(self)


def _reason(exc: BaseException, hook: str | None = None) -> str:
    text = str(exc) or type(exc).__name__
    text = text if isinstance(exc, PetriflowError) else f"{type(exc).__name__}: {text}"
    return f"{hook}() failed: {text}" if hook else text


class Scheduler:
    """Runs a net's transitions as agent actions over an optional world.

    Args:
        net: the net to run.
        world: a :class:`petriflow.world.World` or any object with ``dt``,
            ``step()`` and optionally ``distance(a, b)``; ``None`` for a world-less run.
        config: faults, channel models, limits (:class:`RunConfig`).
        seed: seed of conflict resolution, action randomness and channel losses
            (overrides ``config.seed`` when given).
        registry: where action and guard names are looked up (when no ``binding``).
        path: the net's file, named in errors.
        binding: the net already bound (:func:`~petriflow.runtime.binding.bind`).

    Raises:
        NetFormatError: an action, parameter, port or guard does not bind; a fault or
            channel of the configuration names nothing in the net.
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
        binding: Binding | None = None,
    ) -> None:
        self.net = net
        self.world = world
        self.config = config or RunConfig()
        self.seed = self.config.seed if seed is None else seed
        self.binding = binding if binding is not None else bind(net, registry, path=path)
        self.registry = self.binding.registry
        self.config.check(net)
        check_sizes(net, path)
        self.kernel = Kernel(float(getattr(world, "dt", None) or self.config.dt))
        compiled = self.compiled = CompiledNet(net)
        self.tokens = TokenStore(compiled, net.initial_marking, net.final_marking)
        ids = self._ids = list(net.transitions)
        self._position = {t: i for i, t in enumerate(ids)}
        agent_of_subnet = {s.id: s.agent or s.id for s in net.subnets.values()}
        transitions = list(net.transitions.values())
        self._agent = [agent_of_subnet[t.subnet] if t.subnet else None for t in transitions]
        self._of_agent: dict[str, list[int]] = {}
        for t, agent in enumerate(self._agent):
            if agent is not None:
                self._of_agent.setdefault(agent, []).append(t)
        self._row = [compiled.transition_index[t] for t in ids]
        self._route = [{o: compiled.row(t, o) for o in Outcome} for t in ids]
        consumers: list[list[int]] = [[] for _ in compiled.places]
        for t, row in enumerate(self._row):
            for p, _ in compiled.pre[row]:
                consumers[p].append(t)
        self._consumers = [tuple(c) for c in consumers]
        self._channel = [net.places[p].channel is not None for p in compiled.places]
        self._cancels = [tuple(self._position[n] for n in t.cancels if n in self._position) for t in transitions]
        self._timeout = [t.timeout for t in transitions]
        bound = [self.binding.transitions[t] for t in ids]
        self._guard = [b.guard for b in bound]
        self._params = [b.params for b in bound]
        self._action_class = [b.action for b in bound]
        self._actions: list[Action | None] = [None] * len(ids)
        self._slot: list[_Firing | None] = [None] * len(ids)
        self._setup_error: list[str | None] = [None] * len(ids)
        self.agenda = Agenda([t.priority for t in transitions])
        self._dirty: set[int] = set(range(len(ids)))
        self._running: dict[int, _Firing] = {}
        self._handlers: list[EventHandler] = []
        self._seq = 0
        self.firings = 0
        self._progress = 0  # the tick of the last firing start or end (the stall watchdog's)
        self._fired_now = 0
        self._rng = random.Random(f"{self.seed}:conflicts")
        self._seed_prefix = f"{self.seed}:"
        self._started = False
        self._closed = False
        self._opened = False  # whether the instant at tick 0 was processed
        self._max_firings: int | None = None
        self._wall_start = 0.0
        self._finished: RunResult | None = None
        self.faults = Faults(self, self.config.faults, self.agents())
        self._alive = self.faults.running
        self.channels = Channels(self, self.config.channel_models(), self.seed)

    # Observers ----------------------------------------------------------------------
    def on_event(self, handler: EventHandler) -> None:
        """Call ``handler(event)`` for every event, in order."""
        self._handlers.append(handler)

    def emit(self, kind: str, transition: str | None = None, agent: str | None = None, **data: Any) -> None:
        """Record an event (for components; observers receive it)."""
        seq = self._seq
        self._seq = seq + 1
        if self._handlers:
            event = Event(seq, round(self.kernel.tick * self.kernel.dt, 9), kind, transition, agent, data)
            for handler in self._handlers:
                handler(event)

    # Queries ------------------------------------------------------------------------
    @property
    def now(self) -> float:
        """Current simulated time in seconds."""
        return self.kernel.now

    @property
    def alive(self) -> dict[str, bool]:
        """``{agent: running}`` for every agent."""
        return self.faults.running

    def agents(self) -> list[str]:
        """Agent names of the net's subnets, in declaration order."""
        seen: dict[str, None] = {}
        for subnet in self.net.subnets.values():
            seen.setdefault(subnet.agent or subnet.id)
        return list(seen)

    def marking(self) -> Marking:
        """Token counts now."""
        return self.tokens.marking()

    def running(self) -> list[str]:
        """Transitions whose actions are running, in firing order."""
        return [self._ids[f.index] for f in sorted(self._running.values(), key=lambda f: f.number)]

    def running_actions(self) -> dict[str, Action]:
        """``{transition: action}`` of the firings running now, in firing order (the
        action instances, for tests and inspection)."""
        firings = sorted(self._running.values(), key=lambda f: f.number)
        return {self._ids[f.index]: f.action for f in firings}

    def enabled(self) -> list[str]:
        """Transitions that may fire now, in the net's order."""
        self._refresh()
        return [self._ids[t] for t in self.agenda.members()]

    def peek(self) -> float | None:
        """Simulated time of the next instant at which something happens, or ``None``."""
        if not self._opened:
            return self.kernel.now
        tick = self.kernel.peek()
        return None if tick is None else tick * self.kernel.dt

    # Enabling -----------------------------------------------------------------------
    def _can_fire(self, t: int) -> bool:
        if t in self._running:
            return False
        agent = self._agent[t]
        if agent is not None and not self._alive.get(agent, True):
            return False
        row = self._row[t]
        if not self.compiled.is_enabled(self.tokens.counts, row):
            return False
        guard = self._guard[t]
        if guard is None:
            return True
        try:
            return bool(guard(self.tokens.offered(row), self._params[t]))
        except Exception as exc:
            name = self.net.transitions[self._ids[t]].guard
            raise PetriflowError(f"transition {self._ids[t]!r}: guard {name!r} raised {_reason(exc)}") from exc

    def _refresh(self) -> None:
        dirty = self._dirty
        if dirty:
            agenda, can_fire = self.agenda, self._can_fire
            for t in dirty:
                if can_fire(t):
                    agenda.add(t)
                else:
                    agenda.discard(t)
            dirty.clear()

    # Firing -------------------------------------------------------------------------
    def _fire_instant(self) -> None:
        """Fire until nothing more can fire at this instant (or the firing limit)."""
        limit = self._max_firings
        agenda, draw, dirty = self.agenda, self._rng.random, self._dirty
        while True:
            if dirty:
                self._refresh()
            if not agenda or (limit is not None and self.firings >= limit):
                return
            self._fire(agenda.pick(draw))
            self._fired_now += 1
            if self._fired_now > limits.FIRINGS_PER_INSTANT:
                raise ZenoError(
                    f"more than {limits.FIRINGS_PER_INSTANT} firings at t={self.now:g}s without time"
                    " passing (a cycle of instant transitions?)"
                )

    def _fire(self, t: int) -> None:
        """Fire transition index ``t`` now: consume, cancel its region, start its action."""
        tid = self._ids[t]
        self.firings += 1
        number = self.firings
        self._progress = self.kernel.tick
        row = self._row[t]
        compiled = self.compiled
        inputs, withdrawn = self.tokens.consume(row)
        consumers, dirty = self._consumers, self._dirty
        for p, _ in compiled.pre[row]:
            dirty.update(consumers[p])
        for p in compiled.reset[row]:
            dirty.update(consumers[p])
        dirty.add(t)
        agent = self._agent[t]
        if self._handlers:
            details: dict[str, Any] = {"firing": number, "consumed": {p: len(v) for p, v in inputs.items()}}
            carried = {p: [summarize(d) for d in v] for p, v in inputs.items() if any(d is not None for d in v)}
            if carried:
                details["inputs"] = carried
            self.emit(_START, tid, agent, **details)
        else:
            self._seq += 1
        if self._cancels[t] or withdrawn:
            self._cancel_region(t, number, withdrawn)
        now = self.kernel.now
        ctx = ActionContext(tid, agent, self._params[t], inputs, self.world, self._seed_prefix + str(number),
                            now, now, _reader=self.tokens.read, _links=self.channels.model_for,
                            _alive=self.faults.alive)
        action = self._actions[t]
        if action is None:
            ctx.result = ctx.token()
            self._finish(number, t, ctx, Outcome.OK)
            return
        if self._setup_error[t] is not None:
            ctx.reason = self._setup_error[t]
            self._finish(number, t, ctx, Outcome.FAILED)
            return
        timeout = self._timeout[t]
        firing = self._slot[t]  # a transition runs one firing at a time: its record is reused
        firing.start(number, ctx, None if timeout is None else now + timeout)
        self._running[t] = firing
        try:
            action.start(ctx)
        except Exception as exc:  # an action's error is a failed outcome, never lost
            ctx.reason = _reason(exc)
            self._stop(firing)
            self._finish(number, t, ctx, Outcome.FAILED)
            return
        kernel = self.kernel
        if timeout is not None:
            tick = max(kernel.tick + 1, kernel.ticks_at(firing.deadline))
            kernel.schedule(tick, Deadline(firing, number), key=number)
        wake = action.wake_at
        if wake is not None and not action.needs_world and wake > now + 1e-12:
            self._wake(firing, max(kernel.tick + 1, kernel.ticks_at(wake)))  # first poll when it asked
        else:
            self._poll(firing)

    def _cancel_region(self, t: int, number: int, withdrawn: dict[str, int]) -> None:
        cancelled = [self._running[u] for u in self._cancels[t] if u in self._running]
        for firing in cancelled:
            firing.cancelling = Outcome.CANCELLED
        if withdrawn or cancelled:
            self.emit(_CANCEL, self._ids[t], self._agent[t], firing=number, withdrawn=withdrawn,
                      actions=[self._ids[f.index] for f in cancelled])
        for firing in cancelled:
            if firing.running:
                self._poll(firing)

    def _stop(self, firing: _Firing) -> None:
        firing.running = False
        del self._running[firing.index]
        self._dirty.add(firing.index)

    def _poll(self, firing: _Firing) -> None:
        """Poll one running action (or drive its cancellation); finish it if it ended."""
        kernel = self.kernel
        firing.polled = tick = kernel.tick
        ctx, action = firing.ctx, firing.action
        ctx.now = now = kernel.now
        if firing.cancelling is None and firing.deadline is not None and now >= firing.deadline - 1e-9:
            firing.cancelling = Outcome.TIMEOUT
        if firing.cancelling is not None:
            outcome = firing.cancelling
            try:
                done = action.cancel(ctx)
            except Exception as exc:
                ctx.reason = _reason(exc, "cancel")
                done, outcome = True, Outcome.FAILED
            if not done:
                self._wake(firing, tick + 1)
                return
            self._stop(firing)
            self._finish(firing.number, firing.index, ctx, outcome)
            return
        try:
            status = action.poll(ctx)
        except Exception as exc:
            ctx.reason = _reason(exc)
            status = Status.FAILED
        if status is Status.RUNNING:
            if action.needs_world:
                self._wake(firing, tick + 1)
            else:
                wake = action.wake_at
                self._wake(firing, tick + 1 if wake is None else max(tick + 1, kernel.ticks_at(wake)))
            return
        if not isinstance(status, Status):
            ctx.reason = f"poll() returned {status!r}, not a Status"
            status = Status.FAILED
        self._stop(firing)
        self._finish(firing.number, firing.index, ctx, Outcome.OK if status is Status.OK else Outcome.FAILED)

    def _wake(self, firing: _Firing, tick: int) -> None:
        firing.wake = tick
        self.kernel.schedule(tick, firing, key=firing.number)

    def _finish(self, number: int, t: int, ctx: ActionContext, outcome: Outcome) -> None:
        """Produce the outputs of ``outcome`` and record the end of the firing."""
        tid = self._ids[t]
        self._progress = self.kernel.tick
        row = self._route[t][outcome]
        if row is None and outcome is not Outcome.CANCELLED and outcome is not Outcome.OK:
            reason = ctx.reason or outcome.value
            self.emit(_END, tid, ctx.agent, firing=number, outcome=outcome.value, produced={}, reason=reason)
            raise _Unrouted(ActionFailure(reason, net=self.net.id, transition=tid,
                                          action=self.net.transitions[tid].action))
        if ctx.emitted:
            for kind, data in ctx.emitted:
                self.emit(_CUSTOM, tid, ctx.agent, firing=number, name=kind, data=summarize(data))
            ctx.emitted.clear()
        produced: dict[str, int] = {}
        sent: list[tuple[str, Any]] = []
        if row is not None:
            result, outputs = ctx.result, ctx.outputs
            if ctx.per_place and isinstance(result, dict):
                result, outputs = None, result
            channel = self._channel
            produced = self.tokens.produce(row, result, outputs, channel)
            places = self.compiled.places
            consumers, dirty = self._consumers, self._dirty
            for p, w in self.compiled.post[row]:
                if channel[p]:
                    sent.extend([(places[p], outputs.get(places[p], result) if outputs else result)] * w)
                else:
                    dirty.update(consumers[p])
        if self._handlers:
            details: dict[str, Any] = {"firing": number, "outcome": outcome.value, "produced": produced}
            if ctx.result is not None:
                details["result"] = summarize(ctx.result)
            if ctx.reason:
                details["reason"] = ctx.reason
            self.emit(_END, tid, ctx.agent, **details)
        else:
            self._seq += 1
        for place, data in sent:
            self.channels.send(place, data, ctx.agent)

    # Components call these ------------------------------------------------------------
    def deliver(self, place: str, data: Any) -> None:
        """A token arrives in ``place`` from outside a firing (a channel's delivery)."""
        index = self.tokens.index[place]
        self.tokens.add(index, data)
        self._dirty.update(self._consumers[index])

    def agent_stopped(self, agent: str) -> None:
        """``agent`` stopped (a fault): its running actions are cancelled, its
        transitions no longer fire."""
        transitions = self._of_agent.get(agent, ())
        self._dirty.update(transitions)
        firings = sorted((self._running[t] for t in transitions if t in self._running), key=lambda f: f.number)
        for firing in firings:
            firing.cancelling = Outcome.CANCELLED
            if firing.running:
                self._poll(firing)

    def agent_started(self, agent: str) -> None:
        """``agent`` started (a late joiner): its transitions may fire."""
        self._dirty.update(self._of_agent.get(agent, ()))

    def set_tokens(self, tokens: dict[str, list[Any]]) -> None:
        """Replace the tokens (with their data) before the run starts.

        Args:
            tokens: ``{place: [data, ...]}``; places not named keep no token.
        """
        if self._started:
            raise PetriflowError("tokens can only be set before the run starts")
        for place in tokens:
            self.net.place(place)
        self.tokens.replace(tokens)
        self._dirty.update(range(len(self._ids)))

    # Running ------------------------------------------------------------------------
    def start(self) -> None:
        """Record the run's start and set up every bound action (called by :meth:`run`
        and :meth:`step` if needed)."""
        if self._started:
            return
        self._started = True
        self._wall_start = wallclock.perf_counter()
        self.emit(_RUN, None, None, net=self.net.id, seed=self.seed, dt=self.kernel.dt,
                  marking=self.marking().to_dict(), agents=self.agents())
        for t, cls in enumerate(self._action_class):
            if cls is None:
                continue
            action = self._actions[t] = cls(self._params[t])
            self._slot[t] = _Firing(self, t, action)
            try:
                action.setup(self.world)
            except Exception as exc:  # every firing of t then fails with this reason
                self._setup_error[t] = _reason(exc, "setup")

    def _advance(self, tick: int, realtime: bool) -> None:
        kernel, world = self.kernel, self.world
        if world is None and not realtime:
            kernel.tick = max(kernel.tick, tick)
        while kernel.tick < tick:
            if world is not None:
                world.step()
            kernel.tick += 1
            if realtime:
                ahead = kernel.now - (wallclock.perf_counter() - self._wall_start)
                if ahead > 0:
                    wallclock.sleep(ahead)
        self._fired_now = 0

    def _instant(self, fire: bool = True) -> None:
        """Process the current tick: due polls and events, then the firings."""
        kernel = self.kernel
        self._opened = True
        while True:
            for tick, event in kernel.pop_due():
                event.apply(tick)
            if fire:
                self._fire_instant()
            if not kernel.due():
                return

    def step(self, realtime: bool = False) -> None:
        """Process the next instant (see the module): advance, poll, apply, fire.

        Raises:
            EmptySchedule: nothing more can happen.
            ZenoError: instant transitions keep firing without time passing.
        """
        self.start()
        if self._opened:
            tick = self.kernel.peek()
            if tick is None:
                raise EmptySchedule(f"nothing more can happen at t={self.now:g}s")
            self._advance(tick, realtime)
        try:
            self._instant()
        except _Unrouted as exc:
            raise exc.failure from None

    def run(self, until: float | None = None, *, max_firings: int | None = None,
            realtime: bool = False) -> RunResult:
        """Run until the net finishes, deadlocks, or a limit is reached.

        Args:
            until: simulated-time limit in seconds (default: the configuration's).
            max_firings: stop after this many firings.
            realtime: pace simulated time to the wall clock.

        Returns:
            How the run ended; an action that failed with no failure route ends it
            with reason ``failed`` (recorded in the trace first).
        """
        until = self.config.until if until is None else limits.check_seconds(until, "until")
        kernel = self.kernel
        limit = None if until is None else kernel.ticks_at(until)
        stall = None if self.config.stall is None else kernel.ticks_at(self.config.stall)
        self._max_firings = max_firings
        self.start()
        if self._closed:
            raise PetriflowError("this run has ended; make a new Scheduler to run again")
        try:
            self._instant()  # the first instant, or the rest of the one a limit stopped in
            while True:
                if max_firings is not None and self.firings >= max_firings:
                    return self._end(StopReason.FIRINGS)
                if not self._running and not kernel.pending and self.tokens.at_final:
                    return self._end(StopReason.FINAL)
                tick = kernel.peek()
                if tick is None:
                    return self._end(StopReason.DEAD)
                if limit is not None and tick > limit:
                    self._advance(limit, realtime)
                    return self._end(StopReason.UNTIL)
                if stall is not None and tick == kernel.tick + 1 and tick - self._progress > stall:
                    running = ", ".join(self.running())
                    return self._end(StopReason.STALLED, f"no firing started or ended for"
                                     f" {self.config.stall:g} s of simulated time while {running} ran")
                self._advance(tick, realtime)
                self._instant()
        except _Unrouted as exc:
            return self._end(StopReason.FAILED, str(exc.failure))

    def fire_one(self, transition: str, timeout: float = 60.0) -> RunResult:
        """Fire ``transition`` now and run only its action until it ends.

        No other transition fires; the world steps as the action needs. This is what
        :func:`petriflow.testing.fire_one` uses to test one transition on its own.

        Raises:
            NotEnabledError: the transition cannot fire in the current marking.
        """
        from petriflow.engine import fire as fire_counts

        self.net.transition(transition)
        t = self._position[transition]
        self.start()
        self._opened = True
        if not self._can_fire(t):
            fire_counts(self.net, self.marking(), transition)  # raises naming short places
            raise PetriflowError(f"transition {transition!r} cannot fire now (guard false or agent down)")
        kernel = self.kernel
        try:
            self._fire(t)
            limit = kernel.ticks_at(self.now + timeout)
            while t in self._running:
                tick = kernel.peek()
                if tick is None or tick > limit:
                    return self._end(StopReason.UNTIL)
                self._advance(tick, False)
                self._instant(fire=False)
        except _Unrouted as exc:
            return self._end(StopReason.FAILED, str(exc.failure))
        return self._end(StopReason.FIRED)

    def close(self) -> dict[str, str]:
        """End the run for good: tear every action down (once). :meth:`run` does it when
        the run is over (final, dead, failed); after a time or firing limit the run
        may go on with another :meth:`run`, so call this (or use the scheduler as a
        context manager) when done.

        Returns:
            ``{transition: reason}`` of the actions whose ``teardown()`` raised.
        """
        problems: dict[str, str] = {}
        if self._closed:
            return problems
        self._closed = True
        for t, action in enumerate(self._actions):
            if action is not None:
                try:
                    action.teardown()
                except Exception as exc:
                    problems[self._ids[t]] = _reason(exc, "teardown")
        return problems

    def __enter__(self) -> "Scheduler":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def _end(self, reason: StopReason, error: str | None = None) -> RunResult:
        problems = {}
        if reason not in (StopReason.UNTIL, StopReason.FIRINGS):
            problems = self.close()
        data: dict[str, Any] = {"reason": reason.value, "firings": self.firings,
                                "marking": self.marking().to_dict(), "running": self.running()}
        if error:
            data["error"] = error
        if problems:
            data["teardown_errors"] = problems
        self.emit(_STOP, None, None, **data)
        self._finished = RunResult(reason, round(self.now, 9), self.firings, self.marking(), self._seq, error,
                                   self.tokens.tokens())
        return self._finished
