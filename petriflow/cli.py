"""The ``petriflow`` command line.

Exit codes: 0 ok, 1 a check found a problem (e.g. a transition is not enabled),
2 bad input (unreadable net, unknown transition, malformed marking, bad option).
Errors are one line on standard error, location first; no traceback.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import sys
import warnings
from typing import Any, Sequence

from petriflow import limits
from petriflow.engine import Simulation, fire
from petriflow.errors import NotEnabledError, PetriflowError
from petriflow.io import load_net
from petriflow.marking import Marking, parse_marking
from petriflow.net import Net
from petriflow.workflow import sink_places, source_places

__all__ = ["main", "build_parser"]

EXIT_OK, EXIT_PROBLEM, EXIT_BAD_INPUT = 0, 1, 2


class _Parser(argparse.ArgumentParser):
    """argparse with the one-line error style of the rest of the tool."""

    def error(self, message: str) -> None:  # type: ignore[override]
        # a value of thousands of characters is shown by its start, on one line
        message = re.sub(r"'([^']{60})[^']{20,}'", r"'\1...'", " ".join(message.split()))
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message}\n")


def _one_line_warning(message, category, filename, lineno, file=None, line=None) -> None:
    print(f"warning: {message}", file=sys.stderr)


def _stdout_gone() -> bool:
    """Whether standard output is a pipe whose reader has closed it."""
    try:
        import select

        poller = select.poll()
        poller.register(sys.stdout.fileno(), select.POLLOUT)
        return any(events & (select.POLLERR | select.POLLHUP) for _, events in poller.poll(0))
    except (AttributeError, OSError, ValueError):  # no poll (Windows), or no real file
        return True


def _start_marking(net: Net, text: str | None) -> Marking:
    if text is None:
        return net.initial_marking
    try:
        return parse_marking(text, net.places)
    except PetriflowError as exc:
        raise PetriflowError(f"--marking: {exc}") from None


def _print_json(data: Any) -> None:
    json.dump(data, sys.stdout, indent=2)
    sys.stdout.write("\n")


def _format_marking(marking: Marking) -> str:
    if not marking:
        return "(empty)"
    return ", ".join(f"{p}={c}" for p, c in marking.items())


# Commands ----------------------------------------------------------------------------


def _load_bound(path: str, import_actions: bool = False, config: str | None = None) -> tuple[Net, list[str], Any]:
    """Load a net as a run would: its run configuration found, every action, parameter,
    port and guard bound (``file:line`` errors with close matches, before anything else
    happens). The configuration's action modules (user code) are imported only when
    ``import_actions``; otherwise what they declare is read from their source and checked
    the same way, and the notes returned (also printed to standard error) list what
    their source cannot tell, each with the reason (docs/security.md). ``config``: this
    run configuration instead of the one the net names. Returns the net, the notes and
    the run configuration."""
    from pathlib import Path

    from petriflow.runtime.session import prepare

    prepared = prepare(path, import_actions=import_actions, config=config)
    config = prepared.config
    if not prepared.binding.unchecked:
        return prepared.net, [], config
    modules = [repr(Path(m).name if Path(m).is_absolute() else m) for m in config.unimported_actions()]
    where = config.path or path
    line = config.lines.get("actions") if config.path else prepared.net.lines.get("run")
    named = (f"module{'s' if len(modules) > 1 else ''} {', '.join(modules)} named in {where}"
             f"{f':{line}' if line else ''} {'are' if len(modules) > 1 else 'is'} not imported")
    notes = []
    for item in prepared.binding.unchecked:
        at = f"{path}:{item.line}" if item.line else path
        notes.append(f"{at}: {item.transition!r}: {item.describe()} ({named}; --import-actions to check)")
    for note in notes:
        print(f"petriflow: note: {note}", file=sys.stderr)
    return prepared.net, notes, config


def _remote(net: Net, config: Any) -> tuple[dict[str, Any] | None, dict[str, str], dict[str, str]]:
    """What a run configuration's ``bridge:`` puts on remote agents: ``{transport, connect,
    agents: {remote agent: {subnets, transitions}}}`` (``None``: no bridge),
    ``{subnet id: remote agent}`` and ``{transition: remote agent}``."""
    spec = getattr(config, "bridge", None)
    if spec is None:
        return None, {}, {}
    from petriflow.bridge.remote import bridged_subnets, remote_transitions

    subnets = bridged_subnets(net, spec)
    agents: dict[str, dict[str, list[str]]] = {}
    for subnet in net.subnets:  # in the net's order
        if subnet in subnets:
            agents.setdefault(subnets[subnet], {"subnets": [], "transitions": []})["subnets"].append(subnet)
    on = remote_transitions(net, spec)
    for tid, name in on.items():
        agents.setdefault(name, {"subnets": [], "transitions": []})["transitions"].append(tid)
    return ({"transport": spec.transport, "connect": spec.connect, "agents": dict(sorted(agents.items()))},
            subnets, on)


def cmd_info(args: argparse.Namespace) -> int:
    net, notes, config = _load_bound(args.net, args.import_actions, args.config)
    remote, remote_subnets, on = _remote(net, config)
    info = {
        "net": net.id,
        "label": net.label,
        "places": len(net.places),
        "transitions": len(net.transitions),
        "arcs": len(net.arcs),
        "initial_marking": net.initial_marking.to_dict(),
        "final_marking": None if net.final_marking is None else net.final_marking.to_dict(),
        "source_places": source_places(net),
        "sink_places": sink_places(net),
        "subnets": {
            s.id: {
                "label": s.label,
                "agent": s.agent or s.id,
                "places": net.nodes_of(s.id)[0],
                "transitions": net.nodes_of(s.id)[1],
                "remote_agent": remote_subnets.get(s.id),
            }
            for s in net.subnets.values()
        },
        "actions": net.actions(),
        "remote": remote,
        "not_checked": notes,
    }
    if args.json:
        _print_json(info)
        return EXIT_OK
    title = f"{net.id}" + (f" — {net.label}" if net.label else "")
    print(title)
    print(f"  {info['places']} places, {info['transitions']} transitions, {info['arcs']} arcs")
    print(f"  initial marking: {_format_marking(net.initial_marking)}")
    if net.final_marking is not None:
        print(f"  final marking:   {_format_marking(net.final_marking)}")
    print(f"  source places: {', '.join(info['source_places']) or '-'}")
    print(f"  sink places:   {', '.join(info['sink_places']) or '-'}")
    if net.subnets:
        print("  subnets:")
        for sid, sub in info["subnets"].items():
            label = f" ({sub['label']})" if sub["label"] else ""
            where = f", on remote agent {sub['remote_agent']}" if sub["remote_agent"] else ""
            print(f"    {sid}{label}: agent {sub['agent']}, {len(sub['places'])} places,"
                  f" {len(sub['transitions'])} transitions{where}")
    if info["actions"]:
        print("  bound actions:")
        for tid, action in info["actions"].items():
            params = net.transitions[tid].params
            shown = f" {json.dumps(params, sort_keys=True)}" if params else ""
            print(f"    {tid}: {action}{shown}{f' (on {on[tid]})' if tid in on else ''}")
    else:
        print("  bound actions: none")
    if remote is not None:
        print(f"  remote agents (bridge: {remote['transport']} {remote['connect']}):")
        for name, where in remote["agents"].items():
            print(f"    {name}: subnets {', '.join(where['subnets']) or '-'};"
                  f" transitions {', '.join(where['transitions']) or '-'}")
    return EXIT_OK


def cmd_simulate(args: argparse.Namespace) -> int:
    net = load_net(args.net)
    if not 0 <= args.steps <= limits.SIMULATE_STEPS:
        raise PetriflowError(f"--steps must be from 0 to {limits.SIMULATE_STEPS:,} (raise the limit with"
                             f" PETRIFLOW_LIMITS=SIMULATE_STEPS=N), got {args.steps}")
    sim = Simulation(net, _start_marking(net, args.marking), seed=args.seed)
    fired = sim.run(until=args.steps)
    result = {
        "net": net.id,
        "seed": args.seed,
        "steps": len(fired),
        "fired": fired,
        "deadlock": sim.is_dead,
        "marking": sim.marking.to_dict(),
    }
    if args.json:
        _print_json(result)
        return EXIT_OK
    for number, transition in enumerate(fired, start=1):
        print(f"{number:>6}  {transition}")
    ending = " (deadlock: no transition enabled)" if sim.is_dead else ""
    print(f"fired {len(fired)} transitions{ending}")
    print(f"marking at the end: {_format_marking(sim.marking)}")
    return EXIT_OK


def cmd_fire(args: argparse.Namespace) -> int:
    net = load_net(args.net)
    marking = _start_marking(net, args.marking)
    for transition in args.transitions:
        if transition not in net.transitions:  # bad input, checked before anything fires
            try:
                net.transition(transition)
            except PetriflowError as exc:
                raise PetriflowError(f"{args.net}: {exc}") from None
    steps = []
    for number, transition in enumerate(args.transitions, start=1):
        try:
            marking = fire(net, marking, transition)
        except NotEnabledError as exc:
            if args.json:
                _print_json({"net": net.id, "fired": steps, "marking": marking.to_dict(),
                             "error": str(exc), "failed_step": number})
            print(f"petriflow: {args.net}: step {number}: {exc}", file=sys.stderr)
            return EXIT_PROBLEM
        steps.append({"transition": transition, "marking": marking.to_dict()})
        if not args.json:
            print(f"{transition:>20} -> {_format_marking(marking)}")
    if args.json:
        _print_json({"net": net.id, "fired": steps, "marking": marking.to_dict()})
    return EXIT_OK


def _size(text: str | None) -> tuple[float, float] | None:
    if text is None:
        return None
    try:
        width, height = (float(v) for v in text.lower().replace("x", ",").split(","))
    except ValueError:
        raise PetriflowError(f"--size is WIDTH,HEIGHT in inches, e.g. 12,9; got {text!r}") from None
    if not (0 < width < 1000 and 0 < height < 1000):
        raise PetriflowError(f"--size must be between 0 and 1000 inches each way, got {text!r}")
    return width, height


def _property_violations(net) -> list[dict[str, Any]]:
    """The net's own properties that fail, as violations with their witness sequence (a
    lasso's cycle is left out: the drawing shows where it starts)."""
    if not net.properties:
        return []
    from petriflow.engine import fire_sequence
    from petriflow.properties.check import check_properties

    found = []
    for result in check_properties(net, net.properties):
        if result["verdict"] is False and result.get("witness") is not None:
            reached = fire_sequence(net, net.initial_marking, result["witness"])
            found.append({"transitions": result["witness"], "marking": reached.to_dict(),
                          "message": f"property {result['id']} fails: {result['formula']}"})
    return [v for v in found if v["transitions"]]


