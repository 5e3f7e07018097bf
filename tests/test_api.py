"""The public API in one import: write an action, register it, run a net from Python."""

import pytest

from petriflow import (
    Action,
    ActionFailure,
    Net,
    Outcome,
    Param,
    Status,
    StopReason,
    action,
    run,
)
from petriflow.runtime.registry import Registry


def charging_net(action_name: str) -> Net:
    net = Net("charging")
    for place in ("empty", "full", "faulty"):
        net.add_place(place, tokens=1 if place == "empty" else 0)
    net.add_transition("charge", action=action_name, params={"minutes": 2})
    net.add_arc("empty", "charge")
    net.add_arc("charge", "full")
    net.add_arc("charge", "faulty", outcome="failed")
    return net


def test_a_generator_function_registered_with_action_runs_from_python():
    registry = Registry(load_plugins=False)

    @action("demo.charge", params={"minutes": Param(float, 5.0)}, registry=registry)
    def charge(ctx):
        yield ctx.params["minutes"] * 60
        return {"battery": 1.0}

    outcome = run(charging_net("demo.charge"), registry=registry, keep_events=True)
    assert outcome.result.reason == StopReason.DEAD and outcome.result.time == 120.0
    assert outcome.result.tokens == {"full": [{"battery": 1.0}]}
    assert [e.kind for e in outcome.events] == ["run", "start", "end", "stop"]


def test_an_action_class_raising_action_failure_is_routed():
    registry = Registry(load_plugins=False)

    @action("demo.charge", registry=registry)
    class Charge(Action):
        params = {"minutes": Param(float, 5.0)}
        needs_world = False

        def start(self, ctx):
            raise ActionFailure("charger fault")

        def poll(self, ctx):
            return Status.OK

    outcome = run(charging_net("demo.charge"), registry=registry, keep_events=True)
    end = outcome.events[2]
    assert (end.data["outcome"], end.data["reason"]) == (Outcome.FAILED, "charger fault")
    assert outcome.result.marking == {"faulty": 1}


def test_an_action_class_declares_its_own_params():
    registry = Registry(load_plugins=False)
    with pytest.raises(Exception, match="declares its own params"):
        action("demo.x", params={"a": Param(int, 1)}, registry=registry)(type("X", (Action,), {}))
