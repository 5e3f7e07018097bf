"""Token data of known types across the bridge (petriflow/bridge/codec.py) and resources
made per world on the agent (Registry.register_resource(per_world=True)). No network:
an in-process hub carries the messages between a real agent server and a real run."""

import json
import threading
from dataclasses import dataclass

import numpy as np
import pytest

from petriflow.bridge import protocol
from petriflow.bridge.agent import AgentServer
from petriflow.bridge.codec import Codec, CodecError
from petriflow.errors import NetFormatError
from petriflow.runtime.action import InstantAction
from petriflow.runtime.channel_models import Message
from petriflow.runtime.registry import Registry, default_registry
from petriflow.runtime.session import run_files

from tests.bridge.test_held_state import hub  # noqa: F401  (the in-process transport fixture)


def through_the_wire(codec_out, codec_in, value):
    """``value`` as one side encodes it, sent as protocol bytes, decoded by the other side."""
    goal = protocol.Goal("r/1/1", "robot", "demo.x", {}, "t", {"box": [codec_out.encode(value)]})
    return codec_in.decode(protocol.decode(protocol.encode(goal)).inputs["box"][0])


def test_a_bidding_message_round_trips_through_both_codecs():
    """A mailbox token (a Message carrying a bidding Payload: its Kind, a tuple, a numpy
    array) sent by one side's codec is rebuilt by the other's: a Message again, its
    payload the registered dataclass, its kind the enum, its size as sent."""
    from petriflow.agents.bidding.protocol import Kind, Payload, token

    types = default_registry.data_types()
    assert "bidding.payload" in types
    run_side, agent_side = Codec(types), Codec(types)
    message = Message("box_robot1", "hmia", "robot1",
                      Payload(Kind.MAPPED, 2, {"points": np.array([[1.0, 2.0], [3.0, 4.5]]), "pose": (1.0, 2.0, 0.5)},
                              cast=7), time=3.25)
    sent = token(message)
    back = through_the_wire(run_side, agent_side, sent)
    assert set(back) == {"kind", "size", "message"} and back["kind"] == "MAPPED" and back["size"] == sent["size"]
    rebuilt = back["message"]
    assert isinstance(rebuilt, Message) and isinstance(rebuilt.data, Payload)
    assert (rebuilt.place, rebuilt.sender, rebuilt.receiver, rebuilt.time, rebuilt.size) == \
        ("box_robot1", "hmia", "robot1", 3.25, message.size)
    assert rebuilt.kind is Kind.MAPPED and rebuilt.data.zone == 2 and rebuilt.data.cast == 7
    assert rebuilt.data.body == {"points": [[1.0, 2.0], [3.0, 4.5]], "pose": [1.0, 2.0, 0.5]}
    again = through_the_wire(agent_side, run_side, back)  # and back the other way: the same JSON
    assert run_side.encode(again) == run_side.encode(back)


def test_what_the_codec_does_not_know_is_summarised_or_stays_json():
    """An object of no known type is only its type's name (as before); a tagged object of
    a type this side lacks stays its JSON; one that does not rebuild raises."""
    class Thing:
        pass

    @dataclass(frozen=True)
    class Note:
        text: str

    codec = Codec({"demo.note": Note})
    assert codec.encode({"x": Thing(), "m": Message(None, "a", "b", Thing())}) == {
        "x": "<Thing>", "m": {"$type": "message", "place": None, "sender": "a", "receiver": "b", "data": "<Thing>",
                              "time": 0.0, "size": 16, "distance": None}}
    assert Codec().decode({"$type": "demo.note", "text": "hi"}) == {"$type": "demo.note", "text": "hi"}
    assert codec.decode({"$type": "demo.note", "text": "hi"}) == Note("hi")
    with pytest.raises(CodecError, match="a 'demo.note' object does not rebuild: TypeError"):
        codec.decode({"$type": "demo.note", "words": "hi"})
    with pytest.raises(CodecError, match="a 'message' object does not rebuild"):
        codec.decode({"$type": "message", "sender": "a"})


def test_registering_a_data_type_checks_it():
    registry = Registry(False)
    with pytest.raises(Exception, match="must be a dataclass"):
        registry.register_data_type("demo.thing", int)


@dataclass(frozen=True)
class Note:
    text: str
    size: int = 8


class Ask(InstantAction):
    def run(self, ctx):
        return {"message": Message("box", "desk", "robot", Note("map zone 2"), time=ctx.now)}


