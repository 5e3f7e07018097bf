"""Properties written by hand: the text syntax, the shorthands, and the ``properties:`` section.

A net's YAML file may carry a ``properties:`` list (and a PNML net a separate YAML file
with one, ``properties: [...]``). Each entry has an ``id`` and one of:

=====================================  ====================================================
``never: P``                           ``AG !P``: no reachable marking satisfies ``P``
``always: P``                          ``AG P``
``reachable: P``                       ``EF P``: some reachable marking satisfies ``P``
``eventually: P``                      LTL ``F P``: every run reaches ``P``
``responds: {to: P, with: Q}``         LTL ``G(P -> F Q)``: every ``P`` is answered by ``Q``
``bound: PLACE`` (or a list)           the most tokens the places hold together; with
                                       ``at_most: N``, whether that stays ``<= N``
``ctl: FORMULA``                       a CTL formula (``AG``, ``EF``, ``A[p U q]``, ...)
``ltl: FORMULA``                       an LTL formula, true when every run satisfies it
=====================================  ====================================================

and optionally ``description``. The formula syntax: state predicates compare linear sums
of token counts (``red_in + blue_in <= 1``, ``2*free >= 1``, ``== != < > <= >=``),
``enabled(t1, t2)`` (one of them can fire), ``deadlock``, ``true``, ``false``;
connectives ``!``/``not``, ``&&``/``and``, ``||``/``or``, ``->``; CTL ``AG AF AX EG EF
EX`` and ``A[p U q]``, ``E[p U q]``; LTL ``G F X`` and ``p U q``. Place and transition
names are the net's ids. Mistakes are :class:`~petriflow.errors.NetFormatError` naming
the file and line.

Examples:
    >>> str(parse_formula("AG(red_in + blue_in <= 1)"))
    'AG(red_in + blue_in <= 1)'
    >>> str(parse_formula("G(enabled(cfp) -> F answered >= 1)"))
    'G((!(enabled(cfp)) || F(answered >= 1)))'
    >>> parse_property({"id": "x", "responds": {"to": "asked >= 1", "with": "told >= 1"}}).kind
    'ltl'
    >>> parse_formula("AG(a <= )")
    Traceback (most recent call last):
    ...
    petriflow.errors.NetFormatError: formula 'AG(a <= )': expected a number or a place name at ')'
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from petriflow.errors import NetFormatError
from petriflow.properties.language import (
    AllPaths, And, Compare, Constant, Deadlock, ExistsPath, Finally, Fireable, Formula, Globally,
    Linear, Next, Not, Or, Property, Until, classify, is_state_formula, names_used
)

__all__ = ["check_property_names", "load_properties", "parse_formula", "parse_properties",
           "parse_property", "property_entry"]

_TOKEN = re.compile(r"\s*(?:(?P<num>\d+)|(?P<name>[A-Za-z_][A-Za-z0-9_.@]*)|"
                    r"(?P<op><=|>=|==|!=|->|&&|\|\||[-+*<>!()\[\],]))")
_COMPARE = {"<=", "<", ">=", ">", "==", "!="}
_UNARY = {"AG": (AllPaths, Globally), "AF": (AllPaths, Finally), "AX": (AllPaths, Next),
          "EG": (ExistsPath, Globally), "EF": (ExistsPath, Finally), "EX": (ExistsPath, Next),
          "G": (None, Globally), "F": (None, Finally), "X": (None, Next)}
_KEYWORDS = set(_UNARY) | {"A", "E", "U", "not", "and", "or", "true", "false", "deadlock", "enabled"}
_SHORTHANDS = ("never", "always", "reachable", "eventually", "responds", "bound", "ctl", "ltl")
_ENTRY_KEYS = {"id", "description", "at_most", *_SHORTHANDS}


class _Parser:
    def __init__(self, text: str) -> None:
        self.text = text
        self.tokens: list[tuple[str, str]] = []
        position = 0
        text = text.rstrip()
        while position < len(text):
            match = _TOKEN.match(text, position)
            if match is None:
                raise self.error(f"unexpected character {text[position:].strip()[0]!r}")
            kind = match.lastgroup or "op"
            self.tokens.append((kind, match.group(kind)))
            position = match.end()
        self.at = 0

    def error(self, message: str) -> NetFormatError:
        return NetFormatError(f"formula {self.text!r}: {message}")

    def peek(self) -> str | None:
        return self.tokens[self.at][1] if self.at < len(self.tokens) else None

    def take(self, expected: str | None = None) -> str:
        token = self.peek()
        if token is None or (expected is not None and token != expected):
            raise self.error(f"expected {expected or 'more'} at {repr(token) if token else 'the end'}")
        self.at += 1
        return token

    def formula(self) -> Formula:
        left = self.disjunction()
        if self.peek() == "->":
            self.take()
            return Or((Not(left), self.formula()))
        return left

    def chain(self, operators: tuple[str, str], operand, connective) -> Formula:
        """``operand (op operand)*`` as one ``connective`` (or the operand alone)."""
        parts = [operand()]
        while self.peek() in operators:
            self.take()
            parts.append(operand())
        return parts[0] if len(parts) == 1 else connective(tuple(parts))

    def disjunction(self) -> Formula:
        return self.chain(("||", "or"), self.conjunction, Or)

    def conjunction(self) -> Formula:
        return self.chain(("&&", "and"), self.until, And)

    def until(self) -> Formula:
        left = self.unary()
        if self.peek() == "U":
            self.take()
            return Until(left, self.until())
        return left

    def unary(self) -> Formula:
        token = self.peek()
        if token in ("!", "not"):
            self.take()
            return Not(self.unary())
        if token in _UNARY:
            self.take()
            quantifier, operator = _UNARY[token]
            inner = operator(self.unary())
            return inner if quantifier is None else quantifier(inner)
        if token in ("A", "E"):
            self.take()
            quantifier = AllPaths if token == "A" else ExistsPath
            if self.peek() == "[":
                self.take()
                left = self.formula_no_until()
                self.take("U")
                right = self.formula()
                self.take("]")
                return quantifier(Until(left, right))
            return quantifier(self.unary())
        return self.atom()

    def formula_no_until(self) -> Formula:
        left = self.unary()
        while self.peek() in ("&&", "and", "||", "or"):
            op = self.take()
            right = self.unary()
            left = And((left, right)) if op in ("&&", "and") else Or((left, right))
        return left

    def atom(self) -> Formula:
        token = self.peek()
        if token == "(":
            self.take()
            inner = self.formula()
            self.take(")")
            return inner
        if token in ("true", "false"):
            self.take()
            return Constant(token == "true")
        if token == "deadlock":
            self.take()
            return Deadlock()
        if token == "enabled":
            self.take()
            self.take("(")
            names = [self.name()]
            while self.peek() == ",":
                self.take()
                names.append(self.name())
            self.take(")")
            return Fireable(tuple(names))
        left = self.linear()
        op = self.peek()
        if op not in _COMPARE:
            raise self.error(f"expected a comparison (<=, ==, ...) after {left} at {repr(op) if op else 'the end'}")
        self.take()
        return Compare(op, left, self.linear())

    def name(self) -> str:
        kind, value = self.tokens[self.at] if self.at < len(self.tokens) else ("", "")
        if kind != "name" or value in _KEYWORDS:
            raise self.error(f"expected a transition name at {repr(value) if value else 'the end'}")
        self.at += 1
        return value

    def linear(self) -> Linear:
        total = self.term()
        while self.peek() in ("+", "-"):
            sign = 1 if self.take() == "+" else -1
            total = total.plus(self.term(), sign)
        return total

    def term(self) -> Linear:
        if self.peek() == "-":
            self.take()
            return self.term().times(-1)
        kind, value = self.tokens[self.at] if self.at < len(self.tokens) else ("", "")
        if kind == "num":
            self.at += 1
            if self.peek() == "*":
                self.take()
                return self.term().times(int(value))
            return Linear.constant(int(value))
        if kind == "name" and value not in _KEYWORDS:
            self.at += 1
            return Linear(((value, 1),))
        raise self.error(f"expected a number or a place name at {repr(value) if value else 'the end'}")


def parse_formula(text: str) -> Formula:
    """Parse the text syntax (module documentation) into a formula.

    Raises:
        NetFormatError: a syntax error, naming the formula and where.
    """
    if not isinstance(text, str) or not text.strip():
        raise NetFormatError(f"a formula must be non-empty text, got {text!r}")
    parser = _Parser(text)
    formula = parser.formula()
    if parser.peek() is not None:
        raise parser.error(f"unexpected {parser.peek()!r}")
    return formula


def _state(text: Any, what: str) -> Formula:
    formula = parse_formula(text)
    if not is_state_formula(formula):
        raise NetFormatError(f"{what} takes a state predicate (no temporal operator): {text!r}")
    return formula


def parse_property(entry: Any, path: str | None = None) -> Property:
    """One ``properties:`` entry (a mapping) as a :class:`~petriflow.properties.language.Property`.

    Raises:
        NetFormatError: not a mapping, no id, not exactly one shorthand, an unknown key, or
            a bad formula; the message names ``path`` and the entry's line.
    """
    line = getattr(entry, "line", None) or None
    try:
        return _property(entry, path, line)
    except NetFormatError as exc:
        if exc.path is None and path is not None:
            raise NetFormatError(exc.message, path=path, line=exc.line or line) from None
        raise


def _property(entry: Any, path: str | None, line: int | None) -> Property:
    if not isinstance(entry, dict):
        raise NetFormatError(f"a property is a mapping with an 'id', got {entry!r}", path=path, line=line)
    unknown = sorted(set(map(str, entry)) - _ENTRY_KEYS)
    ident = entry.get("id")
    if not isinstance(ident, str) or not ident:
        raise NetFormatError("a property needs an 'id' (text)", path=path, line=line)
    if unknown:
        raise NetFormatError(f"property {ident!r}: unknown key {unknown[0]!r} (one of: "
                             f"{', '.join(_SHORTHANDS)}, description, at_most)", path=path, line=line)
    kinds = [k for k in _SHORTHANDS if k in entry]
    if len(kinds) != 1:
        raise NetFormatError(f"property {ident!r}: give exactly one of {', '.join(_SHORTHANDS)}"
                             f" (found {', '.join(kinds) or 'none'})", path=path, line=line)
    kind, value = kinds[0], entry[kinds[0]]
    description = entry.get("description")
    if description is not None and not isinstance(description, str):
        raise NetFormatError(f"property {ident!r}: 'description' is text", path=path, line=line)
    at_most = entry.get("at_most")
    if at_most is not None and (kind != "bound" or not isinstance(at_most, int) or isinstance(at_most, bool)):
        raise NetFormatError(f"property {ident!r}: 'at_most' (an integer) goes with 'bound' only",
                             path=path, line=line)
    where = f"property {ident!r}: {kind}"
    try:
        if kind == "bound":
            places = [value] if isinstance(value, str) else value
            if not isinstance(places, list) or not places or not all(isinstance(p, str) for p in places):
                raise NetFormatError(f"{where} takes a place id or a list of them")
            return Property(ident, bound=tuple(places), at_most=at_most, line=line, source=path,
                            description=description)
        if kind == "responds":
            if not isinstance(value, dict) or set(value) != {"to", "with"}:
                raise NetFormatError(f"{where} takes {{to: P, with: Q}}")
            formula: Formula = AllPaths(Globally(Or((Not(_state(value["to"], where + ".to")),
                                                     Finally(_state(value["with"], where + ".with"))))))
        elif kind == "never":
            formula = AllPaths(Globally(Not(_state(value, where))))
        elif kind == "always":
            formula = AllPaths(Globally(_state(value, where)))
        elif kind == "reachable":
            formula = ExistsPath(Finally(_state(value, where)))
        elif kind == "eventually":
            formula = AllPaths(Finally(_state(value, where)))
        elif kind == "ltl":
            formula = parse_formula(value)
            if classify(formula) == "boolean":     # A G F p && A F q: each LTL formula quantified
                return Property(ident, formula, line=line, source=path, description=description)
            if not isinstance(formula, (AllPaths, ExistsPath)):
                formula = AllPaths(formula)
            if classify(formula) not in ("ltl", "reachability", "ctl") or any(
                    isinstance(node, (AllPaths, ExistsPath)) for node in formula.operand.walk()):
                raise NetFormatError(f"{where}: path quantifiers (A, E) belong to CTL: {value!r}")
        else:
            formula = parse_formula(value)
            if classify(formula) not in ("ctl", "reachability"):
                raise NetFormatError(f"{where}: not CTL (every G, F, X, U needs A or E in front): {value!r}")
    except NetFormatError as exc:
        message = exc.message
        if not message.startswith("property "):
            message = f"{where}: {message}"
        raise NetFormatError(message, path=path, line=line) from None
    return Property(ident, formula, line=line, source=path, description=description)


def parse_properties(entries: Any, path: str | None = None, line: int | None = None) -> list[Property]:
    """A ``properties:`` list; ids must be distinct."""
    if not isinstance(entries, list):
        raise NetFormatError("'properties' must be a list of mappings", path=path, line=line)
    found = [parse_property(entry, path) for entry in entries]
    seen: set[str] = set()
    for prop in found:
        if prop.id in seen:
            raise NetFormatError(f"duplicate property id {prop.id!r}", path=path, line=prop.line)
        seen.add(prop.id)
    return found


def load_properties(path: str | Path) -> list[Property]:
    """Read a properties file: the contest's XML (``<property-set>``) or YAML with a
    ``properties:`` list (or a bare list).

    Raises:
        NetFormatError: unreadable or malformed, naming the file and line.
    """
    from petriflow.io.files import read_text_file
    from petriflow.io.safe_yaml import parse_yaml, yaml_problem

    path = Path(path)
    if not path.is_file():
        raise NetFormatError("no such file", path=str(path))
    text = read_text_file(path)
    if text.lstrip().startswith("<"):
        from petriflow.properties.mcc_xml import parse_mcc_properties

        return parse_mcc_properties(text, str(path))
    try:
        data = parse_yaml(text)
    except NetFormatError as exc:
        raise NetFormatError(exc.message, path=str(path), line=exc.line) from None
    except Exception as exc:  # noqa: BLE001 - yaml's errors: one line naming the spot
        raise NetFormatError(yaml_problem(exc), path=str(path)) from None
    if isinstance(data, dict):
        if set(data) - {"properties"} or "properties" not in data:
            raise NetFormatError("a properties file holds one key, 'properties'", path=str(path),
                                 line=getattr(data, "line", None))
        data = data["properties"]
    return parse_properties(data, str(path))




def check_property_names(net: Any, properties: list[Property]) -> None:
    """Raise :class:`~petriflow.errors.NetFormatError` for the first property naming a
    place or transition ``net`` lacks (with the property's file and line, and a hint)."""
    from petriflow.errors import did_you_mean

    for prop in properties:
        places, transitions = (set(prop.bound), set()) if prop.formula is None else names_used(prop.formula)
        for kind, names, known in (("place", places, net.places), ("transition", transitions, net.transitions)):
            for name in sorted(names):
                if name not in known:
                    raise NetFormatError(f"property {prop.id!r}: unknown {kind} {name!r}"
                                         f"{did_you_mean(name, list(known))}", path=prop.source,
                                         line=prop.line)


def property_entry(prop: Property) -> dict[str, Any]:
    """A property as a ``properties:`` entry that :func:`parse_property` reads back.

    Examples:
        >>> property_entry(parse_property({"id": "x", "never": "a + b >= 2"}))
        {'id': 'x', 'never': 'a + b >= 2'}
        >>> property_entry(parse_property({"id": "y", "ctl": "AG EF o == 1"}))
        {'id': 'y', 'ctl': 'AG(EF(o == 1))'}
    """
    entry: dict[str, Any] = {"id": prop.id}
    if prop.description:
        entry["description"] = prop.description
    if prop.formula is None:
        entry["bound"] = list(prop.bound) if len(prop.bound) != 1 else prop.bound[0]
        if prop.at_most is not None:
            entry["at_most"] = prop.at_most
    else:
        entry.update(_shorthand(prop.formula))
    return entry


def _shorthand(formula: Formula) -> dict[str, Any]:
    """The shortest entry that reads back as ``formula``."""
    path = formula.operand if isinstance(formula, (AllPaths, ExistsPath)) else None
    inner = getattr(path, "operand", None)
    if isinstance(formula, AllPaths) and isinstance(path, Globally) and is_state_formula(inner):
        if isinstance(inner, Not):
            return {"never": str(inner.operand)}
        return {"always": str(inner)}
    if isinstance(formula, ExistsPath) and isinstance(path, Finally) and is_state_formula(inner):
        return {"reachable": str(inner)}
    if isinstance(formula, AllPaths) and isinstance(path, Finally) and is_state_formula(inner):
        return {"eventually": str(inner)}
    if (isinstance(formula, AllPaths) and isinstance(path, Globally) and isinstance(inner, Or)
            and len(inner.operands) == 2 and isinstance(inner.operands[0], Not)
            and isinstance(inner.operands[1], Finally) and is_state_formula(inner.operands[0].operand)
            and is_state_formula(inner.operands[1].operand)):
        return {"responds": {"to": str(inner.operands[0].operand), "with": str(inner.operands[1].operand)}}
    if classify(formula) == "ltl" and isinstance(formula, AllPaths):
        return {"ltl": str(formula.operand)}
    return {"ctl": str(formula)}
