"""The command line of live runs: ``petriflow run --live``, ``--paused``, and ``petriflow ctl``."""

from __future__ import annotations

import argparse
import json
import sys

__all__ = ["add_run_options", "add_parser", "live_of", "cmd_ctl"]


def add_run_options(run: argparse.ArgumentParser) -> None:
    """``petriflow run``'s ``--live`` and ``--paused``."""
    run.add_argument("--live", metavar="[HOST:]PORT",
                     help="serve the run's live page and controls here (host default 127.0.0.1; port 0: a free"
                          " one); prints the page's URL with the run's secret token")
    run.add_argument("--paused", action="store_true",
                     help="with --live: start paused, waiting for the page or petriflow ctl to go on")


def live_of(args: argparse.Namespace):
    """The run's :class:`~petriflow.runtime.session.Live`, or ``None`` without ``--live``."""
    from petriflow.errors import PetriflowError
    from petriflow.runtime.session import Live

    if args.live is None:
        if args.paused:
            raise PetriflowError("--paused needs --live (someone has to be able to resume the run)")
        return None

    def announce(url: str) -> None:
        print(f"petriflow: live page: {url}", file=sys.stderr, flush=True)

    from petriflow.live.server import parse_address

    parse_address(args.live)  # checked before anything is made
    return Live(args.live, args.paused, announce)


def cmd_ctl(args: argparse.Namespace) -> int:
    from petriflow.live.ctl import command_of, send

    command, arguments = command_of(args.words)
    reply = send(args.url, command, arguments, by=args.by)
    if args.json:
        print(json.dumps(reply, indent=2, sort_keys=True))
    elif command == "status":
        control = reply.get("control") or {}
        state = "ended" if reply.get("stop") else "paused" if control.get("paused") else "running"
        print(f"{state} at t = {reply.get('time', 0):g} s; marking {reply.get('marking')};"
              f" running {[f['t'] for f in reply.get('running') or []]};"
              f" breakpoints {control.get('breakpoints') or []}")
    else:
        print(("" if reply.get("ok") else "refused: ") + str(reply.get("message")))
    if reply.get("status") == 400:
        return 2
    return 0 if reply.get("ok") else 1


def add_parser(sub: argparse._SubParsersAction) -> None:
    from petriflow.live.ctl import USAGE

    ctl = sub.add_parser("ctl", help="Steer a live run (petriflow run --live): pause, step, breakpoints, tokens...",
                         description="Send one command to a live run and print its answer. Commands: " + USAGE +
                         ". Breakpoints: transition NAME | place NAME >= N | lost | failed. Exit 0: applied;"
                         " 1: refused by the run; 2: malformed, or the run cannot be reached.")
    ctl.add_argument("url", help="the live page's URL, with its token, as petriflow run --live printed it")
    ctl.add_argument("words", nargs="+", metavar="COMMAND ...", help=USAGE)
    ctl.add_argument("--by", help="who asks (recorded in the trace; default: your user name)")
    ctl.add_argument("--json", action="store_true", help="print the run's whole reply as JSON")
    ctl.set_defaults(handler=cmd_ctl)
