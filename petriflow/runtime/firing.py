"""Firing transitions: consume, cancel a region, start the action; produce when it ends.

:class:`Firer` is the part of a run that changes the marking. At an instant it fires,
one at a time, every transition the :class:`~petriflow.runtime.enabling.EnabledSet`
offers (highest priority first, ties broken by one draw of the run's seeded
generator). A firing consumes its inputs and applies its cancellation region at
once; its action runs in the :class:`~petriflow.runtime.lifecycle.ActionRunner`, and
when it ends the firing's outcome picks the output arcs (``ok``, ``failed``,
``timeout``, ``cancelled``) whose places receive the tokens. Tokens put into channel
places are messages: they go to :class:`~petriflow.runtime.channels.Channels` once the
firing's end is recorded. A failure with no ``failed`` arcs stops the run
(:class:`Unrouted`).
"""

from __future__ import annotations

import random
from typing import Any

from petriflow import limits
from petriflow.errors import PetriflowError
from petriflow.net import Net
from petriflow.outcome import Outcome
from petriflow.runtime.action import ActionContext, ActionFailure
from petriflow.runtime.agents import Agents
from petriflow.runtime.channels import Channels
from petriflow.runtime.enabling import EnabledSet
from petriflow.runtime.index import RunIndex
from petriflow.runtime.kernel import Kernel
from petriflow.runtime.lifecycle import ActionRunner, Firing
from petriflow.runtime.recorder import Recorder
from petriflow.runtime.services import RunServices
from petriflow.runtime.tokens import TokenStore
from petriflow.runtime.trace import EventKind, summarize

__all__ = ["Firer", "Unrouted", "ZenoError"]

_START, _END, _CANCEL, _CUSTOM = (EventKind.START.value, EventKind.END.value, EventKind.CANCEL.value,
                                  EventKind.CUSTOM.value)


class ZenoError(PetriflowError):
    """Instant transitions keep firing without simulated time passing."""


class Unrouted(Exception):
    """A failure with no ``failed`` arcs: the run stops (internal)."""

    def __init__(self, failure: ActionFailure) -> None:
        super().__init__(str(failure))
        self.failure = failure


