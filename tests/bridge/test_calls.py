"""Run services over the bridge: a remote action's calls, answered by the run (mostly with no
network: an in-process hub carries the messages between a real agent server and a
dispatcher; the last test runs a net over a real broker or router)."""

import json
import threading
import time

import pytest

from petriflow import Port
from petriflow.bridge import protocol
from petriflow.bridge.agent import AgentServer
from petriflow.bridge.calls import answer
from petriflow.bridge.dispatcher import Dispatcher, Phase
from petriflow.bridge.spec import BridgeSpec
from petriflow.bridge.transport import from_agent, to_agent
from petriflow.runtime.registry import Registry
from petriflow.runtime.services import RunServices
from petriflow.runtime.session import run_files


class Hub:
    """Publish/subscribe in one process: each message is handed to the handlers whose
    pattern matches its topic (``*``: one level), at once."""

    def __init__(self):
        self.subscribers = []
        self.published = []

    def subscribe(self, pattern, handler):
        self.subscribers.append((pattern.split("/"), handler))

    def publish(self, topic, payload):
        self.published.append((topic, payload))
        levels = topic.split("/")
        for pattern, handler in list(self.subscribers):
            if len(pattern) == len(levels) and all(p in ("*", x) for p, x in zip(pattern, levels)):
                handler(topic, bytes(payload))

    def close(self):
        pass

    def sent(self, topic):
        return [protocol.decode(p) for t, p in self.published if t == topic]


class Board:
    """The run's tokens and liveness, as a test sets them."""

    def __init__(self, places, alive=()):
        self.places, self.alive_agents, self.read_places = places, set(alive), []

    def read(self, place):
        self.read_places.append(place)
        return list(self.places.get(place, []))

    def alive(self, agent):
        return agent in self.alive_agents


def demo_registry():
    registry = Registry()

    @registry.action("demo.peek", {"scene": Port("the place watched")})
    def peek(ctx):
        return {"latest": ctx.latest("scene"), "blue": ctx.running("blue"), "red": ctx.running("red")}

    @registry.action("demo.mind")
    def mind(ctx):
        return ctx.state

    @registry.action("demo.wait_then_peek", {"scene": Port("the place watched")})
    def wait_then_peek(ctx):
        yield 0.05
        return ctx.read("scene")

    return registry


@pytest.fixture
def bridge():
    """``(hub, dispatcher, agent server)``: agent ``red`` served in a thread; all stopped after."""
    hub = Hub()
    spec = BridgeSpec.from_dict({"transport": "mqtt", "agents": {"red": "red"}, "heartbeat": 1000,
                                 "heartbeat_timeout": 2000})
    dispatcher = Dispatcher(spec, hub, run="r")
    server = AgentServer(["red"], hub, registry=demo_registry(), heartbeat=0.05, call_timeout=20)
    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()
    assert dispatcher.wait_for(10) == []
    yield hub, dispatcher, server
    server.stop()
    thread.join(timeout=10)
    assert not thread.is_alive()
    dispatcher.close()


def serve_calls(dispatcher, goal_id, services, ports, until_ended=True, seconds=10.0):
    """What the kernel does at each poll of the goal's firing: answer its calls."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        for call in dispatcher.take_calls(goal_id):
            dispatcher.reply(answer(call, services, ports))
        state = dispatcher.goal(goal_id)
        if until_ended and state.ended:
            return state
        time.sleep(0.002)
    return dispatcher.goal(goal_id)


def test_a_remote_action_reads_the_runs_port_and_liveness_through_calls(bridge):
    """ctx.latest and ctx.running on the agent are answered from the run's own services."""
    hub, dispatcher, server = bridge
    board = Board({"S": [{"robots": {"yellow": {"x": 0.5}}}, {"robots": {"yellow": {"x": 0.7}}}]}, alive={"blue"})
    dispatcher.send(protocol.Goal("r/1/1", "red", "demo.peek", {"scene": "S"}, "peek"))
    state = serve_calls(dispatcher, "r/1/1", RunServices(tokens=board, liveness=board), {"S"})
    assert state.phase == Phase.OK, state.reason
    assert state.data == {"latest": {"robots": {"yellow": {"x": 0.7}}}, "blue": True, "red": False}
    assert board.read_places == ["S"]
    assert state.answered_calls == 3
    calls = [m for m in hub.sent(from_agent("red")) if isinstance(m, protocol.Call)]
    assert [(c.call, c.service, c.method, c.args) for c in calls] == [
        (1, "tokens", "read", ["S"]), (2, "liveness", "alive", ["blue"]), (3, "liveness", "alive", ["red"])]


