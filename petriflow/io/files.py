"""Writing output files so that a failure never leaves a half-written or lost file."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Any

from petriflow import limits

__all__ = ["write_atomic", "read_yaml_file", "parse_json"]


def write_atomic(path: str | Path, data: str | bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file and an atomic rename.

    If anything fails before the rename, ``path`` keeps its old content (or stays
    absent) and the temporary file is removed.
    """
    path = Path(path)
    mode = "wb" if isinstance(data, bytes) else "w"
    fd, temporary = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent or ".")
    try:
        with os.fdopen(fd, mode, **({} if isinstance(data, bytes) else {"encoding": "utf-8"})) as out:
            out.write(data)
        os.chmod(temporary, 0o666 & ~_umask())  # an ordinary file's mode, not mkstemp's 0600
        os.replace(temporary, path)
    except BaseException:
        try:
            os.unlink(temporary)
        except FileNotFoundError:
            pass
        raise


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def read_yaml_file(path: str | Path, *, lines: bool = False) -> Any:
    """Parse a YAML data file (world, run configuration) with the net reader's safe,
    bounded parser (:func:`petriflow.io.yaml.parse_yaml`): no tags run, no alias bombs,
    no nesting deeper than it allows, every error with its line.

    Args:
        path: the file.
        lines: keep the parser's mappings and lists, which know their lines (for
            checks that name them); else plain dicts and lists.

    Raises:
        NetFormatError: the file is unreadable or malformed, naming it and the line.
    """
    import yaml

    from petriflow.errors import NetFormatError
    from petriflow.io.yaml import _plain, parse_yaml

    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise NetFormatError(f"cannot read: {getattr(exc, 'strerror', None) or exc}", path=str(path)) from None
    try:
        data = parse_yaml(text)
        return data if lines else _plain(data)
    except NetFormatError as exc:
        raise exc.at(str(path)) from None
    except yaml.YAMLError as exc:
        from petriflow.io.yaml import _yaml_problem

        mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
        problem = getattr(exc, "problem", None) or getattr(exc, "context", None) or _yaml_problem(exc)
        raise NetFormatError(f"malformed YAML: {problem}", path=str(path),
                             line=mark.line + 1 if mark else None) from None


def parse_json(text: str) -> Any:
    """Parse JSON text from a file petriflow did not write itself (PNML data, traces,
    journals), refusing what would exhaust the machine or crash later.

    Raises:
        ValueError: malformed JSON, nesting deeper than :data:`~petriflow.limits.JSON_DEPTH`, a number
            too long to convert, or ``NaN``/``Infinity`` (not JSON); the message says
            which (callers add the file and line).

    Examples:
        >>> parse_json('{"a": [1, 2.5]}')
        {'a': [1, 2.5]}
        >>> parse_json("[" * 100 + "]" * 100)
        Traceback (most recent call last):
        ...
        ValueError: nested more than 64 levels deep
    """
    import json

    def no_constant(name: str) -> Any:
        raise ValueError(f"{name} is not a JSON number")

    try:
        value = json.loads(text, parse_constant=no_constant)
    except RecursionError:
        raise ValueError(f"nested more than {limits.JSON_DEPTH} levels deep") from None
    except json.JSONDecodeError as exc:
        raise ValueError(f"not valid JSON: {exc.msg} (column {exc.colno})") from None
    except ValueError as exc:  # an integer of more than 4,300 digits
        raise ValueError("a number of more than 4,300 digits" if "digits" in str(exc) else str(exc)) from None
    stack = [(value, 0)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, (dict, list)):
            if depth >= limits.JSON_DEPTH:
                raise ValueError(f"nested more than {limits.JSON_DEPTH} levels deep")
            stack.extend((inner, depth + 1) for inner in (item.values() if isinstance(item, dict) else item))
    return value
