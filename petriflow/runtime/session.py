"""One run from files to files: read, check, put together, run, record.

A run goes one way, each step taking the previous one's typed value:

1. **read** (:func:`~petriflow.runtime.loading.read_run`): the net file, its run
   configuration and its world file, each read and parsed once (:class:`RunFiles`);
2. **check** (:func:`~petriflow.runtime.validation.check_run`): the net bound to the
   registry, the configuration and the world checked against it, the world's settings
   read, all with ``file:line`` errors (:class:`CheckedRun`);
3. **put together** (:func:`~petriflow.runtime.assembly.open_run`): the world built,
   the :class:`~petriflow.runtime.scheduler.Scheduler` made;
4. **run**, watched by the observers asked for (:mod:`~petriflow.runtime.observers`),
   into one :class:`~petriflow.runtime.result.RunResult`.

:func:`run_files` is ``petriflow run``; :func:`resume` is ``--resume`` (the same steps
from the texts a journal keeps); :func:`run` is the Python API; :func:`prepare` is what
the commands that only look at a net (``info``, ``check``) do: read and bind, no world.

The run configuration is, first found: the one given (``--config``), the one the net
names (``run:`` in YAML, ``<run>`` in PNML's petriflow data: a file beside the net or
the configuration itself), ``run.yaml`` beside the net, or the defaults.

Examples:
    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "net.yaml").write_text('''
    ... petriflow: 1
    ... run: {until: 10}
    ... places: [{id: i, tokens: 1}, o]
    ... transitions: [{id: rest, action: core.wait, params: {seconds: 1.5}, in: [i], out: [o]}]
    ... final: {o: 1}
    ... ''')
    >>> result = run_files(folder / "net.yaml", trace=folder / "run.jsonl")
    >>> result.reason, result.time
    (<StopReason.FINAL: 'final'>, 1.5)
    >>> [e.kind for e in read_trace(folder / "run.jsonl")]
    ['run', 'start', 'end', 'stop']
"""

from __future__ import annotations

import time as wallclock
import warnings
from contextlib import ExitStack
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from petriflow.collector import paused
from petriflow.errors import NetFormatError
from petriflow.net import Net
from petriflow.runtime.assembly import open_run
from petriflow.runtime.binding import Binding, bind
from petriflow.runtime.config import RunConfig, load_config
from petriflow.runtime.control import Control
from petriflow.runtime.journal import Journal
from petriflow.runtime.loading import from_journal, journal_inputs, net_config, read_run, read_world
from petriflow.runtime.observers import Progress, run_observed
from petriflow.runtime.outputs import check_outputs, make_folders
from petriflow.runtime.registry import Registry
from petriflow.runtime.result import RunResult
from petriflow.runtime.stopwatch import Timing
from petriflow.runtime.summary import RunExtras, extras_for
from petriflow.runtime.trace import read_trace
from petriflow.runtime.validation import UNKNOWN, CheckedRun, check_run, validate

__all__ = ["run", "run_files", "resume", "prepare", "Prepared", "RunResult", "RunOutcome", "Progress", "read_trace",
           "net_config"]

#: The name runs' results had when a run's outcome held its result: the same type.
RunOutcome = RunResult


@dataclass
class Prepared:
    """A net read, its run configuration found, its actions bound: ready to look at
    (and, once its world is read and checked, to run).

    Attributes:
        net: the net (the configuration's ``bind:`` applied).
        text: the net file's text (what a journal keeps).
        config: the run configuration.
        binding: the net bound to the registry.
        world: the world file to use, if any (not read).
    """

    net: Net
    text: str
    config: RunConfig
    binding: Binding
    world: Path | None


