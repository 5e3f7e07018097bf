"""Seed 000's nets: sound, fireable transition by transition, and the mission end to end."""

from __future__ import annotations

import pytest

from petriflow import examples
from petriflow.agents.comm.nets import build
from petriflow.analysis.report import check_net
from petriflow.io import load_net
from petriflow.runtime.config import load_config
from petriflow.runtime.scheduler import Scheduler
from petriflow.world import load_world

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")

SHIPPED = [(2, "decentralised", False), (2, "centralised", False), (3, "decentralised", False),
           (3, "centralised", False), (3, "decentralised", True)]


def fire(net, transition, tokens, *, states=None, world=None, config=None, timeout=60.0):
    """Fire one transition with its real action, the agents' states given (``{agent:
    CommAgent}``): ``(result, events, scheduler)``. (``petriflow.testing.fire_one`` takes
    token data only; the states are the run's, not tokens.)"""
    scheduler = Scheduler(net, world=world, config=config, seed=0)
    scheduler.set_tokens({p: list(v) for p, v in tokens.items()})
    agents = scheduler.firer.agents
    for agent, state in (states or {}).items():
        agents.set_state(agent, state, scheduler.index.state_type.get(agent))
    events = []
    scheduler.on_event(events.append)
    with scheduler:
        result = scheduler.fire_one(transition, timeout=timeout)
    return result, events, scheduler


def outcome(events, transition):
    return [e.data["outcome"] for e in events if e.kind == "end" and e.transition == transition][-1]


@pytest.mark.parametrize("robots, mode, monitor", SHIPPED[:3])
def test_generated_nets_are_sound_workflow_nets(robots, mode, monitor):
    result = check_net(build(robots, mode, monitor))
    assert result["workflow_net"] and result["sound"], result["violations"]


@pytest.mark.parametrize("robots, mode, monitor", SHIPPED)
def test_shipped_nets_are_the_builders(robots, mode, monitor):
    built = build(robots, mode, monitor)
    built.run = "run.yaml"
    shipped = load_net(examples.path("comm", f"{built.id}.yaml"))
    assert shipped.structure() == built.structure()
    assert {s.state for s in shipped.subnets.values()} == {"comm.agent"}


def test_tokens_of_the_work_loop_carry_no_state():
    """The state is the run's (ctx.state): the loop, listening and done places hold plain tokens."""
    from petriflow.runtime.session import run_files

    outcome = run_files(examples.path("comm", "comm-decentralised-2.yaml"), keep_events=True, until=60)
    carried = [e for e in outcome.events if e.kind in ("start", "end") and e.agent is not None
               and (e.data.get("inputs") or e.data.get("result") is not None)
               and not str(e.transition).split("_", 1)[1].startswith("receive")]
    assert carried == []  # only a receive takes data: the packet from its channel place


def test_the_start_up_transitions_one_by_one():
    net = load_net(examples.path("comm", "comm-decentralised-2.yaml"))
    config = load_config(examples.path("comm", "run.yaml"))
    world = load_world(examples.path("comm", "world.yaml"))
    try:
        _, events, run = fire(net, "robot1_characterise", {"robot1_start": [None]}, world=world, config=config)
        assert outcome(events, "robot1_characterise") == "ok"
        state = run.firer.agents.state("robot1")  # ctx.state, kept by the run
        assert state.robot is not None and state.explorer.cell == (0, 0)
        assert [e.data["data"]["pg"] for e in events if e.kind == "custom"] == [[318, 318]]
        _, events, _ = fire(net, "robot1_analyse", {"robot1_c1": [None]}, states={"robot1": state}, world=world,
                            config=config)
        report = [e.data["data"] for e in events if e.kind == "custom"][0]
        assert report["lossless_behind_wall_m"] == 7 and report["range_m"] == pytest.approx(2.0)
        fire(net, "robot1_initialise", {"robot1_c2": [None]}, states={"robot1": state}, world=world, config=config)
        assert state.address == 2 and state.peers["robot2"].box == "box_robot1_robot2"
        result, _, _ = fire(net, "robot1_history", {"robot1_c3": [None]}, states={"robot1": state}, world=world,
                            config=config)
        assert result.tokens == {"robot1_idle": [None], "robot1_listen": [None]}
        _, events, _ = fire(net, "robot1_step", {"robot1_idle": [None]}, states={"robot1": state}, world=world,
                            config=config)
        assert outcome(events, "robot1_step") == "ok" and state.vertices  # it drove to its cell and mapped a vertex
    finally:
        world.close()


