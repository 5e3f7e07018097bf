"""Agent-held state: a bridged subnet's state lives on its agent, its guards are evaluated
there and cached by the run (petriflow/bridge/held.py). No network: an in-process hub
carries the messages between a real agent server (in a thread) and a real run."""

import json
import sys
import threading
import types

import pytest

from petriflow.bridge import protocol
from petriflow.bridge.agent import AgentServer, announcement
from petriflow.bridge.spec import DEFAULT_CONNECT
from petriflow.bridge.transport import TRANSPORTS
from petriflow.runtime.action import InstantAction
from petriflow.runtime.registry import Registry
from petriflow.runtime.session import run_files

from tests.bridge.held_actions import register
from tests.bridge.test_calls import Hub


def demo_registry():
    return register(Registry())


NET = """
petriflow: 1
net: held
final: {finished: 2}
subnets:
- id: counter
  agent: robot
  state: demo.counter
  places: [{id: start, tokens: 1}, work, {id: side, tokens: 1}, noted, {id: fresh, tokens: 1}, finished]
  transitions:
  - {id: before, guard: demo.none, params: {limit: 0}, in: [fresh], out: [noted]}
  - {id: make, action: demo.make, in: [start], out: [work]}
  - {id: slow, action: demo.slow, params: {seconds: 0.3, limit: 0}, guard: demo.reached, in: [work, side], out: [work],
     priority: 2}
  - {id: note, guard: demo.reached, params: {limit: 1}, in: [noted], out: [finished], priority: 3}
  - {id: bump, action: demo.bump, guard: demo.below, params: {limit: 3}, in: [work], out: [work]}
  - {id: done, guard: demo.reached, params: {limit: 3}, in: [work], out: [finished]}
"""


@pytest.fixture
def hub(monkeypatch):
    """A transport named ``hub``: one in-process hub for the run and the agent."""
    shared = Hub()
    module = types.ModuleType("petriflow_test_hub")
    module.connect = lambda endpoint, name="": shared
    monkeypatch.setitem(sys.modules, "petriflow_test_hub", module)
    monkeypatch.setitem(TRANSPORTS, "hub", "petriflow_test_hub")
    monkeypatch.setitem(DEFAULT_CONNECT, "hub", "tcp/127.0.0.1:1")
    return shared


@pytest.fixture
def agent(hub):
    server = AgentServer(["robot"], hub, registry=demo_registry(), heartbeat=0.05)
    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()
    yield server
    server.stop()
    thread.join(timeout=10)
    assert not thread.is_alive()


def starts(path):
    events = [json.loads(line) for line in path.read_text().splitlines()]
    return [e["transition"] for e in events if e["kind"] == "start"], events


def test_a_bridged_stateful_subnet_fires_as_the_simulated_run(agent, hub, tmp_path):
    """The state lives on the agent; the run's guards answer from the agent's snapshots:
    the same firings in the same order as the simulated run, each goal executed once."""
    (tmp_path / "net.yaml").write_text(NET)
    registry = demo_registry()
    simulated = run_files(tmp_path / "net.yaml", registry=registry, trace=tmp_path / "sim.jsonl")
    spec = {"transport": "hub", "connect": "tcp/127.0.0.1:1", "agents": {"counter": "robot"}, "heartbeat": 0.05, "wait": 5}
    (tmp_path / "run.yaml").write_text(f"seed: 1\nbridge: {json.dumps(spec)}\n")
    bridged = run_files(tmp_path / "net.yaml", registry=registry, trace=tmp_path / "bridged.jsonl")
    assert simulated.reason == bridged.reason == "final"
    assert bridged.tokens == simulated.tokens
    assert {"n": 3} in bridged.tokens["finished"]  # bump's ctx.put on the agent, passed on by done
    order, events = starts(tmp_path / "bridged.jsonl")
    expected, sim_events = starts(tmp_path / "sim.jsonl")
    assert order == expected
    ends = [(e["kind"], e["transition"]) for e in events if e["kind"] in ("start", "end")]
    assert ends == [(e["kind"], e["transition"]) for e in sim_events if e["kind"] in ("start", "end")]
    assert ends.index(("start", "note")) < ends.index(("end", "slow"))  # on the snapshot of a feedback
    # `before` fired on no state, `note` fired while `slow` still ran (a feedback's snapshot)
    assert order[:3] == ["before", "make", "slow"] and order.index("note") < order.index("bump")
    assert sorted(order) == sorted(["before", "make", "slow", "note", "bump", "bump", "done"])
    assert agent.executed == 4  # make, slow, bump, bump: once each
    # the custom events the agent's action emitted are in the run's trace, as in the simulated one
    bumped = [e["data"]["data"]["n"] for e in events if e["kind"] == "custom" and e["data"]["name"] == "demo.bumped"]
    assert bumped == [e["data"]["data"]["n"] for e in sim_events
                      if e["kind"] == "custom" and e["data"]["name"] == "demo.bumped"] == [2, 3]
    # the run never held the state: the agent did
    assert [type(h.state).__name__ for run in agent.memory.runs.values() for h in run.values()] == ["Counter"]
    goals = [protocol.decode(p) for t, p in hub.published if t == "petriflow/v1/to/robot"]
    goals = [g for g in goals if isinstance(g, protocol.Goal)]
    assert {g.transition: g.state["type"] for g in goals} == {"make": "demo.counter", "slow": "demo.counter",
                                                              "bump": "demo.counter"}
    assert goals[0].state["guards"]["done"] == ["demo.reached", {"limit": 3}]
    feedback = [protocol.decode(p) for t, p in hub.published if t == "petriflow/v1/from/robot"]
    assert any(isinstance(m, protocol.Feedback) and m.guards.get("note") for m in feedback)
    assert not [e for e in events if e["kind"] == "feedback"]  # a state report, not progress: no trace event


