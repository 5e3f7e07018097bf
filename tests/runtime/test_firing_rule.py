"""The runtime fires by the engine's rule: random nets with core actions (waits,
failures, outcome routes, timeouts, cancellation regions) run through the scheduler,
and every firing is checked against petriflow.engine at the moment it happens."""

from __future__ import annotations

from collections import Counter

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from petriflow.engine import consume, fire, is_enabled, produce
from petriflow.marking import Marking
from petriflow.net import Net
from petriflow.outcome import Outcome, StopReason
from petriflow.runtime.builtin import Wait
from petriflow.runtime.registry import Registry
from petriflow.runtime.scheduler import Scheduler

PLACES = [f"p{k}" for k in range(6)]


@st.composite
def timed_nets(draw: st.DrawFn, cancellation: bool = True) -> Net:
    """1-6 places, 1-5 transitions bound to core.wait / core.fail / nothing, with
    failure and timeout routes, timeouts, and (optionally) cancellation regions."""
    places = PLACES[: draw(st.integers(1, len(PLACES)))]
    net = Net("random")
    for place in places:
        net.add_place(place, tokens=draw(st.integers(0, 2)))
    names = [f"t{k}" for k in range(draw(st.integers(1, 5)))]
    for name in names:
        kind = draw(st.sampled_from(["none", "wait", "wait", "fail"]))
        seconds = draw(st.sampled_from([0.0, 0.01, 0.25, 1.0, 2.5]))
        attributes: dict = {}
        if kind == "wait":
            attributes = {"action": "core.wait", "params": {"seconds": seconds}}
        elif kind == "fail":
            attributes = {"action": "core.fail", "params": {"seconds": seconds, "probability": 0.5}}
        if kind != "none" and draw(st.booleans()):
            attributes["timeout"] = draw(st.sampled_from([0.5, 1.5]))
        attributes["priority"] = draw(st.integers(0, 1))
        net.add_transition(name, **attributes)
        for place, weight in draw(st.dictionaries(st.sampled_from(places), st.integers(1, 2),
                                                  min_size=1, max_size=2)).items():
            net.add_arc(place, name, weight)
        for place, weight in draw(st.dictionaries(st.sampled_from(places), st.integers(1, 2),
                                                  max_size=2)).items():
            net.add_arc(name, place, weight)
        for outcome in ("failed", "timeout", "cancelled"):
            if draw(st.booleans()):
                net.add_arc(name, draw(st.sampled_from(places)), 1, outcome=outcome)
    if cancellation:
        for name in names:
            if draw(st.integers(0, 3)) == 0:
                region = draw(st.lists(st.sampled_from(places + names), min_size=1, max_size=3, unique=True))
                net.transitions[name] = type(net.transitions[name])(
                    **{**vars(net.transitions[name]), "cancels": tuple(region)})
    return net


class EngineWitness:
    """An observer that replays each start and end through the engine's readable rule
    and checks the scheduler's live marking against it, and that tokens are
    conserved: initial + produced - consumed - withdrawn = what the places hold."""

    def __init__(self, net: Net, scheduler: Scheduler) -> None:
        self.net = net
        self.scheduler = scheduler
        self.marking = net.initial_marking
        self.before: dict[int, Marking] = {}
        self.totals = Counter()
        self.running: set[int] = set()
        self.ended: list[tuple[str, str]] = []

    def __call__(self, event) -> None:
        kind, data, t = event.kind, event.data, event.transition
        if kind == "start":
            assert is_enabled(self.net, self.marking, t), f"{t} fired while not enabled in {self.marking}"
            self.marking = consume(self.net, self.marking, t)
            self.totals["consumed"] += sum(data["consumed"].values())
            self.running.add(data["firing"])
        elif kind == "cancel":
            self.totals["withdrawn"] += sum(data["withdrawn"].values())
        elif kind == "end":
            outcome = data["outcome"]
            self.running.discard(data["firing"])
            if self.net.route(t, outcome) is not None:
                self.marking = produce(self.net, self.marking, t, outcome)
                assert data["produced"] == self.net.postset(t, self.net.route(t, outcome))
            else:
                assert outcome in (Outcome.FAILED, Outcome.TIMEOUT) and data["produced"] == {}
            self.totals["produced"] += sum(data["produced"].values())
            self.ended.append((t, outcome))
        else:
            return
        live = self.scheduler.marking()
        assert live == self.marking, f"after {kind} of {t}: runtime {live}, engine {self.marking}"
        if kind == "start" and self.net.transitions[t].cancels:
            return  # what the region withdrew is counted by the cancel event that follows
        held = sum(self.net.initial_marking.values()) + self.totals["produced"] - self.totals["consumed"] \
            - self.totals["withdrawn"]
        assert sum(live.values()) == held


