"""Writing output files so that a failure never leaves a half-written or lost file."""

from __future__ import annotations

import glob
import os
import tempfile
import time
from pathlib import Path
from typing import Any

try:  # POSIX: a writer holds a lock on its temporary file for as long as it lives
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None

from petriflow import limits

__all__ = ["PartialFile", "make_database", "write_atomic", "remove_stale", "read_yaml_file", "parse_json", "decode_text",
           "read_text_file"]


class PartialFile:
    """An output file written under a temporary name in its target folder and renamed into
    place when finished: an existing file of that name is never half-overwritten, and two
    writers never share a temporary file.

    The temporary name is ``.NAME.<pid>-<random>.partial<suffix>`` (the target's suffix
    kept, for writers that choose a format by it), and the writer holds an exclusive
    ``flock`` on it while it lives. A writer that was killed holds no lock any more (the
    kernel drops it with the process, before its parent has even reaped it), so its
    temporary files are recognised and removed by the next writer of the same target: at
    its start and when it finishes (:func:`remove_stale`).

    Args:
        path: the target file.
        binary: open :attr:`file` for bytes rather than UTF-8 text.
        opened: open :attr:`file` at all; with ``False`` the caller writes
            :attr:`temporary` by its name (a picture library, SQLite), and the lock is held
            all the same.

    Examples:
        >>> import tempfile
        >>> folder = Path(tempfile.mkdtemp())
        >>> out = PartialFile(folder / "a.txt")
        >>> _ = out.file.write("done")
        >>> out.finish()
        >>> (folder / "a.txt").read_text(), sorted(p.name for p in folder.iterdir())
        ('done', ['a.txt'])
    """

    def __init__(self, path: str | Path, *, binary: bool = False, opened: bool = True) -> None:
        self.path = Path(path)
        remove_stale(self.path)
        fd, name = tempfile.mkstemp(prefix=f".{self.path.name}.{os.getpid()}-", suffix=f".partial{self.path.suffix}",
                                    dir=self.path.parent if str(self.path.parent) else ".")
        self.temporary = Path(name)
        if fcntl is not None:
            fcntl.flock(fd, fcntl.LOCK_EX)  # a new file of ours: never waits
        self._fd: int | None = fd
        self.file: Any = None
        if opened:
            self.file = os.fdopen(os.dup(fd), "wb" if binary else "w",
                                  **({} if binary else {"encoding": "utf-8"}))

    def finish(self, keep: bool = True) -> None:
        """Close the file and rename it into place (an ordinary file's mode, not
        ``mkstemp``'s 0600), or drop it when ``keep`` is false."""
        try:
            if self.file is not None:
                self.file.close()
            if not keep:
                self.temporary.unlink(missing_ok=True)
                return
            os.chmod(self.temporary, 0o666 & ~_umask())
            os.replace(self.temporary, self.path)
        finally:
            self.release()
        remove_stale(self.path)

    def link(self) -> None:
        """Put the finished file in place only if nothing is there yet (``FileExistsError``
        otherwise), keeping the lock: the target is the same file, so a caller that goes on
        writing it by its name (a database) still holds it against other writers."""
        if self.file is not None:
            self.file.close()
            self.file = None
        os.chmod(self.temporary, 0o666 & ~_umask())
        os.link(self.temporary, self.path)
        self.temporary.unlink()

    def release(self) -> None:
        """Stop holding the lock (its descriptor closed)."""
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def detach(self) -> int:
        """The descriptor holding the lock, now the caller's to close (after :meth:`link`:
        the lock of the file in place)."""
        fd, self._fd = self._fd, None
        assert fd is not None
        return fd