def cmd_export(args: argparse.Namespace) -> int:
    from petriflow.export import export_net, format_of

    to_stdout = args.output == "-"  # the file's bytes on standard output, as Graphviz's -o- does
    if to_stdout and args.format is None:
        raise PetriflowError("-o -: standard output has no file ending to tell the format by; give -f")
    # a bad format or ending fails before any work
    format = format_of(f"net.{args.format}" if to_stdout else args.output, args.format)
    from petriflow.runtime.outputs import check_outputs

    if not to_stdout:
        check_outputs({"--output": args.output}, [args.net])
    size = _size(args.size)
    net = load_net(args.net)
    marking = _start_marking(net, args.marking)
    highlight = [h for h in (args.highlight or "").split(",") if h] or None
    caption = None
    if args.violation:
        from petriflow.analysis.report import check_net

        violations = _property_violations(net)   # what the net states it guarantees comes first
        violations += [v for v in check_net(net)["violations"] if v.get("transitions")]
        if not violations:
            print(f"petriflow: {args.net}: the analysis found no violation with a witness; nothing drawn",
                  file=sys.stderr)
            return EXIT_OK
        witness = violations[0]
        # outcome variants (t@failed) are drawn on the transition they belong to
        from petriflow.engine import CompiledNet

        compiled = CompiledNet(net)
        origin = {row: t for row, (t, _) in zip(compiled.transitions, compiled.origin)}
        highlight = list(dict.fromkeys(origin.get(t, t) for t in witness["transitions"]))
        highlight += [p for p in (witness.get("marking") or {}) if p in net.places]
        marking = net.check_marking(witness.get("marking") or {})
        caption = (f"red: {witness['message']}, reached by firing {' '.join(witness['transitions'])};"
                   " tokens: the marking it reaches")
        print(witness["message"], file=sys.stderr if to_stdout else sys.stdout)
    options = {"marking": marking, "highlight": highlight, "caption": caption, "rankdir": args.rankdir,
               "size": size, "fold": args.fold}
    if not to_stdout:
        note = export_net(net, args.output, format, **options)
        if note:
            print(f"petriflow: {note}", file=sys.stderr)
        print(f"wrote {args.output}")
        return EXIT_OK
    import tempfile

    with tempfile.TemporaryDirectory(prefix="petriflow-export-") as folder:
        made = os.path.join(folder, f"net.{format}")
        note = export_net(net, made, format, **options)
        if note:
            print(f"petriflow: {note}", file=sys.stderr)
        with open(made, "rb") as data:
            sys.stdout.flush()
            shutil.copyfileobj(data, sys.stdout.buffer)
        sys.stdout.buffer.flush()
    return EXIT_OK


