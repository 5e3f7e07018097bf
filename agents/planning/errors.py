"""The error planning raises when it is asked something it cannot answer.

A goal that no path reaches is not an error (:class:`~petriflow.agents.planning.astar.Plan`
says ``found=False``); a start or goal outside the map or inside an obstacle, or a robot
that is not on the map, is.

Examples:
    >>> issubclass(PlanningError, ValueError)
    True
"""

from __future__ import annotations

from petriflow.errors import PetriflowError

__all__ = ["PlanningError"]


class PlanningError(PetriflowError, ValueError):
    """A planning request that makes no sense: a blocked or out-of-map start or goal,
    an unknown robot colour, a bad map."""
