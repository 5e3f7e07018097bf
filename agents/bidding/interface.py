"""The interface agent (HMIA, Fig. 3) as actions: its state, and the steps of its work
loop.

========================  ===========================================================
``bidding.interface``     creates the HMIA's state and its global map
``bidding.team``          on REQUEST + INFORM: INITIALIZE to every RA
``bidding.inform``        random deployment: each RA's zone list (INFORM)
``bidding.cfp``           autonomous deployment: the next zone to the RAs (CFP)
``bidding.map``           every zone owned: MAP to every RA
``bidding.end``           every zone mapped: END to every RA, and the map's accuracy
========================  ===========================================================

A robot that stops (a ``kill`` fault) stops answering; the HMIA notices (as a missing
heartbeat: the run's ``core.liveness`` resource, :func:`watch_team`) and offers its
unmapped zones again to the survivors (a re-auction, in both deployments).
"""

from __future__ import annotations

from typing import Any

from petriflow.agents.bidding.agent import Interface
from petriflow.agents.bidding.needs import LIVE, OFFICE, Step, office_of
from petriflow.agents.bidding.protocol import Kind, Payload
from petriflow.capabilities import Bodies
from petriflow.runtime.action import ActionContext, InstantAction, Param

__all__ = ["AUCTION_TIMEOUT", "MakeInterface", "Team", "Inform", "Offer", "StartMapping", "End", "watch_team",
           "reoffer_due"]


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
        office = office_of(ctx)
        if office is not None:
            from petriflow.agents.bidding.grid import GlobalMap

            truth = office.truth(self.params["resolution"])
            hmia.truth = truth
            hmia.global_map = GlobalMap(truth)


#: Seconds the HMIA waits for an ALLOCATED before it offers the zone again.
AUCTION_TIMEOUT = 10.0


def reoffer_due(hmia: Interface) -> float | None:
    """When the auction under way is offered again if nobody answered (``None``: no
    auction is under way); :func:`watch_team` offers it at the first moment after."""
    return None if hmia.auction is None else hmia.auction_at + AUCTION_TIMEOUT


def watch_team(ctx: ActionContext, hmia: Interface) -> None:
    """Robots that stopped: drop what waits for them, re-offer their unmapped zones;
    an auction nobody answered within :data:`AUCTION_TIMEOUT` is offered again."""
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


class _HmiaStep(Step):
    """A step of the HMIA's work loop."""

    agent_state = Interface
    resources = LIVE


class Team(_HmiaStep):
    """HMIA: create the team: INITIALIZE (with its start pose) to every RA; the world's
    robots that are not in the team are taken out of it."""

    uses = (Bodies,)

    def step(self, ctx: ActionContext, hmia: Interface) -> None:
        world = ctx.world  # robots of the world that are not in the team are not deployed
        for agent in [a for a in world.agents if a.startswith("robot") and a not in hmia.robots]:
            world.remove(agent)
        watch_team(ctx, hmia)
        for rank, robot in enumerate(hmia.robots):
            if robot in hmia.alive:
                hmia.queue(robot, Payload(Kind.INITIALIZE, body={"rank": rank, "team": list(hmia.robots)}))
        hmia.initialise_sent = True
        if hmia.mode == "autonomous":
            hmia.to_offer.extend(range(len(hmia.zones)))


class Inform(_HmiaStep):
    """HMIA, random deployment: every RA's zone list (INFORM)."""

    def step(self, ctx: ActionContext, hmia: Interface) -> None:
        watch_team(ctx, hmia)
        for robot, zones in zip(hmia.robots, hmia.lists or []):
            for zone in zones:
                hmia.owner[zone] = robot
            if robot in hmia.alive:
                hmia.queue(robot, Payload(Kind.INFORM, body={
                    "zones": list(zones), "positions": [hmia.zones[z] for z in zones]}))
        hmia.informed = True
        for zone in range(len(hmia.zones)):
            if hmia.owner.get(zone) not in hmia.alive and zone not in hmia.to_offer:
                hmia.owner.pop(zone, None)
                hmia.to_offer.append(zone)


class Offer(_HmiaStep):
    """HMIA: a call for proposals for the next zone to every living RA (CFP)."""

    def step(self, ctx: ActionContext, hmia: Interface) -> None:
        watch_team(ctx, hmia)
        if not hmia.to_offer or not hmia.alive:
            return
        zone = hmia.to_offer.popleft()
        hmia.auction = zone
        hmia.auction_at = ctx.now
        bidders = [r for r in hmia.robots if r in hmia.alive]
        hmia.broadcast(Kind.CFP, bidders, zone, {"position": hmia.zones[zone], "bidders": bidders})
        ctx.emit("bidding.cfp", zone=zone + 1, bidders=len(bidders))


class StartMapping(_HmiaStep):
    """HMIA: every zone has an owner: MAP to every living RA (mapping starts)."""

    def step(self, ctx: ActionContext, hmia: Interface) -> None:
        # mapping until the world is mapped: the RAs look out for every zone (its position in sight)
        body = {"zones": [tuple(z) for z in hmia.zones]} if hmia.until == "mapped" else None
        hmia.broadcast(Kind.MAP, [r for r in hmia.robots if r in hmia.alive], body=body)
        hmia.map_sent = ctx.now
        ctx.emit("bidding.map", owners={str(z + 1): r for z, r in sorted(hmia.owner.items())})


class End(_HmiaStep):
    """HMIA: every zone is mapped: END to every living RA; the map's accuracy (eq. 10)."""

    params = {"tolerance": Param(int, 1, "cells between a mapped point and a real obstacle that still count"
                                 " as real (eq. 10's sigma)", low=0)}

    def step(self, ctx: ActionContext, hmia: Interface) -> None:
        watch_team(ctx, hmia)
        hmia.broadcast(Kind.END, [r for r in hmia.robots if r in hmia.alive])
        hmia.end_sent = ctx.now
        report: dict[str, Any] = {"time_s": round(ctx.now - (hmia.map_sent or 0.0), 6), "points": hmia.points}
        if hmia.global_map is not None:
            from petriflow.agents.bidding.grid import accuracy, fictitious

            score = fictitious(hmia.global_map)
            fit = accuracy(hmia.global_map.occupied, hmia.truth.occupied, self.params["tolerance"])
            report.update(accuracy_pct=round(score.percent, 4), sigma=int(score.sigma), xi=int(score.xi),
                          fit_pct=round(fit.percent, 4), coverage=round(fit.coverage, 4))
        ctx.emit("bidding.end", **report)

