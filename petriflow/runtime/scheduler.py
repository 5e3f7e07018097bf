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

A run is made of parts a reader can take one at a time, each in its own module: the
:class:`~petriflow.runtime.kernel.Kernel` (clock ticks and the events ahead), a
:class:`~petriflow.runtime.clock.Clock` (moving to the next instant, as fast as
possible or paced to the wall clock), the :class:`~petriflow.runtime.index.RunIndex`
(the net by integer indices), the :class:`~petriflow.runtime.tokens.TokenStore` (the
marking with data), the :class:`~petriflow.runtime.enabling.EnabledSet` (which
transitions may fire), the :class:`~petriflow.runtime.firing.Firer` (firing and
producing), the :class:`~petriflow.runtime.lifecycle.ActionRunner` (each firing's
action), the :class:`~petriflow.runtime.recorder.Recorder` (events and observers),
the components :class:`~petriflow.runtime.channels.Channels` and
:class:`~petriflow.runtime.faults.Faults`, and the
:class:`~petriflow.runtime.services.RunServices` the actions' contexts reach. Each
part is made with its collaborators named and typed; none holds the scheduler. The
scheduler puts them together, steps from instant to instant and decides when the run
stops.

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
    (<StopReason.FINAL: 'final'>, 2.0, Marking({'o': 1}))
    >>> run = Scheduler(net, seed=1)
    >>> run.peek(), run.step(), run.peek(), run.running()
    (0.0, None, 2.0, ['rest'])
