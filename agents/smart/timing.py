"""Where a run's wall-clock time goes: render, vision, planning, physics, gait control, net.

:class:`Timers` wraps the functions that do each kind of work, for the duration of a
``with`` block, and adds up their wall-clock time; the components run unchanged (each
wrapper calls the original with the same arguments and returns its result). Nested
calls of one category count once (``smart.follow`` calling the gait's own ``poll``).
What no category claims is the net's own time: the scheduler, guards, token data,
trace and events.

====================  ==================================================================
category              wrapped
====================  ==================================================================
``render``            :meth:`petriflow.world.Camera.capture` (pybullet TinyRenderer)
``vision``            :func:`petriflow.vision.pipeline.process` (segmentation ... grey map)
``planning``          A* on the label map (:func:`~petriflow.agents.planning.actions.plan_world_path`:
                      binary map, C-space, cells, search) and path tracking
                      (:func:`~petriflow.agents.planning.tracking.check_track`); the
                      search alone is also kept as ``search`` (not in the split)
``physics``           :meth:`petriflow.world.World.step`
``control``           the gait actions' ``poll`` (inverse kinematics, motor commands)
====================  ==================================================================

Examples:
    >>> from petriflow.world import World
    >>> with Timers() as timers:
    ...     world = World({"plane": False})
    ...     world.step()
    ...     world.close()
    >>> timers.calls["physics"]
    1
"""

from __future__ import annotations

import functools
import time
from typing import Any

__all__ = ["CATEGORIES", "DETAILS", "Timers"]

#: The measured categories, in report order (``net`` is the remainder).
CATEGORIES = ("render", "vision", "planning", "physics", "control")
#: Measured inside a category, not part of the split: ``search`` is the A* search
#: alone (:func:`~petriflow.agents.planning.astar.astar`), inside ``planning``.
DETAILS = ("search",)


class Timers:
    """Add up wall-clock seconds per category while the block runs (see the module)."""

    def __init__(self) -> None:
        names = CATEGORIES + DETAILS
        self.seconds: dict[str, float] = {c: 0.0 for c in names}
        self.calls: dict[str, int] = {c: 0 for c in names}
        self.samples: dict[str, list[float]] = {c: [] for c in names}
        self._depth: dict[str, int] = {c: 0 for c in names}
        self._patched: list[tuple[Any, str, Any]] = []
        self.wall = 0.0
        self._started = 0.0

    def _wrap(self, owner: Any, name: str, category: str, keep: bool = False) -> None:
        original = owner.__dict__[name]
        function = original.__func__ if isinstance(original, (staticmethod, classmethod)) else original
        clock = time.perf_counter

        @functools.wraps(function)
        def timed(*args: Any, **kwargs: Any) -> Any:
            if self._depth[category]:
                return function(*args, **kwargs)
            self._depth[category] += 1
            began = clock()
            try:
                return function(*args, **kwargs)
            finally:
                took = clock() - began
                self._depth[category] -= 1
                self.seconds[category] += took
                self.calls[category] += 1
                if keep:
                    self.samples[category].append(took)

        setattr(owner, name, timed)
        self._patched.append((owner, name, original))

    def __enter__(self) -> Timers:
        import petriflow.agents.planning.actions as planning_actions
        import petriflow.agents.smart.actions as smart_actions
        from petriflow.agents.legged import actions as legged
        from petriflow.agents.planning import tracking
        from petriflow.vision import pipeline

        from petriflow.world import Camera, World

        self._wrap(Camera, "capture", "render", keep=True)
        self._wrap(pipeline, "process", "vision", keep=True)
        self._wrap(planning_actions, "plan_world_path", "planning", keep=True)
        self._wrap(planning_actions, "astar", "search", keep=True)
        self._wrap(tracking, "check_track", "planning")
        self._wrap(World, "step", "physics")
        for cls in (legged.Walk, legged.StandUp, smart_actions.Follow):
            if "poll" in cls.__dict__:
                self._wrap(cls, "poll", "control")
        self._started = time.perf_counter()
        return self

    def __exit__(self, *exc: object) -> None:
        self.wall = time.perf_counter() - self._started
        for owner, name, original in reversed(self._patched):
            setattr(owner, name, original)
        self._patched.clear()

    def split(self, wall: float | None = None) -> dict[str, float]:
        """Seconds per category plus ``net`` (the rest of ``wall``, default: the block's)."""
        wall = self.wall if wall is None else wall
        out = {c: self.seconds[c] for c in CATEGORIES}
        out["net"] = max(0.0, wall - sum(out.values()))
        return out
