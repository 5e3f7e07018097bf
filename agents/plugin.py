"""Registers the actions of ``petriflow.agents`` (the ``petriflow.actions`` entry point).

Targets are lazy ``"module:Class"`` strings: nothing robotic is imported until a net
actually binds one of these actions.
"""

from __future__ import annotations

__all__ = ["register"]

ACTIONS = {
    "drive.goto": ("petriflow.agents.drive:GoTo", "drive a differential robot to (x, y)"),
}


def register(registry) -> None:
    """Register every action of this package in ``registry``."""
    for name, (target, doc) in ACTIONS.items():
        registry.register(name, target, doc=doc)
