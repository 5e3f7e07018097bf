"""A run's picture: the world seen from above with the robots' trajectories.

``petriflow run NET --picture out.png`` (or ``run_files(..., picture=...)``) draws it at
the end of the run, from the world as it is then: every fixed body (walls, furniture,
posts) as its outline (:func:`petriflow.runtime.poses.outlines`, what the run viewer
draws too), every agent's path as a line from a circle (start) to a triangle
(where it ended), named. The ground plane is left out.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from petriflow.runtime.poses import outlines as fixed_outlines

__all__ = ["draw_run"]


def draw_run(world: Any, paths: dict[str, list[tuple[float, float, float]]], out: str | Path,
             title: str = "") -> None:
    """Write the top view of ``world`` with ``paths`` (``{agent: [(t, x, y), ...]}``) to
    ``out`` (PNG, SVG or PDF by its suffix)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon

    outlines = [shape["points"] for shape in fixed_outlines(world)]
    xs = [x for shape in outlines for x, _ in shape] + [x for path in paths.values() for _, x, _ in path]
    ys = [y for shape in outlines for _, y in shape] + [y for path in paths.values() for _, _, y in path]
    if not xs:
        xs, ys = [-1.0, 1.0], [-1.0, 1.0]
    width, height = max(xs) - min(xs), max(ys) - min(ys)
    scale = 9.0 / max(width, height, 1e-6)
    figure, axes = plt.subplots(figsize=(max(3.0, width * scale + 1.5), max(3.0, height * scale + 1.0)))
    try:
        for shape in outlines:
            axes.add_patch(Polygon(shape, closed=True, facecolor="0.55", edgecolor="0.35", linewidth=0.5))
        colours = plt.get_cmap("tab10" if len(paths) <= 10 else "tab20")
        named = len(paths) <= 40
        for k, (agent, path) in enumerate(sorted(paths.items())):
            if not path:
                continue
            colour = colours(k % colours.N)
            px, py = [x for _, x, _ in path], [y for _, _, y in path]
            axes.plot(px, py, color=colour, linewidth=1.2, label=agent if named else None)
            axes.plot(px[:1], py[:1], "o", color=colour, markersize=5)
            axes.plot(px[-1:], py[-1:], "^", color=colour, markersize=6)
            if named:
                axes.annotate(agent, (px[-1], py[-1]), textcoords="offset points", xytext=(4, 4),
                              fontsize=7, color=colour)
        margin = 0.03 * max(width, height, 1.0)
        axes.set_xlim(min(xs) - margin, max(xs) + margin)
        axes.set_ylim(min(ys) - margin, max(ys) + margin)
        axes.set_aspect("equal")
        axes.set_xlabel("x (m)")
        axes.set_ylabel("y (m)")
        axes.set_title(title or "top view", fontsize=9)
        if named and paths:
            axes.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
        figure.tight_layout()
        figure.savefig(out, dpi=110)
    finally:
        plt.close(figure)
