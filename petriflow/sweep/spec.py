"""A sweep file: which net to run, over which parameters and seeds, measuring what.

The format is documented in ``docs/sweep-format.md``; in short::

    petriflow-sweep: 1
    net: ../smart.yaml            # relative to this file; ${param} allowed; or {builder: module:function}
    run: ../run.yaml              # optional: else the run configuration the net names
    trials: 10                    # seeds 1..10 (or seeds: [4, 8, 15])
    timeout: 120                  # wall seconds a trial may take (default 600)
    matrix:                       # every combination, first parameter slowest
      mode: [centralised, decentralised]
      kill_at: [60, 110]
    rows:                         # explicit rows, after the matrix's
      - {mode: central, kill_at: 0, paper: {time_s: 49}}
    set:                          # where the parameters go
      run.faults: [{kill: robot3, at: "${kill_at}"}]
      world.robots.0.position: [0.5, 0.5]
      net.transitions.plan.params.speed: "${speed}"
    metrics:                      # registered metrics, reported under their own name or another
      - core.end_time
      - time_s: {metric: core.time_of, transition: done}
    paper:                        # published values beside the measured ones
      source: Table 7
      rows:
        - {params: {mode: centralised}, values: {time_s: 55.2}}

A trial is one row's parameters and one seed; :meth:`Sweep.payload` is all a worker
needs to run it (plain data; absolute paths, made relative to the shipped files on a
cluster), so a trial's result depends only on
(sweep, parameters, seed), on any backend.

Examples:
    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "n.yaml").write_text("petriflow: 1\\nplaces: [p]\\n")
    >>> sweep = Sweep.from_dict({"petriflow-sweep": 1, "net": "n.yaml", "trials": 2,
    ...                          "matrix": {"a": [1, 2], "b": ["x", "y"]},
    ...                          "set": {"run.faults": [{"join": "${b}", "at": "${a}"}]}}, folder / "s.yaml")
    >>> [row.params for row in sweep.rows]
    [{'a': 1, 'b': 'x'}, {'a': 1, 'b': 'y'}, {'a': 2, 'b': 'x'}, {'a': 2, 'b': 'y'}]
    >>> len(sweep.trials()), sweep.trials()[1]
    (8, Trial(row=0, params={'a': 1, 'b': 'x'}, seed=2))
    >>> substitute({"at": "${a}", "name": "robot${a}"}, {"a": 3})
    {'at': 3, 'name': 'robot3'}
"""

from __future__ import annotations

import itertools
import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from petriflow.errors import NetFormatError
from petriflow.runtime.metrics import MetricRef, parse_refs

__all__ = ["Sweep", "Row", "Trial", "MetricRef", "substitute", "FORMAT_VERSION", "SET_ROOTS", "PAPER_STATUSES"]

#: The sweep format version this reader understands (``petriflow-sweep: 1``).
FORMAT_VERSION = 1
#: What a ``set:`` target may start with.
SET_ROOTS = ("run", "world", "net")
#: What a published value can be to a sweep: the simulation's output with no published
#: value used to get it; a published value was an input (the ``because`` says which); or
#: not reproduced (the ``because`` names the mechanism the source leaves unstated).
PAPER_STATUSES = ("predicted", "built-in", "missed")
#: Wall seconds a trial may take unless the file says otherwise.
DEFAULT_TIMEOUT = 600.0
#: The most trials one sweep may hold (rows x seeds).
MAX_TRIALS = 1_000_000

_KEYS = {"petriflow-sweep", "name", "net", "run", "trials", "seeds", "timeout", "matrix", "rows", "set",
         "metrics", "paper", "description"}
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
_PLACEHOLDER = re.compile(r"\$\{([^}]*)\}")
_RESERVED = {"seed"}


@dataclass(frozen=True)
class Trial:
    """One run of a sweep: a row's parameters and a seed."""

    row: int
    params: dict[str, Any]
    seed: int

    @property
    def key(self) -> str:
        """The trial's identity in a results database: its parameters (canonical JSON)."""
        return canonical(self.params)


@dataclass
class Row:
    """One row of the report: parameters, and the paper's values for it."""

    index: int
    params: dict[str, Any]
    paper: dict[str, Any] = field(default_factory=dict)
    #: per paper value: ``{"status": predicted | built-in | missed, "because": TEXT}``
    #: (a value given without a status has none here).
    paper_status: dict[str, dict[str, str]] = field(default_factory=dict)


