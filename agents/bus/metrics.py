"""Metrics of seed 002's chain runs, from the events the firmware records.

* ``bus.lost_pct``: messages lost, % of those sent, mean over the modules (Tables 1–3
  count per sender: a message is received when every addressee that exists read it;
  a message for an address nobody holds, when it crossed the bus intact).
* ``bus.lost_pct_module``: the same for one module (``module: 1`` is the head, m1).
* ``bus.phase_error_rad``: mean phase-locking error of neighbours,
  ``|wrap(φi − φ(i+1) − lag)|`` averaged over pairs and over samples every 0.1 s,
  from ``min(5 s, half the time)`` to when the first module sent its last message.
* ``bus.speed_mps``: forward speed of the chain (its modules' mean position, first to
  last sample), when the modules drive a chain in the world.
* ``bus.lost_by_reason``: lost frames by reason (collision, overwritten, ...).
* ``bus.sniffer_lost_pct_module``: where the paper counts: the messages of one module
  that the sniffer on the bus did not capture, % of those the module sent (each CPG
  message is one frame on every bus), whoever they were for;
  ``bus.sniffer_lost_pct``: the mean over the modules.
"""

from __future__ import annotations

import math
import statistics
from typing import Any

__all__ = ["register"]


def _custom(record: Any, name: str) -> list[Any]:
    return [e for e in record.events if e.kind == "custom" and e.data.get("name") == name]


def _per_sender(record: Any) -> dict[str, tuple[int, int]]:
    """``{agent: (sent, received)}``."""
    copies: dict[tuple[str, int], int] = {}
    sent: dict[str, int] = {}
    for e in _custom(record, "bus.sent"):
        data = e.data["data"]
        copies[(e.agent, data["group"])] = max(1, len(data["to"]))
        sent[e.agent] = sent.get(e.agent, 0) + 1
    read: dict[tuple[str, int], int] = {}
    bad: set[tuple[str, int]] = set()
    for e in _custom(record, "bus.read"):
        data = e.data["data"]
        key = (data.get("sender"), data.get("group"))
        if data.get("lost"):
            bad.add(key)
        else:
            read[key] = read.get(key, 0) + 1
    received: dict[str, int] = {agent: 0 for agent in sent}
    for key, n in copies.items():
        if key not in bad and read.get(key, 0) >= n:
            received[key[0]] += 1
    return {agent: (sent[agent], received[agent]) for agent in sent}


def lost_pct_module(record: Any, module: int = 1) -> float | None:
    counts = _per_sender(record).get(f"m{module}")
    if not counts or not counts[0]:
        return None
    return 100.0 * (counts[0] - counts[1]) / counts[0]


def lost_pct(record: Any) -> float | None:
    counts = _per_sender(record)
    values = [100.0 * (s - r) / s for s, r in counts.values() if s]
    return statistics.fmean(values) if values else None


def _sniffer_counts(record: Any) -> dict[str, tuple[int, int]]:
    """``{agent: (sent, captured by the sniffer)}`` (empty without a sniffer's record)."""
    records = _custom(record, "bus.sniffed")
    if not records:
        return {}
    captured = records[-1].data["data"].get("captured") or {}
    sent: dict[str, int] = {}
    for e in _custom(record, "bus.sent"):
        sent[e.agent] = sent.get(e.agent, 0) + 1
    return {agent: (n, min(n, int(captured.get(agent, 0)))) for agent, n in sent.items()}


def sniffer_lost_pct_module(record: Any, module: int = 1) -> float | None:
    counts = _sniffer_counts(record).get(f"m{module}")
    if not counts or not counts[0]:
        return None
    return 100.0 * (counts[0] - counts[1]) / counts[0]


def sniffer_lost_pct(record: Any) -> float | None:
    values = [100.0 * (s - c) / s for s, c in _sniffer_counts(record).values() if s]
    return statistics.fmean(values) if values else None


def lost_by_reason(record: Any) -> dict[str, int]:
    out: dict[str, int] = {}
    for e in _custom(record, "bus.read"):
        data = e.data["data"]
        if data.get("lost"):
            why = str(data.get("why") or "lost")
            out[why] = out.get(why, 0) + 1
    return out


def phase_error_rad(record: Any, lag: float = 2 * math.pi / 3, frequency: float = 0.5) -> float | None:
    addresses = {e.agent: e.data["data"]["address"] for e in _custom(record, "bus.addressed")}
    samples: dict[str, list[tuple[float, float]]] = {}
    for e in _custom(record, "bus.phase"):
        samples.setdefault(e.agent, []).append((e.time, e.data["data"]["phase"]))
    if len(samples) < 2 or len(samples) != len(addresses):
        return None
    order = sorted(samples, key=lambda a: addresses[a])
    finished = [e.time for e in _custom(record, "bus.sent")
                if e.data["data"].get("number") == max(x.data["data"].get("number", 0)
                                                       for x in _custom(record, "bus.sent") if x.agent == e.agent)]
    end = min(finished) if finished else record.result.time
    begin = min(5.0, end / 2.0)
    errors = []
    index = {a: 0 for a in order}
    for time, _ in samples[order[0]]:
        if not begin <= time <= end:
            continue
        phases = []
        for agent in order:
            rows = samples[agent]
            i = index[agent]
            while i + 1 < len(rows) and rows[i + 1][0] <= time:
                i += 1
            index[agent] = i
            t, phase = rows[i]
            phases.append(phase + frequency * (time - t))
        pairs = [abs(math.remainder(a - b - lag, 2 * math.pi)) for a, b in zip(phases, phases[1:])]
        errors.append(statistics.fmean(pairs))
    return statistics.fmean(errors) if errors else None


def speed_mps(record: Any) -> float | None:
    poses = _custom(record, "bus.pose")
    if len(poses) < 2:
        return None
    by_time: dict[float, list[tuple[float, float]]] = {}
    for e in poses:
        by_time.setdefault(round(e.time, 6), []).append((e.data["data"]["x"], e.data["data"]["y"]))
    times = sorted(by_time)
    first, last = times[0], times[-1]
    if last - first <= 0:
        return None
    centre = lambda ps: (statistics.fmean(p[0] for p in ps), statistics.fmean(p[1] for p in ps))
    (x0, y0), (x1, y1) = centre(by_time[first]), centre(by_time[last])
    return math.hypot(x1 - x0, y1 - y0) / (last - first)


def register(registry: Any) -> None:
    """Register the metrics (the ``petriflow.actions`` plugin calls this)."""
    for name, function in (("bus.lost_pct", lost_pct), ("bus.lost_pct_module", lost_pct_module),
                           ("bus.phase_error_rad", phase_error_rad), ("bus.speed_mps", speed_mps),
                           ("bus.lost_by_reason", lost_by_reason), ("bus.sniffer_lost_pct", sniffer_lost_pct),
                           ("bus.sniffer_lost_pct_module", sniffer_lost_pct_module)):
        registry.register_metric(name, function, events=("custom",))
