"""The paper's test environment (Fig. 6), rebuilt from its tables.

Fig. 6 is not in the text we have; Table 6 is: the 36 vertices of the map the RA built
in experiment 1, each with its position (map frame, metres, the start at (0, 0)) and
the vertex it was reached from (``last id``). Table 8 adds the pending paths the
vertices 0-6 still had when the RA failed in experiment 3. :func:`derive_corridors`
turns them into the corridor graph, in three rules:

1. **Tree**: every vertex is joined to its ``last id`` (35 corridors): the RA drove
   them.
2. **Table 8**: a pending path of vertex ``v`` (identifier ``d``) is a corridor from
   ``v`` in direction ``d`` to the nearest vertex aligned with it that way (within
   ``tolerance`` across): 1-28, 3-28 and 4-35 (the others are tree corridors).
3. **Openings**: Algorithm 1 makes a vertex only at a frontal obstacle or a lateral
   opening, so a vertex the corridors so far cross straight (two corridors, opposite
   ways) must have a lateral opening: it leads to the nearest aligned vertex on either
   side. Repeated until no vertex is crossed straight: 13-29, 15-31, 16-32, 20-25,
   22-25, 26-34, 22-34.

That gives 45 corridors (:func:`corridor_graph`), each of whose 36 vertices is a dead
end, a corner or a junction, as Algorithm 1 needs. The corridors' centre lines are
the vertices' coordinates merged along them (:func:`snapped`: a row of vertices joined
by east-west corridors shares the mean of their ``y``; a column, the mean ``x``): the
paper's positions scatter by up to 0.4 m about a line, which is its own odometry error
(:func:`paper_scatter`).

The paper's speed (15 m/s) contradicts its times; :func:`paper_route_length` is the
distance its RA must have driven for Table 6 (vertices in the order of their ids, each
new one reached from its ``last id`` over the corridors already known, plus every loop
corridor once to clear its pending paths), and :func:`derived_speed` that distance over
a published time.

Examples:
    >>> graph = corridor_graph()
    >>> graph.number_of_nodes(), graph.number_of_edges()
    (36, 45)
    >>> round(paper_route_length(), 2)
    326.25
    >>> round(derived_speed(), 3)   # over experiment 2's 16:43
    0.325
"""

from __future__ import annotations

import math

import networkx as nx

from petriflow.agents.slam.history import STEP, direction_between, opposite

__all__ = [
    "TABLE6",
    "TABLE8",
    "TIMES",
    "corridor_graph",
    "derive_corridors",
    "derived_speed",
    "paper_route_length",
    "paper_scatter",
    "snapped",
]

#: Table 6: ``id: (x m, y m, last id)`` of the 36 vertices after experiment 1 (the
#: map frame: the start at (0, 0); the paper's offset of -1.5 m is the start's place).
TABLE6: dict[int, tuple[float, float, int]] = {
    0: (0, 0, 0), 1: (0, 6, 0), 2: (0.2, 10, 1), 3: (3, 9.7, 2), 4: (9, 10, 3), 5: (9, 19.7, 4),
    6: (9, 21.7, 5), 7: (4, 22, 6), 8: (4, 17.8, 7), 9: (6, 17.8, 8), 10: (5.8, 13, 9), 11: (0.5, 13, 10),
    12: (0.5, 21.7, 11), 13: (12, 22, 6), 14: (22.8, 21.7, 13), 15: (22.7, 11.2, 14), 16: (22.8, 7.8, 15),
    17: (22.73, 0, 16), 18: (20.5, -0.16, 17), 19: (20.5, 5.5, 18), 20: (17.7, 5.35, 19),
    21: (16.13, 5.4, 20), 22: (16, 3.5, 21), 23: (15.9, -0.5, 22), 24: (17.7, -0.5, 23),
    25: (17.75, 3.5, 24), 26: (13.5, -0.6, 23), 27: (2.8, -0.4, 26), 28: (2.85, 5.7, 27),
    29: (11.7, 19.7, 5), 30: (20.1, 19.7, 29), 31: (20.04, 11.1, 30), 32: (20, 7.9, 31),
    33: (13.5, 7.7, 32), 34: (13.5, 3.7, 33), 35: (13.6, 9.61, 33),
}
#: Table 8: the pending paths of vertices 0-6 in the arrays the second RA loaded.
TABLE8: dict[int, tuple[int, ...]] = {0: (), 1: (0,), 2: (), 3: (3,), 4: (0,), 5: (0,), 6: (0, 2)}
#: Published times (seconds): experiment 1 (22:20), 2 (16:43), 3 (the second RA 18:21, total 25:21).
TIMES = {"decentralised": 22 * 60 + 20, "centralised": 16 * 60 + 43, "second_ra": 18 * 60 + 21,
         "handover_total": 25 * 60 + 21, "failure_at": 7 * 60}


def _aligned(points: dict[int, tuple[float, float]], v: int, direction: int, tolerance: float) -> int | None:
    """The nearest vertex from ``v`` in ``direction`` (map identifiers) within
    ``tolerance`` metres across that direction."""
    ux, uy = STEP[direction]
    best, where = None, math.inf
    for u, (x, y) in points.items():
        if u == v:
            continue
        dx, dy = x - points[v][0], y - points[v][1]
        along, across = dx * ux + dy * uy, abs(dx * uy - dy * ux)
        if along > tolerance and across <= tolerance and along < where:
            best, where = u, along
    return best


