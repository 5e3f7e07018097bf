"""One run from files to files: load, bind, run, record.

:func:`prepare` is what every command that reads a net to run, check or show does:
read the net file once, find its run configuration, import the configuration's
action modules, and bind the net (:func:`~petriflow.runtime.binding.bind`), so a
typo fails with ``file:line`` before anything is created on disk. :func:`run_files`
is ``petriflow run``; :func:`resume` is ``--resume``; :func:`run` is the Python API.

The run configuration is, first found: the one given (``--config``), the one the net
names (``run:`` in YAML, ``<run>`` in PNML's petriflow data: a file beside the net or
the configuration itself), ``run.yaml`` beside the net, or the defaults.

Observers (trace file, XES log, journal, progress line) subscribe to the scheduler's
events; none of them keeps events in memory, so a run's memory does not grow with its
length unless ``keep_events`` asks for the event list.

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
    >>> outcome = run_files(folder / "net.yaml", trace=folder / "run.jsonl")
    >>> outcome.result.reason, outcome.result.time
    (<StopReason.FINAL: 'final'>, 1.5)
    >>> [e.kind for e in read_trace(folder / "run.jsonl")]
    ['run', 'start', 'end', 'stop']
"""

from __future__ import annotations

import sys
import warnings
import time as wallclock
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

from petriflow.collector import paused
from petriflow.errors import NetFormatError
from petriflow.net import Net
from petriflow.runtime.assembly import open_run, validate
from petriflow.runtime.binding import Binding, bind
from petriflow.runtime.config import RunConfig, load_config
from petriflow.runtime.journal import Journal, JournalError
from petriflow.runtime.registry import Registry
from petriflow.runtime.scheduler import RunResult, Scheduler
from petriflow.runtime.summary import RunExtras, extras_for
from petriflow.runtime.trace import Event, TraceWriter, XesWriter, read_trace

__all__ = ["run", "run_files", "resume", "prepare", "Prepared", "RunOutcome", "Progress", "read_trace"]

#: Events after which the journal commits: each firing's start and end.
_COMMIT_KINDS = {"run", "start", "end", "stop"}


@dataclass
class RunOutcome:
    """What a run produced.

    Attributes:
        result: how it ended.
        net: the net run.
        events: every event, when the run was asked to keep them (else empty).
        wall: wall-clock seconds the run took.
        written: the files written.
        seed: the run's random seed (conflicts, action randomness, channel losses).
    """

    result: RunResult
    net: Net
    events: list[Event]
    wall: float
    written: list[str] = field(default_factory=list)
    seed: int | None = None
    #: the metrics the run configuration (or ``metrics=``) asked for, by name
    metrics: dict[str, Any] = field(default_factory=dict)
    #: CPU seconds of the run itself (``time.process_time``), ``None`` when not measured
    cpu: float | None = None

    @property
    def realtime_factor(self) -> float:
        """Simulated seconds per wall-clock second."""
        return self.result.time / self.wall if self.wall > 0 else float("inf")


@dataclass
class Prepared:
    """A net read, its run configuration found, its actions bound: ready to run.

    Attributes:
        net: the net.
        text: the net file's text (what a journal keeps).
        config: the run configuration.
        binding: the net bound to the registry.
        world: the world file to use, if any.
    """

    net: Net
    text: str
    config: RunConfig
    binding: Binding
    world: Path | None


class Progress:
    """Progress of a run on standard error: a live line on a terminal, or, off a
    terminal (a log, CI), a line every ``interval`` wall seconds, so a long run is never
    silent. Simulated time, firings and agents alive.

    Args:
        scheduler: the run.
        stream: where to write (default: standard error).
        delay: on a terminal, seconds before the line first appears.
        interval: off a terminal, seconds between lines (``None``: nothing off a terminal).
    """

    def __init__(self, scheduler: Scheduler, stream: TextIO = sys.stderr, delay: float = 1.0,
                 interval: float | None = 30.0) -> None:
        self.scheduler = scheduler
        self.stream = stream
        self.delay = delay
        self.start = wallclock.perf_counter()
        self.last = 0.0
        self.shown = False
        self.terminal = hasattr(stream, "isatty") and stream.isatty()
        self.interval = interval
        self.active = self.terminal or interval is not None

    def _text(self, time: float) -> str:
        alive = sum(self.scheduler.alive.values())
        total = len(self.scheduler.alive)
        agents = f"  agents alive {alive}/{total}" if total else ""
        return f"t = {time:9.2f} s  firings {self.scheduler.firings:7d}{agents}"

    def __call__(self, scheduler: Scheduler) -> None:
        """After an instant (``Scheduler.on_instant``): no event needs building for it."""
        if not self.active:
            return
        now = wallclock.perf_counter()
        if self.terminal:
            if now - self.start < self.delay or now - self.last < 0.2:
                return
            self.last = now
            self.stream.write(f"\r  {self._text(scheduler.now)}   ")
            self.stream.flush()
            self.shown = True
        elif now - max(self.last, self.start) >= self.interval:
            self.last = now
            self.stream.write(f"{self.scheduler.net.id}: {self._text(scheduler.now)}"
                              f"  ({now - self.start:.0f} s wall)\n")
            self.stream.flush()

    def close(self) -> None:
        if self.shown:
            self.stream.write("\n")
            self.stream.flush()


