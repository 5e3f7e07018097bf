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
from petriflow.netbuild import AgentBuilder, Mailbox, NetBuilder
from petriflow.runtime.action import Action, ActionContext, ActionFailure, InstantAction, Param, Port, Status
from petriflow.runtime.agents import AgentState
from petriflow.runtime.clock import RealtimeClock, SimulatedClock
from petriflow.runtime.config import RunConfig
from petriflow.runtime.registry import Registry, action, default_registry, guard, metric
from petriflow.runtime.resources import Liveness, ResourceContext
from petriflow.runtime.scheduler import RunResult, Scheduler
from petriflow.runtime.session import RunOutcome, run
from petriflow.workflow import add_operator
from petriflow.view import view

__version__ = "0.1.0"

__all__ = [
    "Action", "ActionContext", "ActionFailure", "AgentBuilder", "AgentState", "Arc", "CompiledNet", "Deadlock",
    "InstantAction", "Liveness", "Mailbox", "Marking", "MarkingError", "Net", "NetBuilder", "NetFormatError",
    "NetStructureError", "NotEnabledError", "Operator", "Outcome", "Param", "PetriflowError", "Place", "Port",
    "RealtimeClock", "Registry", "ResourceContext", "RunConfig", "RunOutcome", "RunResult", "Scheduler",
    "Simulation", "SimulatedClock", "Status", "StopReason", "Subnet", "Transition", "UnknownElementError",
    "action", "add_operator", "default_registry", "enabled", "fire", "fire_sequence", "guard", "load_net",
    "metric", "run", "save_net", "view",
]
