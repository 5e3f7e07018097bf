"""Metrics: numbers computed from a finished run, registered by name like actions.

A sweep file names the metrics it wants (``metrics: [core.end_time, core.messages]``);
each is a function ``f(record, **params)`` of a :class:`RunRecord` (the run's result,
its events, the final tokens, the world, the run configuration) that returns a number,
a string, ``None`` (not measured in this run), or a flat ``{key: number}`` mapping
(reported as ``name.key``). A metric depends only on what the run did, never on the
wall clock, unless it is registered ``wall_clock=True`` (``core.wall_s``,
``core.cpu_s_per_sim_s``: reports mark them), so the same (net, parameters, seed) gives
the same value on every machine and backend.

Register one with :func:`petriflow.metric` (or ``registry.metric``) in an action
module or a plugin; ``events=True`` makes the run keep its events in memory for it,
``events=("message",)`` only the events of those kinds (the others are not even built)::

    from petriflow import metric

    @metric("bidding.messages", events=("message",))
    def messages(record):
        return sum(1 for e in record.events if e.kind == "message")

Core metrics:

=========================  =============================================================
``core.end_time``          simulated seconds at the end of the run
``core.firings``           transitions fired
``core.outcome``           why the run ended (``final``, ``until``, ``dead``, ...)
``core.completed``         1 if the run reached the net's final marking, else 0
``core.tokens``            tokens in ``place`` at the end
``core.fired``             firings of ``transition`` (and ``outcome``, if given)
``core.time_of``           simulated time ``transition`` first (``which: last``) ended
``core.result``            a field of ``transition``'s result (first or last ok firing)
``core.reported``          a value actions reported with ``ctx.emit(name, field=...)``
``core.messages``          messages sent / delivered / lost / bytes (``channel``, ``agent``)
``core.messages_per_channel``  the same per channel (``radio.sent``, ...)
``core.messages_per_agent``    the same per sending agent (``robot1.sent``, ...)
``core.wall_s``            wall-clock seconds of the run (not reproducible)
``core.cpu_s_per_sim_s``   CPU seconds the run took per simulated second (not
                           reproducible): :attr:`RunRecord.cpu` over ``core.end_time``;
                           ``None`` when the run took no simulated time
=========================  =============================================================

Examples:
    >>> from petriflow.runtime.trace import Event
    >>> record = RunRecord(events=[
    ...     Event(0, 0.0, "message", None, "r1", {"fate": "sent", "channel": "radio", "size": 10}),
    ...     Event(1, 0.0, "message", None, "r2", {"fate": "lost", "channel": "radio", "size": 4}),
    ...     Event(2, 0.1, "message", None, "r1", {"fate": "delivered", "channel": "radio"})])
    >>> messages(record)
    {'sent': 2, 'delivered': 1, 'lost': 1, 'bytes': 14}
    >>> messages_per_agent(record)["r2.lost"]
    1
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Any, Iterable

from petriflow.errors import PetriflowError

__all__ = ["RunRecord", "MetricRef", "register", "parse_refs", "measure", "plain_value", "event_kinds", "messages",
           "messages_per_agent", "messages_per_channel", "cpu_s_per_sim_s"]


@dataclass
class RunRecord:
    """What a metric sees of a finished run.

    Attributes:
        result: how the run ended (:class:`~petriflow.runtime.result.RunResult`).
        events: the run's events (kept only when a metric asked for them).
        world: the world at the end (still open), or ``None``.
        config: the run configuration.
        params: the sweep parameters of this trial.
        seed: the run seed.
        wall: wall-clock seconds the run took.
        scheduler: the scheduler, for anything else (channels, faults, agents).
        cpu: CPU seconds the run took (``time.process_time()`` around the scheduler's
            run, from entering it to closing it): user and system time of every thread
            of the trial's process, so the scheduler, the actions, the world's physics,
            the channels and keeping the events a metric asked for; not the imports,
            reading and binding the net, loading the world, building the scheduler, or
            computing metrics, nor the sweep's parent process. ``None`` when not
            measured (a record built outside a sweep trial).
    """

    result: Any = None
    events: list[Any] = field(default_factory=list)
    world: Any = None
    config: Any = None
    params: dict[str, Any] = field(default_factory=dict)
    seed: int | None = None
    wall: float = 0.0
    scheduler: Any = None
    cpu: float | None = None

    @property
    def settings(self) -> Any:
        """``{section: {name: value}}``: the world file's settings the run's actions (and
        their resources) declare, checked when the world was loaded (empty without a
        scheduler). A metric reads a scenario's settings here, not in ``world.meta``."""
        return {} if self.scheduler is None else self.scheduler.settings

    def section(self, section: Any) -> dict[str, Any]:
        """The values of the declared settings ``section`` (a
        :class:`~petriflow.runtime.settings.Section`) for this run: as the run read them
        (:attr:`settings`), else read now from the record's world file (a record made by
        hand from a run's outcome and its world), else its defaults.

        Raises:
            NetFormatError: the world's settings do not check (``file:line``).
        """
        if section.name in self.settings:
            return dict(self.settings[section.name])
        from petriflow.capabilities import Described, provides

        if not provides(self.world, Described):
            return section.read(None)
        return section.read((self.world.meta or {}).get(section.name), path=self.world.path)

    @property
    def tokens(self) -> dict[str, list[Any]]:
        """``{place: [data, ...]}`` at the end."""
        return getattr(self.result, "tokens", {}) or {}


