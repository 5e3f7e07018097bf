"""Seed 004's agents as actions nets bind by name, and the guards that route them.

Every agent's state (:mod:`~petriflow.agents.bidding.agent`) is kept by the run: the
agent's create action sets it (``ctx.state``), every later action and guard of the
agent reads it (``ctx.state``), and the tokens of its places are plain. Every agent's
subnet has a work loop (a token in ``<agent>_work``) and a listening place (a token in
``<agent>_listen``). ``bidding.receive`` takes one message from the agent's mailbox (a
channel place) into its state; the work loop's transitions act on what arrived, each
guarded by the state:

========================  ===========================================================
``bidding.operator``      the operator: the mission (REQUEST, then INFORM)
``bidding.interface``     creates the HMIA's state and its global map
``bidding.robot``         creates an RA's state
``bidding.team``          HMIA, on REQUEST + INFORM: INITIALIZE to every RA
``bidding.ready``         RA, on INITIALIZE: its laser and pose; INITIALIZED back
``bidding.inform``        HMIA, random deployment: each RA's zone list (INFORM)
``bidding.cfp``           HMIA, autonomous deployment: the next zone to the RAs (CFP)
``bidding.bid``           RA, on CFP: its eq. 6 cost to the other bidders (PROPOSE)
``bidding.decide``        RA, all proposals in: lowest cost (ties: smallest rank)
                          wins; the winner tells the HMIA (ALLOCATED)
``bidding.map``           HMIA, every zone owned: MAP to every RA
``bidding.explore``       RA: drive its zones nearest first, laser scans, MAPPED
``bidding.end``           HMIA, every zone mapped: END to every RA
``bidding.send``          any agent: the next message for one peer into its mailbox
``bidding.wait``          any agent with nothing to do: wait for news
========================  ===========================================================

A robot that stops (a ``kill`` fault) stops answering; the HMIA notices (as a missing
heartbeat: the run's ``core.liveness`` resource), and offers its unmapped zones again to
the survivors (a re-auction, in both deployments). The office plan and the navigators
planned on it are the run's ``bidding.office`` resource
(:class:`~petriflow.agents.bidding.office.Plan`).

The guards read the agent's state and say which of its keys (see
:class:`~petriflow.agents.bidding.protocol.Mailbox`) they read, so after a firing only
the guards whose keys changed are asked again: ``bidding.has_message`` reads
``outbox/{peer}``, the step guards ``step``, ``bidding.idle`` and ``bidding.finished``
``step`` and ``pending`` (:data:`GUARDS`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from petriflow.agents.bidding.agent import Auction, Interface, Operator, RobotAgent
from petriflow.agents.bidding.auction import best, random_deployment, tour
from petriflow.agents.bidding.cost import AREA_M2, SPEED_M_S, Weights, bid_costs
from petriflow.agents.bidding.protocol import Mailbox, Message
from petriflow.runtime.action import Action, ActionContext, ActionFailure, InstantAction, Param, Status

__all__ = ["GUARDS", "OFFICE", "LIVE"]

#: The run's office plan (:class:`~petriflow.agents.bidding.office.Plan`, or ``None``: the
#: world has no ``meta.office``), as actions declare it.
OFFICE = {"office": "bidding.office"}
#: Which agents run now (what heartbeats tell), as actions declare it.
LIVE = {"live": "core.liveness"}


def _office(ctx: ActionContext) -> Any:
    """The world's office (``None``: it has none)."""
    plan = ctx.resource("office")
    return None if plan is None else plan.office


# Creating the agents ---------------------------------------------------------------------

