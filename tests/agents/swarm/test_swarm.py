"""The swarm scenario: its nets are sound and linear in the team, its history is seed
000's, its radio broadcasts to the robots in range, and a mission runs to the end."""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from petriflow.agents.comm.framework import History, plan
from petriflow.agents.swarm.agent import OPEN, Scout, SwarmHistory
from petriflow.agents.swarm.nets import build, world
from petriflow.analysis.report import check_net
from petriflow.io import load_net
from petriflow.runtime.scheduler import Scheduler
from petriflow.world import World

NETS = Path(__file__).resolve().parents[3] / "nets" / "swarm"


def test_the_three_robot_net_is_sound_and_the_shipped_one_is_what_build_writes():
    net = build(3)
    result = check_net(net)
    assert result["workflow_net"] and result["sound"]
    shipped = load_net(NETS / "swarm-3.yaml")
    assert sorted(shipped.transitions) == sorted(net.transitions)
    assert sorted(shipped.places) == sorted(net.places)


def test_the_net_grows_linearly_with_the_team():
    small, large = build(10), build(100)
    assert len(large.transitions) - 2 == 10 * (len(small.transitions) - 2)
    assert len(large.places) - 2 == 10 * (len(small.places) - 2)


def test_the_swarm_history_follows_seed_000s_rules_exactly():
    rng = random.Random(3)
    plain, indexed = History(1), SwarmHistory(1)
    for step in range(400):
        kind = rng.random()
        peer, source = rng.randint(2, 6), rng.randint(1, 6)
        if kind < 0.3:
            item = (rng.randint(0, 50), 0.5, 0.5, 1)
            assert plain.add_own(item) == indexed.add_own(item)
        elif kind < 0.6:
            items = [(rng.randint(0, 50), 0.5, 0.5, 2) for _ in range(rng.randint(1, 3))]
            assert plain.receive(peer, source, items) == indexed.receive(peer, source, items)
        else:
            assert plain.unsent(peer, source) == indexed.unsent(peer, source)
            items = plain.unsent(peer, source)[:2]
            plain.sent(peer, source, items)
            indexed.sent(peer, source, items)
        assert plain.rows == indexed.rows
        assert plain.outgoing(peer) == indexed.outgoing(peer)


def test_the_swarm_history_plans_what_seed_000s_plans_over_long_exchanges():
    """Algorithm 1 over both histories, for every peer after every operation: the same
    packets, the same rows, what each peer holds the same (the shortcuts the swarm's
    history takes must not show)."""
    rng = random.Random(11)
    plain, indexed = History(1), SwarmHistory(1)
    peers = range(2, 9)
    for step in range(1500):
        kind = rng.random()
        peer, source = rng.choice(peers), rng.randint(1, 8)
        if kind < 0.2:
            item = (rng.randint(0, 80), 0.5, 1.5, rng.randint(0, 15))
            assert plain.add_own(item) == indexed.add_own(item)
        elif kind < 0.5:
            items = [(rng.randint(0, 80), 0.5, 1.5, rng.randint(0, 15)) for _ in range(rng.randint(1, 6))]
            assert plain.receive(peer, source, items) == indexed.receive(peer, source, items)
        elif kind < 0.75:  # a plan goes out as Algorithm 1 says, and the items sent are noted
            planned = [(m.code, m.source, m.count, m.vertices) for m in plan(plain, peer)]
            assert planned == [(m.code, m.source, m.count, m.vertices) for m in plan(indexed, peer)]
            for code, src, _, vertices in planned:
                if code == 3:
                    plain.sent(peer, src, list(vertices))
                    indexed.sent(peer, src, list(vertices))
        else:  # a request answered
            chosen = plain.unsent(peer, source)[:rng.randint(1, 4)]
            assert chosen == indexed.unsent(peer, source)[:len(chosen)]
            if chosen:
                plain.sent(peer, source, chosen)
                indexed.sent(peer, source, chosen)
        assert plain.rows == indexed.rows
        assert plain.held == indexed.held
        for other in peers:
            for src in range(1, 9):
                assert (plain.pending(other, src), plain.sent_count(other, src), plain.count_for(other, src)) == \
                    (indexed.pending(other, src), indexed.sent_count(other, src), indexed.count_for(other, src))
    assert plain.data == indexed.data


