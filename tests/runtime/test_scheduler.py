"""The scheduler: actions over simulated time, outcomes, conflicts, limits."""

import pytest

from petriflow.errors import NetFormatError, NotEnabledError
from petriflow.io.yaml import loads_net
from petriflow.runtime.action import Status
from petriflow.runtime.registry import Registry, default_registry
from petriflow.runtime.scheduler import Scheduler, ZenoError
from petriflow.testing import ScriptedAction


def net_of(text):
    return loads_net("petriflow: 1\n" + text)


def events_of(scheduler):
    events = []
    scheduler.on_event(events.append)
    return events


def test_action_lasts_simulated_time_and_produces_on_completion():
    """Outputs appear when the action ends, not when the transition fires."""
    net = net_of("""
places: [{id: a, tokens: 1}, b]
transitions: [{id: t, action: core.wait, params: {seconds: 2.5}, in: [a], out: [b]}]
""")
    run = Scheduler(net)
    events = events_of(run)
    result = run.run()
    start, end = [e for e in events if e.kind in ("start", "end")]
    assert (start.time, end.time) == (0.0, 2.5)
    assert result.marking == {"b": 1} and result.reason == "final"  # a WF-net ends at its sink b


def test_concurrent_actions_of_two_agents_overlap_in_time():
    """Two agents' actions run at the same time."""
    net = net_of("""
subnets:
  - {id: r1, places: [{id: a1, tokens: 1}, b1], transitions: [{id: t1, action: core.wait, params: {seconds: 3}, in: [a1], out: [b1]}]}
  - {id: r2, places: [{id: a2, tokens: 1}, b2], transitions: [{id: t2, action: core.wait, params: {seconds: 2}, in: [a2], out: [b2]}]}
final: {b1: 1, b2: 1}
""")
    result = Scheduler(net).run()
    assert (result.reason, result.time) == ("final", 3.0)


def test_failure_is_routed_by_outcome_arcs():
    """A failed action produces on its 'failed' arcs only."""
    net = net_of("""
places: [{id: a, tokens: 1}, done, retry]
transitions:
  - {id: t, action: core.fail, params: {seconds: 1}, in: [a], out: [done], outcomes: {failed: [retry]}}
""")
    result = Scheduler(net).run()
    assert result.marking == {"retry": 1}


def test_unrouted_failure_stops_the_run_naming_transition_and_action():
    """With no failure route, the run stops with the failure recorded."""
    net = net_of("""
places: [{id: a, tokens: 1}, b]
transitions: [{id: grab, action: core.fail, params: {reason: gripper jammed}, in: [a], out: [b]}]
""")
    run = Scheduler(net)
    events = events_of(run)
    result = run.run()
    assert result.reason == "failed"
    assert "transition 'grab': action 'core.fail' failed: gripper jammed" in result.error
    assert events[-2].kind == "end" and events[-2].data["outcome"] == "failed"


def test_timeout_routes_to_timeout_arcs_and_cancels_action():
    """An action running past the transition's timeout ends with outcome timeout."""
    Walk = ScriptedAction.script([Status.RUNNING])
    registry = Registry(load_plugins=False)
    registry.register("test.walk", Walk)
    net = net_of("""
places: [{id: a, tokens: 1}, there, gave_up]
transitions:
  - {id: walk, action: test.walk, timeout: 1.5, in: [a], out: [there], outcomes: {timeout: [gave_up]}}
""")
    run = Scheduler(net, registry=registry)
    result = run.run()
    assert result.marking == {"gave_up": 1} and result.time == 1.5
    assert Walk.calls["cancel"] == 1


def test_timeout_falls_back_to_failure_route():
    """A timeout with only failure arcs takes the failure route."""
    Walk = ScriptedAction.script([Status.RUNNING])
    registry = Registry(load_plugins=False)
    registry.register("test.walk", Walk)
    net = net_of("""
places: [{id: a, tokens: 1}, there, failed]
transitions:
  - {id: walk, action: test.walk, timeout: 1, in: [a], out: [there], outcomes: {failed: [failed]}}
""")
    assert Scheduler(net, registry=registry).run().marking == {"failed": 1}