class MakeOperator(InstantAction):
    """The operator's mission: REQUEST, then INFORM (deployment, team, zones, lists)."""

    agent_state = Operator
    resources = OFFICE
    params = {
        "hmia": Param(str, "hmia", "the interface agent"),
        "robots": Param(list, doc="the robot agents, in rank order"),
        "deployment": Param(str, "autonomous", "autonomous (bidding) or random (the operator's lists)",
                            choices=("autonomous", "random")),
        "zones": Param((list, type(None)), None, "zone positions [[x, y], ...] in rank order (default: the"
                       " world's office)"),
        "lists": Param((list, type(None)), None, "random deployment: each robot's zone numbers (1-based), in"
                       " visiting order (default: drawn at random with the run's seed)"),
    }

    @classmethod
    def check_params(cls, given: dict[str, Any], where: str) -> dict[str, Any]:
        """The declared types, then the shapes: zones are ``[x, y]`` pairs of finite
        numbers, lists hold whole zone numbers from 1, robots are names."""
        from petriflow.errors import NetFormatError

        checked = super().check_params(given, where)

        def fail(name: str, why: str) -> None:
            error = NetFormatError(f"parameter {name!r}: {why}", element=where)
            error.param = name
            raise error

        def number(v: Any) -> bool:
            return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)

        if not checked["robots"] or not all(isinstance(r, str) and r for r in checked["robots"]):
            fail("robots", f"a non-empty list of agent names, got {checked['robots']!r}")
        if checked["zones"] is not None and not all(
                isinstance(z, (list, tuple)) and len(z) >= 2 and all(number(v) for v in z[:2]) for z in checked["zones"]):
            fail("zones", "a list of [x, y] positions in metres")
        lists = checked["lists"]
        if lists is not None:
            if not all(isinstance(zs, list) and all(isinstance(z, int) and not isinstance(z, bool) and z >= 1
                                                    for z in zs) for zs in lists):
                fail("lists", f"one list of zone numbers (1, 2, ...) per robot, got {lists!r}")
            if len(lists) != len(checked["robots"]):
                fail("lists", f"{len(lists)} zone lists for {len(checked['robots'])} robots")
        return checked

    def run(self, ctx: ActionContext) -> None:
        p = self.params
        zones = p["zones"]
        if zones is None:
            office = _office(ctx)
            if office is None:
                raise ActionFailure("bidding.operator: no zones given and the world has no meta.office")
            zones = [list(z) for z in office.zones]
        zones = [[float(v) for v in z[:2]] for z in zones]
        robots = [str(r) for r in p["robots"]]
        if not robots:
            raise ActionFailure("bidding.operator: the team has no robot")
        lists = p["lists"]
        if p["deployment"] == "random":
            if lists is None:
                lists = random_deployment(len(robots), len(zones), ctx.rng)
            else:
                if len(lists) != len(robots):
                    raise ActionFailure(f"bidding.operator: {len(lists)} zone lists for {len(robots)} robots")
                lists = [[int(z) - 1 for z in zs] for zs in lists]
                flat = sorted(z for zs in lists for z in zs)
                if flat != list(range(len(zones))):
                    raise ActionFailure("bidding.operator: the zone lists must hold every zone number from 1 to"
                                        f" {len(zones)} once, got {[[z + 1 for z in zs] for zs in lists]}")
        mission = {"deployment": p["deployment"], "robots": robots, "zones": zones, "lists": lists}
        operator = ctx.state = Operator(ctx.agent or ctx.transition, p["hmia"], mission)
        operator.queue(Message("REQUEST", operator.name, p["hmia"], body={"task": "map"}))
        operator.queue(Message("INFORM", operator.name, p["hmia"], body={
            "deployment": p["deployment"], "zones": [tuple(z) for z in zones],
            "lists": None if lists is None else [list(zs) for zs in lists], "robots": list(robots)}))
        ctx.emit("bidding.mission", deployment=p["deployment"], robots=len(robots), zones=len(zones),
                 lists=None if lists is None else [[z + 1 for z in zs] for zs in lists])


class MakeInterface(InstantAction):
    """The HMIA's state, with an empty global map over the world's office."""

    agent_state = Interface
    resources = OFFICE
    params = {"resolution": Param(float, 0.1, "global map cell (m)", low=1e-9),
              "until": Param(str, "mapped", "END when every zone is mapped: in a laser's sight or reached"
                             " (mapped; the paper maps \"until mapping the entire world\") or only when every"
                             " zone is reached (reached)", choices=("mapped", "reached")),
              "casts": Param(bool, False, "follow broadcasts so each may leave in one firing (the agent's net has a"
                             " cast transition)")}

    def run(self, ctx: ActionContext) -> None:
        hmia = ctx.state = Interface(ctx.agent or ctx.transition)
        hmia.until = self.params["until"]
        if self.params["casts"]:
            hmia.track_casts()
        office = _office(ctx)
        if office is not None:
            from petriflow.agents.bidding.grid import GlobalMap

            truth = office.truth(self.params["resolution"])
            hmia.truth = truth
            hmia.global_map = GlobalMap(truth)


class MakeRobot(InstantAction):
    """An RA's state (it waits for INITIALIZE)."""

    agent_state = RobotAgent
    params = {"rank": Param(int, 0, "the robot's rank in the team (ties go to the smallest)"),
              "hmia": Param(str, "hmia", "the interface agent"),
              "casts": Param(bool, False, "follow broadcasts so each may leave in one firing (the agent's net has a"
                             " cast transition)")}

    def run(self, ctx: ActionContext) -> None:
        ra = ctx.state = RobotAgent(ctx.agent or ctx.transition, self.params["rank"], self.params["hmia"])
        if self.params["casts"]:
            ra.track_casts()


# Receiving -------------------------------------------------------------------------------

class Receive(InstantAction):
    """One message from the agent's mailbox into its state."""

    agent_state = (Interface, RobotAgent)
    resources = LIVE
    params = {"box": Param(str, doc="the mailbox (channel place)", places="")}

    def run(self, ctx: ActionContext) -> None:
        state = ctx.state
        packet = ctx.inputs[self.params["box"]][0]
        message = packet.get("message") if isinstance(packet, dict) else None
        if not isinstance(message, Message):
            raise ActionFailure(f"bidding.receive: {self.params['box']!r} held no protocol message")
        state.now = ctx.now
        state.received[message.kind] = state.received.get(message.kind, 0) + 1
        if isinstance(state, Interface):
            _hmia_receive(ctx, state, message)
        elif isinstance(state, RobotAgent):
            _robot_receive(ctx, state, message)
        state.changed()


def _hmia_receive(ctx: ActionContext, hmia: Interface, message: Message) -> None:
    kind = message.kind
    if kind == "REQUEST":
        hmia.request = message
    elif kind == "INFORM":
        body = message.body
        hmia.mode = body["deployment"]
        hmia.robots = list(body["robots"])
        hmia.zones = [tuple(z) for z in body["zones"]]
        hmia.lists = body["lists"]
        live = ctx.resource("live")
        hmia.alive = {r for r in hmia.robots if live.alive(r)}
        hmia.requested = True
    elif kind == "INITIALIZED":
        hmia.initialised.add(message.sender)
    elif kind == "ALLOCATED":
        zone = message.zone
        hmia.owner[zone] = message.sender
        if hmia.auction == zone:
            hmia.auction = None
        ctx.emit("bidding.allocated", zone=zone + 1, robot=message.sender, cost=message.body.get("cost"))
    elif kind == "MAPPED":
        points = message.body.get("points")
        if points is not None and len(points) and hmia.global_map is not None:
            hmia.points += len(points)
            hmia.global_map.add(int(message.body.get("rank", 0)), np.asarray(points, dtype=float),
                                real=message.body.get("real"))
        for zone in message.body.get("finished", ()):
            if zone not in hmia.finished:
                hmia.finished.add(zone)
                ctx.emit("bidding.zone_mapped", zone=zone + 1, robot=message.sender)
        for zone in message.body.get("seen", ()):
            if zone not in hmia.seen:
                hmia.seen.add(zone)
                ctx.emit("bidding.zone_seen", zone=zone + 1, robot=message.sender)


