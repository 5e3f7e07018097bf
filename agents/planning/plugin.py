"""Registers the planning actions and guards (the ``petriflow.actions`` entry point
``planning``).

Action targets are lazy ``"module:Class"`` strings, so neither numpy-heavy planning code
nor numba is imported until a net binds one of these actions. The guards are plain
functions from a module that imports nothing heavy.

Examples:
    >>> from petriflow.runtime.registry import Registry
    >>> registry = Registry(load_plugins=False)
    >>> register(registry)
    >>> [name for name in registry.names() if name.startswith("planning.")]
    ['planning.astar', 'planning.track']
    >>> registry.guard("planning.replan")({"p": [{"decision": "replan"}]}, {})
    True
"""

from __future__ import annotations

__all__ = ["register", "ACTIONS"]

ACTIONS = {
    "planning.astar": ("petriflow.agents.planning.actions:PlanPath",
                       "plan a robot's path with A* on the camera's label map"),
    "planning.track": ("petriflow.agents.planning.actions:TrackPath",
                       "check a robot against its path: on track, reinsert, or re-plan"),
}


def register(registry) -> None:
    """Register the planning actions and guards in ``registry``."""
    from petriflow.agents.planning.guards import GUARDS

    for name, (target, doc) in ACTIONS.items():
        registry.register(name, target, doc=doc)
    for name, function in GUARDS.items():
        registry.predicate(name)(function)
