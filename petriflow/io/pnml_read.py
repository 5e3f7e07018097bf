"""Reading PNML: the ISO/IEC 15909-2 P/T net structure, with the dialects tools write.

Use it through :mod:`petriflow.io.pnml` (``load_pnml``, ``loads_pnml``). Three modules
read a file, one concept each: :mod:`petriflow.io.safe_xml` parses the XML safely (no
DTD, no entities: no XXE, no entity bombs, no network access), each element knowing its
line; this module reads the ISO/IEC 15909-2 structure; :mod:`petriflow.io.pnml_dialects`
holds what other tools (PM4Py, ProM, WoPeD, JARP, Petri Net Plans, PIPE, SNAKES, the
Model Checking Contest, petriflow itself) write beyond it, in a table. The writer is
:mod:`petriflow.io.pnml_write`. Nothing read from a file is ever evaluated or unpickled.

The ISO structure, matched by local names (no namespace tricks): nested ``<page>``
elements are flattened (every node kept), ``referencePlace``/``referenceTransition``
chains are resolved to their final node, ``<name><text>``, ``<initialMarking><text>``,
``<inscription><text>``; node positions go to ``meta["position"] = [x, y]``.

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

import re
import warnings
from pathlib import Path
from typing import Any, NoReturn
from xml.etree.ElementTree import Element

from petriflow import limits
from petriflow.errors import NetFormatError, NumberError, PetriflowError, did_you_mean
from petriflow.io.files import decode_text, read_text_file
from petriflow.io.pnml_dialects import (
    OTHER_NET_KINDS,
    PETRIFLOW_TOOL,
    PETRIFLOW_TOOL_VERSION,
    PNML_NAMESPACE,
    PT_NET_TYPES,
    PTNET_TYPE,
    TOOLS,
    WOPED_OPERATOR_TYPES,
    check_arc_type,
    check_nupn,
    class_counts,
    multiset_count,
    name_of,
    read_arc_name,
    read_capacity,
    read_data_guard,
    read_data_variables,
    read_final_marking,
    read_subprocess_pages,
    read_tagged,
    report_losses,
    tags_of,
    universal_type,
    value_element,
    woped_operator,
)
from petriflow.io.safe_xml import child, children, line_of, local_name, parse_xml
from petriflow.limits import parse_decimal
from petriflow.net import OUTCOMES, Net

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

_NODE_TAGS = {"place", "transition", "arc", "referencePlace", "referenceTransition"}
# Children that carry nothing a P/T net needs beyond what is read: layout only.
_LAYOUT_TAGS = {"graphics", "arcpath", "orientation"}
# The children of each element the reader knows (ISO's and the dialects'); any other is
# reported as not part of a P/T net.
_PLACE_TAGS = {"name", "initialMarking", "toolspecific"} | _LAYOUT_TAGS | tags_of("place")
_TRANSITION_TAGS = {"name", "toolspecific"} | _LAYOUT_TAGS | tags_of("transition")
_ARC_TAGS = {"inscription", "toolspecific"} | _LAYOUT_TAGS | tags_of("arc")
_NET_TAGS = {"name", "page", "toolspecific"} | _LAYOUT_TAGS | tags_of("net")
_PAGE_TAGS = {"name", "page", "toolspecific"} | _LAYOUT_TAGS | tags_of("page")


class PnmlWarning(UserWarning):
    """Part of a PNML file that a petriflow net cannot hold; the net is read without it.

    The message is one line naming the file and the elements, e.g.
    ``Subprocesses.pnml: transition 'sub1': subprocess page not inlined; ...``.
    """


def _plural(kind: str) -> str:
    return kind + "s"


# The reader ----------------------------------------------------------------------------


class _Reader:
    """Turns a parsed PNML document into a :class:`Net`, failing loudly with lines.

    It reads the ISO/IEC 15909-2 structure and hands each tool's additions to the rules
    of :mod:`~petriflow.io.pnml_dialects` (it is their
    :class:`~petriflow.io.pnml_dialects.Reading`).
    """

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
        raise NetFormatError(message, path=self.path, line=line_of(element), element=node)

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
        for item in element:
            name = local_name(item.tag)
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
        check_nupn(self)
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
        read_subprocess_pages(self)
        read_final_marking(self, net_element)
        if len(self.pages) > 1:
            shown = ", ".join(repr(p) for p in self.pages)
            self.note("net", self.net.id, f"pages {shown} flattened into one page (every node kept)")
        self.emit()
        return self.net

    def net_element(self) -> Element:
        root = self.root
        if local_name(root.tag) != "pnml":
            self.fail(f"root element is <{local_name(root.tag)}>, not <pnml>: not a PNML file", root)
        nets = children(root, "net")
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
        kind = OTHER_NET_KINDS.get(net_type.strip().rstrip("/").rpartition("/")[2])
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
                      f"{line_of(other)}", element, node)
        self.ids[node] = (kind, element)
        return node

    def collect(self, container: Element, net_element: Element, depth: int) -> None:
        """Gather the nodes of ``container`` and of its nested pages, in document order.

        A page holding a ``<net>`` is a WoPeD subprocess: its net is set aside (see
        :func:`~petriflow.io.pnml_dialects.read_subprocess_pages`), but any node beside that net
        is still read.
        """
        if depth > limits.PNML_PAGE_DEPTH:
            self.fail(f"pages nested more than {limits.PNML_PAGE_DEPTH} deep", container, container.get("id"))
        allowed = _NET_TAGS if container is net_element else _PAGE_TAGS
        if child(container, "net") is not None and container is not net_element:
            allowed = allowed | {"net"}
        page = None if container is net_element else (container.get("id") or f"(line {line_of(container)})")
        for item in container:
            name = local_name(item.tag)
            if name in _NODE_TAGS:
                node = self.register(item, name)
                self.page_of[item] = page
                if name != "arc":
                    self.node_page[str(node)] = page
                if name == "place":
                    self.places.append(item)
                elif name == "transition":
                    self.transitions.append(item)
                elif name == "arc":
                    self.arcs.append(item)
                else:
                    self.references[str(node)] = item
            elif name == "page":
                if child(item, "net") is not None:
                    self.subprocess_pages.append(item)
                else:
                    self.pages.append(item.get("id") or f"(line {line_of(item)})")
                    self.read_toolspecifics(item, "page", item.get("id"), {})
                self.collect(item, net_element, depth + 1)
            elif name not in allowed:
                kind = "net" if container is net_element else "page"
                self.note(kind, container.get("id"), f"<{name}> is not part of a P/T net; ignored")

    # Net level ----------------------------------------------------------------------
    def read_net_annotations(self, net_element: Element) -> None:
        self.net.label = name_of(net_element)
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
        if "properties" in data:   # what the net must guarantee (petriflow.properties)
            from petriflow.properties.yaml_props import parse_properties

            self.net.properties = parse_properties(data["properties"], None, data["properties_line"])
        read_data_variables(self, net_element)

    # Nodes --------------------------------------------------------------------------
    def read_place(self, element: Element) -> None:
        node = str(element.get("id"))
        marking = child(element, "initialMarking")
        multiset = child(marking, "multiset")
        if multiset is not None:
            tokens = multiset_count(self, multiset, node)
        else:
            tokens = self.count(marking, "initial marking", node, minimum=0)
        if tokens:
            self.tokens[node] = tokens
        data = self.read_toolspecifics(element, "place", node, {})
        meta = dict(data.get("meta", {}))
        position = self.position(element, node)
        if position is not None:
            meta["position"] = position
        read_capacity(self, element, node)
        allowed = _PLACE_TAGS | ({"type"} if universal_type(element) else set())
        self.unknown(element, allowed, "place", node)
        try:
            self.net.add_place(node, label=data.get("label", name_of(element)),
                               subnet=data.get("subnet"), meta=meta, channel=data.get("channel"))
        except PetriflowError as exc:
            self.fail(str(exc), element, node)
        self.net.lines[node] = line_of(element)

    def read_transition(self, element: Element) -> None:
        node = str(element.get("id"))
        data = self.read_toolspecifics(element, "transition", node, {})
        meta = dict(data.get("meta", {}))
        position = self.position(element, node)
        if position is not None:
            meta["position"] = position
        read_data_guard(self, element, node, meta)
        report_losses(self, element, "transition", node)
        self.unknown(element, _TRANSITION_TAGS, "transition", node)
        operator = data.get("operator")
        if operator is None and "woped_operator" in data:
            operator = woped_operator(self, data["woped_operator"], element, node)
        attributes = dict(
            label=data.get("label", name_of(element)),
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
        self.net.lines[node] = line_of(element)
        for key, line in data.get("lines", {}).items():
            self.net.lines[f"{node}/{key}"] = line

    # Toolspecific data --------------------------------------------------------------
    def read_toolspecifics(self, element: Element, kind: str, node: str | None,
                           found: dict[str, Any]) -> dict[str, Any]:
        """Read every ``<toolspecific>`` child of ``element`` into ``found``."""
        for tool_element in children(element, "toolspecific"):
            tool = (tool_element.get("tool") or "").strip()
            data = TOOLS.get(tool)
            if data is not None and (data.kinds is None or kind in data.kinds):
                data.read(self, tool_element, kind, node, found)
            else:
                self.note(kind, node, f"toolspecific data of tool {tool!r} is not representable;"
                          " ignored")
        return found

    # Numbers ------------------------------------------------------------------------
    def count(self, annotation: Element | None, what: str, node: str | None, minimum: int,
              default: int = 0) -> int:
        """A token count or arc weight: a whole number, PIPE's ``class,count`` pairs allowed."""
        holder = value_element(annotation)
        raw = holder.text if holder is not None else None
        if raw is None or not raw.strip():
            return default
        where = holder if holder is not None else annotation
        text = raw.strip()
        if "," in text:
            value = class_counts(self, text, what, node, where)
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
        position = child(child(element, "graphics"), "position")
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
                value = parse_decimal(text)
                if value is None:
                    return None
                found.append(value)
        return found

    # References and arcs ------------------------------------------------------------
    def resolve_references(self) -> None:
        """Follow every reference node to the place or transition it finally stands for."""
        for start in self.references:
            chain, on_chain = [start], {start}
            current = start
            while current in self.references and current not in self.targets:
                element = self.references[current]
                kind = local_name(element.tag)
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
            weight = self.count(child(element, "inscription"), "arc weight", label, minimum=1,
                                default=1)
            check_arc_type(self, element, label)
            read_arc_name(self, element, label)
            read_tagged(self, element, label)
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
        try:
            data = decode_text(data)
        except ValueError as exc:
            raise NetFormatError(f"cannot decode the file: {exc}", path=path) from None
    data = data.removeprefix("\ufeff")
    root = parse_xml(data, path)
    # warnings point at the caller of the public function: +1 for emit, read, _loads
    net = _Reader(root, path, stacklevel + 2).read()
    net.path = path
    return net


def load_pnml(path: str | Path) -> Net:
    """Read a net from a PNML file (see :func:`loads_pnml`).

    Raises:
        NetFormatError: also when the file is missing or unreadable.
    """
    name = str(path)
    return _loads(read_text_file(path), name, stacklevel=3)