def test_a_state_of_the_wrong_type_fails_the_goal_on_the_agent(agent, hub, tmp_path):
    """The agent checks the state an action sets against the type the subnet declares."""
    class Wrong(InstantAction):
        def run(self, ctx):
            ctx.state = 3

    registry = demo_registry()
    registry.register("demo.wrong", Wrong)
    agent.registry.register("demo.wrong", Wrong)
    agent.actions = announcement(agent.registry)
    (tmp_path / "net.yaml").write_text(NET.replace("action: demo.make", "action: demo.wrong"))
    spec = {"transport": "hub", "connect": "tcp/127.0.0.1:1", "agents": {"counter": "robot"}, "heartbeat": 0.05, "wait": 5}
    (tmp_path / "run.yaml").write_text(f"seed: 1\nbridge: {json.dumps(spec)}\n")
    result = run_files(tmp_path / "net.yaml", registry=registry, trace=tmp_path / "t.jsonl")
    assert result.reason == "failed"
    events = [json.loads(line) for line in (tmp_path / "t.jsonl").read_text().splitlines()]
    end = next(e for e in events if e["kind"] == "end" and e["transition"] == "make")
    assert "its state must be a Counter, not int" in json.dumps(end)


def test_messages_without_the_extensions_are_the_bytes_they_were():
    """Agent-held state extends version 1 compatibly: empty extension fields are left out."""
    goal = protocol.Goal("r/1/1", "red", "core.wait", {"seconds": 1.0})
    assert b"state" not in protocol.encode(goal)
    result = protocol.Result("r/1/1", "red", "ok")
    assert protocol.encode(result) == b'{"v":1,"type":"result","id":"r/1/1","agent":"red","outcome":"ok",' \
                                      b'"data":null,"reason":""}'
    held = protocol.Result("r/1/1", "red", "ok", None, "", {"t": True}, 4, [["x", {"a": 1}]])
    assert protocol.decode(protocol.encode(held)) == held
    with pytest.raises(protocol.Refused, match="guards maps transitions"):
        protocol.decode(b'{"v":1,"type":"result","id":"x","agent":"a","outcome":"ok","guards":{"t":1}}')


class Team(InstantAction):
    """Reads the run's core.liveness resource: which agents run."""

    resources = {"live": "core.liveness"}

    def run(self, ctx):
        live = ctx.resource("live")
        return {"running": live.running(), "other": live.alive("other")}


TEAM_NET = """
petriflow: 1
net: team
final: {seen: 1, idle: 1}
subnets:
- id: counter
  agent: robot
  places: [{id: start, tokens: 1}, seen]
  transitions:
  - {id: look, action: demo.team, in: [start], out: [seen]}
- id: other
  agent: other
  places: [{id: rest, tokens: 1}, idle]
  transitions:
  - {id: sit, in: [rest], out: [idle]}
"""


def test_the_runs_liveness_resource_is_served_to_a_remote_action(agent, hub, tmp_path):
    """core.liveness (which agents run) is answered by the run through calls, as a local
    action reads it; any other resource stays refused at bind time (test_bridged_run.py)."""
    registry = demo_registry()
    registry.register("demo.team", Team)
    agent.registry.register("demo.team", Team)
    agent.actions = announcement(agent.registry)
    (tmp_path / "net.yaml").write_text(TEAM_NET)
    simulated = run_files(tmp_path / "net.yaml", registry=registry)
    spec = {"transport": "hub", "agents": {"counter": "robot"}, "heartbeat": 0.05, "wait": 5}
    (tmp_path / "run.yaml").write_text(f"seed: 1\nbridge: {json.dumps(spec)}\n")
    bridged = run_files(tmp_path / "net.yaml", registry=registry)
    assert simulated.reason == bridged.reason == "final"
    assert bridged.tokens["seen"] == simulated.tokens["seen"] == [{"running": ["robot", "other"], "other": True}]
    calls = [protocol.decode(p) for t, p in hub.published if t == "petriflow/v1/from/robot"]
    assert [(c.service, c.method) for c in calls if isinstance(c, protocol.Call)] == [
        ("liveness", "running"), ("liveness", "alive")]