def _robot_receive(ctx: ActionContext, ra: RobotAgent, message: Message) -> None:
    kind = message.kind
    body = message.body
    if kind == "INITIALIZE":
        ra.initialise = message
    elif kind == "INFORM":  # random deployment: the operator's list for this robot
        for zone, position in zip(body["zones"], body["positions"]):
            ra.zones[zone] = tuple(position)
            if zone not in ra.mine:
                ra.mine.append(zone)
            ra.order.append(zone)  # the operator's order is the visiting order
    elif kind == "CFP":
        ra.auctions = type(ra.auctions)(a for a in ra.auctions if a.zone != message.zone)
        ra.auctions.append(Auction(message.zone, tuple(body["position"]), list(body["bidders"])))
        ra.zones[message.zone] = tuple(body["position"])
    elif kind == "PROPOSE":
        for auction in ra.auctions:
            if auction.zone == message.zone:
                auction.propose(message.sender, float(body["cost"]), ra.name, ra.alive)
                ra.ranks[message.sender] = int(body["rank"])
    elif kind == "MAP":
        ra.mapping = True
        ra.sight = {int(z): (float(p[0]), float(p[1])) for z, p in enumerate(body.get("zones", ()))}
    elif kind == "END":
        ra.ended = True
        ra.mapping = False


# The interface agent --------------------------------------------------------------------

#: Seconds the HMIA waits for an ALLOCATED before it offers the zone again.
AUCTION_TIMEOUT = 10.0


def _hmia_alive(ctx: ActionContext, hmia: Interface) -> None:
    """Robots that stopped: drop what waits for them, re-offer their unmapped zones;
    an auction nobody answered within :data:`AUCTION_TIMEOUT` is offered again."""
    hmia.now = ctx.now
    if hmia.auction is not None and ctx.now - hmia.auction_at > AUCTION_TIMEOUT:
        hmia.to_offer.appendleft(hmia.auction)
        hmia.auction = None
        ctx.emit("bidding.reoffer", zone=hmia.to_offer[0] + 1)
    live = ctx.resource("live")
    for robot in sorted(hmia.alive):
        if live.alive(robot):
            continue
        hmia.alive.discard(robot)
        hmia.drop(robot)
        mapped = hmia.mapped()
        lost = sorted(z for z, owner in hmia.owner.items() if owner == robot and z not in mapped)
        for zone in lost:
            del hmia.owner[zone]
            if zone not in hmia.to_offer:
                hmia.to_offer.append(zone)
        if hmia.auction is not None and hmia.auction not in hmia.owner:
            hmia.to_offer.appendleft(hmia.auction)
            hmia.auction = None
        ctx.emit("bidding.breakdown", robot=robot, reoffered=[z + 1 for z in lost])


class _HmiaStep(InstantAction):
    """A step of the HMIA's work loop: :meth:`step` changes its state, which then says
    its next step may have changed."""

    agent_state = Interface
    resources = LIVE

    def run(self, ctx: ActionContext) -> None:
        hmia = ctx.state
        self.step(ctx, hmia)
        hmia.changed()

    def step(self, ctx: ActionContext, hmia: Interface) -> None:
        raise NotImplementedError


class Team(_HmiaStep):
    """HMIA: create the team: INITIALIZE (with its start pose) to every RA."""

    def step(self, ctx: ActionContext, hmia: Interface) -> None:
        world = ctx.world
        if world is not None:  # robots of the world that are not in the team are not deployed
            for agent in [a for a in world.agents if a.startswith("robot") and a not in hmia.robots]:
                world.remove(agent)
        _hmia_alive(ctx, hmia)
        for rank, robot in enumerate(hmia.robots):
            if robot in hmia.alive:
                hmia.queue(Message("INITIALIZE", hmia.name, robot, body={"rank": rank, "team": list(hmia.robots)}))
        hmia.initialise_sent = True
        if hmia.mode == "autonomous":
            hmia.to_offer.extend(range(len(hmia.zones)))


class Inform(_HmiaStep):
    """HMIA, random deployment: every RA's zone list (INFORM)."""

    def step(self, ctx: ActionContext, hmia: Interface) -> None:
        _hmia_alive(ctx, hmia)
        for robot, zones in zip(hmia.robots, hmia.lists or []):
            for zone in zones:
                hmia.owner[zone] = robot
            if robot in hmia.alive:
                hmia.queue(Message("INFORM", hmia.name, robot, body={
                    "zones": list(zones), "positions": [hmia.zones[z] for z in zones]}))
        hmia.informed = True
        for zone in range(len(hmia.zones)):
            if hmia.owner.get(zone) not in hmia.alive and zone not in hmia.to_offer:
                hmia.owner.pop(zone, None)
                hmia.to_offer.append(zone)


