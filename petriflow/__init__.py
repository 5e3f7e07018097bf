"""petriflow: coordinate multi-robot systems with workflow Petri nets.

The top level holds the stable names (``__all__``; see ``docs/api.md``): the net model,
reading and writing nets, the two rules of the token game, :func:`run` (the one way to
run a net from Python), what an action is made of, :class:`NetBuilder`, :func:`view`
and the errors a caller catches. Everything else lives in its subpackage
(:mod:`petriflow.engine`, :mod:`petriflow.runtime`, :mod:`petriflow.analysis`,
:mod:`petriflow.io`, :mod:`petriflow.sweep`, ...). The core holds no robotics: robot
and vision actions live in ``petriflow.agents`` and ``petriflow.vision`` and are found
by name when a net is bound.

``import petriflow`` is light: a stable name loads its module the first time it is
asked for, so a script that only reads a net never imports the runtime.

Examples:
    A net built in code, an action written as a generator function, one run:

    >>> from petriflow import Net, Param, action, run
    >>> from petriflow.runtime.registry import Registry
    >>> registry = Registry(load_plugins=False)
    >>> @action("demo.charge", params={"minutes": Param(float, 5.0)}, registry=registry)
    ... def charge(ctx):
    ...     yield ctx.params["minutes"] * 60       # simulated seconds
    ...     return {"battery": 1.0}                 # the output tokens' data
    >>> net = Net("charging")
    >>> _ = net.add_place("empty", tokens=1); _ = net.add_place("full")
    >>> _ = net.add_transition("charge", action="demo.charge", params={"minutes": 2})
    >>> _ = net.add_arc("empty", "charge"); _ = net.add_arc("charge", "full")
    >>> outcome = run(net, registry=registry)
    >>> outcome.result.reason, outcome.result.time, outcome.result.tokens
    (<StopReason.FINAL: 'final'>, 120.0, {'full': [{'battery': 1.0}]})

    A name that left the top level says where it lives now:

    >>> import petriflow
    >>> petriflow.Scheduler
    Traceback (most recent call last):
    ...
    AttributeError: petriflow.Scheduler is not a top-level name: import it from petriflow.runtime.scheduler
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

# ``view`` is a function and a subpackage of the same name; importing it here, where
# it costs one small module, keeps ``petriflow.view`` the function whatever imports
# ``petriflow.view.*`` later.
from petriflow.view import view

if TYPE_CHECKING:  # what type checkers and editors see; at run time __getattr__ loads them
    from petriflow.engine import enabled, fire
    from petriflow.errors import NetFormatError, NetStructureError, NotEnabledError, PetriflowError
    from petriflow.io import load_net, save_net
    from petriflow.marking import Marking
    from petriflow.net import Arc, Net, Place, Subnet, Transition
    from petriflow.netbuild import NetBuilder
    from petriflow.outcome import StopReason
    from petriflow.runtime.action import Action, ActionContext, ActionFailure, Param, Port, Status
    from petriflow.runtime.registry import action, guard, metric
    from petriflow.runtime.session import run

__version__ = "0.1.0"

#: The stable names, by the module that defines them (docs/api.md lists them).
_STABLE_BY_MODULE = {
    "petriflow.net": ("Net", "Place", "Transition", "Arc", "Subnet"),  # the net model
    "petriflow.marking": ("Marking",),
    "petriflow.io": ("load_net", "save_net"),  # net files
    "petriflow.engine": ("enabled", "fire"),  # the token game's two rules
    "petriflow.runtime.session": ("run",),  # the one way to run a net from Python
    "petriflow.outcome": ("StopReason",),
    "petriflow.runtime.action": ("Action", "ActionContext", "ActionFailure", "Param", "Port", "Status"),
    "petriflow.runtime.registry": ("action", "guard", "metric"),
    "petriflow.netbuild": ("NetBuilder",),
    "petriflow.errors": ("PetriflowError", "NetFormatError", "NetStructureError", "NotEnabledError"),
}
_STABLE = {name: module for module, names in _STABLE_BY_MODULE.items() for name in names}

#: Names the top level used to hold, and the module to import each one from now.
_MOVED = {
    "AgentBuilder": "petriflow.netbuild", "Mailbox": "petriflow.netbuild",
    "AgentState": "petriflow.runtime.agents",
    "CompiledNet": "petriflow.engine", "Deadlock": "petriflow.engine", "Simulation": "petriflow.engine",
    "fire_sequence": "petriflow.engine",
    "InstantAction": "petriflow.runtime.action",
    "Liveness": "petriflow.runtime.resources", "ResourceContext": "petriflow.runtime.resources",
    "MarkingError": "petriflow.errors", "UnknownElementError": "petriflow.errors",
    "Operator": "petriflow.net", "Outcome": "petriflow.outcome",
    "RealtimeClock": "petriflow.runtime.clock", "SimulatedClock": "petriflow.runtime.clock",
    "Registry": "petriflow.runtime.registry", "default_registry": "petriflow.runtime.registry",
    "RunConfig": "petriflow.runtime.config",
    "RunOutcome": "petriflow.runtime.session",
    "RunResult": "petriflow.runtime.scheduler", "Scheduler": "petriflow.runtime.scheduler",
    "add_operator": "petriflow.workflow",
}

__all__ = sorted([*_STABLE, "view"], key=lambda name: (name[0].islower(), name))


def __getattr__(name: str) -> Any:
    """A stable name, imported from its module the first time it is asked for.

    Raises:
        AttributeError: ``name`` is not a top-level name (one that moved names its
            module), so ``from petriflow import examples`` still finds the submodule.
    """
    home = _STABLE.get(name)
    if home is None:
        where = f": import it from {_MOVED[name]}" if name in _MOVED else ""
        raise AttributeError(f"petriflow.{name} is not a top-level name{where}")
    value = getattr(importlib.import_module(home), name)
    globals()[name] = value  # asked once: later lookups find it without this hook
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