def _exchange(a: Scout, b: Scout, rounds: int = 4) -> None:
    """Frames between two scouts in range, both ways, a few rounds."""
    for _ in range(rounds):
        a.plan_for(b.name, b.address)
        b.plan_for(a.name, a.address)
        for sender, receiver in ((a, b), (b, a)):
            frame = sender.frame()
            for packet in frame["to"].get(receiver.name, []):
                receiver.receive(sender.name, sender.address, packet)


def test_two_scouts_end_with_each_others_maps_and_nothing_more_to_say():
    a, b = Scout("robot1", 1, cols=4, rows=4), Scout("robot2", 2, cols=4, rows=4)
    a.sense(0, OPEN["north"])
    a.sense(4, OPEN["south"] | OPEN["east"])
    b.sense(15, OPEN["west"])
    _exchange(a, b)
    assert set(a.sides) == set(b.sides) == {0, 4, 15}
    assert a.sides[15] == OPEN["west"] and b.sides[4] == OPEN["south"] | OPEN["east"]
    sent = a.sent_bytes + b.sent_bytes
    b.sense(14, OPEN["east"])                       # new data: it goes by query, request, transfer
    _exchange(a, b)
    assert 14 in a.sides and a.sent_bytes + b.sent_bytes > sent
    a.plan_for(b.name, b.address)
    assert not any(a.outbox.values())               # nothing pending: nothing sent again


def _mission(robots: int, until: float = 900.0, tiles: int = 1):
    from petriflow.runtime.config import load_config

    config = load_config(NETS / "run.yaml")
    description = world(robots, tiles=tiles)
    w = World(description, base=NETS)
    scheduler = Scheduler(build(robots, tiles=tiles), world=w, config=config, seed=1)
    events = []
    scheduler.on_event(events.append)
    with scheduler:
        result = scheduler.run(until=until)
    return result, events, description, w, scheduler


def test_a_small_swarm_maps_its_maze_shares_it_and_goes_home():
    result, events, description, w, scheduler = _mission(6)
    try:
        assert result.reason.value == "final"
        cells = description["meta"]["maze"]["rows"] * description["meta"]["maze"]["cols"]
        sensed = {e.data["data"]["cell"] for e in events if e.kind == "custom" and e.data["name"] == "swarm.sensed"}
        assert len(sensed) >= 0.9 * cells
        homes = {e.agent for e in events if e.kind == "custom" and e.data["name"] == "swarm.home"}
        assert homes == {f"robot{k}" for k in range(1, 7)}
        sent = [e for e in events if e.kind == "message" and e.data["fate"] == "sent"]
        assert sent and sum(e.data["size"] for e in sent) > 0
        # every robot stands on its start cell again, exactly on the centre
        for body in description["robots"]:
            x, y, _ = w.pose(body["id"])
            assert (x, y) == pytest.approx(tuple(body["position"]), abs=1e-6)
        # the maps were shared: robots know cells they never sensed, and hold others' data
        states = scheduler.firer.agents.states
        learnt = [len(set(s.sides) - s.sensed) for s in states.values()]
        assert sum(n > 0 for n in learnt) >= 4
        assert all(s.history.count(s.address) == len(s.sensed) for s in states.values())
        assert sum(len(s.history.sources()) > 1 for s in states.values()) >= 4
    finally:
        w.close()