def test_cancellation_region_withdraws_tokens_and_cancels_running_actions():
    """Firing a cancelling transition empties its region and stops its actions."""
    Walk = ScriptedAction.script([Status.RUNNING])
    registry = Registry(load_plugins=False)
    registry.register("test.walk", Walk)
    registry.register("test.alarm", ScriptedAction.script([Status.RUNNING] * 100 + [Status.OK]))
    net = net_of("""
places: [{id: a, tokens: 1}, s, {id: junk, tokens: 3}, walked, stopped, {id: watch, tokens: 1}]
transitions:
  - {id: walk, action: test.walk, in: [a], out: [walked], outcomes: {cancelled: [stopped]}}
  - {id: abort, action: test.alarm, in: [watch], out: [s]}
  - {id: emergency, in: [s], cancels: [walk, junk], out: []}
""")
    run = Scheduler(net, registry=registry)
    events = events_of(run)
    result = run.run(until=5)
    cancel = [e for e in events if e.kind == "cancel"][0]
    assert cancel.data == {"firing": 3, "withdrawn": {"junk": 3}, "actions": ["walk"]}
    assert "junk" not in result.marking and result.marking["stopped"] == 1


def test_priority_wins_conflicts():
    """Of two enabled transitions sharing a token, the higher priority fires."""
    net = net_of("""
places: [{id: p, tokens: 1}, low_out, high_out]
transitions:
  - {id: low, in: [p], out: [low_out]}
  - {id: high, priority: 5, in: [p], out: [high_out]}
""")
    for seed in range(5):
        assert Scheduler(net, seed=seed).run().marking == {"high_out": 1}


def test_random_conflict_choice_depends_on_seed_only():
    """Equal priorities are decided by the seed: same seed, same choice."""
    net = net_of("""
places: [{id: p, tokens: 1}, x, y]
transitions: [{id: tx, in: [p], out: [x]}, {id: ty, in: [p], out: [y]}]
""")
    outcomes = {seed: Scheduler(net, seed=seed).run().marking for seed in range(20)}
    assert outcomes == {seed: Scheduler(net, seed=seed).run().marking for seed in range(20)}
    assert {tuple(m) for m in outcomes.values()} == {("x",), ("y",)}


def test_same_seed_gives_identical_events():
    """Two runs of the same net and seed record the same events."""
    net = net_of("""
places: [{id: p, tokens: 3}, q]
transitions:
  - {id: work, action: core.fail, params: {seconds: 0.5, probability: 0.5}, in: [p], out: [q], outcomes: {failed: [p]}}
""")
    first, second = Scheduler(net, seed=4), Scheduler(net, seed=4)
    a, b = events_of(first), events_of(second)
    first.run(until=20)
    second.run(until=20)
    assert [e.to_json() for e in a] == [e.to_json() for e in b]


def test_token_data_flows_from_inputs_to_outputs():
    """An action's result becomes the data of its output tokens."""
    net = net_of("""
places: [{id: a, tokens: 1}, b, c]
transitions:
  - {id: make, action: core.set, params: {value: {pose: [1, 2]}}, in: [a], out: [b]}
  - {id: carry, action: core.wait, params: {seconds: 1}, in: [b], out: [c]}
""")
    assert Scheduler(net).run().tokens == {"c": [{"pose": [1, 2]}]}


def test_guard_reads_token_data_through_a_registered_predicate():
    """A guard is a registered predicate over the tokens a firing would take."""
    registry = Registry(load_plugins=False)
    registry.predicate("test.positive")(lambda tokens, params: tokens["n"][0] > 0)
    registry.register("core.noop", default_registry.resolve("core.noop"))
    net = net_of("""
places: [n, out]
transitions: [{id: use, guard: test.positive, in: [n], out: [out]}]
""")
    for value, fires in ((3, True), (-1, False)):
        run = Scheduler(net, registry=registry)
        run.set_tokens({"n": [value]})
        assert (run.run().marking == {"out": 1}) is fires


