"""An agent whose action computes for a long time inside ``start`` stays alive to the run:
its heartbeats come from a thread of their own (over a real broker or router on loopback)."""

import json
import time

import pytest

from petriflow import Action, Param, Status
from petriflow.runtime.registry import Registry
from petriflow.runtime.session import run_files

from tests.bridge.test_bridged_run import write

pytestmark = pytest.mark.slow

HEARTBEAT, HEARTBEAT_TIMEOUT = 0.1, 1.0
#: Longer than the computation a cancel waits for here (a cancel not acknowledged within it
#: gives the goal up: tests/bridge/test_cancel_deadline.py).
CANCEL_TIMEOUT = 10.0

BUSY = """\
petriflow: 1
net: busy
subnets:
  - id: r1
    agent: r1
    places: [{id: a, tokens: 1}]
    transitions:
      - {id: plan, action: demo.compute, params: {seconds: SECONDS}, in: [a], out: [b]TIMEOUT,
         outcomes: {failed: [broken], timeout: [late]}}
places: [b, broken, late]
final: {b: 1}
"""


class Compute(Action):
    """Computes (the CPU busy, in Python: no sleep, no I/O) for ``seconds`` inside ``start``,
    as a planner does; ends ok at its first poll (``hold``: never, only a cancel ends it).
    Records when its ``cancel`` was called."""

    params = {"seconds": Param(float, 1.0), "hold": Param(bool, False)}
    cancels: list[float] = []

    def start(self, ctx):
        until = time.monotonic() + self.params["seconds"]
        count = 0
        while time.monotonic() < until:
            count += 1
        ctx.result = {"count": count}

    def poll(self, ctx):
        return Status.RUNNING if self.params["hold"] else Status.OK

    def cancel(self, ctx):
        type(self).cancels.append(time.monotonic())
        return True


def busy_registry():
    registry = Registry()
    Compute.cancels = []
    registry.register("demo.compute", Compute)
    return registry


def net(seconds, timeout=None, hold=False):
    text = BUSY.replace("SECONDS", f"{seconds}, hold: {str(hold).lower()}")
    return text.replace("TIMEOUT", "" if timeout is None else f", timeout: {timeout}")


def run_busy(middleware, serve, folder, net_text, final):
    """Serve the busy action on an agent, run ``net_text`` on it to its ``final`` marking
    with the agent never lost; ``(agent, result, {what: the plan firing's event})``."""
    kind, server = middleware
    agent = serve(kind, server.connect, ["robot1"], heartbeat=HEARTBEAT, registry=busy_registry())
    path = write(folder, kind, server.connect, net=net_text, heartbeat=HEARTBEAT,
                 heartbeat_timeout=HEARTBEAT_TIMEOUT, cancel_timeout=CANCEL_TIMEOUT)
    result = run_files(path, trace=folder / "t.jsonl")
    events = [json.loads(line) for line in (folder / "t.jsonl").read_text().splitlines()]
    assert not [e for e in events if e["kind"] == "fault"], "the busy agent was declared lost"
    assert result.reason == "final" and result.marking.to_dict() == final
    found = {"end": next(e["data"] for e in events if e["kind"] == "end" and e["transition"] == "plan"),
             "remote": next(e["data"]["data"] for e in events
                            if e["kind"] == "custom" and e["data"]["name"] == "remote")}
    return agent, result, found


def test_an_action_computing_for_three_heartbeat_timeouts_in_start_is_not_lost(middleware, serve, tmp_path):
    """The action blocks its agent's action thread for 3 x heartbeat_timeout inside ``start``:
    the agent is never declared lost, and the firing ends ok with the action's data."""
    agent, result, found = run_busy(middleware, serve, tmp_path, net(3 * HEARTBEAT_TIMEOUT), {"b": 1})
    assert found["end"]["outcome"] == "ok"
    assert found["remote"]["round_trip_ms"] >= 3000 * HEARTBEAT_TIMEOUT
    assert result.tokens["b"][0]["count"] > 0
    assert agent.server.executed == 1


def test_a_timeout_during_the_computation_cancels_the_goal_once_start_returns(middleware, serve, tmp_path):
    """The transition's timeout (1 s) runs out while the action computes (3 s, then runs until
    cancelled): the run's cancel waits on the agent until ``start`` returns, then the action's
    ``cancel`` runs and is acknowledged; the firing ends ``timeout`` (its route fires), the
    agent never lost."""
    started = time.monotonic()
    text = net(3 * HEARTBEAT_TIMEOUT, timeout=1, hold=True).replace("final: {b: 1}", "final: {late: 1}")
    _, result, found = run_busy(middleware, serve, tmp_path, text, {"late": 1})
    assert found["end"]["outcome"] == "timeout"
    assert len(Compute.cancels) == 1 and Compute.cancels[0] - started >= 3 * HEARTBEAT_TIMEOUT
    assert found["remote"]["phase"] == "cancelled"
    assert result.metrics["bridge.dropped"] == 0  # each cancel sent again is answered: none a replay
