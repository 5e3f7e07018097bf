"""Each agent's topological map at the end of a run, drawn beside the maze's (seed 000
Fig. 11: the vertices an agent lacks are marked).

``python -m petriflow.agents.comm.maps SWEEP.yaml ROW OUT.png`` runs one trial of a sweep
file (its row ``ROW``, counted from 1, seed 1) and draws the maps.

Examples:
    >>> from petriflow.runtime.trace import Event
    >>> held = holdings_at_end([Event(0, 1.0, "custom", None, "r1", {"name": "comm.learnt", "data": {"ids": [3, 4]}})])
    >>> held
    {'r1': {3, 4}}
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from petriflow.agents.mobile.maze import from_meta

__all__ = ["holdings_at_end", "draw_maps"]


def holdings_at_end(events: list[Any]) -> dict[str, set[int]]:
    """``{agent: vertex ids it holds}`` at the end of a run, from its ``comm.learnt`` reports."""
    held: dict[str, set[int]] = {}
    for event in events:
        if event.kind == "custom" and event.data.get("name") == "comm.learnt":
            held.setdefault(event.agent, set()).update(event.data["data"].get("ids", []))
    return held


def draw_maps(events: list[Any], maze_meta: dict[str, Any], path: str | Path, title: str = "") -> dict[str, int]:
    """One panel per agent: the maze's map in grey, the agent's vertices and the corridors
    between two of them in colour, missing vertices as red crosses. Returns the number
    of vertices each agent lacks."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    maze = from_meta(maze_meta)
    graph = maze.graph()
    ids = {r * maze.cols + c: (r, c) for r, c in graph.nodes}
    held = holdings_at_end(events)
    killed = {e.agent for e in events if e.kind == "fault" and e.data.get("fault") == "kill"}
    agents = sorted(held)
    figure, axes = plt.subplots(1, max(1, len(agents)), figsize=(3.6 * max(1, len(agents)), 3.8), squeeze=False)
    lacking = {}
    for axis, agent in zip(axes[0], agents):
        have = {ids[v] for v in held[agent] if v in ids}
        for a, b in graph.edges:
            (xa, ya), (xb, yb) = maze.centre(a), maze.centre(b)
            both = a in have and b in have
            axis.plot([xa, xb], [ya, yb], color="tab:blue" if both else "0.85", linewidth=1.5 if both else 1)
        for cell in graph.nodes:
            x, y = maze.centre(cell)
            if cell in have:
                axis.scatter([x], [y], s=16, color="tab:blue", zorder=3)
            else:
                axis.scatter([x], [y], s=40, marker="x", color="tab:red", zorder=3)
        lacking[agent] = len(graph.nodes) - len(have)
        state = " (failed)" if agent in killed else ""
        axis.set_title(f"{agent}{state}: {len(have)}/{graph.number_of_nodes()} vertices", fontsize=9)
        axis.set_aspect("equal")
        axis.set_xlim(0, maze.size[0])
        axis.set_ylim(0, maze.size[1])
        axis.set_xticks([])
        axis.set_yticks([])
    if title:
        figure.suptitle(title, fontsize=10)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
    return lacking


def main(argv: list[str] | None = None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 3:
        raise SystemExit("usage: python -m petriflow.agents.comm.maps SWEEP.yaml ROW OUT.png")
    from petriflow.runtime.scheduler import Scheduler
    from petriflow.sweep import load_sweep
    from petriflow.sweep.trial import build
    from petriflow.world import World

    sweep = load_sweep(argv[0])
    row = sweep.rows[int(argv[1]) - 1]
    built = build(sweep.to_data(), row.params, 1)
    world = World(built.world, base=Path(built.config.world).resolve().parent)
    try:
        scheduler = Scheduler(built.net, world=world, config=built.config, seed=1, binding=built.binding)
        events: list[Any] = []
        scheduler.on_event(events.append)
        with scheduler:
            scheduler.run()
        label = ", ".join(f"{k}={v}" for k, v in row.params.items())
        print(draw_maps(events, built.world["meta"]["maze"], argv[2], f"{sweep.name}: {label} (seed 1)"))
    finally:
        world.close()


if __name__ == "__main__":
    main()
