"""The actions of a run, from setup to teardown, and each firing's lifecycle.

When a transition fires, :class:`ActionRunner` starts its action and then polls it on
the kernel: at the time it asked for (``wake_at``), at every tick while it steps with
the world (``needs_world``), and at its transition's timeout. A cancellation (a
cancellation region, a fault killing its agent) or a timeout calls
:meth:`~petriflow.runtime.action.Action.cancel` instead of ``poll`` until it says it
is done. When the action ends, the runner hands its outcome to the run
(:class:`Finisher`), which produces the outputs.

An action that sleeps on its agent's state (:attr:`~petriflow.runtime.action.Action.wake_on`)
is registered with the agent's :class:`~petriflow.runtime.agents.Sleepers` and polled
when a key it sleeps on changes (at the tick its polled twin would see the change,
:meth:`~petriflow.runtime.kernel.Kernel.poll_tick`) or at its ``wake_at``, whichever
comes first; never in between.

An action that only waits (:meth:`~petriflow.runtime.action.Action.delay`, e.g.
``core.wait``) on a transition without a timeout is not polled: :meth:`ActionRunner.wait`
schedules its end, which comes at the tick its poll would have ended it, with no
context made unless the firing is cancelled.

An exception in any hook is that firing's ``failed`` outcome with the exception as
reason, never a lost token; an exception in ``setup`` makes every firing of the
transition fail with it.
"""

from __future__ import annotations

from typing import Any, Callable, Protocol

from petriflow.outcome import Outcome
from petriflow.runtime.action import Action, ActionContext, Status, first_data
from petriflow.runtime.agents import Sleepers
from petriflow.runtime.enabling import EnabledSet, reason_of
from petriflow.runtime.index import RunIndex
from petriflow.runtime.kernel import POLL, Deadline, Kernel, Scheduled

__all__ = ["Firing", "ActionRunner", "Finisher"]


#: The shortest delay :meth:`ActionRunner.wait` schedules (a shorter one is polled).
SHORTEST_DELAY = 1e-6


class Finisher(Protocol):
    """What the runner tells when a firing ends (the run produces its outputs); ``ctx``
    is ``None`` for a delay's firing ending ``ok``, whose output data is ``data``."""

    def __call__(self, number: int, t: int, ctx: ActionContext | None, outcome: Outcome, data: Any = None) -> None:
        ...


class Contexts(Protocol):
    """Makes the context of firing ``number`` of transition ``t`` (the run knows its world
    and seed) for its consumed ``inputs`` (``None``: black tokens only), started at ``now``."""

    def __call__(self, t: int, number: int, inputs: dict[str, list[Any]] | None, now: float) -> ActionContext: ...


class Firing(Scheduled):
    """The running firing of one transition (a transition runs one at a time, so one
    record per transition serves all its firings); scheduled on the kernel, it is its
    own wake-up (the poll it asked for last). A delay's firing has no ``ctx`` until it
    is cancelled; it keeps its ``inputs`` and ``started`` time."""

    __slots__ = ("runner", "number", "index", "action", "ctx", "deadline", "cancelling", "wake", "polled",
                 "running", "inputs", "started", "nap", "note")
    phase = POLL

    def __init__(self, runner: "ActionRunner", index: int, action: Action) -> None:
        self.runner = runner
        self.index = index
        self.action = action
        self.number = 0
        self.ctx: ActionContext | None = None
        self.inputs: dict[str, list[Any]] | None = None
        self.started = 0.0
        self.deadline: float | None = None
        self.cancelling: Outcome | None = None
        self.wake = -1
        self.polled = -1
        self.running = False
        self.nap = 0  # the sleep on its state it is in (0: awake)
        self.note = ""  # why it was forced to end (an operator's intervention)

    def live(self, tick: int) -> bool:
        # an entry left by an earlier firing of this transition (a wake-up it no longer
        # needed) is dead even at the tick the current firing wakes: polled there, it
        # would poll the current firing out of firing order (its key is the older number)
        polling = self.runner.kernel.polling
        return self.running and self.wake == tick and (polling is None or polling == self.number)

    def apply(self, tick: int) -> None:
        if self.polled != tick:  # once per tick, whichever entry comes first
            self.runner.poll(self)

    def asleep_on(self, nap: int) -> bool:
        """Whether the sleep ``nap`` is the one this firing is still in."""
        return self.running and self.nap == nap

    def rouse(self) -> None:
        """Its agent's state changed under its sleep: it is polled when a polled firing
        would first see that (:meth:`~petriflow.runtime.kernel.Kernel.poll_tick`)."""
        self.nap = 0
        self.runner.wake(self)


