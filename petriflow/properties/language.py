"""The property language: state predicates, CTL and LTL formulas, and named properties.

A formula is a tree of frozen dataclasses:

* **State predicates** — :class:`Compare` of two :class:`Linear` token sums
  (``red_in + blue_in <= 1``; the contest's ``tokens-count`` and ``integer-constant``),
  :class:`Fireable` (some of the named transitions is enabled: the contest's
  ``is-fireable``), :class:`Deadlock` (no transition enabled), :class:`Constant`, and the
  Boolean connectives :class:`Not`, :class:`And`, :class:`Or`.
* **Temporal operators** — :class:`Next` (``X``), :class:`Finally` (``F``),
  :class:`Globally` (``G``) and :class:`Until` (``U``), and the path quantifiers
  :class:`AllPaths` (``A``) and :class:`ExistsPath` (``E``). CTL pairs every temporal
  operator with a quantifier (``AG``, ``E[p U q]``); LTL has one ``A`` around a path
  formula with no quantifier inside.

A :class:`Property` is a formula (or, for an upper bound, a list of places) with an id.
:func:`classify` says which checker decides a formula.

Examples:
    >>> p = Compare("<=", Linear.of_places(["red_in", "blue_in"]), Linear.constant(1))
    >>> str(AllPaths(Globally(p)))
    'AG(red_in + blue_in <= 1)'
    >>> classify(AllPaths(Globally(p))), classify(AllPaths(Globally(Finally(p))))
    ('reachability', 'ltl')
    >>> classify(AllPaths(Globally(ExistsPath(Finally(p)))))
    'ctl'
    >>> classify(Or((AllPaths(Globally(Finally(p))), ExistsPath(Finally(p)))))
    'boolean'
    >>> classify(AllPaths(Finally(ExistsPath(Globally(Finally(p))))))
    'ctl*'
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from typing import ClassVar

__all__ = [
    "AllPaths", "And", "Compare", "Constant", "Deadlock", "ExistsPath", "Finally", "Fireable",
    "Formula", "Globally", "Linear", "Next", "Not", "Or", "Property", "Until", "atoms",
    "classify", "is_state_formula", "names_used",
]

_COMPARISONS = {"<=", "<", ">=", ">", "==", "!="}


@dataclass(frozen=True)
class Linear:
    """``sum(coefficient * tokens(place)) + constant``: an integer expression over a marking."""

    terms: tuple[tuple[str, int], ...] = ()
    offset: int = 0

    @staticmethod
    def of_places(places: Iterable[str]) -> Linear:
        """The total of the places' tokens (the contest's ``tokens-count``)."""
        return Linear(tuple((p, 1) for p in places))

    @staticmethod
    def constant(value: int) -> Linear:
        """A constant."""
        return Linear((), int(value))

    def plus(self, other: Linear, sign: int = 1) -> Linear:
        """``self + sign * other``, like terms merged."""
        merged: dict[str, int] = dict(self.terms)
        for place, k in other.terms:
            merged[place] = merged.get(place, 0) + sign * k
        return Linear(tuple((p, k) for p, k in merged.items() if k), self.offset + sign * other.offset)

    def times(self, factor: int) -> Linear:
        """``factor * self``."""
        return Linear(tuple((p, k * factor) for p, k in self.terms if k * factor), self.offset * factor)

    def __str__(self) -> str:
        parts = []
        for place, k in self.terms:
            text = place if abs(k) == 1 else f"{abs(k)}*{place}"
            parts.append(("- " if k < 0 else "+ ") + text)
        if self.offset or not parts:
            parts.append(("- " if self.offset < 0 else "+ ") + str(abs(self.offset)))
        text = " ".join(parts)
        return text[2:] if text.startswith("+ ") else "-" + text[2:]


class Formula:
    """Base of every formula node (state predicates and temporal operators)."""

    def children(self) -> tuple[Formula, ...]:
        """The direct subformulas."""
        return tuple(getattr(self, name) for name in self.__dataclass_fields__  # type: ignore[attr-defined]
                     if isinstance(getattr(self, name), Formula))

    def walk(self) -> Iterator[Formula]:
        """This node and every node below it, depth first."""
        yield self
        for child in self.children():
            yield from child.walk()


@dataclass(frozen=True)
class Constant(Formula):
    """``true`` or ``false``."""

    value: bool

    def __str__(self) -> str:
        return "true" if self.value else "false"


@dataclass(frozen=True)
class Compare(Formula):
    """``left OP right`` over token counts, ``OP`` one of ``<= < >= > == !=``."""

    op: str
    left: Linear
    right: Linear

    def __post_init__(self) -> None:
        if self.op not in _COMPARISONS:
            raise ValueError(f"unknown comparison {self.op!r}")

    def __str__(self) -> str:
        return f"{self.left} {self.op} {self.right}"


@dataclass(frozen=True)
class Fireable(Formula):
    """Some of ``transitions`` is enabled (the contest's ``is-fireable``; none: false)."""

    transitions: tuple[str, ...]

    def __str__(self) -> str:
        return f"enabled({', '.join(self.transitions)})"


@dataclass(frozen=True)
class Deadlock(Formula):
    """No transition is enabled."""

    def __str__(self) -> str:
        return "deadlock"


@dataclass(frozen=True)
class _Unary(Formula):
    """An operator of one operand, written ``SYMBOL(operand)``."""

    operand: Formula
    symbol: ClassVar[str] = ""

    def __str__(self) -> str:
        return f"{self.symbol}({self.operand})"


class Not(_Unary):
    """Negation."""

    symbol = "!"


@dataclass(frozen=True)
class _Nary(Formula):
    """An associative connective of any number of operands (none: its unit)."""

    operands: tuple[Formula, ...]
    symbol: ClassVar[str] = ""
    unit: ClassVar[str] = ""

    def children(self) -> tuple[Formula, ...]:
        return self.operands

    def __str__(self) -> str:
        return "(" + f" {self.symbol} ".join(map(str, self.operands)) + ")" if self.operands else self.unit


class And(_Nary):
    """Conjunction (of two or more operands; none: true)."""

    symbol, unit = "&&", "true"


class Or(_Nary):
    """Disjunction (of two or more operands; none: false)."""

    symbol, unit = "||", "false"


class Next(_Unary):
    """``X φ``: φ holds in the next state."""

    symbol = "X"


class Finally(_Unary):
    """``F φ``: φ holds now or later."""

    symbol = "F"


class Globally(_Unary):
    """``G φ``: φ holds now and forever."""

    symbol = "G"


@dataclass(frozen=True)
class Until(Formula):
    """``φ U ψ``: ψ holds some time, φ until then (strong until)."""

    left: Formula
    right: Formula

    def __str__(self) -> str:
        return f"({self.left} U {self.right})"


class AllPaths(_Unary):
    """``A ψ``: every path from the state satisfies ψ."""

    def __str__(self) -> str:
        return "A" + _quantified(self.operand)


class ExistsPath(_Unary):
    """``E ψ``: some path from the state satisfies ψ."""

    def __str__(self) -> str:
        return "E" + _quantified(self.operand)


def _quantified(path: Formula) -> str:
    """How a path formula reads after ``A``/``E``: ``G(p)``, ``[p U q]``, ``(...)``."""
    inner = str(path)
    if isinstance(path, (Next, Finally, Globally)):
        return inner
    return f"[{inner[1:-1]}]" if isinstance(path, Until) else f"({inner})"


_TEMPORAL = (Next, Finally, Globally, Until)
_QUANTIFIERS = (AllPaths, ExistsPath)
_ATOMS = (Constant, Compare, Fireable, Deadlock)


@dataclass(frozen=True)
class Property:
    """A named property: a formula, or (``bound``) the places whose token total is bounded.

    ``at_most`` turns a bound into a yes/no property (the total never exceeds it);
    ``line`` is where it was declared, when read from a file.
    """

    id: str
    formula: Formula | None = None
    bound: tuple[str, ...] = ()
    at_most: int | None = None
    line: int | None = field(default=None, compare=False)
    source: str | None = field(default=None, compare=False)
    description: str | None = None

    @property
    def kind(self) -> str:
        """``bound``, or the checker of the formula (:func:`classify`)."""
        return "bound" if self.formula is None else classify(self.formula)


def is_state_formula(formula: Formula) -> bool:
    """Whether the formula has no temporal operator or path quantifier."""
    return not any(isinstance(node, _TEMPORAL + _QUANTIFIERS) for node in formula.walk())


def atoms(formula: Formula) -> list[Formula]:
    """The maximal state subformulas a temporal formula is built from (no duplicates)."""
    found: dict[Formula, None] = {}

    def visit(node: Formula) -> None:
        if is_state_formula(node):
            found[node] = None
        else:
            for child in node.children():
                visit(child)

    visit(formula)
    return list(found)


def _is_ctl(formula: Formula, under_quantifier: bool = False) -> bool:
    if isinstance(formula, _QUANTIFIERS):
        return isinstance(formula.operand, _TEMPORAL) and _is_ctl(formula.operand, True)
    if isinstance(formula, _TEMPORAL):
        return under_quantifier and all(_is_ctl(c) for c in formula.children())
    return all(_is_ctl(c) for c in formula.children())


def _is_path_ltl(formula: Formula) -> bool:
    return not any(isinstance(node, _QUANTIFIERS) for node in formula.walk())


def classify(formula: Formula) -> str:
    """Which checker decides ``formula`` at the initial marking.

    ``reachability`` (``EF p``/``AG p``, p a state predicate, or a state predicate
    alone), ``ctl`` (every temporal operator directly under a quantifier), ``ltl``
    (``A`` or ``E`` around a quantifier-free path formula, or a path formula alone,
    read as ``A``), ``boolean`` (``!``, ``&&``, ``||`` of quantified formulas of those
    kinds, some of them LTL: ``A G F p && A F q``, each decided on its own), else
    ``ctl*`` (not decided).
    """
    if is_state_formula(formula):
        return "reachability"
    if isinstance(formula, (AllPaths, ExistsPath)) and isinstance(formula.operand, (Finally, Globally)) \
            and is_state_formula(formula.operand.operand) \
            and isinstance(formula.operand, Globally if isinstance(formula, AllPaths) else Finally):
        return "reachability"
    if _is_ctl(formula):
        return "ctl"
    if _is_path_ltl(formula) or (isinstance(formula, _QUANTIFIERS) and _is_path_ltl(formula.operand)):
        return "ltl"
    if isinstance(formula, (And, Or, Not)) and all(
            isinstance(c, (AllPaths, ExistsPath, And, Or, Not)) or is_state_formula(c) for c in formula.children()) \
            and all(classify(c) != "ctl*" for c in formula.children()):
        return "boolean"
    return "ctl*"


def names_used(formula: Formula) -> tuple[set[str], set[str]]:
    """``(places, transitions)`` the formula names."""
    places: set[str] = set()
    transitions: set[str] = set()
    for node in formula.walk():
        if isinstance(node, Compare):
            places.update(p for p, _ in node.left.terms + node.right.terms)
        elif isinstance(node, Fireable):
            transitions.update(node.transitions)
    return places, transitions
