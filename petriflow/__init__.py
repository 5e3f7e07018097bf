"""petriflow: coordinate multi-robot systems with workflow Petri nets.

The core package holds no robotics: the net model (:mod:`petriflow.net`), markings
(:mod:`petriflow.marking`), YAML and PNML I/O (:mod:`petriflow.io`), the firing engine
(:mod:`petriflow.engine`), export and the command line. Robot and vision actions live in
``petriflow.agents`` and ``petriflow.vision`` and are found by name at run time.
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
from petriflow.workflow import add_operator

__version__ = "0.1.0"

__all__ = [
    "Arc", "CompiledNet", "Deadlock", "Marking", "MarkingError", "Net", "NetFormatError",
    "NetStructureError", "NotEnabledError", "Operator", "PetriflowError", "Place",
    "Simulation", "Subnet", "Transition", "UnknownElementError", "add_operator", "enabled",
    "fire", "fire_sequence", "load_net", "save_net",
]