@paused()  # reading and binding a large net makes no cycles (petriflow.collector)
def prepare(net_path: str | Path, *, config: str | Path | RunConfig | None = None,
            world: str | Path | None = None, registry: Registry | None = None,
            import_actions: bool = True) -> Prepared:
    """Read the net in ``net_path`` once, resolve its run configuration, import the
    configuration's action modules and bind the net (its world file is found, not read).

    Args:
        import_actions: import the action modules the run configuration names (user
            code: what running does). ``False`` is how the commands that only look at a
            net bind it: installed plugins are checked as always; a name only a module
            not imported could provide lands in ``binding.unchecked`` (see
            docs/security.md).

    Raises:
        NetFormatError: a file is missing or malformed, an action, parameter or guard
            does not bind (``file:line``), a module of ``actions`` does not import.
    """
    files = read_run(net_path, config=config, world=world, with_world=False)
    run_config = files.config
    net = run_config.bound(files.net)  # the configuration's bind: over what the file binds
    if import_actions:
        run_config.import_actions()
    pending = [] if import_actions else run_config.unimported_actions()
    try:
        if run_config.bridge is not None:  # remote subnets: checked against their agents when the run connects
            from petriflow.bridge.remote import bind_remote
            from petriflow.runtime.registry import default_registry

            run_config.check(net)  # the subnets it names, at the configuration's line
            binding = bind_remote(net, run_config.bridge, registry or default_registry,
                                  lambda local: bind(local, registry, path=str(files.path), unimported=pending),
                                  str(files.path))
        else:
            binding = bind(net, registry, path=str(files.path), unimported=pending)
    except NetFormatError as exc:
        raise run_config.blame(exc) from None
    run_config.check(net)
    return Prepared(net, files.text, run_config, binding, files.world_path)


@dataclass
class Live:
    """A run served live (``--live``, :mod:`petriflow.live`): where, whether it starts
    paused, and whom to tell the page's address."""

    address: str = "127.0.0.1:0"
    paused: bool = False
    announce: Any = None


def _execute(checked: CheckedRun, inputs: dict[str, Any], *, journal: Journal | None, trace: Path | None,
             xes: Path | None, realtime: bool, gui: bool, progress: bool | float, max_firings: int | None,
             keep_events: bool = False, extras: RunExtras | None = None,
             stopwatch: Timing | None = None, wait_agents: float | None = None,
             live: Live | None = None) -> RunResult:
    """Put the checked run together and run it with its observers (step 3 and 4); a
    configuration with a ``bridge:`` connects to its remote agents first
    (:mod:`petriflow.bridge.orchestrator`; ``wait_agents``: seconds to wait for them);
    ``live``: serve its page and controls (:mod:`petriflow.live`)."""
    extras = extras or RunExtras()
    keep = keep_events or extras.needs_events()
    # a steered run (served live, with breakpoints, or resumed from a steered journal)
    # has a control queue; a resumed one applies the journaled interventions again
    script = journal.controls() if journal is not None and journal.journaled else []
    control = None
    if live is not None or checked.config.breakpoints or script:
        control = Control(breakpoints=checked.config.breakpoints, paused=live is not None and live.paused,
                          interactive=live is not None, script=script)
    server = None
    if live is not None:
        from petriflow.live.page import LivePage
        from petriflow.live.server import LiveServer, parse_address

        host, port = parse_address(live.address)
        server = LiveServer(control, LivePage(checked.net), host, port)  # drawn when a page asks
        url = server.start()
        if live.announce is not None:
            live.announce(url)
    try:
        return _observed(checked, inputs, journal=journal, trace=trace, xes=xes, realtime=realtime, gui=gui,
                         progress=progress, max_firings=max_firings, keep_events=keep_events, extras=extras,
                         keep=keep, control=control, server=server, stopwatch=stopwatch, wait_agents=wait_agents)
    finally:
        if server is not None:
            server.stop()