class Offer(_HmiaStep):
    """HMIA: a call for proposals for the next zone to every living RA (CFP)."""

    def step(self, ctx: ActionContext, hmia: Interface) -> None:
        _hmia_alive(ctx, hmia)
        if not hmia.to_offer or not hmia.alive:
            return
        zone = hmia.to_offer.popleft()
        hmia.auction = zone
        hmia.auction_at = ctx.now
        bidders = [r for r in hmia.robots if r in hmia.alive]
        hmia.broadcast("CFP", hmia.name, bidders, zone, {"position": hmia.zones[zone], "bidders": bidders})
        ctx.emit("bidding.cfp", zone=zone + 1, bidders=len(bidders))


class StartMapping(_HmiaStep):
    """HMIA: every zone has an owner: MAP to every living RA (mapping starts)."""

    def step(self, ctx: ActionContext, hmia: Interface) -> None:
        # mapping until the world is mapped: the RAs look out for every zone (its position in sight)
        body = {"zones": [tuple(z) for z in hmia.zones]} if hmia.until == "mapped" else None
        hmia.broadcast("MAP", hmia.name, [r for r in hmia.robots if r in hmia.alive], body=body)
        hmia.map_sent = ctx.now
        ctx.emit("bidding.map", owners={str(z + 1): r for z, r in sorted(hmia.owner.items())})


class End(_HmiaStep):
    """HMIA: every zone is mapped: END to every living RA; the map's accuracy (eq. 10)."""

    params = {"tolerance": Param(int, 1, "cells between a mapped point and a real obstacle that still count"
                                 " as real (eq. 10's sigma)", low=0)}

    def step(self, ctx: ActionContext, hmia: Interface) -> None:
        _hmia_alive(ctx, hmia)
        hmia.broadcast("END", hmia.name, [r for r in hmia.robots if r in hmia.alive])
        hmia.end_sent = ctx.now
        report: dict[str, Any] = {"time_s": round(ctx.now - (hmia.map_sent or 0.0), 6), "points": hmia.points}
        if hmia.global_map is not None:
            from petriflow.agents.bidding.grid import accuracy, fictitious

            score = fictitious(hmia.global_map)
            fit = accuracy(hmia.global_map.occupied, hmia.truth.occupied, self.params["tolerance"])
            report.update(accuracy_pct=round(score.percent, 4), sigma=int(score.sigma), xi=int(score.xi),
                          fit_pct=round(fit.percent, 4), coverage=round(fit.coverage, 4))
        ctx.emit("bidding.end", **report)


# Robot agents ----------------------------------------------------------------------------

class _RobotStep(InstantAction):
    """A step of an RA's work loop: :meth:`step` changes its state, which then says its
    next step may have changed."""

    agent_state = RobotAgent

    def run(self, ctx: ActionContext) -> None:
        ra = ctx.state
        self.step(ctx, ra)
        ra.changed()

    def step(self, ctx: ActionContext, ra: RobotAgent) -> None:
        raise NotImplementedError


class Ready(_RobotStep):
    """RA, on INITIALIZE: take its pose, odometry and laser; INITIALIZED back.

    ``localization: odom`` (default) gives the robot Stage's odometry error model
    (:mod:`~petriflow.agents.bidding.odometry`): its error proportions are drawn now,
    from ``odom_error`` (Stage's default ``[0.03, 0.03, 0.05]``) and this firing's
    seeded generator; ``gps`` localises it perfectly."""

    resources = {**OFFICE, **LIVE}
    params = {"radius": Param(float, 0.1, "wheel radius (m)", low=1e-9),
              "ppr": Param(int, 500, "encoder pulses per turn", low=1),
              "track": Param(float, 0.33, "wheel track (m)", low=1e-9),
              "localization": Param(str, "odom", "odom (Stage's odometry error model; the paper's robots"
                                    " localise by odometry, §4.1) or gps (the true pose)", choices=("odom", "gps")),
              "odom_error": Param((list, type(None)), None, "Stage's odom_error [x, y, heading]: the largest"
                                  " proportion of error per axis (default Stage 3.2's [0.03, 0.03, 0.05])")}
    requires = frozenset({"world"})

    @classmethod
    def check_params(cls, given: dict[str, Any], where: str) -> dict[str, Any]:
        from petriflow.errors import NetFormatError

        checked = super().check_params(given, where)
        limits = checked["odom_error"]
        if limits is not None and not (len(limits) == 3 and all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and 0 <= v < 2
                for v in limits)):
            error = NetFormatError(f"parameter 'odom_error': [x, y, heading], three numbers from 0 to 2, got"
                                   f" {limits!r}", element=where)
            error.param = "odom_error"
            raise error
        return checked

    def step(self, ctx: ActionContext, ra: RobotAgent) -> None:
        if ctx.world is None:
            raise ActionFailure("bidding.ready: a robot agent needs a world")
        from petriflow.agents.mobile.kinematic import KinematicRobot

        ra.robot = KinematicRobot(ctx.world, ra.name, radius=self.params["radius"], ppr=self.params["ppr"],
                                  track=self.params["track"])
        if self.params["localization"] == "odom":
            from petriflow.agents.bidding.odometry import STAGE_ODOM_ERROR, Odometry, draw_errors

            limits = self.params["odom_error"]
            ra.odometry = Odometry(ra.robot.pose, draw_errors(STAGE_ODOM_ERROR if limits is None else limits,
                                                              ctx.rng))
        if ra.initialise is not None:
            ra.rank = int(ra.initialise.body.get("rank", ra.rank))
            ra.team = list(ra.initialise.body.get("team", [ra.name]))
        ra.ranks.update({name: rank for rank, name in enumerate(ra.team)})
        _robot_alive(ctx, ra)
        ra.initialised = True
        x, y, yaw = ra.pose()
        ra.queue(Message("INITIALIZED", ra.name, ra.hmia, body={"pose": (x, y, yaw)}))
        ctx.emit("bidding.ready", pose=[round(x, 3), round(y, 3), round(yaw, 4)],
                 odometry=None if ra.odometry is None else ra.odometry.to_dict()["errors"])


