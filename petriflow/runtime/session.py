"""One run from files to files: load the net, world and configuration, run, record.

:func:`run_files` is what ``petriflow run`` does; :func:`resume` is ``--resume``.
Observers (trace file, journal, progress line) subscribe to the scheduler's events.

Examples:
    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "net.yaml").write_text('''
    ... petriflow: 1
    ... places: [{id: i, tokens: 1}, o]
    ... transitions: [{id: rest, action: core.wait, params: {seconds: 1.5}, in: [i], out: [o]}]
    ... final: {o: 1}
    ... ''')
    >>> outcome = run_files(folder / "net.yaml", trace=folder / "run.jsonl")
    >>> outcome.result.reason, outcome.result.time
    ('final', 1.5)
    >>> [e.kind for e in read_trace(folder / "run.jsonl")]
    ['run', 'start', 'end', 'stop']
"""

from __future__ import annotations

import sys
import time as wallclock
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

from petriflow.errors import NetFormatError
from petriflow.net import Net
from petriflow.runtime.config import RunConfig, load_config
from petriflow.runtime.journal import Journal, JournalError
from petriflow.runtime.registry import Registry
from petriflow.runtime.scheduler import RunResult, Scheduler
from petriflow.runtime.trace import Event, TraceWriter, read_trace, write_xes

__all__ = ["run_files", "resume", "RunOutcome", "Progress", "read_trace"]

#: Events after which the journal commits: each firing's start and end.
_COMMIT_KINDS = {"run", "start", "end", "stop"}


@dataclass
class RunOutcome:
    """What a run produced."""

    result: RunResult
    net: Net
    events: list[Event]
    wall: float
    written: list[str] = field(default_factory=list)

    @property
    def realtime_factor(self) -> float:
        """Simulated seconds per wall-clock second."""
        return self.result.time / self.wall if self.wall > 0 else float("inf")


class Progress:
    """A one-line live display (simulated time, firings, agents alive) on a terminal.

    It appears only after the run has lasted ``delay`` wall seconds and only when
    ``stream`` is a terminal.
    """

    def __init__(self, scheduler: Scheduler, stream: TextIO = sys.stderr, delay: float = 1.0) -> None:
        self.scheduler = scheduler
        self.stream = stream
        self.delay = delay
        self.start = wallclock.perf_counter()
        self.last = 0.0
        self.shown = False
        self.active = hasattr(stream, "isatty") and stream.isatty()

    def __call__(self, event: Event) -> None:
        if not self.active:
            return
        now = wallclock.perf_counter()
        if now - self.start < self.delay or now - self.last < 0.2:
            return
        self.last = now
        alive = sum(self.scheduler.alive.values())
        total = len(self.scheduler.alive)
        agents = f"  agents alive {alive}/{total}" if total else ""
        self.stream.write(f"\r  t = {event.time:9.2f} s  firings {self.scheduler._firings:7d}{agents}   ")
        self.stream.flush()
        self.shown = True

    def close(self) -> None:
        if self.shown:
            self.stream.write("\n")
            self.stream.flush()


