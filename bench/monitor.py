"""What ``run --monitor`` costs: CPU of the 20-robot bidding mission with and without it.

Each run is a fresh process (``run_files``; the CPU seconds of the run itself,
``time.process_time``, as ``RunResult.cpu`` measures them), alternating without and
with the monitor, ``--repeats`` times each, for ``--until`` simulated seconds of the
20-robot mission in the generated office (``nets/bidding/bidding-autonomous-20.yaml``:
its three properties, two of which the monitor checks on every marking, one CTL
property it reports as not monitorable). Prints a Markdown table and the ratio of the
medians. Run: ``python bench/monitor.py [--until 120] [--repeats 3]``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
NET = ROOT / "nets" / "bidding" / "bidding-autonomous-20.yaml"

CHILD = """
import json, sys
from petriflow.runtime.session import run_files
result = run_files(sys.argv[1], config=sys.argv[2], until=float(sys.argv[3]), monitor=sys.argv[4] == "1")
print(json.dumps({"cpu": result.cpu, "firings": result.firings, "time": result.time,
                  "properties": [(p["id"], p["verdict"]) for p in result.properties]}))
"""


def one(monitor: bool, until: float) -> dict:
    done = subprocess.run([sys.executable, "-c", CHILD, str(NET), str(NET.parent / "run-20.yaml"), str(until),
                           "1" if monitor else "0"], capture_output=True, text=True, check=True, cwd=ROOT)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--until", type=float, default=120.0, help="simulated seconds of each run")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    rows = {False: [], True: []}
    for _ in range(args.repeats):
        for monitor in (False, True):
            rows[monitor].append(one(monitor, args.until))
    print("| monitor | runs | firings | CPU s (median) | CPU s (all) |")
    print("|---|---|---|---|---|")
    for monitor in (False, True):
        cpus = [r["cpu"] for r in rows[monitor]]
        print(f"| {'on' if monitor else 'off'} | {len(cpus)} | {rows[monitor][0]['firings']} |"
              f" {statistics.median(cpus):.2f} | {' '.join(f'{c:.2f}' for c in cpus)} |")
    off = statistics.median(r["cpu"] for r in rows[False])
    on = statistics.median(r["cpu"] for r in rows[True])
    print(f"\nmonitor overhead: {100 * (on / off - 1):+.1f} % CPU (median with / median without = {on / off:.3f})")
    print(f"properties (last monitored run): {rows[True][-1]['properties']}")


if __name__ == "__main__":
    main()
