"""A sweep's report: per row, each metric's mean, standard deviation and count over the
trials that ran, beside the paper's value; as text, JSON, CSV or a plot.

Examples:
    >>> from petriflow.sweep.spec import Row
    >>> rows = [Row(0, {"n": 1}, {"t": 9.0})]
    >>> trials = [{"row": 0, "status": "ok", "metrics": {"t": 10.0}},
    ...           {"row": 0, "status": "ok", "metrics": {"t": 12.0}},
    ...           {"row": 0, "status": "timeout", "metrics": {}}]
    >>> summary(rows, trials, ["t"])[0]
    {'params': {'n': 1}, 'trials': 3, 'failed': 1, 'status': {'ok': 2, 'timeout': 1}, 'metrics': {'t': {'mean': 11.0, 'sd': 1.414214, 'n': 2}}, 'paper': {'t': 9.0}, 'paper_status': {}}

A published value's status (``paper_status``, from the sweep file) is ``predicted``,
``built-in`` or ``missed`` (:data:`petriflow.sweep.spec.PAPER_STATUSES`), with the
reason (``because``); the text table shows it beside the value and lists the reasons
under the table (:func:`status_notes`). The file declares it; the measurement has the
last word (:func:`judge`): a value declared ``predicted`` whose measured mean is off by
more than :data:`TOLERANCE` of the published value *and* by more than two standard
deviations of the trials is reported ``missed`` (with the file's ``because`` if it gives
one, else as a miss with no mechanism stated, counted apart: ``unexplained``); built in
and missed values keep their status whatever the deviation.

A trial's status is ``ok``, ``run failed`` (it ran, and the run ended ``failed``: an
action failed with no failure route), ``error`` (it could not run: a bad parameter, a
metric that raised), ``crashed`` (its worker process died) or ``timeout`` (it ran past
the sweep's timeout). Every status but ``ok`` counts as failed, in the table, in the
JSON and in the exit code (1 when any trial failed).
"""

from __future__ import annotations

import csv
import json
import math
from collections import Counter
from pathlib import Path
from typing import Any

from petriflow.sweep.spec import Row

__all__ = ["summary", "metric_names", "text_table", "write_csv", "plot", "trial_status", "fixed", "deviation",
           "status_label", "status_notes", "status_counts", "judge", "TOLERANCE", "SPREADS", "COUNTED"]

#: A predicted value stays predicted while the measured mean is within this share of the
#: published value (or within :data:`SPREADS` standard deviations of the trials).
TOLERANCE = 0.25
#: ... or within this many standard deviations of the measured trials.
SPREADS = 2.0
#: What :func:`status_counts` counts: the statuses, the misses with no mechanism stated
#: (a part of ``missed``) and the values with no status.
COUNTED = ("predicted", "built-in", "missed", "unexplained", "unstated")

#: A trial that ran and whose run ended ``failed`` (an action failure with no route).
RUN_FAILED = "run failed"


def trial_status(trial: dict[str, Any]) -> str:
    """A trial's status for reports (see the module)."""
    if trial["status"] == "ok" and trial.get("outcome") == "failed":
        return RUN_FAILED
    return trial["status"]


def metric_names(declared: list[str], trials: list[dict[str, Any]]) -> list[str]:
    """Names reported: each declared metric, or its ``name.key`` parts when it gave a mapping."""
    seen: list[str] = []
    for trial in trials:
        for key in trial["metrics"]:
            if key not in seen:
                seen.append(key)
    names: list[str] = []
    for name in declared:
        parts = [k for k in seen if k == name or k.startswith(name + ".")]
        names += parts or [name]
    return names


def _stats(values: list[Any]) -> dict[str, Any]:
    numbers = [v for v in values if isinstance(v, (int, float)) and not isinstance(v, bool)]
    texts = [v for v in values if isinstance(v, str)]
    if texts and not numbers:
        return {"mean": None, "sd": None, "n": len(texts), "counts": dict(sorted(Counter(texts).items()))}
    n = len(numbers)
    if n == 0:
        return {"mean": None, "sd": None, "n": 0}
    mean = math.fsum(numbers) / n
    sd = math.sqrt(math.fsum((v - mean) ** 2 for v in numbers) / (n - 1)) if n > 1 else 0.0
    return {"mean": round(mean, 6), "sd": round(sd, 6), "n": n}