def event_kinds(specs: Iterable[Any]) -> list[str] | None:
    """The event kinds a run must keep for these metric specs: ``None`` for every kind
    (one of them reads them all), else the kinds they name, in a fixed order (empty:
    none reads events)."""
    kinds: set[str] = set()
    for spec in specs:
        if spec.events is True:
            return None
        if spec.events:
            kinds.update(spec.events)
    return sorted(kinds)


def end_time(record: RunRecord) -> float:
    """Simulated seconds at the end of the run."""
    return record.result.time


def firings(record: RunRecord) -> int:
    """Transitions fired."""
    return record.result.firings


def outcome(record: RunRecord) -> str:
    """Why the run ended: final, until, dead, firings, failed, stalled."""
    return str(getattr(record.result.reason, "value", record.result.reason))


def completed(record: RunRecord) -> int:
    """1 if the run reached the net's final marking, else 0."""
    return int(outcome(record) == "final")


def tokens(record: RunRecord, place: str) -> int:
    """Tokens in ``place`` at the end."""
    return record.result.marking[place]


def fired(record: RunRecord, transition: str, outcome: str | None = None) -> int:
    """Firings of ``transition`` that ended (with ``outcome``, if given)."""
    return sum(1 for e in record.events if e.kind == "end" and e.transition == transition
               and (outcome is None or e.data.get("outcome") == outcome))


def time_of(record: RunRecord, transition: str, which: str = "first") -> float | None:
    """Simulated time at which ``transition`` first (``which: last``: last) ended ok."""
    if which not in ("first", "last"):
        raise PetriflowError(f"core.time_of: which must be 'first' or 'last', not {which!r}")
    times = [e.time for e in record.events if e.kind == "end" and e.transition == transition
             and e.data.get("outcome", "ok") == "ok"]
    if not times:
        return None
    return times[0] if which == "first" else times[-1]


def result(record: RunRecord, transition: str, field: str, which: str = "first") -> Any:
    """``field`` of the result of ``transition``'s first (``which: last``: last) firing
    that ended ok (a dotted ``field`` reaches into nested results)."""
    if which not in ("first", "last"):
        raise PetriflowError(f"core.result: which must be 'first' or 'last', not {which!r}")
    ends = [e for e in record.events if e.kind == "end" and e.transition == transition
            and e.data.get("outcome", "ok") == "ok"]
    if not ends:
        return None
    value = (ends[0] if which == "first" else ends[-1]).data.get("result")
    for key in field.split("."):
        if not isinstance(value, dict) or key not in value:
            return None
        value = value[key]
    return value


_REDUCE = {
    "first": lambda values: values[0],
    "last": lambda values: values[-1],
    "sum": sum,
    "max": max,
    "min": min,
    "mean": lambda values: sum(values) / len(values),
}