def canonical(value: Any) -> str:
    """Canonical JSON (sorted keys, no spaces): equal data, equal text."""
    return json.dumps(value, sort_keys=True, separators=(",", ":"), allow_nan=False)


def placeholders(value: Any) -> set[str]:
    """The ``${name}`` placeholders anywhere in ``value``."""
    if isinstance(value, str):
        return set(_PLACEHOLDER.findall(value))
    if isinstance(value, dict):
        return set().union(*(placeholders(v) for v in value.values())) if value else set()
    if isinstance(value, list):
        return set().union(*(placeholders(v) for v in value)) if value else set()
    return set()


def substitute(value: Any, params: dict[str, Any]) -> Any:
    """``value`` with every ``${name}`` replaced by ``params[name]``: a string that is one
    placeholder becomes the parameter's value itself (a number stays a number), a
    placeholder inside a longer string is replaced by its text."""
    if isinstance(value, str):
        whole = _PLACEHOLDER.fullmatch(value)
        if whole:
            return params[whole.group(1)]
        return _PLACEHOLDER.sub(lambda m: str(params[m.group(1)]), value)
    if isinstance(value, dict):
        return {k: substitute(v, params) for k, v in value.items()}
    if isinstance(value, list):
        return [substitute(v, params) for v in value]
    return value


def _plain_value(value: Any) -> bool:
    """Whether ``value`` is data a sweep can carry: JSON types, finite numbers."""
    if value is None or isinstance(value, (bool, int, str)):
        return True
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, list):
        return all(_plain_value(v) for v in value)
    if isinstance(value, dict):
        return all(isinstance(k, str) and _plain_value(v) for k, v in value.items())
    return False