"""

from __future__ import annotations

from typing import Any, Iterable, Mapping

from petriflow import limits
from petriflow.capabilities import Stepped, missing
from petriflow.collector import paused, relaxed
from petriflow.errors import PetriflowError
from petriflow.marking import Marking
from petriflow.net import Net
from petriflow.outcome import Outcome, StopReason
from petriflow.runtime.action import Action
from petriflow.runtime.agents import Agents
from petriflow.runtime.binding import Binding
from petriflow.runtime.channels import Channels
from petriflow.runtime.clock import Clock, RealtimeClock, SimulatedClock
from petriflow.runtime.control import PAUSED_STEP, Control, ControlError
from petriflow.runtime.config import RunConfig
from petriflow.runtime.enabling import EnabledSet
from petriflow.runtime.faults import Faults
from petriflow.runtime.firing import Firer, Unrouted, ZenoError
from petriflow.runtime.index import RunIndex
from petriflow.runtime.kernel import Kernel
from petriflow.runtime.lifecycle import Firing
from petriflow.runtime.recorder import EventHandler, Recorder
from petriflow.runtime.registry import Registry
from petriflow.runtime.resources import Liveness, ResourceContext, Resources
from petriflow.runtime.result import RunResult
from petriflow.runtime.services import RemoteGoals, RunServices
from petriflow.runtime.stopwatch import UNTIMED, Timing
from petriflow.runtime.tokens import TokenStore
from petriflow.runtime.trace import EventKind
from petriflow.runtime.validation import UNKNOWN, settings_of, validate
from petriflow.workflow import final_marking_of

__all__ = ["Scheduler", "RunResult", "ZenoError", "EmptySchedule"]

_RUN, _STOP = EventKind.RUN.value, EventKind.STOP.value


class EmptySchedule(PetriflowError):
    """:meth:`Scheduler.step` was asked for an instant but nothing more can happen."""


class Scheduler:
    """Runs a net's transitions as agent actions over an optional world (see the module).

    Args:
        net: the net to run.
        world: a :class:`petriflow.world.World` or any object with ``dt`` and
            ``step()`` (:class:`~petriflow.capabilities.Stepped`) and the capabilities
            the actions use; ``None`` for a world-less run.
        config: faults, channel models, limits (:class:`RunConfig`, or its mapping).
        seed: seed of conflict resolution, action randomness and channel losses
            (overrides ``config.seed`` when given).
        registry: where action and guard names are looked up (when no ``binding``).
        path: the net's file, named in errors.
        binding: the net already bound (:func:`~petriflow.runtime.binding.bind`).
        clock: how time moves between instants (default
            :class:`~petriflow.runtime.clock.SimulatedClock`).
        settings: the world file's settings the actions read, checked
            (:class:`~petriflow.runtime.validation.CheckedRun`); default: read from the
            world's ``meta`` (:func:`~petriflow.runtime.validation.settings_of`).
        stopwatch: what the actions report their work's wall-clock time to
            (``ctx.stopwatch``; :mod:`~petriflow.runtime.stopwatch`); give the clock
            the same one to time the world's steps.
        control: the run's control queue, when it is steered (a live page, a resumed
            steered run): :class:`~petriflow.runtime.control.Control`.

    Raises:
        NetFormatError: an action, parameter, port or guard does not bind; a fault or
            channel of the configuration names nothing in the net; the world lacks a
            capability an action uses, or a setting it reads is bad.
    """

    @paused()  # indexing a large net makes no cycles (petriflow.collector)
    def __init__(self, net: Net, *, world: Any = None, config: RunConfig | dict | None = None, seed: int | None = None,
                 registry: Registry | None = None, path: str | None = None, binding: Binding | None = None,
                 clock: Clock | None = None, settings: Mapping[str, Mapping[str, Any]] | None = None,
                 stopwatch: Timing = UNTIMED, remote: RemoteGoals | None = None,
                 control: Control | None = None) -> None:
        self.net = net
        self.world = world
        self.config = config = RunConfig.from_dict(config) if isinstance(config, dict) else config or RunConfig()
        self.seed = seed = config.seed if seed is None else seed
        # a binding not checked yet is checked here, for the capabilities the actions use
        # of the world given too (a world-less run is refused for an action that needs a
        # world where a file run is: by validation, before anything is made)
        checked = binding is not None and binding.checked
        self.binding = validate(net, config, binding=binding, registry=registry, path=path,
                                world=UNKNOWN if world is None or checked else world)
        self.registry = self.binding.registry
        self.clock = clock or SimulatedClock()
        self.settings = settings_of(world, self.binding) if settings is None else settings
        stepped = world is not None and not missing(world, Stepped)  # else the configuration's dt
        kernel = self.kernel = Kernel(float((world.dt if stepped else None) or config.dt))
        index = self.index = RunIndex(net, self.binding)
        self.compiled = index.compiled
        self.final = final_marking_of(net)  # declared, else a WF-net's sink (the rule check uses)
        tokens = self.tokens = TokenStore(index.compiled, net.initial_marking, self.final)
        recorder = self.recorder = Recorder(kernel)
        faults = self.faults = Faults(kernel, recorder, config.faults, index.agents, stopped=self.agent_stopped,
                                      started=self.agent_started)
        running: dict[int, Firing] = {}  # the firings running now (the runner's; enabling reads it)
        states: dict[str, Any] = {}  # the agents' states (the agents'; state guards read them)
        enabled = self.enabled_set = EnabledSet(index, tokens, faults.stopped, running, states)
        agents = self.agent_states = Agents(index, enabled, states)
        self.channels = Channels(net, config.channel_models(self.registry), seed, kernel=kernel, recorder=recorder,
                                 links=faults, world=world, deliver=self.deliver)
        self.resources = Resources(self.registry, ResourceContext(world, Liveness(faults.alive, index.agents), config,
                                                                  self.settings))
        services = RunServices(agents=agents, tokens=tokens, channels=self.channels, resources=self.resources,
                               liveness=faults, settings=self.settings, stopwatch=stopwatch, remote=remote)
        self.firer = Firer(net, index, kernel, tokens, enabled, recorder=recorder, agents=agents,
                           channels=self.channels, services=services, world=world, seed=seed, running=running)
        self.runner = self.firer.runner
        self.control = control
        if control is not None:
            self.firer.control = control
            control.attach(self)
            self.clock.interrupt = control.interrupt  # a pause stops the clock between instants too
            if remote is not None:  # remote agents work on during a pause: their results are taken as they come
                control.idle = self.pass_paused
        self._started = self._closed = self._opened = False  # _opened: the instant at tick 0 was processed
        self._watchers: list[Any] = []
        self._finished: RunResult | None = None

    # Observers ----------------------------------------------------------------------
    def on_event(self, handler: EventHandler, kinds: Iterable[str] | None = None, *,
                 transitions: Iterable[str] | None = None, places: Iterable[str] | None = None,
                 fields: Mapping[str, Iterable[Any]] | None = None) -> None:
        """Call ``handler(event)`` for every event, in order (or for those of ``kinds``,
        about ``transitions``, ``places`` and ``fields``: :meth:`Recorder.on_event
        <petriflow.runtime.recorder.Recorder.on_event>`); an event no one hears is not built."""
        self.recorder.on_event(handler, kinds, transitions=transitions, places=places, fields=fields)

    def on_instant(self, watcher: Any) -> None:
        """Call ``watcher(scheduler)`` after each instant: for displays that need no
        event data (a progress line), so no event has to be built for them."""
        self._watchers.append(watcher)

    def emit(self, kind: str, transition: str | None = None, agent: str | None = None, **data: Any) -> None:
        """Record an event (for components; observers receive it)."""
        self.recorder.emit(kind, transition, agent, **data)

    @property
    def firings(self) -> int:
        """Transitions fired so far."""
        return self.firer.count

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
        return list(self.index.agents)

    def marking(self) -> Marking:
        """Token counts now."""
        return self.tokens.marking()

    def running(self) -> list[str]:
        """Transitions whose actions are running, in firing order."""
        return [self.index.ids[f.index] for f in self.runner.in_firing_order()]

    def running_actions(self) -> dict[str, Action]:
        """``{transition: action}`` of the firings running now, in firing order (the
        action instances, for tests and inspection)."""
        return {self.index.ids[f.index]: f.action for f in self.runner.in_firing_order()}

    def enabled(self) -> list[str]:
        """Transitions that may fire now, in the net's order."""
        return [self.index.ids[t] for t in self.enabled_set.members()]

    def peek(self) -> float | None:
        """Simulated time of the next instant at which something happens, or ``None``."""
        if not self._opened:
            return self.kernel.now
        tick = self.kernel.peek()
        return None if tick is None else tick * self.kernel.dt

    # Components call these ------------------------------------------------------------
    def deliver(self, place: str, data: Any) -> None:
        """A token arrives in ``place`` from outside a firing (a channel's delivery)."""
        index = self.tokens.index[place]
        self.tokens.add(index, data)
        self.enabled_set.mark_place(index)

    def agent_stopped(self, agent: str) -> None:
        """``agent`` stopped (a fault): its running actions are cancelled, its
        transitions no longer fire."""
        transitions = self.index.of_agent.get(agent, [])
        self.enabled_set.mark(transitions)
        self.runner.drive(self.runner.cancel(transitions))
        self.agent_states.running_changed()

    def agent_lost(self, agent: str, why: str = "") -> None:
        """``agent`` (a remote one) stopped answering: its running actions end
        ``failed`` (what they did is unknown, so the net's failure routes decide), its
        transitions no longer fire until :meth:`agent_back`; what that enables fires now."""
        self.faults.lose(agent, why)
        transitions = self.index.of_agent.get(agent, [])
        self.enabled_set.mark(transitions)
        self.runner.drive(self.runner.cancel(transitions, Outcome.FAILED))
        if not self._holding():
            self.firer.fire_instant()  # a failure route, at the instant the loss is noticed

    def agent_back(self, agent: str) -> None:
        """A lost ``agent`` announced itself again: it runs again, as a late joiner."""
        self.faults.rejoin(agent)
        if not self._holding():
            self.firer.fire_instant()

    def _holding(self) -> bool:
        """Whether a pause holds the firing (what became enabled fires when it ends)."""
        return self.control is not None and self.control.holding

    def agent_started(self, agent: str) -> None:
        """``agent`` started (a late joiner): its transitions may fire."""
        self.enabled_set.mark(self.index.of_agent.get(agent, ()))
        self.agent_states.running_changed()

    def set_tokens(self, tokens: dict[str, list[Any]]) -> None:
        """Replace the tokens (with their data) before the run starts: ``{place: [data,
        ...]}``; places not named keep no token."""
        if self._started:
            raise PetriflowError("tokens can only be set before the run starts")
        for place in tokens:
            self.net.place(place)
        self.tokens.replace(tokens)
        self.enabled_set.resync()

    # Steering (what a Control changes, at its checkpoints) ------------------------------
    def inject(self, place: str, count: int) -> dict[str, int]:
        """Put ``count`` black tokens into ``place`` now (an operator's intervention:
        call it through :class:`~petriflow.runtime.control.Control`, so it is recorded).

        Raises:
            ControlError: no such place.
        """
        index = self._place(place)
        for _ in range(count):
            self.tokens.add(index, None)
        self.enabled_set.mark_place(index)
        return {place: count}

    def remove(self, place: str, count: int) -> dict[str, int]:
        """Take ``count`` tokens (the oldest) out of ``place`` now.

        Raises:
            ControlError: no such place, or it holds fewer tokens.
        """
        index = self._place(place)
        held = self.tokens.counts[index]
        if held < count:
            raise ControlError(f"place {place!r} holds {held} token{'s' * (held != 1)}, not {count}")
        self.tokens.remove(index, count)
        self.enabled_set.mark_place(index)
        return {place: count}

    def find_firing(self, firing: str) -> tuple[str, int]:
        """``(transition, firing number)`` of the running firing ``firing`` names (its
        number, or its transition's id).

        Raises:
            ControlError: no such firing is running.
        """
        order = self.runner.in_firing_order()
        found = [f for f in order if str(f.number) == str(firing) or self.index.ids[f.index] == firing]
        if not found:
            running = ", ".join(f"{self.index.ids[f.index]} (firing {f.number})" for f in order)
            raise ControlError(f"no running firing {firing!r} (running: {running or 'none'})")
        return self.index.ids[found[0].index], found[0].number

    def force(self, firing: str, outcome: Outcome, reason: str) -> tuple[str, int]:
        """End a running firing (its number, or its transition's id) with ``outcome``:
        its action is cancelled, then the outcome's arcs produce (an operator's
        intervention: call it through :class:`~petriflow.runtime.control.Control`).

        Raises:
            ControlError: no such firing is running.
        """
        transition, number = self.find_firing(firing)
        self.runner.force(self.index.position[transition], outcome, reason)
        return transition, number

    def set_speed(self, factor: float) -> None:
        """Pace the run at ``factor`` times real time from now on (0: as fast as it goes)."""
        stopwatch = getattr(self.clock, "stopwatch", None)
        self.clock = SimulatedClock(stopwatch) if factor == 0 else RealtimeClock(stopwatch, factor, self.now)
        if self.control is not None:
            self.clock.interrupt = self.control.interrupt

    def pass_paused(self) -> bool:
        """While paused with remote agents, time goes on (theirs does): advance at most
        :data:`PAUSED_STEP` seconds, take in what is due (a remote firing's result, its
        ``end`` recorded now; an agent lost, its firings ended ``failed``) and let the
        watchers look, but fire nothing (a pause stops dispatching). ``True`` if
        something happened. The control calls it while it waits
        (:attr:`Control.idle <petriflow.runtime.control.Control.idle>`): a paced clock
        waits for the wall clock here, and for an unpaced one (:attr:`paced`) the
        control waits out the rest of the step itself.
        """
        kernel, seen = self.kernel, self.recorder.count
        tick = kernel.peek()
        target = kernel.tick + max(1, kernel.ticks_at(PAUSED_STEP))
        if tick is not None:
            target = min(target, max(tick, kernel.tick + 1))
        while kernel.tick < target:  # the clock stops after each tick while paused (interrupt)
            self.clock.advance(kernel, self.world, target)
        self.firer.new_instant()
        kernel.run_due()
        for watcher in self._watchers:
            watcher(self)
        return self.recorder.count != seen

    @property
    def paced(self) -> bool:
        """Whether the run's clock waits for the wall clock itself (a real-time clock)."""
        return getattr(self.clock, "rebase", None) is not None

    def rebase_clock(self) -> None:
        """The run stood still: a paced run goes on from now, without rushing to catch up."""
        rebase = getattr(self.clock, "rebase", None)
        if rebase is not None:
            rebase(self.now)

    def count(self, place: str) -> int:
        """Tokens in ``place`` now."""
        return self.tokens.counts[self._place(place)]

    def can_fire(self, t: int) -> bool:
        """Whether transition index ``t`` may fire now."""
        return self.enabled_set.can_fire(t)

    def transition_of(self, t: int) -> str:
        """Transition index ``t``'s id."""
        return self.index.ids[t]

    def recorder_count(self) -> int:
        """The number the next event will have."""
        return self.recorder.count

    def _place(self, place: str) -> int:
        index = self.tokens.index.get(place) if isinstance(place, str) else None
        if index is None:
            from difflib import get_close_matches

            close = get_close_matches(str(place), list(self.tokens.index), n=1)
            raise ControlError(f"no place {place!r} in net {self.net.id!r}"
                               f"{f' (did you mean {close[0]!r}?)' if close else ''}")
        return index

    # Running ------------------------------------------------------------------------
    def start(self) -> None:
        """Record the run's start and set up every bound action (called by :meth:`run`
        and :meth:`step` if needed)."""
        if self._started:
            return
        self._started = True
        self.resources.need(sorted({kind for cls in self.index.action_class if cls is not None
                                    for kind in getattr(cls, "resources", {}).values()}))
        self.clock.start()
        # the names a tool gave transitions whose ids are not (PNML ids are often UUIDs):
        # the trace says them, so replay shows them without the net
        labels = {t.id: t.label for t in self.net.transitions.values() if t.label and t.label != t.id}
        self.emit(_RUN, None, None, net=self.net.id, seed=self.seed, dt=self.kernel.dt,
                  marking=self.marking().to_dict(), agents=self.agents(), **({"labels": labels} if labels else {}))
        self.runner.setup(self.world)

    def _advance(self, tick: int) -> None:
        self.clock.advance(self.kernel, self.world, tick)
        self.firer.new_instant()
        if self.control is not None:
            self.control.new_instant(self.kernel.now)

    def _instant(self, fire: bool = True) -> None:
        """Process the current tick: due polls and events, then the firings."""
        kernel = self.kernel
        self._opened = True
        while True:
            kernel.run_due()
            if fire:
                self.firer.fire_instant()
            if not kernel.due():
                for watcher in self._watchers:
                    watcher(self)
                return

    def step(self) -> None:
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
            self._advance(tick)
        try:
            self._instant()
        except Unrouted as exc:
            raise exc.failure from None

    @relaxed()  # long-lived agent data: fewer full collector passes (petriflow.collector)
    def run(self, until: float | None = None, *, max_firings: int | None = None) -> RunResult:
        """Run until the net finishes, deadlocks, or a limit is reached.

        Args:
            until: simulated-time limit in seconds (default: the configuration's).
            max_firings: stop after this many firings.

        Returns:
            How the run ended; an action that failed with no failure route ends it
            with reason ``failed`` (recorded in the trace first).
        """
        until = self.config.until if until is None else limits.check_seconds(until, "until")
        self.firer.limit = max_firings
        self.start()
        if self._closed:
            raise PetriflowError("this run has ended; make a new Scheduler to run again")
        kernel = self.kernel
        limit = None if until is None else kernel.ticks_at(until)
        try:
            self._instant()  # the first instant, or the rest of the one a limit stopped in
            control = self.control
            while True:
                if control is not None and control.between():  # tokens put in or taken out
                    self._instant()  # what they enable fires now, before time moves on
                    continue
                stop = self._stop_reason(limit)
                if stop is not None:
                    return stop
                tick = kernel.peek()
                if control is not None:  # a resumed run stops where an intervention came between instants
                    tick = control.cut(kernel.tick, tick, kernel.ticks_at)
                self._advance(tick)
                self._instant()
        except Unrouted as exc:
            return self._end(StopReason.FAILED, str(exc.failure))

    def _stop_reason(self, limit: int | None) -> RunResult | None:
        """The run's end if it ends before the next instant (see
        :class:`~petriflow.runtime.result.RunResult`)."""
        kernel, stall = self.kernel, self.config.stall
        if self.firer.limit is not None and self.firings >= self.firer.limit:
            return self._end(StopReason.FIRINGS)
        if not self.runner.running and not kernel.pending and self.tokens.at_final:
            return self._end(StopReason.FINAL)
        tick = kernel.peek()
        if tick is None:
            return self._end(StopReason.DEAD)
        if limit is not None and tick > limit:
            self._advance(limit)
            return self._end(StopReason.UNTIL)
        if stall is not None and tick == kernel.tick + 1 and tick - self.firer.progress > kernel.ticks_at(stall):
            return self._end(StopReason.STALLED, f"no firing started or ended for {stall:g} s of simulated time"
                             f" while {', '.join(self.running())} ran")
        return None

    def fire_one(self, transition: str, timeout: float = 60.0) -> RunResult:
        """Fire ``transition`` now and run only its action until it ends.

        No other transition fires; the world steps as the action needs. This is what
        :func:`petriflow.testing.fire_one` uses to test one transition on its own.

        Raises:
            NotEnabledError: the transition cannot fire in the current marking.
        """
        from petriflow.engine import fire as fire_counts

        self.net.transition(transition)
        t = self.index.position[transition]
        self.start()
        self._opened = True
        if not self.enabled_set.can_fire(t):
            fire_counts(self.net, self.marking(), transition)  # raises naming short places
            raise PetriflowError(f"transition {transition!r} cannot fire now (guard false or agent down)")
        kernel = self.kernel
        self.enabled_set.agenda.discard(t)  # as the firing loop's take does
        try:
            self.firer.fire(t)
            limit = kernel.ticks_at(self.now + timeout)
            while t in self.runner.running:
                tick = kernel.peek()
                if tick is None or tick > limit:
                    return self._end(StopReason.UNTIL)
                self._advance(tick)
                self._instant(fire=False)
        except Unrouted as exc:
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
        if self._closed:
            return {}
        self._closed = True
        return self.runner.teardown(lambda t: self.index.ids[t])

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
        if self.control is not None:
            self.control.close()
        self._finished = RunResult(reason, round(self.now, 9), self.firings, self.marking(), self.recorder.count, error,
                                   self.tokens.tokens(), net=self.net, seed=self.seed)
        return self._finished
