"""Registers seed 000's framework (the ``petriflow.actions`` entry point): actions,
guards over the agent's state (with the state keys each reads), the agent-state type
``comm.agent`` (:class:`~petriflow.agents.comm.agent.CommAgent`; subnets declare
``state: comm.agent``), the ``comm.radio`` channel model and the mission's metrics."""

from __future__ import annotations

__all__ = ["register"]

ACTIONS = {
    "comm.characterise": ("petriflow.agents.comm.actions:Characterise", "process 1: agent state, dpp, grid"),
    "comm.analyse": ("petriflow.agents.comm.actions:Analyse", "process 2: the Fig. 5 sweep of a radio link"),
    "comm.initialise": ("petriflow.agents.comm.actions:Initialise", "process 3: address (eq. 4) or DHCP (eq. 5)"),
    "comm.history": ("petriflow.agents.comm.actions:MakeHistory", "process 4: empty data and history arrays"),
    "comm.explore": ("petriflow.agents.comm.actions:Explore", "a robot explores one maze cell and plans sends"),
    "comm.listen": ("petriflow.agents.comm.actions:Listen", "a static agent waits and plans sends"),
    "comm.send": ("petriflow.agents.comm.actions:Send", "process 5: one message into a channel place"),
    "comm.receive": ("petriflow.agents.comm.actions:Receive", "one message from a channel place into the history"),
}


def register(registry) -> None:
    from petriflow.agents.comm import metrics
    from petriflow.agents.comm.actions import GUARDS
    from petriflow.agents.comm.agent import CommAgent

    for name, (target, doc) in ACTIONS.items():
        registry.register(name, target, doc=doc)
    registry.register_state("comm.agent", CommAgent)
    for name, (function, reads) in GUARDS.items():
        registry.predicate(name, reads=reads)(function)
    registry.register_channel("comm.radio", "petriflow.agents.comm.radio:RadioChannel")
    metrics.register(registry)
