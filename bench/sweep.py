"""Sweep benchmark: what ``petriflow sweep`` costs beyond its trials, how it scales with
workers, and the Ray backend beside the local pool.

Prints a Markdown table. Run: ``python bench/sweep.py`` (``--quick`` for a smoke run,
``--json OUT`` to keep the numbers).

Every trial is the same small net whose one action burns ``--work`` seconds of CPU
(0.1 s by default): a CPU-bound trial whose own cost is known.

* **Overhead** (target < 10 %): ``--trials`` trials (200) on one worker, against the
  same trials run one after another in one process by a plain loop over
  :func:`petriflow.sweep.trial.run_trial` (what a script would do; no processes, no
  database, no report).
* **Parallelism** (target >= 1.7x on 2 cores): the sweep on ``--workers`` (2) local
  workers against one, beside ``multiprocessing.Pool.map`` over the same trials (the
  standard library's pool: the peer).
* **Ray** (target within 1.3x of the local pool): the sweep on the Ray backend with
  as many tasks in flight, on a Ray instance already running (a cluster's case), and
  counting the start of a local instance.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

ACTIONS = '''
import time
from petriflow import Param, action

@action("bench.spin", params={"seconds": Param(float, 0.1)})
def spin(ctx):
    end = time.process_time() + ctx.params["seconds"]
    x = 0
    while time.process_time() < end:
        x += 1
    return {"spins": x > 0}
'''


def write_sweep(folder: Path, trials: int, work: float) -> Path:
    (folder / "bench_sweep_actions.py").write_text(ACTIONS)
    (folder / "run.yaml").write_text("until: 10\nactions: [bench_sweep_actions.py]\n")
    (folder / "net.yaml").write_text(
        "petriflow: 1\nrun: run.yaml\nplaces: [{id: i, tokens: 1}, o]\n"
        f"transitions: [{{id: work, action: bench.spin, params: {{seconds: {work}}}, in: [i], out: [o]}}]\n"
        "final: {o: 1}\n")
    path = folder / "sweep.yaml"
    path.write_text(f"petriflow-sweep: 1\nnet: net.yaml\ntrials: {trials}\nmetrics: [core.end_time, core.firings]\n")
    return path


def timed(function) -> tuple[float, object]:
    started = time.perf_counter()
    value = function()
    return time.perf_counter() - started, value


def main(argv: list[str] | None = None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=200)
    parser.add_argument("--work", type=float, default=0.1, help="CPU seconds per trial")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--no-ray", action="store_true")
    parser.add_argument("--quick", action="store_true", help="20 trials of 0.02 s")
    parser.add_argument("--json", help="write the rows as JSON here")
    args = parser.parse_args(argv)
    if args.quick:
        args.trials, args.work = 20, 0.02
    sys.path.insert(0, str(ROOT))
    from petriflow.sweep import load_sweep, run_sweep
    from petriflow.sweep.trial import run_trial

    rows: list[dict] = []
    with tempfile.TemporaryDirectory() as tmp:
        sweep = load_sweep(write_sweep(Path(tmp), args.trials, args.work))
        payloads = [sweep.payload(t) for t in sweep.trials()]
        run_trial(payloads[0])  # imports and the action module, as a warm worker has them
        loop, results = timed(lambda: [run_trial(p) for p in payloads])
        assert all(r["status"] == "ok" for r in results)
        inside = sum(r["wall"] for r in results)
        one, _ = timed(lambda: run_sweep(sweep, workers=1))
        rows.append({"measure": f"overhead: {args.trials} trials of {args.work:g} s, 1 worker",
                     "petriflow": one, "peer": loop, "peer_name": "plain loop of run_trial",
                     "ratio": one / loop, "target": "< 1.10", "note": f"trials themselves {inside:.2f} s"})
        many, _ = timed(lambda: run_sweep(sweep, workers=args.workers))
        with multiprocessing.get_context("spawn").Pool(args.workers) as pool:
            pool.map(run_trial, payloads[:args.workers])  # start-up outside the timing, as the peer is kindest
            pooled, _ = timed(lambda: pool.map(run_trial, payloads, chunksize=1))
        rows.append({"measure": f"parallelism: {args.workers} workers vs 1", "petriflow": many, "peer": pooled,
                     "peer_name": f"multiprocessing.Pool({args.workers}).map (warm)",
                     "ratio": one / many, "target": ">= 1.7x speed-up", "note": f"pool {one / pooled:.2f}x of 1 worker"})
        if not args.no_ray:
            try:
                import ray
            except ImportError:
                ray = None
            if ray is not None:
                cold, _ = timed(lambda: run_sweep(sweep, backend="ray", workers=args.workers))
                ray.init(num_cpus=args.workers, include_dashboard=False, log_to_driver=False, logging_level="ERROR")
                try:
                    run_sweep(sweep.with_seeds(args.workers), backend="ray", workers=args.workers)  # workers warm
                    warm, _ = timed(lambda: run_sweep(sweep, backend="ray", workers=args.workers))
                finally:
                    ray.shutdown()
                rows.append({"measure": f"ray, {args.workers} tasks in flight, instance running", "petriflow": warm,
                             "peer": many, "peer_name": f"local backend, {args.workers} workers",
                             "ratio": warm / many, "target": "<= 1.3x", "note": ""})
                rows.append({"measure": f"ray, {args.workers} tasks in flight, starting a local instance",
                             "petriflow": cold, "peer": many, "peer_name": f"local backend, {args.workers} workers",
                             "ratio": cold / many, "target": "-", "note": "Ray's start-up included"})
    print("| measure | petriflow sweep (s) | peer | peer (s) | ratio | target | note |")
    print("|---|---:|---|---:|---:|---|---|")
    for row in rows:
        print(f"| {row['measure']} | {row['petriflow']:.2f} | {row['peer_name']} | {row['peer']:.2f} |"
              f" {row['ratio']:.2f} | {row['target']} | {row['note']} |")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2))
    return rows


if __name__ == "__main__":
    main()
