"""Metrics of seed 001's missions, from a finished run's events and its world.

The ground truth is the world's corridor graph (``meta.slam``: vertices in the map
frame, corridors); the built map is the union of those the agents recorded as done
(``slam.map``: one RA's, or each RA's of a team, or the central unit's), else the
largest an agent holds at the end. :func:`map_quality` pairs
built vertices with true ones (nearest first, each used once, within ``tolerance`` m)
and compares the corridors through the pairs.

=========================  ==========================================================
``slam.time_s``            when the map was done: the last of the RAs still working found
                           nothing pending; ``None`` if that never happened
``slam.completed``         1 when the map was done, else 0
``slam.was_used``          WAs installed, plus the centralised system's pre-installed nodes
``slam.vertices_missing``  ground-truth vertices with no built vertex paired
``slam.vertex_error_m``    mean distance of the paired vertices (m)
``slam.vertices_extra``    built vertices paired with none
``slam.edges_missing``     corridors of the ground truth the map lacks
``slam.edges_extra``       edges of the map that are no corridor
``slam.second_ra_s``       from the reserve RA's dispatch to the map done
``slam.alert_s``           the first alert the base received
``slam.odometry_error_m``  the finishing RA's odometry error when it finished
``slam.dead_reckoning_m``  its encoder-only (x, y, heading) estimate's error then
``slam.umbmark_m``         UMBmark's E_max on the 4 m square with the wheels the RA believes
``slam.distance_m``        metres the RAs drove
``slam.wa_exchanges``      frames WAs sent one another (Algorithm 2)
=========================  ==========================================================
"""

from __future__ import annotations

import math
from typing import Any

from petriflow.agents.slam.corridors import SLAM

__all__ = ["built_map", "map_quality", "parse_map", "register", "truth", "union"]


def _custom(record: Any, name: str) -> list[Any]:
    return [e for e in record.events if e.kind == "custom" and e.data.get("name") == name]


def truth(record: Any) -> tuple[dict[int, tuple[float, float]], set[tuple[int, int]]]:
    """The world's ground truth: ``({id: (x, y)}, {(a, b)})`` in the map frame."""
    meta = record.section(SLAM)
    if not meta["vertices"]:
        raise ValueError("the world has no meta.slam: seed 001's metrics need its corridor graph")
    vertices = {int(v): (float(p[0]), float(p[1])) for v, p in meta["vertices"].items()}
    return vertices, {(min(a, b), max(a, b)) for a, b in meta["edges"]}


def built_map(record: Any) -> tuple[dict[int, tuple[float, float]], set[tuple[int, int]]]:
    """The map the mission built (see the module)."""
    maps = _custom(record, "slam.map")
    if maps:
        return union([parse_map(e.data["data"]) for e in maps])
    best = None
    scheduler = getattr(record, "scheduler", None)
    if scheduler is not None:
        for state in scheduler.firer.agents.states.values():
            history = getattr(state, "history", None)
            if history is not None and (best is None or len(history) > len(best)):
                best = history
    if best is None:
        return {}, set()
    return {v.id: (v.x, v.y) for v in best.vertices()}, best.edges()


def parse_map(data: dict[str, Any]) -> tuple[dict[int, tuple[float, float]], set[tuple[int, int]]]:
    """A ``slam.map`` event's map: ``({id: (x, y)}, {(a, b)})``.

    Examples:
        >>> parse_map({"vertices": "0,0.000,0.000;1,0.000,5.850", "edges": "0-1"})
        ({0: (0.0, 0.0), 1: (0.0, 5.85)}, {(0, 1)})
    """
    vertices = {}
    for row in filter(None, data["vertices"].split(";")):
        vid, x, y = row.split(",")
        vertices[int(vid)] = (float(x), float(y))
    edges = set()
    for pair in filter(None, data["edges"].split(";")):
        a, b = (int(v) for v in pair.split("-"))
        edges.add((min(a, b), max(a, b)))
    return vertices, edges


def union(maps: list[tuple[dict[int, tuple[float, float]], set[tuple[int, int]]]],
          radius: float = 0.5) -> tuple[dict[int, tuple[float, float]], set[tuple[int, int]]]:
    """The maps several agents recorded, as one: a vertex id once, two ids at one place
    (two RAs found the same vertex before they shared) as the first.

    Examples:
        >>> union([({0: (0, 0), 1: (0, 5)}, {(0, 1)}), ({0: (0, 0), 1000: (0.1, 5.1), 1001: (3, 5)},
        ...        {(0, 1000), (1000, 1001)})])
        ({0: (0, 0), 1: (0, 5), 1001: (3, 5)}, {(0, 1), (1, 1001)})
    """
    vertices: dict[int, tuple[float, float]] = {}
    alias: dict[int, int] = {}
    for points, _ in maps:
        for vid, p in sorted(points.items()):
            if vid in vertices or vid in alias:
                continue
            twin = next((v for v, q in vertices.items() if math.dist(p, q) <= radius), None)
            if twin is None:
                vertices[vid] = p
            else:
                alias[vid] = twin
    edges = set()
    for _, pairs in maps:
        for a, b in pairs:
            a, b = alias.get(a, a), alias.get(b, b)
            if a != b:
                edges.add((min(a, b), max(a, b)))
    return vertices, edges