def _progress(args: argparse.Namespace) -> bool | float:
    """What ``run`` shows while it runs: nothing (``--quiet``, ``--json``), else a line on
    a terminal, and off one a line every ``--progress-every`` seconds."""
    if args.quiet or args.json:
        return False
    if not args.progress_every > 0:
        raise PetriflowError(f"--progress-every must be a number of seconds > 0, got {args.progress_every}")
    return float(args.progress_every)


def cmd_run(args: argparse.Namespace) -> int:
    from petriflow.runtime.session import resume, run_files
    from petriflow.view.command import run_view_finish, run_view_start

    if args.resume and args.db is None:
        raise PetriflowError("--resume needs --db RUN_DB (the journal of the run to continue)")
    if args.resume and args.net is not None and not os.path.lexists(args.db):
        # killed before its journal was made: nothing happened yet, so it starts over
        print(f"petriflow: note: {args.db}: no journal (the run was stopped before it began);"
              f" running {args.net} from its beginning", file=sys.stderr)
        args.resume = False
    from petriflow.live.command import live_of

    live = live_of(args)  # --live: the run's page and controls served as it goes
    made_up_trace = run_view_start(args)  # --view: a trace (and poses) for the page
    try:
        if args.resume:
            outcome = resume(args.db, trace=args.trace, xes=args.xes, realtime=args.realtime,
                             gui=args.gui, progress=_progress(args), picture=args.picture, live=live)
        else:
            if args.net is None:
                raise PetriflowError("give the net to run (or --resume --db RUN_DB)")
            if args.until is not None:
                limits.check_seconds(args.until, "--until")
            if args.max_firings is not None and args.max_firings < 0:
                raise PetriflowError(f"--max-firings must be >= 0, got {args.max_firings}")
            outcome = run_files(args.net, world=args.world, config=args.config, seed=args.seed,
                                until=args.until, trace=args.trace, xes=args.xes, db=args.db, poses=args.poses,
                                realtime=args.realtime, gui=args.gui, progress=_progress(args),
                                max_firings=args.max_firings, metrics=_metric_names(args.metrics),
                                picture=args.picture, wait_agents=args.wait_agents,
                                monitor=args.monitor, live=live)
    except BaseException:
        if made_up_trace is not None:  # the page's made-up trace, in a folder of its own
            shutil.rmtree(made_up_trace.parent, ignore_errors=True)
        raise
    run_view_finish(args, outcome, made_up_trace)
    result = outcome.result
    from petriflow.workflow import final_marking_of

    final = final_marking_of(outcome.net)  # declared, else a WF-net's sink: the rule check uses
    problem = result.reason in ("failed", "stalled") or (final is not None and result.reason != "final")
    problem = problem or any(p["verdict"] is False for p in outcome.properties)
    summary = {
        "net": outcome.net.id,
        "reason": result.reason,
        "time": result.time,
        "firings": result.firings,
        "events": result.event_count,
        "wall_seconds": round(outcome.wall, 3),
        "realtime_factor": round(outcome.realtime_factor, 2) if outcome.wall > 0 and result.time > 0 else None,
        "seed": outcome.seed,
        "marking": result.marking.to_dict(),
        "final_marking": None if final is None else final.to_dict(),
        "error": result.error,
        "metrics": outcome.metrics,
        "written": outcome.written,
    }
    if args.monitor:
        summary["properties"] = outcome.properties
    if args.json:
        _print_json(summary)
    else:
        factor = outcome.realtime_factor
        pace = ("no simulated time passed" if result.time <= 0 else
                "too quick to time" if outcome.wall < 0.01 else f"{factor:.1f}x real time")
        print(f"{outcome.net.id}: {result.reason} at t = {result.time:g} s after {result.firings}"
              f" firing{'' if result.firings == 1 else 's'} (seed {outcome.seed}; {outcome.wall:.2f} s wall, {pace})")
        print(f"  marking at the end: {_format_marking(result.marking)}")
        if final is not None and outcome.net.final_marking is None:
            print(f"  final marking: {_format_marking(final)} (the file declares none: the WF-net's sink)")
        if result.error:
            print(f"  error: {result.error}")
        _print_metrics(outcome.metrics)
        _print_monitored(outcome.properties)
        for path in outcome.written:
            print(f"  wrote {path}")
    return EXIT_PROBLEM if problem else EXIT_OK


