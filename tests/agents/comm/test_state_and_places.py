"""Seed 000 on the kernel's parts: the agent's state kept by the run (``comm.agent``),
guards that say which state keys they read, liveness from ``core.liveness``, and every
place an action names checked when the net is loaded."""

from __future__ import annotations

import re

import pytest

from petriflow import examples
from petriflow.agents.comm.actions import Explore, Listen
from petriflow.agents.comm.agent import CommAgent, Peer
from petriflow.agents.comm.framework import History, Packet
from petriflow.errors import NetFormatError
from petriflow.io.yaml import loads_net
from petriflow.runtime.binding import bind
from petriflow.runtime.config import load_config
from petriflow.runtime.registry import default_registry
from petriflow.runtime.scheduler import Scheduler


def shipped_text(name: str = "comm-decentralised-2.yaml") -> str:
    with open(examples.path("comm", name), encoding="utf-8") as handle:
        return handle.read()


def test_the_agent_state_type_and_the_guards_reads_are_registered():
    assert default_registry.state_type("comm.agent") is CommAgent
    assert default_registry.guard_reads("comm.has_message") == ("outbox/{peer}",)
    assert default_registry.guard_reads("comm.finished") == ("*",)
    assert default_registry.guard_reads("comm.going_on") == ("*",)
    binding = bind(loads_net(shipped_text()))
    assert binding.transitions["robot1_send_robot2"].reads == ("outbox/robot2",)


def test_the_state_touches_one_peers_key_when_its_queue_or_hearing_changes():
    state = CommAgent("robot1", "robot", address=2, history=History(2))
    state.peers = {"robot2": Peer("robot2", 128, "box_robot1_robot2"), "robot3": Peer("robot3", 170, "b13")}
    touched: list[tuple[str, ...]] = []
    state.attach(touched.append)
    state.queue(Packet(3, 2, 1, 2, 128, [(0, 0.4, 0.4)]))
    assert touched == [("outbox/robot2",)]
    state.hear({"robot2"})
    state.hear({"robot2"})  # no change: nothing to ask again
    assert touched[1:] == [("outbox/robot2",)]
    assert state.has_for("robot2") and not state.has_for("robot3")
    state.hear({"robot3"})
    assert touched[2:] == [("outbox/robot2", "outbox/robot3")]
    assert state.take("robot2") is not None and touched[3:] == [("outbox/robot2",)]


@pytest.mark.parametrize("old, new, transition, param", [
    ("params: {peer: robot2, box: box_robot1_robot2}", "params: {peer: robot2, box: box_robot1_robot3}",
     "robot1_send_robot2", "box"),
    ("params: {box: box_robot2_robot1}", "params: {box: box_robot2_robotl}", "robot1_receive_robot2", "box"),
    ("params: {channel_place: box_robot2_robot1}", "params: {channel_place: box_robot2_robot}", "robot1_analyse",
     "channel_place"),
    ("robot2: {address: 128, box: box_robot1_robot2}", "robot2: {address: 128, box: box_robot1_robot02}",
     "robot1_initialise", "peers"),
])
def test_a_misspelt_place_in_any_comm_parameter_fails_at_load_with_its_line(old, new, transition, param):
    text = shipped_text()
    assert old in text
    text = text.replace(old, new, 1)
    line = text[:text.index(new)].count("\n") + 1
    with pytest.raises(NetFormatError) as error:
        bind(loads_net(text, path="comm.yaml"))
    message = str(error.value)
    assert re.match(rf"comm\.yaml:(\d+): '{transition}': parameter '{param}' names unknown place", message), message
    assert abs(int(message.split(":")[1]) - line) <= 2  # the transition's params (or the line of the key)
    assert "did you mean" in message


def test_comm_actions_read_liveness_from_the_core_resource():
    assert Explore.resources == {"live": "core.liveness"} and Listen.resources == {"live": "core.liveness"}


def test_a_peer_that_has_not_joined_is_not_heard(tmp_path):
    """The central unit plans only towards peers that run now (core.liveness): robot2
    joins at 100 s, so at 0 s only robot1 is heard (no world: every link is usable)."""
    (tmp_path / "run.yaml").write_text("seed: 1\nchannels: {radio: {model: comm.radio}}\n"
                                       "faults: [{join: robot2, at: 100}]\n")
    config = load_config(tmp_path / "run.yaml")
    net = loads_net(shipped_text("comm-centralised-2.yaml"))
    central = CommAgent("central", "central", address=129, history=History(129))
    central.peers = {"robot1": Peer("robot1", 2, "box_central_robot1"),
                     "robot2": Peer("robot2", 128, "box_central_robot2")}
    run = Scheduler(net, config=config, seed=0)
    run.set_tokens({"central_idle": [None]})
    run.firer.agents.set_state("central", central, CommAgent)
    with run:
        result = run.fire_one("central_step", timeout=5)
    assert result.reason == "fired" and central.in_range == {"robot1"}


def test_a_waiting_robot_woken_once_ends_its_wait_at_the_same_step(monkeypatch):
    """comm.explore sleeps through a wait (one wake, computed by counting the wait down
    step by step) instead of being polled at every step: the run is the same, event for
    event, as with a poll at every step."""
    from petriflow.runtime.session import run_files

    def events():
        outcome = run_files(examples.path("comm", "comm-decentralised-2.yaml"), keep_events=True)
        return [(e.kind, round(e.time, 9), e.transition, e.agent, e.data.get("name"), e.data.get("data"))
                for e in outcome.events if e.kind not in ("run", "stop")]

    slept = []
    sleep = Explore._sleep
    monkeypatch.setattr(Explore, "_sleep", lambda self, ctx: slept.append(ctx.now) or sleep(self, ctx))
    woken = events()
    monkeypatch.setattr(Explore, "_sleep", lambda self, ctx: None)  # polled at every step
    polled = events()
    assert len(slept) > 10 and woken == polled