def _read_text(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise NetFormatError(f"cannot read: {getattr(exc, 'strerror', None) or exc}", path=str(path)) from None


def _net_from_text(text: str, name: str, path: str) -> Net:
    if text.lstrip().startswith("<"):
        from petriflow.io.pnml import loads_pnml

        return loads_pnml(text, path=path)
    from petriflow.io.yaml import loads_net

    return loads_net(text, path=path, name=name)


def _world_from(inputs: dict[str, Any], gui: bool):
    if inputs.get("world_text") is None:
        return None
    import yaml

    from petriflow.world import World

    data = yaml.safe_load(inputs["world_text"])
    return World(data, base=inputs["world_base"], gui=gui, path=inputs["world_file"])


def _execute(inputs: dict[str, Any], *, journal: Journal | None, trace: Path | None, xes: Path | None,
             realtime: bool, gui: bool, registry: Registry | None, progress: bool,
             max_firings: int | None) -> RunOutcome:
    net = _net_from_text(inputs["net_text"], Path(inputs["net_file"]).stem, inputs["net_file"])
    config = RunConfig.from_dict(inputs["config"])
    config.world = inputs.get("world_file")
    world = _world_from(inputs, gui)
    events: list[Event] = []
    writer = None
    display = None
    try:
        scheduler = Scheduler(net, world=world, config=config, seed=inputs["seed"], registry=registry,
                              path=inputs["net_file"])
        scheduler.on_event(events.append)
        if journal is not None:
            def journal_event(event: Event) -> None:
                journal.record(event)
                if event.kind in _COMMIT_KINDS:
                    journal.commit()

            scheduler.on_event(journal_event)
        if trace is not None:
            writer = TraceWriter(trace)
            scheduler.on_event(writer)
        if progress:
            display = Progress(scheduler)
            scheduler.on_event(display)
        started = wallclock.perf_counter()
        result = scheduler.run(until=inputs["until"], max_firings=max_firings, realtime=realtime)
        wall = wallclock.perf_counter() - started
    except BaseException:
        if writer is not None:
            writer.close(keep=False)
        raise
    finally:
        if display is not None:
            display.close()
        if world is not None:
            world.close()
    outcome = RunOutcome(result, net, events, wall)
    if writer is not None:
        writer.close()
        outcome.written.append(str(trace))
    if journal is not None:
        journal.finish()
        outcome.written.append(str(journal.path))
    if xes is not None:
        labels = {t.id: t.label or t.id for t in net.transitions.values()}
        silent = [t.id for t in net.transitions.values() if t.silent]
        write_xes(events, xes, case=net.id, labels=labels, silent=silent)
        outcome.written.append(str(xes))
    return outcome


def run_files(net_path: str | Path, *, world: str | Path | None = None, config: str | Path | None = None,
              seed: int | None = None, until: float | None = None, trace: str | Path | None = None,
              xes: str | Path | None = None, db: str | Path | None = None, realtime: bool = False,
              gui: bool = False, registry: Registry | None = None, progress: bool = False,
              max_firings: int | None = None) -> RunOutcome:
    """Run the net in ``net_path``.

    The run configuration is ``config``, or ``run.yaml`` beside the net when that
    exists; ``world``, ``seed`` and ``until`` override what the configuration says.

    Raises:
        NetFormatError: a file is missing or malformed, an action is unknown...
        JournalError: ``db`` already exists.
    """
    net_path = Path(net_path)
    net_text = _read_text(net_path)
    if config is None and (net_path.parent / "run.yaml").is_file():
        config = net_path.parent / "run.yaml"
    run_config = load_config(config) if config is not None else RunConfig()
    world_path = Path(world) if world is not None else (Path(run_config.world) if run_config.world else None)
    inputs = {
        "net_file": str(net_path),
        "net_text": net_text,
        "config": {k: v for k, v in run_config.to_dict().items() if k != "world"},
        "seed": run_config.seed if seed is None else seed,
        "until": run_config.until if until is None else until,
        "world_file": None if world_path is None else str(world_path),
        "world_base": None if world_path is None else str(world_path.parent),
        "world_text": None if world_path is None else _read_text(world_path),
    }
    # fail on a bad net before creating any output file
    _net_from_text(net_text, net_path.stem, str(net_path))
    journal = Journal(db, inputs) if db is not None else None
    try:
        return _execute(inputs, journal=journal, trace=None if trace is None else Path(trace),
                        xes=None if xes is None else Path(xes), realtime=realtime, gui=gui,
                        registry=registry, progress=progress, max_firings=max_firings)
    finally:
        if journal is not None:
            journal.close()


def resume(db: str | Path, *, trace: str | Path | None = None, xes: str | Path | None = None,
           realtime: bool = False, gui: bool = False, registry: Registry | None = None,
           progress: bool = False) -> RunOutcome:
    """Continue the run journaled in ``db`` after a kill.

    The run is re-executed from its journaled inputs; every event up to the journal's
    end must come out identical (else :class:`~petriflow.runtime.journal.ResumeMismatch`),
    and only later events are appended. The trace written is the whole run's.
    """
    journal = Journal(db)
    try:
        if journal.finished:
            raise JournalError(f"{db}: the run already finished ({journal.journaled} events)")
        return _execute(journal.inputs, journal=journal, trace=None if trace is None else Path(trace),
                        xes=None if xes is None else Path(xes), realtime=realtime, gui=gui,
                        registry=registry, progress=progress, max_firings=None)
    finally:
        journal.close()