def _read_text(path: Path) -> str:
    from petriflow.io.files import read_text_file

    return read_text_file(path)


def _net_from_text(text: str, path: str) -> Net:
    text = text.removeprefix("\ufeff")
    if text.lstrip().startswith("<"):
        from petriflow.io.pnml import loads_pnml

        return loads_pnml(text, path=path)
    from petriflow.io.yaml import loads_net

    return loads_net(text, path=path, name=Path(path).stem)


def net_config(net: Net, path: Path) -> RunConfig | None:
    """The run configuration ``net`` (read from ``path``) names, or ``None``."""
    named = net.run
    if named is None:
        return None
    if isinstance(named, str):
        file = path.parent / named
        if not file.is_file():
            raise NetFormatError(f"run configuration {named!r} not found (looked for {file}); give it with"
                                 " --config, or put it beside the net", path=str(path), line=net.lines.get("run"))
        return load_config(file)
    return RunConfig.from_dict(named, str(path), base=str(path.parent), line=net.lines.get("run"))


@paused()  # reading and binding a large net makes no cycles (petriflow.collector)
def prepare(net_path: str | Path, *, config: str | Path | RunConfig | None = None,
            world: str | Path | None = None, registry: Registry | None = None,
            import_actions: bool = True) -> Prepared:
    """Read the net in ``net_path`` once, resolve its run configuration, import the
    configuration's action modules and bind the net.

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
    net_path = Path(net_path)
    if not net_path.is_file():
        raise NetFormatError("no such file", path=str(net_path))
    text = _read_text(net_path)
    net = _net_from_text(text, str(net_path))
    if isinstance(config, RunConfig):
        run_config = config
    elif config is not None:
        run_config = load_config(config)
    else:
        run_config = net_config(net, net_path)
        if run_config is None and (net_path.parent / "run.yaml").is_file():
            run_config = load_config(net_path.parent / "run.yaml")
        run_config = run_config or RunConfig()
    net = run_config.bound(net)  # the configuration's bind: over what the file binds
    if import_actions:
        run_config.import_actions()
    pending = [] if import_actions else run_config.unimported_actions()
    try:
        binding = bind(net, registry, path=str(net_path), unimported=pending)
    except NetFormatError as exc:
        raise run_config.blame(exc) from None
    run_config.check(net)
    world_path = Path(world) if world is not None else (Path(run_config.world) if run_config.world else None)
    return Prepared(net, text, run_config, binding, world_path)


def _world_data(inputs: dict[str, Any]) -> dict[str, Any] | None:
    """The world description in ``inputs``, parsed and checked (no pybullet needed)."""
    if inputs.get("world_text") is None:
        return None
    import yaml

    from petriflow.io.yaml import parse_yaml
    from petriflow.worldfile import check_world

    try:
        data = parse_yaml(inputs["world_text"])
    except NetFormatError as exc:
        raise exc.at(inputs["world_file"]) from None
    except yaml.YAMLError as exc:
        from petriflow.io.yaml import _yaml_problem

        mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
        problem = getattr(exc, "problem", None) or _yaml_problem(exc)
        raise NetFormatError(f"malformed YAML: {problem}", path=inputs["world_file"],
                             line=mark.line + 1 if mark else None) from None
    return check_world(data, inputs["world_file"])


def _check_outputs(outputs: dict[str, str | Path | None], read: list[Path | str | None]) -> None:
    """Refuse two outputs on one file, an output that is one of the run's inputs, and an
    output whose folder cannot be made or written (before anything is created).

    Raises:
        NetFormatError: naming the option and the file.
    """
    import os

    seen: dict[Path, str] = {}
    inputs = {Path(p).resolve() for p in read if p is not None}
    for option, path in outputs.items():
        if path is None:
            continue
        where = Path(path).resolve()
        if where in seen:
            raise NetFormatError(f"{option} and {seen[where]} name the same file", path=str(path))
        if where in inputs:
            raise NetFormatError(f"{option} would overwrite one of the inputs", path=str(path))
        if where.is_dir():
            raise NetFormatError(f"{option} names a folder, not a file", path=str(path))
        seen[where] = option
        folder = where.parent
        while not folder.exists() and folder != folder.parent:
            folder = folder.parent
        if not os.access(folder, os.W_OK | os.X_OK) or not _can_create_in(folder):
            raise NetFormatError(f"{option}: cannot write into {folder}", path=str(path))


def _can_create_in(folder: Path) -> bool:
    """Whether a file can be made in ``folder`` (tried: permission bits do not tell for the
    superuser, nor on read-only or pseudo file systems such as /proc)."""
    import tempfile

    try:  # nameless where the system allows (O_TMPFILE): a kill here leaves nothing behind
        with tempfile.TemporaryFile(dir=folder, prefix=".petriflow-", suffix=".probe"):
            return True
    except OSError:
        return False


def _observe(scheduler: Scheduler, net: Net, *, journal: Journal | None, trace: Path | None,
             xes: Path | None, progress: bool | float, keep_events: bool,
             kinds: list[str] | None = None) -> dict[str, Any]:
    """Subscribe the requested observers (the events kept: of ``kinds``, or all);
    returns them by name."""
    observers: dict[str, Any] = {}
    if keep_events:
        observers["events"] = events = []
        scheduler.on_event(events.append, kinds)
    if journal is not None:
        def journal_event(event: Event) -> None:
            journal.record(event)
            if event.kind in _COMMIT_KINDS:
                journal.commit()

        scheduler.on_event(journal_event)
    if trace is not None:
        observers["trace"] = TraceWriter(trace)
        scheduler.on_event(observers["trace"])
    if xes is not None:
        labels = {t.id: t.label or t.id for t in net.transitions.values()}
        silent = [t.id for t in net.transitions.values() if t.silent]
        observers["xes"] = XesWriter(xes, case=net.id, labels=labels, silent=silent)
        scheduler.on_event(observers["xes"])
    if progress:
        display = Progress(scheduler, interval=None if progress is True else float(progress))
        if display.active:  # watches instants: no event is built for it
            observers["progress"] = display
            scheduler.on_instant(display)
    return observers


def _observed_run(scheduler: Scheduler, net: Net, *, journal: Journal | None, trace: Path | None,
                  xes: Path | None, progress: bool | float, keep_events: bool, kinds: list[str] | None = None,
                  **limits: Any) -> RunOutcome:
    """Run ``scheduler`` with the requested observers; the trace and XES files are
    renamed into place if the run ends, dropped if it raises."""
    observers: dict[str, Any] = {}
    try:
        observers = _observe(scheduler, net, journal=journal, trace=trace, xes=xes, progress=progress,
                             keep_events=keep_events, kinds=kinds)
        started = wallclock.perf_counter()
        with scheduler:
            result = scheduler.run(**limits)
        wall = wallclock.perf_counter() - started
    except BaseException:
        for name in ("trace", "xes"):
            if name in observers:
                observers[name].close(keep=False)
        raise
    finally:
        if "progress" in observers:
            observers["progress"].close()
    outcome = RunOutcome(result, net, observers.get("events", []), wall, seed=scheduler.seed)
    for name, path in (("trace", trace), ("xes", xes)):
        if name in observers:
            observers[name].close()
            outcome.written.append(str(path))
    return outcome


def _execute(net: Net, binding: Binding, config: RunConfig, inputs: dict[str, Any], *,
             journal: Journal | None, trace: Path | None, xes: Path | None, realtime: bool, gui: bool,
             progress: bool | float, max_firings: int | None, keep_events: bool = False,
             extras: RunExtras | None = None) -> RunOutcome:
    extras = extras or RunExtras()
    keep = keep_events or extras.needs_events()
    with open_run(net, binding, config, seed=inputs["seed"], world_data=_world_data(inputs),
                  world_file=inputs.get("world_file"), world_base=inputs.get("world_base"), gui=gui,
                  realtime=realtime) as scheduler:
        if inputs.get("poses"):  # the world's body poses as trace events (petriflow.runtime.poses)
            from petriflow.runtime.poses import PoseSampler

            scheduler.on_instant(PoseSampler(inputs["poses"]))
        extras.watch(scheduler)
        cpu = wallclock.process_time()
        outcome = _observed_run(scheduler, net, journal=journal, trace=trace, xes=xes, progress=progress,
                                keep_events=keep, kinds=None if keep_events else extras.event_kinds(),
                                until=inputs["until"], max_firings=max_firings)
        outcome.cpu = wallclock.process_time() - cpu
        extras.finish(scheduler, outcome, config)
    if not keep_events:
        outcome.events = []
    if journal is not None:
        journal.finish()
        outcome.written.append(str(journal.path))
    return outcome


def _inputs(prepared: Prepared, net_path: Path, seed: int | None, until: float | None) -> dict[str, Any]:
    config = prepared.config
    world = prepared.world
    return {
        "net_file": str(net_path),
        "net_text": prepared.text,
        "config": {k: v for k, v in config.to_dict().items() if k != "world"},
        "seed": config.seed if seed is None else seed,
        "until": config.until if until is None else until,
        "world_file": None if world is None else str(world),
        "world_base": None if world is None else str(world.resolve().parent),
        "world_text": None if world is None else _read_text(world),
    }


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


def _make_folders(*outputs: str | Path | None) -> None:
    """Create the folders the output files go into (before anything is written)."""
    for output in outputs:
        if output is not None:
            try:
                Path(output).parent.mkdir(parents=True, exist_ok=True)
            except OSError as exc:
                raise NetFormatError(f"cannot create its folder: {getattr(exc, 'strerror', None) or exc}", path=str(output)) from None


def run_files(net_path: str | Path, *, world: str | Path | None = None, config: str | Path | None = None,
              seed: int | None = None, until: float | None = None, trace: str | Path | None = None,
              xes: str | Path | None = None, db: str | Path | None = None, realtime: bool = False,
              gui: bool = False, registry: Registry | None = None, progress: bool | float = False,
              max_firings: int | None = None, keep_events: bool = False, metrics: list[str] | None = None,
              picture: str | Path | None = None, poses: float | None = None) -> RunOutcome:
    """Run the net in ``net_path`` (what ``petriflow run`` does).

    The run configuration is ``config``, else the one the net names, else
    ``run.yaml`` beside the net; ``world``, ``seed`` and ``until`` override what the
    configuration says. ``progress``: ``True`` shows a live line on a terminal; a
    number of seconds also prints a line that often off a terminal (a log, CI).
    ``outcome.metrics`` holds the metrics the configuration names (``metrics``: these
    registered metrics instead); ``picture`` draws the world's top view with the
    robots' trajectories at the end (see :mod:`petriflow.runtime.summary`). ``poses``:
    record the world's body poses as ``pose`` events every so many simulated seconds
    (:mod:`petriflow.runtime.poses`; what ``petriflow view`` draws the world from).

    Raises:
        NetFormatError: a file is missing or malformed, an action is unknown...
        JournalError: ``db`` already exists.
    """
    net_path = Path(net_path)
    prepared = prepare(net_path, config=config, world=world, registry=registry)
    binding = validate(prepared.net, prepared.config, binding=prepared.binding, path=str(net_path),
                       has_world=prepared.world is not None)
    _warn_unbound(prepared.net, net_path)
    inputs = _inputs(prepared, net_path, seed, until)
    inputs["max_firings"] = max_firings
    if poses is not None:  # journaled, so a resumed run samples them too
        inputs["poses"] = _pose_interval(poses)
    inputs["outputs"] = {name: None if path is None else str(Path(path).resolve())
                         for name, path in (("trace", trace), ("xes", xes))}
    extras = extras_for(prepared.config, metrics=metrics, picture=picture, registry=prepared.binding.registry)
    if picture is not None and prepared.world is None:
        raise NetFormatError("--picture draws the run's world, and this run has none (give --world, or a run"
                             " configuration with world:)", path=str(net_path))
    # everything is checked before the first file is made: the world too (a journal
    # must never hold a run that cannot start)
    _check_outputs({"--trace": trace, "--xes": xes, "--db": db, "--picture": picture},
                   [net_path, prepared.world, prepared.config.path])
    _world_data(inputs)
    _make_folders(trace, xes, db, picture)
    journal = Journal(db, inputs) if db is not None else None
    try:
        return _execute(prepared.net, binding, prepared.config, inputs, journal=journal,
                        trace=None if trace is None else Path(trace), xes=None if xes is None else Path(xes),
                        realtime=realtime, gui=gui, progress=progress, max_firings=max_firings,
                        keep_events=keep_events, extras=extras)
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
           progress: bool | float = False, picture: str | Path | None = None) -> RunOutcome:
    """Continue the run journaled in ``db`` after a kill.

    The run is re-executed from its journaled inputs (the firing limit and the trace and
    XES files it was started with included); every event up to the journal's end must
    come out identical (else :class:`~petriflow.runtime.journal.ResumeMismatch`), and
    only later events are appended. The trace written is the whole run's; ``trace``
    and ``xes`` write it elsewhere; ``picture`` draws the world's top view at the end,
    as :func:`run_files` does. A run whose end is journaled already (killed while it
    wrote its outputs) is re-executed all the same, with a warning, so that a resume
    after a kill at any moment leaves the outputs of an uninterrupted run.
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
        _check_outputs({"--trace": trace, "--xes": xes, "--db": db, "--picture": picture}, [])
        _make_folders(trace, xes, picture)
        net = _net_from_text(inputs["net_text"], inputs["net_file"])
        try:
            config = RunConfig.from_dict(inputs["config"])
        except NetFormatError as exc:
            raise JournalError(f"{db}: a damaged journal: its run configuration: {exc}") from None
        net = config.bound(net)
        config.import_actions()
        binding = validate(net, config, registry=registry, path=inputs["net_file"])
        return _execute(net, binding, config, inputs, journal=journal,
                        trace=None if trace is None else Path(trace), xes=None if xes is None else Path(xes),
                        realtime=realtime, gui=gui, progress=progress, max_firings=inputs.get("max_firings"),
                        extras=extras_for(config, registry=binding.registry, picture=picture))
    finally:
        journal.close()


