"""Writing output files so that a failure never leaves a half-written or lost file."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Any

from petriflow import limits

__all__ = ["write_atomic", "read_yaml_file", "parse_json", "decode_text", "read_text_file"]


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


#: Byte-order marks, longest first (UTF-32's little-endian mark starts with UTF-16's).
_BOMS = ((b"\x00\x00\xfe\xff", "utf-32-be"), (b"\xff\xfe\x00\x00", "utf-32-le"), (b"\xef\xbb\xbf", "utf-8"),
         (b"\xfe\xff", "utf-16-be"), (b"\xff\xfe", "utf-16-le"))


def decode_text(data: bytes) -> str:
    """The text of a net, world or configuration file, in any encoding XML and YAML allow.

    A byte-order mark decides (UTF-8, UTF-16 or UTF-32, either byte order; the mark is
    dropped); without one, UTF-16 is recognised by its first character (``<`` or an
    ASCII letter, as XML's and YAML's autodetection do), then an XML declaration's
    ``encoding`` is used, else UTF-8.

    Raises:
        ValueError: the bytes are not text in that encoding, or the declared encoding
            is unknown (the message says which).

    Examples:
        >>> decode_text("\ufeffnet: a".encode("utf-8"))
        'net: a'
        >>> decode_text("<pnml/>".encode("utf-16"))
        '<pnml/>'
        >>> decode_text("<?xml version='1.0' encoding='latin-1'?><a>é</a>".encode("latin-1"))[-8:]
        '<a>é</a>'
    """
    import codecs
    import re

    for mark, encoding in _BOMS:
        if data.startswith(mark):
            return _decode(data[len(mark):], encoding)
    if len(data) >= 2 and data[0] == 0 and data[1] != 0:
        return _decode(data, "utf-16-be")
    if len(data) >= 2 and data[1] == 0 and data[0] != 0 and not (len(data) >= 4 and data[2] == 0):
        return _decode(data, "utf-16-le")
    declared = re.match(rb"\s*<\?xml[^>]*?encoding\s*=\s*[\"']([A-Za-z0-9._-]+)[\"']", data[:512])
    encoding = declared.group(1).decode("ascii") if declared else "utf-8"
    try:
        codecs.lookup(encoding)
    except LookupError:
        raise ValueError(f"unknown encoding {encoding!r} in the XML declaration") from None
    return _decode(data, encoding)


def _decode(data: bytes, encoding: str) -> str:
    try:
        return data.decode(encoding)
    except UnicodeDecodeError as exc:
        raise ValueError(f"not {exc.encoding} text (byte {exc.start})") from None


def read_text_file(path: str | Path) -> str:
    """Read a text file petriflow did not write itself (see :func:`decode_text`).

    Raises:
        NetFormatError: unreadable or undecodable, naming the file.
    """
    from petriflow.errors import NetFormatError

    try:
        return decode_text(Path(path).read_bytes())
    except OSError as exc:
        raise NetFormatError(f"cannot read: {exc.strerror or exc}", path=str(path)) from None
    except ValueError as exc:
        raise NetFormatError(f"cannot read: {exc}", path=str(path)) from None


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
    text = read_text_file(path)
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
