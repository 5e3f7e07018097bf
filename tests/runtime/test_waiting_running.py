"""Waiting on state, two edges: a sleep on ``RUNNING`` wakes when a teammate stops, and
a firing's left-over wake-up never polls a later firing of its transition out of
firing order."""

from __future__ import annotations

import pytest

from petriflow.io.yaml import loads_net
from petriflow.runtime.action import Action, InstantAction, Param, Status
from petriflow.runtime.agents import RUNNING, AgentState
from petriflow.runtime.registry import Registry
from petriflow.runtime.scheduler import Scheduler


class Counts(AgentState):
    def __init__(self) -> None:
        super().__init__()
        self.n = {"a": 0, "b": 0}

    def bump(self, key: str) -> None:
        self.n[key] += 1
        self.touch(key)


class Begin(InstantAction):
    def run(self, ctx):
        ctx.state = Counts()


class BumpEvery(Action):
    """Bump a counter every ``period`` s, ``times`` times."""

    needs_world = False
    params = {"key": Param(str, "a"), "period": Param(float, 0.3), "times": Param(int, 2)}

    def start(self, ctx):
        self.left = self.params["times"]
        self.wake_at = ctx.now + self.params["period"]

    def poll(self, ctx):
        if ctx.now < self.wake_at - 1e-9:
            return Status.RUNNING
        ctx.state.bump(self.params["key"])
        self.left -= 1
        self.wake_at += self.params["period"]
        return Status.OK if self.left == 0 else Status.RUNNING


class Watch(Action):
    """Until the counter ``key`` moves, or a teammate stops (``key: running``), or
    ``within`` s; polled at every tick (``sleeping = False``) or asleep."""

    needs_world = False
    sleeping = False
    params = {"key": Param(str, "a"), "within": Param(float, 1.0), "peer": Param(str, "")}

    def start(self, ctx):
        self.seen = dict(ctx.state.n)
        self.until = ctx.now + self.params["within"]

    def poll(self, ctx):
        key, peer = self.params["key"], self.params["peer"]
        moved = ctx.state.n[key] != self.seen[key] if key != RUNNING else not ctx.running(peer)
        if ctx.now > ctx.started and moved or ctx.now >= self.until - 1e-9:
            ctx.result = {"at": round(ctx.now, 6)}
            return Status.OK
        if self.sleeping:  # moved already when it started: it ends at the next tick
            self.wake_on, self.wake_at = (key,), ctx.now if moved else self.until - 2e-9
        return Status.RUNNING


class SleepingWatch(Watch):
    sleeping = True


def events(text: str, sleeping: bool, config: dict | None = None, seed: int = 0) -> list[tuple]:
    made = Registry(load_plugins=False)
    made.register_state("demo.counts", Counts)
    made.register("demo.begin", Begin)
    made.register("demo.bump_every", BumpEvery)
    made.register("demo.watch", SleepingWatch if sleeping else Watch)
    scheduler = Scheduler(loads_net(text), registry=made, config={"dt": 0.1, **(config or {})},
                          seed=seed)
    seen: list[tuple] = []
    scheduler.on_event(lambda e: seen.append((e.seq, e.kind, e.time, e.transition, repr(e.data))))
    result = scheduler.run(until=3)
    return seen + [(result.reason, result.time, result.firings)]


LOOPS = """
petriflow: 1
subnets:
  - id: r
    state: demo.counts
    places: [{id: go, tokens: 1}, a0, b0, c0, c1]
    transitions:
      - {id: begin, action: demo.begin, in: [go], out: [a0, b0, c0]}
      - {id: bump, action: demo.bump_every, params: {key: a, period: 0.5, times: 4}, in: [c0], out: [c1]}
      - {id: watch_a, action: demo.watch, params: {key: a, within: 1.0}, in: [a0], out: [a0]}
      - {id: watch_b, action: demo.watch, params: {key: b, within: 0.5}, in: [b0], out: [b0]}
"""


@pytest.mark.parametrize("seed", range(6))
def test_left_over_wake_ups_do_not_change_the_order_of_polls(seed):
    """A watch that ends early leaves a wake-up behind; its transition's next firing,
    woken at that same tick, is still polled in firing order: the same events as polled
    watches."""
    assert events(LOOPS, sleeping=True, seed=seed) == events(LOOPS, sleeping=False, seed=seed)


TEAM = """
petriflow: 1
subnets:
  - id: r1
    state: demo.counts
    places: [{id: go, tokens: 1}, s, e]
    transitions:
      - {id: begin, action: demo.begin, in: [go], out: [s]}
      - {id: watch, action: demo.watch, params: {key: running, within: 5.0, peer: r2}, in: [s], out: [e]}
  - id: r2
    places: [{id: idle, tokens: 1}, gone]
    transitions:
      - {id: linger, action: core.wait, params: {seconds: 9.0}, in: [idle], out: [gone]}
"""


@pytest.mark.parametrize("at", [0.0, 0.35, 1.2])
def test_a_sleep_on_running_wakes_when_a_teammate_stops(at):
    """Asleep on RUNNING, the watch ends at the tick a watch asking every tick sees r2 stop."""
    config = {"faults": [{"kill": "r2", "at": at}]}
    sleeping = events(TEAM, sleeping=True, config=config)
    assert sleeping == events(TEAM, sleeping=False, config=config)
    ended = [e for e in sleeping if e[1] == "end" and e[3] == "watch"]
    assert ended and ended[0][2] < 5.0