def _print_monitored(results: list[dict[str, Any]]) -> None:
    """``run --monitor``: one line per property, a violation with its event."""
    for entry in results:
        verdict = entry["verdict"]
        text = "undecided" if verdict is None else ("holds" if verdict is True else "violated"
                                                     if verdict is False else str(verdict))
        line = f"  property {entry['id']}: {text}"
        where = entry.get("violation")
        if where:
            line += (f" at event {where['seq']} (t = {where['time']:g} s, {where['kind']}"
                     f"{' ' + where['transition'] if where['transition'] else ''})")
        elif entry.get("reason"):
            line += f" ({entry['reason']})"
        print(line)


def _metric_names(given: str | None) -> list[str] | None:
    """``--metrics``: ``None`` (the configuration's), ``[]`` for 'none', else the names."""
    if given is None:
        return None
    names = [n.strip() for n in given.split(",") if n.strip()]
    return [] if names == ["none"] else names


def _print_metrics(metrics: dict) -> None:
    """The run's metrics, one per line, aligned."""
    if not metrics:
        return
    print("  metrics:")
    width = max(len(name) for name in metrics)
    for name, value in metrics.items():
        text = "-" if value is None else f"{value:.6g}" if isinstance(value, float) else str(value)
        print(f"    {name:{width}}  {text}")