class Firer:
    """Fires a run's transitions and produces their outputs (see the module).

    Args:
        net: the net run.
        index: the net by integer indices.
        kernel: the run's event kernel.
        tokens: the run's tokens.
        enabled: the transitions that may fire.
        recorder: the run's events.
        agents: the agents' states (a firing of an agent is news for its guards).
        channels: where tokens put into channel places go.
        services: what the firings' contexts reach (:class:`~.services.RunServices`).
        world: the run's world (``None``: a world-less run).
        seed: the run seed.
        running: the dictionary of running firings (shared with ``enabled``).

    Attributes:
        count: transitions fired so far (a firing's number is the count when it fired).
        progress: the tick of the last firing start or end (the stall watchdog reads it).
        limit: stop firing at this count (``None``: no limit).
        runner: the action runner the firings' actions run in.
    """

    def __init__(self, net: Net, index: RunIndex, kernel: Kernel, tokens: TokenStore, enabled: EnabledSet, *,
                 recorder: Recorder, agents: Agents, channels: Channels, services: RunServices, world: Any,
                 seed: Any, running: dict[int, Firing]) -> None:
        self.net, self.index, self.kernel, self.tokens = net, index, kernel, tokens
        self.enabled, self.recorder, self.agents, self.channels = enabled, recorder, agents, channels
        self.services, self.world = services, world
        self.runner = ActionRunner(index, kernel, enabled, agents.sleepers, self.finish, self.context, running)
        self._sleepers = agents.sleepers
        self._delay = self.runner.delay  # per transition: the seconds its action only waits, or None
        compiled, consumers = index.compiled, index.consumers
        self._running = self.runner.running
        self._acts = [self.agents.any_readers(index.agent[t]) for t in range(len(index.ids))]
        # per compiled row, its non-channel output places
        self._fed = [tuple(p for p, _ in compiled.post[r] if not index.channel[p] and consumers[p])
                     for r in range(len(compiled.transitions))]
        # per compiled row, whether it puts tokens into channel places (messages)
        self._sends = [any(index.channel[p] for p, _ in compiled.post[r]) for r in range(len(compiled.transitions))]
        self.count = 0
        self.progress = 0
        self.limit: int | None = None
        #: the run's control queue (:class:`~petriflow.runtime.control.Control`), if it
        #: is steered: every firing is admitted by it first (where pause, step and
        #: breakpoints hold the run, for simulated and dispatched actions alike)
        self.control: Any = None
        self.now_count = 0  # firings at the current instant (the Zeno check's)
        self._looping: list[str] = []  # near the limit: what fires (to name a cycle)
        self._rng = random.Random(f"{seed}:conflicts")
        self._seed_prefix = f"{seed}:"

    def fire_instant(self) -> None:
        """Fire until nothing more can fire at this instant (or the firing limit)."""
        limit, draw, enabled = self.limit, self._rng.random, self.enabled
        agenda, dirty, changed, refresh, fire = enabled.agenda, enabled.dirty, enabled.changed, enabled.refresh, \
            self.fire
        watch = limits.FIRINGS_PER_INSTANT - 64
        control = self.control
        while limit is None or self.count < limit:
            if dirty or changed:
                refresh()
            if not agenda.count:
                return
            t = agenda.take(draw)
            if control is not None and not control.admit(t):  # an intervention took its tokens
                dirty.add(t)
                continue
            fire(t)
            self.now_count += 1
            if self.now_count > watch:
                self._zeno(t)

    def new_instant(self) -> None:
        """Time moved on: the count of firings in one instant starts again."""
        self.now_count = 0
        self._looping.clear()

    def _zeno(self, t: int) -> None:
        """Near the limit of firings in one instant: remember what fires, and at the limit
        stop the run naming the file, the limit and the transitions that keep firing."""
        looping = self._looping
        looping.append(self.index.ids[t])
        if self.now_count > limits.FIRINGS_PER_INSTANT:
            names = list(dict.fromkeys(looping))
            where = f"{self.net.path}: " if self.net.path else ""
            raise ZenoError(f"{where}more than {limits.FIRINGS_PER_INSTANT:,} firings at t={self.kernel.now:g} s"
                            f" without time passing (limit FIRINGS_PER_INSTANT, docs/limits.md): instant"
                            f" transitions fire in a cycle: {', '.join(names[:8])}"
                            f"{f' and {len(names) - 8} more' if len(names) > 8 else ''} (give one of them an"
                            " action that takes time, or stop the run with --max-firings)")

    def fire(self, t: int) -> None:
        """Fire transition index ``t`` now: consume, cancel its region, start its action.
        ``t`` is off the agenda (:meth:`fire_instant` takes it from there)."""
        index = self.index
        self.count = number = self.count + 1
        kernel = self.kernel
        tick = self.progress = kernel.tick
        inputs, withdrawn = self.tokens.take(index.row[t])  # inputs None: all black
        enabled = self.enabled
        taking = enabled.taking[t]
        if taking:
            enabled.changed.update(taking)
        if self._acts[t] or self._sleepers.any:
            self.agents.acted(index.agent[t])
        recorder = self.recorder
        if recorder.by_kind[_START] or recorder.narrow[_START] and recorder.wants(_START, index.ids[t]):
            taken = self.tokens.black(index.row[t]) if inputs is None else inputs
            details: dict[str, Any] = {"firing": number, "consumed": {p: len(v) for p, v in taken.items()}}
            carried = {p: [summarize(d) for d in v] for p, v in taken.items() if any(d is not None for d in v)}
            if carried:
                details["inputs"] = carried
            recorder.emit(_START, index.ids[t], index.agent[t], **details)
        else:
            recorder.count += 1
        if withdrawn or index.cancels[t]:
            self._cancel_region(t, number, withdrawn)
        now = tick * kernel.dt
        if self._delay[t] is not None:  # an action that only waits: its end is scheduled
            self.runner.wait(t, number, inputs, now)
            return
        self.runner.start(t, number, self.context(t, number, inputs, now))
        if t not in self._running:  # ended at once: check it again (a running one is when it ends)
            enabled.dirty.add(t)

    def context(self, t: int, number: int, inputs: dict[str, list[Any]] | None, now: float) -> ActionContext:
        """The context of firing ``number`` of transition index ``t``, started ``now``,
        that took ``inputs`` (``None``: black tokens only)."""
        index = self.index
        if inputs is None:
            inputs = self.tokens.black(index.row[t])
        return ActionContext(index.ids[t], index.agent[t], index.params[t], inputs, self.world,
                             self._seed_prefix + str(number), now, now, services=self.services,
                             action=index.action_class[t])

    def _cancel_region(self, t: int, number: int, withdrawn: dict[str, int]) -> None:
        cancelled = self.runner.cancel(list(self.index.cancels[t]))
        if withdrawn or cancelled:
            self.recorder.emit(_CANCEL, self.index.ids[t], self.index.agent[t], firing=number,
                               withdrawn=dict(withdrawn), actions=[self.index.ids[f.index] for f in cancelled])
        self.runner.drive(cancelled)

    def finish(self, number: int, t: int, ctx: ActionContext | None, outcome: Outcome, data: Any = None) -> None:
        """Produce the outputs of ``outcome`` and record the end of the firing (``ctx``
        ``None``: a delay's firing ending ``ok``, its output data ``data``).

        Raises:
            Unrouted: a failure or timeout the net gives no arcs for.
        """
        if ctx is None:
            self._produce(number, t, self.index.ok_row[t], outcome, data, None, data, "")
            return
        tid, recorder = self.index.ids[t], self.recorder
        row = self.index.ok_row[t] if outcome is Outcome.OK else self.index.route[t][outcome]
        if row is None and outcome is not Outcome.CANCELLED and outcome is not Outcome.OK:
            self.progress = self.kernel.tick
            if self._acts[t] or self._sleepers.any:
                self.agents.acted(ctx.agent)
            reason = ctx.reason or outcome.value
            recorder.emit(_END, tid, ctx.agent, firing=number, outcome=outcome.value, produced={}, reason=reason)
            raise Unrouted(ActionFailure(reason, net=self.net.id, transition=tid,
                                         action=self.net.transitions[tid].action))
        if ctx.emitted:
            for kind, data in ctx.emitted:  # summarized only for someone listening
                if recorder.wants(_CUSTOM, tid):
                    recorder.emit(_CUSTOM, tid, ctx.agent, firing=number, name=kind, data=summarize(data))
                else:
                    recorder.skip()
            ctx.emitted.clear()
        result, outputs = ctx.result, ctx.outputs
        if ctx.per_place and isinstance(result, dict):
            result, outputs = None, result
        self._produce(number, t, row, outcome, result, outputs, ctx.result, ctx.reason)

    def _produce(self, number: int, t: int, row: int | None, outcome: Outcome, result: Any,
                 outputs: dict[str, Any] | None, shown: Any, reason: str) -> None:
        """The end of firing ``number`` of ``t``: the tokens of compiled ``row`` (none if
        ``None``) with ``result`` as data (``outputs[place]`` where given), its end event
        (showing ``shown`` and ``reason``), then its messages."""
        recorder, agent = self.recorder, self.index.agent[t]
        self.progress = self.kernel.tick
        if self._acts[t] or self._sleepers.any:
            self.agents.acted(agent)
        sent: list[tuple[str, Any]] | None = None
        if row is not None:  # the outputs: tokens here, messages once the end is recorded
            channel = self.index.channel
            self.tokens.put(row, result, outputs, channel)
            self.enabled.changed.update(self._fed[row])
            if self._sends[row]:
                sent, places = [], self.index.compiled.places
                for p, w in self.index.compiled.post[row]:
                    if channel[p]:
                        sent.extend([(places[p], outputs.get(places[p], result) if outputs else result)] * w)
        if recorder.by_kind[_END] or recorder.narrow[_END] and recorder.wants(_END, self.index.ids[t]):
            produced = {} if row is None else self.tokens.produced(row, self.index.channel)
            details: dict[str, Any] = {"firing": number, "outcome": outcome.value, "produced": produced}
            if shown is not None:
                details["result"] = summarize(shown)
            if reason:
                details["reason"] = reason
            recorder.emit(_END, self.index.ids[t], agent, **details)
        else:
            recorder.count += 1
        if sent:
            for place, data in sent:
                self.channels.send(place, data, agent)
