"""Registers seed 002's buses as channel models (``bus.serial``, ``bus.can``,
``bus.zigbee``), the modules' firmware as actions and guards, and the chain's metrics.

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
    "bus.serial": "petriflow.agents.bus.parameters:SerialBus",
    "bus.can": "petriflow.agents.bus.parameters:CanBus",
    "bus.zigbee": "petriflow.agents.bus.parameters:ZigbeeBus",
}


_F = "petriflow.agents.bus.firmware"
#: The firmware's actions (see :mod:`petriflow.agents.bus.firmware`).
ACTIONS = {
    "bus.boot": (f"{_F}:Boot", "a module starts: auto-addressing, its scheme and oscillator"),
    "bus.cpg": (f"{_F}:Cpg", "theta = CPG(...); move actuator: one control step"),
    "bus.wait": (f"{_F}:Wait", "algorithm 1: Wait(Delay)"),
    "bus.send": (f"{_F}:Send", "send the CPG message: one frame to the addressees"),
    "bus.available": (f"{_F}:Available", "algorithm 2: the bus-available interrupt"),
    "bus.overflow": (f"{_F}:Overflow", "algorithm 2: the 1 s overflow interrupt"),
    "bus.receive": (f"{_F}:Receive", "the reception routine (a frame, or a loss notice)"),
    "bus.drain": (f"{_F}:Drain", "a frame for no module leaves the bus"),
    "bus.sniffer": (f"{_F}:Sniffer", "the sniffer joins the bus as a node that only listens"),
    "bus.sniffed": (f"{_F}:Sniffed", "the sniffer's record: frames captured per module"),
}


def register(registry) -> None:
    """Register the three buses, the firmware's actions and guards, and the metrics in ``registry``."""
    for name, target in CHANNEL_MODELS.items():
        registry.register_channel(name, target)
    for name, (target, doc) in ACTIONS.items():
        registry.register(name, target, doc=doc)
    from petriflow.agents.bus import metrics
    from petriflow.agents.bus.firmware import GUARDS

    for name, function in GUARDS.items():
        registry.predicate(name)(function)
    metrics.register(registry)
