"""Seed 000 at scale: the mapping mission with 3, 5, 10, 25 and 50 robots, centralised
and decentralised, in mazes that grow with the team (about 12 cells a robot).

Prints a Markdown table: map vertices, bytes of map data, when every agent held the
whole map, distance per robot, wall time, the real-time factor, and the CPU seconds of
the run (``time.process_time()`` around reading, binding and running the net) per
simulated second, the cost measure that other jobs on the machine disturb least. Run:
``python bench/comm.py`` (``--quick``: 3 and 5 robots only; ``--robots 3 10``).

Each run is one seed (1); the maze of a size is the same for both modes.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]


def maze_side(robots: int) -> int:
    return 6 if robots <= 3 else math.ceil(math.sqrt(12 * robots))


def run(robots: int, mode: str, folder: Path, until: float = 6000.0) -> dict:
    from petriflow.agents.comm import metrics
    from petriflow.agents.comm.nets import build, world
    from petriflow.runtime.metrics import RunRecord
    from petriflow.runtime.session import run_files
    from petriflow.world import load_world

    cols = maze_side(robots)
    area = round(cols * 5 / 6, 6)
    (folder / "world.yaml").write_text(yaml.safe_dump(world(robots=robots, cols=cols, area=area), sort_keys=False))
    (folder / "run.yaml").write_text(f"seed: 1\nuntil: {until}\nstall: 1200\nworld: world.yaml\n"
                                     "channels: {radio: {model: comm.radio, adapter_limit: [central], on_loss: notify}}\n")
    net = folder / f"{mode}-{robots}.yaml"
    built = build(robots, mode, cols=cols, area=area, cell=area / cols)
    if not isinstance(built, str):  # a Net (the builder's return since it uses petriflow.netbuild)
        from petriflow.io.yaml import dumps_net

        built = dumps_net(built)
    net.write_text("run: run.yaml\n" + built)
    started, cpu_started = time.perf_counter(), time.process_time()
    outcome = run_files(net, keep_events=True)
    cpu = time.process_time() - cpu_started
    wall = time.perf_counter() - started
    scene = load_world(folder / "world.yaml")
    try:
        record = RunRecord(outcome.result, outcome.events, scene)
        return {"robots": robots, "mode": mode, "maze": f"{cols}x{cols}", "vertices": metrics.vertices(record),
                "bytes": metrics.bytes_total(record), "time_s": metrics.time_s(record),
                "complete": metrics.maps_complete(record), "distance_m": metrics.distance_m(record),
                "end": outcome.result.time, "reason": str(outcome.result.reason.value), "wall": wall,
                "factor": outcome.result.time / wall, "cpu": cpu, "cpu_per_s": cpu / outcome.result.time}
    finally:
        scene.close()


def main(argv: list[str] | None = None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, nargs="+", default=[3, 5, 10, 25, 50])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--modes", nargs="+", default=["centralised", "decentralised"])
    parser.add_argument("--until", type=float, default=6000.0, help="simulated-time limit of each run (s)")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    teams = [3, 5] if args.quick else args.robots
    rows = []
    print("| robots | mode | maze | vertices | bytes of map data | bytes / vertex | all maps complete at (s) "
          "| maps complete | distance / robot (m) | run ends (s) | wall (s) | x real time | CPU (s) "
          "| CPU ms / simulated s |")
    print("|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for robots in teams:
        for mode in args.modes:
            with tempfile.TemporaryDirectory() as tmp:
                row = run(robots, mode, Path(tmp), args.until)
            rows.append(row)
            print(f"| {row['robots']} | {row['mode']} | {row['maze']} | {row['vertices']} | {row['bytes']:,} |"
                  f" {row['bytes'] / row['vertices']:.1f} | {row['time_s']:.0f} | {row['complete']:.2f} |"
                  f" {row['distance_m']:.1f} | {row['end']:.0f} ({row['reason']}) | {row['wall']:.1f} |"
                  f" {row['factor']:.0f} | {row['cpu']:.1f} | {1000 * row['cpu_per_s']:.1f} |", flush=True)
    return rows


if __name__ == "__main__":
    main()