def map_quality(built: dict[int, tuple[float, float]], built_edges: set[tuple[int, int]],
                true: dict[int, tuple[float, float]], true_edges: set[tuple[int, int]],
                tolerance: float = 1.0) -> dict[str, Any]:
    """Pair built vertices with true ones and compare the corridors (see the module).

    Examples:
        >>> q = map_quality({0: (0, 0.1), 1: (0, 6.2), 9: (5, 5)}, {(0, 1), (1, 9)},
        ...                 {0: (0, 0), 1: (0, 6), 2: (3, 6)}, {(0, 1), (1, 2)})
        >>> q["vertices_missing"], q["vertices_extra"], round(q["vertex_error_m"], 3), q["edges_missing"], q["edges_extra"]
        (1, 1, 0.15, 1, 1)
    """
    pairs = sorted((math.dist(p, q), b, t) for b, p in built.items() for t, q in true.items()
                   if math.dist(p, q) <= tolerance)
    to_true: dict[int, int] = {}
    used: set[int] = set()
    errors = []
    for distance, b, t in pairs:
        if b in to_true or t in used:
            continue
        to_true[b] = t
        used.add(t)
        errors.append(distance)
    mapped = set()
    extra = 0
    for a, b in built_edges:
        if a in to_true and b in to_true:
            edge = (min(to_true[a], to_true[b]), max(to_true[a], to_true[b]))
            if edge in true_edges:
                mapped.add(edge)
            else:
                extra += 1
        else:
            extra += 1
    return {"vertices_missing": len(true) - len(used), "vertices_extra": len(built) - len(to_true),
            "vertex_error_m": sum(errors) / len(errors) if errors else None,
            "edges_missing": len(true_edges - mapped), "edges_extra": extra, "pairs": to_true}


def _quality(record: Any, tolerance: float = 1.0) -> dict[str, Any]:
    vertices, edges = built_map(record)
    true, true_edges = truth(record)
    return map_quality(vertices, edges, true, true_edges, tolerance)


def _team(record: Any) -> tuple[set[str], set[str], dict[str, float]]:
    """The RAs that started, those that broke down, and when each that finished did."""
    started = {e.agent for e in _custom(record, "slam.umbmark")}
    broken = {e.agent for e in _custom(record, "slam.failed") if str(e.agent).startswith("ra")}
    done: dict[str, float] = {}
    for e in _custom(record, "slam.finished"):
        done.setdefault(e.agent, e.time)
    return started, broken, done


def time_s(record: Any) -> float | None:
    """When the map was done: every RA that started and did not break down found nothing
    pending (the last of them; with one RA, when it did)."""
    started, broken, done = _team(record)
    working = started - broken
    if not done or not working <= set(done):
        return None
    return round(max(done[ra] for ra in working), 3)


def completed(record: Any) -> int:
    return 0 if time_s(record) is None else 1


def was_used(record: Any) -> int:
    nodes = sum(e.data["data"].get("count", 0) for e in _custom(record, "slam.nodes"))
    return len(_custom(record, "slam.installed")) + nodes


def vertices_missing(record: Any, tolerance: float = 1.0) -> int:
    return _quality(record, tolerance)["vertices_missing"]


def vertex_error_m(record: Any, tolerance: float = 1.0) -> float | None:
    error = _quality(record, tolerance)["vertex_error_m"]
    return None if error is None else round(error, 4)


def vertices_extra(record: Any, tolerance: float = 1.0) -> int:
    return _quality(record, tolerance)["vertices_extra"]


def edges_missing(record: Any, tolerance: float = 1.0) -> int:
    return _quality(record, tolerance)["edges_missing"]


def edges_extra(record: Any, tolerance: float = 1.0) -> int:
    return _quality(record, tolerance)["edges_extra"]


def second_ra_s(record: Any) -> float | None:
    sent = _custom(record, "slam.dispatched")
    done = _custom(record, "slam.finished")
    if not sent or not done:
        return None
    return round(done[0].time - sent[0].time, 3)


def alert_s(record: Any) -> float | None:
    alerts = _custom(record, "slam.alert")
    return round(alerts[0].time, 3) if alerts else None


def odometry_error_m(record: Any) -> float | None:
    done = _custom(record, "slam.finished")
    return done[0].data["data"].get("odometry_error_m") if done else None


def dead_reckoning_m(record: Any) -> float | None:
    done = _custom(record, "slam.finished")
    return done[0].data["data"].get("dead_reckoning_error_m") if done else None


def umbmark_m(record: Any) -> float | None:
    """UMBmark's E_max (m) with the wheels the first RA drove on: after its correction,
    or without it when it did not calibrate."""
    reports = _custom(record, "slam.umbmark")
    if not reports:
        return None
    return round(reports[0].data["data"]["passes"][-1]["e_max"], 4)


def distance_m(record: Any) -> float:
    last: dict[str, float] = {}
    for e in _custom(record, "slam.leg"):
        last[e.agent] = e.data["data"].get("distance_m", 0.0)
    return round(sum(last.values()), 3)


def wa_exchanges(record: Any) -> int:
    return sum(1 for e in _custom(record, "slam.sent")
               if str(e.agent).startswith("wa_") and str(e.data["data"].get("to", "")).startswith("wa_"))


METRICS = {
    "slam.time_s": time_s, "slam.completed": completed, "slam.was_used": was_used,
    "slam.vertices_missing": vertices_missing, "slam.vertex_error_m": vertex_error_m,
    "slam.vertices_extra": vertices_extra, "slam.edges_missing": edges_missing, "slam.edges_extra": edges_extra,
    "slam.second_ra_s": second_ra_s, "slam.alert_s": alert_s, "slam.odometry_error_m": odometry_error_m,
    "slam.dead_reckoning_m": dead_reckoning_m, "slam.umbmark_m": umbmark_m, "slam.distance_m": distance_m, "slam.wa_exchanges": wa_exchanges,
}


def register(registry: Any) -> None:
    """Register the metrics (the plugin calls this)."""
    for name, function in METRICS.items():
        registry.register_metric(name, function, events=("custom",))
