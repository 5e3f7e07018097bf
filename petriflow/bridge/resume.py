"""Resuming a bridged run after the orchestrator was killed: replay, then re-attach.

``petriflow run --resume`` re-executes a journaled run and checks every event against
the journal. A bridged run ran in wall-clock time, so its remote firings cannot be
executed again to the same times; instead, until the journal's last event, they are
*replayed* from it (:class:`Replay`): each remote firing the journal shows ended ends
at its journaled time with its journaled outcome, data and reason (no goal is sent),
and each remote agent lost or back, and each agent's ``feedback``, comes at its journaled
time, in its journaled order; the clock runs as fast
as it can meanwhile (:class:`ResumeClock`). A firing the journal shows started and not
ended was still running on its agent when the orchestrator died: its goal is sent again
with the same id (the run's name is journaled), and the agent, which de-duplicates by
id, answers as for the first (``accepted`` while it still runs, its ``result`` if it
ended meanwhile): the run *re-attaches* to it, and no action runs twice. From the
journal's end, the run goes on in wall-clock time with the live agents.
"""

from __future__ import annotations

import time as wallclock
from typing import Any

from petriflow.bridge import protocol
from petriflow.bridge.dispatcher import Dispatcher, GoalState, Phase
from petriflow.bridge.watch import Listen
from petriflow.runtime.kernel import Kernel
from petriflow.runtime.trace import Event

__all__ = ["Replay", "ReplayingRemote", "ResumeClock", "ReplayWatch"]

_PHASES = {"ok": Phase.OK, "failed": Phase.FAILED, "cancelled": Phase.CANCELLED, "timeout": Phase.FAILED}


class Replay:
    """What a journal says of a bridged run's remote firings (see the module).

    Args:
        events: the journal's events.
        remote: the transitions executed by remote agents.
    """

    def __init__(self, events: list[Event], remote: set[str]) -> None:
        self.until = events[-1].time if events else 0.0
        self.ends: dict[int, Event] = {}
        self.records: dict[int, dict[str, Any]] = {}
        self.faults: list[tuple[float, str, str, str]] = []  # (time, lost|back, agent, why)
        #: The journal's faults (as :attr:`faults`) and ``feedback`` events, in its order.
        self.outside: list[tuple[float, str, str, str] | Event] = []
        for event in events:
            firing = event.data.get("firing")
            if event.kind == "end" and event.transition in remote:
                self.ends[firing] = event
            elif event.kind == "custom" and event.data.get("name") == "remote":
                self.records[firing] = event.data.get("data") or {}
            elif event.kind == "fault" and event.data.get("fault") in ("lost", "back"):
                self.faults.append((event.time, event.data["fault"], event.agent, event.data.get("why", "")))
                self.outside.append(self.faults[-1])
            elif event.kind == "feedback":
                self.outside.append(event)

    def state(self, goal: protocol.Goal, firing: int) -> GoalState | None:
        """The journaled ending of ``goal`` (firing ``firing``), to be taken at its time."""
        end = self.ends.get(firing)
        if end is None:
            return None
        record = self.records.get(firing, {})
        trip = record.get("round_trip_ms")
        phase = record.get("phase") or _PHASES.get(end.data.get("outcome"), Phase.FAILED)
        state = GoalState(goal, phase=phase, sent=0.0,
                          answered=None if trip is None else trip / 1e3, resent=record.get("resent", 0),
                          data=end.data.get("result"), reason=end.data.get("reason", ""))
        state.answered_calls = record.get("calls", 0)
        state.at = end.time
        return state


