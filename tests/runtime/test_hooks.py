"""Every lifecycle hook fails safely: an exception is a failed outcome the net routes,
never a lost token; setup runs for every bound action before the first firing."""

import pytest

from petriflow.io.yaml import loads_net
from petriflow.outcome import StopReason
from petriflow.runtime.action import Action, ActionFailure, Status
from petriflow.runtime.registry import Registry, default_registry
from petriflow.runtime.scheduler import Scheduler
from petriflow.testing import ScriptedAction

ROUTED = """
petriflow: 1
places: [{id: a, tokens: 1}, done, broken, {id: alarm, tokens: 1}, s, cut]
transitions:
  - {id: work, action: test.hook, timeout: 1, in: [a], out: [done],
     outcomes: {failed: [broken], timeout: [cut], cancelled: [cut]}}
  - {id: ring, action: core.wait, params: {seconds: 0.5}, in: [alarm], out: [s]}
final: {broken: 1, s: 1}
"""


def hook_action(hook: str, exc: Exception):
    """An action that runs for a while (to be cancelled) and raises ``exc`` in ``hook``."""

    class Faulty(Action):
        needs_world = False

        def setup(self, world):
            if hook == "setup":
                raise exc

        def start(self, ctx):
            if hook == "start":
                raise exc
            self.wake_at = ctx.now + 5.0

        def poll(self, ctx):
            if hook == "poll":
                raise exc
            return Status.RUNNING

        def cancel(self, ctx):
            if hook == "cancel":
                raise exc
            return True

    return Faulty


def registry_with(cls):
    registry = Registry(load_plugins=False)
    registry.register("test.hook", cls)
    registry.register("core.wait", default_registry.resolve("core.wait"))
    return registry


@pytest.mark.parametrize("hook", ["setup", "start", "poll", "cancel"])
@pytest.mark.parametrize("exc", [ActionFailure("gripper jammed"), KeyError("gripper jammed")])
def test_an_exception_in_any_hook_is_a_routed_failure(hook, exc):
    """The firing ends 'failed' with the exception as reason; its failed arcs produce,
    and the run goes on to the final marking."""
    net = loads_net(ROUTED)
    if hook == "poll":  # poll first runs when wake_at comes: make it come before the timeout
        net = loads_net(ROUTED.replace("timeout: 1,", "timeout: 9,"))
    run = Scheduler(net, registry=registry_with(hook_action(hook, exc)), seed=1)
    events = []
    run.on_event(events.append)
    result = run.run()
    end = [e for e in events if e.kind == "end" and e.transition == "work"][0]
    assert end.data["outcome"] == "failed" and "gripper jammed" in end.data["reason"]
    if hook in ("setup", "cancel"):
        assert f"{hook}() failed" in end.data["reason"]
    assert result.reason == StopReason.FINAL and result.marking == {"broken": 1, "s": 1}


def test_setup_runs_for_every_bound_action_before_the_first_firing():
    """Transitions that never fire are set up too, once, when the run starts; every
    action is torn down at the end."""
    Walk = ScriptedAction.script([Status.OK])
    registry = Registry(load_plugins=False)
    registry.register("test.walk", Walk)
    net = loads_net("""
petriflow: 1
places: [{id: a, tokens: 1}, b, never]
transitions:
  - {id: go, action: test.walk, in: [a], out: [b]}
  - {id: idle, action: test.walk, in: [never], out: [b]}
""")
    run = Scheduler(net, registry=registry)
    run.on_event(lambda e: e.kind == "start" and calls.append(dict(Walk.calls)))
    calls = []
    run.run()
    assert calls[0]["setup"] == 2 and calls[0]["start"] == 0
    assert Walk.calls["teardown"] == 2 and Walk.calls["start"] == 1


def test_a_failing_setup_without_a_failure_route_stops_the_run_with_the_token_recorded():
    """No failed arcs: the run stops 'failed' naming the hook; the start and end are in
    the trace (the consumed token is accounted for, not silently lost)."""
    net = loads_net("""
petriflow: 1
places: [{id: a, tokens: 1}, b]
transitions: [{id: grab, action: test.hook, in: [a], out: [b]}]
""")
    run = Scheduler(net, registry=registry_with(hook_action("setup", RuntimeError("no arm"))))
    events = []
    run.on_event(events.append)
    result = run.run()
    assert result.reason == StopReason.FAILED
    assert "setup() failed: RuntimeError: no arm" in result.error
    assert [e.kind for e in events] == ["run", "start", "end", "stop"]


def test_a_failing_teardown_is_recorded_and_does_not_change_the_ending():
    class Sloppy(Action):
        needs_world = False

        def teardown(self):
            raise OSError("port busy")

    net = loads_net("""
petriflow: 1
places: [{id: a, tokens: 1}, b]
transitions: [{id: t, action: test.hook, in: [a], out: [b]}]
final: {b: 1}
""")
    run = Scheduler(net, registry=registry_with(Sloppy))
    events = []
    run.on_event(events.append)
    assert run.run().reason == StopReason.FINAL
    assert events[-1].data["teardown_errors"] == {"t": "teardown() failed: OSError: port busy"}


def test_poll_returning_something_else_than_a_status_fails():
    class Sloppy(Action):
        needs_world = False

        def poll(self, ctx):
            return True

    net = loads_net("""
petriflow: 1
places: [{id: a, tokens: 1}, b, bad]
transitions: [{id: t, action: test.hook, in: [a], out: [b], outcomes: {failed: [bad]}}]
""")
    result = Scheduler(net, registry=registry_with(Sloppy)).run()
    assert result.marking == {"bad": 1}


def test_a_guard_that_raises_is_a_clear_error():
    """A guard's bug names the transition and the guard."""
    from petriflow.errors import PetriflowError

    registry = Registry(load_plugins=False)
    registry.predicate("test.buggy")(lambda tokens, params: tokens["a"][0]["missing"])
    net = loads_net("""
petriflow: 1
places: [{id: a, tokens: 1}, b]
transitions: [{id: t, guard: test.buggy, in: [a], out: [b]}]
""")
    with pytest.raises(PetriflowError, match="transition 't': guard 'test.buggy' raised TypeError"):
        Scheduler(net, registry=registry).run()
