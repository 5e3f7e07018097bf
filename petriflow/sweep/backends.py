"""Where trials run: a pool of local worker processes, or a Ray cluster.

Both take payloads (:meth:`Sweep.payload <petriflow.sweep.spec.Sweep.payload>`, plain
data) and yield ``(index, result)`` as trials finish, in any order; a trial that
raises, kills its worker or outlives the sweep's ``timeout`` becomes a result with
status ``error``, ``crashed`` or ``timeout`` and the sweep goes on.

* :func:`run_local`: ``workers`` long-lived processes (``spawn``: no state shared with
  the parent), each running trials one after another; a worker that crashes or runs
  past the timeout is killed and replaced.
* :func:`run_ray`: one Ray task per trial (``ray.init(address=...)``: an existing
  cluster, else a local Ray instance), at most ``workers`` in flight; the driver
  gathers the results, so they still land in the local results database.
"""

from __future__ import annotations

import multiprocessing
import os
import time as wallclock
from collections import deque
from collections.abc import Iterator
from multiprocessing.connection import Connection, wait
from typing import Any

from petriflow.errors import PetriflowError

__all__ = ["run_local", "run_ray", "BackendError", "BACKENDS", "default_workers"]

BACKENDS = ("local", "ray")


class BackendError(PetriflowError):
    """A backend cannot start (Ray missing, a cluster that does not answer)."""


