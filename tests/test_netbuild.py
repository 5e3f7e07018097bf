"""petriflow.netbuild: nets built in Python are sound, fire to their end, round-trip, and
misuse is refused with a clear error."""

from __future__ import annotations

import pytest

from petriflow.analysis.report import check_net
from petriflow.engine import Simulation, enabled, fire_sequence
from petriflow.errors import NetStructureError, UnknownElementError
from petriflow.io.pnml import dumps_pnml, loads_pnml
from petriflow.io.yaml import dumps_net, loads_net
from petriflow.net import Net
from petriflow.netbuild import Mailbox, NetBuilder


def ping_pong(capacity: int = 1) -> Net:
    """robot1 pings into robot2's mailbox and waits; robot2 listens, and answers once pinged."""
    b = NetBuilder("pingpong", label="ping-pong")
    r1, r2 = b.agent("robot1", label="the pinger"), b.agent("robot2")
    box1 = b.mailbox(r1, channel="radio", capacity=capacity)
    box2 = b.mailbox(r2, channel="radio", capacity=capacity)
    for place in ("start", "wait", "done"):
        r1.place(place)
    ping = r1.transition("ping", action="demo.say", params={"text": "ping"}, inputs=["start"],
                         outputs=["wait"])
    b.send(ping, box2)
    b.receive(r1.transition("hear", inputs="wait", outputs="done", priority=1), box1)
    for place in ("start", "listen", "heard", "done"):
        r2.place(place)
    r2.transition("boot", inputs=["start"], outputs=["listen"])
    b.receive(r2.transition("hear", inputs=["listen"], outputs=["heard"]), box2)
    b.send(r2.transition("pong", inputs={"heard": 1}, outputs=["done"], timeout=5), box1)
    r1.start("start")
    r2.start("start")
    r1.done("done")
    r2.done("done")
    b.envelope(begin_label="power on", end_label="both done")
    return b.build()


def test_a_ping_pong_net_built_with_the_api_is_a_sound_workflow_net():
    """check_net finds a sound WF-net with no violation, ending in o."""
    net = ping_pong()
    result = check_net(net)
    assert result["workflow_net"] and result["sound"], result["violations"]
    assert result["violations"] == []
    assert result["source_place"] == "i" and result["sink_place"] == "o"
    assert net.initial_marking == {"i": 1} and net.final_marking == {"o": 1}


@pytest.mark.parametrize("seed", range(5))
def test_the_token_game_ends_in_the_final_marking(seed):
    """Whatever the order of firing, the token game stops with one token in o and nothing else."""
    net = ping_pong()
    game = Simulation(net, seed=seed)
    fired = game.run(100)
    assert game.is_dead
    assert game.marking == net.final_marking
    assert fired[0] == "begin" and fired[-1] == "end"
    assert {"robot1_ping", "robot2_hear", "robot2_pong", "robot1_hear"} <= set(fired)


def test_elements_belong_to_their_agent_and_are_named_by_one_rule():
    """An agent's places and transitions are f"{agent}_{local}" in its subnet; the
    envelope and nothing else lies outside every agent."""
    net = ping_pong()
    assert net.subnets["robot1"].label == "the pinger" and net.subnets["robot1"].agent == "robot1"
    assert net.nodes_of("robot1") == (["robot1_box", "robot1_box_slot", "robot1_start", "robot1_wait",
                                       "robot1_done"], ["robot1_ping", "robot1_hear"])
    outside = [n for n in net if (net.places.get(n) or net.transitions.get(n)).subnet is None]
    assert sorted(outside) == ["begin", "end", "i", "o"]
    assert net.place("robot2_box").channel == "radio" and net.place("robot2_box_slot").channel is None
    assert net.transition("begin").label == "power on" and net.transition("end").label == "both done"


def test_a_built_net_round_trips_through_yaml():
    """dumps_net then loads_net gives the same structure (bindings, subnets, markings)."""
    net = ping_pong()
    back = loads_net(dumps_net(net))
    assert back.structure() == net.structure()
    assert back.transition("robot2_pong").timeout == 5.0


def test_a_built_net_round_trips_through_pnml():
    """dumps_pnml then loads_pnml gives the same structure."""
    net = ping_pong(capacity=2)
    assert loads_pnml(dumps_pnml(net)).structure() == net.structure()


