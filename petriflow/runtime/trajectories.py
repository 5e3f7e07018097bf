"""Trajectories: where each agent's robot went during a run, sampled as it runs.

A :class:`Trajectories` watches the scheduler's instants (no event is built for it) and
records each robot's ``(t, x, y)`` at most once every ``every`` simulated seconds, and
once more at the end. ``petriflow run --picture out.png`` draws them over the world's
top view (:func:`petriflow.picture.draw_run`).

Examples:
    >>> from types import SimpleNamespace
    >>> world = SimpleNamespace(agents={"r1": "body1"}, position=lambda a: (1.0, 2.0))
    >>> run = SimpleNamespace(world=world, now=0.0)
    >>> track = Trajectories(every=0.5)
    >>> track(run); run.now = 0.2; track(run); run.now = 0.6; track(run)
    >>> track.paths["r1"]
    [(0.0, 1.0, 2.0), (0.6, 1.0, 2.0)]
"""

from __future__ import annotations

from typing import Any

__all__ = ["Trajectories"]


class Trajectories:
    """Samples every agent's robot position (see the module).

    Args:
        every: simulated seconds between samples.
        limit: the most samples kept per robot; beyond it every other sample is
            dropped and the interval doubled, so a long run keeps its whole path.
    """

    def __init__(self, every: float = 0.5, limit: int = 4000) -> None:
        if not every > 0:
            raise ValueError(f"every must be > 0, got {every!r}")
        self.every = float(every)
        self.limit = max(2, int(limit))
        self.paths: dict[str, list[tuple[float, float, float]]] = {}
        self._next = 0.0

    def __call__(self, scheduler: Any) -> None:
        now = scheduler.now
        if now < self._next or scheduler.world is None:
            return
        self.sample(scheduler.world, now)
        self._next = now + self.every

    def sample(self, world: Any, now: float) -> None:
        """Record where every agent's robot is at ``now``."""
        for agent in list(world.agents):
            where = world.position(agent)
            if where is None:  # removed from the world
                continue
            path = self.paths.setdefault(agent, [])
            if path and path[-1][0] == now:
                continue
            path.append((float(now), float(where[0]), float(where[1])))
            if len(path) > self.limit:
                path[:] = path[::2]
                self.every *= 2
