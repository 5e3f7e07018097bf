"""Seed 004's mission as a net: soundness, single transitions, whole missions,
breakdowns and the teammate filter."""

from __future__ import annotations

import pytest
import yaml

from petriflow import examples
from petriflow.agents.bidding.agent import Interface, Operator, RobotAgent
from petriflow.agents.bidding.auction import autonomous
from petriflow.agents.bidding.nets import build
from petriflow.agents.bidding.office import paper_office
from petriflow.agents.bidding.protocol import Payload, token
from petriflow.runtime.channel_models import Message
from petriflow.analysis import check_net
from petriflow.io import load_net
from petriflow.io.yaml import dumps_net
from petriflow.runtime.config import load_config
from petriflow.runtime.scheduler import Scheduler
from petriflow.world import World

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")


@pytest.mark.parametrize("robots", [1, 2, 3, 4, 5])
def test_nets_are_sound_workflow_nets(robots):
    for deployment in ("autonomous", "random"):
        result = check_net(build(robots, deployment))
        assert result["workflow_net"] and result["sound"], result["violations"]


def test_a_mailbox_can_hold_one_message_from_every_sender():
    net = build(3, "autonomous", mailbox="senders")
    result = check_net(net)
    assert result["workflow_net"] and result["sound"], result["violations"]
    for place in (p for p in net.places.values() if p.channel):
        senders = {net.transitions[t].subnet for t in net.place_preset(place.id)}
        assert net.postset("begin")[f"slot_{place.subnet}"] == len(senders)  # HMIA: operator + 3 RAs; RA: 3
    assert net.postset("begin")["slot_hmia"] == 4
    one = build(3, "autonomous")
    assert {p: w for p, w in one.postset("begin").items() if p.startswith("slot_")} == dict.fromkeys(
        ["slot_hmia", "slot_robot1", "slot_robot2", "slot_robot3"], 1)
    for bad in (0, -1, 1.5, True, "all"):
        with pytest.raises(ValueError, match="mailbox"):
            build(3, "autonomous", mailbox=bad)


@pytest.mark.parametrize("robots, deployment, run", [(3, "autonomous", "run.yaml"), (5, "random", "run.yaml"),
                                                     (20, "autonomous", "run-20.yaml")])
def test_shipped_nets_are_the_builders(robots, deployment, run):
    built = build(robots, deployment)
    built.run = run
    shipped = load_net(examples.path("bidding", f"bidding-{deployment}-{robots}.yaml"))
    assert shipped.structure() == built.structure()
    assert {s.id: s.state for s in shipped.subnets.values()} == {
        "operator": "bidding.operator", "hmia": "bidding.interface",
        **{f"robot{i + 1}": "bidding.robot" for i in range(robots)}}


def test_actions_name_only_declared_places_and_no_state_place():
    """Send and receive name their mailbox (a declared place parameter); no action is
    told where a state token lives: the state is the run's."""
    net = build(2)
    for t in net.transitions.values():
        assert "state" not in t.params
        if t.action in ("bidding.send", "bidding.receive"):
            assert t.params["box"] in net.places and net.places[t.params["box"]].channel == "lan"
    from petriflow.errors import NetFormatError
    from petriflow.runtime.binding import bind

    net.transitions["robot1_send_robot2"].params["box"] = "box_robot9"
    with pytest.raises(NetFormatError, match="box_robot9"):
        bind(net)


def fire(net, transition, tokens, *, states=None, world=None, config=None):
    """Fire one transition with its real action, the agents' states given (``{agent:
    state}``; ``petriflow.testing.fire_one`` takes token data only, and the states are the
    run's): ``(result, events, scheduler)``."""
    scheduler = Scheduler(net, world=world, config=config, seed=0)
    scheduler.set_tokens({p: list(v) for p, v in tokens.items()})
    agents = scheduler.firer.agents
    for agent, state in (states or {}).items():
        agents.set_state(agent, state, scheduler.index.state_type.get(agent))
    events = []
    scheduler.on_event(events.append)
    with scheduler:
        result = scheduler.fire_one(transition)
    return result, events, scheduler


def _outcome(events, transition):
    return [e.data["outcome"] for e in events if e.kind == "end" and e.transition == transition][-1]


def test_builder_refuses_nonsense():
    with pytest.raises(ValueError, match="deployment"):
        build(2, "greedy")
    with pytest.raises(ValueError, match="robots"):
        build(0)


