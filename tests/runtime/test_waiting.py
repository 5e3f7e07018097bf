"""Waiting on state: an action asleep until its agent's state changes, never polled meanwhile."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from petriflow.io.yaml import loads_net
from petriflow.outcome import StopReason
from petriflow.runtime.action import Action, InstantAction, Param, StateChange, Status
from petriflow.runtime.agents import RUNNING, AgentState
from petriflow.runtime.registry import Registry
from petriflow.runtime.scheduler import Scheduler


class Counts(AgentState):
    """A state with two counters, each a key of its own."""

    def __init__(self) -> None:
        super().__init__()
        self.n = {"a": 0, "b": 0}

    def bump(self, key: str) -> None:
        self.n[key] += 1
        self.touch(key)


class Begin(InstantAction):
    """The agent's state is made."""

    def run(self, ctx):
        ctx.state = Counts()


class Bump(InstantAction):
    """Bump a counter when the firing starts (a change in an instant's firings)."""

    params = {"key": Param(str, "a")}

    def run(self, ctx):
        ctx.state.bump(self.params["key"])


class BumpEvery(Action):
    """Bump a counter every ``period`` seconds, ``times`` times (a change in the polls)."""

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


WAIT_PARAMS = {"key": Param(str, "a"), "count": Param(int, 1)}


def _reached(ctx) -> bool:
    key, n = ctx.params["key"], ctx.state.n
    return (n["a"] + n["b"] if key == "*" else n[key]) >= ctx.params["count"]


def polled_wait(ctx):
    """Until the counter reaches ``count``, looking at every tick."""
    while not _reached(ctx):
        yield
    return ctx.now


def sleeping_wait(ctx):
    """Until the counter reaches ``count``, asleep until it changes."""
    while not _reached(ctx):
        yield StateChange(ctx.params["key"])
    return ctx.now


class PolledUntil(Action):
    """The class form, polled at every tick."""

    needs_world = False
    params = WAIT_PARAMS

    def poll(self, ctx):
        if _reached(ctx):
            ctx.result = ctx.now
            return Status.OK
        return Status.RUNNING


class SleepingUntil(PolledUntil):
    """The class form, asleep on its key between polls."""

    def poll(self, ctx):
        status = super().poll(ctx)
        self.wake_on = (self.params["key"],)
        return status


def registry(sleeping: bool) -> Registry:
    made = Registry(load_plugins=False)
    made.register_state("demo.counts", Counts)
    made.register("demo.begin", Begin)
    made.register("demo.bump", Bump)
    made.register("demo.bump_every", BumpEvery)
    made.action("demo.wait", WAIT_PARAMS)(sleeping_wait if sleeping else polled_wait)
    made.register("demo.until", SleepingUntil if sleeping else PolledUntil)
    return made


def counting_net(writers: list[tuple[str, float, str, float, int]], waiters: list[tuple[str, float, str, int]]):
    """One agent: ``demo.begin``, then each writer ``(action, delay, key, period, times)``
    and each waiter ``(action, delay, key, count)`` after a ``core.wait`` of its delay."""
    starts = [f"s{i}" for i in range(len(writers) + len(waiters))]
    places = ["{id: go, tokens: 1}", *starts, *(f"d{i}" for i in range(len(starts))),
              *(f"e{i}" for i in range(len(starts)))]
    transitions = [f"{{id: begin, action: demo.begin, in: [go], out: [{', '.join(starts)}]}}"]
    for i, (action, delay, key, period, times) in enumerate(writers):
        params = f"{{key: {key}}}" if action == "demo.bump" else f"{{key: {key}, period: {period}, times: {times}}}"
        transitions += [f"{{id: w{i}, action: core.wait, params: {{seconds: {delay}}}, in: [s{i}], out: [d{i}]}}",
                        f"{{id: write{i}, action: {action}, params: {params}, in: [d{i}], out: [e{i}]}}"]
    for j, (action, delay, key, count) in enumerate(waiters, start=len(writers)):
        transitions += [f"{{id: w{j}, action: core.wait, params: {{seconds: {delay}}}, in: [s{j}], out: [d{j}]}}",
                        f"{{id: wait{j}, action: {action}, params: {{key: '{key}', count: {count}}},"
                        f" in: [d{j}], out: [e{j}]}}"]
    text = "\n".join(["petriflow: 1", "subnets:", "  - id: r", "    state: demo.counts",
                      f"    places: [{', '.join(places)}]", "    transitions:",
                      *(f"      - {t}" for t in transitions)])
    return loads_net(text)


