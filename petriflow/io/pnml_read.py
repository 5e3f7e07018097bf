"""Reading PNML: the ISO/IEC 15909-2 P/T net format and the dialects tools write.

Use it through :mod:`petriflow.io.pnml` (``load_pnml``, ``loads_pnml``). This module holds
the reader; :mod:`petriflow.io.pnml_write` holds the writer.

Parser and hardening: files are parsed with ``defusedxml.ElementTree``'s
``DefusedXMLParser`` with ``forbid_dtd=True`` (which also forbids entity declarations and
external references). A PNML file never needs a DTD, so any ``<!DOCTYPE>`` is refused
before an entity could be declared, expanded or fetched: no XXE, no entity-expansion
bombs, no network access. defusedxml is already a petriflow dependency, so reading PNML
needs nothing more (lxml, which pm4py brings along, is not used). The parser feeds a
tree builder that records the line each element starts on, so errors name their line.
Nothing read from a file is ever evaluated or unpickled.

Dialects read (all without namespace tricks: tags are matched by local name):

* ISO/IEC 15909-2 (ePNK, the Model Checking Contest): nested ``<page>`` elements are
  flattened (every node kept), ``referencePlace``/``referenceTransition`` chains are
  resolved to their final node, ``<name><text>``, ``<initialMarking><text>``,
  ``<inscription><text>``; node positions go to ``meta["position"] = [x, y]``; the
  MCC's NUPN unit structure (``<toolspecific tool="nupn">``) goes to
  ``net.meta["nupn"]`` (units, their places and subunits, root, safe), which the writer
  keeps with the net's other meta data.
* PM4Py / ProM (``pnmlcoremodel``): ``<finalmarkings>``, ``$invisible$`` silent
  transitions, ``<arctype>normal``; data Petri net extras are reported, not kept.
* WoPeD (``ptNetb``): operator parts rebuild :class:`~petriflow.net.Operator`;
  subprocess pages stay one atomic transition.
* JARP / Petri Net Plans (``PTNet``) and PIPE (``P/T net``): ``<value>`` labels,
  PIPE's ``"Default,1"`` token counts; GSPN timing is reported, not kept.
* SNAKES and other writers that give no net type at all.

Refused with :class:`~petriflow.errors.NetFormatError` (file, line, element): malformed
or unsafe XML, a root other than ``<pnml>``, more than one ``<net>``, net types that are
not P/T (coloured, high-level, unknown), duplicate ids, arcs to missing nodes or between
two places or two transitions, reset/inhibitor arcs, counts and weights that are not
whole numbers (or are negative, or a zero weight), tokens of several colours, and
reference cycles or dangling references.

Every whole number in the file (initial and final markings, inscriptions, PIPE's
``class,count`` pairs, SNAKES multiplicities, capacities, positions, WoPeD operator
types, petriflow priorities and outcome weights) is read by one rule,
:func:`petriflow.limits.parse_integer`: XSD's integer, an optional sign and the ASCII
digits 0-9 (another script's digits, such as U+0663, are refused, not read as 3), at
most 2**60; a refusal names the file and the line.

Layout beyond node positions (arc bend points, label offsets, sizes, token graphics) is
not kept and not reported: it has no meaning for the net. Everything else the model
cannot hold is reported with one :class:`PnmlWarning` per kind of loss, naming the file
and the elements.
"""

from __future__ import annotations

import math
import re
import warnings
from pathlib import Path
from typing import Any, NoReturn
from xml.etree.ElementTree import Element, ParseError, TreeBuilder

from defusedxml import DefusedXmlException
from defusedxml.ElementTree import DefusedXMLParser

from petriflow import limits
from petriflow.errors import NetFormatError, NumberError, PetriflowError, did_you_mean
from petriflow.io.files import parse_json
from petriflow.net import OPERATOR_KINDS, OUTCOMES, Net, Operator

__all__ = [
    "PnmlWarning",
    "PNML_NAMESPACE",
    "PTNET_TYPE",
    "PT_NET_TYPES",
    "WOPED_OPERATOR_TYPES",
    "PETRIFLOW_TOOL",
    "PETRIFLOW_TOOL_VERSION",
    "load_pnml",
    "loads_pnml",
]

#: Namespace of ISO/IEC 15909-2 PNML documents.
PNML_NAMESPACE = "http://www.pnml.org/version-2009/grammar/pnml"
#: Net type of an ISO/IEC 15909-2 place/transition net (what the writer writes).
PTNET_TYPE = "http://www.pnml.org/version-2009/grammar/ptnet"

#: Net types read as place/transition nets, with the tools that write them. A ``<net>``
#: without a ``type`` (SNAKES, course material) is read as a P/T net too; any other
#: type is refused.
PT_NET_TYPES: dict[str, str] = {
    PTNET_TYPE: "ISO/IEC 15909-2 P/T net (ePNK, Model Checking Contest)",
    "http://www.pnml.org/version-2009/grammar/pnmlcoremodel": "PNML core model (PM4Py, ProM)",
    "http://www.informatik.hu-berlin.de/top/pntd/ptNetb": "WoPeD",
    "http://www.informatik.hu-berlin.de/top/pntd/ptNet": "pre-ISO PNML P/T net (PNK)",
    "PTNet": "JARP, Petri Net Plans",
    "P/T net": "PIPE",
}

_OTHER_NET_KINDS = {
    "symmetricnet": "a symmetric (coloured) net",
    "hlpn": "a high-level Petri net",
    "hlpng": "a high-level Petri net",
    "pt-hlpng": "a P/T net in high-level notation",
    "pt_hlpng": "a P/T net in high-level notation",
    "empty": "an 'empty' net type (no P/T semantics)",
}