class Bid(_RobotStep):
    """RA, on CFP: its cost for the zone by eq. 6, to every other bidder (PROPOSE)."""

    resources = OFFICE
    params = {
        "speed": Param(float, SPEED_M_S, "the speed turning distance into travel time P_ij (m/s)",
                       low=1e-9),
        "accuracy": Param(float, 1.0, "E_i, the laser's accuracy (0..1)", low=0, high=1),
        "alpha": Param(float, 1 / 3, "eq. 6 weight of travel time", low=0, high=1),
        "beta": Param(float, 1 / 3, "eq. 6 weight of the zones held", low=0, high=1),
        "gamma": Param(float, 1 / 3, "eq. 6 weight of sensor inaccuracy", low=0, high=1),
        "area": Param((float, type(None)), None, "L x W (m^2); default: the world's office, else 32 x 22"),
    }

    def step(self, ctx: ActionContext, ra: RobotAgent) -> None:
        auction = ra.auction()
        if auction is None:
            raise ActionFailure("bidding.bid: no call for proposals")
        p = self.params
        x, y, _ = ra.pose()
        travel = math.dist((x, y), auction.position) / p["speed"]
        held = len(ra.mine)  # the zones this robot already holds (eq. 6's sum over k < j)
        weights = Weights(p["alpha"], p["beta"], p["gamma"])
        area = p["area"]
        if area is None:
            office = _office(ctx)
            area = office.size[0] * office.size[1] if office is not None else AREA_M2
        cost = float(bid_costs([[travel]], [held], [p["accuracy"]], area=area, weights=weights)[0, 0])
        auction.own = cost
        others = [b for b in auction.bidders if b != ra.name]
        if others:
            ra.broadcast("PROPOSE", ra.name, others, auction.zone, {"cost": cost, "rank": ra.rank})
        ctx.emit("bidding.bid", zone=auction.zone + 1, cost=round(cost, 6), held=held)


class Decide(_RobotStep):
    """RA, every proposal in: the lowest cost wins (ties: smallest rank); the winner
    takes the zone and tells the HMIA (ALLOCATED)."""

    def step(self, ctx: ActionContext, ra: RobotAgent) -> None:
        auction = ra.auctions.popleft()
        names = [ra.name] + [b for b in auction.proposals if b in ra.alive or not ra.alive]
        costs = [auction.own] + [auction.proposals[b] for b in names[1:]]
        ranks = [ra.rank] + [ra.ranks.get(b, 1 << 30) for b in names[1:]]
        winner_rank = best(costs, ranks)
        if winner_rank == ra.rank:
            if auction.zone not in ra.mine:
                ra.mine.append(auction.zone)
            ra.queue(Message("ALLOCATED", ra.name, ra.hmia, zone=auction.zone, body={"cost": auction.own}))
        ctx.emit("bidding.decided", zone=auction.zone + 1, won=winner_rank == ra.rank)


def _robot_alive(ctx: ActionContext, ra: RobotAgent) -> None:
    live = ctx.resource("live")
    plan = ctx.resource("office")
    if plan is None:
        ra.set_alive({r for r in ra.team if live.alive(r)})
    else:  # the run's running agents, read once per time step for the whole team
        ra.set_alive(set(plan.running(live, ctx.now) & ra.members()))