def default_workers() -> int:
    """The CPUs this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not Linux
        return max(1, os.cpu_count() or 1)


def _failed(status: str, error: str, wall: float) -> dict[str, Any]:
    return {"status": status, "metrics": {}, "outcome": None, "error": error, "wall": wall}


#: What a worker sends once its imports are done, before it takes its first trial.
_READY = "ready"
#: Seconds a new worker process may take to import petriflow and say it is ready.
START_TIMEOUT = 300.0


def _serve(connection: Connection) -> None:
    """A worker: import what trials need, say so, then run each payload received and
    send its result back, until ``None``."""
    from petriflow.sweep.trial import run_trial
    import petriflow.runtime.session  # noqa: F401  (imported before the clock of the first trial starts)

    connection.send(_READY)
    while True:
        try:
            payload = connection.recv()
        except EOFError:
            return
        if payload is None:
            return
        connection.send(run_trial(payload))


class _Worker:
    """One worker process: starting (not yet ready), idle, or running ``job`` since
    ``started`` (the moment the payload went to a worker that was ready for it, so a
    trial's timeout measures the trial, never the queue or the worker's start-up)."""

    def __init__(self, context: Any) -> None:
        self.connection, child = context.Pipe()
        self.process = context.Process(target=_serve, args=(child,), daemon=True)
        self.process.start()
        child.close()
        self.ready = False
        self.job: int | None = None
        self.started = wallclock.perf_counter()

    def give(self, index: int, payload: dict[str, Any]) -> bool:
        """Send a trial; ``False`` when the worker is gone (the trial was not given)."""
        try:
            self.connection.send(payload)
        except OSError:
            return False
        self.job, self.started = index, wallclock.perf_counter()
        return True

    def kill(self) -> None:
        self.process.kill()
        self.process.join(5)
        self.connection.close()

    def stop(self) -> None:
        try:
            self.connection.send(None)
        except OSError:
            pass
        self.process.join(2)
        if self.process.is_alive():
            self.kill()
        self.connection.close()


class _Pool:
    """Worker processes that are replaced when they die or time out."""

    def __init__(self, size: int) -> None:
        self.context = multiprocessing.get_context("spawn")
        self.workers = [_Worker(self.context) for _ in range(size)]
        self.failed_starts = 0

    def replace(self, worker: _Worker) -> None:
        worker.kill()
        self.workers[self.workers.index(worker)] = _Worker(self.context)

    def started_badly(self, worker: _Worker, why: str) -> None:
        """A worker died or hung before it was ready: replace it, unless no worker starts."""
        self.failed_starts += 1
        code = worker.process.exitcode
        self.replace(worker)
        if self.failed_starts >= 2 * len(self.workers) + 1:
            raise BackendError(f"local sweep workers cannot start: {why}"
                               + (f" (exit code {code})" if code is not None else ""))

    def close(self) -> None:
        for worker in self.workers:
            if worker.job is None and worker.ready:
                worker.stop()
            else:
                worker.kill()


def run_local(payloads: list[dict[str, Any]], workers: int, timeout: float) -> Iterator[tuple[int, dict[str, Any]]]:
    """Run ``payloads`` on ``workers`` local processes; yields ``(index, result)``.

    A trial's ``timeout`` counts from the moment it goes to a worker that has finished
    starting, so neither waiting in the queue nor a worker's imports count against it.

    Raises:
        BackendError: worker processes die or hang before they are ready, again and
            again (nothing a trial did).
    """
    if not payloads:
        return
    pending = deque(range(len(payloads)))
    pool = _Pool(min(workers, len(payloads)))
    try:
        while pending or any(w.job is not None for w in pool.workers):
            for worker in list(pool.workers):
                if worker.ready and worker.job is None and pending:
                    index = pending.popleft()
                    if not worker.give(index, payloads[index]):
                        pending.appendleft(index)
                        pool.started_badly(worker, "a worker exited before its first trial")
            busy = [w for w in pool.workers if w.job is not None]
            starting = [w for w in pool.workers if not w.ready]
            deadlines = [w.started + timeout for w in busy] + [w.started + START_TIMEOUT for w in starting]
            waiting = {w.connection: w for w in busy + starting}
            waiting.update({w.process.sentinel: w for w in busy + starting})
            if not waiting:
                continue
            ready = wait(list(waiting), timeout=max(0.0, min(deadlines) - wallclock.perf_counter()))
            handled: list[_Worker] = []
            for handle in ready:
                worker = waiting[handle]
                if worker in handled:
                    continue
                handled.append(worker)
                try:
                    message = worker.connection.recv() if worker.connection.poll() else None
                except (EOFError, OSError):
                    message = None
                if not worker.ready:
                    if message == _READY:
                        worker.ready = True
                        pool.failed_starts = 0
                    else:
                        pool.started_badly(worker, "a worker exited while importing petriflow")
                    continue
                index, wall = worker.job, wallclock.perf_counter() - worker.started
                worker.job = None
                if message is None:
                    worker.process.join(2)  # the pipe closes a moment before the process is gone
                    code = worker.process.exitcode
                    pool.replace(worker)
                    message = _failed("crashed", f"the worker process died (exit code {code})", wall)
                yield index, message
            now = wallclock.perf_counter()
            for worker in list(pool.workers):
                if worker.job is not None and now - worker.started >= timeout:
                    index = worker.job
                    pool.replace(worker)
                    yield index, _failed("timeout", f"ran past the sweep's timeout of {timeout:g} s", now - worker.started)
                elif not worker.ready and now - worker.started >= START_TIMEOUT:
                    pool.started_badly(worker, f"a worker did not start within {START_TIMEOUT:g} s")
    finally:
        pool.close()


def _ray_trial(payload: dict[str, Any]) -> dict[str, Any]:
    from petriflow.sweep.trial import run_trial

    return run_trial(payload)


def run_ray(payloads: list[dict[str, Any]], workers: int | None, timeout: float,
            address: str | None = None) -> Iterator[tuple[int, dict[str, Any]]]:
    """Run ``payloads`` as Ray tasks; yields ``(index, result)``.

    Args:
        workers: tasks in flight at once (default: the cluster's CPUs).
        address: the cluster (``ray://host:10001`` or ``host:6379``); default
            ``RAY_ADDRESS``, else a local Ray instance started for this sweep.
    """
    if not payloads:
        return
    try:
        import ray
    except ImportError:
        raise BackendError("the ray backend needs Ray: pip install 'petriflow[ray]'") from None
    address = address or os.environ.get("RAY_ADDRESS") or None
    started_here = not ray.is_initialized()
    if started_here:
        try:
            options: dict[str, Any] = {"address": address, "include_dashboard": False, "log_to_driver": False,
                                       "logging_level": "ERROR"}
            if address is None:
                options["num_cpus"] = workers or default_workers()
            ray.init(**options)
        except Exception as exc:  # ConnectionError, RuntimeError, ValueError from ray
            raise BackendError(f"ray: cannot start or reach the cluster{f' at {address}' if address else ''}:"
                               f" {type(exc).__name__}: {exc}".splitlines()[0]) from None
    try:
        task = ray.remote(max_retries=0, num_cpus=1)(_ray_trial)
        slots = workers or max(1, int(ray.cluster_resources().get("CPU", 1)))
        pending = deque(range(len(payloads)))
        flight: dict[Any, tuple[int, float]] = {}
        while pending or flight:
            while pending and len(flight) < slots:
                index = pending.popleft()
                flight[task.remote(payloads[index])] = (index, wallclock.perf_counter())
            soonest = min(t for _, t in flight.values()) + timeout
            ready, _ = ray.wait(list(flight), num_returns=1, timeout=max(0.0, soonest - wallclock.perf_counter()))
            for ref in ready:
                index, started = flight.pop(ref)
                try:
                    result = ray.get(ref)
                except Exception as exc:  # the task's worker died
                    result = _failed("crashed", f"ray task failed: {type(exc).__name__}: {exc}".splitlines()[0],
                                     wallclock.perf_counter() - started)
                yield index, result
            now = wallclock.perf_counter()
            for ref, (index, started) in list(flight.items()):
                if now - started >= timeout:
                    ray.cancel(ref, force=True)
                    del flight[ref]
                    yield index, _failed("timeout", f"ran past the sweep's timeout of {timeout:g} s", now - started)
    finally:
        if started_here:
            ray.shutdown()
