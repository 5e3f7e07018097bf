"""Seed 001 at speed and at scale.

1. The paper's mission (experiment 1, the Fig. 6 world, one RA): simulated seconds,
   wall seconds and the real-time factor (the target: a 22-minute mission in well under
   a minute, >= 50x real time), and the CPU seconds per simulated second (the cost
   measure other jobs on the machine disturb least).
2. Scale: a generated 50 m x 50 m maze (10 x 10 cells of 5 m, 10 % loops,
   ``nets/slam/experiments/maze-50.yaml``) mapped by one RA, then by five RAs sharing
   their WAs: when the map was done, WAs installed, map quality, wall time.

Prints Markdown tables. Run ``python bench/slam.py`` (``--quick``: the paper's mission
only; ``--seeds 1 2 3``). Each row is one seed.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def run(mode: str = "decentralised", *, robots: int = 1, reserves: int = 1, was: int = 16,
        world: str = "world.yaml", seed: int = 1, until: float = 20000.0) -> dict:
    from petriflow.agents.slam import metrics
    from petriflow.agents.slam.nets import build
    from petriflow.runtime.config import load_config
    from petriflow.runtime.metrics import RunRecord
    from petriflow.runtime.session import run as run_net
    from petriflow.world import load_world

    scene = load_world(ROOT / "nets" / "slam" / world)
    config = load_config(ROOT / "nets" / "slam" / "run.yaml")
    net = build(mode, robots=robots, reserves=reserves, was=was)
    started, cpu_started = time.perf_counter(), time.process_time()
    outcome = run_net(net, world=scene, config=config, seed=seed, until=until, keep_events=True)
    cpu = time.process_time() - cpu_started
    wall = time.perf_counter() - started
    try:
        record = RunRecord(outcome.result, outcome.events, scene, config)
        return {"mode": mode, "robots": robots, "world": world, "seed": seed, "time_s": metrics.time_s(record),
                "was": metrics.was_used(record), "missing": metrics.vertices_missing(record),
                "truth": len(record.world.meta["slam"]["vertices"]), "error": metrics.vertex_error_m(record),
                "extra": metrics.vertices_extra(record), "distance": metrics.distance_m(record),
                "end": outcome.result.time, "reason": str(outcome.result.reason.value), "wall": wall,
                "cpu": cpu}
    finally:
        scene.close()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="seed 001 at speed and at scale")
    parser.add_argument("--quick", action="store_true", help="only the paper's mission")
    parser.add_argument("--seeds", type=int, nargs="+", default=[1])
    args = parser.parse_args(argv)
    print("| mission | seed | map done (s) | simulated (s) | wall (s) | x real time | CPU s / sim s |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for seed in args.seeds:
        row = run(seed=seed)
        print(f"| experiment 1 (Fig. 6, 1 RA) | {seed} | {row['time_s']:.0f} | {row['end']:.0f} | {row['wall']:.1f} |"
              f" {row['end'] / row['wall']:.0f} | {row['cpu'] / row['end']:.4f} |")
        sys.stdout.flush()
    if args.quick:
        return 0
    print()
    print("| 50 m maze | seed | map done (s) | WAs | vertices missing / truth | extra | error (m) | driven (m) |"
          " wall (s) | x real time |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for robots, was in ((1, 40), (5, 20)):
        for seed in args.seeds:
            row = run(robots=robots, reserves=0, was=was, world="experiments/maze-50.yaml", seed=seed)
            done = "never" if row["time_s"] is None else f"{row['time_s']:.0f}"
            error = "-" if row["error"] is None else f"{row['error']:.2f}"
            print(f"| {robots} RA{'s' if robots > 1 else ''} | {seed} | {done} | {row['was']} |"
                  f" {row['missing']} / {row['truth']} | {row['extra']} | {error} | {row['distance']:.0f} |"
                  f" {row['wall']:.0f} | {row['end'] / row['wall']:.0f} |")
            sys.stdout.flush()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
