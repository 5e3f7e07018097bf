"""Receiving: one message from an agent's mailbox into its state, by a table.

``bidding.receive`` takes one token from the agent's mailbox (a channel place) and
hands its message (a :class:`~petriflow.runtime.channel_models.Message` carrying a
:class:`~petriflow.agents.bidding.protocol.Payload`) to the handler the agent's table
names for its kind (:data:`RECEIVE`: ``{agent state type: {Kind:
handler}}``); a kind the agent has no handler for only counts as received. A handler
changes the state; the state then says whether its next step changed.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from petriflow.agents.bidding.agent import Auction, Interface, RobotAgent
from petriflow.agents.bidding.needs import LIVE
from petriflow.agents.bidding.protocol import Kind, Payload
from petriflow.runtime.channel_models import Message
from petriflow.runtime.action import ActionContext, ActionFailure, InstantAction, Param

__all__ = ["Receive", "RECEIVE", "HMIA_RECEIVES", "ROBOT_RECEIVES"]

#: What a handler is: ``handler(ctx, state, message)`` (its ``data`` a :class:`Payload`).
Handler = Callable[[ActionContext, Any, Message], None]


# The interface agent ----------------------------------------------------------------------

def request(ctx: ActionContext, hmia: Interface, message: Message) -> None:
    """REQUEST: the operator asks for a map."""
    hmia.request = message


def mission(ctx: ActionContext, hmia: Interface, message: Message) -> None:
    """INFORM (from the operator): the deployment, the team, the zones, the lists."""
    body = message.data.body
    hmia.mode = body["deployment"]
    hmia.robots = list(body["robots"])
    hmia.zones = [tuple(z) for z in body["zones"]]
    hmia.lists = body["lists"]
    live = ctx.resource("live")
    hmia.alive = {r for r in hmia.robots if live.alive(r)}
    hmia.requested = True


def initialised(ctx: ActionContext, hmia: Interface, message: Message) -> None:
    """INITIALIZED: a robot agent is ready."""
    hmia.initialised.add(message.sender)


def allocated(ctx: ActionContext, hmia: Interface, message: Message) -> None:
    """ALLOCATED: a zone's auction is won."""
    zone = message.data.zone
    hmia.owner[zone] = message.sender
    if hmia.auction == zone:
        hmia.auction = None
    ctx.emit("bidding.allocated", zone=zone + 1, robot=message.sender, cost=message.data.body.get("cost"))


def mapped(ctx: ActionContext, hmia: Interface, message: Message) -> None:
    """MAPPED: world points into the global map; zones reached and first in sight."""
    points = message.data.body.get("points")
    if points is not None and len(points) and hmia.global_map is not None:
        hmia.points += len(points)
        hmia.global_map.add(int(message.data.body.get("rank", 0)), np.asarray(points, dtype=float),
                            real=message.data.body.get("real"))
    for zone in message.data.body.get("finished", ()):
        if zone not in hmia.finished:
            hmia.finished.add(zone)
            ctx.emit("bidding.zone_mapped", zone=zone + 1, robot=message.sender)
    for zone in message.data.body.get("seen", ()):
        if zone not in hmia.seen:
            hmia.seen.add(zone)
            ctx.emit("bidding.zone_seen", zone=zone + 1, robot=message.sender)


#: The HMIA's handlers, by kind.
HMIA_RECEIVES: dict[Kind, Handler] = {
    Kind.REQUEST: request,
    Kind.INFORM: mission,
    Kind.INITIALIZED: initialised,
    Kind.ALLOCATED: allocated,
    Kind.MAPPED: mapped,
}


# Robot agents -----------------------------------------------------------------------------

def initialise(ctx: ActionContext, ra: RobotAgent, message: Message) -> None:
    """INITIALIZE: the robot's rank and team (taken by ``bidding.ready``)."""
    ra.initialise = message


def zone_list(ctx: ActionContext, ra: RobotAgent, message: Message) -> None:
    """INFORM (random deployment): the operator's list for this robot, in visiting order."""
    body = message.data.body
    for zone, position in zip(body["zones"], body["positions"]):
        ra.zones[zone] = tuple(position)
        if zone not in ra.mine:
            ra.mine.append(zone)
        ra.order.append(zone)


def call(ctx: ActionContext, ra: RobotAgent, message: Message) -> None:
    """CFP: a zone under auction (a call for the same zone replaces the older one)."""
    body = message.data.body
    ra.auctions = type(ra.auctions)(a for a in ra.auctions if a.zone != message.data.zone)
    ra.auctions.append(Auction(message.data.zone, tuple(body["position"]), list(body["bidders"])))
    ra.zones[message.data.zone] = tuple(body["position"])


def proposal(ctx: ActionContext, ra: RobotAgent, message: Message) -> None:
    """PROPOSE: another bidder's cost for a zone under auction."""
    body = message.data.body
    for auction in ra.auctions:
        if auction.zone == message.data.zone:
            auction.propose(message.sender, float(body["cost"]), ra.name, ra.alive)
            ra.ranks[message.sender] = int(body["rank"])


def start_mapping(ctx: ActionContext, ra: RobotAgent, message: Message) -> None:
    """MAP: mapping starts (with the mission's zones to look out for)."""
    ra.mapping = True
    ra.sight = {int(z): (float(p[0]), float(p[1])) for z, p in enumerate(message.data.body.get("zones", ()))}


def end(ctx: ActionContext, ra: RobotAgent, message: Message) -> None:
    """END: the mission is over."""
    ra.ended = True
    ra.mapping = False


#: A robot agent's handlers, by kind.
ROBOT_RECEIVES: dict[Kind, Handler] = {
    Kind.INITIALIZE: initialise,
    Kind.INFORM: zone_list,
    Kind.CFP: call,
    Kind.PROPOSE: proposal,
    Kind.MAP: start_mapping,
    Kind.END: end,
}

#: ``{agent state type: {Kind: handler}}``: who handles what.
RECEIVE: dict[type, dict[Kind, Handler]] = {Interface: HMIA_RECEIVES, RobotAgent: ROBOT_RECEIVES}


class Receive(InstantAction):
    """One message from the agent's mailbox into its state (see the module)."""

    agent_state = (Interface, RobotAgent)
    resources = LIVE
    params = {"box": Param(str, doc="the mailbox (channel place)", places="")}

    def run(self, ctx: ActionContext) -> None:
        state = ctx.state
        packet = ctx.inputs[self.params["box"]][0]
        message = packet.get("message") if isinstance(packet, dict) else None
        if not (isinstance(message, Message) and isinstance(message.data, Payload)):
            raise ActionFailure(f"bidding.receive: {self.params['box']!r} held no protocol message")
        state.received[message.kind] = state.received.get(message.kind, 0) + 1
        handler = RECEIVE[type(state)].get(message.kind)
        if handler is not None:
            handler(ctx, state, message)
        state.changed()
