"""Seed 004's mission as a net: soundness, single transitions, whole missions,
breakdowns and the teammate filter."""

from __future__ import annotations

import pytest
import yaml

from petriflow import examples
from petriflow.agents.bidding.auction import autonomous
from petriflow.agents.bidding.nets import build
from petriflow.agents.bidding.office import paper_office
from petriflow.analysis import check_net
from petriflow.io import load_net
from petriflow.io.yaml import loads_net
from petriflow.runtime.config import load_config
from petriflow.testing import fire_one
from petriflow.world import World

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")


@pytest.mark.parametrize("robots", [1, 2, 3, 4, 5])
def test_nets_are_sound_workflow_nets(robots):
    for deployment in ("autonomous", "random"):
        result = check_net(loads_net(build(robots, deployment)))
        assert result["workflow_net"] and result["sound"], result["violations"]


def test_shipped_nets_are_the_builders():
    shipped = load_net(examples.path("bidding", "bidding-autonomous-3.yaml"))
    assert shipped.structure() == loads_net("run: run.yaml\n" + build(3, "autonomous")).structure()


def test_builder_refuses_nonsense():
    with pytest.raises(ValueError, match="deployment"):
        build(2, "greedy")
    with pytest.raises(ValueError, match="robots"):
        build(0)


def _run(tmp_path, robots=2, deployment="autonomous", faults=(), **options):
    from petriflow.runtime.session import run_files

    net = tmp_path / "net.yaml"
    net.write_text(build(robots, deployment, **options))
    (tmp_path / "world.yaml").write_text(examples.path("bidding", "world.yaml").read_text())
    config = {"seed": 3, "until": 900, "world": "world.yaml", "stall": 120,
              "channels": {"lan": {"model": "ideal", "latency": 0.0}}, "faults": list(faults)}
    (tmp_path / "run.yaml").write_text(yaml.safe_dump(config))
    return run_files(net, config=tmp_path / "run.yaml", keep_events=True)


def _custom(outcome, name):
    return [e for e in outcome.events if e.kind == "custom" and e.data.get("name") == name]


def _metric(outcome, name):
    from petriflow.agents.bidding import metrics
    from petriflow.runtime.metrics import RunRecord

    return getattr(metrics, name)(RunRecord(outcome.result, outcome.events))


def test_transitions_fire_one_at_a_time():
    net = load_net(examples.path("bidding", "bidding-autonomous-2.yaml"))
    config = load_config(examples.path("bidding", "run.yaml"))
    world = World(yaml.safe_load(examples.path("bidding", "world.yaml").read_text()))
    try:
        op = fire_one(net, "operator_request", world=world, config=config, tokens={"operator_start": [None]})
        operator = op.tokens["operator_work"][0]
        assert [m.kind for m in operator.outbox["hmia"]] == ["REQUEST", "INFORM"]
        sent = fire_one(net, "operator_send_hmia", world=world, config=config,
                        tokens={"operator_work": [operator], "slot_hmia": [None]})
        assert sent.marking["operator_work"] == 1 and "slot_hmia" not in sent.marking
        hmia = fire_one(net, "hmia_create", world=world, config=config,
                        tokens={"hmia_start": [None]}).tokens["hmia_work"][0]
        for message in operator.outbox["hmia"]:
            got = fire_one(net, "hmia_receive", world=world, config=config,
                           tokens={"box_hmia": [message.token()], "hmia_listen": [hmia]})
            assert got.marking["slot_hmia"] == 1
        assert hmia.requested and hmia.robots == ["robot1", "robot2"] and len(hmia.zones) == 8
        team = fire_one(net, "hmia_team", world=world, config=config, tokens={"hmia_work": [hmia]})
        assert team.outcome == "ok" and [m.kind for m in hmia.outbox["robot1"]] == ["INITIALIZE"]
        # robot1 initialises, then bids on a CFP for Z6 with its eq. 6 cost
        robot = fire_one(net, "robot1_create", world=world, config=config,
                         tokens={"robot1_start": [None]}).tokens["robot1_work"][0]
        fire_one(net, "robot1_receive", world=world, config=config,
                 tokens={"box_robot1": [hmia.outbox["robot1"][0].token()], "robot1_listen": [robot]})
        assert fire_one(net, "robot1_ready", world=world, config=config, tokens={"robot1_work": [robot]}).outcome == "ok"
        assert robot.initialised and robot.outbox["hmia"][0].kind == "INITIALIZED"
        from petriflow.agents.bidding.protocol import Message

        cfp = Message("CFP", "hmia", "robot1", zone=5, body={"position": (0.5, -5.5), "bidders": ["robot1", "robot2"]})
        fire_one(net, "robot1_receive", world=world, config=config,
                 tokens={"box_robot1": [cfp.token()], "robot1_listen": [robot]})
        fire_one(net, "robot1_bid", world=world, config=config, tokens={"robot1_work": [robot]})
        propose = robot.outbox["robot2"][0]
        assert propose.kind == "PROPOSE" and propose.body["cost"] == pytest.approx(((6 - 0.5) ** 2 + 3.5 ** 2) ** 0.5
                                                                                  / 0.5 / 3)
        # robot2 bids lower: robot1 loses and sends no ALLOCATED
        theirs = Message("PROPOSE", "robot2", "robot1", zone=5, body={"cost": 1.0, "rank": 1})
        fire_one(net, "robot1_receive", world=world, config=config,
                 tokens={"box_robot1": [theirs.token()], "robot1_listen": [robot]})
        fire_one(net, "robot1_decide", world=world, config=config, tokens={"robot1_work": [robot]})
        assert robot.mine == [] and [m.kind for m in robot.outbox["hmia"]] == ["INITIALIZED"]
    finally:
        world.close()