def _run(tmp_path, robots=2, deployment="autonomous", faults=(), **options):
    from petriflow.runtime.session import run_files

    net = tmp_path / "net.yaml"
    net.write_text(dumps_net(build(robots, deployment, **options)))
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
        result, _, run = fire(net, "operator_request", {"operator_start": [None]}, world=world, config=config)
        operator = run.firer.agents.states["operator"]
        assert isinstance(operator, Operator) and result.tokens == {"operator_work": [None]}  # a plain token
        mission = list(operator.outbox["hmia"])
        assert [m.kind for m in mission] == ["REQUEST", "INFORM"]
        sent, _, _ = fire(net, "operator_send_hmia", {"operator_work": [None], "slot_hmia": [None]},
                          states={"operator": operator}, world=world, config=config)
        assert sent.marking["operator_work"] == 1 and "slot_hmia" not in sent.marking
        assert [m.kind for m in operator.outbox["hmia"]] == ["INFORM"]
        _, _, run = fire(net, "hmia_create", {"hmia_start": [None]}, world=world, config=config)
        hmia = run.firer.agents.states["hmia"]
        for message in mission:
            got, _, _ = fire(net, "hmia_receive", {"box_hmia": [token(message)], "hmia_listen": [None]},
                             states={"hmia": hmia}, world=world, config=config)
            assert got.marking["slot_hmia"] == 1 and got.tokens["hmia_listen"] == [None]
        assert hmia.requested and hmia.robots == ["robot1", "robot2"] and len(hmia.zones) == 8
        team, events, _ = fire(net, "hmia_team", {"hmia_work": [None]}, states={"hmia": hmia}, world=world,
                               config=config)
        assert _outcome(events, "hmia_team") == "ok"
        assert [m.kind for m in hmia.outbox["robot1"]] == ["INITIALIZE"]
        # robot1 initialises, then bids on a CFP for Z6 with its eq. 6 cost
        _, _, run = fire(net, "robot1_create", {"robot1_start": [None]}, world=world, config=config)
        robot = run.firer.agents.states["robot1"]

        def receive(message):
            fire(net, "robot1_receive", {"box_robot1": [token(message)], "robot1_listen": [None]},
                 states={"robot1": robot}, world=world, config=config)

        def step(name):
            return _outcome(fire(net, f"robot1_{name}", {"robot1_work": [None]}, states={"robot1": robot},
                                 world=world, config=config)[1], f"robot1_{name}")

        receive(hmia.outbox["robot1"][0])
        assert step("ready") == "ok"
        assert robot.initialised and robot.outbox["hmia"][0].kind == "INITIALIZED"
        cfp = Message(None, "hmia", "robot1", Payload("CFP", zone=5, body={"position": (0.5, -5.5),
                                                                  "bidders": ["robot1", "robot2"]}))
        receive(cfp)
        step("bid")
        propose = robot.outbox["robot2"][0]
        cost = ((6 - 0.5) ** 2 + 3.5 ** 2) ** 0.5 / 0.4 / 3
        assert propose.kind == "PROPOSE" and propose.data.body["cost"] == pytest.approx(cost)
        assert not robot.bids_in()  # robot2's proposal is missing
        # robot2 bids lower: robot1 loses and sends no ALLOCATED
        receive(Message(None, "robot2", "robot1", Payload("PROPOSE", zone=5, body={"cost": 1.0, "rank": 1})))
        assert robot.bids_in() and robot.next_step() == "decide"
        step("decide")
        assert robot.mine == [] and [m.kind for m in robot.outbox["hmia"]] == ["INITIALIZED"]
    finally:
        world.close()


def test_a_step_the_state_does_not_call_for_cannot_fire():
    net = build(2)
    robot = RobotAgent("robot1", 0, "hmia")
    with pytest.raises(Exception, match="cannot fire"):
        fire(net, "robot1_bid", {"robot1_work": [None]}, states={"robot1": robot})