class ActionRunner:
    """Starts, polls, cancels and ends the actions of a run (see the module).

    Args:
        index: the run's net index.
        kernel: the run's event kernel.
        enabled: the run's enabled set (a transition whose action stops may fire again).
        sleepers: where firings asleep on their agent's state are registered.
        finish: called when a firing ends, with its outcome.
        contexts: makes a firing's context (for a delay's firing being cancelled).
        running: the dictionary to keep the running firings in (shared with the
            enabled set, for which a running transition may not fire).

    Attributes:
        running: ``{transition index: Firing}`` of the actions running now.
        delay: per transition, the seconds its action only waits (:meth:`wait` starts
            it), or ``None`` (:meth:`start`); known once :meth:`setup` ran.
    """

    def __init__(self, index: RunIndex, kernel: Kernel, enabled: EnabledSet, sleepers: Sleepers, finish: Finisher,
                 contexts: Contexts, running: dict[int, Firing] | None = None) -> None:
        self.index = index
        self.kernel = kernel
        self.enabled = enabled
        self.sleepers = sleepers
        self.finish = finish
        self.contexts = contexts
        self.running: dict[int, Firing] = {} if running is None else running
        self._naps = 0  # sleeps begun so far (each sleep's number)
        self.delay: list[float | None] = [None] * len(index.ids)
        self.actions: list[Action | None] = [None] * len(index.ids)
        self._slot: list[Firing | None] = [None] * len(index.ids)
        self._setup_error: list[str | None] = [None] * len(index.ids)

    def setup(self, world: Any) -> None:
        """Make every bound transition's action and set it up (once, at the run's start)."""
        for t, cls in enumerate(self.index.action_class):
            if cls is None:
                continue
            action = self.actions[t] = cls(self.index.params[t])
            self._slot[t] = Firing(self, t, action)
            try:
                action.setup(world)
                seconds = action.delay() if self.index.timeout[t] is None else None
            except Exception as exc:  # every firing of t then fails with this reason
                self._setup_error[t] = reason_of(exc, "setup")
                continue
            if seconds is not None and seconds >= SHORTEST_DELAY:
                self.delay[t] = seconds

    def wait(self, t: int, number: int, inputs: dict[str, list[Any]] | None, now: float) -> None:
        """Start firing ``number`` of transition ``t``, whose action only waits
        (:attr:`delay`), having taken ``inputs`` (``None``: black tokens only): its end
        is scheduled at the first tick at which the action's poll would end it, nothing
        is called."""
        kernel = self.kernel
        wake = now + self.delay[t]
        dt = kernel.dt
        tick = max(kernel.tick + 1, kernel.ticks_at(wake))
        while tick * dt < wake - 1e-12:
            tick += 1
        firing = self._slot[t]  # a delay's record never has a deadline (no timeout)
        firing.number = number
        firing.ctx = firing.cancelling = None
        firing.note = ""
        firing.inputs = inputs
        firing.started = now
        firing.running = True
        self.running[t] = firing
        self._wake(firing, tick)

    def start(self, t: int, number: int, ctx: ActionContext) -> None:
        """Start firing ``number`` of transition ``t`` (its inputs are consumed)."""
        action = self.actions[t]
        if action is None:  # no action: the firing ends at once, passing its input data on
            ctx.result = ctx.token()
            self.finish(number, t, ctx, Outcome.OK)
            return
        if self._setup_error[t] is not None:
            ctx.reason = self._setup_error[t]
            self.finish(number, t, ctx, Outcome.FAILED)
            return
        kernel = self.kernel
        now = ctx.now
        timeout = self.index.timeout[t]
        firing = self._slot[t]  # its record begins firing `number` (the previous one has ended)
        firing.number, firing.ctx, firing.deadline = number, ctx, None if timeout is None else now + timeout
        firing.cancelling, firing.wake, firing.polled, firing.running = None, -1, -1, True
        firing.note = ""
        self.running[t] = firing
        try:
            action.start(ctx)
        except Exception as exc:  # an action's error is a failed outcome, never lost
            ctx.reason = reason_of(exc)
            self._stop(firing)
            self.finish(number, t, ctx, Outcome.FAILED)
            return
        if timeout is not None:
            tick = max(kernel.tick + 1, kernel.ticks_at(firing.deadline))
            kernel.schedule(tick, Deadline(firing, number), key=number)
        wake = action.wake_at
        if not action.needs_world and action.wake_on is not None:  # asleep on its state from the start
            firing.polled = kernel.tick  # as if polled now: a change of this instant wakes it at the next tick
            if self._sleep(firing, ctx, action.wake_on) and wake is not None:
                self._wake(firing, max(kernel.tick + 1, kernel.ticks_at(wake)))
        elif wake is not None and not action.needs_world and wake > now + 1e-12:
            self._wake(firing, max(kernel.tick + 1, kernel.ticks_at(wake)))  # first poll when it asked
        else:
            self.poll(firing)

    def cancel(self, transitions: list[int], outcome: Outcome = Outcome.CANCELLED) -> list[Firing]:
        """Cancel the running firings of ``transitions`` (in firing order); returns them."""
        firings = sorted((self.running[t] for t in transitions if t in self.running), key=lambda f: f.number)
        for firing in firings:
            firing.cancelling = outcome
        return firings

    def force(self, t: int, outcome: Outcome, note: str) -> Firing:
        """End the running firing of ``t`` with ``outcome`` (someone steering the run
        says so): its action's ``cancel()`` is called until it is done, as for a
        cancellation, then the firing ends with ``outcome`` and ``note`` as its reason
        (an ``ok`` one produces its plain outputs, with the data the action left)."""
        firing = self.running[t]
        firing.cancelling = outcome
        firing.note = note
        self.drive([firing])
        return firing

    def drive(self, firings: list[Firing]) -> None:
        """Poll firings being cancelled at once (they may finish in this instant)."""
        for firing in firings:
            if firing.running:
                self.poll(firing)

    def poll(self, firing: Firing) -> None:
        """Poll one running action (or drive its cancellation); end it if it ended."""
        kernel = self.kernel
        firing.polled = tick = kernel.tick
        firing.nap = 0  # polled: awake, whatever it slept on
        ctx, action = firing.ctx, firing.action
        if ctx is None:  # a delay's firing: its time has come, or it is cancelled
            if firing.cancelling is None:
                self._stop(firing)
                inputs = firing.inputs
                self.finish(firing.number, firing.index, None, Outcome.OK,
                            None if inputs is None else first_data(inputs))
                return
            ctx = firing.ctx = self.contexts(firing.index, firing.number, firing.inputs, firing.started)
        ctx.now = now = tick * kernel.dt
        if firing.cancelling is None and firing.deadline is not None and now >= firing.deadline - 1e-9:
            firing.cancelling = Outcome.TIMEOUT
        if firing.cancelling is not None:
            self._drive_cancel(firing, ctx, action, tick)
            return
        try:
            status = action.poll(ctx)
        except Exception as exc:
            ctx.reason = reason_of(exc)
            status = Status.FAILED
        if status is Status.OK:
            outcome = Outcome.OK
        elif status is Status.RUNNING:
            if action.needs_world:
                self._wake(firing, tick + 1)
            else:
                wake = action.wake_at
                if action.wake_on is not None:  # asleep on its state (and at most until wake_at)
                    if not self._sleep(firing, ctx, action.wake_on):
                        return
                    if wake is None:
                        firing.wake = -1  # no time wakes it: its entries ahead are dead
                        return
                self._wake(firing, tick + 1 if wake is None else max(tick + 1, kernel.ticks_at(wake)))
            return
        else:
            if status is not Status.FAILED:
                ctx.reason = f"poll() returned {status!r}, not a Status"
            outcome = Outcome.FAILED
        self._stop(firing)
        self.finish(firing.number, firing.index, ctx, outcome)

    def _drive_cancel(self, firing: Firing, ctx: ActionContext, action: Action, tick: int) -> None:
        outcome = firing.cancelling
        try:
            done = action.cancel(ctx)
        except Exception as exc:
            ctx.reason = reason_of(exc, "cancel")
            done, outcome = True, Outcome.FAILED
        if not done:
            self._wake(firing, tick + 1)
            return
        if firing.note and not ctx.reason:
            ctx.reason = firing.note
        self._stop(firing)
        self.finish(firing.number, firing.index, ctx, outcome)

    def _sleep(self, firing: Firing, ctx: ActionContext, keys: tuple[str, ...]) -> bool:
        """Register ``firing`` asleep on ``keys`` of its agent's state; ``False`` (and the
        firing failed) when its transition has no agent."""
        agent = self.index.agent[firing.index]
        if agent is None:
            ctx.reason = f"it waits on its agent's state ({', '.join(keys)}), and {ctx.transition!r} is in no" \
                         " agent subnet"
            self._stop(firing)
            self.finish(firing.number, firing.index, ctx, Outcome.FAILED)
            return False
        self._naps += 1
        firing.nap = self._naps
        self.sleepers.add(agent, keys, firing, self._naps)
        return True

    def wake(self, firing: Firing) -> None:
        """``firing``'s agent state changed under its sleep: poll it at the tick a firing
        polled every tick would first see the change."""
        self._wake(firing, self.kernel.poll_tick(firing.number, firing.polled))

    def _stop(self, firing: Firing) -> None:
        firing.running = False
        firing.nap = 0
        del self.running[firing.index]
        self.enabled.dirty.add(firing.index)

    def _wake(self, firing: Firing, tick: int) -> None:
        firing.wake = tick
        self.kernel.schedule_poll(tick, firing, firing.number)

    def in_firing_order(self) -> list[Firing]:
        """The firings running now, oldest first."""
        return sorted(self.running.values(), key=lambda f: f.number)

    def teardown(self, name: Callable[[int], str]) -> dict[str, str]:
        """Tear every action down; ``{transition: reason}`` of those whose teardown raised."""
        problems: dict[str, str] = {}
        for t, action in enumerate(self.actions):
            if action is not None:
                try:
                    action.teardown()
                except Exception as exc:
                    problems[name(t)] = reason_of(exc, "teardown")
        return problems