def judge(status: dict[str, str] | None, stats: dict[str, Any] | None, published: Any) -> dict[str, Any] | None:
    """A published value's reported status: the declared ``status`` unless it is
    ``predicted`` and the measured mean is off by more than :data:`TOLERANCE` of
    ``published`` and by more than :data:`SPREADS` standard deviations; then
    ``missed``, with ``declared: predicted``, the deviation's share (``off``), the file's
    ``because`` if any, else ``unexplained: True`` (no mechanism stated). A value with no
    numeric mean or no numeric published value keeps its declared status.

    Examples:
        >>> judge({"status": "predicted"}, {"mean": 168.4, "sd": 0.0, "n": 1}, 95)
        {'status': 'missed', 'declared': 'predicted', 'off': 0.772632, 'unexplained': True}
        >>> judge({"status": "predicted"}, {"mean": 120.0, "sd": 15.0, "n": 5}, 90)   # within 2 sd
        {'status': 'predicted'}
        >>> judge({"status": "predicted", "because": "the wait"}, {"mean": 2.0, "sd": 0.1, "n": 5}, 1)["because"]
        'the wait'
        >>> judge({"status": "built-in", "because": "the speed"}, {"mean": 9.0, "sd": 0.0, "n": 1}, 1)["status"]
        'built-in'
    """
    if not status or status.get("status") != "predicted" or not stats or stats.get("mean") is None:
        return status
    if not isinstance(published, (int, float)) or isinstance(published, bool):
        return status
    off = abs(stats["mean"] - published)
    spread = SPREADS * (stats.get("sd") or 0.0) if stats.get("n", 0) > 1 else 0.0
    if off <= TOLERANCE * abs(published) + 1e-12 or off <= spread:
        return status
    judged: dict[str, Any] = {"status": "missed", "declared": "predicted",
                              "off": round(off / abs(published), 6) if published else None}
    if status.get("because"):
        judged["because"] = status["because"]
    else:
        judged["unexplained"] = True
    return judged


def summary(rows: list[Row], trials: list[dict[str, Any]], names: list[str]) -> list[dict[str, Any]]:
    """One entry per row, in the sweep's order:
    ``{"params", "trials", "failed", "metrics": {name: {"mean", "sd", "n"}}, "paper",
    "paper_status"}``; each published value's status is the declared one as the
    measurement leaves it (:func:`judge`)."""
    by_row: dict[int, list[dict[str, Any]]] = {row.index: [] for row in rows}
    for trial in trials:
        by_row.setdefault(trial["row"], []).append(trial)
    out = []
    for row in rows:
        done = by_row.get(row.index, [])
        statuses = Counter(trial_status(t) for t in done)
        measured = [t for t in done if t["status"] == "ok"]  # a failed run's metrics still describe it
        metrics = {name: _stats([t["metrics"][name] for t in measured if t["metrics"].get(name) is not None])
                   for name in names}
        judged = {}
        for key, declared in row.paper_status.items():
            verdict = judge(dict(declared), metrics.get(key), row.paper.get(key))
            if verdict:
                judged[key] = verdict
        out.append({"params": row.params, "trials": len(done), "failed": len(done) - statuses.get("ok", 0),
                    "status": dict(sorted(statuses.items())), "metrics": metrics, "paper": dict(row.paper),
                    "paper_status": judged})
    return out


def _number(value: Any) -> str:
    if value is None:
        return "-"
    if isinstance(value, str):
        return value
    if isinstance(value, (list, tuple, dict)):  # a row parameter such as a list of faults
        return json.dumps(value, sort_keys=True, separators=(",", ":"))
    if value == 0 or 0.01 <= abs(value) < 1e6:
        return f"{value:.4g}" if abs(value) < 1000 else f"{value:,.0f}"
    return f"{value:.3g}"


def fixed(mean: float, sd: float | None) -> str:
    """``mean ± sd`` to the precision the spread allows: two significant digits of the
    sd, the mean to the same decimal place (four significant digits without a spread).

    Examples:
        >>> fixed(36.29, 0.00577), fixed(18.25, 9.342), fixed(246.0, 5.02), fixed(0.5, 0.0)
        ('36.2900 ± 0.0058', '18.2 ± 9.3', '246.0 ± 5.0', '0.5')
    """
    if not sd:
        return _number(mean)
    decimals = max(0, 1 - math.floor(math.log10(abs(sd))))
    return f"{mean:.{decimals}f} ± {sd:.{decimals}f}"


def deviation(mean: float | None, paper: Any) -> str:
    """Measured minus published, and as a share of the published value.

    Examples:
        >>> deviation(246.0, 240), deviation(121.0, 120.0), deviation(None, 3), deviation(5.0, 0)
        ('+6 (+2.5%)', '+1 (+0.8%)', '-', '+5')
    """
    if mean is None or not isinstance(paper, (int, float)) or isinstance(paper, bool):
        return "-"
    difference = mean - paper
    text = f"{difference:+.3g}" if abs(difference) < 1000 else f"{difference:+,.0f}"
    return text if paper == 0 else f"{text} ({100 * difference / abs(paper):+.1f}%)"