def events_of(net, sleeping: bool, seed: int = 0) -> list[tuple]:
    scheduler = Scheduler(net, seed=seed, registry=registry(sleeping), config={"dt": 0.1})
    events: list[tuple] = []
    scheduler.on_event(lambda e: events.append((e.seq, e.kind, e.time, e.transition, repr(e.data))))
    result = scheduler.run(until=30)
    return events + [(result.reason, result.time, result.firings)]


writer = st.tuples(st.sampled_from(["demo.bump", "demo.bump_every"]), st.sampled_from([0.0, 0.1, 0.2, 0.45]),
                   st.sampled_from(["a", "b"]), st.sampled_from([0.1, 0.2, 0.35]), st.integers(1, 3))
waiter = st.tuples(st.sampled_from(["demo.wait", "demo.until"]), st.sampled_from([0.0, 0.1, 0.3]),
                   st.sampled_from(["a", "b", "*"]), st.integers(1, 4))


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(writer, min_size=1, max_size=4), st.lists(waiter, min_size=1, max_size=4), st.integers(0, 3))
def test_a_sleeping_wait_ends_where_a_polled_wait_would(writers, waiters, seed):
    """Changes made while an instant's firings start and while other actions are polled
    (earlier and later firings), waits on one key or on any change: the same events at
    the same times as with waits that look at the state every tick."""
    made = {"a": 0, "b": 0}
    for action, _, key, _, times in writers:
        made[key] += 1 if action == "demo.bump" else times
    # every wait is met in the end: a polled wait that never is would step on to the time limit
    waiters = [(action, delay, key, min(count, made["a"] + made["b"] if key == "*" else made[key]) or 1)
               for action, delay, key, count in waiters if key == "*" or made[key]]
    net = counting_net(writers, waiters)
    polled = events_of(net, sleeping=False, seed=seed)
    assert events_of(net, sleeping=True, seed=seed) == polled
    assert polled[-1][0] in (StopReason.DEAD, StopReason.FINAL) and polled[-1][1] < 30


class Polls(Action):
    """A sleeping wait that counts its polls."""

    needs_world = False
    params = {"key": Param(str, "a"), "count": Param(int, 2), "within": Param((float, type(None)), None)}
    polls = 0

    def start(self, ctx):
        self.wake_on = (self.params["key"],)
        if self.params["within"] is not None:
            self.wake_at = ctx.now + self.params["within"]

    def poll(self, ctx):
        type(self).polls += 1
        if _reached(ctx) or ctx.now >= (self.wake_at or 1e9) - 1e-9:
            ctx.result = {"at": round(ctx.now, 6), "n": dict(ctx.state.n)}
            return Status.OK
        return Status.RUNNING


def sleeper_net(key: str, within: float | None = None, agent: bool = True, timeout: str = "") -> tuple:
    made = registry(sleeping=True)
    Polls.polls = 0
    made.register("demo.polls", Polls)
    params = f"{{key: '{key}', count: 2{'' if within is None else f', within: {within}'}}}"
    body = [
        "places: [{id: go, tokens: 1}, s0, s1, s2, d0, d1, e0, e1, e2]",
        "transitions:",
        "  - {id: begin, action: demo.begin, in: [go], out: [s0, s1, s2]}",
        "  - {id: late, action: core.wait, params: {seconds: 5}, in: [s0], out: [d0]}",
        "  - {id: tick, action: demo.bump_every, params: {key: a, period: 2.0, times: 2}, in: [d0], out: [e0]}",
        "  - {id: other, action: demo.bump_every, params: {key: b, period: 0.5, times: 6}, in: [s1], out: [e1]}",
        f"  - {{id: sleep, action: demo.polls, params: {params}, in: [s2], out: [e2]{timeout}}}",
    ]
    if agent:
        text = "\n".join(["petriflow: 1", "subnets:", "  - id: r", "    state: demo.counts",
                          *(f"    {line}" for line in body)])
    else:
        text = "\n".join(["petriflow: 1", *body]).replace("demo.begin", "core.noop")
    return loads_net(text), made


def ended(net, made) -> dict:
    events = []
    scheduler = Scheduler(net, registry=made, config={"dt": 0.1})
    scheduler.on_event(events.append, ["end"])
    result = scheduler.run(until=60)
    return {"result": result, "sleep": next(e.data for e in events if e.transition == "sleep")}