class Answer(InstantAction):
    """On the robot: reads the Message it was given, answers with one of its own."""

    def run(self, ctx):
        asked = ctx.inputs["box"][0]["message"]
        assert isinstance(asked, Message) and isinstance(asked.data, Note), asked
        ctx.put("reply", {"message": Message("reply", "robot", asked.sender, Note(f"done: {asked.data.text}"))})


class Look(InstantAction):
    """On the robot: what its per-world resource says."""

    resources = {"room": "demo.room"}

    def run(self, ctx):
        return {"room": ctx.resource("room")}


def mail_registry(made):
    registry = Registry()
    registry.register("demo.ask", Ask)
    registry.register("demo.answer", Answer)
    registry.register("demo.look", Look)
    registry.register_data_type("demo.note", Note)

    def room(context):
        made.append(context.world)
        return {"room": getattr(context.world, "name", None)}

    registry.register_resource("demo.room", room, per_world=True)
    return registry


MAIL_NET = """
petriflow: 1
net: mail
places: [box, reply, seen]
subnets:
- id: desk
  agent: desk
  places: [{id: start, tokens: 1}]
  transitions:
  - {id: ask, action: demo.ask, in: [start], out: [box]}
- id: robot
  agent: robot
  places: [{id: idle, tokens: 2}]
  transitions:
  - {id: answer, action: demo.answer, in: [box], out: [reply]}
  - {id: look, action: demo.look, in: [idle], out: [seen]}
final: {reply: 1, seen: 2}
"""


class World:
    name = "the robot's own world"
    dt = 0.01
    meta = {}

    def step(self):
        pass


@pytest.fixture
def mail_agent(hub):  # noqa: F811
    made = []
    server = AgentServer(["robot"], hub, registry=mail_registry(made), heartbeat=0.05, world=World())
    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()
    yield server, made
    server.stop()
    thread.join(timeout=10)
    assert not thread.is_alive()


def test_messages_cross_and_a_per_world_resource_is_made_on_the_agent(mail_agent, hub, tmp_path):  # noqa: F811
    """The robot's action reads the desk's Message as a Message and its reply reaches
    the run as one (the same tokens as the simulated run's); its resource is made once,
    on the agent, from the agent's world, never in the run."""
    server, made = mail_agent
    made_in_run = []
    registry = mail_registry(made_in_run)
    (tmp_path / "net.yaml").write_text(MAIL_NET)
    simulated = run_files(tmp_path / "net.yaml", registry=registry)
    assert simulated.reason == "final" and simulated.tokens["seen"] == [{"room": {"room": None}}] * 2
    made_in_run.clear()
    spec = {"transport": "hub", "agents": {"robot": "robot"}, "heartbeat": 0.05, "wait": 5}
    (tmp_path / "run.yaml").write_text(f"seed: 1\nbridge: {json.dumps(spec)}\n")
    bridged = run_files(tmp_path / "net.yaml", registry=registry)
    assert bridged.reason == "final"
    assert bridged.tokens["reply"] == simulated.tokens["reply"] == [
        {"message": Message("reply", "robot", "desk", Note("done: map zone 2"))}]
    assert bridged.tokens["seen"] == [{"room": {"room": "the robot's own world"}}] * 2
    assert [getattr(w, "name", None) for w in made] == ["the robot's own world"]  # once per run, on the agent
    assert made_in_run == []


def test_a_resource_not_made_per_world_is_refused_at_bind_time_at_the_line(tmp_path):
    """Which resources an agent makes is the registration's ``per_world``: a resource of
    the run's own is refused when the net binds, with the net's file:line."""
    registry = mail_registry([])
    registry.register_resource("demo.room", lambda context: None, replace=True)  # the run's own now
    (tmp_path / "net.yaml").write_text(MAIL_NET)
    spec = {"transport": "mqtt", "agents": {"robot": "robot"}}
    (tmp_path / "run.yaml").write_text(f"seed: 1\nbridge: {json.dumps(spec)}\n")
    with pytest.raises(NetFormatError, match=r"net.yaml:16: 'look': action demo.look takes the run's resource\(s\)"
                                             r" room, which are not served to remote agents \(served: core.liveness,"
                                             r" by calls; a resource registered per_world"):
        run_files(tmp_path / "net.yaml", registry=registry, db=tmp_path / "run.sqlite")
    assert not (tmp_path / "run.sqlite").exists()
