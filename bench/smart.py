"""SMART helping-task benchmark: real-time factor and where the wall-clock time goes.

Runs ``nets/smart/smart.yaml`` over ``nets/smart/world.yaml`` as ``petriflow run``
does (seed 1), once with the world's 640 x 480 camera and once with the camera at
320 x 240; the camera loop closes at 6 Hz of simulated time and a frame is rendered
only when a capture transition (T0, T2) fires. Prints Markdown tables: simulated and
wall seconds, the real-time factor (simulated seconds per wall second) against the
targets (>= 1x at 640 x 480, >= 3x at 320 x 240), and the split of the wall time
into render / vision / planning / physics / gait control / net
(:class:`petriflow.agents.smart.timing.Timers`, the run's stopwatch, to which those
parts report; the rest is the net: scheduler, guards, token data and trace events).

Run: ``python bench/smart.py`` (``--quick`` for a short smoke run: 5 s simulated,
``--json OUT`` to keep the numbers).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
NETS = REPO / "nets" / "smart"
#: (label, camera size, real-time factor target)
CASES = (("640x480", (640, 480), 1.0), ("320x240", (320, 240), 3.0))
PARTS = ("render", "vision", "planning", "physics", "control", "net")


def measure(size: tuple[int, int], until: float | None, folder: Path) -> dict:
    """One run of the helping net with the camera at ``size``; the numbers of a row."""
    from petriflow.agents.planning.astar import warm_up
    from petriflow.agents.smart.experiments import world_with_camera
    from petriflow.agents.smart.timing import Timers

    from petriflow.runtime.session import run_files

    world = world_with_camera(NETS / "world.yaml", folder, None if size == (640, 480) else size)
    warm_up()  # numba's compilation is not part of the run
    kwargs = {} if until is None else {"until": until}
    with Timers() as timers:
        outcome = run_files(NETS / "smart.yaml", world=world, seed=1, stopwatch=timers, **kwargs)
    result = outcome.result
    split = timers.split(outcome.wall)
    renders = timers.calls["render"]
    return {
        "camera": f"{size[0]}x{size[1]}", "reason": result.reason, "simulated_s": result.time,
        "wall_s": outcome.wall, "realtime_factor": result.time / outcome.wall if outcome.wall else None,
        "frames": renders, "frames_per_sim_s": renders / result.time if result.time else None,
        "ms_per_frame": 1000 * timers.seconds["render"] / renders if renders else None,
        "ms_per_vision": 1000 * timers.seconds["vision"] / max(1, timers.calls["vision"]),
        "planning_ms": [round(1000 * s, 3) for s in timers.samples["planning"]],
        "search_ms": [round(1000 * s, 3) for s in timers.samples["search"]],
        "physics_steps": timers.calls["physics"],
        "split_s": split, "split_share": {k: v / outcome.wall for k, v in split.items()} if outcome.wall else {},
    }


def main(argv: list[str] | None = None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="5 s of simulated time per camera (smoke test)")
    parser.add_argument("--json", help="also write the numbers as JSON")
    args = parser.parse_args(argv)
    until = 5.0 if args.quick else None
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for label, size, target in CASES:
            row = measure(size, until, Path(folder))
            row["target"] = target
            rows.append(row)
    print("SMART helping task (nets/smart/smart.yaml, seed 1), camera loop at 6 Hz of simulated time\n")
    print("| camera | run | simulated s | wall s | real-time factor | target | frames | ms/frame "
          "| ms/image processed | planning ms (A* search ms) |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for row in rows:
        met = "met" if row["realtime_factor"] >= row["target"] else "missed"
        astar = ", ".join(f"{v:.1f} ({w:.1f})" for v, w in zip(row["planning_ms"], row["search_ms"])) or "-"
        print(f"| {row['camera']} | {row['reason']} | {row['simulated_s']:.1f} | {row['wall_s']:.1f} "
              f"| {row['realtime_factor']:.2f}x | >= {row['target']:.0f}x ({met}) | {row['frames']} "
              f"| {row['ms_per_frame']:.1f} | {row['ms_per_vision']:.1f} | {astar} |")
    print("\nwall-clock split (seconds, share of the run)\n")
    print("| camera | " + " | ".join(PARTS) + " |")
    print("|---|" + "---:|" * len(PARTS))
    for row in rows:
        cells = [f"{row['split_s'][p]:.2f} ({100 * row['split_share'][p]:.0f} %)" for p in PARTS]
        print(f"| {row['camera']} | " + " | ".join(cells) + " |")
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(rows, indent=2), encoding="utf-8")
    return rows


if __name__ == "__main__":
    main()
    sys.exit(0)
