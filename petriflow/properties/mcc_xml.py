"""The Model Checking Contest's property files, read as they are published.

``ReachabilityCardinality.xml``, ``ReachabilityFireability.xml``, ``UpperBounds.xml``,
``CTLCardinality.xml``, ``CTLFireability.xml``, ``LTLCardinality.xml`` and
``LTLFireability.xml`` all hold a ``<property-set>`` of ``<property>`` elements, each with
an ``<id>`` and a ``<formula>``. The XML is parsed by :mod:`petriflow.io.safe_xml` (no
DTD, no entities). Element names map onto :mod:`petriflow.properties.language`:
``all-paths``/``exists-path`` → ``A``/``E``; ``globally``/``finally``/``next`` →
``G``/``F``/``X``; ``until`` with ``before``/``reach`` → ``U``; ``negation``,
``conjunction``, ``disjunction``; ``integer-le`` over ``tokens-count`` (a sum of
places) and ``integer-constant``; ``is-fireable`` (some listed transition enabled);
``place-bound`` (the UpperBounds examination: the most tokens the listed places hold
together in a reachable marking). Anything else is an error naming the file, line and
element.

Examples:
    >>> text = '''<property-set xmlns="http://mcc.lip6.fr/"><property><id>N-00</id><formula>
    ... <exists-path><finally><integer-le><integer-constant>2</integer-constant>
    ... <tokens-count><place>p</place><place>q</place></tokens-count></integer-le>
    ... </finally></exists-path></formula></property></property-set>'''
    >>> [str(p.formula) for p in parse_mcc_properties(text, "f.xml")]
    ['EF(2 <= p + q)']
"""

from __future__ import annotations

from pathlib import Path

from petriflow.errors import NetFormatError
from petriflow.io.safe_xml import child, children, line_of, local_name, parse_xml
from petriflow.properties.language import (
    AllPaths, And, Compare, Constant, Deadlock, ExistsPath, Finally, Fireable, Formula, Globally,
    Linear, Next, Not, Or, Property, Until
)

__all__ = ["load_mcc_properties", "parse_mcc_properties"]

_UNARY = {"all-paths": AllPaths, "exists-path": ExistsPath, "globally": Globally,
          "finally": Finally, "next": Next, "negation": Not}


def load_mcc_properties(path: str | Path) -> list[Property]:
    """Read a contest property file.

    Raises:
        NetFormatError: unreadable, malformed, or an element this reader does not know.
    """
    from petriflow.io.files import read_text_file

    return parse_mcc_properties(read_text_file(Path(path)), str(path))


def parse_mcc_properties(text: str, path: str | None = None) -> list[Property]:
    """The properties of a contest ``<property-set>`` document, in file order."""
    root = parse_xml(text, path, document="property XML")
    if local_name(root.tag) != "property-set":
        raise NetFormatError(f"expected <property-set>, found <{local_name(root.tag)}>", path=path,
                             line=line_of(root))
    found = []
    for item in children(root, "property"):
        ident = child(item, "id")
        formula = child(item, "formula")
        if ident is None or not (ident.text or "").strip():
            raise NetFormatError("<property> without an <id>", path=path, line=line_of(item))
        name = ident.text.strip()
        if formula is None or len(formula) != 1:
            raise NetFormatError(f"property {name!r}: <formula> must hold one element", path=path,
                                 line=line_of(formula if formula is not None else item))
        top = formula[0]
        if local_name(top.tag) == "place-bound":
            found.append(Property(name, bound=_places(top, path), line=line_of(item), source=path))
        else:
            found.append(Property(name, _formula(top, path), line=line_of(item), source=path))
    return found


def _fail(element, message: str, path: str | None) -> NetFormatError:
    return NetFormatError(message, path=path, line=line_of(element))


def _places(element, path: str | None) -> tuple[str, ...]:
    names = []
    for item in element:
        if local_name(item.tag) != "place" or not (item.text or "").strip():
            raise _fail(item, f"<{local_name(element.tag)}> holds <place> names only, found "
                              f"<{local_name(item.tag)}>", path)
        names.append(item.text.strip())
    return tuple(names)


def _operands(element, path: str | None, count: int | None = None) -> list[Formula]:
    items = [_formula(item, path) for item in element]
    if count is not None and len(items) != count:
        raise _fail(element, f"<{local_name(element.tag)}> takes {count} operand(s), found {len(items)}",
                    path)
    return items


def _integer(element, path: str | None) -> Linear:
    tag = local_name(element.tag)
    if tag == "tokens-count":
        return Linear.of_places(_places(element, path))
    if tag == "integer-constant":
        try:
            return Linear.constant(int((element.text or "").strip()))
        except ValueError:
            raise _fail(element, f"<integer-constant> is not an integer: {element.text!r}", path) from None
    if tag in ("integer-sum", "integer-difference"):
        parts = [_integer(item, path) for item in element]
        total = parts[0] if parts else Linear.constant(0)
        for part in parts[1:]:
            total = total.plus(part, -1 if tag == "integer-difference" else 1)
        return total
    raise _fail(element, f"unknown integer expression <{tag}>", path)


def _formula(element, path: str | None) -> Formula:
    tag = local_name(element.tag)
    if tag in _UNARY:
        return _UNARY[tag](*_operands(element, path, 1))
    if tag in ("conjunction", "disjunction"):
        operands = tuple(_operands(element, path))
        return And(operands) if tag == "conjunction" else Or(operands)
    if tag == "until":
        before, reach = child(element, "before"), child(element, "reach")
        if before is None or reach is None or len(element) != 2:
            raise _fail(element, "<until> needs <before> and <reach>", path)
        return Until(*_operands(before, path, 1), *_operands(reach, path, 1))
    if tag in ("integer-le", "integer-lt", "integer-ge", "integer-gt", "integer-eq", "integer-ne"):
        values = [_integer(item, path) for item in element]
        if len(values) != 2:
            raise _fail(element, f"<{tag}> compares two integers, found {len(values)}", path)
        op = {"le": "<=", "lt": "<", "ge": ">=", "gt": ">", "eq": "==", "ne": "!="}[tag[8:]]
        return Compare(op, values[0], values[1])
    if tag == "is-fireable":
        names = []
        for item in element:
            if local_name(item.tag) != "transition" or not (item.text or "").strip():
                raise _fail(item, "<is-fireable> holds <transition> names only", path)
            names.append(item.text.strip())
        return Fireable(tuple(names))
    if tag in ("true", "false"):
        return Constant(tag == "true")
    if tag == "deadlock":
        return Deadlock()
    raise _fail(element, f"unknown formula element <{tag}>", path)