def _observed(checked: CheckedRun, inputs: dict[str, Any], *, journal: Journal | None, trace: Path | None,
              xes: Path | None, realtime: bool, gui: bool, progress: bool | float, max_firings: int | None,
              keep_events: bool, extras: RunExtras, keep: bool, control: Control | None, server: Any,
              stopwatch: Timing | None, wait_agents: float | None) -> RunResult:
    with ExitStack() as stack:
        remote, clock, watch = None, None, None
        spec = checked.config.bridge
        if spec is not None:  # remote agents: connected and checked first, then in wall-clock time
            from petriflow.bridge.orchestrator import connect_run

            remote, clock, watch = connect_run(stack, checked, run=inputs.get("bridge_run"), wait=wait_agents,
                                               journal=journal)
        scheduler = stack.enter_context(open_run(checked, seed=inputs["seed"], gui=gui, realtime=realtime,
                                                 clock=clock, remote=remote, stopwatch=stopwatch,
                                                 control=control))
        if remote is not None:
            scheduler.on_instant(watch)
        if server is not None:
            server.watch(scheduler)
        if inputs.get("poses"):  # the world's body poses as trace events (petriflow.runtime.poses)
            from petriflow.runtime.poses import PoseSampler

            scheduler.on_instant(PoseSampler(inputs["poses"]))
        extras.watch(scheduler)
        cpu = wallclock.process_time()
        result = run_observed(scheduler, journal=journal, trace=trace, xes=xes, progress=progress,
                              keep_events=keep, kinds=None if keep_events else extras.event_kinds(),
                              until=inputs["until"], max_firings=max_firings)
        result.cpu = wallclock.process_time() - cpu
        extras.finish(scheduler, result, checked.config)
        if remote is not None:  # what the bridge dropped, by reason (docs/bridge.md)
            dropped = getattr(remote, "dispatcher", remote).dropped
            result.metrics["bridge.dropped"] = sum(dropped.values())
            result.metrics.update({f"bridge.dropped.{why}": count for why, count in sorted(dropped.items())})
    if not keep_events:
        result.events = []
    if journal is not None:
        journal.finish()
        result.written.append(str(journal.path))
    return result


def _warn_unbound(net: Net, path: Path) -> None:
    """Warn when no transition of ``net`` is bound to an action (a net from another tool,
    say): each then fires the moment it is enabled, and the run is only a token game."""
    transitions = list(net.transitions.values())
    if not transitions or any(t.action for t in transitions):
        return
    names = [t.id if not t.label or t.label == t.id else f"{t.label} ({t.id})" for t in transitions]
    shown = ", ".join(names[:6]) + (f" and {len(names) - 6} more" if len(names) > 6 else "")
    warnings.warn(f"{path}: no transition is bound to an action, so each fires at once when enabled (a token"
                  f" game): {shown}; bind them in a run configuration's 'bind:' (docs/runtime.md,"
                  " \"Binding a net from another tool\")", stacklevel=3)


def _pose_interval(every: Any) -> float:
    """``poses``: simulated seconds between pose samples, checked (> 0)."""
    from petriflow import limits
    from petriflow.errors import PetriflowError

    seconds = limits.check_seconds(every, "--poses")
    if seconds <= 0:
        raise PetriflowError(f"--poses must be a number of seconds > 0, got {every!r}")
    return seconds


