"""What the bidding actions declare of their run: the resources they read and the
world capabilities they use (checked when a net binds; see docs/runtime.md,
"Declared needs"), and the base of the agents' work-loop steps (:class:`Step`).

* :data:`OFFICE`: the run's office plan (the ``bidding.office`` resource, a
  :class:`~petriflow.agents.bidding.office.Plan` made from the world file's
  ``meta.office`` section, or ``None``: the world has no office).
* :data:`OFFICE_SETTINGS`: that section of the world file, declared (the resource
  reads it; a misspelt or mistyped setting fails when the world loads, at its line).
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
from petriflow.runtime.action import ActionContext, InstantAction
from petriflow.runtime.settings import Section, Setting

__all__ = ["OFFICE", "OFFICE_SETTINGS", "LIVE", "DRIVEN", "office_of", "Step"]

#: The run's office plan, as actions declare it.
OFFICE = {"office": "bidding.office"}


def _numbers(doc: str) -> Setting:
    return Setting(list, doc=doc, items=Setting(float))


#: The world file's ``meta.office`` (what
#: :meth:`~petriflow.agents.bidding.office.Office.meta` writes), as the
#: ``bidding.office`` resource declares it: checked when the world loads, with the world
#: file's line. A world without it (no ``size``) has no office.
OFFICE_SETTINGS = Section("office", {
    "size": Setting((list, type(None)), None, "the office's L x W (m); none: the world has no office",
                    items=Setting(float)),
    "origin": Setting(list, [0.0, 0.0], "world x, y of its south-west corner (m)", items=Setting(float)),
    "walls": Setting(list, [], "wall boxes [cx, cy, w, d] (m)", items=_numbers("a box [cx, cy, w, d] (m)")),
    "furniture": Setting(list, [], "furniture boxes [cx, cy, w, d] (m)",
                         items=_numbers("a box [cx, cy, w, d] (m)")),
    "rooms": Setting(list, [], "the rooms (the corridor is one, named corridor)", items=Setting(dict, fields={
        "name": Setting(str, doc="the room's name"),
        "xmin": Setting(float, doc="west side (m)"), "ymin": Setting(float, doc="south side (m)"),
        "xmax": Setting(float, doc="east side (m)"), "ymax": Setting(float, doc="north side (m)")})),
    "zones": Setting(list, [], "the zones the interface agent auctions, [x, y] in rank order",
                     items=_numbers("a zone [x, y] (m)")),
    "starts": Setting(list, [], "the robots' starts [x, y, yaw]", items=_numbers("a start [x, y, yaw]")),
}, doc="the office plan the robots navigate on and the map is scored against")


#: Which agents run now (what heartbeats tell), as actions declare it.
LIVE = {"live": "core.liveness"}
#: The world capabilities a robot agent's body (wheels, laser, position) uses.
DRIVEN = (Poses, Bodies, Physics, Stepped)


def office_of(ctx: ActionContext) -> Any:
    """The run's office (:class:`~petriflow.agents.bidding.office.Office`; ``None``: the
    world has none)."""
    plan = ctx.resource("office")
    return None if plan is None else plan.office


class Step(InstantAction):
    """A step of an agent's work loop: :meth:`step` changes the agent's state, which then
    says whether its next step changed (subclasses declare ``agent_state``)."""

    def run(self, ctx: ActionContext) -> None:
        state = ctx.state
        self.step(ctx, state)
        state.changed()

    def step(self, ctx: ActionContext, state: Any) -> None:
        """Change ``state`` (the agent's)."""
        raise NotImplementedError
