"""Registers the legged robots' gait actions (the ``legged`` ``petriflow.actions`` entry point).

Targets are lazy ``"module:Class"`` strings: pybullet and the gait code are imported
only when a net binds one of these actions.

Examples:
    >>> from petriflow.runtime.registry import Registry
    >>> registry = Registry(load_plugins=False)
    >>> register(registry)
    >>> [name for name in registry.names() if name.startswith("gait.")]
    ['gait.brace', 'gait.stand_up', 'gait.turn', 'gait.walk']
"""

from __future__ import annotations

__all__ = ["ACTIONS", "register"]

ACTIONS = {
    "gait.walk": ("petriflow.agents.legged.actions:Walk",
                  "walk a legged robot to (x, y) or a distance along its heading"),
    "gait.turn": ("petriflow.agents.legged.actions:Turn", "turn a legged robot on the spot by an angle"),
    "gait.brace": ("petriflow.agents.legged.actions:Brace",
                   "helper: walk behind a fallen robot's back and hold it"),
    "gait.stand_up": ("petriflow.agents.legged.actions:StandUp",
                      "a fallen Robot4L rolls from its side onto its feet (leaning on a helper)"),
}


def register(registry) -> None:
    """Register the gait actions in ``registry``."""
    for name, (target, doc) in ACTIONS.items():
        registry.register(name, target, doc=doc)