def test_decentralised_mission_maps_the_whole_maze():
    from petriflow.runtime.session import run_files
    from petriflow.runtime.metrics import RunRecord
    from petriflow.agents.comm import metrics

    outcome = run_files(examples.path("comm", "comm-decentralised-2.yaml"), keep_events=True)
    assert outcome.result.reason == "final"
    world = load_world(examples.path("comm", "world.yaml"))
    try:
        record = RunRecord(outcome.result, outcome.events, world)
        assert metrics.maps_complete(record) == 1.0
        assert 0 < metrics.time_s(record) <= outcome.result.time
        sent = metrics.bytes_per_agent(record)
        assert set(sent) == {"robot1", "robot2"} and all(v % 5 == 0 and v > 0 for v in sent.values())
    finally:
        world.close()


def trial_metrics(table: str, row: int) -> tuple[dict, dict]:
    from petriflow.sweep import load_sweep
    from petriflow.sweep.trial import run_trial

    sweep = load_sweep(examples.path("comm", f"experiments/{table}.yaml"))
    trial = [t for t in sweep.trials() if t.row == row][0]
    result = run_trial(sweep.payload(trial))
    assert result["status"] == "ok", result["error"]
    return result["metrics"], trial.params


def test_a_broken_down_robot_leaves_the_decentralised_survivors_with_the_whole_map():
    metrics, params = trial_metrics("table8-breakdown", 0)
    assert params["breakdown"] == "robot3" and params["fail_at"] == 110
    assert metrics["maps_complete"] == 1.0                  # robot1 and robot2, the working agents
    assert metrics["complete_per_agent.robot3"] == 0        # nobody drives to it: its map lacks vertices (Fig. 11)


def test_a_failed_central_unit_leaves_every_robot_with_a_partial_map():
    metrics, params = trial_metrics("table8", 0)
    assert params["fail_at"] == 110
    assert metrics["maps_complete"] == 0.0


@pytest.mark.slow
def test_a_late_monitor_relays_to_the_broken_down_robot():
    metrics, params = trial_metrics("table9", 0)
    assert params["monitor"] is True
    assert metrics["bytes_per_agent.monitor1"] > 0          # it joined, got data and passed it on
    assert metrics["complete_per_agent.robot3"] == 1        # robot3, which cannot move, holds the whole map


def test_each_agents_map_is_drawn_with_its_missing_vertices(tmp_path):
    from petriflow.agents.comm.maps import draw_maps
    from petriflow.agents.comm.nets import world
    from petriflow.runtime.trace import Event

    maze = world()["meta"]["maze"]
    events = [Event(0, 1.0, "custom", None, "robot1", {"name": "comm.learnt", "data": {"ids": [0, 1]}}),
              Event(1, 2.0, "custom", None, "robot2", {"name": "comm.learnt", "data": {"ids": list(range(36))}})]
    lacking = draw_maps(events, maze, tmp_path / "maps.png")
    assert lacking["robot2"] == 0 and lacking["robot1"] == 24 - len({0, 1} & set(range(36)) & _vertex_ids(maze))
    assert (tmp_path / "maps.png").stat().st_size > 10_000


def _vertex_ids(maze_meta) -> set[int]:
    from petriflow.agents.mobile.maze import from_meta

    maze = from_meta(maze_meta)
    return {r * maze.cols + c for r, c in maze.vertices()}


