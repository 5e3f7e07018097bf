"""Corridor worlds: a topological graph made into walls, and the map frame beside it.

A corridor world is a square of solid floor-to-ceiling blocks with corridors cut out
of it: a corridor of width ``2 * half_width`` along every edge of a graph whose
vertices have axis-aligned positions, and a square of the same width at every vertex
(:func:`free_space`). The cut-out is rasterised at ``cell`` metres and the solid part
decomposed into boxes (runs of solid cells merged along rows, then equal runs merged
down columns: :func:`solid_boxes`), so pybullet holds a few hundred static boxes and the
RA's distance sensors see walls where the corridors end.

**Frames.** The graph is in the paper's map frame (x west, y north, the RA's start at
the origin); the world is pybullet's (x east, y north). ``origin`` is the world point of
the map's origin: ``world = (origin_x - x, origin_y + y)`` (:func:`to_world`,
:func:`to_map`).

Two worlds are built this way: the paper's Fig. 6 (:func:`fig6_world`, from
:mod:`petriflow.agents.slam.fig6`) and generated mazes (:func:`maze_world`, a perfect
maze of :mod:`petriflow.agents.mobile.maze` with some loops, its topological graph made
into corridors), both with the graph in ``meta.slam`` so metrics score the built map
against it.

Examples:
    >>> to_world((0.0, 6.0), (23.5, 1.5)), to_map((23.5, 7.5), (23.5, 1.5))
    ((23.5, 7.5), (0.0, 6.0))
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from petriflow.runtime.settings import Section, Setting

__all__ = [
    "HALF_WIDTH",
    "SLAM",
    "draw",
    "fig6_world",
    "free_space",
    "maze_world",
    "nodes_grid",
    "solid_boxes",
    "to_map",
    "to_world",
    "world_description",
]

#: Half the corridors' width (m): 1.2 m corridors fit Fig. 6's closest parallel
#: corridors (1.7 m between centre lines) with a wall between them.
HALF_WIDTH = 0.6

_POINT = Setting(list, doc="x, y (m)", items=Setting(float))

#: A corridor world's ``meta.slam`` (:func:`petriflow.agents.slam.corridors.world_description`
#: writes it): the map frame, the corridors' ground truth the metrics score the built
#: map against, the centralised system's nodes.
SLAM = Section("slam", {
    "origin": Setting((list, type(None)), None, "world x, y of the map's origin (default: the RA's start)",
                      items=Setting(float)),
    "size": Setting((list, type(None)), None, "the world's extent x, y (m)", items=Setting(float)),
    "half_width": Setting(float, HALF_WIDTH, "half a corridor's width (m)", low=0),
    "vertices": Setting(dict, {}, "the ground-truth graph's vertices: id -> map x, y (m)"),
    "edges": Setting(list, [], "the ground-truth graph's corridors: [vertex, vertex]"),
    "nodes": Setting(list, [], "the centralised system's pre-installed nodes (world x, y)", items=_POINT),
    "starts": Setting(list, [], "the RAs' starts in the map frame (a generated maze)", items=_POINT),
    "maze_seed": Setting((int, type(None)), None, "the seed of a generated maze"),
    "paper": Setting(dict, {}, "the vertices as published, for comparison (the Fig. 6 world)"),
}, doc="a corridor world: the map frame and the ground truth")
#: Height of the walls (m); the distance sensors look at 0.1 m.
WALL_HEIGHT = 0.5
RA_URDF = "petriflow.agents:robots/diffdrive.urdf"


def to_world(point: tuple[float, float], origin: tuple[float, float]) -> tuple[float, float]:
    """World (x east) of a map point (x west)."""
    return (round(origin[0] - point[0], 6), round(origin[1] + point[1], 6))


def to_map(point: tuple[float, float], origin: tuple[float, float]) -> tuple[float, float]:
    """Map point (x west) of a world point (x east)."""
    return (round(origin[0] - point[0], 6), round(point[1] - origin[1], 6))


def free_space(vertices: dict[int, tuple[float, float]], edges, origin: tuple[float, float],
               size: tuple[float, float], half_width: float = HALF_WIDTH, cell: float = 0.05) -> np.ndarray:
    """Boolean grid (rows from y = 0 up, columns from x = 0 right) of the free cells."""
    cols, rows = int(round(size[0] / cell)), int(round(size[1] / cell))
    free = np.zeros((rows, cols), dtype=bool)

    def cut(x0: float, x1: float, y0: float, y1: float) -> None:
        c0, c1 = max(0, int(math.floor(x0 / cell + 1e-9))), min(cols, int(math.ceil(x1 / cell - 1e-9)))
        r0, r1 = max(0, int(math.floor(y0 / cell + 1e-9))), min(rows, int(math.ceil(y1 / cell - 1e-9)))
        free[r0:r1, c0:c1] = True

    world = {v: to_world(p, origin) for v, p in vertices.items()}
    for x, y in world.values():
        cut(x - half_width, x + half_width, y - half_width, y + half_width)
    for a, b in edges:
        (xa, ya), (xb, yb) = world[a], world[b]
        if abs(xa - xb) >= abs(ya - yb):  # east-west corridor at the mean y
            y = (ya + yb) / 2
            cut(min(xa, xb) - half_width, max(xa, xb) + half_width, y - half_width, y + half_width)
        else:
            x = (xa + xb) / 2
            cut(x - half_width, x + half_width, min(ya, yb) - half_width, max(ya, yb) + half_width)
    return free


def solid_boxes(free: np.ndarray, cell: float, height: float = WALL_HEIGHT, colour: str = "grey") -> list[dict]:
    """World boxes filling the solid cells of ``free``'s complement (runs merged)."""
    rows, cols = free.shape
    open_runs: dict[tuple[int, int], int] = {}  # (start col, end col) -> first row
    rectangles = []
    for r in range(rows + 1):
        runs = set()
        if r < rows:
            c = 0
            line = free[r]
            while c < cols:
                if line[c]:
                    c += 1
                    continue
                start = c
                while c < cols and not line[c]:
                    c += 1
                runs.add((start, c))
        for run in list(open_runs):
            if run not in runs:
                rectangles.append((run[0], run[1], open_runs.pop(run), r))
        for run in runs:
            open_runs.setdefault(run, r)
    boxes = []
    for i, (c0, c1, r0, r1) in enumerate(sorted(rectangles, key=lambda t: (t[2], t[0]))):
        w, d = (c1 - c0) * cell, (r1 - r0) * cell
        boxes.append({"id": f"wall_{i}", "size": [round(w, 6), round(d, 6), height],
                      "position": [round(c0 * cell + w / 2, 6), round(r0 * cell + d / 2, 6), height / 2],
                      "colour": colour})
    return boxes


