"""Metrics of the swarm mission, from a finished run's events and its world's maze.

* ``swarm.coverage``: share of the maze's cells some robot sensed (0..1).
* ``swarm.bytes_total``: bytes of every frame the robots put on the air.
* ``swarm.time_s``: when the last robot got home (the run's end if one never did).
* ``swarm.home``: share of the robots back home at the end.

Examples:
    >>> from petriflow.runtime.trace import Event
    >>> from petriflow.runtime.metrics import RunRecord
    >>> record = RunRecord(events=[Event(0, 1.0, "message", None, "r1", {"fate": "sent", "channel": "swarm", "size": 40}),
    ...                            Event(1, 1.5, "message", None, "r1", {"fate": "delivered", "channel": "swarm"})])
    >>> bytes_total(record)
    40
"""

from __future__ import annotations

from typing import Any

from petriflow.agents.mobile.maze import MAZE, TILES

__all__ = ["register", "coverage", "bytes_total", "time_s", "home"]


def _cells(record: Any) -> int:
    maze = record.section(MAZE)
    if not maze["rows"]:
        raise ValueError("the world has no meta.maze: swarm metrics need the maze")
    tiles = record.section(TILES)["count"]  # copies of the maze (their cell ids differ)
    return maze["rows"] * maze["cols"] * tiles


def _custom(record: Any, name: str):
    return (e for e in record.events if e.kind == "custom" and e.data.get("name") == name)


def coverage(record: Any) -> float:
    sensed = {e.data["data"]["cell"] for e in _custom(record, "swarm.sensed")}
    return len(sensed) / _cells(record)


def bytes_total(record: Any, channel: str = "swarm") -> int:
    return sum(e.data.get("size", 0) for e in record.events
               if e.kind == "message" and e.data.get("fate") == "sent" and e.data.get("channel") == channel)


def time_s(record: Any) -> float:
    homes = [e.time for e in _custom(record, "swarm.home")]
    robots = len({e.agent for e in _custom(record, "swarm.home")})
    wanted = _robot_count(record)
    if homes and robots >= wanted:
        return max(homes)
    return record.result.time


def _robot_count(record: Any) -> int:
    net = getattr(getattr(record, "scheduler", None), "net", None)
    if net is not None:
        return sum(1 for s in net.subnets.values() if s.state == "swarm.scout")
    return len({e.agent for e in record.events if e.kind == "start" and e.agent})


def home(record: Any) -> float | None:
    wanted = _robot_count(record)
    if not wanted:
        return None
    return len({e.agent for e in _custom(record, "swarm.home")}) / wanted


def register(registry: Any) -> None:
    """Register the metrics (the ``petriflow.actions`` plugin calls this)."""
    for name, function in (("swarm.coverage", coverage), ("swarm.bytes_total", bytes_total),
                           ("swarm.time_s", time_s), ("swarm.home", home)):
        registry.register_metric(name, function, events=("custom", "message", "start"))