def status_label(status: dict[str, Any] | None) -> str:
    """A published value's status as the reports write it (``-`` for none given); a
    value declared predicted that the measurement missed says so.

    Examples:
        >>> status_label({"status": "built-in", "because": "x"}), status_label(None)
        ('built in', '-')
        >>> status_label({"status": "missed", "declared": "predicted", "unexplained": True})
        'missed (no mechanism stated)'
        >>> status_label({"status": "missed", "declared": "predicted", "because": "x"})
        'missed (declared predicted)'
    """
    if not status:
        return "-"
    label = status["status"].replace("-", " ")
    if status.get("unexplained"):
        return f"{label} (no mechanism stated)"
    if status.get("declared") and status["declared"] != status["status"]:
        return f"{label} (declared {status['declared'].replace('-', ' ')})"
    return label


def status_notes(rows: list[dict[str, Any]], names: list[str], parameters: list[str]) -> list[str]:
    """One line per published value whose status has a reason: ``status: metric (row): because``.

    Examples:
        >>> status_notes([{"params": {"n": 1}, "paper": {"t": 9.0},
        ...                "paper_status": {"t": {"status": "built-in", "because": "t sets the speed"}}}],
        ...              ["t"], ["n"])
        ['built in: t (n=1): t sets the speed']
    """
    lines = []
    for row in rows:
        where = ", ".join(f"{p}={_number(row['params'].get(p))}" for p in parameters)
        for name in names:
            status = row.get("paper_status", {}).get(name)
            if name not in row["paper"] or not status:
                continue
            reason = status.get("because")
            if status.get("declared") and status.get("off") is not None:
                off = f"{100 * status['off']:.0f} % off the published value"
                reason = f"{off}: {reason}" if reason else off
            if reason:
                lines.append(f"{status_label(status)}: {name}{f' ({where})' if where else ''}: {reason}")
    return lines


def status_counts(rows: list[dict[str, Any]]) -> dict[str, int]:
    """How many published values are predicted, built in, missed (and of those, missed
    with no mechanism stated: ``unexplained``), or have no status (:data:`COUNTED`).

    Examples:
        >>> status_counts([{"paper": {"a": 1, "b": 2, "c": 3}, "paper_status": {"a": {"status": "missed"},
        ...                "c": {"status": "missed", "declared": "predicted", "unexplained": True}}}])
        {'predicted': 0, 'built-in': 0, 'missed': 2, 'unexplained': 1, 'unstated': 1}
    """
    counts = dict.fromkeys(COUNTED, 0)
    for row in rows:
        for name in row["paper"]:
            status = row.get("paper_status", {}).get(name)
            counts[status["status"] if status else "unstated"] += 1
            if status and status.get("unexplained"):
                counts["unexplained"] += 1
    return counts


def _cell(stats: dict[str, Any]) -> str:
    if stats.get("counts"):
        return " ".join(f"{k}:{v}" for k, v in stats["counts"].items())
    if stats["mean"] is None:
        return "-"
    if stats["n"] == 1:
        return _number(stats["mean"])
    return fixed(stats["mean"], stats["sd"])


def text_table(rows: list[dict[str, Any]], names: list[str], parameters: list[str], width: int = 100) -> str:
    """The report as aligned text: parameters, trials, failures (with their statuses),
    and per metric ``mean ± sd``, and where the paper gives a value, the paper's value,
    the deviation (measured − paper, and %) and the value's status where the file gives
    one (predicted, built in, missed). A table wider than ``width`` characters is
    split into blocks of metrics, each repeating the parameter columns."""
    lead = [*parameters, "trials", "failed"]
    lead_cells = []
    for row in rows:
        line = [_number(row["params"].get(p)) if not isinstance(row["params"].get(p), str) else row["params"][p]
                for p in parameters]
        failed = str(row["failed"])
        bad = {k: v for k, v in row.get("status", {}).items() if k != "ok"}
        if bad:
            failed += " (" + ", ".join(f"{k} {v}" for k, v in bad.items()) + ")"
        lead_cells.append(line + [str(row["trials"]), failed])
    blocks: list[tuple[list[str], list[list[str]]]] = []
    for name in names:
        header = [name]
        cells = [[_cell(row["metrics"][name])] for row in rows]
        if any(name in r["paper"] for r in rows):
            header += ["paper", "deviation"]
            for cell, row in zip(cells, rows):
                cell += [_number(row["paper"].get(name)), deviation(row["metrics"][name]["mean"], row["paper"].get(name))]
            if any(r.get("paper_status", {}).get(name) for r in rows if name in r["paper"]):
                header.append("status")
                for cell, row in zip(cells, rows):
                    cell.append(status_label(row.get("paper_status", {}).get(name)) if name in row["paper"] else "")
        blocks.append((header, cells))
    lead_width = _width([lead] + lead_cells)
    tables, current = [], []
    for block in blocks:
        size = _width([block[0]] + block[1])
        if current and lead_width + sum(_width([b[0]] + b[1]) for b in current) + size > width:
            tables.append(current)
            current = []
        current.append(block)
    tables.append(current)
    text = []
    for group in tables:
        header = lead + [h for block in group for h in block[0]]
        lines = [header] + [lead_cells[i] + [c for block in group for c in block[1][i]] for i in range(len(rows))]
        widths = [max(len(str(line[i])) for line in lines) for i in range(len(header))]
        if text:
            text.append("")
        for number, line in enumerate(lines):
            text.append("  ".join(str(cell).rjust(w) if number else str(cell).ljust(w)
                                  for cell, w in zip(line, widths)).rstrip())
            if number == 0:
                text.append("  ".join("-" * w for w in widths))
    return "\n".join(text)