def test_two_robot_mission_maps_every_zone_with_the_central_auctions_result(tmp_path):
    outcome = _run(tmp_path, 2)
    assert outcome.result.reason == "final"
    office = paper_office()
    expected = autonomous([s[:2] for s in office.starts[:2]], office.zones)
    won = {e.data["data"]["zone"] - 1: e.data["data"]["robot"] for e in _custom(outcome, "bidding.allocated")}
    assert won == {z: f"robot{w + 1}" for z, w in zip(expected.zones, expected.winner)}
    assert sorted(e.data["data"]["zone"] for e in _custom(outcome, "bidding.zone_mapped")) == list(range(1, 9))
    kinds = _metric(outcome, "messages_by_kind")
    assert {k: kinds[k] for k in ("REQUEST", "INFORM", "INITIALIZE", "INITIALIZED", "CFP", "PROPOSE", "ALLOCATED",
                                  "MAP", "END")} == {"REQUEST": 1, "INFORM": 1, "INITIALIZE": 2, "INITIALIZED": 2,
                                                     "CFP": 8, "PROPOSE": 16, "ALLOCATED": 8, "MAP": 1, "END": 1}
    assert kinds["MAPPED"] > 50 and _metric(outcome, "messages") == sum(kinds.values())
    # a broadcast is one message but one delivery per mailbox: CFP, MAP and END reach both robots
    assert _metric(outcome, "deliveries") == sum(kinds.values()) + 8 + 1 + 1
    end = _custom(outcome, "bidding.end")[0].data["data"]
    assert end["accuracy_pct"] > 90 and end["coverage"] > 0.8
    assert _metric(outcome, "time_s") == pytest.approx(end["time_s"], abs=0.2)


def test_a_broken_robots_zones_are_reauctioned_and_the_map_completes(tmp_path):
    outcome = _run(tmp_path, 3, faults=[{"kill": "robot1", "at": 40}])
    broken = _custom(outcome, "bidding.breakdown")
    assert [e.data["data"]["robot"] for e in broken] == ["robot1"] and broken[0].data["data"]["reoffered"]
    lost = set(broken[0].data["data"]["reoffered"])
    later = {e.data["data"]["zone"]: e.data["data"]["robot"] for e in _custom(outcome, "bidding.allocated")
             if e.time > 40}
    assert set(later) == lost and "robot1" not in later.values()
    assert sorted(e.data["data"]["zone"] for e in _custom(outcome, "bidding.zone_mapped")) == list(range(1, 9))
    assert _custom(outcome, "bidding.end"), "the HMIA ends the mission once the survivors mapped every zone"


