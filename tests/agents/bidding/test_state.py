"""Seed 004's agent states as the run keeps them: the keys they touch, the counters that
make every guard cost the same whatever the team's size, the plugin's registrations and
the office resource."""

from __future__ import annotations

import pytest

from petriflow.agents.bidding.guards import GUARDS
from petriflow.agents.bidding.agent import Auction, Interface, Operator, RobotAgent
from petriflow.agents.bidding.needs import OFFICE_SETTINGS
from petriflow.agents.bidding.office import Plan, paper_office, plan_resource
from petriflow.agents.bidding.correspondent import Correspondent
from petriflow.agents.bidding.protocol import Payload
from petriflow.runtime.agents import AgentState
from petriflow.runtime.registry import default_registry
from petriflow.runtime.resources import ResourceContext


def watched(state):
    touched = []
    state.attach(lambda keys: touched.extend(keys))
    return touched


def test_the_outbox_touches_the_peer_and_pending_when_it_empties_or_fills():
    box = Correspondent()
    assert isinstance(box, AgentState)
    touched = watched(box)
    box.queue("robot1", Payload("CFP", zone=0))
    box.broadcast("MAP", ["robot1", "robot2"])
    assert touched == ["outbox/robot1", "pending", "outbox/robot1", "outbox/robot2"]
    assert box.pending() and box.queued == 3 and box.has_for("robot2")
    touched.clear()
    assert box.take("robot1").kind == "CFP" and box.take("robot9") is None
    assert box.drop("robot1") == 1 and box.drop("robot3") == 0
    assert touched == ["outbox/robot1", "outbox/robot1"] and box.pending()
    box.take("robot2")
    assert touched[-2:] == ["outbox/robot2", "pending"] and not box.pending()
    assert box.sent == {"CFP": 1, "MAP": 1}


def test_step_is_touched_only_when_what_the_step_guards_answer_changes():
    robot = RobotAgent("robot1", 0, "hmia")
    touched = watched(robot)
    robot.changed()  # the first signature: nothing to do
    assert touched == ["step"] and robot.next_step() is None
    robot.alive = {"robot1", "robot2", "robot3"}
    robot.initialised = True
    robot.auctions.append(Auction(2, (1.0, 1.0), ["robot1", "robot2", "robot3"]))
    robot.changed()
    assert robot.next_step() == "bid" and touched == ["step", "step"]
    robot.auctions[0].own = 3.0
    robot.changed()
    assert robot.next_step() is None and len(touched) == 3  # waiting for two proposals
    robot.auctions[0].propose("robot2", 1.0, "robot1", robot.alive)
    robot.changed()
    assert len(touched) == 3  # one proposal among many: no guard asked again
    robot.auctions[0].propose("robot3", 2.0, "robot1", robot.alive)
    robot.changed()
    assert robot.next_step() == "decide" and len(touched) == 4


def test_missing_proposals_are_counted_again_when_a_teammate_stops():
    robot = RobotAgent("robot1", 0, "hmia")
    robot.initialised, robot.alive = True, {"robot1", "robot2", "robot3"}
    auction = Auction(0, (0.0, 0.0), ["robot1", "robot2", "robot3"], own=1.0)
    robot.auctions.append(auction)
    auction.propose("robot2", 2.0, "robot1", robot.alive)
    assert not robot.bids_in() and auction.missing == 1
    auction.propose("robot2", 2.5, "robot1", robot.alive)  # the same bidder again counts once
    assert auction.missing == 1
    robot.set_alive({"robot1", "robot2"})  # robot3 stopped: its proposal will not come
    assert auction.missing == 0 and robot.bids_in() and robot.next_step() == "decide"  # counted again
    auction.propose("robot9", 0.0, "robot1", robot.alive)  # not a bidder
    assert auction.count("robot1", robot.alive) == 0


def test_the_hmia_next_step_follows_the_protocol():
    hmia = Interface("hmia")
    assert hmia.next_step() is None and not hmia.busy()
    hmia.requested = True
    assert hmia.next_step() == "team"
    hmia.initialise_sent, hmia.robots, hmia.alive = True, ["robot1"], {"robot1"}
    hmia.zones, hmia.to_offer = [(0.0, 0.0)], type(hmia.to_offer)([0])
    assert hmia.next_step() is None  # robot1 has not answered INITIALIZE
    hmia.initialised.add("robot1")
    assert hmia.next_step() == "cfp"
    hmia.to_offer.clear()
    hmia.owner = {0: "robot1"}
    assert hmia.next_step() == "map"
    hmia.map_sent, hmia.finished = 1.0, {0}
    assert hmia.next_step() == "end" and hmia.signature() == ("end", False)


