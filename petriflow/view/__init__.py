"""See a run, or a sweep, as one self-contained HTML page.

``petriflow view RUN.jsonl --net NET -o run.html`` (or :func:`view` from Python) writes
a page that opens from disk in any current browser, with no server and no network: its
scripts, styles and data are inside it. A run's page replays the trace: the net with
its marking and running transitions at the instant a slider (or play/step) chooses,
the world seen from above at that instant (from the ``pose`` events that
``petriflow run --poses S`` or ``--view`` records), the messages between agents as a
sequence chart, every event in a filterable list, and each agent's firings as a Gantt
chart. A sweep's page (``petriflow view SWEEP.db``) holds the report's table with the
paper's values beside the measured ones, and each metric against the first parameter
with error bars. See ``docs/viewer.md``.
"""

from __future__ import annotations

from pathlib import Path

from petriflow.errors import PetriflowError

__all__ = ["view", "run_page", "sweep_page", "SWEEP_SUFFIXES"]

#: File endings read as a sweep's results database (anything else is a run's trace).
SWEEP_SUFFIXES = (".db", ".sqlite", ".sqlite3")


def view(source: str | Path, *, net: str | Path | None = None, out: str | Path | None = None,
         sweep: str | Path | None = None, max_mb: float | None = None, trace_name: str | None = "") -> Path:
    """Write the page of a run's trace (``.jsonl``) or of a sweep's results (``.db``).

    Args:
        source: a trace written by ``petriflow run --trace``, or a results database
            written by ``petriflow sweep --db``.
        net: the net the trace was recorded on (a run's page draws it; without it the
            marking is shown as a list of places).
        out: the page to write (default: ``source`` with the ending ``.html``).
        sweep: for a results database, its sweep file (default: the file the database
            names), for the paper's values and the rows' order.
        max_mb: the most a run's page should weigh (default 20 MB): past it, the bulky
            data of events that the page does not need to replay them (token data copied
            into ``inputs`` and ``result``, an action's own reports) is left out of the
            events' records, each such value replaced by a note naming its trace line;
            every event stays in the page.
        trace_name: what a run's page calls its trace (default: the file's name; ``None``
            for a trace that was only a means to the page, which then names the net).

    Returns:
        The page written.

    Raises:
        PetriflowError: an input is missing or malformed (naming it), or the page
            cannot be written.
    """
    source = Path(source)
    out = Path(out) if out is not None else source.with_suffix(".html")
    if out.suffix.lower() not in (".html", ".htm"):
        raise PetriflowError(f"{out}: the page is HTML; name it .html")
    if out.resolve() == source.resolve():
        raise PetriflowError(f"{out}: the page would overwrite its own input")
    if not source.is_file():
        raise PetriflowError(f"{source}: no such file")
    if source.suffix.lower() in SWEEP_SUFFIXES:
        if net is not None:
            raise PetriflowError("--net is for a run's trace; a sweep's page takes --sweep")
        from petriflow.view.sweep_page import sweep_page

        html = sweep_page(source, sweep=sweep)
    else:
        if sweep is not None:
            raise PetriflowError("--sweep is for a sweep's results database (.db), not a trace")
        from petriflow.view.run_page import run_page

        from petriflow.view.run_page import DEFAULT_MAX_MB

        if max_mb is not None and not max_mb > 0:
            raise PetriflowError(f"--max-mb must be a size in MB > 0, got {max_mb}")
        html = run_page(source, net=net, max_mb=DEFAULT_MAX_MB if max_mb is None else max_mb,
                        trace_name=trace_name)
    from petriflow.io.files import write_atomic

    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(out, html.encode("utf-8"))
    except OSError as exc:
        raise PetriflowError(f"{out}: cannot write the page: {exc.strerror or exc}") from None
    return out


def run_page(trace: str | Path, *, net: str | Path | None = None, max_mb: float = 20.0,
             trace_name: str | None = "") -> str:
    """The HTML of a run's page (see :mod:`petriflow.view.run_page`)."""
    from petriflow.view.run_page import run_page as build

    return build(trace, net=net, max_mb=max_mb, trace_name=trace_name)


def sweep_page(db: str | Path, *, sweep: str | Path | None = None) -> str:
    """The HTML of a sweep's page (see :mod:`petriflow.view.sweep_page`)."""
    from petriflow.view.sweep_page import sweep_page as build

    return build(db, sweep=sweep)
