"""Registers the swarm scenario (the ``petriflow.actions`` entry point ``swarm``): its
actions, the robot state ``swarm.scout``, the guards (with the state keys each reads),
the ``swarm.radio`` medium and the metrics."""

from __future__ import annotations

__all__ = ["register"]

ACTIONS = {
    "swarm.wake": ("Wake", "a swarm robot starts: its state and home cell"),
    "swarm.explore": ("Explore", "read the radio, go one cell towards the unmapped, sense it, plan a frame"),
    "swarm.share": ("Share", "the robot's frame into its radio place (a broadcast)"),
    "swarm.sent": ("Sent", "the frame's airtime is over"),
    "swarm.home": ("Home", "back to the start cell through known cells"),
}


def register(registry) -> None:
    from petriflow.agents.swarm import metrics
    from petriflow.agents.swarm.actions import GUARDS
    from petriflow.agents.swarm.agent import Scout

    for name, (cls, doc) in ACTIONS.items():
        registry.register(name, f"petriflow.agents.swarm.actions:{cls}", doc=doc)
    registry.register_state("swarm.scout", Scout)
    for name, (function, reads) in GUARDS.items():
        registry.predicate(name, reads=reads)(function)
    registry.register_channel("swarm.radio", "petriflow.agents.swarm.radio:SwarmRadio")
    metrics.register(registry)