def nodes_grid(size: tuple[float, float], per_side: int = 4) -> list[tuple[float, float]]:
    """Pre-installed nodes of the centralised system (Fig. 8, not in our text): a
    ``per_side`` x ``per_side`` grid centred in its cells (16 nodes, 6.25 m apart in
    25 m: every point within 4.4 m of one, inside their 5 m range)."""
    return [(round((i + 0.5) * size[0] / per_side, 4), round((j + 0.5) * size[1] / per_side, 4))
            for j in range(per_side) for i in range(per_side)]


def world_description(vertices: dict[int, tuple[float, float]], edges, *, origin: tuple[float, float],
                      size: tuple[float, float], robots: int = 2, was_per_robot: int = 16,
                      starts: list[tuple[float, float]] | None = None, half_width: float = HALF_WIDTH,
                      cell: float = 0.05, dt: float = 0.1, nodes: int = 4, extra: dict | None = None
                      ) -> dict[str, Any]:
    """A world description (see :mod:`petriflow.world`): the walls, ``robots`` RA
    bodies (``ra1``...; map-frame ``starts``, default all at the origin, facing north),
    ``was_per_robot`` WA boxes per RA parked off the floor plan (``wa_r1_1``...: an RA
    puts one where it installs it), the centralised system's pre-installed nodes
    (``node1``...), and the graph in ``meta.slam``."""
    free = free_space(vertices, edges, origin, size, half_width, cell)
    boxes = solid_boxes(free, cell)
    starts = starts or [(0.0, 0.0)] * robots
    colours = ["red", "blue", "green", "orange", "yellow"]
    bodies = []
    for i in range(robots):
        x, y = to_world(starts[i % len(starts)], origin)
        bodies.append({"id": f"ra{i + 1}", "agent": f"ra{i + 1}", "urdf": RA_URDF, "position": [x, y],
                       "yaw": round(math.pi / 2, 6), "z": 0.05, "colour": colours[i % len(colours)]})
    for i in range(robots):
        for k in range(was_per_robot):
            boxes.append({"id": f"wa_r{i + 1}_{k + 1}", "size": [0.1, 0.1, 0.06],
                          "position": [round(-2.0 - 0.2 * k, 3), round(-2.0 - 0.2 * i, 3), 0.03], "colour": "blue"})
    grid = nodes_grid(size, nodes) if nodes else []
    for i, (x, y) in enumerate(grid):
        boxes.append({"id": f"node{i + 1}", "size": [0.1, 0.1, 0.06], "position": [x, y, 0.03],
                      "colour": "orange"})
    meta = {"slam": {"origin": list(origin), "size": list(size), "half_width": half_width,
                     "vertices": {str(v): [round(p[0], 3), round(p[1], 3)] for v, p in sorted(vertices.items())},
                     "edges": [[a, b] for a, b in sorted((min(e), max(e)) for e in edges)],
                     "nodes": [list(p) for p in grid], **(extra or {})}}
    return {"dt": dt, "gravity": 0.0, "plane": True, "boxes": boxes, "robots": bodies, "meta": meta}


