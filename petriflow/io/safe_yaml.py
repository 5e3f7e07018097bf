"""YAML parsed safely into data that knows its lines.

:func:`parse_yaml` composes with a safe loader (no Python tags; libyaml's C parser when
PyYAML has it) and builds plain data whose mappings (:class:`LineDict`) and lists
(:class:`LineList`) record the line they start on, and each mapping the line of each
key, so that whoever reads a net, a run configuration, a world or a sweep names the
line of a mistake (:func:`line_of`). It refuses what would exhaust the machine: nesting
deeper than :data:`~petriflow.limits.YAML_DEPTH`, alias bombs, numbers too long to
convert, and integers in any form but plain decimal. :func:`plain` strips the line
records; :func:`yaml_problem` says what a YAML error is about, on one line.

Examples:
    >>> data = parse_yaml("net: demo\\nplaces: [i, o]\\n")
    >>> data, line_of(data["places"]), data.key_lines["places"]
    ({'net': 'demo', 'places': ['i', 'o']}, 2, 2)
    >>> parse_yaml("a: 1\\na: 2")
    Traceback (most recent call last):
    ...
    petriflow.errors.NetFormatError: line 2: duplicate key 'a'
"""

from __future__ import annotations

import re
from typing import Any

import yaml

from petriflow import limits
from petriflow.errors import NetFormatError, NumberError

__all__ = ["LineDict", "LineList", "line_of", "parse_yaml", "plain", "yaml_problem"]


class LineDict(dict):
    """A mapping that remembers its line and the line of each key."""

    line: int = 0
    key_lines: dict[Any, int] = {}


class LineList(list):
    """A list that remembers its line and the line of each item."""

    line: int = 0
    item_lines: list[int] = []


_Composer = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
_STR = "tag:yaml.org,2002:str"
_INT = "tag:yaml.org,2002:int"
_SEQ = "tag:yaml.org,2002:seq"
_MAP = "tag:yaml.org,2002:map"
_MERGE = "tag:yaml.org,2002:merge"