def test_unknown_action_fails_at_load_with_close_match():
    """Binding names the transition and suggests the action meant."""
    net = net_of("""
places: [a]
transitions: [{id: t, action: core.wiat, in: [a]}]
""")
    with pytest.raises(NetFormatError, match=r"'t': unknown action 'core.wiat' \(did you mean 'core.wait'"):
        Scheduler(net)


def test_misspelt_action_parameter_fails_at_load():
    """Parameters are checked against the action's declaration."""
    net = net_of("""
places: [a]
transitions: [{id: t, action: core.wait, params: {second: 2}, in: [a]}]
""")
    with pytest.raises(NetFormatError, match="no parameter 'second'.*did you mean 'seconds'"):
        Scheduler(net)


def test_unknown_guard_fails_at_load():
    """A guard name must be registered."""
    net = net_of("places: [a]\ntransitions: [{id: t, guard: nope, in: [a]}]\n")
    with pytest.raises(NetFormatError, match="unknown guard 'nope'"):
        Scheduler(net)


def test_endless_instant_cycle_is_reported():
    """A cycle of instant transitions that never lets time pass is an error."""
    net = net_of("places: [{id: p, tokens: 1}]\ntransitions: [{id: spin, in: [p], out: [p]}]\n")
    with pytest.raises(ZenoError):
        Scheduler(net).run()


def test_until_stops_at_the_time_limit():
    """--until stops the run at that simulated time, actions still running."""
    net = net_of("""
places: [{id: a, tokens: 1}, b]
transitions: [{id: t, action: core.wait, params: {seconds: 10}, in: [a], out: [b]}]
""")
    result = Scheduler(net).run(until=4)
    assert (result.reason, result.time, result.marking) == ("until", 4.0, {})


def test_fire_one_refuses_a_disabled_transition():
    """Firing a transition that is not enabled names the short place."""
    net = net_of("places: [a, b]\ntransitions: [{id: t, in: [a], out: [b]}]\n")
    with pytest.raises(NotEnabledError, match="a has 0, needs 1"):
        Scheduler(net).fire_one("t")


def test_cancellation_clean_up_may_take_several_ticks():
    """An action whose cancel() needs three ticks ends 'cancelled' only when it is done."""
    from petriflow.runtime.action import Action

    class SlowStop(Action):
        needs_world = False

        def start(self, ctx):
            self.left = 3

        def poll(self, ctx):
            return Status.RUNNING

        def cancel(self, ctx):
            self.left -= 1
            return self.left == 0

    registry = Registry(load_plugins=False)
    registry.register("test.slowstop", SlowStop)
    registry.register("core.wait", default_registry.resolve("core.wait"))
    net = net_of("""
places: [{id: a, tokens: 1}, {id: alarm, tokens: 1}, b, stopped, s]
transitions:
  - {id: work, action: test.slowstop, in: [a], out: [b], outcomes: {cancelled: [stopped]}}
  - {id: ring, action: core.wait, params: {seconds: 1}, in: [alarm], out: [s]}
  - {id: abort, in: [s], cancels: [work]}
""")
    run = Scheduler(net, registry=registry)
    events = events_of(run)
    result = run.run(until=5)
    end = [e for e in events if e.kind == "end" and e.transition == "work"][0]
    assert end.data["outcome"] == "cancelled"
    assert end.time == pytest.approx(1.02)  # abort at 1.0 s, then two more ticks of clean-up
    assert result.marking == {"stopped": 1}


def test_step_and_peek_walk_the_run_one_instant_at_a_time():
    """peek() says when the next instant is; step() processes it; EmptySchedule at the end."""
    from petriflow.runtime.scheduler import EmptySchedule

    net = net_of("""
places: [{id: a, tokens: 1}, b, c]
transitions:
  - {id: first, action: core.wait, params: {seconds: 1.5}, in: [a], out: [b]}
  - {id: second, action: core.wait, params: {seconds: 2}, in: [b], out: [c]}
""")
    run = Scheduler(net)
    seen = []
    while run.peek() is not None:
        seen.append(run.peek())
        run.step()
        seen.append(run.running())
    assert seen == [0.0, ["first"], 1.5, ["second"], 3.5, []]
    assert run.marking() == {"c": 1}
    with pytest.raises(EmptySchedule):
        run.step()