@dataclass
class Sweep:
    """A parsed, checked sweep file.

    Attributes:
        path: the file (absolute).
        name: its name (``name:``, else the file's stem).
        net: the net file (absolute, may hold ``${param}``), or ``{"builder": "module:function"}``.
        run: the run configuration file (absolute), or ``None`` for the net's own.
        seeds: the seeds every row is run with.
        timeout: wall seconds a trial may take.
        rows: the report's rows, in the file's order.
        set: ``{target: value}``: where parameters go.
        metrics: what each trial measures.
        paper_source: where the paper's values come from (``Table 7``).
    """

    path: str
    name: str
    net: str | dict[str, str]
    run: str | None
    seeds: list[int]
    timeout: float
    rows: list[Row]
    set: dict[str, Any]
    metrics: list[MetricRef]
    paper_source: str | None = None
    description: str | None = None
    lines: dict[str, int | None] = field(default_factory=dict, repr=False)
    shown: str = ""

    # Reading --------------------------------------------------------------------------
    @classmethod
    def from_dict(cls, data: Any, path: str | Path) -> "Sweep":
        """Check ``data`` (the parsed file) and build the sweep; errors name ``path`` and the line.

        Raises:
            NetFormatError: a key, value or parameter is wrong (with the line when known).
        """
        shown = str(path)
        path = str(Path(path).resolve())
        folder = Path(path).parent

        def fail(message: str, item: Any = None, key: str | None = None, element: str | None = None):
            line = getattr(item, "line", None)
            if line is None and key is not None:
                line = getattr(data, "key_lines", {}).get(key)
            if line is None:
                line = getattr(data, "line", None)
            raise NetFormatError(message, path=shown, line=line, element=element)

        if not isinstance(data, dict):
            fail("a sweep file is a mapping (petriflow-sweep: 1, net: ..., matrix: ...)")
        for key in data:
            if key not in _KEYS:
                from petriflow.errors import did_you_mean

                fail(f"unknown key {key!r}{did_you_mean(str(key), _KEYS)}", key=key)
        version = data.get("petriflow-sweep")
        if version is None:
            fail("not a sweep file: the key 'petriflow-sweep: 1' is missing")
        if isinstance(version, bool) or version != FORMAT_VERSION:
            fail(f"sweep format version {version!r} is not supported (this petriflow reads {FORMAT_VERSION})",
                 key="petriflow-sweep")

        name = data.get("name", Path(path).stem)
        if not isinstance(name, str) or not name:
            fail("name must be text", key="name")
        description = data.get("description")
        if description is not None and not isinstance(description, str):
            fail("description must be text", key="description")

        # the net: a file (placeholders allowed) or a builder
        net = data.get("net")
        if isinstance(net, str) and net.strip():
            net_value: str | dict[str, str] = str(folder / net)
            if not _PLACEHOLDER.search(net) and not Path(net_value).is_file():
                fail(f"net {net!r} not found (looked for {net_value})", key="net")
        elif isinstance(net, dict) and set(net) == {"builder"} and isinstance(net["builder"], str) \
                and re.fullmatch(r"[A-Za-z_][\w.]*:[A-Za-z_]\w*", net["builder"]):
            net_value = {"builder": net["builder"]}
        else:
            fail("net must be a file name (relative to the sweep file, ${param} allowed) or"
                 " {builder: module:function}", key="net")

        run = data.get("run")
        if run is not None:
            if not isinstance(run, str) or not run.strip():
                fail("run must be the name of a run configuration file", key="run")
            run = str((folder / run).resolve())
            if not Path(run).is_file():
                fail(f"run configuration {data['run']!r} not found (looked for {run})", key="run")

        seeds = _seeds(data, fail)
        timeout = data.get("timeout", DEFAULT_TIMEOUT)
        if isinstance(timeout, bool) or not isinstance(timeout, (int, float)) or not 0 < timeout < math.inf:
            fail(f"timeout must be a positive number of wall seconds, not {timeout!r}", key="timeout")

        rows = _rows(data, fail)
        if len(rows) * len(seeds) > MAX_TRIALS:
            fail(f"{len(rows)} rows x {len(seeds)} seeds is more than {MAX_TRIALS:,} trials")
        names = set().union(*(row.params for row in rows)) if rows else set()

        targets = data.get("set", {})
        if not isinstance(targets, dict):
            fail("set must map targets (run.KEY, world.KEY, net.transitions.ID.params.KEY) to values", key="set")
        for target, value in targets.items():
            item = targets
            if not isinstance(target, str) or target.split(".")[0] not in SET_ROOTS or "." not in target \
                    or "" in target.split("."):
                fail(f"set target {target!r} must start with run., world. or net.", item=item, key="set")
            if target.startswith("net.") and not (
                re.fullmatch(r"net\.transitions\.[^.]+\.params(\.[^.]+)+", target)
                or re.fullmatch(r"net\.initial\.[^.]+", target)
            ):
                fail(f"set target {target!r}: a net's parameters are net.transitions.ID.params.KEY"
                     " and its initial tokens net.initial.PLACE", key="set")
            if not _plain_value(value):
                fail(f"set {target}: the value must be plain data (text, finite numbers, lists, mappings)", key="set")

        used = placeholders(list(targets.values())) | (placeholders(net) if isinstance(net, str) else set())
        for row in rows:
            missing = sorted(used - set(row.params) - _RESERVED)
            if missing:
                fail(f"row {row.index + 1} ({canonical(row.params)}) has no value for ${{{missing[0]}}}",
                     key="rows" if "rows" in data else "matrix")
        unused = sorted(names - used)
        if unused and isinstance(net_value, str):
            # a parameter that goes nowhere would make rows that differ only by name
            fail(f"parameter {unused[0]!r} is not used: name it in set: (\"${{{unused[0]}}}\") or in the net's"
                 " file name", key="set" if "set" in data else ("matrix" if "matrix" in data else "rows"))

        metrics = _metrics(data, fail)
        paper_source = _paper(data, rows, {m.name for m in metrics}, fail)
        lines = {key: getattr(data, "key_lines", {}).get(key) for key in _KEYS}
        return cls(path, name, net_value, run, seeds, float(timeout), rows, dict(targets), metrics,
                   paper_source, description, lines, shown)

    # Using ----------------------------------------------------------------------------
    def with_seeds(self, trials: int) -> "Sweep":
        """The same sweep run with seeds 1..``trials``."""
        from dataclasses import replace

        return replace(self, seeds=list(range(1, trials + 1)))

    def trials(self) -> list[Trial]:
        """Every trial, row by row, seed by seed."""
        return [Trial(row.index, row.params, seed) for row in self.rows for seed in self.seeds]

    def to_data(self) -> dict[str, Any]:
        """Plain data: what a worker needs to run a trial (no live objects)."""
        return {"path": self.path, "name": self.name, "net": self.net, "run": self.run, "set": self.set,
                "metrics": [[m.name, m.metric, m.params] for m in self.metrics], "timeout": self.timeout}

    def payload(self, trial: Trial) -> dict[str, Any]:
        """What a worker runs: :func:`petriflow.sweep.trial.run_trial` of this."""
        return {"sweep": self.to_data(), "row": trial.row, "params": trial.params, "seed": trial.seed}

    @property
    def parameters(self) -> list[str]:
        """The parameter names, in the order of the first row that has each."""
        names: list[str] = []
        for row in self.rows:
            names += [n for n in row.params if n not in names]
        return names