class Explore(Action):
    """RA: drive to its zones nearest first (the operator's order in a random
    deployment), steering on where its odometry says it is, scanning the laser every
    ``scan_period`` s; each scan's new world points (eq. 7-8, from the believed pose)
    go to the HMIA (MAPPED), with the zones reached and the zones first in sight. Once
    its zones are done it stands and goes on mapping until END (``idle: scan``).

    Ends after ``step`` s, or as soon as a message waits to be sent, so the work loop
    sends it and answers calls for proposals while mapping.
    """

    params = {
        "speed": Param(float, SPEED_M_S, "cruise speed (m/s)", low=1e-9),
        "turn_rate": Param(float, 1.0, "turn rate (rad/s; Stage 3.2's position controller: 1)", low=1e-9),
        "step": Param(float, 1.0, "longest run of one firing (s)", low=1e-9),
        "scan_period": Param(float, 1.0, "seconds between laser scans", low=0),
        "range": Param(float, 8.0, "laser range (m)", low=1e-9),
        "fov": Param(float, 180.0, "laser field of view (degrees)", low=1e-9, high=360),
        "beams": Param(int, 360, "laser beams", low=1),
        "z": Param(float, 0.13, "laser height (m): at the robots' body height, so teammates are seen"),
        "filter_teammates": Param(bool, False, "drop laser returns on teammates (the paper's drawback, fixed)"),
        "cell": Param(float, 0.1, "a point is new when its cell (m) was not sent before", low=1e-9),
        "send": Param(str, "every", "MAPPED after every scan (every, the paper's: its message counts follow"
                      " the mapping time) or only after scans that saw new cells (new)", choices=("every", "new")),
        "spin": Param(bool, False, "turn a full circle at every waypoint (the paper describes none)"),
        "idle": Param(str, "scan", "once its zones are done: go on scanning and sending MAPPED until END"
                      " (scan; the RA's procedure \"continues until receiving END\", §3.2.2) or stop (stop)",
                      choices=("scan", "stop")),
        "visit": Param(str, "centre", "what mapping a zone means: drive to its position (centre, the paper's)"
                       " or through waypoints spread over its room (room)", choices=("centre", "room")),
        "clearance": Param(float, 0.8, "hold while a robot of smaller rank is this close ahead (m)",
                           low=0),
        "patience": Param(float, 3.0, "seconds held before planning a detour around the robot in the way",
                          low=0),
        "inflate": Param(float, 0.35, "obstacle margin for path planning (m)", low=0),
    }
    needs_world = True
    agent_state = RobotAgent
    resources = {**OFFICE, **LIVE}

    def start(self, ctx: ActionContext) -> None:
        self.ra = ra = ctx.state
        ra.now = ctx.now
        self.left = self.params["step"]
        self.at = ctx.now
        ra.keep_mapping = self.params["idle"] == "scan"
        if ra.robot is None:
            raise ActionFailure("bidding.explore: the robot agent is not initialised")
        # how far a teammate may drive between two questions of one time step (one step of
        # its own at this speed), plus slack: the margin of the robots' positions per step
        self._margin = 0.5 + 2.0 * self.params["speed"] * float(getattr(ctx.world, "dt", 0.1) or 0.1)
        _robot_alive(ctx, ra)

    def poll(self, ctx: ActionContext) -> Status:
        ra = self.ra
        dt = ctx.now - self.at  # the first poll comes at the start: no time has passed yet
        self.at = ra.now = ctx.now
        if dt <= 1e-12:
            return Status.RUNNING
        self.dt = dt
        self.left -= dt
        standing = False
        if not ra.route and ra.spin_left <= 0 and not self._next(ctx):
            if not ra.keep_mapping:
                ra.changed()
                return Status.OK
            standing = True  # every zone done: stand and go on mapping until END
        if standing:
            pass
        elif ra.spin_left > 0:
            w = self.params["turn_rate"]
            half = ra.robot.encoders.track / 2.0
            self._drive(-w * half, w * half, dt)
            ra.spin_left -= w * dt
        elif not self._held(ctx):
            target = ra.route[0]
            if self._towards(target, dt, tolerance=0.05):
                ra.route.pop(0)
                if not ra.route:
                    ra.passing = None
                    ra.spin_left = 2 * math.pi if self.params["spin"] else 0.0
        ra.waiting += dt
        if ra.waiting >= self.params["scan_period"] - 1e-9:
            ra.waiting = 0.0
            self._scan(ctx)
        if not ra.route and ra.spin_left <= 0 and not ra.waypoints and ra.plan:
            self._zone_done(ctx)
        if ra.pending() or self.left <= 1e-9:
            ra.changed()
            return Status.OK
        return Status.RUNNING

    def _drive(self, left: float, right: float, dt: float) -> None:
        """Turn the wheels: the body moves (the truth), the odometry integrates the
        same wheel speeds with its errors (the robot's belief)."""
        ra = self.ra
        ra.robot.drive(left, right, dt)
        if ra.odometry is not None:
            ra.odometry.wheels(left, right, ra.robot.encoders.track, dt)

    def _towards(self, goal: tuple[float, float], dt: float, tolerance: float) -> bool:
        """One ``dt`` towards ``goal`` steered on where the robot believes it is: turn on
        the spot to face it, then drive straight at it; ``True`` once (believed) within
        ``tolerance``."""
        ra = self.ra
        x, y, yaw = ra.pose()
        distance = math.hypot(goal[0] - x, goal[1] - y)
        if distance <= tolerance:
            return True
        error = math.atan2(goal[1] - y, goal[0] - x) - yaw
        error = math.atan2(math.sin(error), math.cos(error))
        half = ra.robot.encoders.track / 2.0
        if abs(error) > 0.02:
            w = math.copysign(min(self.params["turn_rate"], abs(error) / dt), error)
            self._drive(-w * half, w * half, dt)
            return False
        v = min(self.params["speed"], distance / dt)
        w = error / dt * 0.5
        self._drive(v - w * half, v + w * half, dt)
        x, y, _ = ra.pose()
        return math.hypot(goal[0] - x, goal[1] - y) <= tolerance

    def _next(self, ctx: ActionContext) -> bool:
        """Route to the next waypoint (of this zone, or of the nearest zone left)."""
        ra = self.ra
        if not ra.waypoints:
            left = ra.left()
            if not left:
                return False
            x, y, _ = ra.pose()
            listed = [z for z in ra.order if z in left]
            zone = listed[0] if listed else left[tour((x, y), [ra.zones[z] for z in left])[0]]
            ra.plan = [zone]
            office = _office(ctx)
            if office is not None and self.params["visit"] == "room":
                points = [tuple(p) for p in office.waypoints(zone)]
            else:
                points = [ra.zones[zone]]
            ra.waypoints = [points[k] for k in tour((x, y), points)]
        goal = ra.waypoints.pop(0)
        plan = ctx.resource("office")
        if plan is None:
            ra.route = [goal]
            return True
        route = plan.navigator(self.params["inflate"]).route(ra.pose()[:2], goal)
        if route is None:
            ctx.emit("bidding.unreachable", goal=[round(goal[0], 3), round(goal[1], 3)])
            return bool(ra.waypoints) or self._finish_zone(ctx)
        ra.route = route
        return True

    def _finish_zone(self, ctx: ActionContext) -> bool:
        self._zone_done(ctx)
        return False

    def _zone_done(self, ctx: ActionContext) -> None:
        ra = self.ra
        zone = ra.plan.pop(0)
        ra.done.add(zone)
        ra.queue(Message("MAPPED", ra.name, ra.hmia, zone=zone, body={"points": None, "finished": [zone],
                                                                      "rank": ra.rank}))
        (bx, by, _), (tx, ty, _) = ra.pose(), ra.robot.pose
        ctx.emit("bidding.zone_done", zone=zone + 1, distance_m=round(ra.robot.travelled, 3),
                 drift_m=round(math.hypot(bx - tx, by - ty), 4))

    def _held(self, ctx: ActionContext) -> bool:
        """Hold while a robot of smaller rank is close ahead (no two robots wait for
        each other: ranks order them); after ``patience`` s, drive around it."""
        ra = self.ra
        blocker = self._blocker(ctx)
        if blocker is None:
            ra.held = 0.0
            return False
        ra.held += self.dt
        if ra.held < self.params["patience"]:
            return True
        ra.held = 0.0
        plan = ctx.resource("office")
        if plan is None or not ra.route:
            return False
        where = ctx.world.position(blocker)
        navigator = plan.navigator(self.params["inflate"])
        detour = navigator.around([(where[0], where[1], self.params["clearance"])]).route(ra.pose()[:2],
                                                                                           ra.route[-1])
        ctx.emit("bidding.detour", around=blocker, found=detour is not None)
        if detour is not None:
            ra.route = detour
            ra.passing = blocker
        return False

    def _blocker(self, ctx: ActionContext) -> str | None:
        ra = self.ra
        world = ctx.world
        x, y, yaw = ra.robot.pose
        clearance = self.params["clearance"]
        plan = ctx.resource("office")
        # who can be that close: the team's positions read once per step (margin: a step
        # of every robot between two questions of one step), instead of every robot's here
        near = None if plan is None else plan.near(world, ctx.now, x, y, clearance + self._margin)
        # only the robots near (not the whole team: a step's cost must not grow with it),
        # in rank order (the nearest in rank of those in the way, whatever the set's order)
        candidates = ra.alive if near is None else (near & ra.alive)
        for other in sorted(candidates, key=lambda name: (ra.ranks.get(name, ra.rank), name)):
            if other == ra.name or other == ra.passing or ra.ranks.get(other, ra.rank) >= ra.rank:
                continue
            where = world.position(other)
            if where is None:
                continue
            dx, dy = where[0] - x, where[1] - y
            distance = math.hypot(dx, dy)
            if distance < clearance:
                bearing = math.atan2(dy, dx) - yaw
                if math.cos(bearing) > 0.3:
                    return other
        return None

    def _scan(self, ctx: ActionContext) -> None:
        from petriflow.agents.bidding.laser import scan, world_points

        ra = self.ra
        p = self.params
        # the beams leave from where the robot is; it places their returns (eq. 7-8) where
        # it believes it is
        ranges, angles, bodies = scan(ctx.world, ra.name, ra.robot.pose, max_range=p["range"], fov_deg=p["fov"],
                                      beams=p["beams"], z=p["z"], ignore_teammates=p["filter_teammates"],
                                      hits=True)
        pose = ra.pose()
        points = world_points(pose, ranges, angles, p["range"])
        # which returns came off a real obstacle, which off a teammate (the simulator's
        # knowledge, for eq. 10's scoring only)
        hit = np.isfinite(ranges) & (ranges >= 0) & (ranges < p["range"]) & np.isfinite(angles)
        real = ~np.isin(bodies[hit], self._team_bodies(ctx))
        ra.scans += 1
        seen = self._sighted(pose, ranges, angles)
        every = p["send"] == "every"
        if not len(points):
            if every or seen:
                ra.queue(Message("MAPPED", ra.name, ra.hmia, body={"points": None, "finished": [], "seen": seen,
                                                                   "rank": ra.rank}))
            return
        cells = np.floor(points / p["cell"]).astype(np.int64)
        keys = cells[:, 0] * 1_000_003 + cells[:, 1]
        keys, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
        # a cell is real when a real return fell in it; a cell sent as a teammate is sent
        # again once a real return falls in it
        real_cell = np.bincount(inverse.reshape(-1), weights=real.astype(float), minlength=len(keys)) > 0
        new = [k for k in range(len(keys)) if int(keys[k]) not in ra.seen
               and (real_cell[k] or int(keys[k]) not in ra.seen_teammate)]
        if not new and not every and not seen:
            return
        for k in new:
            (ra.seen if real_cell[k] else ra.seen_teammate).add(int(keys[k]))
        fresh = points[first[new]].astype(np.float32)
        ra.queue(Message("MAPPED", ra.name, ra.hmia, body={"points": fresh, "finished": [], "seen": seen,
                                                           "rank": ra.rank, "real": real_cell[new]}))

    def _team_bodies(self, ctx: ActionContext) -> np.ndarray:
        """The pybullet bodies of the robot's teammates (what its laser may see that is
        not a real obstacle)."""
        bodies = getattr(self, "_bodies", None)
        if bodies is None:
            world = ctx.world
            bodies = self._bodies = np.asarray(
                [world.body(name) for name in self.ra.team if name != self.ra.name and name in world.agents],
                dtype=np.int64)
        return bodies

    def _sighted(self, pose: tuple[float, float, float], ranges: np.ndarray, angles: np.ndarray) -> list[int]:
        """The mission's zones this scan has in sight for the first time: within the
        laser's range and field of view, and the beam nearest their bearing reaches past
        them (nothing in between). Judged from where the robot believes it is."""
        ra = self.ra
        if not ra.sight or len(ra.sighted) == len(ra.sight) or not len(angles):
            return []
        x, y, yaw = pose
        spacing = float(angles[1] - angles[0]) if len(angles) > 1 else math.pi
        seen = []
        for zone, (zx, zy) in ra.sight.items():
            if zone in ra.sighted:
                continue
            distance = math.hypot(zx - x, zy - y)
            if distance >= self.params["range"]:
                continue
            bearing = math.atan2(zy - y, zx - x) - yaw
            bearing = math.atan2(math.sin(bearing), math.cos(bearing))
            k = int(round((bearing - float(angles[0])) / spacing))
            if not 0 <= k < len(angles) or abs(float(angles[k]) - bearing) > spacing:
                continue
            if ranges[k] >= distance:
                seen.append(zone)
        ra.sighted.update(seen)
        return seen