def _width(lines: list[list[str]]) -> int:
    """Characters the columns of ``lines`` take, two spaces between them."""
    if not lines or not lines[0]:
        return 0
    return sum(max(len(str(line[i])) for line in lines) + 2 for i in range(len(lines[0])))


def write_csv(path: str | Path, rows: list[dict[str, Any]], names: list[str], parameters: list[str]) -> None:
    """The report as CSV: a line per row; per metric ``_mean``, ``_sd``, ``_n``, ``_paper``
    and ``_status`` (the published value's: predicted, built-in, missed)."""
    from petriflow.io.files import write_atomic

    header = [*parameters, "trials", "failed"]
    for name in names:
        header += [f"{name}_mean", f"{name}_sd", f"{name}_n", f"{name}_paper", f"{name}_status"]
    import io

    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    for row in rows:
        line = [row["params"].get(p) for p in parameters] + [row["trials"], row["failed"]]
        for name in names:
            stats = row["metrics"][name]
            mean = stats["mean"] if not stats.get("counts") else " ".join(f"{k}:{v}" for k, v in stats["counts"].items())
            status = row.get("paper_status", {}).get(name) if name in row["paper"] else None
            line += [mean, stats["sd"], stats["n"], row["paper"].get(name), status["status"] if status else None]
        writer.writerow(["" if v is None else v for v in line])
    write_atomic(path, buffer.getvalue())


def plot(path: str | Path, rows: list[dict[str, Any]], names: list[str], parameters: list[str],
         title: str = "") -> list[str]:
    """Draw each numeric metric against the first parameter with error bars (± sd),
    one line per value of the other parameters, the paper's values as hollow markers
    on dashed lines. Returns the metrics drawn."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    numeric = [n for n in names if any(r["metrics"][n]["mean"] is not None for r in rows)]
    if not numeric:
        numeric = []
    x_name = parameters[0] if parameters else None
    xs = []
    for row in rows:
        value = row["params"].get(x_name) if x_name else 0
        if value not in xs:
            xs.append(value)
    categorical = not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in xs)
    position = {v: (i if categorical else v) for i, v in enumerate(xs)}
    groups: dict[str, list[dict[str, Any]]] = {}
    for row in rows:
        label = ", ".join(f"{p}={row['params'][p]}" for p in parameters[1:]) or (x_name or "all")
        groups.setdefault(label, []).append(row)
    count = max(1, len(numeric))
    columns = min(3, count)
    lines = math.ceil(count / columns)
    figure, axes = plt.subplots(lines, columns, figsize=(4.6 * columns, 3.6 * lines), squeeze=False)
    for k, name in enumerate(numeric):
        axis = axes[k // columns][k % columns]
        for index, (label, members) in enumerate(groups.items()):
            colour = f"C{index % 10}"
            points = [(position[m["params"].get(x_name) if x_name else 0], m["metrics"][name]) for m in members
                      if m["metrics"][name]["mean"] is not None]
            if points:
                axis.errorbar([p for p, _ in points], [s["mean"] for _, s in points],
                              yerr=[s["sd"] for _, s in points], marker="o", capsize=3, color=colour, label=label)
            paper = [(position[m["params"].get(x_name) if x_name else 0], m["paper"][name]) for m in members
                     if isinstance(m["paper"].get(name), (int, float))]
            if paper:
                axis.plot([p for p, _ in paper], [v for _, v in paper], linestyle="--", marker="s",
                          markerfacecolor="none", color=colour, label=f"{label} (paper)")
        axis.set_title(name)
        axis.set_xlabel(x_name or "")
        if categorical:
            axis.set_xticks(range(len(xs)), [str(v) for v in xs])
        axis.grid(alpha=0.3)
        axis.legend(fontsize=7)
    for k in range(len(numeric), lines * columns):
        axes[k // columns][k % columns].set_visible(False)
    if title:
        figure.suptitle(title)
    figure.tight_layout()
    from petriflow.io.files import write_atomic

    import io

    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=110)
    plt.close(figure)
    write_atomic(path, buffer.getvalue())
    return numeric