#: WoPeD operator codes as ``code: (split, join)``, from the constants of WoPeD's
#: ``org.woped.core.model.petrinet.OperatorTransitionModel``: 101 AND_SPLIT, 102 AND_JOIN,
#: 104 XOR_SPLIT, 105 XOR_JOIN, 106 XORJOIN_XORSPLIT, 107 AND_SPLITJOIN,
#: 108 ANDJOIN_XORSPLIT, 109 XORJOIN_ANDSPLIT. 103 (OR_SPLIT) has no AND/XOR equivalent.
WOPED_OPERATOR_TYPES: dict[int, tuple[str | None, str | None]] = {
    101: ("and", None),
    102: (None, "and"),
    104: ("xor", None),
    105: (None, "xor"),
    106: ("xor", "xor"),
    107: ("and", "and"),
    108: ("xor", "and"),
    109: ("and", "xor"),
}

#: The ``tool`` name of petriflow's own ``<toolspecific>`` data, and its version.
PETRIFLOW_TOOL = "petriflow"
PETRIFLOW_TOOL_VERSION = "1"

_NODE_TAGS = {"place", "transition", "arc", "referencePlace", "referenceTransition"}
# Children that carry nothing a P/T net needs beyond what is read: layout only.
_LAYOUT_TAGS = {"graphics", "arcpath", "orientation"}
_PLACE_TAGS = {"name", "initialMarking", "toolspecific", "capacity"} | _LAYOUT_TAGS
_TRANSITION_TAGS = {"name", "toolspecific", "readVariable", "writeVariable"} | _LAYOUT_TAGS
_GSPN_TAGS = {"rate", "timed", "infiniteServer", "priority"}
_ARC_TAGS = {"inscription", "toolspecific", "arctype", "type", "name", "tagged"} | _LAYOUT_TAGS
_NET_TAGS = {"name", "page", "toolspecific", "finalmarkings", "variables", "token"} | _LAYOUT_TAGS
_PAGE_TAGS = {"name", "page", "toolspecific"} | _LAYOUT_TAGS
_WOPED_LAYOUT = {
    "bounds", "scale", "treeWidth", "treeWidthRight", "treeHeightOverview",
    "overviewPanelVisible", "treePanelVisible", "verticalLayout", "timeUnit",
    "displayProbabilityOn", "displayProbabilityPosition",
}


class PnmlWarning(UserWarning):
    """Part of a PNML file that a petriflow net cannot hold; the net is read without it.

    The message is one line naming the file and the elements, e.g.
    ``Subprocesses.pnml: transition 'sub1': subprocess page not inlined; ...``.
    """


# XML parsing ------------------------------------------------------------------------


class _Node(Element):
    """An element that remembers the line its start tag is on."""

    sourceline: int | None = None


class _LineTreeBuilder(TreeBuilder):
    """Builds :class:`_Node` elements stamped with the parser's current line."""

    def __init__(self) -> None:
        super().__init__(element_factory=_Node)
        self.expat: Any = None

    def start(self, tag: str, attrs: dict[str, str]) -> Element:  # type: ignore[override]
        element = super().start(tag, attrs)
        if self.expat is not None:
            element.sourceline = self.expat.CurrentLineNumber
        return element


def _parse_xml(data: str | bytes, path: str | None) -> Element:
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
            "DOCTYPE, entity declarations and external references are not allowed in PNML",
            path=path, line=parser.parser.CurrentLineNumber,
        ) from None
    except (ValueError, LookupError) as exc:  # undecodable text, unknown encoding
        raise NetFormatError(f"cannot decode the file: {exc}", path=path) from None


# Small helpers over elements ---------------------------------------------------------


def _local(tag: str) -> str:
    return tag.rpartition("}")[2]


def _children(element: Element, name: str) -> list[Element]:
    return [child for child in element if _local(child.tag) == name]


def _child(element: Element | None, name: str) -> Element | None:
    if element is None:
        return None
    for child in element:
        if _local(child.tag) == name:
            return child
    return None


def _line(element: Element | None) -> int | None:
    return getattr(element, "sourceline", None)


def _value_element(annotation: Element | None) -> Element | None:
    """The element holding an annotation's value: ISO ``<text>``, JARP/PIPE ``<value>``.

    Course-material files nest it once more, as ``<initialMarking><token><value>``.
    """
    for holder in (annotation, _child(annotation, "token")):
        for name in ("text", "value"):
            found = _child(holder, name)
            if found is not None:
                return found
    return None


def _name_of(element: Element) -> str | None:
    """The ``<name>`` of a node or net, stripped; ``None`` when absent or empty."""
    value = _value_element(_child(element, "name"))
    if value is None or value.text is None:
        return None
    return value.text.strip() or None


#: A decimal number in ASCII (XSD's ``decimal`` or ``double``, without INF and NaN):
#: ``float()`` alone would read any script's digits, and underscores.
_DECIMAL = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")


def _decimal(text: str | None) -> float | None:
    """``text`` as a finite float when it is an ASCII decimal number, else ``None``."""
    text = (text or "").strip(" \t\r\n")
    if not _DECIMAL.fullmatch(text):
        return None
    value = float(text)
    return value if math.isfinite(value) else None


def _plural(kind: str) -> str:
    return kind + "s"


# The reader --------------------------------------------------------------------------