def _seeds(data: dict, fail) -> list[int]:
    if "trials" in data and "seeds" in data:
        fail("give trials: K (seeds 1..K) or seeds: [...], not both", key="seeds")
    if "seeds" in data:
        seeds = data["seeds"]
        if not isinstance(seeds, list) or not seeds or any(
                isinstance(s, bool) or not isinstance(s, int) or not 0 <= s < 2 ** 63 for s in seeds):
            fail("seeds must be a non-empty list of integers >= 0", key="seeds")
        if len(set(seeds)) != len(seeds):
            fail("seeds are listed twice", key="seeds")
        return list(seeds)
    trials = data.get("trials", 1)
    if isinstance(trials, bool) or not isinstance(trials, int) or not 1 <= trials <= MAX_TRIALS:
        fail(f"trials must be an integer from 1 to {MAX_TRIALS:,}, not {trials!r}", key="trials")
    return list(range(1, trials + 1))


def _check_params(params: Any, fail, item: Any, where: str) -> dict[str, Any]:
    if not isinstance(params, dict):
        fail(f"{where}: parameters are a mapping name: value", item=item)
    for name, value in params.items():
        if not isinstance(name, str) or not _NAME.match(name) or name in _RESERVED | {"paper"}:
            fail(f"{where}: {name!r} is not a parameter name (letters, digits, _; not seed or paper)", item=item)
        if not _plain_value(value):
            fail(f"{where}: {name}: the value must be plain data (text, finite numbers, lists, mappings)",
                 item=item)
    return dict(params)


def _rows(data: dict, fail) -> list[Row]:
    rows: list[Row] = []
    matrix = data.get("matrix")
    if matrix is not None:
        if not isinstance(matrix, dict) or not matrix:
            fail("matrix must map each parameter to a list of values", key="matrix")
        for name, values in matrix.items():
            if not isinstance(values, list) or not values:
                fail(f"matrix: {name!r} needs a non-empty list of values", item=matrix, key="matrix")
            if len({canonical(v) for v in values if _plain_value(v)}) != len(values):
                fail(f"matrix: {name!r} lists a value twice (or one that is not plain data)", key="matrix")
        _check_params({k: v[0] for k, v in matrix.items()}, fail, matrix, "matrix")
        size = math.prod(len(v) for v in matrix.values())
        if size > MAX_TRIALS:
            fail(f"matrix has {size:,} rows (at most {MAX_TRIALS:,})", key="matrix")
        for combination in itertools.product(*matrix.values()):
            params = dict(zip(matrix, combination))
            _check_params(params, fail, matrix, "matrix")
            rows.append(Row(len(rows), params))
    explicit = data.get("rows")
    if explicit is not None:
        if not isinstance(explicit, list) or not explicit:
            fail("rows must be a non-empty list of parameter mappings", key="rows")
        for entry in explicit:
            if not isinstance(entry, dict):
                fail("rows: each row is a mapping of parameters (and paper: {metric: value})", item=entry,
                     key="rows")
            params = {k: v for k, v in entry.items() if k != "paper"}
            paper = entry.get("paper", {})
            if not isinstance(paper, dict):
                fail("rows: paper must map metric names to values", item=entry)
            row = Row(len(rows), _check_params(params, fail, entry, f"row {len(rows) + 1}"))
            for name, value in paper.items():
                row.paper[name], status = _paper_value(name, value, None, fail, paper)
                if status:
                    row.paper_status[name] = status
            rows.append(row)
    if not rows:
        rows.append(Row(0, {}))
    seen: dict[str, int] = {}
    for row in rows:
        key = canonical(row.params)
        if key in seen:
            fail(f"row {row.index + 1} repeats the parameters of row {seen[key] + 1}: {key}",
                 key="rows" if explicit is not None else "matrix")
        seen[key] = row.index
    names = [sorted(row.params) for row in rows]
    if any(n != names[0] for n in names):
        fail("every row must set the same parameters"
             f" (row 1: {', '.join(names[0]) or 'none'}; another: {', '.join(next(n for n in names if n != names[0])) or 'none'})",
             key="rows" if explicit is not None else "matrix")
    return rows


