"""A robot agent (RA, Fig. 4) as actions: its state, and the steps of its work loop but
driving (:mod:`~petriflow.agents.bidding.driving`).

========================  ===========================================================
``bidding.robot``         creates an RA's state
``bidding.ready``         on INITIALIZE: its laser and pose; INITIALIZED back
``bidding.bid``           on CFP: its eq. 6 cost to the other bidders (PROPOSE)
``bidding.decide``        all proposals in: lowest cost (ties: smallest rank) wins;
                          the winner tells the HMIA (ALLOCATED)
========================  ===========================================================
"""

from __future__ import annotations

import math
from typing import Any

from petriflow.agents.bidding.agent import RobotAgent
from petriflow.agents.bidding.auction import best
from petriflow.agents.bidding.cost import AREA_M2, SPEED_M_S, Weights, bid_costs
from petriflow.agents.bidding.needs import DRIVEN, LIVE, OFFICE, Step, office_of
from petriflow.agents.bidding.protocol import Kind, Payload
from petriflow.runtime.action import ActionContext, ActionFailure, InstantAction, Param

__all__ = ["MakeRobot", "Ready", "Bid", "Decide", "watch_teammates"]


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



class _RobotStep(Step):
    """A step of an RA's work loop."""

    agent_state = RobotAgent


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
    uses = DRIVEN

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
            ra.rank = int(ra.initialise.data.body.get("rank", ra.rank))
            ra.team = list(ra.initialise.data.body.get("team", [ra.name]))
        ra.ranks.update({name: rank for rank, name in enumerate(ra.team)})
        watch_teammates(ctx, ra)
        ra.initialised = True
        x, y, yaw = ra.pose()
        ra.queue(ra.hmia, Payload(Kind.INITIALIZED, body={"pose": (x, y, yaw)}))
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
            plan = office_of(ctx)
            area = plan.size[0] * plan.size[1] if plan is not None else AREA_M2
        cost = float(bid_costs([[travel]], [held], [p["accuracy"]], area=area, weights=weights)[0, 0])
        auction.own = cost
        others = [b for b in auction.bidders if b != ra.name]
        if others:
            ra.broadcast(Kind.PROPOSE, others, auction.zone, {"cost": cost, "rank": ra.rank})
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
            ra.queue(ra.hmia, Payload(Kind.ALLOCATED, zone=auction.zone, body={"cost": auction.own}))
        ctx.emit("bidding.decided", zone=auction.zone + 1, won=winner_rank == ra.rank)


def watch_teammates(ctx: ActionContext, ra: RobotAgent) -> None:
    """The teammates running now (what the heartbeats say) into the RA's state."""
    live = ctx.resource("live")
    plan = ctx.resource("office")
    if plan is None:
        ra.set_alive({r for r in ra.team if live.alive(r)})
    else:  # the run's running agents, read once per time step for the whole team
        ra.set_alive(set(plan.running(live, ctx.now) & ra.members()))