def test_random_deployment_follows_the_operators_lists(tmp_path):
    lists = [[2, 8, 1, 6, 5], [7, 3, 4]]  # Table 3, random deployment
    outcome = _run(tmp_path, 2, "random", lists=lists)
    assert outcome.result.reason == "final"
    done = {}
    for e in _custom(outcome, "bidding.zone_done"):
        done.setdefault(e.agent, []).append(e.data["data"]["zone"])
    assert done == {"robot1": lists[0], "robot2": lists[1]}
    assert not _custom(outcome, "bidding.cfp")


def test_filtering_teammates_removes_the_fictitious_obstacles(tmp_path):
    seen = _custom(_run(tmp_path, 3), "bidding.end")[0].data["data"]
    filtered = _custom(_run(tmp_path, 3, filter_teammates=True), "bidding.end")[0].data["data"]
    assert seen["xi"] > 0 and filtered["xi"] == 0 and filtered["accuracy_pct"] == 100.0


def test_hmia_steps_and_a_robots_exploration_fire_alone():
    from petriflow.agents.bidding.agent import Interface, RobotAgent
    from petriflow.agents.bidding.protocol import Message

    net = load_net(examples.path("bidding", "bidding-autonomous-2.yaml"))
    config = load_config(examples.path("bidding", "run.yaml"))
    world = World(yaml.safe_load(examples.path("bidding", "world.yaml").read_text()))
    try:
        hmia = fire_one(net, "hmia_create", world=world, config=config,
                        tokens={"hmia_start": [None]}).tokens["hmia_work"][0]
        assert isinstance(hmia, Interface) and hmia.global_map is not None
        hmia.requested, hmia.robots, hmia.alive = True, ["robot1", "robot2"], {"robot1", "robot2"}
        hmia.zones = [tuple(z) for z in paper_office().zones]
        hmia.initialise_sent, hmia.initialised = True, {"robot1", "robot2"}
        hmia.to_offer.extend(range(8))
        cfp = fire_one(net, "hmia_cfp", world=world, config=config, tokens={"hmia_work": [hmia]})
        assert cfp.outcome == "ok" and hmia.auction == 0
        calls = [hmia.outbox[r][0] for r in ("robot1", "robot2")]
        assert {m.kind for m in calls} == {"CFP"} and calls[0].cast == calls[1].cast  # one broadcast
        hmia.outbox.clear()
        hmia.auction, hmia.to_offer = None, type(hmia.to_offer)()
        hmia.owner = {z: "robot1" for z in range(8)}
        fire_one(net, "hmia_map", world=world, config=config, tokens={"hmia_work": [hmia]})
        assert hmia.map_sent is not None and hmia.outbox["robot2"][0].kind == "MAP"
        hmia.finished = set(range(8))
        end = fire_one(net, "hmia_end", world=world, config=config, tokens={"hmia_work": [hmia]})
        report = [e.data["data"] for e in end.events if e.kind == "custom" and e.data["name"] == "bidding.end"][0]
        assert report["accuracy_pct"] == 100.0 and report["sigma"] == 0  # nothing mapped, nothing wrong

        robot = RobotAgent("robot1", 0, "hmia")
        robot.initialise = Message("INITIALIZE", "hmia", "robot1", body={"rank": 0, "team": ["robot1", "robot2"]})
        fire_one(net, "robot1_ready", world=world, config=config, tokens={"robot1_work": [robot]})
        robot.outbox.clear()
        robot.mapping, robot.mine, robot.zones = True, [4], {4: (13.0, -8.1)}
        before = robot.robot.pose
        step = fire_one(net, "robot1_explore", world=world, config=config, tokens={"robot1_work": [robot]})
        assert step.outcome == "ok" and 0.0 < step.time <= 1.0 + 1e-9  # at most one step of 1 s
        assert robot.robot.pose != before and robot.outbox["hmia"][0].kind == "MAPPED"  # turning towards Z5
        points = robot.outbox["hmia"][0].body["points"]
        assert len(points) > 50 and abs(points).max() < 17  # world points inside the office
    finally:
        world.close()