class Send(InstantAction):
    """Any agent: the next message waiting for ``peer`` into its mailbox. (Only the
    outbox changes: the guards reading ``outbox/<peer>`` and ``pending`` are asked again,
    not the agent's step guards.)"""

    agent_state = Mailbox
    params = {"peer": Param(str, doc="the receiving agent"),
              "box": Param(str, doc="its mailbox (channel place)", places="")}

    def run(self, ctx: ActionContext) -> None:
        message = ctx.state.take(self.params["peer"])
        if message is None:
            raise ActionFailure(f"bidding.send: nothing waits for {self.params['peer']!r}")
        _post(ctx, self.params["box"], message)


def _post(ctx: ActionContext, box: str, message: Message) -> None:
    """Put ``message`` into the mailbox ``box`` as a token and record it as sent."""
    token = message.token()
    ctx.put(box, token)
    ctx.emit("bidding.sent", message=message.kind, to=message.receiver, bytes=token["size"],
             broadcast=message.cast)


class Cast(InstantAction):
    """Any agent: a broadcast to exactly the agents of ``boxes`` into all their
    mailboxes in one firing, once every copy of it is first in its receiver's queue
    (``bidding.has_cast``). Each copy is put and recorded as :class:`Send` does."""

    agent_state = Mailbox
    params = {"boxes": Param(dict, doc="receiving agent -> its mailbox (channel place)", places="*")}

    def run(self, ctx: ActionContext) -> None:
        boxes = self.params["boxes"]
        messages = ctx.state.take_cast(frozenset(boxes))
        if not messages:
            raise ActionFailure(f"bidding.cast: no broadcast to {', '.join(sorted(boxes))} is ready")
        for message in messages:
            _post(ctx, boxes[message.receiver], message)


