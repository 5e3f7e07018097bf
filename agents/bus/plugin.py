"""Registers seed 002's buses as channel models: ``bus.serial``, ``bus.can``, ``bus.zigbee``.

A run configuration then names them like the built-in models
(``channels: {cpg: {model: bus.can, read_period: 0.02}}``). Targets are lazy
``"module:Class"`` strings.

Examples:
    >>> from petriflow.runtime.registry import Registry
    >>> registry = Registry(load_plugins=False)
    >>> register(registry)
    >>> registry.channel_names()
    ['bus.can', 'bus.serial', 'bus.zigbee']
    >>> registry.channel_model("bus.can").__name__
    'CanBus'
"""

from __future__ import annotations

__all__ = ["CHANNEL_MODELS", "register"]

#: Channel model names and their classes.
CHANNEL_MODELS = {
    "bus.serial": "petriflow.agents.bus.medium:SerialBus",
    "bus.can": "petriflow.agents.bus.medium:CanBus",
    "bus.zigbee": "petriflow.agents.bus.medium:ZigbeeBus",
}


def register(registry) -> None:
    """Register the three buses in ``registry``."""
    for name, target in CHANNEL_MODELS.items():
        registry.register_channel(name, target)
