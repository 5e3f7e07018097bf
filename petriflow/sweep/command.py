"""``petriflow sweep``: run a sweep file and print (or write) its report.

Exit codes: 0 every trial ran and no run ended ``failed``, 1 some trial failed (its
run ended failed, or it could not run, crashed or timed out; they are in the report,
with their status, and in the results database), 2 bad input. Progress goes to standard
error: a bar on a terminal, a line every ``--progress-every`` seconds otherwise (a log,
CI), nothing with ``--quiet``; so does anything else written to standard output while
trials run (a trial's prints), and on Ray whatever Ray itself writes goes to a log file
(named on standard error), so ``--json`` prints one JSON document and nothing else.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import sys
from pathlib import Path

from petriflow.errors import PetriflowError

__all__ = ["add_parser", "cmd_sweep", "add_reproduce_parser", "cmd_reproduce"]


def add_parser(sub) -> argparse.ArgumentParser:
    """Add the ``sweep`` command to the ``petriflow`` subcommands ``sub``."""
    from petriflow.limits import integer_argument, number_argument
    from petriflow.sweep.backends import BACKENDS, RETRIES

    sweep = sub.add_parser(
        "sweep", help="Run an experiment: a net over a grid of parameters and seeds, measured.",
        description="Run every trial (a row's parameters and a seed) of a sweep file, record one row per"
        " trial in SQLite (--db) and print each metric's mean ± sd per row beside the paper's value."
        " See docs/sweep-format.md. Exit 0 when every trial ran, 1 when some failed, 2 on bad input.")
    sweep.add_argument("spec", help="sweep file (YAML)")
    sweep.add_argument("--backend", choices=BACKENDS, default="local",
                       help="local worker processes (default) or a Ray cluster")
    sweep.add_argument("--workers", type=integer_argument, help="processes (local; default: every CPU) or"
                       " trials in flight at most (ray; default: the cluster's CPUs, as nodes come and go)")
    sweep.add_argument("--trials", type=integer_argument,
                       help="run seeds 1..K (overrides the file's trials or seeds)")
    sweep.add_argument("--db", help="SQLite results database (new file; or the one to --resume)")
    sweep.add_argument("--resume", action="store_true", help="run only the trials --db lacks, and again those"
                       " recorded crashed (their process or node died)")
    sweep.add_argument("--ray-address", help="Ray cluster address: HOST:6379 on a node of the cluster, or"
                       " ray://HOST:10001 with ray[client] (default: RAY_ADDRESS, else a local instance)")
    sweep.add_argument("--retries", type=integer_argument, default=RETRIES, metavar="N",
                       help=f"ray: times a trial is tried again after its node or worker died (default {RETRIES})")
    sweep.add_argument("--ray-pip", action="append", metavar="REQUIREMENT",
                       help="ray: a package more for nodes that get petriflow's dependencies by pip (your action"
                       " modules' imports); repeat for more")
    sweep.add_argument("--json", action="store_true", help="print the report as JSON")
    sweep.add_argument("--csv", metavar="OUT", help="write the report as CSV")
    sweep.add_argument("--plot", metavar="OUT.png", help="plot each metric against the first parameter")
    sweep.add_argument("--metrics", metavar="NAMES", help="report only these metrics (comma-separated)")
    sweep.add_argument("--quiet", action="store_true", help="no progress on standard error")
    sweep.add_argument("--progress-every", type=number_argument, default=30.0, metavar="S",
                       help="off a terminal: a progress line every S wall seconds (default 30)")
    sweep.set_defaults(handler=cmd_sweep)
    return sweep


def cmd_sweep(args: argparse.Namespace) -> int:
    from petriflow.sweep import load_sweep, run_sweep
    from petriflow.sweep.report import plot, status_counts, status_notes, text_table, write_csv

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
    from petriflow.runtime.outputs import check_outputs

    if _job_working_dir() is not None:
        for flag, value in (("--db", args.db), ("--csv", args.csv), ("--plot", args.plot)):
            if value is not None and not Path(value).is_absolute():
                raise PetriflowError(f"{flag} {value}: under `ray job submit --working-dir` a relative path"
                                     " lands in Ray's temporary copy of the working directory, which Ray may"
                                     f" remove; give an absolute path on the head node ({flag} /data/"
                                     f"{Path(value).name})")
    check_outputs({"--db": args.db, "--csv": args.csv, "--plot": args.plot},
                   [Path(sweep.path)] + ([Path(sweep.run)] if sweep.run else []))
    if not args.progress_every > 0:
        raise PetriflowError(f"--progress-every must be a number of seconds > 0, got {args.progress_every}")
    progress = None if args.quiet else ("bar" if sys.stderr.isatty() else args.progress_every)
    if args.retries < 0:
        raise PetriflowError(f"--retries must be 0 or more, got {args.retries}")
    # while trials run, whatever else writes to standard output (a trial's prints) goes
    # to standard error, and on Ray, whatever Ray writes to either to a log file: the
    # report alone is on standard output, petriflow's own lines on standard error
    with (_ray_output() if args.backend == "ray" else _stdout_to_stderr()):
        result = run_sweep(sweep, backend=args.backend, workers=args.workers, db=args.db, resume=args.resume,
                           progress=progress, ray_address=args.ray_address, retries=args.retries,
                           ray_pip=args.ray_pip)
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
        notes = status_notes(result.rows, result.names, parameters)
        if notes:
            counts = status_counts([{**r, "paper": {k: v for k, v in r["paper"].items() if k in result.names}}
                                    for r in result.rows])
            print("  published values: " + ", ".join(f"{n} {k.replace('-', ' ')}" for k, n in counts.items() if n))
            for note in notes:
                print(f"  {note}")
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


#: ``petriflow reproduce``'s options: (flags, argparse keywords).
_REPRODUCE_OPTIONS = (
    (("root",), {"nargs": "?", "default": "nets", "help": "the folder of scenarios (default: nets)"}),
    (("--quick",), {"action": "store_true", "help": "one trial a row (a quick pass)"}),
    (("--only",), {"metavar": "NAMES", "help": "only these scenarios (comma-separated folder names)"}),
    (("--out",), {"help": "results databases and pages (default: out/reproduction, or out/reproduction-quick"
                          " with --quick)"}),
    (("--report",), {"metavar": "FILE.md", "help": "the report (default: docs/reproduction.md; with --quick or"
                                                    " --only, OUT/reproduction.md)"}),
    (("--no-pages",), {"action": "store_true", "help": "write no sweep pages"}),
    (("--list",), {"action": "store_true", "help": "run nothing: list every published value and its status"}),
    (("--commit",), {"help": "the commit to name in the report (scripts/reproduce.sh passes it)"}),
)


def add_reproduce_parser(sub) -> argparse.ArgumentParser:
    """Add the ``reproduce`` command to the ``petriflow`` subcommands ``sub``."""
    from petriflow.limits import integer_argument

    summary = ("Run every sweep file with paper: values under ROOT/*/experiments/ (each scenario's published"
               " tables), keep each one's results database and page under --out, and write the report"
               " (Markdown): every published value beside the measured mean ± sd, its status (predicted, built"
               " in, missed) and the deviation. Exit 0 when every trial ran, 1 when some failed, 2 on bad input.")
    command = sub.add_parser("reproduce", description=summary,
                             help="Run every published table of the scenarios and write the reproduction report.")
    for flags, keywords in _REPRODUCE_OPTIONS:
        command.add_argument(*flags, **keywords)
    command.add_argument("--workers", type=integer_argument, help="processes (default: every CPU)")
    command.set_defaults(handler=cmd_reproduce)
    return command


def cmd_reproduce(args: argparse.Namespace) -> int:
    from petriflow.io.files import write_atomic
    from petriflow.sweep.reproduce import markdown, reproduce

    if args.workers is not None and args.workers < 1:
        raise PetriflowError(f"--workers must be at least 1, got {args.workers}")
    root = Path(args.root)
    if not root.is_dir():
        raise PetriflowError(f"{root}: no such folder of scenarios")
    out = Path(args.out or ("out/reproduction-quick" if args.quick else "out/reproduction"))
    only = [n.strip() for n in args.only.split(",") if n.strip()] if args.only else None
    report = Path(args.report) if args.report else (out / "reproduction.md" if args.quick or only
                                                     else Path("docs/reproduction.md"))
    if report.suffix.lower() != ".md":
        raise PetriflowError(f"--report writes Markdown: name a .md file, not {str(report)!r}")
    if args.list and not args.report:
        report = out / "published.md"
    outcome = reproduce(root, out, quick=args.quick, only=only, workers=args.workers,
                        pages=not (args.no_pages or args.list), measure=not args.list,
                        progress=lambda line: print(line, file=sys.stderr, flush=True))
    words = ["petriflow reproduce", *(["--quick"] if args.quick else []), *([f"--only {args.only}"] if only else []),
             *(["--list"] if args.list else [])]
    try:
        report.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(report, markdown(outcome, root, commit=args.commit, command=" ".join(words)))
    except OSError as exc:
        raise PetriflowError(f"{report}: cannot write the report ({exc.strerror or exc})") from None
    failed = sum(t.failed for s in outcome.scenarios for t in s.tables)
    print(f"wrote {report} ({sum(len(s.tables) for s in outcome.scenarios)} tables,"
          f" {failed} failed trials, {outcome.wall / 60:.1f} min)")
    return 1 if failed else 0


def _job_working_dir() -> str | None:
    """The working directory (a package URI) of the Ray job this process is the
    entrypoint of (``ray job submit --working-dir``: the current folder is then Ray's
    unpacked copy of it), else ``None``."""
    text = os.environ.get("RAY_JOB_CONFIG_JSON_ENV_VAR")
    try:
        runtime_env = json.loads(text).get("runtime_env") if text else None
    except (ValueError, AttributeError):
        return None
    return (runtime_env.get("working_dir") or None) if isinstance(runtime_env, dict) else None


@contextlib.contextmanager
def _stdout_to_stderr():
    """Point file descriptor 1 at standard error for the block (threads and child
    processes included), then back."""
    sys.stdout.flush()
    try:
        saved = os.dup(1)
    except OSError:  # no standard output at all
        yield
        return
    try:
        os.dup2(2, 1)
        yield
    finally:
        try:
            sys.stdout.flush()
        except (OSError, ValueError):
            pass
        os.dup2(saved, 1)
        os.close(saved)


@contextlib.contextmanager
def _ray_output():
    """Point file descriptors 1 and 2 at a log file for the block (Ray's threads and
    its C++ core write there), with ``sys.stderr`` still the real standard error;
    name the log on standard error when Ray wrote anything."""
    import tempfile

    sys.stdout.flush()
    sys.stderr.flush()
    try:
        saved_out, saved_err = os.dup(1), os.dup(2)
    except OSError:
        yield
        return
    log_fd, log_path = tempfile.mkstemp(prefix="petriflow-sweep-ray-", suffix=".log")
    real_stderr = sys.stderr
    sys.stderr = os.fdopen(os.dup(saved_err), "w", buffering=1, encoding=real_stderr.encoding or "utf-8",
                           errors="backslashreplace")
    finished = False
    try:
        os.dup2(log_fd, 1)
        os.dup2(log_fd, 2)
        yield
        finished = True
    finally:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        ours, sys.stderr = sys.stderr, real_stderr
        ours.close()
        os.dup2(saved_out, 1)
        os.dup2(saved_err, 2)
        os.close(saved_out)
        os.close(saved_err)
        os.close(log_fd)
        if finished and os.path.getsize(log_path):
            print(f"ray: its own messages are in {log_path}", file=sys.stderr)
        else:  # nothing, or a failure whose error line says what matters
            os.unlink(log_path)


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}{'' if n == 1 else 's'}"
