"""Registers the actions of ``petriflow.agents`` (the ``petriflow.actions`` entry point).

Targets are lazy ``"module:Class"`` strings: nothing robotic is imported until a net
actually binds one of these actions.
"""

from __future__ import annotations

__all__ = ["register"]

ACTIONS = {
    "drive.goto": ("petriflow.agents.drive:GoTo", "drive a differential robot to (x, y)"),
    "smart.capture": ("petriflow.agents.smart.actions:Capture",
                      "vision.capture after putting the world's marker hats on (once)"),
    "smart.dispatch": ("petriflow.agents.smart.actions:Dispatch",
                       "decision maker: start the helping task (final point, map, SMART frames)"),
    "smart.send": ("petriflow.agents.smart.actions:Send", "send fixed SMART command frames"),
    "smart.follow": ("petriflow.agents.smart.actions:Follow",
                     "walk a planned path by the gait, tracking it after every move (and brace)"),
    "smart.avoid": ("petriflow.agents.smart.actions:Avoid",
                    "collision detection: the lower-priority robot holds, the other re-plans"),
    "smart.push": ("petriflow.agents.smart.actions:Push", "push a robot with an external force"),
}


def register(registry) -> None:
    """Register every action (and the SMART guards) of this package in ``registry``."""
    from petriflow.agents.smart.guards import GUARDS

    for name, (target, doc) in ACTIONS.items():
        registry.register(name, target, doc=doc)
    for name, function in GUARDS.items():
        registry.predicate(name)(function)
    from petriflow.agents.smart.arena import SMART

    registry.register_resource("smart.arena", "petriflow.agents.smart.arena:arena_resource", settings=SMART)