def reported(record: RunRecord, name: str, field: str | None = None, reduce: str = "last") -> Any:
    """A value actions reported with ``ctx.emit(name, field=value)``: ``reduce`` (first,
    last, sum, max, min, mean, count) over every report; ``field`` omitted: the
    simulated time of the report (``count``: how many there were)."""
    if reduce != "count" and reduce not in _REDUCE:
        raise PetriflowError(f"core.reported: reduce must be one of count, {', '.join(_REDUCE)}; not {reduce!r}")
    values = []
    for event in record.events:
        if event.kind != "custom" or event.data.get("name") != name:
            continue
        if field is None:
            values.append(event.time)
            continue
        data = event.data.get("data")
        if isinstance(data, dict) and field in data:
            values.append(data[field])
    if reduce == "count":
        return len(values)
    return _REDUCE[reduce](values) if values else None


def _count(record: RunRecord, key) -> dict[Any, Counter]:
    counts: dict[Any, Counter] = {}
    for event in record.events:
        if event.kind != "message":
            continue
        group = key(event)
        if group is None:
            continue
        counter = counts.setdefault(group, Counter(sent=0, delivered=0, lost=0, bytes=0))
        fate = event.data.get("fate")
        if fate == "sent" or (fate == "lost" and not event.data.get("in_flight")):
            # every message put into a channel is sent or lost then (one a medium lost in flight was sent)
            counter["sent"] += 1
            counter["bytes"] += event.data.get("size", 0)
        if fate in ("delivered", "lost"):
            counter[fate] += 1
    return counts


def messages(record: RunRecord, channel: str | None = None, agent: str | None = None) -> dict[str, int]:
    """Messages put into channels (``sent``, lost ones included), ``delivered``,
    ``lost`` and ``bytes`` sent; only ``channel``'s or ``agent``'s when given."""
    counts = _count(record, lambda e: 0 if ((channel is None or e.data.get("channel") == channel)
                                            and (agent is None or e.agent == agent)) else None)
    return dict(counts.get(0, Counter(sent=0, delivered=0, lost=0, bytes=0)))


def _flat(counts: dict[Any, Counter]) -> dict[str, int]:
    return {f"{group}.{k}": v for group in sorted(counts, key=str) for k, v in counts[group].items()}


def messages_per_channel(record: RunRecord) -> dict[str, int]:
    """:func:`messages` per channel: ``{"radio.sent": n, ...}``."""
    return _flat(_count(record, lambda e: e.data.get("channel")))


def messages_per_agent(record: RunRecord) -> dict[str, int]:
    """:func:`messages` per sending agent: ``{"robot1.sent": n, ...}``."""
    return _flat(_count(record, lambda e: e.agent))


def wall_s(record: RunRecord) -> float:
    """Wall-clock seconds the run took (not reproducible: depends on the machine)."""
    return record.wall


def cpu_s_per_sim_s(record: RunRecord) -> float | None:
    """CPU seconds of the run per simulated second (not reproducible: depends on the
    machine and its load); ``None`` when the CPU time was not measured or the run took
    no simulated time."""
    if record.cpu is None or not record.result.time > 0:
        return None
    return record.cpu / record.result.time


def register(registry: Any) -> None:
    """Register the core metrics in ``registry``."""
    for name, function, events in (
        ("core.end_time", end_time, False),
        ("core.firings", firings, False),
        ("core.outcome", outcome, False),
        ("core.completed", completed, False),
        ("core.tokens", tokens, False),
        ("core.fired", fired, True),
        ("core.time_of", time_of, True),
        ("core.result", result, True),
        ("core.reported", reported, True),
        ("core.messages", messages, True),
        ("core.messages_per_channel", messages_per_channel, True),
        ("core.messages_per_agent", messages_per_agent, True),
        ("core.wall_s", wall_s, False),
        ("core.cpu_s_per_sim_s", cpu_s_per_sim_s, False),
    ):
        registry.register_metric(name, function, events=events,
                                 wall_clock=name in ("core.wall_s", "core.cpu_s_per_sim_s"))


# Naming metrics in files, and measuring them -------------------------------------------

