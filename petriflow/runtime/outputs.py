"""A run's output files, checked before anything is made.

A command that writes files (``petriflow run --trace/--xes/--db/--picture``, ``sweep``,
``replay --draw``, ``export``) first checks every output it was given, so that a
typo or a folder it cannot write into fails before a run starts or a journal is made:
:func:`check_outputs`, then :func:`make_folders` for the folders they go into.

Examples:
    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> check_outputs({"--trace": folder / "a.jsonl", "--xes": folder / "a.jsonl"}, [])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    petriflow.errors.NetFormatError: .../a.jsonl: --xes and --trace name the same file
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from petriflow.errors import NetFormatError

__all__ = ["check_outputs", "make_folders", "can_create_in"]


def check_outputs(outputs: dict[str, str | Path | None], read: list[Path | str | None]) -> None:
    """Refuse two outputs on one file, an output that is one of the run's inputs, and an
    output whose folder cannot be made or written (before anything is created).

    Args:
        outputs: ``{option: file}`` (``None``: the option was not given).
        read: the files the command reads (``None`` entries are skipped).

    Raises:
        NetFormatError: naming the option and the file.
    """
    seen: dict[Path, str] = {}
    inputs = {Path(p).resolve() for p in read if p is not None}
    for option, path in outputs.items():
        if path is None:
            continue
        where = Path(path).resolve()
        if where in seen:
            raise NetFormatError(f"{option} and {seen[where]} name the same file", path=str(path))
        if where in inputs:
            raise NetFormatError(f"{option} would overwrite one of the inputs", path=str(path))
        if where.is_dir():
            raise NetFormatError(f"{option} names a folder, not a file", path=str(path))
        seen[where] = option
        folder = where.parent
        while not folder.exists() and folder != folder.parent:
            folder = folder.parent
        if not os.access(folder, os.W_OK | os.X_OK) or not can_create_in(folder):
            raise NetFormatError(f"{option}: cannot write into {folder}", path=str(path))


def can_create_in(folder: Path) -> bool:
    """Whether a file can be made in ``folder`` (tried: permission bits do not tell for the
    superuser, nor on read-only or pseudo file systems such as /proc)."""
    try:  # nameless where the system allows (O_TMPFILE): a kill here leaves nothing behind
        with tempfile.TemporaryFile(dir=folder, prefix=".petriflow-", suffix=".probe"):
            return True
    except OSError:
        return False


def make_folders(*outputs: str | Path | None) -> None:
    """Create the folders the output files go into (before anything is written).

    Raises:
        NetFormatError: a folder cannot be made (naming the output).
    """
    for output in outputs:
        if output is not None:
            try:
                Path(output).parent.mkdir(parents=True, exist_ok=True)
            except OSError as exc:
                raise NetFormatError(f"cannot create its folder: {getattr(exc, 'strerror', None) or exc}",
                                     path=str(output)) from None