def test_an_action_waking_later_is_first_polled_when_it_asked():
    """needs_world False and wake_at set in start(): no poll before that time."""
    from petriflow.runtime.action import Action

    polls = []

    class Later(Action):
        needs_world = False

        def start(self, ctx):
            self.wake_at = ctx.now + 2.0

        def poll(self, ctx):
            polls.append(ctx.now)
            return Status.OK

    registry = Registry(load_plugins=False)
    registry.register("test.later", Later)
    net = net_of("places: [{id: a, tokens: 1}, b]\ntransitions: [{id: t, action: test.later, in: [a], out: [b]}]\n")
    assert Scheduler(net, registry=registry).run().time == 2.0
    assert polls == [2.0]


def test_staggered_and_lockstep_agents_fire_the_same_firings():
    """Independent agents: whether their waits line up or not, each fires its cycle."""
    lines = ["subnets:"]
    for k, seconds in enumerate((1.0, 1.0, 1.37, 1.91)):
        lines.append(f"  - {{id: r{k}, places: [{{id: r{k}a, tokens: 1}}, r{k}b], transitions: ["
                     f"{{id: r{k}go, action: core.wait, params: {{seconds: {seconds}}}, in: [r{k}a], out: [r{k}b]}},"
                     f"{{id: r{k}back, action: core.wait, params: {{seconds: {seconds}}}, in: [r{k}b], out: [r{k}a]}}]}}")
    run = Scheduler(net_of("\n".join(lines) + "\n"))
    events = events_of(run)
    run.run(until=10)
    starts = [e.transition for e in events if e.kind == "start"]
    assert [starts.count(f"r{k}go") for k in range(4)] == [6, 6, 4, 3]   # at 0, 2, ... 10 s; 0, 2.74...; 0, 3.82...


def test_a_long_run_keeps_no_state_per_firing():
    """Without observers nothing per firing is kept: memory after 20,000 firings is
    what it was after 2,000 (within a small margin for Python's allocator)."""
    import gc
    import tracemalloc

    net = net_of("""
subnets:
  - {id: r, places: [{id: a, tokens: 1}, b], transitions: [
      {id: go, action: core.wait, params: {seconds: 0.5}, in: [a], out: [b]},
      {id: back, action: core.fail, params: {seconds: 0.5, probability: 0.3}, in: [b], out: [a], outcomes: {failed: [a]}}]}
""")
    run = Scheduler(net, seed=2)
    tracemalloc.start()
    try:
        run.run(max_firings=2_000)
        gc.collect()
        early = tracemalloc.get_traced_memory()[0]
        run.run(max_firings=20_000)
        gc.collect()
        late = tracemalloc.get_traced_memory()[0]
    finally:
        tracemalloc.stop()
    assert run.firings == 20_000
    assert late - early < 64_000   # the old kernel kept ~1.2 kB per firing: 21 MB here


def test_a_run_stopped_by_a_limit_goes_on_with_the_same_events():
    """run(until=...) then run() again: the same events as one run, and the actions are
    torn down only once the run is over."""
    Walk = ScriptedAction.script([Status.RUNNING] * 30 + [Status.OK])
    registry = Registry(load_plugins=False)
    registry.register("test.walk", Walk)
    registry.register("core.wait", default_registry.resolve("core.wait"))
    text = """
places: [{id: a, tokens: 3}, b, c]
transitions:
  - {id: walk, action: test.walk, in: [a], out: [b]}
  - {id: rest, action: core.wait, params: {seconds: 0.25}, in: [b], out: [c]}
"""
    whole = Scheduler(net_of(text), registry=registry, seed=2)
    expected = events_of(whole)
    whole.run()
    parts = Scheduler(net_of(text), registry=registry, seed=2)
    got = events_of(parts)
    assert parts.run(until=0.4).reason == "until" and Walk.calls["teardown"] == 1
    assert parts.run(max_firings=4).reason == "firings"
    assert parts.run().reason == "dead" and Walk.calls["teardown"] == 2
    def story(events):  # the stops of the partial runs take sequence numbers of their own
        return [(e.kind, e.transition, e.time, e.data) for e in events if e.kind != "stop"]

    assert story(got) == story(expected)
