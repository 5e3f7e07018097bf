"""Registers seed 004's agents (the ``petriflow.actions`` entry point): actions, the
agent-state types subnets declare (``bidding.operator``, ``bidding.interface``,
``bidding.robot``), guards over those states with the keys each reads, the
``bidding.office`` resource (the run's office plan and navigators, made once per run
from its world) and the mission's metrics."""

from __future__ import annotations

__all__ = ["register"]

_P = "petriflow.agents.bidding"
ACTIONS = {
    "bidding.operator": (f"{_P}.operator:MakeOperator", "the operator: the mission (REQUEST, INFORM)"),
    "bidding.interface": (f"{_P}.interface:MakeInterface", "the interface agent's state and global map"),
    "bidding.robot": (f"{_P}.robot:MakeRobot", "a robot agent's state"),
    "bidding.receive": (f"{_P}.receive:Receive", "one message from the agent's mailbox into its state"),
    "bidding.team": (f"{_P}.interface:Team", "HMIA: INITIALIZE every robot agent"),
    "bidding.inform": (f"{_P}.interface:Inform", "HMIA, random deployment: INFORM each robot of its zones"),
    "bidding.cfp": (f"{_P}.interface:Offer", "HMIA: CFP, the next zone to every living robot agent"),
    "bidding.map": (f"{_P}.interface:StartMapping", "HMIA: MAP, mapping starts"),
    "bidding.end": (f"{_P}.interface:End", "HMIA: END, and the map's accuracy (eq. 10)"),
    "bidding.ready": (f"{_P}.robot:Ready", "RA: laser and pose; INITIALIZED"),
    "bidding.bid": (f"{_P}.robot:Bid", "RA: eq. 6 cost to the other bidders (PROPOSE)"),
    "bidding.decide": (f"{_P}.robot:Decide", "RA: lowest cost wins, ties to the smallest rank (ALLOCATED)"),
    "bidding.explore": (f"{_P}.driving:Explore", "RA: map its zones nearest first, laser scans (MAPPED)"),
    "bidding.send": (f"{_P}.mail:Send", "the next message for one peer into its mailbox"),
    "bidding.cast": (f"{_P}.mail:Cast", "a broadcast into every receiver's mailbox in one firing"),
    "bidding.wait": (f"{_P}.waiting:Wait", "an agent with nothing to do waits for news"),
}


def register(registry) -> None:
    from petriflow.agents.bidding import metrics
    from petriflow.agents.bidding.guards import GUARDS
    from petriflow.agents.bidding.agent import Interface, Operator, RobotAgent

    for name, (target, doc) in ACTIONS.items():
        registry.register(name, target, doc=doc)
    for name, cls in (("bidding.operator", Operator), ("bidding.interface", Interface),
                      ("bidding.robot", RobotAgent)):
        registry.register_state(name, cls)
    for name, (function, reads) in GUARDS.items():
        registry.predicate(name, reads=reads)(function)
    from petriflow.agents.bidding.needs import OFFICE_SETTINGS

    # made from the world alone: a bridged robot's agent makes it from its own world
    registry.register_resource("bidding.office", "petriflow.agents.bidding.office:plan_resource",
                               settings=OFFICE_SETTINGS, per_world=True)
    from petriflow.agents.bidding.protocol import Payload

    registry.register_data_type("bidding.payload", Payload)  # a message's payload, rebuilt across a bridge
    metrics.register(registry)
