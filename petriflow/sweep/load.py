"""A sweep file read and checked: every row's trial built before any of them runs.

:func:`load_sweep` reads the file into a :class:`~petriflow.sweep.spec.Sweep` and
:func:`check_sweep` builds its rows' trials without running them (the net read and
bound with the row's ``set:`` targets, the run configuration, the world description,
the metrics), so that a mistake in any of them fails with its file and line before the
first trial starts.

Examples:
    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "n.yaml").write_text("petriflow: 1\\nplaces: [{id: i, tokens: 1}, o]\\n"
    ...     "transitions: [{id: t, action: core.wait, params: {seconds: 1}, in: [i], out: [o]}]\\n")
    >>> _ = (folder / "s.yaml").write_text("petriflow-sweep: 1\\nnet: n.yaml\\ntrials: 2\\n")
    >>> load_sweep(folder / "s.yaml").seeds
    [1, 2]
    >>> _ = (folder / "bad.yaml").write_text("petriflow-sweep: 1\\nnet: n.yaml\\n"
    ...                                      "set: {net.transitions.t.params.secs: 2}\\n")
    >>> load_sweep(folder / "bad.yaml")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    petriflow.errors.NetFormatError: ...bad.yaml:3: ...n.yaml:3: 't': action has no parameter 'secs' ...
"""

from __future__ import annotations

from pathlib import Path

from petriflow.errors import NetFormatError
from petriflow.io.files import read_yaml_file
from petriflow.sweep.spec import Sweep, canonical
from petriflow.sweep.trial import TrialError, build

__all__ = ["check_sweep", "load_sweep"]


def check_sweep(sweep: Sweep, rows: int = 200) -> None:
    """Build the first ``rows`` rows' trials of ``sweep`` without running them (net read
    and bound with the row's targets set, run configuration, world description,
    metrics), so a mistake fails before any trial starts.

    Raises:
        NetFormatError: naming the net, configuration or world file and line, or the
            sweep file and the ``set:``/``metrics:`` line.
    """
    for row in sweep.rows[:rows]:
        try:
            build(sweep.to_data(), row.params, sweep.seeds[0])
        except (TrialError, NetFormatError) as exc:
            key = "metrics" if str(exc).startswith("metrics:") else "set" if sweep.set else "net"
            where = f"row {row.index + 1} ({canonical(row.params)}): " if row.params else ""
            raise NetFormatError(f"{where}{exc}", path=sweep.shown or sweep.path,
                                 line=sweep.lines.get(key) or sweep.lines.get("net")) from None


def load_sweep(path: str | Path) -> Sweep:
    """Read and check a sweep file.

    Raises:
        NetFormatError: the file is unreadable or malformed, naming it and the line; or
            a row's trial cannot be built (:func:`check_sweep`).
    """
    if not Path(path).is_file():
        raise NetFormatError("no such file", path=str(path))
    sweep = Sweep.from_dict(read_yaml_file(path, lines=True), path)
    check_sweep(sweep)
    return sweep
