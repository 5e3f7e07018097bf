"""XML parsed safely, each element knowing the line it starts on.

Files are parsed with ``defusedxml.ElementTree``'s ``DefusedXMLParser`` with
``forbid_dtd=True`` (which also forbids entity declarations and external references).
The documents petriflow reads (PNML) never need a DTD, so any ``<!DOCTYPE>`` is refused
before an entity could be declared, expanded or fetched: no XXE, no entity-expansion
bombs, no network access. defusedxml is already a petriflow dependency, so nothing more
is needed (lxml, which pm4py brings along, is not used). The parser feeds a tree builder
that records the line each element starts on (:func:`line_of`), so errors name their
line. Tags are matched by their local name (:func:`local_name`, :func:`child`,
:func:`children`): no namespace tricks.

Examples:
    >>> root = parse_xml('<pnml xmlns="urn:x">\\n  <net id="n"/>\\n</pnml>', "a.pnml")
    >>> local_name(root.tag), [line_of(net) for net in children(root, "net")]
    ('pnml', [2])
    >>> parse_xml('<!DOCTYPE pnml [<!ENTITY e "x">]><pnml/>', "a.pnml")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    petriflow.errors.NetFormatError: a.pnml:1: DOCTYPE, entity declarations and external references ...
"""

from __future__ import annotations

import re
from typing import Any
from xml.etree.ElementTree import Element, ParseError, TreeBuilder

from defusedxml import DefusedXmlException
from defusedxml.ElementTree import DefusedXMLParser

from petriflow.errors import NetFormatError

__all__ = ["LineElement", "child", "children", "line_of", "local_name", "parse_xml"]


class LineElement(Element):
    """An element that remembers the line its start tag is on."""

    sourceline: int | None = None


class _LineTreeBuilder(TreeBuilder):
    """Builds :class:`LineElement` elements stamped with the parser's current line."""

    def __init__(self) -> None:
        super().__init__(element_factory=LineElement)
        self.expat: Any = None

    def start(self, tag: str, attrs: dict[str, str]) -> Element:  # type: ignore[override]
        element = super().start(tag, attrs)
        if self.expat is not None:
            element.sourceline = self.expat.CurrentLineNumber
        return element


def parse_xml(data: str | bytes, path: str | None, document: str = "PNML") -> Element:
    """Parse ``data`` into elements that know their lines.

    Raises:
        NetFormatError: malformed XML, a DOCTYPE or entity, or text that cannot be
            decoded, naming ``path`` and the line (``document`` names the format the
            file should be in).
    """
    builder = _LineTreeBuilder()
    parser = DefusedXMLParser(target=builder, forbid_dtd=True, forbid_entities=True,
                              forbid_external=True)
    builder.expat = parser.parser
    try:
        parser.feed(data)
        return parser.close()
    except ParseError as exc:
        line = exc.position[0] if getattr(exc, "position", None) else None
        problem = re.sub(r": line \d+, column \d+$", "", str(exc))
        raise NetFormatError(f"malformed XML: {problem}", path=path, line=line) from None
    except DefusedXmlException:
        raise NetFormatError(
            f"DOCTYPE, entity declarations and external references are not allowed in {document}",
            path=path, line=parser.parser.CurrentLineNumber,
        ) from None
    except (ValueError, LookupError) as exc:  # undecodable text, unknown encoding
        raise NetFormatError(f"cannot decode the file: {exc}", path=path) from None


def local_name(tag: str) -> str:
    """A tag without its namespace."""
    return tag.rpartition("}")[2]


def children(element: Element, name: str) -> list[Element]:
    """The children of ``element`` named ``name`` (by local name)."""
    return [found for found in element if local_name(found.tag) == name]


def child(element: Element | None, name: str) -> Element | None:
    """The first child of ``element`` named ``name`` (by local name), or ``None``."""
    if element is None:
        return None
    for found in element:
        if local_name(found.tag) == name:
            return found
    return None


def line_of(element: Element | None) -> int | None:
    """The line ``element`` starts on (``None`` for an element not parsed here)."""
    return getattr(element, "sourceline", None)