def run(net: Net | str | Path, *, world: Any = None, config: RunConfig | dict | str | Path | None = None,
        seed: int | None = None, until: float | None = None, max_firings: int | None = None,
        trace: str | Path | None = None, xes: str | Path | None = None, registry: Registry | None = None,
        keep_events: bool = False) -> RunOutcome:
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
        keep_events: keep every event in the outcome's ``events`` (memory grows with
            the run, so it is off by default: a run's memory does not grow with its
            length; write a ``trace`` for long runs).

    Returns:
        The :class:`RunOutcome`; ``outcome.result.reason`` says how the run ended.

    Examples:
        >>> from petriflow import Net, run
        >>> net = Net("demo")
        >>> _ = net.add_place("i", tokens=1); _ = net.add_place("o")
        >>> _ = net.add_transition("rest", action="core.wait", params={"seconds": 3})
        >>> _ = net.add_arc("i", "rest"); _ = net.add_arc("rest", "o")
        >>> outcome = run(net, keep_events=True)
        >>> outcome.result.time, [e.kind for e in outcome.events]
        (3.0, ['run', 'start', 'end', 'stop'])
    """
    binding = None
    config = RunConfig.from_dict(config) if isinstance(config, dict) else config
    if not isinstance(net, Net):
        if world is None or isinstance(world, (str, Path)):
            return run_files(net, world=world, config=config, seed=seed, until=until, trace=trace, xes=xes,
                             registry=registry, max_firings=max_firings, keep_events=keep_events)
        prepared = prepare(net, config=config, registry=registry)  # a file run over a World made in code
        net, config, binding = prepared.net, prepared.config, prepared.binding
    config = (load_config(config) if isinstance(config, (str, Path)) else config) or RunConfig()
    if binding is None:  # a net made in code: the configuration's bind: applies to it here
        net = config.bound(net)
    config.import_actions()
    close = False
    if isinstance(world, (str, Path)):
        from petriflow.world import load_world

        world, close = load_world(world), True
    try:
        binding = validate(net, config, binding=binding, registry=registry)
        with open_run(net, binding, config, seed=seed, world=world) as scheduler:
            return _observed_run(scheduler, net, journal=None, trace=None if trace is None else Path(trace),
                                 xes=None if xes is None else Path(xes), progress=False, keep_events=keep_events,
                                 until=until, max_firings=max_firings)
    finally:
        if close:
            world.close()