def _metrics(data: dict, fail) -> list[MetricRef]:
    return parse_refs(data.get("metrics", ["core.end_time", "core.firings", "core.outcome"]), fail)


def _paper_value(name: Any, value: Any, default: dict[str, str] | None, fail, item: Any) \
        -> tuple[Any, dict[str, str] | None]:
    """A published value and its status: ``value`` is a number or text, or
    ``{value: V, status: S, because: TEXT}``; ``default`` is the paper row's own
    ``status``/``because`` (for values that give none)."""
    where = f"paper: {name}"
    status = default
    if isinstance(value, dict):
        unknown = sorted(set(value) - {"value", "status", "because"})
        if unknown or "value" not in value:
            fail(f"{where}: a value with a status is {{value: V, status: {' | '.join(PAPER_STATUSES)},"
                 f" because: TEXT}}" + (f" (unknown key {unknown[0]!r})" if unknown else " (no value:)"),
                 item=value)
        status = _status(value, where, fail, value, inherited=default)
        value = value["value"]
    elif isinstance(item, dict) and getattr(item, "key_lines", None):
        item = _Where(item.key_lines.get(name, getattr(item, "line", None)))
    if not _plain_value(value) or isinstance(value, (list, dict)):
        fail(f"{where}: a value is a number or text", item=item)
    return value, status


@dataclass
class _Where:
    """A line to name in an error."""

    line: int | None


def _status(holder: dict, where: str, fail, item: Any, inherited: dict[str, str] | None = None) \
        -> dict[str, str] | None:
    """``{"status", "because"}`` from ``holder``'s ``status:`` and ``because:`` (or
    ``inherited`` where it gives neither); ``None`` where there is none."""
    if "status" not in holder and "because" not in holder:
        return inherited
    status = holder.get("status", (inherited or {}).get("status"))
    because = holder.get("because", (inherited or {}).get("because") if "status" not in holder else None)
    if status not in PAPER_STATUSES:
        fail(f"{where}: status must be one of {', '.join(PAPER_STATUSES)}, not {status!r}", item=item)
    if because is not None and (not isinstance(because, str) or not because.strip()):
        fail(f"{where}: because must be text", item=item)
    if status != "predicted" and because is None:
        fail(f"{where}: a {status} value needs because: (which published value went in, or which mechanism"
             " the paper leaves unstated)", item=item)
    return {"status": status, "because": " ".join(because.split())} if because else {"status": status}


def _paper(data: dict, rows: list[Row], metric_names: set[str], fail) -> str | None:
    paper = data.get("paper")
    source = None
    if paper is not None:
        if not isinstance(paper, dict) or not set(paper) <= {"source", "rows"}:
            fail("paper must be {source: TEXT, rows: [{params: {...}, values: {metric: value}}]}", key="paper")
        source = paper.get("source")
        if source is not None and not isinstance(source, str):
            fail("paper: source must be text", key="paper")
        entries = paper.get("rows", [])
        if not isinstance(entries, list):
            fail("paper: rows must be a list", key="paper")
        for entry in entries:
            if not isinstance(entry, dict) or not set(entry) <= {"params", "values", "status", "because"} \
                    or not isinstance(entry.get("params", {}), dict) or not isinstance(entry.get("values"), dict):
                fail("paper: each row is {params: {name: value}, values: {metric: value}} (and optionally"
                     " status:, because: for its values)", item=entry, key="paper")
            params = entry.get("params", {})
            matched = [row for row in rows if all(k in row.params and row.params[k] == v for k, v in params.items())]
            if not matched:
                fail(f"paper: no row has the parameters {canonical(params)}", item=entry, key="paper")
            default = _status(entry, f"paper: row {canonical(params)}", fail, entry)
            values = entry["values"]
            parsed = {name: _paper_value(name, value, default, fail, values) for name, value in values.items()}
            for row in matched:
                for name, (value, status) in parsed.items():
                    row.paper[name] = value
                    if status:
                        row.paper_status[name] = status
                    else:
                        row.paper_status.pop(name, None)
    for row in rows:
        for name, value in row.paper.items():
            if not any(name == m or name.startswith(m + ".") for m in metric_names):
                from petriflow.errors import did_you_mean

                fail(f"paper: {name!r} is not one of the sweep's metrics{did_you_mean(name, metric_names)}",
                     key="paper" if paper is not None else "rows")
    return source