class _Builder:
    """Turns composed YAML nodes into plain data with line numbers.

    Composing is libyaml's (fast); building is this small walk: strings are taken as
    they are, other scalars through PyYAML's safe constructor; a node reached twice
    through an alias is built once and shared, so aliases never multiply work. The
    walk refuses what would exhaust the machine later: nesting deeper than
    :data:`~petriflow.limits.YAML_DEPTH`, more than :data:`~petriflow.limits.YAML_VALUES`
    values once aliases are expanded
    (an "alias bomb"), an alias inside itself, and numbers too long to convert.

    Integers follow petriflow's one rule (:func:`~petriflow.limits.parse_integer`):
    decimal ASCII digits with an optional sign, at most 2**60. The other forms YAML 1.1
    (PyYAML) reads as integers are refused with their line rather than guessed at:
    ``0x1F``, ``0b101``, ``017`` (octal 15 in YAML 1.1, 17 in YAML 1.2), ``1_000``,
    ``1:30`` (base 60: 90).
    """

    def __init__(self) -> None:
        self.scalars = yaml.SafeLoader("")
        self.built: dict[int, Any] = {}
        self.sizes: dict[int, int] = {}
        self.open: set[int] = set()
        self.total = 0

    def fail(self, message: str, node: yaml.Node) -> NetFormatError:
        return NetFormatError(message, line=node.start_mark.line + 1)

    def scalar(self, node: yaml.Node) -> Any:
        if node.tag == _INT:
            return self.integer(node)
        try:
            return self.scalars.construct_object(node)
        except (ValueError, OverflowError) as exc:  # e.g. an integer of more than 4,300 digits
            why = "a number of more than 4,300 digits" if "digits" in str(exc) else str(exc)
            raise self.fail(f"value {node.value[:20]!r}{'...' if len(node.value) > 20 else ''} cannot be"
                            f" read: {why}", node) from None

    def integer(self, node: yaml.Node) -> int:
        """A YAML integer, by the one rule (its text, not PyYAML's reading of it)."""
        text = node.value
        if re.fullmatch(r"[-+]?0[0-9]+", text) or (not re.fullmatch(r"[-+]?[0-9]+", text)
                                                   and re.fullmatch(r"[-+]?[0-9a-fA-FxXob_:]+", text)):
            shown = text if len(text) <= 20 else text[:20] + "..."
            meant = ""
            if len(text) <= 20:
                try:
                    meant = f" (YAML 1.1 reads it as {self.scalars.construct_object(node)})"
                except (ValueError, OverflowError):  # pragma: no cover - short texts convert
                    pass
            raise self.fail(f"integer {shown!r}{meant} is not plain decimal: petriflow reads whole numbers"
                            " written with the digits 0-9 and no leading zero (no 0x, 0b, octal, _ or"
                            " base 60); write it in decimal, or quote it to make it text", node)
        try:
            return limits.parse_integer(text, "integer")
        except NumberError as exc:
            raise self.fail(f"{exc} (quote it if it is text, such as an id)", node) from None

    def build(self, node: yaml.Node, depth: int = 0) -> Any:
        kind = node.__class__
        if kind is yaml.ScalarNode:
            self.total += 1
            return node.value if node.tag == _STR else self.scalar(node)
        key = id(node)
        if key in self.open:
            raise self.fail("an alias refers to a value that contains it (a recursive alias)", node)
        if key in self.built:  # an alias: shared, but counted as if it were copied
            self.total += self.sizes[key]
            if self.total > limits.YAML_VALUES:
                raise self.fail(f"more than {limits.YAML_VALUES:,} values once aliases are expanded (an alias bomb?)",
                                node)
            return self.built[key]
        if depth > limits.YAML_DEPTH:
            raise self.fail(f"nested more than {limits.YAML_DEPTH} levels deep", node)
        before = self.total
        self.open.add(key)
        try:
            result = self.container(node, kind, depth)
        finally:
            self.open.discard(key)
        self.sizes[key] = self.total - before
        self.built[key] = result
        return result

    def container(self, node: yaml.Node, kind: type, depth: int) -> Any:
        self.total += 1
        if node.tag not in (_SEQ, _MAP):  # !!set, !!omap...: PyYAML's safe constructor, or its error
            return self.scalars.construct_object(node, deep=True)
        if kind is yaml.SequenceNode:
            result = LineList()
            result.line = node.start_mark.line + 1
            result.item_lines = [child.start_mark.line + 1 for child in node.value]
            result.extend(self.build(child, depth + 1) for child in node.value)
            return result
        if kind is not yaml.MappingNode:  # pragma: no cover - the composer makes only these
            raise self.fail(f"unexpected YAML node {node.tag}", node)
        if any(key.tag == _MERGE for key, _ in node.value):
            self.scalars.flatten_mapping(node)
        mapping = LineDict()
        mapping.line = node.start_mark.line + 1
        mapping.key_lines = {}
        for key_node, value_node in node.value:
            key = self.build(key_node, depth + 1)
            try:
                hash(key)
            except TypeError:
                raise self.fail("a mapping key must be a plain value", key_node) from None
            if key in mapping:
                raise self.fail(f"duplicate key {key!r}", key_node)
            mapping.key_lines[key] = key_node.start_mark.line + 1
            mapping[key] = self.build(value_node, depth + 1)
        return mapping


def parse_yaml(text: str) -> Any:
    """Parse YAML text safely into data whose mappings and lists know their lines.

    Raises:
        yaml.YAMLError: malformed YAML.
        NetFormatError: a duplicate key (with its line).
    """
    node = yaml.compose(text, Loader=_Composer)  # noqa: S506 - a safe composer: no tags are run
    return None if node is None else _Builder().build(node)


def line_of(item: Any, default: int | None = None) -> int | None:
    """The line a parsed mapping or list starts on (``default`` for other values)."""
    return getattr(item, "line", default)


def plain(value: Any) -> Any:
    """Strip the line-recording containers so parameters are plain dicts and lists
    (:func:`parse_yaml` has bounded the size and depth already)."""
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items()}
    if isinstance(value, list):
        return [plain(v) for v in value]
    return value


def yaml_problem(exc: Exception) -> str:
    """A YAML error's problem, on one line (a reader error names the bad character)."""
    reason = getattr(exc, "reason", None)
    if reason is not None:  # yaml.reader.ReaderError: a character YAML does not allow
        return f"{reason} (character {getattr(exc, 'character', '?')!r} at position {getattr(exc, 'position', '?')})"
    return " ".join(str(exc).split())