def test_a_place_no_port_names_is_refused_and_the_goal_fails_with_the_reason(bridge):
    """The run reads only the places the action's ports name; a refused call fails the goal."""
    hub, dispatcher, server = bridge
    board = Board({"S": [1], "secret": [2]})
    dispatcher.send(protocol.Goal("r/1/1", "red", "demo.peek", {"scene": "secret"}, "peek"))
    state = serve_calls(dispatcher, "r/1/1", RunServices(tokens=board), {"S"})
    assert state.phase == Phase.FAILED
    assert "tokens.read: the run refused: tokens.read: place 'secret' is named by none of the action's ports" \
        in state.reason
    assert board.read_places == []


def test_a_service_not_served_fails_the_goal_at_once_without_a_call(bridge):
    """ctx.state on a remote agent: the goal fails with a one-line reason, nothing is sent to the run."""
    hub, dispatcher, server = bridge
    dispatcher.send(protocol.Goal("r/1/1", "red", "demo.mind", {}, "mind"))
    state = dispatcher.wait_goal("r/1/1", 10)
    assert state.phase == Phase.FAILED
    assert "ctx.state reaches the run's agent states, which is not served to remote agents" in state.reason
    assert not [m for m in hub.sent(from_agent("red")) if isinstance(m, protocol.Call)]


def test_a_call_for_a_goal_given_up_is_refused_and_its_action_fails(bridge):
    """The run cancelled the goal (or lost its agent): its waiting call is refused, a later one too."""
    hub, dispatcher, server = bridge
    dispatcher.send(protocol.Goal("r/1/1", "red", "demo.wait_then_peek", {"scene": "S"}, "peek"))
    deadline = time.monotonic() + 10
    while not dispatcher.goal("r/1/1").calls and time.monotonic() < deadline:
        time.sleep(0.005)
    dispatcher.forget("r/1/1")  # as when the agent is lost: the waiting call is refused
    refused = [m for m in hub.sent(to_agent("red")) if isinstance(m, protocol.Reply)]
    assert len(refused) == 1 and refused[0].call == 1 and "the run gave up the goal" in refused[0].error
    deadline = time.monotonic() + 10
    while "r/1/1" not in server.ended and time.monotonic() < deadline:
        time.sleep(0.005)
    assert server.ended["r/1/1"].outcome == "failed" and "the run refused" in server.ended["r/1/1"].reason
    # a call arriving after: refused at once, never queued for the kernel
    hub.publish(from_agent("red"), protocol.encode(protocol.Call("r/1/1", "red", 2, "tokens", "read", ["S"])))
    later = [m for m in hub.sent(to_agent("red")) if isinstance(m, protocol.Reply) and m.call == 2]
    assert len(later) == 1 and "the goal ended (cancelled)" in later[0].error
    assert dispatcher.take_calls("r/1/1") == []


def quiet_dispatcher():
    hub = Hub()
    spec = BridgeSpec.from_dict({"transport": "mqtt", "agents": {"red": "red"}, "heartbeat": 1000,
                                 "heartbeat_timeout": 2000})
    return hub, Dispatcher(spec, hub, run="r")


def test_unknown_malformed_or_foreign_calls_are_dropped_and_counted():
    """A call of a service not served, with ill-typed arguments, malformed, for an unknown or
    another agent's goal: dropped, counted by reason, never queued or answered."""
    hub, dispatcher = quiet_dispatcher()
    try:
        dispatcher.send(protocol.Goal("r/1/1", "red", "demo.peek", {"scene": "S"}))
        send = lambda body: dispatcher.receive(from_agent("red"), body)  # noqa: E731
        send(protocol.encode(protocol.Call("r/1/1", "red", 1, "agents", "set_state", ["red", 1])))
        send(protocol.encode(protocol.Call("r/1/1", "red", 2, "tokens", "write", ["S"])))
        send(protocol.encode(protocol.Call("r/1/1", "red", 3, "tokens", "read", [["S"]])))
        send(protocol.encode(protocol.Call("r/1/1", "red", 4, "tokens", "read", ["S", "T"])))
        send(b'{"v":1,"type":"call","id":"r/1/1","agent":"red","call":"one","service":"tokens","method":"read"}')
        send(b'{"v":1,"type":"call","id":"r/1/1","agent":"red","call":true,"service":"tokens","method":"read"}')
        send(b'{"v":1,"type":"call","id":"r/1/1","agent":"red","call":1,"service":"tokens"}')
        send(protocol.encode(protocol.Call("r/9/1", "red", 1, "tokens", "read", ["S"])))
        send(protocol.encode(protocol.Reply("r/1/1", "red", 1, 5)))  # only the run replies
        dispatcher.receive(from_agent("mallory"), protocol.encode(protocol.Call("r/1/1", "mallory", 1, "tokens",
                                                                                "read", ["S"])))
        assert dict(dispatcher.dropped) == {"unknown_call": 4, "malformed": 4, "unknown_goal": 1,
                                            "unknown_agent": 1}
        assert dispatcher.take_calls("r/1/1") == []
        assert not [m for t, m in hub.published if t == to_agent("red") and b'"reply"' in m]
    finally:
        dispatcher.close()


