"""Experiments as data: run a net over a grid of parameters and seeds, measure each run.

``petriflow sweep SPEC.yaml`` and :func:`run_sweep` read a sweep file
(:mod:`petriflow.sweep.spec`, ``docs/sweep-format.md``), run each trial (a row's
parameters and a seed) on a backend (:mod:`petriflow.sweep.backends`: local worker
processes or a Ray cluster), record one row per trial in SQLite
(:mod:`petriflow.sweep.store`) and report each metric's mean and standard deviation per
row beside the paper's value (:mod:`petriflow.sweep.report`).

Examples:
    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "net.yaml").write_text('''
    ... petriflow: 1
    ... places: [{id: i, tokens: 1}, o]
    ... transitions: [{id: rest, action: core.wait, params: {seconds: 1}, in: [i], out: [o]}]
    ... final: {o: 1}
    ... ''')
    >>> _ = (folder / "sweep.yaml").write_text('''
    ... petriflow-sweep: 1
    ... net: net.yaml
    ... trials: 2
    ... matrix: {wait: [1.5, 3]}
    ... set: {net.transitions.rest.params.seconds: "${wait}"}
    ... metrics: [core.end_time]
    ... ''')
    >>> result = run_sweep(load_sweep(folder / "sweep.yaml"), workers=1)
    >>> [(row["params"], row["metrics"]["core.end_time"]["mean"]) for row in result.rows]
    [({'wait': 1.5}, 1.5), ({'wait': 3}, 3.0)]
"""

from __future__ import annotations

import sys
import time as wallclock
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from petriflow.errors import PetriflowError
from petriflow.sweep.backends import BACKENDS, RETRIES, BackendError, RayBackend, default_workers, run_local
from petriflow.sweep.report import metric_names, summary, trial_status
from petriflow.sweep.ship import collect
from petriflow.sweep.load import load_sweep
from petriflow.sweep.spec import Sweep, Trial, canonical
from petriflow.sweep.store import Store, StoreError

__all__ = ["Sweep", "SweepResult", "load_sweep", "run_sweep", "BACKENDS", "BackendError", "StoreError"]


@dataclass
class SweepResult:
    """What a sweep produced.

    Attributes:
        sweep: the sweep.
        rows: the report, a dict per row (:func:`petriflow.sweep.report.summary`).
        trials: every trial recorded (this run's and, resumed, the earlier ones).
        names: the metric names reported (a mapping metric's keys expanded).
        ran: trials run by this call.
        wall: wall seconds of this call.
    """

    sweep: Sweep
    rows: list[dict[str, Any]]
    trials: list[dict[str, Any]]
    names: list[str]
    ran: int = 0
    wall: float = 0.0
    failures: list[dict[str, Any]] = field(default_factory=list)

    def to_json(self) -> dict[str, Any]:
        """``{"spec": PATH, "rows": [...]}`` (the rows of :func:`~petriflow.sweep.report.summary`)."""
        return {"spec": self.sweep.path, "rows": self.rows, "wall_clock": self.wall_clock()}

    def wall_clock(self) -> list[str]:
        """The reported metrics that measure wall-clock time: not reproducible between
        runs of the same trial, unlike every other metric."""
        from petriflow.runtime.registry import default_registry

        names = []
        for ref in self.sweep.metrics:
            try:
                if default_registry.metric_spec(ref.metric).wall_clock:
                    names.append(ref.name)
            except PetriflowError:
                pass
        return names


class _LogProgress:
    """Progress for a log or CI (no terminal): a line on standard error every
    ``interval`` wall seconds, from a background thread, so a long trial is not silence."""

    def __init__(self, name: str, total: int, interval: float) -> None:
        import threading

        self.name, self.total, self.interval = name, total, interval
        self.done = self.failed = 0
        self.started = wallclock.perf_counter()
        self._stop = threading.Event()
        print(f"{name}: running {total} trial{'s' if total != 1 else ''}", file=sys.stderr, flush=True)
        self._thread = threading.Thread(target=self._loop, daemon=True)
        self._thread.start()

    def update(self, result: dict[str, Any]) -> None:
        self.done += 1
        self.failed += result.get("status") != "ok" or result.get("outcome") == "failed"

    def line(self) -> str:
        elapsed = wallclock.perf_counter() - self.started
        left = (elapsed / self.done * (self.total - self.done)) if self.done else None
        eta = f", about {left:.0f} s left" if left is not None else ""
        return (f"{self.name}: {self.done}/{self.total} trials done ({self.failed} failed) after"
                f" {elapsed:.0f} s{eta}")

    def _loop(self) -> None:
        while not self._stop.wait(self.interval):
            print(self.line(), file=sys.stderr, flush=True)

    def close(self) -> None:
        self._stop.set()
        print(self.line(), file=sys.stderr, flush=True)