def _sides(points: dict[int, tuple[float, float]], edges: set[tuple[int, int]], v: int) -> dict[int, int]:
    out = {}
    for a, b in edges:
        if v in (a, b):
            other = b if a == v else a
            out[direction_between(points[v], points[other])] = other
    return out


def derive_corridors(table: dict[int, tuple[float, float, int]] | None = None,
                     pending: dict[int, tuple[int, ...]] | None = None,
                     tolerance: float = 0.5) -> tuple[set[tuple[int, int]], list[tuple[str, int, int]]]:
    """The corridors of the environment (see the module): ``(edges, why)``, ``why``
    listing each corridor beyond the tree with its rule (``"table8"``, ``"opening"``)."""
    table = TABLE6 if table is None else table
    pending = TABLE8 if pending is None else pending
    points = {v: (x, y) for v, (x, y, _) in table.items()}
    edges = {(min(v, last), max(v, last)) for v, (_, _, last) in table.items() if v != last}
    why: list[tuple[str, int, int]] = []
    for v, paths in sorted(pending.items()):
        for direction in paths:
            u = _aligned(points, v, direction, tolerance)
            if u is not None and (min(u, v), max(u, v)) not in edges:
                edges.add((min(u, v), max(u, v)))
                why.append(("table8", v, u))
    changed = True
    while changed:
        changed = False
        for v in sorted(points):
            sides = _sides(points, edges, v)
            if len(sides) != 2 or set(sides) not in ({0, 2}, {1, 3}):
                continue
            lateral = (1, 3) if set(sides) == {0, 2} else (0, 2)
            options = []
            for direction in lateral:
                u = _aligned(points, v, direction, tolerance)
                if u is not None:
                    options.append((abs(points[u][0] - points[v][0]) + abs(points[u][1] - points[v][1]), u))
            if options:
                _, u = min(options)
                edges.add((min(u, v), max(u, v)))
                why.append(("opening", v, u))
                changed = True
                break
    return edges, why


def snapped(table: dict[int, tuple[float, float, int]] | None = None,
            edges: set[tuple[int, int]] | None = None) -> dict[int, tuple[float, float]]:
    """Vertex positions with the corridors' shared centre lines: vertices joined by an
    east-west corridor share one ``y`` (the mean of theirs), by a north-south one one
    ``x`` (transitively, along the corridors)."""
    table = TABLE6 if table is None else table
    edges = derive_corridors(table)[0] if edges is None else edges
    points = {v: (x, y) for v, (x, y, _) in table.items()}
    rows, cols = nx.Graph(), nx.Graph()
    rows.add_nodes_from(points)
    cols.add_nodes_from(points)
    for a, b in edges:
        horizontal = direction_between(points[a], points[b]) in (0, 2)
        (rows if horizontal else cols).add_edge(a, b)
    x = {v: points[v][0] for v in points}
    y = {v: points[v][1] for v in points}
    for group in nx.connected_components(rows):
        mean = sum(points[v][1] for v in group) / len(group)
        for v in group:
            y[v] = round(mean, 3)
    for group in nx.connected_components(cols):
        mean = sum(points[v][0] for v in group) / len(group)
        for v in group:
            x[v] = round(mean, 3)
    return {v: (x[v], y[v]) for v in sorted(points)}


def corridor_graph() -> nx.Graph:
    """The ground truth: vertices at their snapped positions (``pos``, map frame) and
    the 45 corridors (``length`` in metres)."""
    edges, _ = derive_corridors()
    where = snapped(edges=edges)
    graph = nx.Graph()
    for v, position in where.items():
        graph.add_node(v, pos=position)
    for a, b in sorted(edges):
        graph.add_edge(a, b, length=abs(where[a][0] - where[b][0]) + abs(where[a][1] - where[b][1]))
    return graph


def paper_scatter() -> float:
    """Mean distance (m) of Table 6's positions from the corridors' centre lines: the
    paper's own vertex position error, as far as the table shows it."""
    where = snapped()
    return sum(math.dist(where[v], TABLE6[v][:2]) for v in TABLE6) / len(TABLE6)


def paper_route_length() -> float:
    """Metres the paper's RA drove at least to build Table 6 (see the module)."""
    points = {v: (x, y) for v, (x, y, _) in TABLE6.items()}
    length = lambda a, b: abs(points[a][0] - points[b][0]) + abs(points[a][1] - points[b][1])
    known = nx.Graph()
    known.add_node(0)
    here, total = 0, 0.0
    for v in sorted(TABLE6)[1:]:
        last = TABLE6[v][2]
        total += nx.shortest_path_length(known, here, last, weight="length") + length(last, v)
        known.add_edge(last, v, length=length(last, v))
        here = v
    edges, why = derive_corridors()
    total += sum(length(a, b) for _, a, b in why)
    return total


def derived_speed(time_s: float | None = None) -> float:
    """The RA's speed (m/s): :func:`paper_route_length` over ``time_s`` (default
    experiment 2's 16:43, the run with no stops to install agents)."""
    return paper_route_length() / (TIMES["centralised"] if time_s is None else time_s)


def opposite_of(direction: int) -> int:  # re-exported for the world builder
    return opposite(direction)
