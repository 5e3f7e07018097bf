"""Where a run's wall-clock time goes: render, vision, planning, physics, gait control, net.

:class:`Timers` is the run's stopwatch (:mod:`petriflow.runtime.stopwatch`), given to
it as ``run_files(..., stopwatch=timers)``: the run's parts report their work to it,
nothing is patched. Nested measures of one category count once (``smart.follow``
calling the gait's own ``poll``). What no category claims is the net's own time: the
scheduler, guards, token data, trace and events.

====================  ==================================================================
category              measured by
====================  ==================================================================
``render``            ``vision.capture`` around the camera's frame (pybullet TinyRenderer)
``vision``            ``vision.locate`` around :func:`petriflow.vision.pipeline.process`
                      (segmentation ... grey map)
``planning``          ``planning.astar`` around A* on the label map
                      (:func:`~petriflow.agents.planning.actions.plan_world_path`:
                      binary map, C-space, cells, search), and path tracking
                      (:func:`~petriflow.agents.planning.tracking.check_track` in
                      ``planning.track`` and ``smart.follow``); the search alone is
                      also kept as ``search`` (not in the split)
``physics``           the run's clock around each world step
``control``           the gait actions' ``poll`` (``@timed("control")``: inverse
                      kinematics, motor commands)
====================  ==================================================================

Examples:
    >>> with Timers() as timers:
    ...     with timers.measure("physics"):
    ...         pass
    >>> timers.calls["physics"], timers.calls["render"], sorted(timers.split()) == sorted(CATEGORIES + ("net",))
    (1, 0, True)
"""

from __future__ import annotations

import time

from petriflow.runtime.stopwatch import Stopwatch

__all__ = ["CATEGORIES", "DETAILS", "Timers"]

#: The measured categories, in report order (``net`` is the remainder).
CATEGORIES = ("render", "vision", "planning", "physics", "control")
#: Measured inside a category, not part of the split: ``search`` is the A* search
#: alone (:func:`~petriflow.agents.planning.astar.astar`), inside ``planning``.
DETAILS = ("search",)


class Timers(Stopwatch):
    """A run's stopwatch over :data:`CATEGORIES` and :data:`DETAILS`; as a ``with``
    block, it also keeps the block's wall-clock time (``wall``) for :meth:`split`."""

    def __init__(self) -> None:
        super().__init__(CATEGORIES + DETAILS)
        self.wall = 0.0
        self._started = 0.0

    def __enter__(self) -> Timers:
        self._started = time.perf_counter()
        return self

    def __exit__(self, *exc: object) -> None:
        self.wall = time.perf_counter() - self._started

    def split(self, wall: float | None = None) -> dict[str, float]:
        """Seconds per category plus ``net`` (the rest of ``wall``, default: the block's)."""
        wall = self.wall if wall is None else wall
        out = {c: self.seconds[c] for c in CATEGORIES}
        out["net"] = max(0.0, wall - sum(out.values()))
        return out