class ReplayingRemote:
    """The run's remote service on resume: journaled endings until the journal's end,
    the live :class:`~petriflow.bridge.dispatcher.Dispatcher` for the rest."""

    def __init__(self, dispatcher: Dispatcher, replay: Replay) -> None:
        self.dispatcher = dispatcher
        self.replay = replay
        self.run = dispatcher.run
        self.spec = dispatcher.spec
        self.replayed: dict[str, GoalState] = {}
        self.lost: set[str] = set()  # remote agents lost as the journal says (while replaying)
        self.replaying = True

    def send(self, goal: protocol.Goal) -> GoalState:
        firing = int(goal.id.split("/")[1])
        state = self.replay.state(goal, firing)
        if state is not None:
            self.replayed[goal.id] = state
            return state
        return self.dispatcher.send(goal)  # running at the kill (re-attach), or new

    def goal(self, goal_id: str) -> GoalState | None:
        return self.replayed.get(goal_id) or self.dispatcher.goal(goal_id)

    def cancel(self, goal_id: str) -> None:
        if goal_id not in self.replayed:
            self.dispatcher.cancel(goal_id)

    def forget(self, goal_id: str) -> None:
        if goal_id not in self.replayed:
            self.dispatcher.forget(goal_id)

    def done(self, goal_id: str) -> None:
        if self.replayed.pop(goal_id, None) is None:
            self.dispatcher.done(goal_id)

    def take_calls(self, goal_id: str) -> list[protocol.Call]:
        return [] if goal_id in self.replayed else self.dispatcher.take_calls(goal_id)

    def reply(self, reply: protocol.Reply) -> None:
        self.dispatcher.reply(reply)

    def refuse_calls(self, goal_id: str, why: str) -> None:
        if goal_id not in self.replayed:
            self.dispatcher.refuse_calls(goal_id, why)

    def is_lost(self, agent: str) -> bool:
        return agent in self.lost if self.replaying else self.dispatcher.is_lost(agent)

    def silence(self, agent: str) -> float:
        return self.dispatcher.silence(agent)

    def why_lost(self, agent: str) -> str:
        return self.dispatcher.why_lost(agent)


class ResumeClock:
    """As fast as it can up to ``until`` (the journal's end), then paced to the wall
    clock from there (a :class:`~petriflow.runtime.clock.RealtimeClock` whose start is
    ``until`` seconds ago when it gets there)."""

    def __init__(self, until: float) -> None:
        self.until = until
        self._start: float | None = None

    def start(self) -> None:
        self._start = None

    def advance(self, kernel: Kernel, world: Any, tick: int) -> None:
        while kernel.tick < tick:
            if world is not None:
                world.step()
            kernel.tick += 1
            if kernel.now <= self.until + 1e-9:
                continue
            if self._start is None:
                self._start = wallclock.perf_counter() - kernel.now
            ahead = kernel.now - (wallclock.perf_counter() - self._start)
            if ahead > 0:
                wallclock.sleep(ahead)


class ReplayWatch:
    """After each instant: journaled losses and returns while replaying; the live
    agents' after the journal's end (see :class:`~petriflow.bridge.orchestrator.AgentWatch`)."""

    def __init__(self, remote: ReplayingRemote, live: Any, runs: dict[str, list[str]]) -> None:
        self.remote = remote
        self.live = live
        self.runs = runs
        self.owner = {agent: name for name, agents in runs.items() for agent in agents}
        self.faults = list(remote.replay.outside)
        self.listening: set[int] = set()

    def __call__(self, scheduler: Any) -> None:
        remote, now = self.remote, scheduler.now
        if remote.replaying:
            self._listen(scheduler)
            while self.faults and _time(self.faults[0]) <= now + 1e-9:
                head = self.faults.pop(0)
                if isinstance(head, Event):  # an agent's feedback, as journaled
                    scheduler.emit(head.kind, head.transition, head.agent, **head.data)
                    continue
                _, kind, agent, why = head
                name = self.owner.get(agent, agent)
                if kind == "lost":
                    remote.lost.add(name)
                    scheduler.agent_lost(agent, why)
                else:
                    remote.lost.discard(name)
                    scheduler.agent_back(agent)
            if now < remote.replay.until - 1e-9:
                return
            remote.replaying = False  # the journal's end: the live agents from here
            for name in sorted(remote.lost):
                if remote.dispatcher.announced(name) is not None:
                    for agent in self.runs.get(name, []):
                        scheduler.agent_back(agent)
                else:
                    remote.dispatcher.mark_lost(name)
            return
        self.live(scheduler)

    def _listen(self, scheduler: Any) -> None:
        """An instant at the next journaled loss or return, and at the journal's end (the
        original run had one there)."""
        kernel = scheduler.kernel
        times = [_time(self.faults[0])] if self.faults else []
        times.append(self.remote.replay.until)
        for at in times:
            tick = kernel.ticks_at(at)
            if tick > kernel.tick and tick not in self.listening:
                self.listening.add(tick)
                kernel.schedule(tick, Listen())


def _time(entry: Any) -> float:
    """A journaled fault's or feedback event's time."""
    return entry.time if isinstance(entry, Event) else entry[0]