def run_witnessed(net: Net, seed: int) -> tuple[EngineWitness, object]:
    scheduler = Scheduler(net, seed=seed)
    witness = EngineWitness(net, scheduler)
    scheduler.on_event(witness)
    stops = []
    scheduler.on_event(lambda e: stops.append(e) if e.kind == "stop" else None)
    result = scheduler.run(until=8, max_firings=300)
    assert set(stops[0].data["running"]) == {t for t in scheduler.running()}
    assert len(witness.running) == len(scheduler.running())
    return witness, result


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(timed_nets(), st.integers(0, 3))
def test_every_firing_follows_the_engines_rule(net, seed):
    """At each start the transition is enabled for the engine and the runtime's marking
    is the engine's consume(); at each end it is the engine's produce() of the
    outcome's route; tokens are conserved at every event."""
    try:
        run_witnessed(net, seed)
    except Exception as exc:  # a cycle of instant transitions is reported, not a rule break
        assert type(exc).__name__ == "ZenoError", exc


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(timed_nets(cancellation=False), st.integers(0, 3))
def test_completed_firings_in_completion_order_are_a_firing_sequence(net, seed):
    """Without cancellation regions, the firings that completed, in the order they
    completed (the XES log's order), fire one after another in the engine from the
    initial marking, each with its outcome."""
    try:
        witness, result = run_witnessed(net, seed)
    except Exception as exc:
        assert type(exc).__name__ == "ZenoError", exc
        return
    marking = net.initial_marking
    for transition, outcome in witness.ended:
        if outcome == Outcome.CANCELLED or net.route(transition, outcome) is None:
            continue
        marking = fire(net, marking, transition, outcome)
    if result.reason in (StopReason.DEAD, StopReason.FINAL):
        assert marking == result.marking


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(timed_nets(), st.integers(0, 3))
def test_nothing_enabled_is_left_unfired_at_the_end_of_an_instant(net, seed):
    """When an instant is over, no transition whose action is not running is enabled by
    the engine's rule in the marking: the enabled set missed no change of the tokens
    (weights of 1 and 2, tokens taken and given back by instant firings, regions)."""
    scheduler = Scheduler(net, seed=seed)
    missed = []

    def check(run):
        if run.firings >= 300:  # stopped by the firing limit in the middle of the instant
            return
        marking, running = run.marking(), set(run.running())
        missed.extend((run.now, t) for t in net.transitions if t not in running and is_enabled(net, marking, t))

    scheduler.on_instant(check)
    try:
        scheduler.run(until=8, max_firings=300)
    except Exception as exc:
        assert type(exc).__name__ == "ZenoError", exc
    assert not missed


class PolledWait(Wait):
    """core.wait as a plain polled action: its start and poll are called (a subclass
    that overrides them is never taken for a pure delay)."""

    def poll(self, ctx):
        return super().poll(ctx)


def trace_of(net: Net, seed: int, registry: Registry | None = None, dt: float = 0.01) -> list[tuple]:
    scheduler = Scheduler(net, seed=seed, registry=registry, config={"dt": dt})
    events = []
    scheduler.on_event(lambda e: events.append((e.kind, e.time, e.transition, repr(e.data))))
    try:
        result = scheduler.run(until=8, max_firings=300)
    except Exception as exc:  # a cycle of instant transitions
        return [type(exc).__name__]
    return events + [(result.reason, result.time, result.firings)]


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(timed_nets(), st.integers(0, 3), st.sampled_from([0.01, 0.1, 0.3]))
def test_a_wait_ended_without_polls_ends_as_a_polled_wait_would(net, seed, dt):
    """core.wait is a pure delay, whose end the runtime schedules without polling it:
    every run (timeouts, failures, cancellation regions cutting waits short) gives the
    same events, at the same times, as with a wait that is polled."""
    polled = Registry(load_plugins=False)
    polled.register("core.wait", PolledWait, replace=True)
    assert PolledWait({"seconds": 1.0}).delay() is None and Wait({"seconds": 1.0}).delay() == 1.0
    assert trace_of(net, seed, dt=dt) == trace_of(net, seed, polled, dt=dt)


def test_waits_of_awkward_lengths_end_where_their_polls_would():
    """Waits whose end falls a hair off a tick, and waits below a microsecond (polled),
    end at the same ticks both ways, passing their token's data on."""
    net = Net("awkward")
    net.add_place("a", tokens=1)
    net.add_place("data")
    net.add_transition("give", action="core.set", params={"value": {"x": 1}})
    net.add_arc("a", "give")
    net.add_arc("give", "data")
    previous = "data"
    for k, seconds in enumerate([0.1 + 0.2, 0.3 + 5e-11, 1e-7, 0.7, 1 / 3, 2e-6, 0.0]):
        net.add_place(f"p{k}")
        net.add_transition(f"w{k}", action="core.wait", params={"seconds": seconds})
        net.add_arc(previous, f"w{k}")
        net.add_arc(f"w{k}", f"p{k}")
        previous = f"p{k}"
    polled = Registry(load_plugins=False)
    polled.register("core.wait", PolledWait, replace=True)
    for dt in (0.1, 0.01, 1 / 3):
        fast = trace_of(net, 0, dt=dt)
        assert fast == trace_of(net, 0, polled, dt=dt)
        assert [kind for kind, *_ in fast[:-1]].count("end") == 8
        assert all("'x': 1" in data for kind, _, _, data in fast[:-1] if kind == "end")


def test_a_region_cuts_a_wait_short_as_it_cuts_a_polled_one():
    """A cancellation region ends a running wait at once with the cancelled outcome
    (its cancelled arc gets the token), as it ends a polled wait."""
    net = Net("cut")
    for place, tokens in [("a", 1), ("b", 1), ("c", 0), ("d", 0), ("e", 0)]:
        net.add_place(place, tokens=tokens)
    net.add_transition("long", action="core.wait", params={"seconds": 2.0})
    net.add_transition("cut", action="core.wait", params={"seconds": 1.0}, cancels=("long",))
    for source, target in [("a", "long"), ("long", "c"), ("b", "cut"), ("cut", "d")]:
        net.add_arc(source, target)
    net.add_arc("long", "e", outcome="cancelled")
    polled = Registry(load_plugins=False)
    polled.register("core.wait", PolledWait, replace=True)
    fast = trace_of(net, 0)
    assert fast == trace_of(net, 0, polled)
    assert ("end", 0.0, "long") in [event[:3] for event in fast[:-1] if "'cancelled'" in event[3]]
    assert fast[-1][0] == StopReason.DEAD and fast[-1][1] == 1.0