def run_files(net_path: str | Path, *, world: str | Path | None = None, config: str | Path | None = None,
              seed: int | None = None, until: float | None = None, trace: str | Path | None = None,
              xes: str | Path | None = None, db: str | Path | None = None, realtime: bool = False,
              gui: bool = False, registry: Registry | None = None, progress: bool | float = False,
              max_firings: int | None = None, keep_events: bool = False, metrics: list[str] | None = None,
              picture: str | Path | None = None, poses: float | None = None,
              stopwatch: Timing | None = None, wait_agents: float | None = None,
              monitor: bool = False, live: Live | None = None) -> RunResult:
    """Run the net in ``net_path`` (what ``petriflow run`` does).

    The run configuration is ``config``, else the one the net names, else
    ``run.yaml`` beside the net; ``world``, ``seed`` and ``until`` override what the
    configuration says. ``progress``: ``True`` shows a live line on a terminal; a
    number of seconds also prints a line that often off a terminal (a log, CI).
    ``result.metrics`` holds the metrics the configuration names (``metrics``: these
    registered metrics instead); ``picture`` draws the world's top view with the
    robots' trajectories at the end (see :mod:`petriflow.runtime.summary`). ``poses``:
    record the world's body poses as ``pose`` events every so many simulated seconds
    (:mod:`petriflow.runtime.poses`; what ``petriflow view`` draws the world from).
    ``live``: serve the run's live page and controls (:class:`Live`, :mod:`petriflow.live`).
    ``stopwatch``: where the run's wall-clock time goes, by category (the world's
    steps as ``physics``, what the actions measure: :mod:`petriflow.runtime.stopwatch`).
    ``wait_agents``: seconds to wait for a bridged run's remote agents (default: the
    configuration's ``bridge: wait``).
    ``monitor``: watch the net's properties during the run
    (:mod:`petriflow.properties.monitor`) into ``result.properties``; a violation is
    also a ``custom`` event ``property_violated`` in the trace.

    Raises:
        NetFormatError: a file is missing or malformed, an action is unknown...
        JournalError: ``db`` already exists.
    """
    net_path = Path(net_path)
    files = read_run(net_path, config=config, world=world)
    checked = check_run(files, registry=registry)
    _warn_unbound(checked.net, net_path)
    inputs = journal_inputs(files, seed=seed, until=until)
    inputs["max_firings"] = max_firings
    if files.config.bridge is not None:  # the run's name in its goal ids: a resume re-attaches by it
        from petriflow.bridge.orchestrator import new_run_name

        inputs["bridge_run"] = new_run_name()
    if poses is not None:  # journaled, so a resumed run samples them too
        inputs["poses"] = _pose_interval(poses)
    inputs["outputs"] = {name: None if path is None else str(Path(path).resolve())
                         for name, path in (("trace", trace), ("xes", xes))}
    extras = extras_for(files.config, metrics=metrics, picture=picture, registry=checked.binding.registry)
    if monitor:
        from petriflow.properties.monitor import PropertyMonitor

        if not checked.net.properties:
            raise NetFormatError("--monitor watches the net's properties, and it declares none (a"
                                 " 'properties:' list)", path=str(net_path))
        extras.monitor = PropertyMonitor(checked.net, checked.net.properties)
    if picture is not None and files.world is None:
        raise NetFormatError("--picture draws the run's world, and this run has none (give --world, or a run"
                             " configuration with world:)", path=str(net_path))
    # everything is checked before the first file is made (a journal must never hold a
    # run that cannot start)
    check_outputs({"--trace": trace, "--xes": xes, "--db": db, "--picture": picture},
                  [net_path, files.world_path, files.config.path])
    make_folders(trace, xes, db, picture)
    journal = Journal(db, inputs) if db is not None else None
    try:
        return _execute(checked, inputs, journal=journal, trace=None if trace is None else Path(trace),
                        xes=None if xes is None else Path(xes), realtime=realtime, gui=gui, progress=progress,
                        max_firings=max_firings, keep_events=keep_events, extras=extras, stopwatch=stopwatch,
                        wait_agents=wait_agents, live=live)
    except BaseException:
        if journal is not None and journal.journaled == 0:  # it never started: leave no journal behind
            journal.close()
            journal.discard()
            journal = None
        raise
    finally:
        if journal is not None:
            journal.close()


def resume(db: str | Path, *, trace: str | Path | None = None, xes: str | Path | None = None,
           realtime: bool = False, gui: bool = False, registry: Registry | None = None,
           progress: bool | float = False, picture: str | Path | None = None,
           live: Live | None = None) -> RunResult:
    """Continue the run journaled in ``db`` after a kill.

    The run is re-executed from its journaled inputs (the firing limit and the trace and
    XES files it was started with included); every event up to the journal's end must
    come out identical (else :class:`~petriflow.runtime.journal.ResumeMismatch`), and
    only later events are appended. The trace written is the whole run's; ``trace``
    and ``xes`` write it elsewhere; ``picture`` draws the world's top view at the end,
    as :func:`run_files` does. A run whose end is journaled already (killed while it
    wrote its outputs) is re-executed all the same, with a warning, so that a resume
    after a kill at any moment leaves the outputs of an uninterrupted run. A steered
    run's interventions (its journaled ``control`` events) are applied again where they
    were; ``live`` serves the resumed run live.
    """
    journal = Journal(db)
    try:
        if journal.finished:  # killed after its end was journaled, before it was done with its outputs
            warnings.warn(f"{db}: the run already finished ({journal.journaled} events); re-executing it,"
                          " checked against the journal, to write its outputs", stacklevel=2)
        inputs = journal.inputs
        started_with = inputs.get("outputs") if isinstance(inputs.get("outputs"), dict) else {}
        trace = trace if trace is not None else started_with.get("trace")
        xes = xes if xes is not None else started_with.get("xes")
        if picture is not None and inputs.get("world_text") is None:
            raise NetFormatError("--picture draws the run's world, and this run has none", path=str(db))
        check_outputs({"--trace": trace, "--xes": xes, "--db": db, "--picture": picture}, [])
        make_folders(trace, xes, picture)
        files = from_journal(inputs, str(db))
        checked = check_run(files, registry=registry)
        return _execute(checked, inputs, journal=journal, trace=None if trace is None else Path(trace),
                        xes=None if xes is None else Path(xes), realtime=realtime, gui=gui, progress=progress,
                        max_firings=inputs.get("max_firings"),
                        extras=extras_for(files.config, registry=checked.binding.registry, picture=picture),
                        live=live)
    finally:
        journal.close()


