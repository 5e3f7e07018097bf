"""A frame the radio loses: the mailbox's slot comes back, and TCP gets the message through.

Before: the comm radio dropped a lost frame without a trace (``on_loss: drop``), its
mailbox's slot token went with it, the pair could never talk again and the envelope's
``end`` could never collect the slot: the 25-robot centralised mission of
``bench/comm.py`` stopped ``dead`` at 4,551 s after the central unit lost two frames
(to robot9 at 865 s, to robot16 at 1,011 s).
"""

from __future__ import annotations

import shutil

import pytest

from petriflow import examples
from petriflow.agents.comm.agent import CommAgent, Peer
from petriflow.agents.comm.framework import History, Packet
from petriflow.agents.comm.radio import RadioChannel
from petriflow.io import load_net
from petriflow.runtime.channel_models import Message
from petriflow.runtime.config import load_config
from petriflow.runtime.scheduler import Scheduler

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")


def test_the_comm_radio_leaves_a_loss_notice():
    assert RadioChannel().on_loss == "notify"


def _receive(net, config, receiver, token):
    run = Scheduler(net, config=config, seed=0)
    run.set_tokens({"box_central_robot1": [token], "robot1_listen": [None]})
    run.firer.agents.set_state("robot1", receiver, CommAgent)
    events = []
    run.on_event(events.append)
    with run:
        result = run.fire_one("robot1_receive_central", timeout=5)
    return result, events


def test_a_loss_notice_gives_the_slot_back_and_the_message_arrives_before_the_next():
    net = load_net(examples.path("comm", "comm-centralised-2.yaml"))
    config = load_config(examples.path("comm", "run.yaml"))
    robot = CommAgent("robot1", "robot", address=2, history=History(2))
    robot.peers["central"] = Peer("central", 129, "box_robot1_central")
    lost = Packet(3, 128, 1, 129, 2, [(5, 4.6, 0.4)])
    notice = {"lost": True, "why": "channel model",
              "data": {"size": lost.size, "payload": lost.payload, "code": 3,
                       "message": Message(None, "central", "robot1", lost)}}
    result, events = _receive(net, config, robot, notice)
    ends = [e.data["outcome"] for e in events if e.kind == "end"]
    assert ends == ["ok"] and result.marking["slot_central_robot1"] == 1  # the pair can talk again
    assert robot.vertices == {} and robot.lost == {"central": [lost]}
    assert [e.data["data"] for e in events if e.kind == "custom"] == [
        {"sender": "central", "code": 3, "bytes": 8, "source": 128}]
    later = Packet(3, 170, 1, 129, 2, [(6, 1.2, 0.4)])
    result, events = _receive(net, config, robot, {"size": later.size, "payload": later.payload, "code": 3,
                                                   "message": Message(None, "central", "robot1", later)})
    custom = [(e.data["name"], e.data["data"]) for e in events if e.kind == "custom"]
    assert custom == [("comm.resent", {"sender": "central", "code": 3, "source": 128}),  # first, in order
                      ("comm.learnt", {"ids": [5]}), ("comm.learnt", {"ids": [6]})]
    assert robot.lost == {}


def test_a_centralised_mission_ends_when_frames_are_lost(tmp_path):
    """The link between the central unit and robot1 is down for a second while they
    talk (a run fault): both frames on the air are lost. The mission still ends at its
    final marking, every map complete, as it does when nothing is lost."""
    from petriflow.agents.comm import metrics
    from petriflow.runtime.metrics import RunRecord
    from petriflow.runtime.session import run_files
    from petriflow.world import load_world

    for name in ("comm-centralised-2.yaml", "world.yaml"):
        shutil.copy(examples.path("comm", name), tmp_path / name)
    (tmp_path / "run.yaml").write_text(
        "seed: 1\nuntil: 3000\nworld: world.yaml\nstall: 600\n"
        "channels: {radio: {model: comm.radio, adapter_limit: [central]}}\n"
        "faults: [{drop_link: [central, robot1], at: 124.5, until: 125.5}]\n")
    outcome = run_files(tmp_path / "comm-centralised-2.yaml", keep_events=True)
    assert outcome.result.reason == "final"  # before: "until" (the central unit waited for ever on robot1's slot)
    lost = [(e.agent, e.data["data"]["code"]) for e in outcome.events
            if e.kind == "custom" and e.data.get("name") == "comm.lost"]
    assert sorted(lost) == [("central", 1), ("robot1", 2)]  # a request, and the vertices that answer one
    resent = [(e.agent, e.data["data"]["code"]) for e in outcome.events
              if e.kind == "custom" and e.data.get("name") == "comm.resent"]
    assert sorted(resent) == sorted(lost)  # both taken in later
    world = load_world(tmp_path / "world.yaml")
    try:
        assert metrics.maps_complete(RunRecord(outcome.result, outcome.events, world)) == 1.0
    finally:
        world.close()
