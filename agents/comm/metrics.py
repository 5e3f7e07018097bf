"""Metrics of seed 000's mapping mission, computed from a finished run's events and
its world's maze (``meta.maze``): the ground truth is the maze's topological map.

* ``comm.bytes_total``: map data sent by all agents, in bytes as the paper counts them
  (5 per vertex); ``count: air`` adds the 3-byte headers of every message.
* ``comm.bytes_per_agent``: the same per agent (``{robot1: 60, ...}``).
* ``comm.time_s``: when every working agent (neither killed nor broken down) first
  held every vertex of the maze's map (the run's end if that never happened).
* ``comm.distance_m``: distance driven, mean over the robots.
* ``comm.maps_complete``: share of the working agents (neither killed nor broken down)
  holding every vertex at the end.
* ``comm.complete_per_agent``: per agent, 1 if it holds every vertex at the end, else 0
  (a robot broken down included: ``{robot3: 0, ...}``).
* ``comm.vertices``: vertices of the maze's map (the ground truth's size).
"""

from __future__ import annotations

from typing import Any

from petriflow.agents.mobile.maze import MAZE, from_meta

__all__ = ["register", "truth", "holdings"]


def truth(record: Any) -> set[int]:
    """Vertex ids of the maze's topological map (the world's ``meta.maze``, :data:`MAZE`)."""
    settings = record.section(MAZE)
    if not settings["rows"]:
        raise ValueError("the world has no meta.maze: comm metrics need the maze's ground truth")
    maze = from_meta(settings)
    return {r * maze.cols + c for r, c in maze.vertices()}


def _agents(record: Any) -> tuple[list[str], set[str]]:
    """The agents that started, and those out of the mission: killed, or broken down
    (``comm.broken``: a robot that cannot move any more)."""
    started, killed = [], set()
    for event in record.events:
        if event.kind == "custom" and event.data.get("name") == "comm.characterised" and event.agent not in started:
            started.append(event.agent)
        elif event.kind == "fault" and event.data.get("fault") == "kill":
            killed.add(event.agent)
        elif event.kind == "custom" and event.data.get("name") == "comm.broken":
            killed.add(event.agent)
    return started, killed


def holdings(record: Any) -> list[tuple[float, str, list[int]]]:
    """``(time, agent, vertex ids)`` each time an agent learnt vertices."""
    return [(e.time, e.agent, list(e.data["data"].get("ids", []))) for e in record.events
            if e.kind == "custom" and e.data.get("name") == "comm.learnt"]


def bytes_total(record: Any, count: str = "payload") -> int:
    key = "payload" if count == "payload" else "bytes"
    return sum(e.data["data"].get(key, 0) for e in record.events
               if e.kind == "custom" and e.data.get("name") == "comm.sent")


def bytes_per_agent(record: Any, count: str = "payload") -> dict[str, int]:
    key = "payload" if count == "payload" else "bytes"
    started, _ = _agents(record)
    out = {agent: 0 for agent in started}
    for e in record.events:
        if e.kind == "custom" and e.data.get("name") == "comm.sent":
            out[e.agent] = out.get(e.agent, 0) + e.data["data"].get(key, 0)
    return out


def time_s(record: Any) -> float:
    wanted = truth(record)
    started, killed = _agents(record)
    survivors = [a for a in started if a not in killed]
    held: dict[str, set[int]] = {a: set() for a in started}
    for time, agent, ids in holdings(record):
        held.setdefault(agent, set()).update(ids)
        if survivors and all(wanted <= held.get(a, set()) for a in survivors):
            return time
    return record.result.time


def maps_complete(record: Any) -> float | None:
    wanted = truth(record)
    started, killed = _agents(record)
    survivors = [a for a in started if a not in killed]
    if not survivors:
        return None
    held: dict[str, set[int]] = {}
    for _, agent, ids in holdings(record):
        held.setdefault(agent, set()).update(ids)
    return sum(1 for a in survivors if wanted <= held.get(a, set())) / len(survivors)


def complete_per_agent(record: Any) -> dict[str, int]:
    wanted = truth(record)
    started, _ = _agents(record)
    held: dict[str, set[int]] = {a: set() for a in started}
    for _, agent, ids in holdings(record):
        held.setdefault(agent, set()).update(ids)
    return {agent: int(wanted <= ids) for agent, ids in held.items()}


def distance_m(record: Any) -> float | None:
    last: dict[str, float] = {}
    for e in record.events:
        if e.kind == "custom" and e.data.get("name") in ("comm.step", "comm.learnt", "comm.explored"):
            distance = e.data["data"].get("distance_m")
            if distance is not None:
                last[e.agent] = distance
    return sum(last.values()) / len(last) if last else None


def vertices(record: Any) -> int:
    return len(truth(record))


def register(registry: Any) -> None:
    """Register the metrics (the ``petriflow.actions`` plugin calls this)."""
    for name, function in (("comm.bytes_total", bytes_total), ("comm.bytes_per_agent", bytes_per_agent),
                           ("comm.time_s", time_s), ("comm.distance_m", distance_m),
                           ("comm.maps_complete", maps_complete), ("comm.complete_per_agent", complete_per_agent),
                           ("comm.vertices", vertices)):
        registry.register_metric(name, function, events=("custom", "fault") if name != "comm.vertices" else False)
