"""A sweep's report: per row, each metric's mean, standard deviation and count over the
trials that ran, beside the paper's value; as text, JSON, CSV or a plot.

Examples:
    >>> from petriflow.sweep.spec import Row
    >>> rows = [Row(0, {"n": 1}, {"t": 9.0})]
    >>> trials = [{"row": 0, "status": "ok", "metrics": {"t": 10.0}},
    ...           {"row": 0, "status": "ok", "metrics": {"t": 12.0}},
    ...           {"row": 0, "status": "timeout", "metrics": {}}]
    >>> summary(rows, trials, ["t"])[0]
    {'params': {'n': 1}, 'trials': 3, 'failed': 1, 'metrics': {'t': {'mean': 11.0, 'sd': 1.414214, 'n': 2}}, 'paper': {'t': 9.0}}
"""

from __future__ import annotations

import csv
import math
from collections import Counter
from pathlib import Path
from typing import Any

from petriflow.sweep.spec import Row

__all__ = ["summary", "metric_names", "text_table", "write_csv", "plot"]


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


def summary(rows: list[Row], trials: list[dict[str, Any]], names: list[str]) -> list[dict[str, Any]]:
    """One entry per row, in the sweep's order:
    ``{"params", "trials", "failed", "metrics": {name: {"mean", "sd", "n"}}, "paper"}``."""
    by_row: dict[int, list[dict[str, Any]]] = {row.index: [] for row in rows}
    for trial in trials:
        by_row.setdefault(trial["row"], []).append(trial)
    out = []
    for row in rows:
        done = by_row.get(row.index, [])
        ok = [t for t in done if t["status"] == "ok"]
        metrics = {name: _stats([t["metrics"][name] for t in ok if t["metrics"].get(name) is not None])
                   for name in names}
        out.append({"params": row.params, "trials": len(done), "failed": len(done) - len(ok),
                    "metrics": metrics, "paper": dict(row.paper)})
    return out


def _number(value: Any) -> str:
    if value is None:
        return "-"
    if isinstance(value, str):
        return value
    if value == 0 or 0.01 <= abs(value) < 1e6:
        return f"{value:.4g}" if abs(value) < 1000 else f"{value:,.0f}"
    return f"{value:.3g}"


def _cell(stats: dict[str, Any]) -> str:
    if stats.get("counts"):
        return " ".join(f"{k}:{v}" for k, v in stats["counts"].items())
    if stats["mean"] is None:
        return "-"
    if stats["n"] == 1:
        return _number(stats["mean"])
    return f"{_number(stats['mean'])} ± {_number(stats['sd'])}"


def text_table(rows: list[dict[str, Any]], names: list[str], parameters: list[str]) -> str:
    """The report as an aligned text table: parameters, trials, failures, and per
    metric ``mean ± sd`` with the paper's value in brackets beside it."""
    header = [*parameters, "trials", "failed"]
    for name in names:
        header.append(name)
        if any(name in row["paper"] for row in rows):
            header.append("paper")
    lines = [header]
    for row in rows:
        line = [_number(row["params"].get(p)) if not isinstance(row["params"].get(p), str) else row["params"][p]
                for p in parameters]
        line += [str(row["trials"]), str(row["failed"])]
        for name in names:
            line.append(_cell(row["metrics"][name]))
            if any(name in r["paper"] for r in rows):
                line.append(_number(row["paper"].get(name)))
        lines.append(line)
    widths = [max(len(str(line[i])) for line in lines) for i in range(len(header))]
    text = []
    for number, line in enumerate(lines):
        text.append("  ".join(str(cell).rjust(width) if number else str(cell).ljust(width)
                              for cell, width in zip(line, widths)).rstrip())
        if number == 0:
            text.append("  ".join("-" * w for w in widths))
    return "\n".join(text)


def write_csv(path: str | Path, rows: list[dict[str, Any]], names: list[str], parameters: list[str]) -> None:
    """The report as CSV: a line per row; per metric ``_mean``, ``_sd``, ``_n`` and ``_paper``."""
    from petriflow.io.files import write_atomic

    header = [*parameters, "trials", "failed"]
    for name in names:
        header += [f"{name}_mean", f"{name}_sd", f"{name}_n", f"{name}_paper"]
    import io

    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    for row in rows:
        line = [row["params"].get(p) for p in parameters] + [row["trials"], row["failed"]]
        for name in names:
            stats = row["metrics"][name]
            mean = stats["mean"] if not stats.get("counts") else " ".join(f"{k}:{v}" for k, v in stats["counts"].items())
            line += [mean, stats["sd"], stats["n"], row["paper"].get(name)]
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
