"""Where trials run: a pool of local worker processes, or a Ray cluster.

Both take payloads (:meth:`Sweep.payload <petriflow.sweep.spec.Sweep.payload>`, plain
data) and yield ``(index, result)`` as trials finish, in any order; a trial that
raises, kills its worker or outlives the sweep's ``timeout`` becomes a result with
status ``error``, ``crashed`` or ``timeout`` and the sweep goes on.

* :func:`run_local`: ``workers`` long-lived processes (``spawn``: no state shared with
  the parent), each running trials one after another; a worker that crashes or runs
  past the timeout is killed and replaced.
* :class:`RayBackend` (and :func:`run_ray`): Ray actors, one per CPU of each live
  node of a cluster (``ray.init(address=...)``; else a local Ray instance), each
  running trials one after another, with the sweep's files and petriflow shipped in
  the job's runtime environment; a trial whose node or worker dies is tried again
  (at most ``RETRIES`` times); the driver gathers the results, so they still land in
  the local results database.
"""

from __future__ import annotations

import math
import multiprocessing
import os
import platform
import re
import shutil
import sys
import tempfile
import time as wallclock
from collections import deque
from collections.abc import Callable, Iterator
from multiprocessing.connection import Connection, wait
from pathlib import Path
from typing import Any

from petriflow.errors import PetriflowError

__all__ = ["run_local", "run_ray", "RayBackend", "BackendError", "BACKENDS", "default_workers", "RETRIES"]

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


#: Times a trial is tried again after an infrastructure failure on Ray (its node died,
#: its worker process died, its result was lost) before it is recorded as ``crashed``.
RETRIES = 2
#: Seconds between two looks at the cluster's nodes and CPUs.
_REFRESH = 1.0
#: Seconds a node's first worker may take to start (Ray's pip environment, built once
#: per node, included) before the node is given up.
RAY_START_TIMEOUT = 900.0
#: Seconds a sweep waits for a node with a CPU to join a cluster that has none.
NO_NODE_WAIT = 60.0
_MISSING = re.compile(r"No module named '[^']+'")
_ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")


class _RayWorker:
    """A Ray actor that runs trials one after another (like a local worker process)."""

    def ready(self) -> dict[str, Any]:
        """Import what trials need; say which Python runs here, or why it cannot."""
        try:
            import petriflow.runtime.session  # noqa: F401
            import petriflow.sweep.trial  # noqa: F401
        except ImportError as exc:
            return {"error": f"{type(exc).__name__}: {exc}", "python": _python()}
        return {"error": None, "python": _python()}

    def run(self, payload: dict[str, Any]) -> dict[str, Any]:
        from petriflow.sweep.trial import run_trial

        return run_trial(payload)


def _python() -> str:
    """This process's Python version, major.minor (what pickled code needs to match)."""
    return ".".join(platform.python_version_tuple()[:2])


def clean_error(exc: BaseException, lines: int = 3) -> str:
    """One line from a Ray exception: no colour codes, the remote traceback's last
    ``lines`` non-empty lines joined."""
    text = _ANSI.sub("", str(exc))
    kept = [line.strip() for line in text.splitlines() if line.strip()]
    kept = [line for line in kept if not line.startswith(("Traceback", "File ", "^"))] or kept
    return f"{type(exc).__name__}: " + " | ".join(kept[-lines:])[:1500]


def _unreachable(address: str | None, timeout: float = 5.0) -> str | None:
    """Why nothing answers at ``address`` (``host:port`` or ``ray://host:port``), or
    ``None`` (it answers, or the address is not one to try: ``auto``, none). Ray itself
    would retry for minutes."""
    import socket

    if not address or address == "auto" or address.startswith("local"):
        return None
    host, _, port = address.removeprefix("ray://").rpartition(":")
    if not host or not (port.isascii() and port.isdigit()) or len(port) > 5:
        return None
    try:
        with socket.create_connection((host.strip("[]"), int(port)), timeout=timeout):
            return None
    except OSError as exc:
        return f"nothing answers there ({exc.strerror or exc}); is the head node started (ray start --head)?"


