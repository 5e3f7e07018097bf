"""Seed 002's chain at speed: 2-minute runs of the 3-module chain (pybullet, 2 ms steps)
with each algorithm on each bus, as nets, and the same experiment as a pure simulation
(no net, no physics: ``petriflow.agents.bus.run_experiment``) for reference.

Prints a Markdown table of simulated seconds, wall seconds and the real-time factor.
Run: ``python bench/bus.py`` (``--quick``: CAN only).
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]


def net_run(algorithm: int, bus: str, seconds: float = 120.0) -> tuple[float, float, str]:
    from petriflow.agents.bus.nets import build
    from petriflow.runtime.session import run_files

    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        for name in ("world-3.yaml", "chain-3.urdf"):
            shutil.copy(ROOT / "nets" / "bus" / name, folder / name)
        config = yaml.safe_load((ROOT / "nets" / "bus" / "run.yaml").read_text())
        config["channels"]["bus"]["model"] = f"bus.{bus}"
        (folder / "run.yaml").write_text(yaml.safe_dump(config))
        (folder / "net.yaml").write_text(build(3, algorithm, messages=10_000))  # never runs out in 2 minutes
        start = time.perf_counter()
        outcome = run_files(folder / "net.yaml", until=seconds)
        return outcome.result.time, time.perf_counter() - start, outcome.result.reason


def pure_run(algorithm: int, bus: str) -> tuple[float, float]:
    from petriflow.agents.bus import run_experiment

    start = time.perf_counter()
    result = run_experiment(bus, algorithm, messages=100, seed=1)
    return result.duration, time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    buses = ["can"] if args.quick else ["serial", "can", "zigbee"]
    print("| run | bus | algorithm | simulated s | wall s | real-time factor |")
    print("|---|---|---:|---:|---:|---:|")
    for bus in buses:
        for algorithm in (1, 2):
            simulated, wall, reason = net_run(algorithm, bus)
            print(f"| net + pybullet chain, 2 minutes ({reason}) | {bus} | {algorithm} | {simulated:.1f} | {wall:.2f} |"
                  f" {simulated / wall:.1f}× |")
    for bus in buses:
        for algorithm in (1, 2):
            simulated, wall = pure_run(algorithm, bus)
            print(f"| pure simulation, 100 messages | {bus} | {algorithm} | {simulated:.1f} | {wall:.2f} |"
                  f" {simulated / wall:.1f}× |")


if __name__ == "__main__":
    main()
