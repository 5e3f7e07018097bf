"""One trial of a sweep: build the run from plain data, run it, measure it.

:func:`run_trial` is what every backend calls, in a worker process or a Ray task. It
takes :meth:`Sweep.payload <petriflow.sweep.spec.Sweep.payload>` (plain data: file
names, parameters, a seed) and returns plain data, so nothing live crosses a process
boundary and the result depends only on the payload.

A trial applies the sweep's ``set:`` targets with the row's parameters substituted:

* ``run.KEY[.KEY...]`` into the run configuration (as its YAML would say it; list
  items by index: ``run.faults.0.at``);
* ``world.KEY[...]`` into the world description (``world.robots.1.position``);
* ``net.transitions.ID.params.KEY`` into a transition's action parameters, and
  ``net.initial.PLACE`` into the initial marking.

The run's wall-clock seconds (``RunRecord.wall``) and CPU seconds (``RunRecord.cpu``,
``time.process_time()``) are measured around the scheduler's run only, from entering it
to closing it: not the imports, reading and binding the net, loading the world,
building the scheduler, or computing the metrics.

Examples:
    >>> data = {"robots": [{"name": "r1", "position": [0, 0]}]}
    >>> set_path(data, "robots.0.position", [1, 2], "world")
    >>> data
    {'robots': [{'name': 'r1', 'position': [1, 2]}]}
"""

from __future__ import annotations

import importlib
import time as wallclock
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from petriflow.errors import NetFormatError, PetriflowError
from petriflow.runtime.metrics import plain_value
from petriflow.sweep.spec import substitute

__all__ = ["run_trial", "build", "Built", "set_path", "TrialError"]


class TrialError(PetriflowError):
    """A trial cannot be built from its sweep (a set target that names nothing...)."""


def set_path(data: Any, path: str, value: Any, root: str) -> None:
    """Set ``value`` at the dotted ``path`` in nested mappings and lists ``data``
    (a missing last key is created; a list item is named by its index)."""
    keys = path.split(".")
    node = data
    for depth, key in enumerate(keys):
        last = depth == len(keys) - 1
        where = ".".join([root, *keys[:depth + 1]])
        if isinstance(node, list):
            if not (key.isascii() and key.isdigit()) or len(key) > 18 or int(key) >= len(node):
                raise TrialError(f"set {root}.{path}: {where} is not an item of a list of {len(node)}")
            index = int(key)
            if last:
                node[index] = value
                return
            node = node[index]
        elif isinstance(node, dict):
            if last:
                node[key] = value
                return
            if key not in node or node[key] is None:
                node[key] = {}
            node = node[key]
        else:
            raise TrialError(f"set {root}.{path}: {where} is inside {type(node).__name__} {node!r}, not a mapping or list")


def _build_net(spec: dict[str, Any], params: dict[str, Any], values: dict[str, Any]):
    from petriflow.io.files import read_text_file
    from petriflow.net import Net
    from petriflow.runtime.loading import net_from_text

    net_spec = spec["net"]
    if isinstance(net_spec, dict):
        module_name, _, name = net_spec["builder"].partition(":")
        try:
            builder = getattr(importlib.import_module(module_name), name)
        except (ImportError, AttributeError) as exc:
            raise TrialError(f"net builder {net_spec['builder']!r}: {exc}") from None
        try:
            built = builder(**params)
        except (TypeError, ValueError, KeyError) as exc:  # the builder refuses these parameters
            raise TrialError(f"net builder {net_spec['builder']!r}: {exc}") from None
        where = Path(spec["path"])
        if isinstance(built, str):
            from petriflow.io.yaml import loads_net

            built = loads_net(built, path=f"{net_spec['builder']}({params})")
        if not isinstance(built, Net):
            raise TrialError(f"net builder {net_spec['builder']!r} returned {type(built).__name__}, not a Net or net text")
        return built, where
    path = Path(substitute(net_spec, values))
    if not path.is_file():
        raise NetFormatError("no such file", path=str(path))
    return net_from_text(read_text_file(path), str(path)), path


def _config(spec: dict[str, Any], net, net_path: Path, sets: dict[str, Any]):
    from petriflow.runtime.config import RunConfig, load_config
    from petriflow.runtime.loading import net_config

    if spec["run"] is not None:
        config = load_config(spec["run"])
    else:
        config = net_config(net, net_path) if net_path.is_file() else None
        if config is None and (net_path.parent / "run.yaml").is_file():
            config = load_config(net_path.parent / "run.yaml")
        config = config or RunConfig()
    if not sets:
        return config
    data = config.to_dict()
    if data.get("world") is None:
        del data["world"]
    for path, value in sets.items():
        set_path(data, path, value, "run")
    base = Path(config.path).parent if config.path else net_path.parent
    return RunConfig.from_dict(data, config.path or f"{spec['path']} (run)", base=str(base))


def _world_data(config, sets: dict[str, Any]) -> dict[str, Any] | None:
    if config.world is None:
        if sets:
            raise TrialError(f"set world.{next(iter(sets))}: the run has no world")
        return None
    from petriflow.io.files import read_yaml_file
    from petriflow.worldfile import check_world

    path = Path(config.world)
    data = read_yaml_file(path)
    for key, value in sets.items():
        set_path(data, key, value, "world")
    return check_world(data, str(path))