def _node_name(node: dict[str, Any]) -> str:
    return f"{node.get('NodeManagerAddress', '?')} ({str(node.get('NodeID', ''))[:8]})"


class _Slot:
    """An actor on a node: starting (``probe`` in flight), idle, or running ``job``
    since ``started`` (the moment it went to the ready actor)."""

    def __init__(self, actor: Any, node: str, probe: Any, pip: bool) -> None:
        self.actor, self.node, self.probe, self.pip = actor, node, probe, pip
        self.ready = False
        self.job: int | None = None
        self.ref: Any = None
        self.started = wallclock.perf_counter()


class RayBackend:
    """Trials as calls to Ray actors, one actor per CPU of each live node.

    Each actor is placed on its node (node affinity) with a runtime environment built
    by petriflow (``runtime_env``): the sweep's files as its working directory,
    petriflow itself as a ``py_module``, and, on a node whose Python lacks petriflow's
    dependencies, those through Ray's ``pip`` field (a virtual environment built once
    per node). A node that cannot run trials even so is left out, with one line on
    standard error, instead of failing trial after trial.

    A trial's timeout counts from the moment it goes to a ready actor. A trial whose
    node dies, whose worker process dies or whose result is lost goes back to the
    queue, at most ``retries`` times; then it is recorded as ``crashed``. The number
    of actors follows the cluster's CPUs as nodes come and go.

    Use: :meth:`connect` (raises :class:`BackendError` when the cluster cannot be
    reached), then :meth:`run`, then :meth:`close`.
    """

    def __init__(self, workers: int | None, timeout: float, address: str | None = None, *,
                 retries: int = RETRIES, pip: list[str] | None = None,
                 log: Callable[[str], None] | None = None) -> None:
        self.workers, self.timeout, self.retries = workers, timeout, retries
        self.address = address or os.environ.get("RAY_ADDRESS") or None
        self.extra_pip = list(pip or [])
        self.log = log or (lambda line: print(line, file=sys.stderr, flush=True))
        self.ray: Any = None
        self.started_here = False
        self.folder: Path | None = None
        self.bundle: Any = None
        self.pip_env: dict[str, Any] | None = None

    # Connecting -----------------------------------------------------------------
    def connect(self, bundle: Any = None) -> None:
        """Start or reach Ray, with the job's runtime environment: ``bundle``'s files
        (:func:`petriflow.sweep.ship.collect`) as its working directory and petriflow
        as a ``py_module``. When this process already called ``ray.init`` itself,
        nothing is shipped: every node must read the sweep's files at the driver's
        paths and have petriflow installed.

        Raises:
            BackendError: Ray is not installed, or the cluster does not answer (with
                what to do for ``ray://`` without ``ray[client]`` and for token
                authentication).
        """
        try:
            import ray
        except ImportError:
            raise BackendError("the ray backend needs Ray: pip install 'petriflow[ray]'") from None
        self.ray = ray
        if ray.is_initialized():
            self.log("ray: already initialised in this process: the sweep's files and petriflow are not shipped"
                     " (every node needs them at the driver's paths)")
            return
        from petriflow.sweep.ship import requirements, stage_petriflow

        self.folder = Path(tempfile.mkdtemp(prefix="petriflow-ray-"))
        env: dict[str, Any] = {"py_modules": [str(stage_petriflow(self.folder / "package"))],
                               "env_vars": {"PYTHONUNBUFFERED": "1"}}
        if bundle is not None:
            env["working_dir"] = str(bundle.stage(self.folder / "files"))
            env["py_modules"] += [str(m) for m in bundle.modules]
            variable = bundle.path_variable()
            if variable:
                env["env_vars"]["PETRIFLOW_PATH"] = variable
        self.pip_env = {"pip": {"packages": requirements() + self.extra_pip, "pip_check": False}}
        options: dict[str, Any] = {"address": self.address, "include_dashboard": False, "log_to_driver": False,
                                   "logging_level": "ERROR", "runtime_env": env}
        if self.address is None:  # a new instance, even where `ray start` left one to find
            options.update(address="local", num_cpus=self.workers or default_workers())
        unreachable = _unreachable(self.address)
        if unreachable:
            self.close()
            raise BackendError(f"ray: cannot start or reach the cluster at {self.address}: {unreachable}")
        # under `ray job submit`, the job's own runtime environment keeps its other fields
        override = os.environ.get("RAY_OVERRIDE_JOB_RUNTIME_ENV")
        os.environ["RAY_OVERRIDE_JOB_RUNTIME_ENV"] = "1"
        try:
            ray.init(**options)
        except Exception as exc:  # ConnectionError, RuntimeError, ValueError, AuthenticationError from ray
            self.close()
            where = f" at {self.address}" if self.address else ""
            text = clean_error(exc, 1)
            hint = ""
            if "ray[client]" in text or "ray.util.client" in text:
                hint = "; ray:// needs Ray Client: pip install 'ray[client]' (petriflow[ray] includes it)"
            elif "auth" in text.lower() or "token" in text.lower():
                hint = ("; this cluster uses token authentication: set RAY_AUTH_MODE=token and give its token"
                        " (RAY_AUTH_TOKEN, RAY_AUTH_TOKEN_PATH or ~/.ray/auth_token)")
            raise BackendError(f"ray: cannot start or reach the cluster{where}: {text}{hint}") from None
        finally:
            if override is None:
                os.environ.pop("RAY_OVERRIDE_JOB_RUNTIME_ENV", None)
            else:
                os.environ["RAY_OVERRIDE_JOB_RUNTIME_ENV"] = override
        self.started_here = True
        self.bundle = bundle

    def close(self) -> None:
        if self.started_here and self.ray is not None:
            self.ray.shutdown()
            self.started_here = False
        if self.folder is not None:
            shutil.rmtree(self.folder, ignore_errors=True)
            self.folder = None

    # Running --------------------------------------------------------------------------
    def run(self, payloads: list[dict[str, Any]]) -> Iterator[tuple[int, dict[str, Any]]]:
        """Run ``payloads``; yields ``(index, result)`` as trials finish (their paths
        made relative to the shipped files when :meth:`connect` shipped them).

        Raises:
            BackendError: no node of the cluster can run trials.
        """
        if not payloads:
            return
        ray = self.ray
        from ray.util.scheduling_strategies import NodeAffinitySchedulingStrategy

        from petriflow.sweep.ship import requirements

        if self.bundle is not None:
            payloads = [self.bundle.relative(p) for p in payloads]
        actor_class = ray.remote(num_cpus=1, max_restarts=0, max_task_retries=0)(_RayWorker)
        python = _python()
        pending = deque(range(len(payloads)))
        tries: dict[int, int] = {}
        slots: list[_Slot] = []
        nodes: dict[str, dict[str, Any]] = {}
        needs_pip: set[str] = set()
        bad: dict[str, str] = {}
        looked = -math.inf
        stuck: float | None = None

        def start(node: str) -> None:
            pip = node in needs_pip
            options: dict[str, Any] = {"scheduling_strategy": NodeAffinitySchedulingStrategy(node, soft=False)}
            if pip:  # merged with the job's: its working directory and py_modules stay
                options["runtime_env"] = self.pip_env or {"pip": {"packages": requirements() + self.extra_pip,
                                                                  "pip_check": False}}
            actor = actor_class.options(**options).remote()
            slots.append(_Slot(actor, node, actor.ready.remote(), pip))

        def drop(slot: _Slot) -> None:
            slots.remove(slot)
            try:
                ray.kill(slot.actor, no_restart=True)
            except Exception:  # already gone with its node
                pass

        def give_up(node: str, why: str) -> None:
            if node not in bad:
                bad[node] = why
                self.log(f"ray: node {_node_name(nodes.get(node, {'NodeID': node}))} cannot run petriflow trials"
                         f" ({why}); no trial goes to it")
            for slot in [s for s in slots if s.node == node]:
                drop(slot)

        def failed(slot: _Slot, why: str) -> Iterator[tuple[int, dict[str, Any]]]:
            """The slot's trial met an infrastructure failure: again, or crashed."""
            index, wall = slot.job, wallclock.perf_counter() - slot.started
            assert index is not None
            tries[index] = tries.get(index, 0) + 1
            if tries[index] > self.retries:
                yield index, _failed("crashed", f"{why} (tried {tries[index]} times)", wall)
            else:
                pending.appendleft(index)

        try:
            while pending or any(s.job is not None for s in slots):
                now = wallclock.perf_counter()
                if now - looked >= _REFRESH:
                    looked = now
                    alive = {n["NodeID"]: n for n in ray.nodes() if n.get("Alive")}
                    for node in [n for n in nodes if n not in alive]:
                        lost = [s for s in slots if s.node == node]
                        busy = sum(s.job is not None for s in lost)
                        self.log(f"ray: node {_node_name(nodes[node])} is gone"
                                 + (f"; its {busy} trial{'s' if busy != 1 else ''} go back to the queue" if busy else ""))
                        for slot in lost:
                            if slot.job is not None:
                                yield from failed(slot, f"ray: node {_node_name(nodes[node])} died during the trial")
                            drop(slot)
                        del nodes[node]
                    nodes.update(alive)
                    # one actor per CPU of each usable node, at most --workers in all
                    usable = [n for n in nodes if n not in bad]
                    cap = self.workers or math.inf
                    room = min(cap, len(pending) + sum(s.job is not None for s in slots))
                    for node in usable:
                        cpus = int(nodes[node].get("Resources", {}).get("CPU", 0))
                        mine = [s for s in slots if s.node == node]
                        while len(mine) > cpus:
                            idle = [s for s in mine if s.job is None]
                            if not idle:
                                break
                            drop(idle[-1])
                            mine.remove(idle[-1])
                        for _ in range(cpus - len(mine)):
                            if len(slots) >= room:
                                break
                            start(node)
                    runnable = [n for n in usable if nodes[n].get("Resources", {}).get("CPU", 0) >= 1]
                    if pending and not slots and not runnable:
                        if bad:
                            raise BackendError("ray: no node of the cluster can run petriflow trials: " + "; ".join(
                                f"{_node_name(nodes.get(n, {'NodeID': n}))}: {why}" for n, why in bad.items()))
                        stuck = stuck if stuck is not None else now
                        if now - stuck > NO_NODE_WAIT:
                            raise BackendError(f"ray: the cluster has no node with a CPU for trials (waited"
                                               f" {NO_NODE_WAIT:g} s for one to join)")
                    else:
                        stuck = None
                # give trials to ready, idle actors
                for slot in slots:
                    if slot.ready and slot.job is None and pending:
                        index = pending.popleft()
                        slot.job, slot.started = index, wallclock.perf_counter()
                        slot.ref = slot.actor.run.remote(payloads[index])
                waiting = {s.probe: s for s in slots if not s.ready}
                waiting.update({s.ref: s for s in slots if s.job is not None})
                deadlines = [looked + _REFRESH]
                deadlines += [s.started + self.timeout for s in slots if s.job is not None]
                deadlines += [s.started + RAY_START_TIMEOUT for s in slots if not s.ready]
                wait_for = max(0.0, min(deadlines) - wallclock.perf_counter())
                if not waiting:
                    wallclock.sleep(wait_for)
                    continue
                done, _ = ray.wait(list(waiting), num_returns=1, timeout=wait_for)
                for ref in done:
                    slot = waiting[ref]
                    if slot not in slots:
                        continue
                    if not slot.ready:
                        try:
                            answer = ray.get(ref)
                        except Exception as exc:
                            if slot.node not in nodes:
                                drop(slot)
                            elif isinstance(exc, ray.exceptions.RuntimeEnvSetupError) or slot.pip:
                                give_up(slot.node, clean_error(exc, 2))
                            elif _MISSING.search(str(exc)):  # petriflow itself cannot be imported there
                                answer = {"error": f"ModuleNotFoundError: {_MISSING.search(str(exc)).group(0)}",
                                          "python": None}
                            else:
                                give_up(slot.node, clean_error(exc, 2))
                            if slot not in slots:
                                continue
                        if answer.get("python") not in (None, python):
                            give_up(slot.node, f"Python {answer['python']} there, {python} here: nodes and the"
                                               " driver need the same Python version")
                        elif answer["error"] is None:
                            slot.ready = True
                        elif slot.pip:
                            give_up(slot.node, answer["error"])
                        else:
                            node = slot.node
                            if node not in needs_pip:
                                needs_pip.add(node)
                                self.log(f"ray: node {_node_name(nodes[node])} lacks petriflow's dependencies"
                                         f" ({answer['error']}); installing them there with Ray's pip runtime"
                                         " environment (once per node)")
                            drop(slot)
                            start(node)
                        continue
                    index = slot.job
                    try:
                        result = ray.get(ref)
                    except ray.exceptions.RayTaskError as exc:  # raised in the trial's code, not caught there
                        slot.job = None
                        yield index, _failed("error", clean_error(exc), wallclock.perf_counter() - slot.started)
                        continue
                    except Exception as exc:  # the actor, its node or the result is gone
                        node = nodes.get(slot.node)
                        why = clean_error(exc, 1)
                        if node is None or "node" in why.lower() and "died" in why.lower():
                            why = f"ray: node {_node_name(node or {'NodeID': slot.node})} died during the trial"
                        elif isinstance(exc, ray.exceptions.RayActorError):
                            why = f"ray: the trial's worker process died ({why})"
                        else:  # ObjectLostError and the like
                            why = f"ray: the trial's result was lost ({why})"
                        yield from failed(slot, why)
                        drop(slot)
                        continue
                    slot.job = None
                    yield index, result
                now = wallclock.perf_counter()
                for slot in list(slots):
                    if slot.job is not None and now - slot.started >= self.timeout:
                        index = slot.job
                        drop(slot)
                        yield index, _failed("timeout", f"ran past the sweep's timeout of {self.timeout:g} s",
                                             now - slot.started)
                    elif not slot.ready and now - slot.started >= RAY_START_TIMEOUT:
                        give_up(slot.node, f"its worker did not start within {RAY_START_TIMEOUT:g} s")
        finally:
            for slot in list(slots):
                drop(slot)


def run_ray(payloads: list[dict[str, Any]], workers: int | None, timeout: float,
            address: str | None = None, *, bundle: Any = None, retries: int = RETRIES,
            pip: list[str] | None = None) -> Iterator[tuple[int, dict[str, Any]]]:
    """Run ``payloads`` on Ray (:class:`RayBackend`); yields ``(index, result)``.

    Args:
        workers: trials in flight at most (default: the cluster's CPUs, as they change).
        address: the cluster (``host:6379``, or ``ray://host:10001`` with
            ``ray[client]``); default ``RAY_ADDRESS``, else a local Ray instance
            started for this sweep.
        bundle: the sweep's files to ship (:func:`petriflow.sweep.ship.collect`).
    """
    if not payloads:
        return
    backend = RayBackend(workers, timeout, address, retries=retries, pip=pip)
    backend.connect(bundle)
    try:
        yield from backend.run(payloads)
    finally:
        backend.close()
