"""A sweep's page: the report's table with the paper's values beside the measured ones
(each with its status, predicted / built in / missed, and the reason under the table),
and each metric against the first parameter with error bars (± one standard
deviation), one line per value of the other parameters, the paper's values as their
own dashed lines, drawn with dygraphs (zoom by dragging, values under the pointer).

The rows and the paper's values come from the sweep file the results database names
(or ``sweep``); the numbers from :func:`petriflow.sweep.report.summary`, as
``petriflow sweep`` prints them. Every trial (parameters, seed, status, metrics) is in
the page too.
"""

from __future__ import annotations

import html
import sqlite3
from pathlib import Path
from typing import Any

from petriflow.errors import PetriflowError
from petriflow.sweep.report import deviation, fixed, metric_names, status_counts, status_notes, summary, trial_status
from petriflow.sweep.spec import Row
from petriflow.sweep.store import FORMAT
from petriflow.view.page import render

__all__ = ["sweep_page", "read_results"]


def read_results(db: str | Path) -> tuple[dict[str, str], list[dict[str, Any]]]:
    """``(meta, trials)`` of a results database, opened read-only.

    Raises:
        PetriflowError: it is not a petriflow sweep results database.
    """
    db = Path(db)
    try:
        connection = sqlite3.connect(f"{db.resolve().as_uri()}?mode=ro", uri=True)
    except sqlite3.Error as exc:
        raise PetriflowError(f"{db}: cannot open the results database ({exc})") from None
    try:
        meta = dict(connection.execute("SELECT key, value FROM sweep").fetchall())
        if meta.get("format") != FORMAT:
            raise PetriflowError(f"{db}: not a petriflow sweep results database")
        from petriflow.sweep.store import Store

        store = Store(db)
        store.db = connection
        trials = store.results()
    except sqlite3.Error as exc:
        raise PetriflowError(f"{db}: not a petriflow sweep results database ({exc})") from None
    finally:
        connection.close()
    return meta, trials


def _load_spec(db: Path, meta: dict[str, str], sweep: str | Path | None) -> tuple[Any, str | None]:
    """The sweep file's spec (or ``None``) and a note on why it is not used."""
    from petriflow.sweep import load_sweep
    from petriflow.sweep.ship import collect

    if sweep is not None:
        spec = load_sweep(sweep)
    else:
        named = meta.get("file")
        candidates = [Path(named), db.parent / Path(named).name] if named else []
        found = next((c for c in candidates if c.is_file()), None)
        if found is None:
            return None, f"its sweep file {named!r} was not found (--sweep FILE names it): no paper values"
        spec = load_sweep(found)
    if collect(spec).digest() != meta.get("digest"):
        return spec, (f"{spec.path} has changed since these results were recorded: its rows and paper values"
                      " are shown as the file says now")
    return spec, None


def sweep_page(db: str | Path, *, sweep: str | Path | None = None) -> str:
    """The HTML of the page of the results database ``db``."""
    db = Path(db)
    meta, trials = read_results(db)
    spec, note = _load_spec(db, meta, sweep)
    if spec is not None:
        rows = list(spec.rows)
        parameters = list(spec.parameters)
        declared = [m.name for m in spec.metrics]
        name, source, description = spec.name, spec.paper_source, spec.description
    else:
        seen: dict[int, dict[str, Any]] = {}
        for trial in trials:
            seen.setdefault(trial["row"], trial["params"])
        rows = [Row(index, params) for index, params in sorted(seen.items())]
        parameters = list(rows[0].params) if rows else []
        declared = list(dict.fromkeys(key for trial in trials for key in trial["metrics"]))
        name, source, description = Path(meta.get("file") or db.stem).stem, None, None
    names = metric_names(declared, trials)
    table = summary(rows, trials, names)
    for row in table:  # the texts petriflow sweep prints
        row["cells"] = {name: _cell(row["metrics"][name]) for name in names}
        row["deviations"] = {name: deviation(row["metrics"][name]["mean"], row["paper"].get(name)) for name in names}
    statuses: dict[str, int] = {}
    for trial in trials:
        status = trial_status(trial)
        statuses[status] = statuses.get(status, 0) + 1
    data = {
        "kind": "sweep",
        "name": name,
        "db": db.name,
        "source": source,
        "description": description,
        "note": note,
        "parameters": parameters,
        "metrics": names,
        "rows": table,
        "statuses": statuses,
        "status_notes": status_notes(table, names, parameters),
        "status_counts": status_counts(table),
        "trials": [{"row": t["row"], "params": t["params"], "seed": t["seed"], "status": trial_status(t),
                    "metrics": t["metrics"], "wall": t["wall"], "error": t["error"]} for t in trials],
    }
    title = f"{name}: sweep" + (f" ({source})" if source else "")
    return render(title=title, body=_BODY.replace("{title}", html.escape(title)), data=data,
                  scripts=["dygraph.min.js", "common.js", "sweep.js"],
                  styles=["dygraph.min.css", "common.css", "sweep.css"])


def _cell(stats: dict[str, Any]) -> str:
    """A metric's cell as the text report writes it.

    Examples:
        >>> _cell({"mean": 18.25, "sd": 9.342, "n": 4}), _cell({"mean": None, "sd": None, "n": 0})
        ('18.2 ± 9.3', '-')
    """
    if stats.get("counts"):
        return " ".join(f"{k}:{v}" for k, v in stats["counts"].items())
    if stats["mean"] is None:
        return "-"
    return fixed(stats["mean"], stats["sd"] if stats["n"] > 1 else None)


_BODY = """
<header>
  <h1>{title}</h1>
  <div id="summary"></div>
</header>
<main>
  <section class="panel"><h2>Report <small>mean ± standard deviation over the trials that ran; the paper's value and the deviation beside it</small></h2>
    <div id="table-box"><table id="report"></table></div>
    <ul id="status-notes"></ul></section>
  <section class="panel"><h2>Each metric against the first parameter <small>error bars: ± one standard deviation; dashed: the paper; drag to zoom, double click to reset</small></h2>
    <div id="plots"></div></section>
  <section class="panel"><h2>Trials</h2>
    <div class="bar"><label>status <select id="t-status"><option value="">all</option></select></label><span id="t-count"></span></div>
    <div id="trials-box"><table id="trials"></table></div></section>
</main>
"""
