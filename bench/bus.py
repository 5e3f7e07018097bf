"""Seed 002's chain at speed: 2-minute runs of the 3-module chain (pybullet, 2 ms steps)
with each algorithm on each bus, as nets, and each bus on its own
(``petriflow.agents.bus.BusSimulator``: no net, no physics) under algorithm 1's load,
for reference.

Prints a Markdown table of simulated seconds, wall seconds and the real-time factor.
Run: ``python bench/bus.py`` (``--quick``: CAN only).
"""

from __future__ import annotations

import argparse
import random
import shutil
import tempfile
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]


def net_run(algorithm: int, bus: str, seconds: float = 120.0) -> tuple[float, float, str]:
    from petriflow.agents.bus.nets import build
    from petriflow.io.yaml import dumps_net
    from petriflow.runtime.session import run_files

    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        for name in ("world-3.yaml", "chain-3.urdf"):
            shutil.copy(ROOT / "nets" / "bus" / name, folder / name)
        config = yaml.safe_load((ROOT / "nets" / "bus" / "run.yaml").read_text())
        config["channels"]["bus"]["model"] = f"bus.{bus}"
        (folder / "run.yaml").write_text(yaml.safe_dump(config))
        net = build(3, algorithm, messages=10_000)  # never runs out in 2 minutes
        (folder / "net.yaml").write_text(dumps_net(net))
        start = time.perf_counter()
        outcome = run_files(folder / "net.yaml", until=seconds)
        return outcome.result.time, time.perf_counter() - start, outcome.result.reason


def bus_run(bus: str, seconds: float = 120.0, seed: int = 1) -> tuple[float, float, int]:
    """The bus alone: 3 modules, each sending its neighbours a CPG frame every
    20 ms + U[0, 1] s (algorithm 1's load) and reading its buffer every 20 ms."""
    from petriflow.agents.bus import BusSimulator, CanBus, Frame, SerialBus, ZigbeeBus

    model = {"serial": SerialBus, "can": CanBus, "zigbee": ZigbeeBus}[bus]()
    sim = BusSimulator(model, modules=[0, 1, 2], seed=seed)
    rng = random.Random(seed)
    frames = 0
    for module in range(3):
        sim.reads_every(module, 0.02, phase=rng.uniform(0.0, 0.1))
        at, period = rng.uniform(0.0, 0.1), 0.02 + rng.uniform(0.0, 1.0)
        neighbours = tuple(m for m in (module - 1, module + 1) if 0 <= m < 3)
        while at < seconds:
            sim.send(at, Frame(module, neighbours, bytes(8), 0x100 + module))
            at += period
            frames += 1
    start = time.perf_counter()
    sim.run(until=seconds)
    return seconds, time.perf_counter() - start, frames


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
            print(f"| net + pybullet chain, 2 minutes ({reason}) | {bus} | {algorithm} | {simulated:.1f} |"
                  f" {wall:.2f} | {simulated / wall:.1f}× |")
    for bus in buses:
        simulated, wall, frames = bus_run(bus)
        print(f"| the bus alone, {frames} frames | {bus} | 1 | {simulated:.1f} | {wall:.2f} |"
              f" {simulated / wall:.0f}× |")


if __name__ == "__main__":
    main()
