"""One error hierarchy for petriflow.

Every error names the spot it is about, location first, so the command line can print
it as a single line: ``nets/relay.yaml:14: transition 'grab': unknown place 'p9'``.
"""

from __future__ import annotations

import difflib
from typing import Iterable

__all__ = [
    "PetriflowError",
    "NetFormatError",
    "NetStructureError",
    "UnknownElementError",
    "NotEnabledError",
    "MarkingError",
    "NumberError",
    "DependencyNotInstalled",
    "did_you_mean",
]


def did_you_mean(name: str, candidates: Iterable[str]) -> str:
    """Return a ``" (did you mean 'x'?)"`` hint, or ``""`` when nothing is close.

    Examples:
        >>> did_you_mean("grap", ["grab", "drop"])
        " (did you mean 'grab'?)"
        >>> did_you_mean("zzz", ["grab"])
        ''
        >>> did_you_mean(-1, ["grab"])  # a name read from a file may be any YAML key
        ''
    """
    close = difflib.get_close_matches(str(name), [str(c) for c in candidates], n=3, cutoff=0.6)
    if not close:
        return ""
    return " (did you mean " + " or ".join(repr(c) for c in close) + "?)"


class PetriflowError(Exception):
    """Base class of every error petriflow raises on purpose."""


class NetFormatError(PetriflowError):
    """A net file (YAML or PNML) cannot be read as a net.

    Args:
        message: what is wrong, without the location.
        path: the file, if known.
        line: 1-based line number in the file, if known.
        element: id of the net element concerned, if any.

    Examples:
        >>> str(NetFormatError("unknown place 'p9'", path="n.yaml", line=3, element="t1"))
        "n.yaml:3: 't1': unknown place 'p9'"
    """

    def __init__(
        self,
        message: str,
        *,
        path: str | None = None,
        line: int | None = None,
        element: str | None = None,
    ) -> None:
        self.message = message
        self.path = path
        self.line = line
        self.element = element
        super().__init__(self._render())

    def _render(self) -> str:
        where = ""
        if self.path is not None:
            where = str(self.path)
            if self.line is not None:
                where += f":{self.line}"
            where += ": "
        elif self.line is not None:
            where = f"line {self.line}: "
        element = f"{self.element!r}: " if self.element is not None else ""
        return f"{where}{element}{self.message}"

    def at(self, path: str) -> "NetFormatError":
        """Return a copy of this error that names ``path`` (when it names none yet)."""
        if self.path is not None:
            return self
        return type(self)(self.message, path=path, line=self.line, element=self.element)


class NetStructureError(PetriflowError):
    """A net built in code breaks a structural rule (duplicate id, dangling arc...)."""


class UnknownElementError(PetriflowError, KeyError):
    """A place or transition id that the net does not have."""

    def __init__(self, kind: str, name: str, candidates: Iterable[str]) -> None:
        self.kind = kind
        self.name = name
        candidates = list(candidates)
        hint = did_you_mean(name, candidates)
        if not hint and candidates:  # nothing close: say what there is
            shown = ", ".join(candidates[:8]) + (f" and {len(candidates) - 8} more" if len(candidates) > 8 else "")
            hint = f" (the net has: {shown})"
        self.message = f"unknown {kind} {name!r}{hint}"
        super().__init__(self.message)

    def __str__(self) -> str:  # KeyError would quote the whole message
        return self.message


class NotEnabledError(PetriflowError):
    """A transition was asked to fire in a marking that does not enable it."""

    def __init__(self, transition: str, missing: dict[str, tuple[int, int]]) -> None:
        self.transition = transition
        self.missing = missing
        need = ", ".join(
            f"{place} has {have}, needs {want}" for place, (have, want) in sorted(missing.items())
        )
        super().__init__(f"transition {transition!r} is not enabled: {need}")


class MarkingError(PetriflowError):
    """A marking is malformed: unknown place, negative or non-integer token count."""


class NumberError(PetriflowError, ValueError):
    """A whole number, as written in a file or an option, breaks petriflow's one rule for
    them (:func:`petriflow.limits.parse_integer`): ASCII digits only, at most 2**60.

    A :class:`ValueError` too, so that code expecting ``int()``'s error catches it."""


class DependencyNotInstalled(PetriflowError):
    """An optional dependency needed for this feature is missing."""