def test_tiles_repeat_one_teams_mission_each_in_its_own_maze():
    """Two tiles of three robots: each runs the 3-robot mission, its cells shifted north
    by the tiles' pitch; no frame crosses from one tile to the other."""
    from petriflow.agents.swarm.metrics import coverage
    from petriflow.runtime.metrics import RunRecord

    def per_robot(events, kind):
        out: dict[str, list] = {}
        for e in events:
            if e.kind == "custom" and e.data["name"] == kind:
                out.setdefault(e.agent, []).append(e.data["data"]["cell"])
            if kind == "sent" and e.kind == "message" and e.data["fate"] == "sent":
                out.setdefault(e.agent, []).append(e.data["size"])
        return out

    one, events1, description1, w1, _ = _mission(3)
    two, events2, description2, w2, scheduler = _mission(6, tiles=2)
    try:
        assert one.reason.value == two.reason.value == "final" and two.time == one.time
        meta = description2["meta"]
        shift = meta["tiles"]["pitch_rows"] * meta["maze"]["cols"]
        ids = [b["id"] for b in description2["boxes"]]
        assert len(ids) == len(set(ids)) == 2 * len(description1["boxes"])
        sensed1, sensed2 = per_robot(events1, "swarm.sensed"), per_robot(events2, "swarm.sensed")
        sent1, sent2 = per_robot(events1, "sent"), per_robot(events2, "sent")
        for k in range(1, 4):
            first, second = f"robot{k}", f"robot{k + 3}"
            assert sensed2[first] == sensed1[first] and sent2[first] == sent1[first]
            assert sensed2[second] == [cell + shift for cell in sensed1[first]] and sent2[second] == sent1[first]
        states = scheduler.firer.agents.states
        for name, state in states.items():   # what a robot heard of came from its own tile only
            tile = (int(name[5:]) - 1) // 3
            assert {(int(other[5:]) - 1) // 3 for other in state.names.values()} <= {tile}
        covered = [coverage(RunRecord(events=events, world=w, result=result))
                   for events, w, result in ((events1, w1, one), (events2, w2, two))]
        assert covered[0] == covered[1] > 0.9
    finally:
        w1.close()
        w2.close()


@pytest.mark.parametrize("robots, tiles", [(10, 3), (10, 0), (4, 8)])
def test_tiles_that_do_not_cut_the_team_evenly_are_refused(robots, tiles):
    with pytest.raises(ValueError, match="tiles must divide"):
        world(robots, tiles=tiles)
    with pytest.raises(ValueError, match="tiles must divide"):
        build(robots, tiles=tiles)


def test_the_radio_reaches_only_the_robots_in_range():
    from petriflow.agents.swarm.radio import SwarmRadio
    from petriflow.runtime.channels import Message
    from petriflow.runtime.kernel import Kernel
    from petriflow.runtime.media import MediumPort, ProcessClock

    robots = [{"id": f"robot{k}", "urdf": "petriflow.agents:robots/diffdrive.urdf", "position": [x, 0.5]}
              for k, x in ((1, 0.5), (2, 3.5), (3, 9.5))]
    w = World({"dt": 0.1, "gravity": 0.0, "mode": "kinematic", "robots": robots})
    try:
        delivered = []
        port = MediumPort(ProcessClock(Kernel(dt=0.1)), delivered.append, lambda m, why: None, None, w)
        radio = SwarmRadio()
        radio.attach(port)
        assert radio.view("robot1").neighbours() == [("robot2", 2)]     # 3 m: heard; 9 m: beyond 5 m
        assert radio.view("robot3").neighbours() == []
        frame = {"to": {"robot2": [(3, 1, 1, False, [])], "robot3": [(3, 1, 1, False, [])]}, "size": 10, "from": 1}
        radio.send(Message("robot1_air", "robot1", "robot1", frame, 0.0, 10))
        port.clock.run(until=0.1)
        assert [m.data["heard"] for m in delivered] == [1]
        assert radio.view("robot2").take() == [("robot1", 1, (3, 1, 1, False, []))]
        assert radio.view("robot3").take() == [] and radio.view("robot2").take() == []
    finally:
        w.close()


def test_the_scale_sweep_builds_every_row_and_runs_its_small_one():
    from petriflow.io.files import read_yaml_file
    from petriflow.sweep import load_sweep
    from petriflow.sweep.trial import build as build_trial, run_trial

    sweep = load_sweep(NETS / "experiments" / "scale.yaml")
    trials = sweep.trials()
    assert [t.params["robots"] for t in trials] == [10, 100, 1000]
    assert {ref.name for ref in sweep.metrics} == {"coverage", "bytes_total", "time_s", "completed",
                                                   "cpu_s_per_sim_s"}
    for trial in trials:
        built = build_trial(sweep.payload(trial)["sweep"], trial.params, trial.seed)
        description = read_yaml_file(built.config.world)
        assert description["mode"] == "kinematic"
        assert [r["id"] for r in description["robots"]] == [
            f"robot{k}" for k in range(1, trial.params["robots"] + 1)]
        assert description == world(trial.params["robots"])   # the shipped world is what world() writes
    result = run_trial(sweep.payload(trials[0]))
    assert result["status"] == "ok" and result["outcome"] == "final", result
    metrics = result["metrics"]
    assert metrics["completed"] == 1 and metrics["coverage"] > 0.9 and metrics["bytes_total"] > 0
    assert 0 < metrics["time_s"] <= 1800 and metrics["cpu_s_per_sim_s"] > 0
