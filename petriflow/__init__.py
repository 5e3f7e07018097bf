"""petriflow: coordinate multi-robot systems with workflow Petri nets.

The core package holds no robotics: the net model (:mod:`petriflow.net`), markings
(:mod:`petriflow.marking`), YAML and PNML I/O (:mod:`petriflow.io`), the firing engine
(:mod:`petriflow.engine`), the runtime (:mod:`petriflow.runtime`), export and the
command line. Robot and vision actions live in ``petriflow.agents`` and
``petriflow.vision`` and are found by name when a net is bound.

Writing and running an action from Python::

    from petriflow import Action, ActionFailure, Param, action, run

    @action("demo.charge", params={"minutes": Param(float, 5.0)})
    def charge(ctx):
        yield ctx.params["minutes"] * 60        # simulated seconds
        if ctx.rng.random() < 0.1:
            raise ActionFailure("charger fault")  # the net routes it by its failed arcs
        return {"battery": 1.0}

    outcome = run("charging.yaml")               # or run(net) with a Net built in code
"""

from petriflow.engine import CompiledNet, Deadlock, Simulation, enabled, fire, fire_sequence
from petriflow.errors import (
    MarkingError,
    NetFormatError,
    NetStructureError,
    NotEnabledError,
    PetriflowError,
    UnknownElementError,
)
from petriflow.io import load_net, save_net
from petriflow.marking import Marking
from petriflow.net import Arc, Net, Operator, Place, Subnet, Transition
from petriflow.outcome import Outcome, StopReason
from petriflow.runtime.action import Action, ActionContext, ActionFailure, Param, Port, Status
from petriflow.runtime.registry import action, guard, metric
from petriflow.runtime.session import run
from petriflow.workflow import add_operator

__version__ = "0.1.0"

__all__ = [
    "Action", "ActionContext", "ActionFailure", "Arc", "CompiledNet", "Deadlock", "Marking",
    "MarkingError", "Net", "NetFormatError", "NetStructureError", "NotEnabledError", "Operator",
    "Outcome", "Param", "PetriflowError", "Place", "Port", "Simulation", "Status", "StopReason",
    "Subnet", "Transition", "UnknownElementError", "action", "add_operator", "enabled", "fire",
    "fire_sequence", "guard", "load_net", "metric", "run", "save_net",
]
