"""Runtime benchmark: scheduler overhead per firing and real-time factor of a world run.

Prints a Markdown table. Run: ``python bench/runtime.py`` (``--quick`` for a smoke run,
``--json OUT`` to keep the numbers).

* Overhead: a two-place cycle of transitions bound to ``core.noop`` (an instant
  action), fired N times by the scheduler with full event recording (no files); the
  bare token game (:class:`petriflow.engine.Simulation`) on the same net is the
  baseline, so the ratio is the cost of actions, events and the clock.
* Real-time factor: the ``nets/passage`` example (two differential robots, pybullet at
  dt = 0.01 s), simulated seconds per wall-clock second, with and without the
  trace, journal and XES files.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CYCLE = """
petriflow: 1
places: [{id: p, tokens: 1}, q]
transitions:
  - {id: a, action: core.noop, in: [p], out: [q]}
  - {id: b, action: core.noop, in: [q], out: [p]}
"""


def overhead(firings: int) -> list[dict]:
    from petriflow.engine import Simulation
    from petriflow.io.yaml import loads_net
    from petriflow.runtime.scheduler import Scheduler

    net = loads_net(CYCLE)
    rows = []
    started = time.perf_counter()
    Simulation(net, seed=0).run(until=firings)
    bare = time.perf_counter() - started
    rows.append({"what": "token game (Simulation), no actions", "firings": firings, "seconds": bare})
    scheduler = Scheduler(net, seed=0)
    events = []
    scheduler.on_event(events.append)
    started = time.perf_counter()
    scheduler.run(max_firings=firings)
    took = time.perf_counter() - started
    rows.append({"what": "scheduler, core.noop action, events kept", "firings": firings, "seconds": took})
    for row in rows:
        row["per_second"] = row["firings"] / row["seconds"]
    return rows


def realtime_factor(repeats: int) -> list[dict]:
    from petriflow.runtime.session import run_files

    net = ROOT / "nets" / "passage" / "passage.yaml"
    rows = []
    for files in (False, True):
        best = None
        for _ in range(repeats):
            with tempfile.TemporaryDirectory() as folder:
                options = {}
                if files:
                    options = {"trace": Path(folder) / "t.jsonl", "xes": Path(folder) / "t.xes",
                               "db": Path(folder) / "t.sqlite"}
                outcome = run_files(net, **options)
            if best is None or outcome.wall < best.wall:
                best = outcome
        rows.append({"what": "passage run" + (" + trace, XES, journal" if files else ""),
                     "simulated_s": best.result.time, "wall_s": best.wall,
                     "realtime_factor": best.realtime_factor, "firings": best.result.firings})
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small counts (smoke test)")
    parser.add_argument("--json", help="also write the numbers as JSON")
    args = parser.parse_args(argv)
    firings = 2_000 if args.quick else 100_000
    first = overhead(firings)
    second = realtime_factor(1 if args.quick else 3)
    print("| measurement | firings | seconds | firings/s |")
    print("|---|---:|---:|---:|")
    for row in first:
        print(f"| {row['what']} | {row['firings']:,} | {row['seconds']:.3f} | {row['per_second']:,.0f} |")
    print(f"\nscheduler overhead: {first[1]['seconds'] / first[1]['firings'] * 1e6:.1f} µs per firing"
          f" ({first[0]['per_second'] / first[1]['per_second']:.1f}x the bare token game)\n")
    print("| run | simulated s | wall s | real-time factor |")
    print("|---|---:|---:|---:|")
    for row in second:
        print(f"| {row['what']} | {row['simulated_s']:.2f} | {row['wall_s']:.3f} | {row['realtime_factor']:.1f}x |")
    if args.json:
        Path(args.json).write_text(json.dumps({"overhead": first, "realtime": second}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
