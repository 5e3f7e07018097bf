"""Draw a mission's world beside the map it built (the paper's Figs. 7 and 9).

``python -m petriflow.agents.slam.maps OUT.png [--mode decentralised] [--fail-at 420]
[--seed 1] [--robots 1] [--world world.yaml]`` runs the mission on a shipped world and
draws the world (walls, the ground-truth corridors) beside the built map (vertices and
edges over the ground truth in grey, the WAs installed with their 5 m range), with the
map's quality in the title.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

__all__ = ["draw_mission", "main"]


def draw_mission(out: str | Path, *, mode: str = "decentralised", fail_at: float | None = None, seed: int = 1,
                 robots: int = 1, world: str = "world.yaml", was: int = 16) -> dict[str, Any]:
    """Run the mission and draw it; returns its metrics."""
    import yaml

    from petriflow import examples
    from petriflow.agents.slam import metrics
    from petriflow.agents.slam.corridors import draw
    from petriflow.agents.slam.nets import build
    from petriflow.runtime.config import load_config
    from petriflow.runtime.metrics import RunRecord
    from petriflow.runtime.session import run
    from petriflow.world import load_world

    path = Path(examples.path("slam", world))
    scene = load_world(path)
    config = load_config(examples.path("slam", "run.yaml"))
    net = build(mode, robots=robots, reserves=1 if robots == 1 else 0, was=was, fail_at=fail_at)
    outcome = run(net, world=scene, config=config, seed=seed, until=20000, keep_events=True)
    try:
        record = RunRecord(outcome.result, outcome.events, scene, config)
        vertices, edges = metrics.built_map(record)
        values = {name.split(".", 1)[1]: f(record) for name, f in metrics.METRICS.items()}
        was_spots = [e.data["data"]["true"] for e in outcome.events
                     if e.kind == "custom" and e.data.get("name") == "slam.installed"]
        done = "never" if values["time_s"] is None else f"{values['time_s']:.0f} s"
        error = "-" if values["vertex_error_m"] is None else f"{values['vertex_error_m']:.2f} m"
        title = (f"{mode}{f', failure at {fail_at:g} s' if fail_at is not None else ''}: map done {done},"
                 f" {values['was_used']} WAs\nvertices missing {values['vertices_missing']},"
                 f" extra {values['vertices_extra']}, error {error}")
        description = yaml.safe_load(path.read_text())
        draw(description, out, built={"vertices": {str(k): list(v) for k, v in vertices.items()},
                                      "edges": [list(e) for e in sorted(edges)], "was": was_spots, "title": title},
             title="the world: walls, ground-truth corridors (green)")
        return values
    finally:
        scene.close()


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description="draw a seed 001 mission's world beside its map")
    parser.add_argument("out")
    parser.add_argument("--mode", default="decentralised", choices=("decentralised", "centralised"))
    parser.add_argument("--fail-at", type=float, default=None)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--robots", type=int, default=1)
    parser.add_argument("--was", type=int, default=16)
    parser.add_argument("--world", default="world.yaml")
    args = parser.parse_args(argv)
    values = draw_mission(args.out, mode=args.mode, fail_at=args.fail_at, seed=args.seed, robots=args.robots,
                          world=args.world, was=args.was)
    print(f"wrote {args.out}: {values}")


if __name__ == "__main__":
    main()
