"""Metrics of seed 004's mission, from a finished run's events.

* ``bidding.time_s``: mapping time, eq. 9: from MAP to END (the run's end when the
  mission never ended).
* ``bidding.accuracy_pct``: eq. 10, ``(1 - xi / sigma) * 100``, of the HMIA's global
  map, ``xi`` the cells only returns off teammates fell in (the paper's fictitious
  obstacles), ``sigma`` those real returns fell in (reported by the HMIA at END;
  :func:`~petriflow.agents.bidding.grid.fictitious`).
* ``bidding.fit_pct``: eq. 10 against the office's ground truth: map cells more than
  a cell from a real wall or piece of furniture count in ``xi`` (teammates, and walls
  drawn off their place by odometry drift; :func:`~petriflow.agents.bidding.grid.accuracy`).
* ``bidding.coverage``: share of the office's walls and furniture cells in the map.
* ``bidding.messages``: protocol messages sent (all ten kinds), a broadcast (CFP,
  PROPOSE, MAP, END go "to all the RAs") counting once, as a network carries it;
  ``bidding.messages_by_kind`` the same per kind; ``bidding.deliveries`` the tokens
  put into mailboxes (a broadcast once per receiver; ``core.messages`` counts these).
* ``bidding.distance_m``: distance driven, mean over the robots; ``bidding.drift_m``
  how far each believed itself from where it was at its last zone (odometry), mean.
* ``bidding.zones_of``: each robot's zones (1-based), ``{"robot1": [6, 8], ...}``.
* ``bidding.reauctioned``: zones offered again after robots broke down.
* ``bidding.zones_mapped``: zones the HMIA heard were mapped (reached, or in a laser's
  sight); ``bidding.zones_reached`` only those reached.
"""

from __future__ import annotations

from typing import Any

__all__ = ["register"]


def _custom(record: Any, name: str) -> list[Any]:
    return [e for e in record.events if e.kind == "custom" and e.data.get("name") == name]


def time_s(record: Any) -> float | None:
    start = _custom(record, "bidding.map")
    if not start:
        return None
    end = _custom(record, "bidding.end")
    return (end[0].time if end else record.result.time) - start[0].time


def _end(record: Any, field: str) -> Any:
    end = _custom(record, "bidding.end")
    return end[0].data["data"].get(field) if end else None


def accuracy_pct(record: Any) -> float | None:
    return _end(record, "accuracy_pct")


def fit_pct(record: Any) -> float | None:
    return _end(record, "fit_pct")


def coverage(record: Any) -> float | None:
    return _end(record, "coverage")


def _messages(record: Any) -> list[str]:
    """The kind of every message sent, a broadcast once."""
    kinds, casts = [], set()
    for e in _custom(record, "bidding.sent"):
        data = e.data["data"]
        cast = data.get("broadcast")
        if cast is not None:
            if (e.agent, cast) in casts:
                continue
            casts.add((e.agent, cast))
        kinds.append(data["message"])
    return kinds


def messages(record: Any) -> int:
    return len(_messages(record))


def deliveries(record: Any) -> int:
    return len(_custom(record, "bidding.sent"))


def messages_by_kind(record: Any) -> dict[str, int]:
    counts: dict[str, int] = {}
    for kind in _messages(record):
        counts[kind] = counts.get(kind, 0) + 1
    return counts


def distance_m(record: Any) -> float | None:
    last: dict[str, float] = {}
    for e in _custom(record, "bidding.zone_done"):
        last[e.agent] = e.data["data"]["distance_m"]
    return sum(last.values()) / len(last) if last else None


def drift_m(record: Any) -> float | None:
    """How far each robot believed itself from where it was (odometry drift, m) at the
    last zone it reached, mean over the robots."""
    last: dict[str, float] = {}
    for e in _custom(record, "bidding.zone_done"):
        last[e.agent] = e.data["data"].get("drift_m", 0.0)
    return sum(last.values()) / len(last) if last else None


def zones_of(record: Any) -> dict[str, list[int]]:
    out: dict[str, list[int]] = {}
    for e in _custom(record, "bidding.zone_done"):
        out.setdefault(e.agent, []).append(e.data["data"]["zone"])
    return out


def reauctioned(record: Any) -> int:
    return sum(len(e.data["data"]["reoffered"]) for e in _custom(record, "bidding.breakdown"))


def zones_mapped(record: Any) -> int:
    return len({e.data["data"]["zone"] for e in _custom(record, "bidding.zone_mapped")}
               | {e.data["data"]["zone"] for e in _custom(record, "bidding.zone_seen")})


def zones_reached(record: Any) -> int:
    return len({e.data["data"]["zone"] for e in _custom(record, "bidding.zone_mapped")})


def register(registry: Any) -> None:
    """Register the metrics (the ``petriflow.actions`` plugin calls this)."""
    for name, function in (("bidding.time_s", time_s), ("bidding.accuracy_pct", accuracy_pct),
                           ("bidding.coverage", coverage), ("bidding.fit_pct", fit_pct), ("bidding.messages", messages), ("bidding.deliveries", deliveries),
                           ("bidding.messages_by_kind", messages_by_kind), ("bidding.distance_m", distance_m), ("bidding.drift_m", drift_m),
                           ("bidding.zones_of", zones_of),
                           ("bidding.reauctioned", reauctioned), ("bidding.zones_mapped", zones_mapped),
                           ("bidding.zones_reached", zones_reached)):
        registry.register_metric(name, function, events=("custom",))