def _apply_net(net, sets: dict[str, Any]) -> None:
    for target, value in sets.items():
        kind, _, rest = target.partition(".")
        if kind == "initial":
            if rest not in net.places:
                raise TrialError(f"set net.initial.{rest}: no place {rest!r} in net {net.id!r}")
            marking = dict(net.initial_marking)
            marking[rest] = value
            net.set_initial_marking({p: n for p, n in marking.items() if n})
            continue
        tid, _, key = rest.partition(".params.")
        if tid not in net.transitions:
            raise TrialError(f"set net.transitions.{rest}: no transition {tid!r} in net {net.id!r}")
        set_path(net.transitions[tid].params, key, value, f"net.transitions.{tid}.params")


def _value(name: str, value: Any, into: dict[str, Any]) -> None:
    """Store a metric's value as plain data (:func:`petriflow.runtime.metrics.plain_value`)."""
    try:
        plain_value(name, value, into)
    except PetriflowError as exc:
        raise TrialError(str(exc)) from None


@dataclass
class Built:
    """A trial ready to run: the net bound, its run configuration, the world's description."""

    net: Any
    net_path: Path
    config: Any
    binding: Any
    world: dict[str, Any] | None
    metrics: list[tuple[str, Any, dict[str, Any]]]


def build(spec: dict[str, Any], params: dict[str, Any], seed: int) -> Built:
    """Everything a trial needs before it runs, checked: the net read (or built) and
    bound with the ``set:`` targets applied, the run configuration, the world's
    description (checked, not loaded: no pybullet), the metrics resolved.

    Raises:
        NetFormatError: a file is malformed or an action does not bind (``file:line``).
        TrialError: a set target names nothing, a metric is unknown.
    """
    from petriflow.runtime.binding import bind, check_sizes, check_world
    from petriflow.runtime.registry import UnknownActionError, default_registry

    values = dict(params, seed=seed)
    targets = {target: substitute(value, values) for target, value in spec["set"].items()}
    sets = {root: {t[len(root) + 1:]: v for t, v in targets.items() if t.startswith(root + ".")}
            for root in ("run", "world", "net")}
    net, net_path = _build_net(spec, params, values)
    _apply_net(net, sets["net"])
    config = _config(spec, net, net_path, sets["run"])
    config.import_actions()
    binding = bind(net, default_registry, path=str(net_path))
    config.check(net)
    check_sizes(net, str(net_path))
    check_world(binding, config.world is not None, str(net_path))
    metrics = []
    for name, metric, args in spec["metrics"]:
        try:
            metrics.append((name, default_registry.metric_spec(metric), dict(args)))
        except UnknownActionError as exc:
            raise TrialError(f"metrics: {name}: {exc}") from None
    return Built(net, net_path, config, binding, _world_data(config, sets["world"]), metrics)


def _measure(spec: dict[str, Any], params: dict[str, Any], seed: int) -> tuple[dict[str, Any], str, str | None]:
    from petriflow.runtime.metrics import RunRecord, event_kinds
    from petriflow.runtime.scheduler import Scheduler

    built = build(spec, params, seed)
    world = None
    if built.world is not None:
        from petriflow.world import World

        path = Path(built.config.world)
        world = World(built.world, base=path.resolve().parent, path=str(path))
    try:
        scheduler = Scheduler(built.net, world=world, config=built.config, seed=seed, binding=built.binding)
        events: list[Any] = []
        if any(m.events for _, m, _ in built.metrics):  # only the kinds they read
            scheduler.on_event(events.append, event_kinds(m for _, m, _ in built.metrics))
        # wall and CPU time of the run itself (RunRecord.cpu says what that includes)
        started, cpu_started = wallclock.perf_counter(), wallclock.process_time()
        with scheduler:
            result = scheduler.run()
        cpu = wallclock.process_time() - cpu_started
        wall = wallclock.perf_counter() - started
        record = RunRecord(result, events, world, built.config, dict(params), seed, wall, scheduler, cpu)
        measured: dict[str, Any] = {}
        for name, metric, args in built.metrics:
            try:
                value = metric.load()(record, **args)
            except TrialError:
                raise
            except Exception as exc:
                raise TrialError(f"metric {name} ({metric.name}): {type(exc).__name__}: {exc}") from None
            _value(name, value, measured)
    finally:
        if world is not None:
            world.close()
    return measured, str(getattr(result.reason, "value", result.reason)), result.error


def run_trial(payload: dict[str, Any]) -> dict[str, Any]:
    """Run one trial; never raises for a trial's own failure.

    Returns:
        ``{"status": "ok" | "error", "metrics": {name: value}, "outcome": reason,
        "error": one line or None (the trial's error, or the run's unrouted failure),
        "wall": seconds, "cpu": CPU seconds of this process (building, running, measuring)}``.
    """
    started, cpu_started = wallclock.perf_counter(), wallclock.process_time()
    try:
        metrics, outcome, error = _measure(payload["sweep"], payload["params"], payload["seed"])
        status = "ok"  # a run that ended failed is a measured run; its error is kept
    except PetriflowError as exc:
        metrics, outcome, status, error = {}, None, "error", str(exc)
    except (Exception, RecursionError) as exc:  # a trial's crash is its own row, the sweep goes on
        metrics, outcome, status, error = {}, None, "error", f"{type(exc).__name__}: {exc}"
    error = None if error is None else " ".join(error.split())[:2000]
    return {"status": status, "metrics": metrics, "outcome": outcome, "error": error,
            "wall": wallclock.perf_counter() - started, "cpu": wallclock.process_time() - cpu_started}