@pytest.mark.parametrize("k", [1, 2, 3])
def test_a_mailbox_of_capacity_k_holds_k_slot_tokens_and_at_most_k_messages(k):
    """begin hands out k slot tokens and end takes k back (arc weight k); the analysis
    bounds the channel place by k, reached when k messages are sent before any is read."""
    b = NetBuilder("burst")
    sender, receiver = b.agent("sender"), b.agent("receiver")
    box = b.mailbox(receiver, channel="lan", capacity=k)
    assert (box.capacity, box.owner, box.channel) == (k, "receiver", "lan")
    states = [sender.place(f"s{n}") for n in range(k + 1)]
    for n in range(k):
        b.send(sender.transition(f"send{n}", inputs=[f"s{n}"], outputs=[f"s{n + 1}"]), box)
    receiver.place("listen")
    b.receive(receiver.transition("take", inputs=["listen"], outputs=["listen"]), box)
    sender.start("s0")
    sender.done(states[-1])
    receiver.start("listen")
    receiver.done("listen")
    b.envelope()
    net = b.build()
    assert net.postset("begin")[box.slot] == k
    assert net.preset("end")[box.slot] == k
    result = check_net(net)
    assert result["sound"], result["violations"]
    assert result["k_bound"][box.id] == k and result["k_bound"][box.slot] == k
    full = fire_sequence(net, net.initial_marking, ["begin"] + [f"sender_send{n}" for n in range(k)])
    assert full[box.id] == k and full[box.slot] == 0


def broadcast_net() -> tuple[Net, list[Mailbox]]:
    b = NetBuilder("announce")
    leader = b.agent("leader")
    followers = [b.agent(f"f{n}") for n in (1, 2)]
    boxes = [b.mailbox(f, channel="radio") for f in followers]
    leader.place("ready")
    leader.place("done")
    b.broadcast(leader.transition("announce", inputs=["ready"], outputs=["ready"]), boxes)
    leader.transition("stop", inputs=["ready"], outputs=["done"])
    leader.start("ready")
    leader.done("done")
    for follower, box in zip(followers, boxes):
        follower.place("listen")
        b.receive(follower.transition("take", inputs=["listen"], outputs=["listen"]), box)
        follower.start("listen")
        follower.done("listen")
    b.envelope()
    return b.build(), boxes


def test_a_broadcast_takes_one_slot_per_mailbox_and_puts_one_message_in_each():
    """The broadcasting transition consumes each mailbox's slot once and produces into each
    channel place once; it waits while any of them is full."""
    net, boxes = broadcast_net()
    assert net.preset("leader_announce") == {"leader_ready": 1, "f1_box_slot": 1, "f2_box_slot": 1}
    assert net.postset("leader_announce") == {"leader_ready": 1, "f1_box": 1, "f2_box": 1}
    after = fire_sequence(net, net.initial_marking, ["begin", "leader_announce"])
    assert [after[b.id] for b in boxes] == [1, 1] and [after[b.slot] for b in boxes] == [0, 0]
    assert "leader_announce" not in enabled(net, after)
    one_read = fire_sequence(net, after, ["f1_take"])
    assert "leader_announce" not in enabled(net, one_read)  # f2's mailbox is still full
    assert "leader_announce" in enabled(net, fire_sequence(net, one_read, ["f2_take"]))
    assert check_net(net)["sound"]


def test_places_are_named_locally_or_by_full_id():
    """An agent's transition may name its own places locally and any place by full id."""
    b = NetBuilder()
    a, c = b.agent("a"), b.agent("c")
    a.place("x")
    c.place("y")
    b.place("shared", tokens=2)
    t = a.transition("t", inputs={"x": 1, "shared": 2}, outputs=["c_y"], outcomes={"failed": ["a_x"]})
    net = b.build()
    assert t == "a_t" and net.transition(t).subnet == "a"
    assert net.preset(t) == {"a_x": 1, "shared": 2}
    assert net.postset(t) == {"c_y": 1} and net.postset(t, "failed") == {"a_x": 1}
    assert net.initial_marking == {"shared": 2} and net.final_marking is None


