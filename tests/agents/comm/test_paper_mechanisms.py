"""Seed 000's mechanisms that bring the mission closer to the paper: the central unit's
history per recipient, the robots' speed from the paper's figures, the central unit's
link by the adapter's lossless limit, a robot that breaks down with its radio on, the
place where two robots last talked, and the metrics that tell working agents from
broken ones."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from petriflow.agents.comm.agent import CommAgent, Peer, vertex_id
from petriflow.agents.comm.framework import History, Message
from petriflow.agents.comm.metrics import complete_per_agent, maps_complete, time_s
from petriflow.agents.comm.nets import SPEED, build
from petriflow.agents.comm.radio import RadioChannel
from petriflow.agents.mobile.explore import Explorer
from petriflow.runtime.trace import Event


def central_unit() -> CommAgent:
    central = CommAgent("central", "central", address=129, history=History(129, identity=vertex_id))
    central.peers = {name: Peer(name, address, f"box_central_{name}")
                     for name, address in (("robot1", 2), ("robot2", 85), ("robot3", 170))}
    return central


def forwarded(agent: CommAgent, peer: str) -> list[int]:
    """Vertex ids queued for ``peer`` by one plan towards it."""
    agent.plan_for(agent.peers[peer])
    return sorted(v[0] for m in agent.outbox.get(peer, ()) for v in m.vertices)


def test_the_central_unit_forwards_each_robot_only_the_vertices_it_lacks():
    central = central_unit()
    central.receive(Message(3, 2, 2, 2, 129, [(5, 0.4, 0.4), (6, 1.2, 0.4)]))        # robot1 mapped 5 and 6
    central.receive(Message(3, 85, 2, 85, 129, [(5, 0.41, 0.39), (7, 2.1, 0.4)]))    # robot2 mapped 5 too, and 7
    assert forwarded(central, "robot1") == [7]           # robot1 holds 5 (its own): not sent again under robot2's name
    assert forwarded(central, "robot2") == [6]           # and robot2 holds 5 too
    assert forwarded(central, "robot3") == [5, 6, 7]     # robot3 lacks all three: 5 goes once
    central.outbox.clear()
    assert forwarded(central, "robot3") == []            # nothing is pending for robot3 any more
    central.receive(Message(3, 170, 1, 170, 129, [(8, 0.4, 4.6)]))
    assert forwarded(central, "robot1") == [8] and forwarded(central, "robot2") == [8]


def test_a_header_count_towards_a_peer_leaves_out_what_it_holds_under_another_source():
    history = History(129, identity=vertex_id)
    history.receive(2, 2, [(5, 0.4, 0.4), (6, 1.2, 0.4)])
    history.receive(85, 85, [(5, 0.41, 0.39), (7, 2.1, 0.4)])
    assert history.count_for(2, 85) == 1      # robot1 needs only vertex 7 of robot2's two to hold them all
    assert history.count_for(170, 85) == 2
    plain = History(129)                      # without identity: the paper's per-source history, as before
    plain.receive(2, 2, [(5, 0.4, 0.4)])
    plain.receive(85, 85, [(5, 0.41, 0.39)])
    assert plain.count_for(2, 85) == 1 and [s for s, _, _ in plain.outgoing(2)] == [85]


def test_a_robot_does_not_explore_cells_the_central_unit_reported():
    explorer = Explorer((0, 0))
    explorer.sense((0, 0), ["north", "east"])
    explorer.learn([(1, 0)])                  # what comm.receive does with a reported vertex (cell id // cols)
    assert explorer.next_cell() == (0, 1)


def test_a_robot_that_breaks_down_says_so_and_is_not_waited_for():
    robot3 = CommAgent("robot3", "robot", address=170, history=History(170), broken=True)
    robot3.peers["robot1"] = Peer("robot1", 2, "box_robot3_robot1")
    robot3.history.add_own((30, 0.4, 4.6))
    robot3.final[170] = 1
    robot3.plan_for(robot3.peers["robot1"])
    sent = robot3.take("robot1")
    assert sent.stopped and sent.encode()[0] & 0x40       # the header's bit after the final flag
    robot1 = CommAgent("robot1", "robot", address=2, history=History(2))
    robot1.peers["robot3"] = Peer("robot3", 170, "box_robot1_robot3")
    robot1.receive(sent)
    robot1.history.add_own((0, 0.4, 0.4))
    robot1.final[2] = 1
    assert robot1.stopped == {"robot3"}
    assert robot1.untold() == []              # it cannot come: nobody drives to tell it


def test_where_two_robots_talked_is_kept_as_a_place_to_meet_again():
    explorer = Explorer((0, 0))
    explorer.sense((0, 0), ["north"])
    explorer.sense((1, 0), ["south"])
    robot = SimpleNamespace(pose=(0.4, 1.2, 0.0))     # in cell (1, 0) of 5/6 m cells
    state = CommAgent("robot1", "robot", address=2, history=History(2), robot=robot, explorer=explorer,
                      cell=5 / 6)
    state.met("robot2")
    assert state.met_at == {"robot2": (1, 0)}
    robot.pose = (2.0, 2.0, 0.0)                      # a cell it never sensed: the last one it did
    state.met("robot2")
    assert state.met_at == {"robot2": (1, 0)}


def test_the_central_units_links_reach_as_far_as_the_adapter_loses_no_frame():
    radio = RadioChannel(adapter_limit=["central"])
    assert radio.limit_dbm("robot1", "robot2") == radio.threshold_dbm
    assert radio.limit_dbm("robot1", "central") == radio.limit_dbm("central", "robot1") == radio.lossless_dbm
    # Fig. 5: nothing lost 7 m behind the concrete wall, frames lost at 8 m
    assert radio.rssi(8.0) - radio.concrete_db < radio.lossless_dbm < radio.rssi(7.0) - radio.concrete_db
    assert radio.gains_db == {}               # no antenna gain the paper does not document


def test_the_builder_takes_the_speed_from_the_paper_and_a_breakdown_as_a_parameter():
    rows = [(30.5, 472.46), (23.84, 457.29), (34.90, 561.58), (28.97, 535.97), (18.63, 289.09), (23.85, 447.69),
            (7.94, 133.56), (18.63, 297.14), (29.20, 523.93), (9.63, 169.96), (30.5, 472.46), (23.85, 447.69),
            (33.3, 484.35), (6.67, 109.70)]   # Tables 6-8: distance (m), time (s) of every robot row
    speeds = sorted(d / t for d, t in rows)
    assert speeds[0] <= SPEED <= speeds[-1] and abs(SPEED - speeds[len(speeds) // 2]) < 0.005
    net = build(3, "decentralised", breakdown="robot3", fail_at=110)
    assert net.transitions["robot3_step"].params["stop_at"] == 110.0
    assert "stop_at" not in net.transitions["robot1_step"].params
    assert net.transitions["robot1_step"].params["meet"] is True
    assert build(3, "centralised").transitions["robot1_step"].params["meet"] is False  # they wait for the relay
    with pytest.raises(ValueError, match="breakdown names no robot"):
        build(2, "decentralised", breakdown="robot3")


def _record(events):
    from petriflow.agents.comm.nets import world
    from petriflow.runtime.metrics import RunRecord

    maze = world()["meta"]["maze"]
    return RunRecord(events=events, world=SimpleNamespace(meta={"maze": maze}, path=None),
                     result=SimpleNamespace(time=events[-1].time))


def test_a_broken_down_robot_is_not_counted_as_a_working_agent():
    from petriflow.agents.comm.metrics import truth

    whole = sorted(truth(_record([Event(0, 0.0, "custom", None, "robot1", {"name": "x", "data": {}})])))

    def custom(n, time, agent, name, data):
        return Event(n, time, "custom", None, agent, {"name": name, "data": data})

    events = [custom(0, 0.0, "robot1", "comm.characterised", {}), custom(1, 0.0, "robot3", "comm.characterised", {}),
              custom(2, 110.0, "robot3", "comm.broken", {"distance_m": 6.0}),
              custom(3, 120.0, "robot3", "comm.learnt", {"ids": whole[:3]}),
              custom(4, 500.0, "robot1", "comm.learnt", {"ids": whole})]
    record = _record(events)
    assert maps_complete(record) == 1.0                  # robot1, the only working agent, holds the map
    assert time_s(record) == 500.0
    assert complete_per_agent(record) == {"robot1": 1, "robot3": 0}