def fig6_world(robots: int = 2, was_per_robot: int = 16, **options: Any) -> dict[str, Any]:
    """The paper's 25 m x 25 m environment (see :mod:`petriflow.agents.slam.fig6`):
    the start 1.5 m from the east and south walls (Table 6's offset of -1.5 m)."""
    from petriflow.agents.slam import fig6

    graph = fig6.corridor_graph()
    vertices = {v: graph.nodes[v]["pos"] for v in graph.nodes}
    return world_description(vertices, graph.edges, origin=(23.5, 1.5), size=(25.0, 25.0), robots=robots,
                             was_per_robot=was_per_robot,
                             extra={"paper": {str(v): [x, y] for v, (x, y, _) in fig6.TABLE6.items()}}, **options)


def maze_world(side: float = 50.0, cells: int = 10, seed: int = 1, robots: int = 5, was_per_robot: int = 20,
               loops: float = 0.1, **options: Any) -> dict[str, Any]:
    """A generated maze of ``cells`` x ``cells`` cells in ``side`` metres (corridors
    between cell centres, a vertex at every dead end, corner and junction); the RAs
    start spread over it (the first at the south-east corner cell: the map origin)."""
    from petriflow.agents.mobile.maze import generate

    cell = side / cells
    maze = generate(cells, cells, seed=seed, cell=cell, loops=loops)
    graph = maze.graph()
    origin = maze.centre((0, cells - 1))
    ids = {c: i for i, c in enumerate(sorted(graph.nodes))}
    vertices = {ids[c]: to_map(maze.centre(c), origin) for c in graph.nodes}
    corners = [(0, cells - 1), (cells - 1, 0), (0, 0), (cells - 1, cells - 1), (cells // 2, cells // 2)]
    starts = []
    for r, c in corners[:robots]:
        near = min(graph.nodes, key=lambda v: (abs(v[0] - r) + abs(v[1] - c), v))
        starts.append(to_map(maze.centre(near), origin))
    while len(starts) < robots:
        starts.append(starts[len(starts) % len(corners)])
    return world_description(vertices, [(ids[a], ids[b]) for a, b in graph.edges], origin=origin,
                             size=(side, side), robots=robots, was_per_robot=was_per_robot, starts=starts,
                             nodes=max(1, math.ceil(side / 6.25)),
                             extra={"starts": [list(s) for s in starts], "maze_seed": seed}, **options)


def draw(description: dict[str, Any], path: str | Path, *, built: dict[str, Any] | None = None,
         title: str = "") -> None:
    """A top view of a corridor world (walls, the ground-truth graph with its ids, the
    RAs' starts, the nodes) and, with ``built`` (``{"vertices": {id: [x, y]}, "edges":
    [[a, b]], "was": [[x, y]]}`` in the map frame), the built map beside it."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    meta = SLAM.read((description.get("meta") or {}).get("slam"))
    origin = tuple(meta["origin"])
    panels = 2 if built is not None else 1
    figure, axes = plt.subplots(1, panels, figsize=(6.4 * panels, 6.4), squeeze=False)
    axis = axes[0][0]
    for box in description["boxes"]:
        if not box["id"].startswith("wall_"):
            continue
        (x, y, _), (w, d, _) = box["position"], box["size"]
        axis.add_patch(plt.Rectangle((x - w / 2, y - d / 2), w, d, color="0.3", linewidth=0))
    vertices = {int(v): to_world(tuple(p), origin) for v, p in meta["vertices"].items()}
    for a, b in meta["edges"]:
        axis.plot([vertices[a][0], vertices[b][0]], [vertices[a][1], vertices[b][1]], color="tab:green", lw=1)
    many = len(vertices) > 60
    for v, (x, y) in vertices.items():
        axis.scatter([x], [y], s=10, color="tab:green", zorder=3)
        if not many:
            axis.annotate(str(v), (x, y), textcoords="offset points", xytext=(3, 3), fontsize=6)
    if meta.get("nodes"):
        xs, ys = zip(*meta["nodes"])
        axis.scatter(xs, ys, marker="^", s=22, color="orange", zorder=4, label="centralised nodes")
    for robot in description["robots"]:
        x, y = robot["position"]
        axis.scatter([x], [y], s=60, color=robot.get("colour", "red"), edgecolors="k", zorder=5)
    axis.scatter([], [], s=60, color="red", edgecolors="k", label="RA start")
    axis.set_aspect("equal")
    axis.set_xlim(0, meta["size"][0])
    axis.set_ylim(0, meta["size"][1])
    axis.set_xlabel("world x (m, east)")
    axis.set_ylabel("world y (m, north)")
    axis.set_title(title or f"world: {len(vertices)} vertices, {len(meta['edges'])} corridors")
    axis.legend(loc="upper center", bbox_to_anchor=(0.5, -0.08), ncol=2, fontsize=7)
    if built is not None:
        right = axes[0][1]
        truth = {int(v): tuple(p) for v, p in meta["vertices"].items()}
        for a, b in meta["edges"]:
            right.plot([-truth[a][0], -truth[b][0]], [truth[a][1], truth[b][1]], color="0.8", lw=3, zorder=1)
        points = {int(v): tuple(p) for v, p in built["vertices"].items()}
        for a, b in built["edges"]:
            if a in points and b in points:
                right.plot([-points[a][0], -points[b][0]], [points[a][1], points[b][1]], color="tab:blue", lw=1)
        for v, (x, y) in points.items():
            right.scatter([-x], [y], s=10, color="tab:blue", zorder=3)
            if not many:
                right.annotate(str(v), (-x, y), textcoords="offset points", xytext=(3, 3), fontsize=6)
        was = built.get("was", [])
        if was:
            right.scatter([-p[0] for p in was], [p[1] for p in was], marker="s", s=40, facecolors="none",
                          edgecolors="tab:red", zorder=4, label=f"WAs installed ({len(was)})")
            for p in was:
                right.add_patch(plt.Circle((-p[0], p[1]), 5.0, fill=False, color="tab:red", alpha=0.15))
        right.set_aspect("equal")
        right.set_xlim(-origin[0], meta["size"][0] - origin[0])
        right.set_ylim(-origin[1], meta["size"][1] - origin[1])
        right.set_xlabel("map x (m; the paper's x grows west, drawn as -x)")
        right.set_ylabel("map y (m, north)")
        right.set_title(built.get("title", "built map (blue) over the ground truth (grey)"), fontsize=9)
        right.legend(loc="upper center", bbox_to_anchor=(0.5, -0.08), ncol=2, fontsize=7)
    figure.tight_layout()
    figure.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(figure)