def test_two_robot_mission_maps_every_zone_with_the_central_auctions_result(tmp_path):
    outcome = _run(tmp_path, 2, until="reached", localization="gps")
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
    outcome = _run(tmp_path, 3, faults=[{"kill": "robot1", "at": 40}], until="reached")
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
    outcome = _run(tmp_path, 2, "random", lists=lists, until="reached")
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
    net = load_net(examples.path("bidding", "bidding-autonomous-2.yaml"))
    config = load_config(examples.path("bidding", "run.yaml"))
    world = World(yaml.safe_load(examples.path("bidding", "world.yaml").read_text()))

    def step(agent, name, state):
        result, events, _ = fire(net, f"{agent}_{name}", {f"{agent}_work": [None]}, states={agent: state},
                                 world=world, config=config)
        return result, events

    try:
        _, _, run = fire(net, "hmia_create", {"hmia_start": [None]}, world=world, config=config)
        hmia = run.firer.agents.states["hmia"]
        assert isinstance(hmia, Interface) and hmia.global_map is not None
        assert run.resources.get("bidding.office").office == paper_office()  # the run's office resource
        hmia.requested, hmia.robots, hmia.alive = True, ["robot1", "robot2"], {"robot1", "robot2"}
        hmia.zones = [tuple(z) for z in paper_office().zones]
        hmia.initialise_sent, hmia.initialised = True, {"robot1", "robot2"}
        hmia.to_offer.extend(range(8))
        result, events = step("hmia", "cfp", hmia)
        assert _outcome(events, "hmia_cfp") == "ok" and hmia.auction == 0
        assert result.tokens["hmia_work"] == [None]  # a plain token
        calls = [hmia.outbox[r][0] for r in ("robot1", "robot2")]
        assert {m.kind for m in calls} == {"CFP"} and calls[0].data.cast == calls[1].data.cast  # one broadcast
        hmia.clear()
        assert not hmia.pending()
        hmia.auction, hmia.to_offer = None, type(hmia.to_offer)()
        hmia.owner = {z: "robot1" for z in range(8)}
        step("hmia", "map", hmia)
        assert hmia.map_sent is not None and hmia.outbox["robot2"][0].kind == "MAP"
        hmia.clear()
        hmia.finished = set(range(8))
        _, events = step("hmia", "end", hmia)
        report = [e.data["data"] for e in events if e.kind == "custom" and e.data["name"] == "bidding.end"][0]
        assert report["accuracy_pct"] == 100.0 and report["sigma"] == 0  # nothing mapped, nothing wrong

        robot = RobotAgent("robot1", 0, "hmia")
        robot.initialise = Message(None, "hmia", "robot1",
                                   Payload("INITIALIZE", body={"rank": 0, "team": ["robot1", "robot2"]}))
        step("robot1", "ready", robot)
        robot.clear()
        robot.mapping, robot.mine, robot.zones = True, [4], {4: (13.0, -8.1)}
        before = robot.robot.pose
        result, events = step("robot1", "explore", robot)
        assert _outcome(events, "robot1_explore") == "ok"
        assert 0.0 < result.time <= 1.0 + 1e-9  # at most one step of 1 s
        assert robot.robot.pose != before and robot.outbox["hmia"][0].kind == "MAPPED"  # turning towards Z5
        points = robot.outbox["hmia"][0].data.body["points"]
        assert len(points) > 50 and abs(points).max() < 17  # world points inside the office
    finally:
        world.close()


def _auction(robots, until=3.0):
    """The first seconds of a mission in the paper's office (the auction's start): the
    scheduler after the run."""
    world = World(yaml.safe_load(examples.path("bidding", "world.yaml").read_text()))
    config = load_config(examples.path("bidding", "run.yaml"))
    scheduler = Scheduler(build(robots), world=world, config=config, seed=1)
    try:
        with scheduler:
            scheduler.run(until=until)
    finally:
        world.close()
    return scheduler


def test_states_are_the_runs_and_tokens_stay_plain():
    run = _auction(2)
    states = run.firer.agents.states
    assert {a: type(s) for a, s in states.items()} == {"operator": Operator, "hmia": Interface,
                                                        "robot1": RobotAgent, "robot2": RobotAgent}
    for place, tokens in run.tokens.tokens().items():  # work, listen, slots: no state among the tokens
        if not run.net.places[place].channel:
            assert all(t is None for t in tokens), place


def test_guards_are_asked_again_only_when_what_they_read_changed():
    """Guard calls per firing do not grow with the team: an agent's send guards are asked
    again when a message for that peer comes or goes, its step guards when its state's
    next step may have changed, not after every firing of the agent."""
    small, large = _auction(2), _auction(5)
    per_firing = [run.enabled_set.evaluations / run.firer.count for run in (small, large)]
    assert per_firing[1] < 1.3 * per_firing[0] and per_firing[1] < 6, per_firing


def test_broadcasts_in_one_firing_give_the_same_mission(tmp_path):
    """With ``casts`` (and a slot per sender) a broadcast leaves in one firing: the
    auction, the messages and the zones are those of the mission that sends each copy
    alone, with fewer firings; the net stays a sound workflow net."""
    result = check_net(build(3, "autonomous", mailbox="senders", casts=True))
    assert result["workflow_net"] and result["sound"], result["violations"]
    (tmp_path / "one").mkdir()
    (tmp_path / "cast").mkdir()
    one = _run(tmp_path / "one", 3, mailbox="senders", localization="gps")
    cast = _run(tmp_path / "cast", 3, mailbox="senders", casts=True, localization="gps")
    fired = [e.transition for e in cast.events if e.kind == "start"]
    assert fired.count("robot1_cast") >= 8 and fired.count("hmia_cast") >= 10  # 8 PROPOSE; CFPs, MAP, END

    def allocated(outcome):
        return {e.data["data"]["zone"]: e.data["data"]["robot"] for e in _custom(outcome, "bidding.allocated")}

    assert allocated(cast) == allocated(one) and len(allocated(one)) == 8
    assert _metric(cast, "messages_by_kind") == _metric(one, "messages_by_kind")
    assert _metric(cast, "deliveries") == _metric(one, "deliveries")
    assert cast.result.firings < one.result.firings