def remove_stale(path: str | Path) -> None:
    """Remove the temporary files of ``path`` (:class:`PartialFile`'s, and the files a
    library made beside them, such as SQLite's ``-wal``) whose writer is gone: nothing
    holds their lock, and the process their name carries is not running on this machine
    (gone, or a zombie not yet reaped), or they were untouched for a minute (a name
    without a process id, or a process id now reused)."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    now = time.time()
    for stale in folder.glob(f".{glob.escape(path.name)}.*.partial*"):
        writer = stale.name[len(path.name) + 2:].split("-", 1)[0]
        try:
            if path.exists() and os.path.samefile(stale, path):  # linked into place, not yet unlinked
                stale.unlink()
                continue
            fd = os.open(stale, os.O_RDONLY)
        except OSError:  # gone already, or not ours to read
            continue
        try:
            gone = not (writer.isascii() and writer.isdigit() and len(writer) < 10 and _running(int(writer)))
            if fcntl is not None and not _lock(fd, wait=2.0 if gone else 0.0):
                continue  # its writer lives
            if gone or os.fstat(fd).st_mtime < now - 60:
                stale.unlink(missing_ok=True)
        except OSError:
            pass
        finally:
            os.close(fd)


def _lock(fd: int, wait: float) -> bool:
    """Take the lock of ``fd`` if it is free within ``wait`` seconds. A killed process's
    main thread turns zombie before its other threads have exited, and its files (with
    their locks) go with the last one: a writer seen dead gets a moment to let go."""
    deadline = time.monotonic() + wait
    while True:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return True
        except OSError:
            if time.monotonic() >= deadline:
                return False
            time.sleep(0.01)


def _running(pid: int) -> bool:
    """Whether process ``pid`` runs on this machine (a zombie, dead but not yet reaped by its
    parent, does not)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return True
    try:
        with open(f"/proc/{pid}/stat", "rb") as stat:
            state = stat.read().rsplit(b")", 1)[1].split()[0]
        return state not in (b"Z", b"X")
    except (OSError, IndexError):
        return True


def make_database(path: str | Path, schema: str, fill: Any) -> int:
    """Make a SQLite database (WAL) whole or not at all: its ``schema`` and what ``fill``
    (called with the open connection, in one transaction) writes go to a
    :class:`PartialFile`, linked into place only if nothing of that name exists. A kill at
    any moment leaves no database or a complete one.

    Returns:
        The descriptor holding the database's lock (the caller's to close: while open, no
        other writer takes the file).

    Raises:
        FileExistsError: ``path`` exists.
        OSError, sqlite3.Error: it cannot be made (nothing is left behind).
    """
    import sqlite3

    partial = PartialFile(path, opened=False)
    try:
        db = sqlite3.connect(str(partial.temporary), isolation_level=None)
        try:
            db.execute("PRAGMA journal_mode=WAL")
            db.executescript(schema)
            db.execute("BEGIN")
            fill(db)
            db.execute("COMMIT")
        finally:
            db.close()
        partial.link()
    except BaseException:
        partial.finish(keep=False)
        raise
    return partial.detach()


def write_atomic(path: str | Path, data: str | bytes) -> None:
    """Write ``data`` to ``path`` through a :class:`PartialFile` (a temporary file and an
    atomic rename).

    If anything fails before the rename, ``path`` keeps its old content (or stays
    absent) and the temporary file is removed; one left by a killed writer is removed by
    the next write of ``path``.
    """
    out = PartialFile(path, binary=isinstance(data, bytes))
    try:
        out.file.write(data)
    except BaseException:
        out.finish(keep=False)
        raise
    out.finish()


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
    bounded parser (:func:`petriflow.io.safe_yaml.parse_yaml`): no tags run, no alias bombs,
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
    from petriflow.io.safe_yaml import parse_yaml, plain, yaml_problem

    path = Path(path)
    text = read_text_file(path)
    try:
        data = parse_yaml(text)
        return data if lines else plain(data)
    except NetFormatError as exc:
        raise exc.at(str(path)) from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
        problem = getattr(exc, "problem", None) or getattr(exc, "context", None) or yaml_problem(exc)
        raise NetFormatError(f"malformed YAML: {problem}", path=str(path),
                             line=mark.line + 1 if mark else None) from None


def parse_json(text: str, *, integer: Any = None) -> Any:
    """Parse JSON text from a file petriflow did not write itself (PNML data, traces,
    journals), refusing what would exhaust the machine or crash later.

    Args:
        text: the JSON.
        integer: called with the text of each JSON integer, as ``json.loads``'s
            ``parse_int`` (default ``int``); ``parse_marking`` keeps the text, so that
            :func:`petriflow.limits.parse_integer` reads every count as written.

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
        value = json.loads(text, parse_constant=no_constant, parse_int=integer)
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