def cmd_actions(args: argparse.Namespace) -> int:
    from petriflow.runtime.action import REQUIRED, Port
    from petriflow.runtime.registry import default_registry

    def type_name(param) -> str:
        if isinstance(param, Port):
            return "port (a place it reads)"
        types = param.type if isinstance(param.type, tuple) else (param.type,)
        return " or ".join("none" if t is type(None) else t.__name__ for t in types)

    listing = []
    for spec in default_registry.specs():
        if args.pattern and args.pattern.lower() not in spec.name.lower():
            continue
        cls = spec.load()
        params = {
            name: {"type": type_name(p), "default": None if p.default is REQUIRED else p.default,
                   "required": p.default is REQUIRED, "doc": p.doc}
            for name, p in cls.params.items()
        }
        doc = spec.doc or ((cls.__doc__ or "").strip().splitlines() or [""])[0]
        listing.append({"name": spec.name, "doc": doc, "params": params})
    if args.json:
        _print_json(listing)
        return EXIT_OK
    for entry in listing:
        print(f"{entry['name']:16} {entry['doc']}")
        for name, p in entry["params"].items():
            default = "required" if p["required"] else f"default {p['default']!r}"
            print(f"{'':18}{name}: {p['type']}, {default}" + (f" — {p['doc']}" if p["doc"] else ""))
    return EXIT_OK


def cmd_replay(args: argparse.Namespace) -> int:
    from petriflow.runtime.replay import replay

    return replay(args.trace, net_path=args.net, draw=args.draw, at=args.at)