def test_an_agent_may_hold_elements_named_outside_the_naming_rule():
    """NetBuilder.place and .transition with ``agent=`` put a full id in that agent's
    subnet (a net file's ids kept as they are); its places may then be named locally."""
    b = NetBuilder()
    a = b.agent("a")
    a.place("on")
    box = b.place("box_b_a", agent=a, channel="radio")
    end = b.transition("end", agent="a", inputs=["on", box])
    net = b.build()
    assert (net.place(box).subnet, net.place(box).channel, net.transition(end).subnet) == ("a", "radio", "a")
    assert net.preset("end") == {"a_on": 1, "box_b_a": 1}
    with pytest.raises(UnknownElementError):
        b.place("p", agent="nobody")


def test_registrations_count_whenever_they_are_made_and_build_can_be_called_again():
    """A mailbox made after envelope() is still handed out by begin; each build() is a new
    net, unchanged by what the builder does later."""
    b = NetBuilder()
    a = b.agent("a")
    a.place("s")
    a.start("s")
    b.envelope()
    first = b.build()
    box = b.mailbox(a, channel=None)
    second = b.build()
    assert box.slot not in first.places and first.postset("begin") == {"a_s": 1}
    assert second.postset("begin") == {"a_s": 1, "a_box_slot": 1}
    assert second.preset("end") == {"a_box_slot": 1}
    assert b.build().structure() == second.structure()


def test_without_an_envelope_start_places_and_resources_start_marked():
    """With no envelope, build() marks what begin would have handed out."""
    b = NetBuilder()
    a = b.agent("a")
    a.place("s")
    a.start("s")
    b.mailbox(a, channel="radio", capacity=2)
    net = b.build()
    assert net.initial_marking == {"a_s": 1, "a_box_slot": 2}
    assert "begin" not in net.transitions and net.final_marking is None


# Misuse ------------------------------------------------------------------------------


def test_an_unknown_local_place_is_refused_with_a_hint_and_the_net_is_unchanged():
    b = NetBuilder()
    a = b.agent("robot1")
    a.place("start")
    with pytest.raises(UnknownElementError, match=r"agent 'robot1': unknown place 'strat': neither"
                       r" 'robot1_strat' nor 'strat' exists \(did you mean 'start'"):
        a.transition("go", inputs=["strat"])
    assert "robot1_go" not in b.build().transitions
    with pytest.raises(UnknownElementError, match="unknown place 'nowhere'"):
        a.start("nowhere")
    with pytest.raises(UnknownElementError, match="unknown transition 'robot1_go'"):
        b.send("robot1_go", b.mailbox(a, channel="radio"))


def test_a_mailbox_of_an_unknown_agent_is_refused():
    b = NetBuilder()
    b.agent("robot1")
    with pytest.raises(UnknownElementError, match=r"unknown agent 'robot3' \(did you mean 'robot1'"):
        b.mailbox("robot3", channel="radio")
    with pytest.raises(UnknownElementError, match="unknown agent 'robot1'"):
        NetBuilder().mailbox(b.agents["robot1"], channel="radio")  # an agent of another builder


def test_an_unknown_mailbox_is_refused():
    b = NetBuilder()
    a = b.agent("a")
    a.place("p")
    t = a.transition("t", inputs=["p"])
    other = NetBuilder()
    stranger = other.mailbox(other.agent("a"), channel="radio")
    with pytest.raises(UnknownElementError, match="unknown mailbox 'a_box'"):
        b.receive(t, stranger)
    with pytest.raises(UnknownElementError, match="unknown mailbox 'box'"):
        b.send(t, "box")


@pytest.mark.parametrize("make", [
    lambda b, a: a.place("start"),
    lambda b, a: a.transition("start"),
    lambda b, a: b.agent("a"),
    lambda b, a: b.mailbox(a, "start", channel="radio"),
    lambda b, a: b.mailbox(a, channel="radio", slot="a_start"),
    lambda b, a: b.envelope(source="a_start"),
], ids=["place", "transition", "agent", "mailbox", "slot", "envelope"])
def test_duplicate_ids_are_refused(make):
    b = NetBuilder()
    a = b.agent("a")
    a.place("start")
    with pytest.raises(NetStructureError, match="duplicate (subnet )?id '(a_start|a)'"):
        make(b, a)