def test_the_plugin_registers_states_guards_with_their_keys_and_the_office():
    registry = default_registry
    assert registry.state_type("bidding.operator") is Operator
    assert registry.state_type("bidding.interface") is Interface
    assert registry.state_type("bidding.robot") is RobotAgent
    assert registry.guard_reads("bidding.has_message") == ("outbox/{peer}",)
    assert registry.guard_reads("bidding.next_bid") == ("step",)
    assert registry.guard_reads("bidding.idle") == ("step", "pending")
    assert all(registry.guard_reads(name) == reads for name, (_, reads) in GUARDS.items())
    assert registry.resource_factory("bidding.office") is plan_resource


class _World:
    def __init__(self, meta, positions=None):
        self.meta = meta
        self.positions = dict(positions or {})
        self.agents = {name: name for name in self.positions}
        self.asked = 0

    def position(self, agent):
        self.asked += 1
        return self.positions.get(agent)


def test_the_office_resource_is_the_worlds_plan_made_once_with_its_navigators():
    office = paper_office()

    def made(meta):
        return plan_resource(ResourceContext(world=_World(meta), liveness=None,
                                             settings={"office": OFFICE_SETTINGS.read(meta.get("office"))}))

    plan = made({"office": office.meta()})
    assert isinstance(plan, Plan) and plan.office == office
    assert plan.navigator(0.35) is plan.navigator(0.35) and plan.navigator(0.3) is not plan.navigator(0.35)
    assert plan_resource(ResourceContext(world=None, liveness=None)) is None
    assert made({}) is None
    with pytest.raises(Exception, match="must be 4 finite numbers"):
        made({"office": {"size": [1, 1], "walls": [[0.0, 0.0, 1.0]]}})


def test_near_reads_the_positions_once_per_step_and_misses_nobody_within_the_radius():
    plan = Plan(paper_office())
    world = _World(None, {"robot1": (0.0, 0.0), "robot2": (1.2, 0.5), "robot3": (5.0, 5.0),
                          "robot4": (-2.1, 0.0)})
    assert plan.near(world, 0.1, 0.0, 0.0, 1.5) >= {"robot1", "robot2"}
    assert "robot3" not in plan.near(world, 0.1, 0.0, 0.0, 1.5)
    assert world.asked == 4  # one reading per robot for the whole step
    world.positions["robot3"] = (0.5, 0.5)
    assert "robot3" not in plan.near(world, 0.1, 0.0, 0.0, 1.5)  # same step: the step's positions
    assert "robot3" in plan.near(world, 0.2, 0.0, 0.0, 1.5) and world.asked == 8
    for x in (-3.0, -1.0, 0.0, 1.9, 4.0):  # a superset of the disc, wherever the cell boundaries fall
        for radius in (0.5, 1.3, 2.5):
            inside = {a for a, (px, py) in world.positions.items() if (px - x) ** 2 + py ** 2 <= radius ** 2}
            assert plan.near(world, 0.2, x, 0.0, radius) >= inside


def test_a_broadcast_leaves_in_one_firing_once_every_copy_is_first_in_its_queue():
    box = Correspondent()
    box.track_casts()
    touched = watched(box)
    team = frozenset({"robot1", "robot2", "robot3"})
    box.queue("robot2", Payload("ALLOCATED", zone=1))  # robot2's queue is not free yet
    box.broadcast("PROPOSE", ["robot3", "robot1", "robot2"], zone=2, body={"cost": 1.0})
    assert box.ready_cast(team) is None and "cast" not in touched
    assert box.take("robot2").kind == "ALLOCATED"
    assert box.ready_cast(team) == box.casts and "cast" in touched
    assert box.ready_cast(frozenset({"robot1", "robot2"})) is None  # exactly its receivers
    box.broadcast("PROPOSE", ["robot1", "robot2", "robot3"], zone=3)
    copies = box.take_cast(team)
    assert [(m.receiver, m.data.zone) for m in copies] == [("robot1", 2), ("robot2", 2), ("robot3", 2)]
    assert box.ready_cast(team) == box.casts  # the next broadcast is first everywhere now
    assert box.queued == 3 and box.sent == {"ALLOCATED": 1, "PROPOSE": 3}
    touched.clear()
    assert box.take("robot1").data.zone == 3  # a copy sent alone: the rest go one by one
    assert box.ready_cast(team) is None and "cast" in touched and box.take_cast(team) == []
    assert [box.take(p).data.zone for p in ("robot2", "robot3")] == [3, 3] and not box.pending()
    box.broadcast("END", ["robot1", "robot2"])
    assert box.drop("robot2") == 1 and box.ready_cast(frozenset({"robot1", "robot2"})) is None


def test_without_track_casts_a_mailbox_follows_no_broadcast():
    box = Correspondent()
    touched = watched(box)
    box.broadcast("MAP", ["robot1", "robot2"])
    assert box.ready_cast(frozenset({"robot1", "robot2"})) is None and "cast" not in touched