def test_an_action_asleep_on_a_key_is_polled_only_when_that_key_changes():
    """Six changes of another key and the passing ticks wake nothing: the wait on ``a``
    is polled twice, once per change of ``a`` (at 7 s and 9 s, by a firing polled
    after it, so at the next tick), never in between."""
    net, made = sleeper_net("a")
    done = ended(net, made)
    assert done["sleep"]["outcome"] == "ok" and done["sleep"]["result"] == {"at": 9.1, "n": {"a": 2, "b": 6}}
    assert Polls.polls == 2


def test_a_sleep_with_a_time_limit_ends_at_the_limit_when_nothing_changes():
    """``wake_at`` with ``wake_on``: the time comes first, and the action is polled then."""
    net, made = sleeper_net("a", within=1.5)
    done = ended(net, made)
    assert done["sleep"]["result"]["at"] == 1.5 and done["sleep"]["result"]["n"]["a"] == 0
    assert Polls.polls == 1


def test_a_sleep_on_any_change_wakes_at_a_change_of_any_key():
    """On ``"*"``: what its agent does wakes it too (``other`` starting after it in the
    first instant), then each change of b, the second of which ends the wait."""
    net, made = sleeper_net("*")
    done = ended(net, made)
    assert done["sleep"]["result"]["n"] == {"a": 0, "b": 2} and Polls.polls == 3


def test_a_sleep_without_an_agent_fails_its_firing_with_the_reason():
    net, made = sleeper_net("a", agent=False)
    made.register("demo.bump_every", type("Quiet", (InstantAction,), {"params": BumpEvery.params,
                                                                     "run": lambda self, ctx: None}), replace=True)
    done = ended(net, made)
    assert done["result"].reason == StopReason.FAILED
    assert "waits on its agent's state (a)" in done["result"].error and "in no agent subnet" in done["result"].error


def test_a_run_with_nothing_left_but_a_sleeper_ends_dead():
    """Nothing can change the state any more: the run is over (a polled wait would step
    on to the time limit)."""
    net, made = sleeper_net("a")
    made.register("demo.bump_every", type("Quiet", (InstantAction,), {"params": BumpEvery.params,
                                                                     "run": lambda self, ctx: None}), replace=True)
    scheduler = Scheduler(net, registry=made, config={"dt": 0.1})
    result = scheduler.run(until=60)
    assert result.reason == StopReason.DEAD and result.time == 5.0 and scheduler.running() == ["sleep"]


def test_a_timeout_ends_a_sleeping_action():
    """The transition's timeout cancels a sleeper as it cancels any running action."""
    net, made = sleeper_net("a", timeout=", timeout: 2, outcomes: {timeout: [e2]}")
    done = ended(net, made)
    assert done["sleep"]["outcome"] == "timeout" and Polls.polls == 0


def test_state_change_takes_keys_and_a_time():
    assert StateChange().keys == ("*",) and StateChange("a", "b").keys == ("a", "b")
    with pytest.raises(Exception, match="within is a number of seconds"):
        StateChange("a", within=-1)


def test_a_generator_yielding_anything_else_fails_with_the_reason():
    made = registry(sleeping=True)

    @made.action("demo.odd")
    def odd(ctx):
        yield "soon"

    net = loads_net("""
petriflow: 1
places: [{id: i, tokens: 1}, o]
transitions: [{id: t, action: demo.odd, in: [i], out: [o]}]
""")
    result = Scheduler(net, registry=made).run()
    assert result.reason == StopReason.FAILED and "yield nothing, a number of seconds or a StateChange" in result.error


# Two edges: a sleep on RUNNING wakes when a teammate stops, and a firing's left-over
# wake-up never polls a later firing of its transition out of firing order.

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


def watch_events(text: str, sleeping: bool, config: dict | None = None, seed: int = 0) -> list[tuple]:
    made = registry(sleeping)
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
    assert watch_events(LOOPS, sleeping=True, seed=seed) == watch_events(LOOPS, sleeping=False, seed=seed)


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
    sleeping = watch_events(TEAM, sleeping=True, config=config)
    assert sleeping == watch_events(TEAM, sleeping=False, config=config)
    ended = [e for e in sleeping if e[1] == "end" and e[3] == "watch"]
    assert ended and ended[0][2] < 5.0