class Wait(Action):
    """An agent with nothing to do: wait until something is (at most ``period`` s)."""

    agent_state = (Interface, RobotAgent)
    resources = {**OFFICE, **LIVE}
    params = {"period": Param(float, 1.0, "longest wait (s)", low=1e-9)}

    def start(self, ctx: ActionContext) -> None:
        self.state = ctx.state
        self.until = ctx.now + self.params["period"]

    def poll(self, ctx: ActionContext) -> Status:
        state = self.state
        state.now = ctx.now
        if isinstance(state, Interface):
            _hmia_alive(ctx, state)
        else:
            _robot_alive(ctx, state)
        if ctx.world is None or ctx.now >= self.until - 1e-9 or (ctx.now > ctx.started and state.busy()):
            state.changed()
            return Status.OK
        return Status.RUNNING


# Guards ----------------------------------------------------------------------------------
# Each is f(state, params) over the agent's state, with the state keys it reads (GUARDS).

def _guard(step: str):
    def guard(state: Any, params: dict[str, Any]) -> bool:
        return isinstance(state, (Interface, RobotAgent)) and state.next_step() == step
    guard.__name__ = f"next_is_{step}"
    guard.__doc__ = f"Guard: the agent's next step is {step!r}."
    return guard


def has_message(state: Any, params: dict[str, Any]) -> bool:
    """Guard: a message waits for ``params['peer']``."""
    return state is not None and state.has_for(params["peer"])


def has_cast(state: Any, params: dict[str, Any]) -> bool:
    """Guard: a broadcast to exactly the agents of ``params['boxes']`` can leave in one
    firing (every copy first in its receiver's queue)."""
    return state is not None and state.ready_cast(frozenset(params["boxes"])) is not None


def finished(state: Any, params: dict[str, Any]) -> bool:
    """Guard: the agent's part is over (operator: sent everything; HMIA: END sent;
    RA: END received) and nothing waits to be sent."""
    if state is None or state.pending():
        return False
    if isinstance(state, Operator):
        return True
    if isinstance(state, Interface):
        return state.end_sent is not None
    return state.ended


def idle(state: Any, params: dict[str, Any]) -> bool:
    """Guard: nothing to do now (the agent waits for news)."""
    return isinstance(state, (Interface, RobotAgent)) and not state.busy()


#: ``{name: (guard, the state keys it reads)}``: a message for the peer; the step the
#: state calls for; whether anything waits to be sent.
GUARDS = {
    "bidding.has_message": (has_message, ("outbox/{peer}",)),
    "bidding.has_cast": (has_cast, ("cast",)),
    "bidding.finished": (finished, ("step", "pending")),
    "bidding.idle": (idle, ("step", "pending")),
    **{f"bidding.next_{step}": (_guard(step), ("step",)) for step in
       ("team", "inform", "cfp", "map", "end", "ready", "bid", "decide", "explore")},
}
