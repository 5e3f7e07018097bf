"""What the bidding actions declare of their run: the resources they read and the
world capabilities they use (checked when a net binds; see docs/runtime.md,
"Declared needs").

* :data:`OFFICE`: the run's office plan (the ``bidding.office`` resource, a
  :class:`~petriflow.agents.bidding.office.Plan` made from the world file's
  ``meta.office`` section, or ``None``: the world has no office).
* :data:`LIVE`: which agents run now (what heartbeats tell: ``core.liveness``).
* :data:`DRIVEN`: what a robot agent's body needs of the world: its pose and body
  (:class:`~petriflow.capabilities.Poses`, :class:`~petriflow.capabilities.Bodies`),
  the physics client its wheels and laser use
  (:class:`~petriflow.capabilities.Physics`) and the world's time step
  (:class:`~petriflow.capabilities.Stepped`).
"""

from __future__ import annotations

from typing import Any

from petriflow.capabilities import Bodies, Physics, Poses, Stepped
from petriflow.runtime.action import ActionContext

__all__ = ["OFFICE", "LIVE", "DRIVEN", "office_of"]

#: The run's office plan, as actions declare it.
OFFICE = {"office": "bidding.office"}
#: Which agents run now (what heartbeats tell), as actions declare it.
LIVE = {"live": "core.liveness"}
#: The world capabilities a robot agent's body (wheels, laser, position) uses.
DRIVEN = (Poses, Bodies, Physics, Stepped)


def office_of(ctx: ActionContext) -> Any:
    """The run's office (:class:`~petriflow.agents.bidding.office.Office`; ``None``: the
    world has none)."""
    plan = ctx.resource("office")
    return None if plan is None else plan.office