class _Reader:
    """Turns a parsed PNML document into a :class:`Net`, failing loudly with lines."""

    def __init__(self, root: Element, path: str | None, stacklevel: int = 2) -> None:
        self.root = root
        self.path = path
        self.stacklevel = stacklevel
        self.net = Net()
        self.ids: dict[str, tuple[str, Element]] = {}
        self.places: list[Element] = []
        self.transitions: list[Element] = []
        self.arcs: list[Element] = []
        self.references: dict[str, Element] = {}
        self.targets: dict[str, str] = {}
        self.outcome_arcs: list[tuple[str, Element]] = []
        self.tokens: dict[str, int] = {}
        self.subprocess_pages: list[Element] = []
        self.nupn: dict[str, Any] | None = None  # the MCC's unit structure, if the file has one
        self.pages: list[str] = []
        self.page_of: dict[Element, str | None] = {}  # the page each node or arc element is on
        self.node_page: dict[str, str | None] = {}   # the page of each node id
        self.notes: dict[tuple[str, str], list[str]] = {}

    # Reporting ----------------------------------------------------------------------
    def fail(self, message: str, element: Element | None = None, node: str | None = None) -> NoReturn:
        raise NetFormatError(message, path=self.path, line=_line(element), element=node)

    def note(self, kind: str, node: str | None, message: str) -> None:
        """Record a loss; :meth:`emit` turns each (kind, message) into one warning."""
        ids = self.notes.setdefault((kind, message), [])
        if node is not None and node not in ids:
            ids.append(node)

    def emit(self) -> None:
        prefix = f"{self.path}: " if self.path else ""
        for (kind, message), ids in self.notes.items():
            if len(ids) == 1:
                who = f"{kind} {ids[0]!r}"
            elif ids:
                shown = ", ".join(repr(i) for i in ids[:6])
                more = f" and {len(ids) - 6} more" if len(ids) > 6 else ""
                who = f"{_plural(kind)} {shown}{more}"
            else:
                who = kind
            warnings.warn(f"{prefix}{who}: {message}", PnmlWarning, stacklevel=self.stacklevel)

    def unknown(self, element: Element, allowed: set[str], kind: str, node: str | None) -> None:
        """Report children that are neither read nor pure layout."""
        for child in element:
            name = _local(child.tag)
            if name not in allowed:
                self.note(kind, node, f"<{name}> is not part of a P/T net; ignored")

    # Top level ----------------------------------------------------------------------
    def read(self) -> Net:
        net_element = self.net_element()
        self.check_type(net_element)
        self.net.id = net_element.get("id") or (Path(self.path).stem if self.path else "net")
        self.collect(net_element, net_element, depth=0)
        self.read_net_annotations(net_element)
        for element in self.places:
            self.read_place(element)
        self.check_nupn()
        # one marking for all places: adding tokens place by place costs O(places^2)
        self.net.set_initial_marking(self.tokens)
        for element in self.transitions:
            self.read_transition(element)
        self.resolve_references()
        self.read_arcs()
        self.read_outcome_arcs()
        try:
            self.net.check_references()
        except PetriflowError as exc:
            self.fail(str(exc), net_element)
        self.read_subprocess_pages()
        self.read_final_marking(net_element)
        if len(self.pages) > 1:
            shown = ", ".join(repr(p) for p in self.pages)
            self.note("net", self.net.id, f"pages {shown} flattened into one page (every node kept)")
        self.emit()
        return self.net

    def net_element(self) -> Element:
        root = self.root
        if _local(root.tag) != "pnml":
            self.fail(f"root element is <{_local(root.tag)}>, not <pnml>: not a PNML file", root)
        nets = _children(root, "net")
        if not nets:
            self.fail("no <net> in the file", root)
        if len(nets) > 1:
            ids = ", ".join(repr(n.get("id")) for n in nets)
            self.fail(f"{len(nets)} nets in one file ({ids}); petriflow reads files holding one net",
                      nets[1], nets[1].get("id"))
        self.unknown(root, {"net"}, "document", None)
        return nets[0]

    def check_type(self, net_element: Element) -> None:
        net_type = net_element.get("type")
        if net_type is None or net_type.strip() in PT_NET_TYPES:
            return
        kind = _OTHER_NET_KINDS.get(net_type.strip().rstrip("/").rpartition("/")[2])
        what = f" ({kind})" if kind else ""
        accepted = ", ".join(repr(t) for t in PT_NET_TYPES)
        self.fail(f"net type {net_type!r}{what} is not a place/transition net type; "
                  f"petriflow reads {accepted}", net_element, net_element.get("id"))

    def register(self, element: Element, kind: str) -> str | None:
        node = element.get("id")
        if not node:
            if kind == "arc":
                return None
            self.fail(f"<{kind}> without an id", element)
        if node in self.ids:
            other_kind, other = self.ids[node]
            self.fail(f"duplicate id: this {kind} repeats the id of the {other_kind} on line "
                      f"{_line(other)}", element, node)
        self.ids[node] = (kind, element)
        return node

    def collect(self, container: Element, net_element: Element, depth: int) -> None:
        """Gather the nodes of ``container`` and of its nested pages, in document order.

        A page holding a ``<net>`` is a WoPeD subprocess: its net is set aside (see
        :meth:`read_subprocess_pages`), but any node beside that net is still read.
        """
        if depth > limits.PNML_PAGE_DEPTH:
            self.fail(f"pages nested more than {limits.PNML_PAGE_DEPTH} deep", container, container.get("id"))
        allowed = _NET_TAGS if container is net_element else _PAGE_TAGS
        if _child(container, "net") is not None and container is not net_element:
            allowed = allowed | {"net"}
        page = None if container is net_element else (container.get("id") or f"(line {_line(container)})")
        for child in container:
            name = _local(child.tag)
            if name in _NODE_TAGS:
                node = self.register(child, name)
                self.page_of[child] = page
                if name != "arc":
                    self.node_page[str(node)] = page
                if name == "place":
                    self.places.append(child)
                elif name == "transition":
                    self.transitions.append(child)
                elif name == "arc":
                    self.arcs.append(child)
                else:
                    self.references[str(node)] = child
            elif name == "page":
                if _child(child, "net") is not None:
                    self.subprocess_pages.append(child)
                else:
                    self.pages.append(child.get("id") or f"(line {_line(child)})")
                    self.read_toolspecifics(child, "page", child.get("id"), {})
                self.collect(child, net_element, depth + 1)
            elif name not in allowed:
                kind = "net" if container is net_element else "page"
                self.note(kind, container.get("id"), f"<{name}> is not part of a P/T net; ignored")

    # Net level ----------------------------------------------------------------------
    def read_net_annotations(self, net_element: Element) -> None:
        self.net.label = _name_of(net_element)
        data = self.read_toolspecifics(net_element, "net", self.net.id, {})
        for subnet_id, label, agent, state, element in data.get("subnets", []):
            try:
                self.net.add_subnet(subnet_id, label, agent, state)
            except PetriflowError as exc:
                self.fail(str(exc), element, subnet_id)
        if "label" in data:
            self.net.label = data["label"]
        self.net.meta = dict(data.get("meta", {}))
        if "run" in data:
            self.net.run = data["run"]
            self.net.lines["run"] = data["run_line"]
        variables = _child(net_element, "variables")
        if variables is not None and len(variables):
            names = ", ".join(
                (_child(v, "name").text or "").strip() if _child(v, "name") is not None else "?"
                for v in variables
            )
            self.note("net", self.net.id, f"data Petri net variables ({names}) are not representable;"
                      " ignored")

    # Nodes --------------------------------------------------------------------------
    def read_place(self, element: Element) -> None:
        node = str(element.get("id"))
        marking = _child(element, "initialMarking")
        multiset = _child(marking, "multiset")
        if multiset is not None:
            tokens = self.multiset_count(multiset, node)
        else:
            tokens = self.count(marking, "initial marking", node, minimum=0)
        if tokens:
            self.tokens[node] = tokens
        data = self.read_toolspecifics(element, "place", node, {})
        meta = dict(data.get("meta", {}))
        position = self.position(element, node)
        if position is not None:
            meta["position"] = position
        capacity = _child(element, "capacity")
        if capacity is not None and self.count(capacity, "capacity", node, minimum=0):
            self.note("place", node, "place capacities are not representable; read as unbounded")
        allowed = _PLACE_TAGS
        place_type = _child(element, "type")
        if place_type is not None and place_type.get("domain") == "universal" and not len(place_type):
            allowed = allowed | {"type"}  # SNAKES' "any value": nothing is lost in a P/T net
        self.unknown(element, allowed, "place", node)
        try:
            self.net.add_place(node, label=data.get("label", _name_of(element)),
                               subnet=data.get("subnet"), meta=meta, channel=data.get("channel"))
        except PetriflowError as exc:
            self.fail(str(exc), element, node)
        self.net.lines[node] = _line(element)

    def read_transition(self, element: Element) -> None:
        node = str(element.get("id"))
        data = self.read_toolspecifics(element, "transition", node, {})
        meta = dict(data.get("meta", {}))
        position = self.position(element, node)
        if position is not None:
            meta["position"] = position
        guard = element.get("guard")
        if guard is not None and guard.strip() not in ("", "true"):
            meta["data_guard"] = guard
            self.note("transition", node, "data Petri net guard expressions are not representable; "
                      "kept in meta['data_guard'], not checked when firing")
        if _child(element, "readVariable") is not None or _child(element, "writeVariable") is not None:
            self.note("transition", node, "data Petri net variable reads/writes (<readVariable>, "
                      "<writeVariable>) are not representable; ignored")
        if any(_local(child.tag) in _GSPN_TAGS for child in element):
            self.note("transition", node, "GSPN timing (<rate>, <timed>, <infiniteServer>, <priority>)"
                      " is not representable; read as an untimed P/T net")
        self.unknown(element, _TRANSITION_TAGS | _GSPN_TAGS, "transition", node)
        operator = data.get("operator")
        if operator is None and "woped_operator" in data:
            operator = self.woped_operator(data["woped_operator"], element, node)
        attributes = dict(
            label=data.get("label", _name_of(element)),
            action=data.get("action"),
            params=data.get("params", {}),
            guard=data.get("guard"),
            subnet=data.get("subnet"),
            silent=data.get("silent", False),
            priority=data.get("priority", 0),
            operator=operator,
            meta=meta,
            timeout=data.get("timeout"),
            cancels=tuple(data.get("cancels", ())),
        )
        try:
            self.net.add_transition(node, **attributes)
        except PetriflowError as exc:
            self.fail(str(exc), element, node)
        self.net.lines[node] = _line(element)
        for key, line in data.get("lines", {}).items():
            self.net.lines[f"{node}/{key}"] = line

    def woped_operator(self, found: tuple[str, str | None, Element], element: Element,
                       node: str) -> Operator | None:
        code, group, operator_element = found
        if not group:
            self.fail("WoPeD <operator> without an id", operator_element, node)
        number = None
        if re.search(r"\d", code):  # any script's digit: the one rule decides (ASCII, at most 2**60)
            number = self.integer(code, "WoPeD operator type", operator_element, node)
        kinds = WOPED_OPERATOR_TYPES.get(number) if number is not None else None
        if kinds is None:
            what = "OR-split" if code.strip() == "103" else f"of unknown type {code!r}"
            self.note("transition", node, f"WoPeD operator {what} has no AND/XOR equivalent; its "
                      "parts are kept as plain transitions")
            return None
        split, join = kinds
        return Operator(group, split, join)

    # Toolspecific data --------------------------------------------------------------
    def read_toolspecifics(self, element: Element, kind: str, node: str | None,
                           found: dict[str, Any]) -> dict[str, Any]:
        """Read every ``<toolspecific>`` child of ``element`` into ``found``."""
        for tool_element in _children(element, "toolspecific"):
            tool = (tool_element.get("tool") or "").strip()
            if tool == PETRIFLOW_TOOL:
                self.read_petriflow(tool_element, kind, node, found)
            elif tool == "ProM":
                self.read_prom(tool_element, kind, node, found)
            elif tool == "WoPeD":
                self.read_woped(tool_element, kind, node, found)
            elif tool == "StochasticPetriNet" and kind == "transition":
                self.read_stochastic(tool_element, node, found)
            elif tool == "nupn" and kind in ("net", "page"):
                self.read_nupn(tool_element, kind, node)
            else:
                self.note(kind, node, f"toolspecific data of tool {tool!r} is not representable;"
                          " ignored")
        return found

    def read_nupn(self, tool: Element, kind: str, node: str | None) -> None:
        """The Model Checking Contest's unit structure (NUPN 1.1), kept as
        ``net.meta["nupn"]``: ``{"version", "root", "safe", "units": {unit: {"places": [...],
        "subunits": [...]}}}`` (the writer keeps it with the net's other meta data)."""
        structure = _child(tool, "structure")
        if structure is None or self.nupn is not None:
            self.note(kind, node, "NUPN data without a <structure>, or a second one, is not"
                      " representable; ignored")
            return
        units: dict[str, dict[str, list[str]]] = {}
        for unit in _children(structure, "unit"):
            unit_id = (unit.get("id") or "").strip()
            places, subunits = _child(unit, "places"), _child(unit, "subunits")
            units[unit_id] = {
                "places": ((places.text or "").split() if places is not None else []),
                "subunits": ((subunits.text or "").split() if subunits is not None else []),
            }
        self.nupn = {"version": (tool.get("version") or "").strip(),
                     "root": (structure.get("root") or "").strip(),
                     "safe": (structure.get("safe") or "").strip().lower() == "true",
                     "units": units}

    def check_nupn(self) -> None:
        """Keep the NUPN units in the net's meta data; one note if they name unknown places."""
        if self.nupn is None:
            return
        self.net.meta["nupn"] = self.nupn
        named = {p for unit in self.nupn["units"].values() for p in unit["places"]}
        unknown = sorted(named - set(self.net.places))
        if unknown:
            some = f"{len(unknown)} places that are" if len(unknown) > 1 else "a place that is"
            self.note("net", self.net.id, f"NUPN units name {some} not in the net"
                      f" (e.g. {unknown[0]!r}); units kept as read")

    def read_prom(self, tool: Element, kind: str, node: str | None, found: dict[str, Any]) -> None:
        if kind == "transition" and tool.get("activity") == "$invisible$":
            found["silent"] = True
        if len(tool):
            self.note(kind, node, "ProM toolspecific content is not representable; ignored")

    def read_stochastic(self, tool: Element, node: str | None, found: dict[str, Any]) -> None:
        for prop in tool:
            if prop.get("key") == "invisible":
                found["silent"] = (prop.text or "").strip().lower() == "true"
            else:
                self.note("transition", node, "stochastic (StochasticPetriNet) distributions are "
                          "not representable; ignored")

    def read_woped(self, tool: Element, kind: str, node: str | None, found: dict[str, Any]) -> None:
        for child in tool:
            name = _local(child.tag)
            text = (child.text or "").strip()
            if name in _WOPED_LAYOUT:
                continue
            if name == "operator" and kind == "transition":
                found["woped_operator"] = (child.get("type") or "", child.get("id"), child)
            elif name == "operator" and kind == "place":
                found.setdefault("meta", {})["woped_operator"] = {
                    "group": child.get("id"), "type": child.get("type")}
            elif name == "subprocess" and kind == "transition":
                found["subprocess"] = text == "true"
            elif name == "time" and kind == "transition":
                if text not in ("", "0"):
                    self.note(kind, node, "WoPeD service times are not representable; ignored")
            elif name == "probability" and kind == "arc":
                if _decimal(text) != 1:
                    self.note(kind, node, "WoPeD arc probabilities are not representable; ignored")
            elif name == "trigger":
                self.note(kind, node, "WoPeD triggers (resource, message, time) are not "
                          "representable; ignored")
            elif name in ("resources", "simulations", "partnerLinks", "variables") and not len(child):
                continue
            else:
                self.note(kind, node, f"WoPeD data <{name}> is not representable; ignored")

    def read_petriflow(self, tool: Element, kind: str, node: str | None, found: dict[str, Any]) -> None:
        version = (tool.get("version") or "").strip()
        if version != PETRIFLOW_TOOL_VERSION:
            self.note(kind, node, f"petriflow data of version {version!r} is not understood by "
                      f"this petriflow (version {PETRIFLOW_TOOL_VERSION}); ignored")
            return
        for child in tool:
            name = _local(child.tag)
            text = child.text or ""
            if name == "subnet" and kind == "net":
                found.setdefault("subnets", []).append(self.subnet_of(child))
            elif name == "subnet" and kind in ("place", "transition"):
                found["subnet"] = text
            elif name == "channel" and kind == "place":
                found["channel"] = text
            elif name == "timeout" and kind == "transition":
                timeout = _decimal(text)
                if timeout is None or not timeout > 0:
                    self.fail(f"timeout must be a number of seconds > 0, got {text!r}", child, node)
                found["timeout"] = timeout
            elif name == "cancel" and kind == "transition":
                if not child.get("node"):
                    self.fail("petriflow <cancel> without a node", child, node)
                found.setdefault("cancels", []).append(child.get("node"))
            elif name == "outcome" and kind == "transition":
                self.outcome_arcs.append((str(node), child))
            elif name in ("action", "guard") and kind == "transition":
                found[name] = text
                found.setdefault("lines", {})[name] = _line(child)
            elif name == "params" and kind == "transition":
                found["params"] = self.json_of(child, dict, "params", node)
                found.setdefault("lines", {})[name] = _line(child)
            elif name == "run" and kind == "net":
                try:
                    run = parse_json(text)
                except ValueError as exc:
                    self.fail(f"petriflow run: {exc}", child, node)
                if not isinstance(run, (str, dict)):
                    self.fail("petriflow run must be a JSON string (a file) or object (the configuration)",
                              child, node)
                found["run"] = run
                found["run_line"] = _line(child)
            elif name == "priority" and kind == "transition":
                found["priority"] = self.integer(text, "priority", child, node)
            elif name == "operator" and kind == "transition":
                found["operator"] = self.operator_of(child, node)
            elif name == "label":
                found["label"] = self.json_of(child, str, "label", node)
            elif name == "meta":
                found["meta"] = self.json_of(child, dict, "meta", node)
            else:
                self.note(kind, node, f"petriflow data <{name}> is not understood; ignored")

    def subnet_of(self, element: Element) -> tuple[str, str | None, str | None, str | None, Element]:
        subnet = element.get("id")
        if not subnet:
            self.fail("petriflow <subnet> without an id", element, self.net.id)
        return subnet, element.get("label"), element.get("agent"), element.get("state"), element

    def operator_of(self, element: Element, node: str | None) -> Operator:
        group = element.get("group")
        if not group:
            self.fail("petriflow <operator> without a group", element, node)
        for side in ("split", "join"):
            kind = element.get(side)
            if kind is not None and kind not in OPERATOR_KINDS:
                self.fail(f"operator {side} must be one of {', '.join(OPERATOR_KINDS)}, got {kind!r}",
                          element, node)
        return Operator(group, element.get("split"), element.get("join"))

    def json_of(self, element: Element, kind: type, what: str, node: str | None) -> Any:
        try:
            value = parse_json(element.text or "")
        except ValueError as exc:
            self.fail(f"petriflow {what}: {exc}", element, node)
        if not isinstance(value, kind):
            self.fail(f"petriflow {what} must be a JSON {'object' if kind is dict else 'string'}",
                      element, node)
        return value

    # Numbers ------------------------------------------------------------------------
    def count(self, annotation: Element | None, what: str, node: str | None, minimum: int,
              default: int = 0) -> int:
        """A token count or arc weight: a whole number, PIPE's ``class,count`` pairs allowed."""
        value_element = _value_element(annotation)
        raw = value_element.text if value_element is not None else None
        if raw is None or not raw.strip():
            return default
        where = value_element if value_element is not None else annotation
        text = raw.strip()
        if "," in text:
            value = self.class_counts(text, what, node, where)
        else:
            value = self.whole(text, what, node, where)
        if value < minimum:
            self.fail(f"{what} must be a whole number >= {minimum}, got {value}", where, node)
        return value

    def whole(self, text: str, what: str, node: str | None, where: Element | None) -> int:
        """A count: a whole number >= 0 by the one rule (:func:`~petriflow.limits.parse_integer`)."""
        return self.integer(text, what, where, node, minimum=0)

    def integer(self, text: str, what: str, where: Element | None, node: str | None,
                minimum: int | None = None) -> int:
        """Every whole number the file holds is read here, by the one rule
        (:func:`~petriflow.limits.parse_integer`: ASCII digits, at most 2**60); a refusal
        names the file and the line."""
        try:
            return limits.parse_integer(text, what, minimum=minimum)
        except NumberError as exc:
            self.fail(str(exc), where, node)

    def position(self, element: Element, node: str) -> list[int | float] | None:
        """A node's ``<graphics><position x= y=>``: whole numbers by the one rule, decimals
        (``120.0``) as floats; anything else is layout petriflow does not keep."""
        position = _child(_child(element, "graphics"), "position")
        if position is None:
            return None
        found: list[int | float] = []
        for axis in ("x", "y"):
            text = (position.get(axis) or "").strip(" \t\r\n")
            # a whole number (\d: any script's digits), or another script's digit anywhere
            # ('\u0663.5'): the rule reads it or says why not
            if re.fullmatch(r"[+-]?\d+", text) or any(c.isdigit() and not c.isascii() for c in text):
                found.append(self.integer(text, f"position {axis}", position, node))
            else:
                value = _decimal(text)
                if value is None:
                    return None
                found.append(value)
        return found

    def multiset_count(self, multiset: Element, node: str) -> int:
        """SNAKES' native marking: ``<multiset><item><value>…</value><multiplicity>n``.

        Black tokens (``<value><token/></value>``) count as tokens; coloured values
        (``<object type="int">5</object>``...) count too, with a warning naming the
        place and the values lost, since a P/T net holds no token values.
        """
        total, coloured = 0, []
        for item in _children(multiset, "item"):
            value = _child(item, "value")
            times = _child(item, "multiplicity")
            text = (times.text or "").strip() if times is not None else "1"
            count = self.whole(text or "1", "multiplicity", node, times if times is not None else item)
            total += count
            inside = list(value) if value is not None else []
            if not (len(inside) == 1 and _local(inside[0].tag) == "token"):
                shown = " ".join("".join(part.itertext()).strip() or _local(part.tag) for part in inside) or "?"
                coloured.append(shown if count == 1 else f"{shown} x{count}")
        if coloured:
            self.note("place", node, f"coloured token values ({', '.join(coloured[:5])}"
                      f"{', ...' if len(coloured) > 5 else ''}) are not representable; read as {total}"
                      " plain tokens")
        return total

    def class_counts(self, text: str, what: str, node: str | None, where: Element | None) -> int:
        """PIPE writes counts as ``Default,1`` (token class, count, ...)."""
        parts = [part.strip() for part in text.split(",")]
        if len(parts) % 2:
            self.fail(f"{what} must be a whole number or 'class,count' pairs, got {text!r}", where, node)
        counts = {cls: self.whole(count, what, node, where) for cls, count in zip(parts[::2], parts[1::2])}
        coloured = [cls for cls, count in counts.items() if count]
        if len(coloured) > 1:
            self.fail(f"{what} {text!r} holds tokens of several classes ({', '.join(coloured)}); "
                      "a P/T net has one kind of token", where, node)
        return sum(counts.values())

    # References and arcs ------------------------------------------------------------
    def resolve_references(self) -> None:
        """Follow every reference node to the place or transition it finally stands for."""
        for start in self.references:
            chain, on_chain = [start], {start}
            current = start
            while current in self.references and current not in self.targets:
                element = self.references[current]
                kind = _local(element.tag)
                target = element.get("ref")
                if not target:
                    self.fail(f"{kind} without a 'ref'", element, current)
                if target in on_chain:
                    cycle = " -> ".join(chain[chain.index(target):] + [target])
                    self.fail(f"{kind} is part of a reference cycle {cycle}", element, current)
                wanted = "place" if kind == "referencePlace" else "transition"
                target_kind = self.ids.get(target, ("", None))[0]
                if target_kind not in (wanted, kind):
                    known = [n for n, (k, _) in self.ids.items() if k in (wanted, kind)]
                    problem = (f"refers to the {target_kind} {target!r}" if target_kind else
                               f"refers to unknown node {target!r}{did_you_mean(target, known)}")
                    self.fail(f"{kind} {problem}; it must refer to a {wanted} or {kind}",
                              element, current)
                chain.append(target)
                on_chain.add(target)
                current = target
            final = self.targets.get(current, current)
            for reference in chain:  # every link of the chain now knows its final node
                if reference in self.references:
                    self.targets[reference] = final

    def node_of(self, end: str | None, which: str, element: Element, arc: str) -> str:
        if not end:
            self.fail(f"arc without a '{which}'", element, arc)
        node = self.targets.get(end, end)
        if node not in self.net.places and node not in self.net.transitions:
            known = list(self.net.places) + list(self.net.transitions)
            self.fail(f"arc {which} {end!r} is not a node of this net{did_you_mean(end, known)}",
                      element, arc)
        return node

    def read_arcs(self) -> None:
        merged: dict[tuple[str, str], list[Any]] = {}
        for element in self.arcs:
            arc_id = element.get("id") or None
            source_ref, target_ref = element.get("source"), element.get("target")
            label = arc_id or f"{source_ref} -> {target_ref}"
            source = self.node_of(source_ref, "source", element, label)
            target = self.node_of(target_ref, "target", element, label)
            page = self.page_of.get(element)
            for end in (source_ref, target_ref):
                if end in self.node_page and self.node_page[end] != page:
                    where = "the net" if self.node_page[end] is None else f"page {self.node_page[end]!r}"
                    self.fail(f"arc on {'the net' if page is None else f'page {page!r}'} joins {end!r} on {where};"
                              " ISO/IEC 15909-2 joins nodes of other pages only through reference nodes",
                              element, label)
            if (source in self.net.places) == (target in self.net.places):
                kind = "places" if source in self.net.places else "transitions"
                self.fail(f"arc joins two {kind} ({source!r} -> {target!r}); arcs join a place and a "
                          "transition", element, label)
            weight = self.count(_child(element, "inscription"), "arc weight", label, minimum=1,
                                default=1)
            self.check_arc_type(element, label)
            name = _name_of(element)
            if name is not None and not name.isdigit():  # ProM names an arc by its weight
                self.note("arc", label, "arc names are not representable; ignored")
            tagged = _value_element(_child(element, "tagged"))
            if tagged is not None and (tagged.text or "").strip() == "true":
                self.note("arc", label, "PIPE tagged arcs are not representable; read as plain arcs")
            self.unknown(element, _ARC_TAGS, "arc", label)
            self.read_toolspecifics(element, "arc", label, {})
            if (source, target) in merged:
                entry = merged[(source, target)]
                entry[0] += weight
                self.note("arc", label, f"parallel to arc {entry[1]!r} ({source!r} -> {target!r}); "
                          "merged into one arc whose weight is the sum")
            else:
                merged[(source, target)] = [weight, label, arc_id]
        for (source, target), (weight, _, arc_id) in merged.items():
            self.net.add_arc(source, target, weight, arc_id)

    def read_outcome_arcs(self) -> None:
        """Output arcs reserved for an action outcome, kept in petriflow data."""
        for transition, element in self.outcome_arcs:
            outcome, place = element.get("kind"), element.get("place")
            label = element.get("id") or f"{transition} -> {place} ({outcome})"
            if outcome not in OUTCOMES:
                self.fail(f"outcome must be one of {', '.join(OUTCOMES)}, got {outcome!r}", element,
                          transition)
            target = self.node_of(place, "target", element, label)
            if target not in self.net.places:
                self.fail(f"outcome arc target {place!r} is not a place", element, label)
            weight_text = (element.get("weight") or "1").strip()
            weight = self.whole(weight_text, "arc weight", label, element)
            if weight < 1:
                self.fail(f"arc weight must be a whole number >= 1, got {weight}", element, label)
            try:
                self.net.add_arc(transition, target, weight, element.get("id"), outcome=outcome)
            except PetriflowError as exc:
                self.fail(str(exc), element, label)

    def check_arc_type(self, element: Element, arc: str) -> None:
        kind = None
        for tag in ("arctype", "type"):  # ProM/PM4Py <arctype><text>, PIPE <type value=...>
            declared = _child(element, tag)
            if declared is not None and kind is None:
                value = _value_element(declared)
                kind = (declared.get("value") or (value.text if value is not None else "") or "").strip()
        if kind not in (None, "", "normal"):
            self.fail(f"{kind} arcs are not place/transition arcs; petriflow cannot represent them",
                      element, arc)

    # Subprocesses and final markings ------------------------------------------------
    def read_subprocess_pages(self) -> None:
        """WoPeD refines a transition by a ``<page id=t><net>``; it stays one transition."""
        for page in self.subprocess_pages:
            page_id = page.get("id")
            inner = _child(page, "net")
            assert inner is not None
            size = {f"{kind}s": len(_children(inner, kind)) for kind in ("place", "transition", "arc")}
            nested = len(_children(inner, "page"))
            if page_id in self.net.transitions:
                self.net.transitions[page_id].meta["subprocess"] = dict(size)
                deeper = f", {nested} nested subprocess(es)" if nested else ""
                self.note("transition", page_id,
                          f"subprocess page not inlined; kept as one atomic transition (its net of "
                          f"{size['places']} places, {size['transitions']} transitions, {size['arcs']} "
                          f"arcs{deeper} is not read)")
            else:
                self.note("page", page_id or f"line {_line(page)}",
                          "page holds a <net> but no transition has its id; its net is not read")

    def read_final_marking(self, net_element: Element) -> None:
        block = _child(net_element, "finalmarkings")
        if block is None:
            return
        markings = _children(block, "marking")
        if len(markings) > 1:
            self.note("net", self.net.id, f"{len(markings)} final markings given; petriflow keeps "
                      "one, the first")
        tokens: dict[str, int] = {}
        for entry in (markings[0] if markings else []):
            if _local(entry.tag) != "place":
                self.fail(f"<{_local(entry.tag)}> in a final marking; expected <place idref=...>",
                          entry, self.net.id)
            ref = entry.get("idref")
            place = self.targets.get(ref or "", ref)
            if not place or place not in self.net.places:
                self.fail(f"final marking names unknown place {ref!r}"
                          f"{did_you_mean(str(ref), self.net.places)}", entry, ref)
            if place in tokens:
                self.fail("final marking names this place twice", entry, place)
            tokens[place] = self.count(entry, "final marking", place, minimum=0)
        self.net.set_final_marking(tokens)


