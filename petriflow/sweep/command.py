"""``petriflow sweep``: run a sweep file and print (or write) its report.

Exit codes: 0 every trial ran and no run ended ``failed``, 1 some trial failed (its
run ended failed, or it could not run, crashed or timed out; they are in the report,
with their status, and in the results database), 2 bad input. Progress goes to standard
error: a bar on a terminal, a line every ``--progress-every`` seconds otherwise (a log,
CI), nothing with ``--quiet``.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from petriflow.errors import PetriflowError

__all__ = ["add_parser", "cmd_sweep"]


def add_parser(sub) -> argparse.ArgumentParser:
    """Add the ``sweep`` command to the ``petriflow`` subcommands ``sub``."""
    from petriflow.sweep.backends import BACKENDS

    sweep = sub.add_parser(
        "sweep", help="Run an experiment: a net over a grid of parameters and seeds, measured.",
        description="Run every trial (a row's parameters and a seed) of a sweep file, record one row per"
        " trial in SQLite (--db) and print each metric's mean ± sd per row beside the paper's value."
        " See docs/sweep-format.md. Exit 0 when every trial ran, 1 when some failed, 2 on bad input.")
    sweep.add_argument("spec", help="sweep file (YAML)")
    sweep.add_argument("--backend", choices=BACKENDS, default="local",
                       help="local worker processes (default) or a Ray cluster")
    sweep.add_argument("--workers", type=int, help="processes (local; default: every CPU) or tasks in"
                       " flight (ray; default: the cluster's CPUs)")
    sweep.add_argument("--trials", type=int, help="run seeds 1..K (overrides the file's trials or seeds)")
    sweep.add_argument("--db", help="SQLite results database (new file; or the one to --resume)")
    sweep.add_argument("--resume", action="store_true", help="run only the trials --db lacks")
    sweep.add_argument("--ray-address", help="Ray cluster address (default: RAY_ADDRESS, else a local instance)")
    sweep.add_argument("--json", action="store_true", help="print the report as JSON")
    sweep.add_argument("--csv", metavar="OUT", help="write the report as CSV")
    sweep.add_argument("--plot", metavar="OUT.png", help="plot each metric against the first parameter")
    sweep.add_argument("--metrics", metavar="NAMES", help="report only these metrics (comma-separated)")
    sweep.add_argument("--quiet", action="store_true", help="no progress on standard error")
    sweep.add_argument("--progress-every", type=float, default=30.0, metavar="S",
                       help="off a terminal: a progress line every S wall seconds (default 30)")
    sweep.set_defaults(handler=cmd_sweep)
    return sweep


def cmd_sweep(args: argparse.Namespace) -> int:
    from petriflow.sweep import load_sweep, run_sweep
    from petriflow.sweep.report import plot, text_table, write_csv

    if args.workers is not None and args.workers < 1:
        raise PetriflowError(f"--workers must be at least 1, got {args.workers}")
    if args.trials is not None and not 1 <= args.trials <= 1_000_000:
        raise PetriflowError(f"--trials must be from 1 to 1,000,000, got {args.trials}")
    if args.resume and args.db is None:
        raise PetriflowError("--resume needs --db RESULTS (the database of the sweep to finish)")
    if args.plot is not None and not args.plot.lower().endswith(".png"):
        raise PetriflowError(f"--plot writes a PNG picture: name a .png file, not {args.plot!r}")
    sweep = load_sweep(args.spec)
    if args.trials is not None:
        sweep = sweep.with_seeds(args.trials)
    from petriflow.runtime.session import _check_outputs

    _check_outputs({"--db": args.db, "--csv": args.csv, "--plot": args.plot},
                   [Path(sweep.path)] + ([Path(sweep.run)] if sweep.run else []))
    if not args.progress_every > 0:
        raise PetriflowError(f"--progress-every must be a number of seconds > 0, got {args.progress_every}")
    progress = None if args.quiet else ("bar" if sys.stderr.isatty() else args.progress_every)
    result = run_sweep(sweep, backend=args.backend, workers=args.workers, db=args.db, resume=args.resume,
                       progress=progress, ray_address=args.ray_address)
    if args.metrics:
        wanted = [m.strip() for m in args.metrics.split(",") if m.strip()]
        unknown = [m for m in wanted if m not in result.names]
        if unknown:
            from petriflow.errors import did_you_mean

            raise PetriflowError(f"--metrics: no metric {unknown[0]!r}{did_you_mean(unknown[0], result.names)}"
                                 f" (the sweep reports {', '.join(result.names)})")
        result.names = wanted
    parameters = sweep.parameters
    if args.json:
        json.dump(result.to_json(), sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        title = sweep.name + (f" ({sweep.paper_source})" if sweep.paper_source else "")
        print(f"{title}: {_count(len(result.trials), 'trial')} in {_count(len(result.rows), 'row')}"
              f" ({result.ran} run now in {result.wall:.1f} s wall, {len(result.failures)} failed)")
        print(text_table(result.rows, result.names, parameters))
        if result.wall_clock():
            print(f"  wall-clock (not reproducible between runs, unlike the other metrics):"
                  f" {', '.join(result.wall_clock())}")
        from petriflow.sweep.report import trial_status

        for failure in result.failures[:5]:
            print(f"  failed: row {failure['row'] + 1} seed {failure['seed']}: {trial_status(failure)}:"
                  f" {failure['error']}")
        if len(result.failures) > 5:
            print(f"  ... and {len(result.failures) - 5} more failures (see --db)")
    if args.csv:
        write_csv(args.csv, result.rows, result.names, parameters)
    if args.plot:
        plot(args.plot, result.rows, result.names, parameters,
             title=sweep.name + (f" (paper: {sweep.paper_source})" if sweep.paper_source else ""))
    if not args.json:
        for path in (args.db, args.csv, args.plot):
            if path:
                print(f"  wrote {path}")
    return 1 if result.failures else 0


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}{'' if n == 1 else 's'}"