def cmd_check(args: argparse.Namespace) -> int:
    from petriflow.analysis.coverability import DEFAULT_MAX_COVERABILITY
    from petriflow.analysis.reachability import DEFAULT_MAX_STATES
    from petriflow.analysis.report import check_net, exit_code, format_report, plain

    if args.max_states is not None and args.max_states < 1:
        raise PetriflowError(f"--max-states must be >= 1, got {args.max_states}")
    for option, value in (("--max-coverability", args.max_coverability),
                          ("--invariant-budget", args.invariant_budget)):
        if value is not None and value < 0:
            raise PetriflowError(f"{option} must be >= 0, got {value}")
    net, _, _ = _load_bound(args.net, args.import_actions)
    if args.properties is not None:
        return _check_properties(args, net)
    result = check_net(
        net, max_states=args.max_states or DEFAULT_MAX_STATES,
        max_coverability=DEFAULT_MAX_COVERABILITY if args.max_coverability is None else args.max_coverability,
        invariant_budget=args.invariant_budget, method=args.method)
    if args.json:
        _print_json(plain(result))
    else:
        print(format_report(result))
    code = exit_code(result)
    if not result["complete"] and code == 2:
        # no verdict: the limit is the answer; a verdict reached anyway (a deadlock found,
        # soundness decided by another method) is an answer, the limit a note in the report
        print(f"petriflow: {args.net}: {result['error']}", file=sys.stderr)
    return code


def _check_properties(args: argparse.Namespace, net) -> int:
    """``check --properties [FILE]``: the file's properties, or the net's own."""
    from petriflow.analysis.reachability import DEFAULT_MAX_STATES
    from petriflow.properties.check import check_properties
    from petriflow.properties.report import format_properties, properties_exit_code
    from petriflow.properties.yaml_props import load_properties

    if args.properties:
        properties = load_properties(args.properties)
    else:
        properties = net.properties
        if not properties:
            raise PetriflowError(f"{args.net}: the net declares no properties (a 'properties:' list);"
                                 " name a properties file: --properties FILE")
    # --method stubborn forces the stubborn-set searches, explicit forbids them
    reduction = {"stubborn": "stubborn", "explicit": "none"}.get(args.method, "auto")
    results = check_properties(net, properties, max_states=args.max_states or DEFAULT_MAX_STATES,
                               reduction=reduction)
    if args.json:
        _print_json({"net": net.id, "properties": results})
    else:
        print(format_properties(results))
    return properties_exit_code(results)