def _checked_in_code(net: Net, config: RunConfig, world: Any, registry: Registry | None,
                     binding: Binding | None = None, path: Path | None = None) -> tuple[CheckedRun, Any]:
    """A net (and world) made or read in code, checked: ``(checked run, world object or
    None)``. A world file is read into the checked run (built when it runs); a world-less
    run is not refused here for an action that needs a world (it fails when it fires)."""
    if isinstance(world, (str, Path)):
        world_file = read_world(world)
        binding = validate(net, config, binding=binding, registry=registry, world=True)
        return CheckedRun.of(net, binding, config, world_file, path), None
    binding = validate(net, config, binding=binding, registry=registry, world=UNKNOWN if world is None else world)
    return CheckedRun(net, binding, config, path=path), world


def run(net: Net | str | Path, *, world: Any = None, config: RunConfig | dict | str | Path | None = None,
        seed: int | None = None, until: float | None = None, max_firings: int | None = None,
        trace: str | Path | None = None, xes: str | Path | None = None, registry: Registry | None = None,
        keep_events: bool = False) -> RunResult:
    """Run a net from Python: a file (as ``petriflow run`` does) or a :class:`Net`.

    Args:
        net: a net file, or a net built or loaded in code.
        world: a world file, a :class:`~petriflow.world.World` (or any object with
            ``dt`` and ``step()``), or ``None``.
        config: a :class:`RunConfig`, its mapping, or a file.
        seed: the run seed (overrides the configuration's).
        until: simulated-time limit in seconds (overrides the configuration's).
        max_firings: stop after this many firings.
        trace: write the events as JSON Lines to this file.
        xes: write the firings as an XES log to this file.
        registry: where actions are looked up (default: the run registry).
        keep_events: keep every event in the result's ``events`` (memory grows with
            the run, so it is off by default: a run's memory does not grow with its
            length; write a ``trace`` for long runs).

    Returns:
        The :class:`~petriflow.runtime.result.RunResult`; ``result.reason`` says how the
        run ended.

    Examples:
        >>> from petriflow import Net, run
        >>> net = Net("demo")
        >>> _ = net.add_place("i", tokens=1); _ = net.add_place("o")
        >>> _ = net.add_transition("rest", action="core.wait", params={"seconds": 3})
        >>> _ = net.add_arc("i", "rest"); _ = net.add_arc("rest", "o")
        >>> result = run(net, keep_events=True)
        >>> result.time, [e.kind for e in result.events]
        (3.0, ['run', 'start', 'end', 'stop'])
    """
    binding, path = None, None
    config = RunConfig.from_dict(config) if isinstance(config, dict) else config
    if not isinstance(net, Net):
        if world is None or isinstance(world, (str, Path)):
            return run_files(net, world=world, config=config, seed=seed, until=until, trace=trace, xes=xes,
                             registry=registry, max_firings=max_firings, keep_events=keep_events)
        prepared = prepare(net, config=config, registry=registry)  # a file run over a World made in code
        net, config, binding, path = prepared.net, prepared.config, prepared.binding, Path(net)
    config = (load_config(config) if isinstance(config, (str, Path)) else config) or RunConfig()
    if binding is None:  # a net made in code: the configuration's bind: applies to it here
        net = config.bound(net)
    config.import_actions()
    checked, given = _checked_in_code(net, config, world, registry, binding, path)
    with open_run(checked, seed=seed, world=given) as scheduler:
        return run_observed(scheduler, trace=None if trace is None else Path(trace),
                            xes=None if xes is None else Path(xes), keep_events=keep_events, until=until,
                            max_firings=max_firings)
