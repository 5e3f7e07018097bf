"""Markings: how many tokens each place holds.

A :class:`Marking` is a value: immutable, hashable, cheap to copy, and it stores only the
places that hold tokens, so two markings are equal exactly when every place holds the
same count.
"""

from __future__ import annotations

from typing import Any, Iterator, Mapping

from petriflow.errors import MarkingError

__all__ = ["Marking", "format_marking", "parse_marking"]


class Marking(Mapping[str, int]):
    """An immutable multiset of place ids.

    Missing places hold zero tokens; zero counts are never stored.

    Args:
        tokens: a mapping ``place id -> count`` (counts must be integers >= 0).

    Examples:
        >>> m = Marking({"p1": 2, "p2": 0})
        >>> m["p1"], m["p2"], len(m)
        (2, 0, 1)
        >>> m == Marking(p1=2)
        True
        >>> m + Marking(p3=1)
        Marking({'p1': 2, 'p3': 1})
    """

    __slots__ = ("_tokens", "_hash")

    def __init__(self, tokens: Mapping[str, int] | None = None, /, **more: int) -> None:
        counts: dict[str, int] = {}
        for source in (tokens or {}, more):
            for place, count in source.items():
                if isinstance(count, bool) or not isinstance(count, int):
                    raise MarkingError(
                        f"place {place!r}: token count must be a whole number, got {count!r}"
                    )
                if count < 0:
                    raise MarkingError(f"place {place!r}: token count {count} is negative")
                if count:
                    counts[str(place)] = counts.get(str(place), 0) + count
        self._tokens = dict(sorted(counts.items()))
        self._hash: int | None = None

    # Mapping protocol ------------------------------------------------------------
    def __getitem__(self, place: str) -> int:
        return self._tokens.get(place, 0)

    def __iter__(self) -> Iterator[str]:
        return iter(self._tokens)

    def __len__(self) -> int:
        return len(self._tokens)

    def __contains__(self, place: object) -> bool:
        return place in self._tokens

    # Read-only views of the stored dict (the Mapping defaults go through __getitem__).
    def keys(self):  # type: ignore[override]
        return self._tokens.keys()

    def items(self):  # type: ignore[override]
        return self._tokens.items()

    def values(self):  # type: ignore[override]
        return self._tokens.values()

    # Value semantics --------------------------------------------------------------
    def __hash__(self) -> int:
        if self._hash is None:
            self._hash = hash(tuple(self._tokens.items()))
        return self._hash

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Marking):
            return self._tokens == other._tokens
        if isinstance(other, Mapping):
            return self._tokens == {k: v for k, v in other.items() if v}
        return NotImplemented

    def __repr__(self) -> str:
        return f"Marking({self._tokens!r})"

    def __add__(self, other: Mapping[str, int]) -> "Marking":
        merged = dict(self._tokens)
        for place, count in other.items():
            merged[place] = merged.get(place, 0) + count
        return Marking(merged)

    def __ge__(self, other: Mapping[str, int]) -> bool:  # type: ignore[override]
        """Cover relation: every place holds at least as many tokens as in ``other``."""
        return all(self[p] >= c for p, c in other.items())

    def __le__(self, other: Mapping[str, int]) -> bool:  # type: ignore[override]
        return all(other.get(p, 0) >= c for p, c in self._tokens.items())

    @property
    def total(self) -> int:
        """Number of tokens in all places together."""
        return sum(self._tokens.values())

    def to_dict(self) -> dict[str, int]:
        """Plain ``{place: count}`` dict of the marked places, sorted by place id."""
        return dict(self._tokens)


def format_marking(marking: Mapping[str, int]) -> str:
    """A marking as the analyses' messages write it: ``place=count`` in the marking's
    order, or ``(empty)``.

    Examples:
        >>> format_marking(Marking({"p": 1, "q": 2})), format_marking({})
        ('p=1, q=2', '(empty)')
    """
    return ", ".join(f"{p}={c}" for p, c in marking.items()) or "(empty)"


def parse_marking(text: str, places: Any = None) -> Marking:
    """Read a marking given on the command line as a JSON object.

    Args:
        text: JSON such as ``'{"p1": 1, "p2": 2}'``.
        places: if given, the place ids the marking may name.

    Raises:
        MarkingError: the text is not a JSON object of place -> whole number (by
            :func:`petriflow.limits.parse_integer`'s rule: at most 2**60), or names an
            unknown place.

    Examples:
        >>> parse_marking('{"p1": 2}')
        Marking({'p1': 2})
    """
    from petriflow.io.files import parse_json

    try:
        data = parse_json(text, integer=_Written)
    except ValueError as exc:
        raise MarkingError(f"marking is not valid JSON: {exc}") from None
    if not isinstance(data, dict):
        raise MarkingError("marking must be a JSON object such as {\"p1\": 1}")
    if places is not None:
        from petriflow.errors import did_you_mean

        known = set(places)
        for place in data:
            if place not in known:
                raise MarkingError(f"marking names unknown place {place!r}{did_you_mean(place, known)}")
    from petriflow.errors import NumberError
    from petriflow.limits import parse_integer

    for place, count in data.items():  # each count as written, by the one rule: at most 2**60
        what = f"place {place!r}: token count"
        try:
            if isinstance(count, _Written):
                data[place] = parse_integer(count, what, minimum=0)
            elif isinstance(count, str):
                parse_integer(count, what)  # not a number at all: the rule's own message
                raise MarkingError(f"{what} must be a whole number, got the text {count!r}"
                                   " (no quotes in JSON)")
        except NumberError as exc:
            raise MarkingError(str(exc)) from None
    return Marking(data)


class _Written(str):
    """A JSON integer as written, for :func:`~petriflow.limits.parse_integer` to read
    (never ``int()`` of thousands of digits); shown without quotes, as in the JSON."""

    __slots__ = ()

    def __repr__(self) -> str:
        return str.__str__(self)