# Entry points ------------------------------------------------------------------------


def loads_pnml(data: str | bytes, *, path: str | None = None) -> Net:
    """Read a net from PNML text (``str``) or the bytes of a PNML file.

    Args:
        data: the document; bytes are decoded by the XML declaration's encoding.
        path: the file it came from, named in errors and warnings.

    Raises:
        NetFormatError: malformed or unsafe XML, a net type that is not P/T, or a net
            that breaks the rules (duplicate ids, dangling arcs, bad counts...).
    """
    return _loads(data, path, stacklevel=3)


def _loads(data: str | bytes, path: str | None, stacklevel: int) -> Net:
    if not isinstance(data, (str, bytes)):
        raise NetFormatError(f"PNML must be text or bytes, got {type(data).__name__}", path=path)
    if isinstance(data, bytes):  # byte-order marks and UTF-16 without one, as the XML spec allows
        from petriflow.io.files import decode_text

        try:
            data = decode_text(data)
        except ValueError as exc:
            raise NetFormatError(f"cannot decode the file: {exc}", path=path) from None
    data = data.removeprefix("\ufeff")
    root = _parse_xml(data, path)
    # warnings point at the caller of the public function: +1 for emit, read, _loads
    net = _Reader(root, path, stacklevel + 2).read()
    net.path = path
    return net


def load_pnml(path: str | Path) -> Net:
    """Read a net from a PNML file (see :func:`loads_pnml`).

    Raises:
        NetFormatError: also when the file is missing or unreadable.
    """
    from petriflow.io.files import read_text_file

    name = str(path)
    return _loads(read_text_file(path), name, stacklevel=3)
