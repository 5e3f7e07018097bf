"""Legged-robot benchmark: pybullet steps/s with Robot4L and Robot3L, walking speeds and
the real-time factor of a walk.

Prints Markdown tables. Run: ``python bench/gait.py`` (``--quick`` for a smoke run,
``--json OUT`` to keep the numbers).

* Physics: a world (dt = 1/240 s, the pybullet default) with one Robot4L, one Robot3L,
  or both, standing on their motors; ``World.step()`` alone, steps per wall second.
* Walking: ``gait.walk`` fired through the scheduler on each robot (and on both at
  once) for a fixed simulated time from a standing start: the speed achieved (metres
  travelled over simulated seconds), the gait's planned speed, steps per wall second
  with the gait control running every tick, and the real-time factor (simulated
  seconds per wall second).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

DT = 1.0 / 240.0
ROBOTS = {
    "robot4l": {"id": "dog", "urdf": "petriflow.agents.legged:robots/robot4l.urdf", "position": [0, 0], "z": 0.14},
    "robot3l": {"id": "cat", "urdf": "petriflow.agents.legged:robots/robot3l.urdf", "position": [0, 0.6], "z": 0.08},
}
SETS = {"Robot4L": ["robot4l"], "Robot3L": ["robot3l"], "both": ["robot4l", "robot3l"]}


def _world(names: list[str]):
    from petriflow.world import World

    return World({"dt": DT, "robots": [ROBOTS[n] for n in names]})


def physics(steps: int) -> list[dict]:
    """Steps per second of ``World.step()`` with the robots standing on their motors."""
    from petriflow.agents.legged.control import LeggedRobot

    rows = []
    for label, names in SETS.items():
        world = _world(names)
        for name in names:
            robot = LeggedRobot(world, ROBOTS[name]["id"])
            robot.hold(robot.nominal())
        for _ in range(200):  # settle first
            world.step()
        started = time.perf_counter()
        for _ in range(steps):
            world.step()
        took = time.perf_counter() - started
        world.close()
        rows.append({"robots": label, "steps": steps, "seconds": took, "steps_per_s": steps / took})
    return rows


def walking(seconds: float) -> list[dict]:
    """Walk each robot set straight ahead for ``seconds`` of simulated time."""
    from petriflow.agents.legged.control import LeggedRobot
    from petriflow.agents.legged.gait import gait_for

    from petriflow.io.yaml import loads_net
    from petriflow.runtime.scheduler import Scheduler

    rows = []
    for label, names in SETS.items():
        world = _world(names)
        transitions = "\n".join(
            f"  - {{id: walk_{n}, action: gait.walk, params: {{robot: {ROBOTS[n]['id']}, distance: 50.0}},"
            f" in: [start_{n}], out: [end_{n}]}}" for n in names)
        places = ", ".join(f"{{id: start_{n}, tokens: 1}}, end_{n}" for n in names)
        net = loads_net(f"petriflow: 1\nplaces: [{places}]\ntransitions:\n{transitions}\n")
        robots = {n: LeggedRobot(world, ROBOTS[n]["id"]) for n in names}
        before = {n: r.pose() for n, r in robots.items()}
        scheduler = Scheduler(net, world=world, seed=0)
        steps_before = world.steps
        started = time.perf_counter()
        result = scheduler.run(until=seconds)
        took = time.perf_counter() - started
        steps = world.steps - steps_before
        for n, robot in robots.items():
            x, y, _ = robot.pose()
            travelled = math.hypot(x - before[n][0], y - before[n][1])
            rows.append({
                "robots": label, "robot": n, "simulated_s": result.time, "wall_s": took,
                "travelled_m": travelled, "speed_m_s": travelled / result.time,
                "planned_m_s": gait_for(robot.design).speed, "steps_per_s": steps / took,
                "realtime_factor": result.time / took, "upright": robot.upright(),
            })
        world.close()
    return rows


def main(argv: list[str] | None = None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small counts (smoke test)")
    parser.add_argument("--json", help="also write the numbers as JSON")
    args = parser.parse_args(argv)
    first = physics(500 if args.quick else 20_000)
    second = walking(3.0 if args.quick else 20.0)
    print(f"pybullet, dt = 1/{1 / DT:.0f} s, robots standing on their motors\n")
    print("| robots | steps | seconds | steps/s |")
    print("|---|---:|---:|---:|")
    for row in first:
        print(f"| {row['robots']} | {row['steps']:,} | {row['seconds']:.3f} | {row['steps_per_s']:,.0f} |")
    print(f"\ngait.walk from a standing start, {second[0]['simulated_s']:.0f} s simulated\n")
    print("| robots | robot | travelled m | speed m/s | planned m/s | steps/s | real-time factor |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for row in second:
        print(f"| {row['robots']} | {row['robot']} | {row['travelled_m']:.3f} | {row['speed_m_s']:.4f}"
              f" | {row['planned_m_s']:.4f} | {row['steps_per_s']:,.0f} | {row['realtime_factor']:.1f}x |")
    if args.json:
        Path(args.json).write_text(json.dumps({"physics": first, "walking": second}, indent=2), encoding="utf-8")
    return first + second


if __name__ == "__main__":
    main()
    sys.exit(0)
