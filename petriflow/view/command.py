"""``petriflow view``: write the HTML page of a run's trace or of a sweep's results."""

from __future__ import annotations

import argparse
from pathlib import Path

from petriflow.limits import number_argument

__all__ = ["add_parser", "cmd_view", "DEFAULT_POSES"]

#: Simulated seconds between pose samples when ``petriflow run --view`` records them
#: and ``--poses`` does not say.
DEFAULT_POSES = 1.0


def add_parser(sub) -> argparse.ArgumentParser:
    view = sub.add_parser(
        "view", help="Write one self-contained HTML page of a run's trace or of a sweep's results.",
        description="Write one self-contained HTML page (no server, no network: it opens from disk) of a"
        " run's trace (.jsonl from petriflow run --trace): the net with its marking at the event a slider"
        " chooses, the world from above, the messages, every event, each agent's firings; or of a sweep's"
        " results database (.db from petriflow sweep --db): the table beside the paper's values and each"
        " metric against the first parameter with error bars. See docs/viewer.md.")
    view.add_argument("source", help="a trace (.jsonl) or a sweep's results database (.db)")
    view.add_argument("--net", help="the net the trace was recorded on (draws it)")
    view.add_argument("--sweep", help="a results database's sweep file (default: the one it names)")
    view.add_argument("-o", "--out", help="the page to write (default: SOURCE with the ending .html)")
    view.add_argument("--max-mb", type=number_argument, metavar="MB",
                      help="the most a run's page should weigh (default 20): past it, bulky event data the page"
                      " does not replay (token data in inputs and result) is left out, with the trace line")
    view.set_defaults(handler=cmd_view)
    return view


def cmd_view(args: argparse.Namespace) -> int:
    from petriflow.view import view

    import sys

    from petriflow.view import SWEEP_SUFFIXES

    page = view(args.source, net=args.net, out=args.out, sweep=args.sweep, max_mb=args.max_mb)
    if args.net is None and Path(args.source).suffix.lower() not in SWEEP_SUFFIXES:
        print(f"petriflow: note: {args.source}: no --net given, so the page shows the marking as a table of"
              " places instead of drawing the net (--net NET draws it)", file=sys.stderr)
    print(f"wrote {page} ({Path(page).stat().st_size / 1e6:.2f} MB)")
    return 0


def add_run_options(run: argparse.ArgumentParser) -> None:
    """``petriflow run``'s ``--view`` and ``--poses``."""
    run.add_argument("--view", metavar="OUT.html",
                     help="write the run's page at the end (as petriflow view does; records poses every"
                     f" {DEFAULT_POSES:g} s unless --poses says)")
    run.add_argument("--poses", type=number_argument, metavar="S",
                     help="record the world's body poses as trace events every S simulated seconds")


def run_view_start(args: argparse.Namespace) -> Path | None:
    """Before ``petriflow run`` with ``--view``: check the page's name, and give the run a
    trace to write (a temporary one beside the page when ``--trace`` names none) and
    pose sampling (``--poses``, else :data:`DEFAULT_POSES`). Returns the temporary
    trace, if one was made up."""
    from petriflow.errors import PetriflowError

    page = getattr(args, "view", None)
    if page is None:
        return None
    if Path(page).suffix.lower() not in (".html", ".htm"):
        raise PetriflowError(f"--view {page}: the page is HTML; name it .html")
    if args.poses is None and not args.resume:
        args.poses = DEFAULT_POSES
    if args.trace is not None:
        return None
    # in a folder of its own outside the page's, so that a kill leaves nothing beside the page
    import tempfile

    temporary = Path(tempfile.mkdtemp(prefix="petriflow-view-")) / "run.jsonl"
    args.trace = str(temporary)
    return temporary


def run_view_finish(args: argparse.Namespace, outcome, temporary: Path | None) -> None:
    """After ``petriflow run`` with ``--view``: write the page from the run's trace (the
    net drawn when the run was of a net file), and drop a made-up trace."""
    page = getattr(args, "view", None)
    if page is None:
        return
    from petriflow.view import view

    try:
        view(args.trace, net=args.net, out=page, trace_name=None if temporary is not None else "")
    finally:
        if temporary is not None:
            import shutil

            shutil.rmtree(temporary.parent, ignore_errors=True)
            if str(temporary) in outcome.written:
                outcome.written.remove(str(temporary))
    outcome.written.append(str(page))