def test_send_and_receive_move_one_message_through_the_channel_place():
    from petriflow.agents.comm.agent import CommAgent, Peer
    from petriflow.agents.comm.framework import History, Packet
    from petriflow.runtime.channel_models import Message

    net = load_net(examples.path("comm", "comm-decentralised-2.yaml"))
    config = load_config(examples.path("comm", "run.yaml"))
    sender = CommAgent("robot1", "robot", address=2, history=History(2))
    sender.peers["robot2"] = Peer("robot2", 128, "box_robot1_robot2")
    sender.hear({"robot2"})
    sender.queue(Packet(3, 2, 1, 2, 128, [(0, 0.4, 0.4)]))
    sent, events, _ = fire(net, "robot1_send_robot2", {"robot1_out": [None], "slot_robot1_robot2": [None]},
                           states={"robot1": sender}, config=config)
    assert outcome(events, "robot1_send_robot2") == "ok" and sent.marking["robot1_out"] == 1
    assert sent.tokens["robot1_out"] == [None]  # the loop's token carries nothing
    on_air = [e.data for e in events if e.kind == "message"]
    assert on_air[0]["fate"] == "sent" and on_air[0]["size"] == 8 and on_air[0]["receiver"] == "robot2"
    assert not sender.outbox["robot2"]
    packet = {"size": 8, "payload": 5, "code": 3,
              "message": Message(None, "robot1", "robot2", Packet(3, 2, 1, 2, 128, [(0, 0.4, 0.4)]))}
    receiver = CommAgent("robot2", "robot", address=128, history=History(128))
    receiver.peers["robot1"] = Peer("robot1", 2, "box_robot2_robot1")
    got, events, _ = fire(net, "robot2_receive_robot1", {"box_robot1_robot2": [packet], "robot2_listen": [None]},
                          states={"robot2": receiver}, config=config)
    assert outcome(events, "robot2_receive_robot1") == "ok"
    assert got.marking["slot_robot1_robot2"] == 1 and got.tokens["robot2_listen"] == [None]  # the slot goes back
    assert receiver.vertices == {0: (0.4, 0.4)}


def test_a_send_is_not_enabled_while_nothing_waits_or_the_peer_is_not_heard():
    from petriflow.agents.comm.agent import CommAgent, Peer
    from petriflow.agents.comm.framework import History, Packet

    net = load_net(examples.path("comm", "comm-decentralised-2.yaml"))
    sender = CommAgent("robot1", "robot", address=2, history=History(2))
    sender.peers["robot2"] = Peer("robot2", 128, "box_robot1_robot2")
    run = Scheduler(net, seed=0)
    run.set_tokens({"robot1_out": [None], "slot_robot1_robot2": [None]})
    run.firer.agents.set_state("robot1", sender, CommAgent)
    assert "robot1_send_robot2" not in run.enabled()
    sender.queue(Packet(3, 2, 1, 2, 128, [(0, 0.4, 0.4)]))  # waiting, but robot2 not heard
    assert "robot1_send_robot2" not in run.enabled()
    sender.hear({"robot2"})  # touches outbox/robot2: the kept answer is forgotten
    assert "robot1_send_robot2" in run.enabled()


def test_walls_between_two_agents_are_counted_by_ray_tests():
    from petriflow.agents.comm.radio import RadioChannel
    from petriflow.world import World

    world = World({"plane": True, "gravity": 0.0,
                   "boxes": [{"id": "w1", "size": [0.04, 2, 0.3], "position": [1, 0, 0.15]},
                             {"id": "w2", "size": [0.04, 2, 0.3], "position": [2, 0, 0.15]}],
                   "robots": [{"id": "a", "urdf": "petriflow.agents:robots/diffdrive.urdf", "position": [0.5, 0]},
                              {"id": "b", "urdf": "petriflow.agents:robots/diffdrive.urdf", "position": [1.5, 0]},
                              {"id": "c", "urdf": "petriflow.agents:robots/diffdrive.urdf", "position": [2.5, 0]}]})
    try:
        radio = RadioChannel()
        radio.bind(world)
        assert radio.between("a", "b")[1] == 1 and radio.between("a", "c")[1] == 2
        assert radio.link_rssi("a", "b") == pytest.approx(radio.rssi(1.0) - 3.0, abs=0.05)
        radio.gains_db = {"c": 20}
        assert radio.link_rssi("a", "c") == pytest.approx(radio.rssi(2.0) - 6.0 + 20, abs=0.05)
    finally:
        world.close()