def test_a_call_sent_again_is_answered_once_with_the_same_reply():
    """An agent that had no reply sends its call again: queued once, answered from the kept reply."""
    hub, dispatcher = quiet_dispatcher()
    try:
        dispatcher.send(protocol.Goal("r/1/1", "red", "demo.peek", {"scene": "S"}))
        call = protocol.encode(protocol.Call("r/1/1", "red", 1, "tokens", "read", ["S"]))
        dispatcher.receive(from_agent("red"), call)
        dispatcher.receive(from_agent("red"), call)
        calls = dispatcher.take_calls("r/1/1")
        assert len(calls) == 1
        board = Board({"S": ["x"]})
        dispatcher.reply(answer(calls[0], RunServices(tokens=board), {"S"}))
        dispatcher.receive(from_agent("red"), call)
        replies = [m for m in hub.sent(to_agent("red")) if isinstance(m, protocol.Reply)]
        assert [(r.call, r.value) for r in replies] == [(1, ["x"]), (1, ["x"])]
        assert board.read_places == ["S"] and dispatcher.goal("r/1/1").answered_calls == 1
    finally:
        dispatcher.close()


def test_the_agent_gives_up_a_call_the_run_never_answers():
    """A run that never answers (paused past the agent's call timeout): the action fails, it
    does not hang, and the call was sent again meanwhile."""
    hub = Hub()
    server = AgentServer(["red"], hub, registry=demo_registry(), heartbeat=0.02, call_timeout=0.3)
    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()
    try:
        hub.publish(to_agent("red"), protocol.encode(protocol.Goal("r/1/1", "red", "demo.peek", {"scene": "S"})))
        deadline = time.monotonic() + 10
        while "r/1/1" not in server.ended and time.monotonic() < deadline:
            time.sleep(0.01)
        result = server.ended["r/1/1"]
        assert result.outcome == "failed" and "no reply from the run within 0.3 s" in result.reason
        sent = hub.sent(from_agent("red"))
        assert len([m for m in sent if isinstance(m, protocol.Call)]) >= 2
        assert any(isinstance(m, protocol.Heartbeat) and m.running == ["r/1/1"] for m in sent)
    finally:
        server.stop()
        thread.join(timeout=10)
    assert not thread.is_alive()


def test_calls_are_messages_of_the_protocol():
    """Encoded and decoded like the others, the call number from 1."""
    call = protocol.Call("r/1/1", "red", 1, "tokens", "read", ["S"])
    assert protocol.decode(protocol.encode(call)) == call
    reply = protocol.Reply("r/1/1", "red", 1, None, "refused")
    assert protocol.decode(protocol.encode(reply)) == reply
    with pytest.raises(protocol.Refused, match="call numbers a goal's calls from 1"):
        protocol.decode(b'{"v":1,"type":"call","id":"g","agent":"a","call":0,"service":"s","method":"m"}')


PORT_NET = """\
petriflow: 1
net: board
subnets:
  - id: r1
    agent: r1
    places: [go]
    transitions:
      - {id: peek, action: demo.peek, params: {scene: board}, in: [go], out: [o]}
  - id: here
    agent: blue
    places: [{id: a, tokens: 1}]
    transitions:
      - {id: post, action: core.set, params: {value: {robots: {yellow: {x: 0.25}}}}, in: [a], out: [board, go]}
places: [board, o]
final: {o: 1, board: 1}
"""


def test_a_bridged_run_reads_the_same_port_values_as_the_simulated_run(middleware, serve, tmp_path):
    """Over a real broker or router: the remote action's port read and liveness question are
    answered by the run, and give what the simulated run's local action read."""
    kind, server = middleware
    registry = demo_registry()
    agent = serve(kind, server.connect, ["robot1"], heartbeat=0.1, registry=registry)
    (tmp_path / "net.yaml").write_text(PORT_NET)
    simulated = run_files(tmp_path / "net.yaml", registry=registry)
    spec = {"transport": kind, "connect": server.connect, "agents": {"r1": "robot1"}, "wait": 10}
    (tmp_path / "run.yaml").write_text(f"seed: 1\nbridge: {json.dumps(spec)}\n")
    bridged = run_files(tmp_path / "net.yaml", registry=registry, trace=tmp_path / "t.jsonl")
    assert simulated.reason == bridged.reason == "final"
    assert bridged.tokens["o"] == simulated.tokens["o"] == [
        {"latest": {"robots": {"yellow": {"x": 0.25}}}, "blue": True, "red": True}]
    remote = [json.loads(line) for line in (tmp_path / "t.jsonl").read_text().splitlines()]
    remote = [e["data"]["data"] for e in remote if e["kind"] == "custom" and e["data"]["name"] == "remote"]
    assert [(r["agent"], r["calls"]) for r in remote] == [("robot1", 3)]
    assert agent.server.executed == 1