@dataclass(frozen=True)
class MetricRef:
    """A metric a file asks for: reported as ``name``, the registered ``metric`` with ``params``."""

    name: str
    metric: str
    params: dict[str, Any] = field(default_factory=dict)


_REF_HELP = ("each entry is a registered metric name, or {name: metric} or"
             " {name: {metric: NAME, PARAM: VALUE}}")


def parse_refs(given: Any, fail: Any, key: str = "metrics") -> list[MetricRef]:
    """The metrics a sweep file or a run configuration names, checked for form (not
    against a registry). ``fail(message, item=..., key=...)`` raises the file's error.

    Examples:
        >>> def fail(message, **where): raise ValueError(message)
        >>> [r.name for r in parse_refs(["core.end_time", {"bytes": "core.messages"}], fail)]
        ['core.end_time', 'bytes']
        >>> parse_refs([{"t": {"metric": "core.time_of", "transition": "done"}}], fail)[0].params
        {'transition': 'done'}
    """
    import re

    entries: list[tuple[Any, Any]] = []
    if isinstance(given, dict):
        entries = list(given.items())
    elif isinstance(given, list) and given:
        for entry in given:
            if isinstance(entry, str):
                entries.append((entry, entry))
            elif isinstance(entry, dict) and len(entry) == 1:
                entries.append(next(iter(entry.items())))
            else:
                fail(f"{key}: {_REF_HELP}", item=entry, key=key)
    else:
        fail(f"{key} must be a non-empty list or mapping of registered metrics", key=key)
    refs: list[MetricRef] = []
    for name, spec in entries:
        if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z_][\w.\-]*", name):
            fail(f"{key}: {name!r} is not a metric name", key=key)
        if isinstance(spec, str):
            metric, params = spec, {}
        elif isinstance(spec, dict) and isinstance(spec.get("metric"), str):
            metric, params = spec["metric"], {k: v for k, v in spec.items() if k != "metric"}
            if not _plain(params):
                fail(f"{key}: {name}: parameters must be plain data", item=spec, key=key)
        else:
            fail(f"{key}: {name}: give a registered metric name or {{metric: NAME, ...}}", item=spec, key=key)
        if any(r.name == name for r in refs):
            fail(f"{key}: {name!r} is listed twice", key=key)
        refs.append(MetricRef(name, metric, dict(params)))
    return refs


def _plain(value: Any) -> bool:
    """Whether ``value`` is plain data (what a YAML file holds)."""
    if value is None or isinstance(value, (bool, int, float, str)):
        return True
    if isinstance(value, (list, tuple)):
        return all(_plain(v) for v in value)
    if isinstance(value, dict):
        return all(isinstance(k, str) and _plain(v) for k, v in value.items())
    return False


def plain_value(name: str, value: Any, into: dict[str, Any]) -> None:
    """Store a metric's value in ``into`` as plain data: numbers, text or ``None``; a
    mapping flattened to ``name.key``; non-finite floats as ``None``."""
    import math

    if isinstance(value, dict):
        for key, item in value.items():
            plain_value(f"{name}.{key}", item, into)
        return
    if hasattr(value, "item") and not isinstance(value, (str, bytes)):  # numpy scalars
        value = value.item()
    if isinstance(value, bool):
        value = int(value)
    if isinstance(value, float) and not math.isfinite(value):
        value = None
    if value is not None and not isinstance(value, (int, float, str)):
        raise PetriflowError(f"metric {name}: returned {type(value).__name__}, not a number, text or mapping")
    into[name] = value


def measure(resolved: list[tuple[MetricRef, Any]], record: RunRecord) -> dict[str, Any]:
    """Each metric of ``resolved`` (``(ref, MetricSpec)`` pairs) computed on ``record``,
    as plain values under the refs' names (mappings flattened)."""
    measured: dict[str, Any] = {}
    for ref, spec in resolved:
        try:
            value = spec.load()(record, **ref.params)
        except PetriflowError as exc:
            raise PetriflowError(f"metric {ref.name} ({spec.name}): {exc}") from None
        except Exception as exc:
            raise PetriflowError(f"metric {ref.name} ({spec.name}): {type(exc).__name__}: {exc}") from None
        plain_value(ref.name, value, measured)
    return measured