def test_a_second_envelope_and_double_registrations_are_refused():
    b = NetBuilder()
    a = b.agent("a")
    a.place("s")
    a.start("s")
    with pytest.raises(NetStructureError, match="'a_s' is already handed out by the envelope's begin"):
        b.start("a_s")
    box = b.mailbox(a, channel="radio")
    with pytest.raises(NetStructureError, match="'a_box_slot' is already collected by the envelope's end"):
        b.done(box.slot)
    b.envelope()
    with pytest.raises(NetStructureError, match="envelope already"):
        b.envelope(begin="b2", end="e2", source="i2", sink="o2")


@pytest.mark.parametrize("capacity", [0, -1, 1.5, True, "2"])
def test_a_capacity_below_one_or_not_whole_is_refused(capacity):
    b = NetBuilder()
    with pytest.raises(NetStructureError, match=r"mailbox 'a_box': capacity must be a whole number >= 1"):
        b.mailbox(b.agent("a"), channel="radio", capacity=capacity)
    assert "a_box" not in b.build().places


def test_sending_twice_and_empty_broadcasts_are_refused():
    b = NetBuilder()
    a = b.agent("a")
    a.place("p")
    t = a.transition("t", inputs=["p"])
    box = b.mailbox(a, channel="radio")
    with pytest.raises(NetStructureError, match="at least one mailbox"):
        b.broadcast(t, [])
    with pytest.raises(NetStructureError, match="mailbox 'a_box' is named twice"):
        b.broadcast(t, [box, box])
    b.send(t, box)
    with pytest.raises(NetStructureError, match="'a_t' already sends to mailbox 'a_box'"):
        b.send(t, box)


def test_what_a_net_file_could_not_hold_is_refused():
    """Parameters and attributes a net file cannot hold exactly are refused up front, so
    every built net round-trips."""
    b = NetBuilder()
    a = b.agent("a")
    with pytest.raises(NetStructureError, match=r"'a_t': params: 'xs' must be text, a number.*got tuple"):
        a.transition("t", params={"xs": (1, 2)})
    with pytest.raises(NetStructureError, match=r"'a_t': params: key 1 must be text"):
        a.transition("t", params={1: "one"})
    with pytest.raises(NetStructureError, match="priority must be a whole number"):
        a.transition("t", priority=1.5)
    with pytest.raises(NetStructureError, match="unknown outcome 'fail'"):
        a.transition("t", outcomes={"fail": []})
    a.place("p")
    with pytest.raises(NetStructureError, match="weight of 'a_p' must be a whole number >= 1"):
        a.transition("t", inputs={"p": 0})
    with pytest.raises(NetStructureError, match="label must be text or None, got 5"):
        a.transition("t", label=5)
    with pytest.raises(NetStructureError, match="'a_q': tokens must be a whole number >= 0, got -1"):
        a.place("q", tokens=-1)
    with pytest.raises(NetStructureError, match="an agent's name must be a non-empty string"):
        b.agent("")
    net = b.build()
    assert list(net.transitions) == [] and list(net.places) == ["a_p"] and list(net.subnets) == ["a"]


# The comm scenario, built with the API ----------------------------------------------


def test_the_comm_builders_net_built_with_the_api_is_sound():
    from petriflow.agents.comm.nets import build

    result = check_net(build(2))
    assert result["sound"] and result["k_bound"]["box_robot1_robot2"] == 1


@pytest.mark.parametrize("envelope", [True, False])
def test_a_mailbox_of_capacity_senders_has_a_slot_per_sending_agent(envelope):
    """capacity="senders": the slot tokens are counted when the net is built, one per
    agent with a transition that sends into the mailbox (two sends of one agent count
    once; a transition outside every agent counts alone), with or without an envelope."""
    b = NetBuilder("team")
    receiver, a, c = b.agent("receiver"), b.agent("a"), b.agent("c")
    box = b.mailbox(receiver, channel="lan", capacity="senders")
    assert box.capacity == "senders"
    for agent, name in ((a, "one"), (a, "two"), (c, "one")):
        agent.place(f"{name}_ready")
        b.send(agent.transition(f"send_{name}", inputs=[f"{name}_ready"]), box)
    b.place("outside_ready")
    b.send(b.transition("outside", inputs=["outside_ready"]), box)
    b.agent("d").place("idle")  # sends nothing
    if envelope:
        b.envelope()
    net = b.build()
    if envelope:
        assert net.postset("begin")[box.slot] == 3 and net.preset("end")[box.slot] == 3
    else:
        assert net.initial_marking[box.slot] == 3