# Parser ------------------------------------------------------------------------------


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``petriflow`` command."""
    from petriflow import __version__

    parser = _Parser(prog="petriflow", description="Workflow Petri nets for multi-robot systems.")
    parser.add_argument("--version", action="version", version=f"petriflow {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    def net_command(name: str, help: str, handler) -> argparse.ArgumentParser:
        command = sub.add_parser(name, help=help, description=help)
        command.add_argument("net", help="net file (.yaml, .yml, .pnml or .xml)")
        command.set_defaults(handler=handler)
        return command

    import_help = ("import the action modules the net's run configuration names (user code) and check"
                   " their actions with it; by default looking at a net never runs its code: their source"
                   " is read instead, and what it cannot tell is listed as not checked")
    info = net_command("info", "Show sizes, subnets and bound actions of a net.", cmd_info)
    info.add_argument("--json", action="store_true", help="print JSON")
    info.add_argument("--import-actions", action="store_true", help=import_help)
    info.add_argument("--config", metavar="RUN.yaml",
                      help="run configuration (default: the one the net names, else run.yaml beside it);"
                           " its bridge: agents are shown as the remote agents of their subnets")

    simulate = net_command("simulate", "Play the random token game.", cmd_simulate)
    simulate.add_argument("--steps", type=limits.integer_argument, default=100,
                          help="firings to make (default 100)")
    simulate.add_argument("--seed", type=limits.integer_argument, default=0, help="random seed (default 0)")
    simulate.add_argument("--marking", help='start marking as JSON, e.g. \'{"p1": 1}\'')
    simulate.add_argument("--json", action="store_true", help="print JSON")

    fire_cmd = net_command("fire", "Fire named transitions in order.", cmd_fire)
    fire_cmd.add_argument("transitions", nargs="+", metavar="T", help="transition ids")
    fire_cmd.add_argument("--marking", help="start marking as JSON (default: initial marking)")
    fire_cmd.add_argument("--json", action="store_true", help="print JSON")

    export = net_command("export", "Convert a net or draw it.", cmd_export)
    export.add_argument("--format", "-f", choices=["pnml", "yaml", "dot", "svg", "png"],
                        help="output format (default: from the output file's ending)")
    export.add_argument("--output", "-o", required=True, help="output file ('-': standard output, with -f)")
    export.add_argument("--rankdir", choices=["LR", "TB", "auto"], default="auto",
                        help="pictures: left to right, top to bottom, or auto (top to bottom when left to"
                        " right would be too wide; the default)")
    export.add_argument("--size", metavar="W,H", help="pictures: at most this size in inches (PNG at 150 dpi)")
    folding = export.add_mutually_exclusive_group()
    folding.add_argument("--fold", dest="fold", action="store_true", default=None,
                         help="pictures: one box per agent subnet, the places between agents as circles"
                              " (the default for team nets of over 150 nodes)")
    folding.add_argument("--full", dest="fold", action="store_false",
                         help="pictures: every node (a net of over 150 nodes is scaled down to fit"
                              " 40 x 40 in, with a note)")
    export.add_argument("--marking", help="marking to draw, as JSON (default: initial)")
    export.add_argument("--highlight", metavar="IDS", help="comma-separated node ids to highlight")
    export.add_argument("--violation", action="store_true",
                        help="analyse the net and draw its first violation: the witness path"
                        " highlighted, with the marking it reaches")

    run = sub.add_parser(
        "run", help="Run a net: fire transitions as agent actions over a pybullet world.",
        description="Run a net: fire transitions as agent actions over a pybullet world. The run"
        " configuration (seed, limits, world, channels, faults, action modules) is --config, else the"
        " one the net names (run: FILE, or inline in the net), else run.yaml beside the net when it"
        " exists. Exit 0 when the run ends, 1 when an action failed without a failure route or the net"
        " stopped short of its final marking, 2 on bad input.")
    run.add_argument("net", nargs="?", help="net file (omit with --resume)")
    run.add_argument("--world", help="world description (YAML); overrides the configuration's")
    run.add_argument("--config", help="run configuration (YAML; default: the one the net names, else run.yaml"
                     " beside it)")
    run.add_argument("--seed", type=limits.integer_argument,
                     help="random seed (overrides the configuration's)")
    run.add_argument("--until", type=limits.number_argument, help="simulated-time limit in seconds")
    run.add_argument("--max-firings", type=limits.integer_argument, help="stop after this many firings")
    run.add_argument("--trace", help="write the events as JSON Lines")
    run.add_argument("--xes", help="write the firings as an XES event log")
    run.add_argument("--db", help="SQLite run journal (new file; or the one to --resume)")
    run.add_argument("--resume", action="store_true",
                     help="continue the killed run journaled in --db (with NET given and no journal there yet:"
                     " start the run from its beginning, saying so)")
    run.add_argument("--realtime", action="store_true", help="pace simulated time to the wall clock")
    run.add_argument("--gui", action="store_true", help="open pybullet's GUI (needs a display)")
    run.add_argument("--wait-agents", type=limits.number_argument, metavar="SECONDS",
                     help="a bridged run: wait this long for its remote agents before binding (default: the"
                     " configuration's bridge: wait)")
    from petriflow.view.command import add_parser as add_view, add_run_options

    add_run_options(run)
    from petriflow.live.command import add_run_options as add_live_options

    add_live_options(run)
    run.add_argument("--json", action="store_true", help="print the summary as JSON")
    run.add_argument("--metrics", metavar="NAMES",
                     help="report these registered metrics at the end (comma-separated; 'none': no metric)"
                          " instead of the ones the run configuration names")
    run.add_argument("--monitor", action="store_true",
                     help="watch the net's properties during the run (docs/analysis.md, 'Properties'):"
                     " safety on every marking, LTL on the finite trace; a violation is reported with its"
                     " event, marked in the trace, and makes the exit code 1")
    run.add_argument("--picture", metavar="OUT.png",
                     help="draw the world's top view with the robots' trajectories (.png, .svg or .pdf)")
    run.add_argument("--quiet", action="store_true", help="no progress on standard error")
    run.add_argument("--progress-every", type=limits.number_argument, default=30.0, metavar="S",
                     help="off a terminal (a log, CI): a progress line every S wall seconds (default 30)")
    run.set_defaults(handler=cmd_run)

    actions = sub.add_parser("actions", help="List the actions transitions can be bound to.",
                             description="List the registered actions and their parameters.")
    actions.add_argument("pattern", nargs="?", help="only the actions whose name contains this (e.g. comm.)")
    actions.add_argument("--json", action="store_true", help="print JSON")
    actions.set_defaults(handler=cmd_actions)

    replay_cmd = sub.add_parser("replay", help="Print (or draw) the token game of a recorded run.",
                                description="Print the token game of a recorded run, or draw the"
                                " marking at one event.")
    replay_cmd.add_argument("trace", help="trace file written by petriflow run --trace")
    replay_cmd.add_argument("--net", help="the net, to draw markings")
    replay_cmd.add_argument("--draw", help="draw the marking (after --at, default: the end) to this"
                            " .svg/.png/.dot file; needs --net")
    replay_cmd.add_argument("--at", type=limits.integer_argument, help="event number to stop at")
    replay_cmd.set_defaults(handler=cmd_replay)
    check = net_command(
        "check", "Analyse a net: WF-net soundness, boundedness, deadlocks, liveness, invariants.",
        cmd_check)
    check.add_argument("--json", action="store_true", help="print JSON")
    check.add_argument("--import-actions", action="store_true", help=import_help)
    check.add_argument("--properties", nargs="?", const="", default=None, metavar="FILE",
                       help="decide properties instead (docs/analysis.md, 'Properties'): those of"
                       " FILE (a YAML 'properties:' list or a Model Checking Contest XML file), or"
                       " without FILE the net's own; exit 1 when one is false, 2 when one is"
                       " undecided")
    check.add_argument("--max-states", type=limits.integer_argument, default=None, metavar="N",
                       help="most markings to explore (default 2,000,000); beyond it the facts"
                       " found so far, and exit 2 (1 when one of them fails)")
    check.add_argument("--max-coverability", type=limits.integer_argument, default=None, metavar="N",
                       help="most nodes of the Karp-Miller search that decides boundedness before"
                       " the state space (default 100,000; 0: none)")
    check.add_argument("--method", choices=("auto", "explicit", "symmetry", "stubborn", "structural"),
                       default="auto", help="how to answer (docs/analysis.md): the full state space"
                       " (explicit), up to permutations of interchangeable agents (symmetry),"
                       " deadlocks by stubborn sets (stubborn; with --properties: EF/AG and LTL"
                       " without X by stubborn sets), soundness of free-choice WF-nets"
                       " by the Rank Theorem (structural); auto (default) picks and reports which")
    check.add_argument("--invariant-budget", type=limits.integer_argument, default=None, metavar="N",
                       help="work budget of each of the P- and T-semiflow computations (0: skip"
                       " them); default 100,000,000 steps (about 0.2 s) for P-semiflows and, for"
                       " T-semiflows, 100 steps per state and edge explored (10,000,000 to"
                       " 100,000,000); beyond it they are 'not computed (over budget)'")
    from petriflow.bridge.command import add_parser as add_bridge
    from petriflow.sweep.command import add_parser as add_sweep, add_reproduce_parser

    add_sweep(sub)
    add_reproduce_parser(sub)
    add_bridge(sub)
    add_view(sub)
    from petriflow.live.command import add_parser as add_ctl

    add_ctl(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    warnings.showwarning = _one_line_warning
    try:
        limits.from_environment()
        return args.handler(args)
    except PetriflowError as exc:
        print("petriflow: " + " ".join(str(exc).split()), file=sys.stderr)  # one line, always
        return EXIT_BAD_INPUT
    except BrokenPipeError as exc:
        if _stdout_gone():  # the reader of our output went away (| head): nothing more to say
            sys.stdout = open(os.devnull, "w")  # so the interpreter's own flush at exit stays quiet
            return EXIT_OK
        print(f"petriflow: {args.command}: a pipe to another process broke: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        return 130
    except MemoryError:
        hint = "lower --max-states" if args.command == "check" else "see docs/limits.md"
        print(f"petriflow: {args.command}: out of memory ({hint})", file=sys.stderr)
        return EXIT_BAD_INPUT
    except RecursionError:
        print("petriflow: input nested too deeply to process", file=sys.stderr)
        return EXIT_BAD_INPUT


if __name__ == "__main__":
    sys.exit(main())
