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
    return BUSY.replace("SECONDS", f"{seconds}, hold: {str(hold).lower()}").replace("TIMEOUT", "" if timeout is None else f", timeout: {timeout}")


def events_of(folder):
    return [json.loads(line) for line in (folder / "t.jsonl").read_text().splitlines()]


def test_an_action_computing_for_three_heartbeat_timeouts_in_start_is_not_lost(middleware, serve, tmp_path):
    """The action blocks its agent's action thread for 3 x heartbeat_timeout inside ``start``:
    the agent is never declared lost, and the firing ends ok with the action's data."""
    kind, server = middleware
    agent = serve(kind, server.connect, ["robot1"], heartbeat=HEARTBEAT, registry=busy_registry())
    path = write(tmp_path, kind, server.connect, net=net(3 * HEARTBEAT_TIMEOUT), heartbeat=HEARTBEAT,
                 heartbeat_timeout=HEARTBEAT_TIMEOUT)
    result = run_files(path, trace=tmp_path / "t.jsonl")
    events = events_of(tmp_path)
    assert not [e for e in events if e["kind"] == "fault"], "the busy agent was declared lost"
    assert result.reason == "final" and result.marking.to_dict() == {"b": 1}
    end = next(e for e in events if e["kind"] == "end" and e["transition"] == "plan")
    assert end["data"]["outcome"] == "ok"
    remote = next(e for e in events if e["kind"] == "custom" and e["data"]["name"] == "remote")
    assert remote["data"]["data"]["round_trip_ms"] >= 3000 * HEARTBEAT_TIMEOUT
    assert result.tokens["b"][0]["count"] > 0
    assert agent.server.executed == 1


def test_a_timeout_during_the_computation_cancels_the_goal_once_start_returns(middleware, serve, tmp_path):
    """The transition's timeout (1 s) runs out while the action computes (3 s, then runs until
    cancelled): the run's cancel waits on the agent until ``start`` returns, then the action's
    ``cancel`` runs and is acknowledged; the firing ends ``timeout`` (its route fires), the
    agent never lost."""
    kind, server = middleware
    serve(kind, server.connect, ["robot1"], heartbeat=HEARTBEAT, registry=busy_registry())
    path = write(tmp_path, kind, server.connect, net=net(3 * HEARTBEAT_TIMEOUT, timeout=1, hold=True).replace(
        "final: {b: 1}", "final: {late: 1}"), heartbeat=HEARTBEAT, heartbeat_timeout=HEARTBEAT_TIMEOUT)
    started = time.monotonic()
    result = run_files(path, trace=tmp_path / "t.jsonl")
    events = events_of(tmp_path)
    assert not [e for e in events if e["kind"] == "fault"], "the busy agent was declared lost"
    assert result.reason == "final" and result.marking.to_dict() == {"late": 1}
    end = next(e for e in events if e["kind"] == "end" and e["transition"] == "plan")
    assert end["data"]["outcome"] == "timeout"
    assert len(Compute.cancels) == 1 and Compute.cancels[0] - started >= 3 * HEARTBEAT_TIMEOUT
    remote = next(e for e in events if e["kind"] == "custom" and e["data"]["name"] == "remote")
    assert remote["data"]["data"]["phase"] == "cancelled"
    assert result.metrics["bridge.dropped"] == 0  # each cancel sent again is answered: none a replay