def _progress(name: str, total: int, progress: Any) -> Any:
    """``"bar"`` (or ``True``): a progress bar (a terminal); a number: a line every that
    many seconds (a log); ``None``/``False``: nothing."""
    if not progress or total == 0:
        return None
    if progress is True or progress == "bar":
        from tqdm import tqdm

        return tqdm(total=total, unit="trial", file=sys.stderr, dynamic_ncols=True, leave=False)
    return _LogProgress(name, total, float(progress))


def run_sweep(sweep: Sweep, *, backend: str = "local", workers: int | None = None, db: str | Path | None = None,
              resume: bool = False, progress: Any = False, ray_address: str | None = None,
              on_result: Callable[[Trial, dict[str, Any]], None] | None = None, retries: int = RETRIES,
              ray_pip: list[str] | None = None) -> SweepResult:
    """Run every trial of ``sweep`` not yet in ``db``; record and summarise them.

    Args:
        backend: ``local`` (worker processes) or ``ray``.
        workers: processes (local; default: every CPU) or trials in flight at most
            (ray; default: the cluster's CPUs, as nodes come and go).
        db: the results database (default: in memory). It is created only once the
            backend has started (a cluster that cannot be reached leaves no file).
        resume: ``db`` exists: run only the trials it lacks, and again those recorded
            ``crashed`` (their process or node died).
        progress: ``"bar"`` (a terminal's progress bar), a number of seconds (a line
            on standard error that often: a log, CI), or nothing.
        ray_address: the Ray cluster (default ``RAY_ADDRESS``, else a local instance).
        on_result: called with each trial's result as it arrives.
        retries: ray: times a trial is tried again after its node or worker died.
        ray_pip: ray: more packages for nodes that get petriflow's dependencies by pip.

    Raises:
        StoreError: ``db`` exists without ``resume``, or holds another sweep (or the
            files the sweep reads changed since).
        BackendError: the backend cannot start.
    """
    if backend not in BACKENDS:
        raise PetriflowError(f"unknown backend {backend!r} (one of {', '.join(BACKENDS)})")
    if workers is not None and workers < 1:
        raise PetriflowError(f"workers must be at least 1, not {workers}")
    if retries < 0:
        raise PetriflowError(f"retries must be 0 or more, not {retries}")
    bundle = collect(sweep)
    meta = {"file": sweep.path, "digest": bundle.digest(), "files": canonical(bundle.hashes)}
    store = Store(db)
    store.check(meta, resume)
    cluster = None
    if backend == "ray":
        cluster = RayBackend(workers, sweep.timeout, ray_address, retries=retries, pip=ray_pip)
        cluster.connect(bundle)
    started = wallclock.perf_counter()
    try:
        store.begin(meta, resume=resume)
        done = store.done()
        todo = [t for t in sweep.trials() if (t.key, t.seed) not in done]
        payloads = [sweep.payload(t) for t in todo]
        if cluster is None:
            results = run_local(payloads, workers or default_workers(), sweep.timeout)
        else:
            results = cluster.run(payloads)
        bar = _progress(sweep.name, len(todo), progress)
        try:
            for index, result in results:
                trial = todo[index]
                store.add(trial.row, trial.params, trial.seed, result)
                if on_result is not None:
                    on_result(trial, result)
                if bar is not None:
                    bar.update(result if isinstance(bar, _LogProgress) else 1)
        finally:
            if bar is not None:
                bar.close()
        trials = store.results()
    finally:
        store.close()
        if cluster is not None:
            cluster.close()
    names = metric_names([m.name for m in sweep.metrics], trials)
    rows = summary(sweep.rows, trials, names)
    failures = [t for t in trials if trial_status(t) != "ok"]
    return SweepResult(sweep, rows, trials, names, len(todo), wallclock.perf_counter() - started, failures)
