"""Registers seed 001 (the ``petriflow.actions`` entry point ``slam``): its actions, the
agent-state types, the guards (with the state keys each reads), the ``slam.air``
resource (the radios' beacons), the ``slam.esp8266`` channel model and the metrics."""

from __future__ import annotations

__all__ = ["register"]

ACTIONS = {
    "slam.boot": ("Boot", "an RA starts: body, UMBmark-calibrated wheels, history; reads a WA's map"),
    "slam.explore": ("Explore", "one leg of Algorithm 1: choose, drive to the next sensor event, update"),
    "slam.install": ("Install", "drop, boot and program the next WA (SSID, array, position)"),
    "slam.finish": ("Finish", "nothing pending: the map is done"),
    "slam.scan": ("Scan", "a WA's Algorithm 2 cycle: scan, exchange, roles, alerts"),
    "slam.switch_off": ("SwitchOff", "a WA's radio goes off at the end"),
    "slam.send": ("Send", "the next frame (or alert) of the agent into the air (or the base's box)"),
    "slam.receive": ("Receive", "a frame for this agent: merge, answer, decide"),
    "slam.central_boot": ("CentralBoot", "the central unit starts"),
    "slam.serve": ("Serve", "the central unit's loop: alerts, its failure"),
    "slam.dispatch": ("Dispatch", "the base sends a reserve RA in"),
}


def register(registry) -> None:
    from petriflow.agents.slam import metrics
    from petriflow.agents.slam.actions import AIR, GUARDS
    from petriflow.agents.slam.agent import Base, Central, Robot, Wireless

    for name, (cls, doc) in ACTIONS.items():
        registry.register(name, f"petriflow.agents.slam.actions:{cls}", doc=doc)
    for name, cls in (("slam.robot", Robot), ("slam.wireless", Wireless), ("slam.central", Central),
                      ("slam.base", Base)):
        registry.register_state(name, cls)
    for name, (function, reads) in GUARDS.items():
        registry.predicate(name, reads=reads)(function)
    registry.register_resource(AIR, "petriflow.agents.slam.agent:make_air")
    registry.register_channel("slam.esp8266", "petriflow.agents.slam.radio:ESP8266")
    metrics.register(registry)
