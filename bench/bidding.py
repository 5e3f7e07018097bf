"""Seed 004 at scale: the eq. 6 auction and the mapping mission.

1. Allocation: 1,000 zones auctioned among 100 robots (random positions in a
   200 m x 100 m floor), one CFP per zone in rank order, as the robot agents decide it.
   Side by side: ``petriflow.agents.bidding.auction.autonomous`` (numpy over the robots),
   the same auction written as plain Python loops (the textbook way; it must give the
   same winners), and SciPy's Hungarian method (``linear_sum_assignment``, an optimal
   assignment of the same size: every robot duplicated 10 times, 1,000 x 1,000; the
   other deployment method the paper cites) when SciPy is installed.
2. Missions: the paper's office with 5 robots (both deployments) and the generated
   20-room office with 20 robots, one seed each: simulated time, wall time, real-time
   factor.

Prints Markdown tables. Run: ``python bench/bidding.py`` (``--quick``: fewer repeats,
no 20-robot mission).
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def plain_auction(positions, zones, speed, area):
    """The sequential auction of eq. 6 with lists and loops (the reference)."""
    counts = [0] * len(positions)
    base = math.log(area)
    winners = []
    for gx, gy in zones:
        best, winner = math.inf, -1
        for i, (x, y) in enumerate(positions):
            n = counts[i]
            travel = math.hypot(x - gx, y - gy) / speed
            cost = (n + 1) * travel / 3 + base ** n * n / 3 + 0.0
            if winner < 0 or cost < best - 1e-9 * max(1.0, abs(best)):
                best, winner = cost, i
        winners.append(winner)
        counts[winner] += 1
    return winners


def timed(function, repeats):
    times = []
    result = None
    for _ in range(repeats):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return statistics.median(times), result


def allocation(repeats: int) -> None:
    from petriflow.agents.bidding.auction import autonomous

    rng = np.random.default_rng(7)
    robots = rng.uniform((0, 0), (200, 100), (100, 2))
    zones = rng.uniform((0, 0), (200, 100), (1000, 2))
    area = 200.0 * 100.0
    ours, won = timed(lambda: autonomous(robots, zones, area=area, speed=0.5), repeats)
    plain, winners = timed(lambda: plain_auction(robots.tolist(), zones.tolist(), 0.5, area), max(1, repeats // 3))
    assert winners == won.winner, "the numpy auction and the plain one disagree"
    rows = [("petriflow `auction.autonomous` (numpy)", ours, "1.00"),
            ("the same auction in plain Python", plain, f"{plain / ours:.1f}× slower")]
    try:
        from scipy.optimize import linear_sum_assignment

        travel = np.hypot(*(robots[:, None, :] - zones[None, :, :]).transpose(2, 0, 1)) / 0.5
        hungarian, _ = timed(lambda: linear_sum_assignment(np.repeat(travel, 10, axis=0)), max(1, repeats // 3))
        rows.append(("SciPy Hungarian, 1,000 × 1,000 (optimal assignment)", hungarian,
                     f"{hungarian / ours:.1f}× slower"))
    except ImportError:
        rows.append(("SciPy Hungarian", math.nan, "SciPy not installed"))
    counts = np.bincount(won.winner, minlength=100)
    print(f"\n### Allocation: 1,000 zones among 100 robots (median of {repeats})\n")
    print("| method | wall time | vs petriflow |\n|---|---:|---:|")
    for name, seconds, ratio in rows:
        print(f"| {name} | {seconds * 1000:.1f} ms | {ratio} |")
    print(f"\nzones per robot: {counts.min()}..{counts.max()} (the load term of eq. 6 spreads them)")


def mission(net: str, seed: int = 1) -> dict:
    from petriflow.agents.bidding import metrics
    from petriflow.runtime.metrics import RunRecord
    from petriflow.runtime.session import run_files

    outcome = run_files(ROOT / "nets" / "bidding" / net, seed=seed, keep_events=True)
    record = RunRecord(outcome.result, outcome.events)
    return {"net": net, "reason": outcome.result.reason, "sim": outcome.result.time, "wall": outcome.wall,
            "factor": outcome.result.time / outcome.wall, "time_s": metrics.time_s(record),
            "accuracy": metrics.accuracy_pct(record), "messages": metrics.messages(record)}


def missions(quick: bool) -> None:
    nets = ["bidding-autonomous-5.yaml", "bidding-random-5.yaml"]
    if not quick:
        nets.append("bidding-autonomous-20.yaml")
    print("\n### Missions (seed 1)\n")
    print("| net | end | simulated s | wall s | real-time factor | mapping time s | accuracy % | messages |")
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    for net in nets:
        r = mission(net)
        print(f"| {r['net']} | {r['reason']} | {r['sim']:.1f} | {r['wall']:.2f} | {r['factor']:.1f}× |"
              f" {r['time_s']:.1f} | {r['accuracy']:.2f} | {r['messages']} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    allocation(3 if args.quick else 9)
    missions(args.quick)


if __name__ == "__main__":
    main()
