"""The PNML dialects petriflow reads: what each tool writes beyond ISO/IEC 15909-2, in one place.

:mod:`petriflow.io.pnml_read` reads the ISO/IEC 15909-2 structure (nets, pages, nodes,
references, arcs, names, markings, inscriptions, positions); this module holds what
other tools add to it, one section a tool, and the table :data:`DIALECTS` that says for
each: the net types it writes (all read as place/transition nets: :data:`PT_NET_TYPES`),
the ``<toolspecific>`` data it writes and who reads it, the elements it adds to nodes
and arcs, and the ones whose content a petriflow net cannot hold (each reported with
one warning, :data:`Loss`). What is read by a rule rather than a table is a function
of the tool's section:

* ISO/IEC 15909-2 (ePNK, the Model Checking Contest): the MCC's NUPN unit structure
  (``<toolspecific tool="nupn">``) goes to ``net.meta["nupn"]`` (units, their places and
  subunits, root, safe), which the writer keeps with the net's other meta data.
* PM4Py / ProM (``pnmlcoremodel``): ``<finalmarkings>``, ``$invisible$`` silent
  transitions (also PM4Py's stochastic ``invisible``), ``<arctype>normal``; data Petri
  net extras (variables, guards, reads and writes) are reported, not kept.
* WoPeD (``ptNetb``): operator parts rebuild :class:`~petriflow.net.Operator`;
  subprocess pages stay one atomic transition.
* JARP / Petri Net Plans (``PTNet``) and PIPE (``P/T net``): ``<value>`` labels,
  PIPE's ``"Default,1"`` token counts; GSPN timing, capacities and tagged arcs are
  reported, not kept.
* SNAKES and other writers that give no net type at all: SNAKES' ``<multiset>``
  markings (coloured values reported), ``<type domain="universal">`` places.
* petriflow's own ``<toolspecific tool="petriflow">`` (what the writer keeps: actions,
  parameters, guards, subnets, operators...).

The rules reach the reader through :class:`Reading`: the net being built, and how to
fail, report a loss and read a number.

Examples:
    >>> PT_NET_TYPES["P/T net"], [d.name for d in DIALECTS if "WoPeD" in d.tools]
    ('PIPE', ['WoPeD'])
    >>> sorted(tags_of("arc")), [loss.tags for loss in losses_of("place")]
    (['arctype', 'name', 'tagged', 'type'], [])
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, NoReturn, Protocol
from xml.etree.ElementTree import Element

from petriflow.errors import did_you_mean
from petriflow.io.files import parse_json
from petriflow.io.safe_xml import child, children, line_of, local_name
from petriflow.limits import parse_decimal
from petriflow.net import OPERATOR_KINDS, Net, Operator

__all__ = [
    "DIALECTS", "PETRIFLOW_TOOL", "PETRIFLOW_TOOL_VERSION", "PNML_NAMESPACE", "PTNET_TYPE", "PT_NET_TYPES",
    "OTHER_NET_KINDS", "TOOLS", "WOPED_OPERATOR_TYPES", "Dialect", "Loss", "Reading", "ToolData",
    "check_arc_type", "check_nupn", "class_counts", "losses_of", "multiset_count", "name_of",
    "read_arc_name", "read_capacity", "read_data_guard", "read_data_variables", "read_final_marking",
    "read_subprocess_pages", "read_tagged", "report_losses", "tags_of", "universal_type", "value_element",
    "woped_operator",
]

#: Namespace of ISO/IEC 15909-2 PNML documents.
PNML_NAMESPACE = "http://www.pnml.org/version-2009/grammar/pnml"
#: Net type of an ISO/IEC 15909-2 place/transition net (what the writer writes).
PTNET_TYPE = "http://www.pnml.org/version-2009/grammar/ptnet"
#: The ``tool`` name of petriflow's own ``<toolspecific>`` data, and its version.
PETRIFLOW_TOOL = "petriflow"
PETRIFLOW_TOOL_VERSION = "1"

#: Net types that are not P/T nets, by the last part of their URI: refused, saying what they are.
OTHER_NET_KINDS = {
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

# WoPeD's layout and editor settings: nothing a net needs, skipped without a word.
_WOPED_LAYOUT = {
    "bounds", "scale", "treeWidth", "treeWidthRight", "treeHeightOverview",
    "overviewPanelVisible", "treePanelVisible", "verticalLayout", "timeUnit",
    "displayProbabilityOn", "displayProbabilityPosition",
}
# PIPE's GSPN timing of a transition.
_GSPN_TAGS = frozenset({"rate", "timed", "infiniteServer", "priority"})


class Reading(Protocol):
    """What the dialects' rules use of the reader building a net."""

    net: Net
    nupn: dict[str, Any] | None
    outcome_arcs: list[tuple[str, Element]]
    subprocess_pages: list[Element]
    targets: dict[str, str]

    def fail(self, message: str, element: Element | None = None, node: str | None = None) -> NoReturn:
        """Refuse the file: ``message`` with the file, the element's line and the node."""

    def note(self, kind: str, node: str | None, message: str) -> None:
        """Report a loss (one warning per kind of element and message)."""

    def integer(self, text: str, what: str, where: Element | None, node: str | None,
                minimum: int | None = None) -> int:
        """A whole number by the one rule, or a refusal naming the line."""

    def whole(self, text: str, what: str, node: str | None, where: Element | None) -> int:
        """A count: a whole number >= 0 by the one rule."""

    def count(self, annotation: Element | None, what: str, node: str | None, minimum: int,
              default: int = 0) -> int:
        """A token count or arc weight held by an annotation."""


# Annotations -------------------------------------------------------------------------


def value_element(annotation: Element | None) -> Element | None:
    """The element holding an annotation's value: ISO ``<text>``, JARP/PIPE ``<value>``.

    Course-material files nest it once more, as ``<initialMarking><token><value>``.
    """
    for holder in (annotation, child(annotation, "token")):
        for name in ("text", "value"):
            found = child(holder, name)
            if found is not None:
                return found
    return None


def name_of(element: Element) -> str | None:
    """The ``<name>`` of a node or net, stripped; ``None`` when absent or empty."""
    value = value_element(child(element, "name"))
    if value is None or value.text is None:
        return None
    return value.text.strip() or None


def report_losses(reading: Reading, element: Element, kind: str, node: str | None) -> None:
    """One note for each :class:`Loss` of a ``kind`` element whose tags ``element`` holds."""
    present = {local_name(found.tag) for found in element}
    for loss in losses_of(kind):
        if present & loss.tags:
            reading.note(kind, node, loss.message)

# PM4Py and ProM --------------------------------------------------------------------


def read_prom(reading: Reading, tool: Element, kind: str, node: str | None, found: dict[str, Any]) -> None:
    """ProM's ``activity="$invisible$"`` makes a silent transition."""
    if kind == "transition" and tool.get("activity") == "$invisible$":
        found["silent"] = True
    if len(tool):
        reading.note(kind, node, "ProM toolspecific content is not representable; ignored")


def read_stochastic(reading: Reading, tool: Element, kind: str, node: str | None,
                    found: dict[str, Any]) -> None:
    """PM4Py's stochastic nets: an ``invisible`` property makes a silent transition."""
    for prop in tool:
        if prop.get("key") == "invisible":
            found["silent"] = (prop.text or "").strip().lower() == "true"
        else:
            reading.note("transition", node, "stochastic (StochasticPetriNet) distributions are "
                         "not representable; ignored")


def read_data_variables(reading: Reading, net_element: Element) -> None:
    """A data Petri net's ``<variables>``: reported, with their names."""
    variables = child(net_element, "variables")
    if variables is not None and len(variables):
        names = ", ".join(
            (child(v, "name").text or "").strip() if child(v, "name") is not None else "?"
            for v in variables
        )
        reading.note("net", reading.net.id, f"data Petri net variables ({names}) are not representable;"
                     " ignored")


def read_data_guard(reading: Reading, element: Element, node: str, meta: dict[str, Any]) -> None:
    """A data Petri net's ``guard`` attribute: kept in ``meta["data_guard"]``, reported."""
    guard = element.get("guard")
    if guard is not None and guard.strip() not in ("", "true"):
        meta["data_guard"] = guard
        reading.note("transition", node, "data Petri net guard expressions are not representable; "
                     "kept in meta['data_guard'], not checked when firing")


def read_arc_name(reading: Reading, element: Element, arc: str) -> None:
    """ProM names an arc by its weight: any other name is reported."""
    name = name_of(element)
    if name is not None and not name.isdigit():
        reading.note("arc", arc, "arc names are not representable; ignored")


def check_arc_type(reading: Reading, element: Element, arc: str) -> None:
    """ProM's and PM4Py's ``<arctype>``, PIPE's ``<type value=...>``: only ``normal`` arcs
    are P/T arcs (reset and inhibitor arcs are refused)."""
    kind = None
    for tag in ("arctype", "type"):  # ProM/PM4Py <arctype><text>, PIPE <type value=...>
        declared = child(element, tag)
        if declared is not None and kind is None:
            value = value_element(declared)
            kind = (declared.get("value") or (value.text if value is not None else "") or "").strip()
    if kind not in (None, "", "normal"):
        reading.fail(f"{kind} arcs are not place/transition arcs; petriflow cannot represent them",
                     element, arc)


def read_final_marking(reading: Reading, net_element: Element) -> None:
    """PM4Py's and ProM's ``<finalmarkings>``: the first marking is the net's final one."""
    block = child(net_element, "finalmarkings")
    if block is None:
        return
    markings = children(block, "marking")
    if len(markings) > 1:
        reading.note("net", reading.net.id, f"{len(markings)} final markings given; petriflow keeps "
                     "one, the first")
    tokens: dict[str, int] = {}
    for entry in (markings[0] if markings else []):
        if local_name(entry.tag) != "place":
            reading.fail(f"<{local_name(entry.tag)}> in a final marking; expected <place idref=...>",
                         entry, reading.net.id)
        ref = entry.get("idref")
        place = reading.targets.get(ref or "", ref)
        if not place or place not in reading.net.places:
            reading.fail(f"final marking names unknown place {ref!r}"
                         f"{did_you_mean(str(ref), reading.net.places)}", entry, ref)
        if place in tokens:
            reading.fail("final marking names this place twice", entry, place)
        tokens[place] = reading.count(entry, "final marking", place, minimum=0)
    reading.net.set_final_marking(tokens)

# WoPeD -----------------------------------------------------------------------------


def read_woped(reading: Reading, tool: Element, kind: str, node: str | None, found: dict[str, Any]) -> None:
    """WoPeD's data: operators (see :func:`woped_operator`) and subprocess flags; its
    layout is skipped; times, probabilities and triggers are reported."""
    for item in tool:
        name = local_name(item.tag)
        text = (item.text or "").strip()
        if name in _WOPED_LAYOUT:
            continue
        if name == "operator" and kind == "transition":
            found["woped_operator"] = (item.get("type") or "", item.get("id"), item)
        elif name == "operator" and kind == "place":
            found.setdefault("meta", {})["woped_operator"] = {
                "group": item.get("id"), "type": item.get("type")}
        elif name == "subprocess" and kind == "transition":
            found["subprocess"] = text == "true"
        elif name == "time" and kind == "transition":
            if text not in ("", "0"):
                reading.note(kind, node, "WoPeD service times are not representable; ignored")
        elif name == "probability" and kind == "arc":
            if parse_decimal(text) != 1:
                reading.note(kind, node, "WoPeD arc probabilities are not representable; ignored")
        elif name == "trigger":
            reading.note(kind, node, "WoPeD triggers (resource, message, time) are not "
                         "representable; ignored")
        elif name in ("resources", "simulations", "partnerLinks", "variables") and not len(item):
            continue
        else:
            reading.note(kind, node, f"WoPeD data <{name}> is not representable; ignored")


def woped_operator(reading: Reading, found: tuple[str, str | None, Element], element: Element,
                   node: str) -> Operator | None:
    """The :class:`~petriflow.net.Operator` a WoPeD operator part belongs to (``None``,
    reported, for an OR-split or an unknown type)."""
    code, group, operator_element = found
    if not group:
        reading.fail("WoPeD <operator> without an id", operator_element, node)
    number = None
    if re.search(r"\d", code):  # any script's digit: the one rule decides (ASCII, at most 2**60)
        number = reading.integer(code, "WoPeD operator type", operator_element, node)
    kinds = WOPED_OPERATOR_TYPES.get(number) if number is not None else None
    if kinds is None:
        what = "OR-split" if code.strip() == "103" else f"of unknown type {code!r}"
        reading.note("transition", node, f"WoPeD operator {what} has no AND/XOR equivalent; its "
                     "parts are kept as plain transitions")
        return None
    split, join = kinds
    return Operator(group, split, join)


def read_subprocess_pages(reading: Reading) -> None:
    """WoPeD refines a transition by a ``<page id=t><net>``; it stays one transition."""
    for page in reading.subprocess_pages:
        page_id = page.get("id")
        inner = child(page, "net")
        assert inner is not None
        size = {f"{kind}s": len(children(inner, kind)) for kind in ("place", "transition", "arc")}
        nested = len(children(inner, "page"))
        if page_id in reading.net.transitions:
            reading.net.transitions[page_id].meta["subprocess"] = dict(size)
            deeper = f", {nested} nested subprocess(es)" if nested else ""
            reading.note("transition", page_id,
                         f"subprocess page not inlined; kept as one atomic transition (its net of "
                         f"{size['places']} places, {size['transitions']} transitions, {size['arcs']} "
                         f"arcs{deeper} is not read)")
        else:
            reading.note("page", page_id or f"line {line_of(page)}",
                         "page holds a <net> but no transition has its id; its net is not read")

# PIPE and SNAKES -------------------------------------------------------------------


def class_counts(reading: Reading, text: str, what: str, node: str | None, where: Element | None) -> int:
    """PIPE writes counts as ``Default,1`` (token class, count, ...)."""
    parts = [part.strip() for part in text.split(",")]
    if len(parts) % 2:
        reading.fail(f"{what} must be a whole number or 'class,count' pairs, got {text!r}", where, node)
    counts = {cls: reading.whole(count, what, node, where) for cls, count in zip(parts[::2], parts[1::2])}
    coloured = [cls for cls, count in counts.items() if count]
    if len(coloured) > 1:
        reading.fail(f"{what} {text!r} holds tokens of several classes ({', '.join(coloured)}); "
                     "a P/T net has one kind of token", where, node)
    return sum(counts.values())


def read_capacity(reading: Reading, element: Element, node: str) -> None:
    """A place's ``<capacity>`` other than 0 (none): reported, read as unbounded."""
    capacity = child(element, "capacity")
    if capacity is not None and reading.count(capacity, "capacity", node, minimum=0):
        reading.note("place", node, "place capacities are not representable; read as unbounded")


def read_tagged(reading: Reading, element: Element, arc: str) -> None:
    """PIPE's tagged arcs: reported, read as plain arcs."""
    tagged = value_element(child(element, "tagged"))
    if tagged is not None and (tagged.text or "").strip() == "true":
        reading.note("arc", arc, "PIPE tagged arcs are not representable; read as plain arcs")


def multiset_count(reading: Reading, multiset: Element, node: str) -> int:
    """SNAKES' native marking: ``<multiset><item><value>…</value><multiplicity>n``.

    Black tokens (``<value><token/></value>``) count as tokens; coloured values
    (``<object type="int">5</object>``...) count too, with a warning naming the
    place and the values lost, since a P/T net holds no token values.
    """
    total, coloured = 0, []
    for item in children(multiset, "item"):
        value = child(item, "value")
        times = child(item, "multiplicity")
        text = (times.text or "").strip() if times is not None else "1"
        count = reading.whole(text or "1", "multiplicity", node, times if times is not None else item)
        total += count
        inside = list(value) if value is not None else []
        if not (len(inside) == 1 and local_name(inside[0].tag) == "token"):
            shown = " ".join("".join(part.itertext()).strip() or local_name(part.tag)
                             for part in inside) or "?"
            coloured.append(shown if count == 1 else f"{shown} x{count}")
    if coloured:
        reading.note("place", node, f"coloured token values ({', '.join(coloured[:5])}"
                     f"{', ...' if len(coloured) > 5 else ''}) are not representable; read as {total}"
                     " plain tokens")
    return total


def universal_type(element: Element) -> bool:
    """Whether a place has SNAKES' ``<type domain="universal"/>`` ("any value"): nothing
    is lost in a P/T net."""
    place_type = child(element, "type")
    return place_type is not None and place_type.get("domain") == "universal" and not len(place_type)

# The Model Checking Contest (NUPN) -------------------------------------------------


def read_nupn(reading: Reading, tool: Element, kind: str, node: str | None, found: dict[str, Any]) -> None:
    """The Model Checking Contest's unit structure (NUPN 1.1), kept as
    ``net.meta["nupn"]``: ``{"version", "root", "safe", "units": {unit: {"places": [...],
    "subunits": [...]}}}`` (the writer keeps it with the net's other meta data)."""
    structure = child(tool, "structure")
    if structure is None or reading.nupn is not None:
        reading.note(kind, node, "NUPN data without a <structure>, or a second one, is not"
                     " representable; ignored")
        return
    units: dict[str, dict[str, list[str]]] = {}
    for unit in children(structure, "unit"):
        unit_id = (unit.get("id") or "").strip()
        places, subunits = child(unit, "places"), child(unit, "subunits")
        units[unit_id] = {
            "places": ((places.text or "").split() if places is not None else []),
            "subunits": ((subunits.text or "").split() if subunits is not None else []),
        }
    reading.nupn = {"version": (tool.get("version") or "").strip(),
                 "root": (structure.get("root") or "").strip(),
                 "safe": (structure.get("safe") or "").strip().lower() == "true",
                 "units": units}


def check_nupn(reading: Reading) -> None:
    """Keep the NUPN units in the net's meta data; one note if they name unknown places."""
    if reading.nupn is None:
        return
    reading.net.meta["nupn"] = reading.nupn
    named = {p for unit in reading.nupn["units"].values() for p in unit["places"]}
    unknown = sorted(named - set(reading.net.places))
    if unknown:
        some = f"{len(unknown)} places that are" if len(unknown) > 1 else "a place that is"
        reading.note("net", reading.net.id, f"NUPN units name {some} not in the net"
                     f" (e.g. {unknown[0]!r}); units kept as read")

# petriflow's own data --------------------------------------------------------------


def read_petriflow(reading: Reading, tool: Element, kind: str, node: str | None,
                   found: dict[str, Any]) -> None:
    """petriflow's own data (what :mod:`~petriflow.io.pnml_write` keeps): subnets, channels,
    actions, parameters, guards, timeouts, cancellation regions, outcome arcs,
    priorities, operators, labels, meta data and the run configuration."""
    version = (tool.get("version") or "").strip()
    if version != PETRIFLOW_TOOL_VERSION:
        reading.note(kind, node, f"petriflow data of version {version!r} is not understood by "
                     f"this petriflow (version {PETRIFLOW_TOOL_VERSION}); ignored")
        return
    for item in tool:
        name = local_name(item.tag)
        text = item.text or ""
        if name == "subnet" and kind == "net":
            found.setdefault("subnets", []).append(_subnet_of(reading, item))
        elif name == "subnet" and kind in ("place", "transition"):
            found["subnet"] = text
        elif name == "channel" and kind == "place":
            found["channel"] = text
        elif name == "timeout" and kind == "transition":
            timeout = parse_decimal(text)
            if timeout is None or not timeout > 0:
                reading.fail(f"timeout must be a number of seconds > 0, got {text!r}", item, node)
            found["timeout"] = timeout
        elif name == "cancel" and kind == "transition":
            if not item.get("node"):
                reading.fail("petriflow <cancel> without a node", item, node)
            found.setdefault("cancels", []).append(item.get("node"))
        elif name == "outcome" and kind == "transition":
            reading.outcome_arcs.append((str(node), item))
        elif name in ("action", "guard") and kind == "transition":
            found[name] = text
            found.setdefault("lines", {})[name] = line_of(item)
        elif name == "params" and kind == "transition":
            found["params"] = _json_of(reading, item, dict, "params", node)
            found.setdefault("lines", {})[name] = line_of(item)
        elif name == "run" and kind == "net":
            try:
                run = parse_json(text)
            except ValueError as exc:
                reading.fail(f"petriflow run: {exc}", item, node)
            if not isinstance(run, (str, dict)):
                reading.fail("petriflow run must be a JSON string (a file) or object (the configuration)",
                             item, node)
            found["run"] = run
            found["run_line"] = line_of(item)
        elif name == "properties" and kind == "net":
            try:
                found["properties"] = parse_json(text)
            except ValueError as exc:
                reading.fail(f"petriflow properties: {exc}", item, node)
            found["properties_line"] = line_of(item)
        elif name == "priority" and kind == "transition":
            found["priority"] = reading.integer(text, "priority", item, node)
        elif name == "operator" and kind == "transition":
            found["operator"] = _operator_of(reading, item, node)
        elif name == "label":
            found["label"] = _json_of(reading, item, str, "label", node)
        elif name == "meta":
            found["meta"] = _json_of(reading, item, dict, "meta", node)
        else:
            reading.note(kind, node, f"petriflow data <{name}> is not understood; ignored")


def _subnet_of(reading: Reading, element: Element) -> tuple[str, str | None, str | None, str | None, Element]:
    subnet = element.get("id")
    if not subnet:
        reading.fail("petriflow <subnet> without an id", element, reading.net.id)
    return subnet, element.get("label"), element.get("agent"), element.get("state"), element


def _operator_of(reading: Reading, element: Element, node: str | None) -> Operator:
    group = element.get("group")
    if not group:
        reading.fail("petriflow <operator> without a group", element, node)
    for side in ("split", "join"):
        kind = element.get(side)
        if kind is not None and kind not in OPERATOR_KINDS:
            reading.fail(f"operator {side} must be one of {', '.join(OPERATOR_KINDS)}, got {kind!r}",
                         element, node)
    return Operator(group, element.get("split"), element.get("join"))


def _json_of(reading: Reading, element: Element, kind: type, what: str, node: str | None) -> Any:
    try:
        value = parse_json(element.text or "")
    except ValueError as exc:
        reading.fail(f"petriflow {what}: {exc}", element, node)
    if not isinstance(value, kind):
        reading.fail(f"petriflow {what} must be a JSON {'object' if kind is dict else 'string'}",
                     element, node)
    return value

# The table ------------------------------------------------------------------------------


@dataclass(frozen=True)
class ToolData:
    """How one tool's ``<toolspecific tool=...>`` data is read: by ``read`` (into the
    ``found`` dict of the element), on the elements of ``kinds`` (``None``: all);
    elsewhere it is reported as a loss."""

    read: Callable[[Reading, Element, str, str | None, dict[str, Any]], None]
    kinds: frozenset[str] | None = None


@dataclass(frozen=True)
class Loss:
    """Children (``tags``) of a ``kind`` element whose content no petriflow net holds:
    reported with ``message``, once per kind of loss."""

    kind: str
    tags: frozenset[str]
    message: str


@dataclass(frozen=True)
class Dialect:
    """One tool's PNML: what it writes beyond ISO/IEC 15909-2.

    Attributes:
        name: the tool(s).
        net_types: the ``<net type=...>`` URIs it writes, each with what it is (read as
            place/transition nets).
        tools: its ``<toolspecific>`` data, by ``tool`` name.
        tags: per kind of element (``net``, ``place``, ``transition``, ``arc``), the
            children it adds: read by its rules or reported, never "unknown".
        losses: the children whose content is reported as lost.
    """

    name: str
    net_types: Mapping[str, str] = field(default_factory=dict)
    tools: Mapping[str, ToolData] = field(default_factory=dict)
    tags: Mapping[str, frozenset[str]] = field(default_factory=dict)
    losses: tuple[Loss, ...] = ()


#: Every dialect read, in the order their net types are listed in errors.
DIALECTS: tuple[Dialect, ...] = (
    Dialect("ISO/IEC 15909-2 (ePNK, Model Checking Contest)",
            net_types={PTNET_TYPE: "ISO/IEC 15909-2 P/T net (ePNK, Model Checking Contest)"},
            tools={"nupn": ToolData(read_nupn, frozenset({"net", "page"}))}),
    Dialect("PM4Py, ProM",
            net_types={"http://www.pnml.org/version-2009/grammar/pnmlcoremodel":
                       "PNML core model (PM4Py, ProM)"},
            tools={"ProM": ToolData(read_prom),
                   "StochasticPetriNet": ToolData(read_stochastic, frozenset({"transition"}))},
            tags={"net": frozenset({"finalmarkings", "variables"}),
                  "transition": frozenset({"readVariable", "writeVariable"}),
                  "arc": frozenset({"arctype", "name"})},
            losses=(Loss("transition", frozenset({"readVariable", "writeVariable"}),
                         "data Petri net variable reads/writes (<readVariable>, <writeVariable>) are not"
                         " representable; ignored"),)),
    Dialect("WoPeD",
            net_types={"http://www.informatik.hu-berlin.de/top/pntd/ptNetb": "WoPeD"},
            tools={"WoPeD": ToolData(read_woped)}),
    Dialect("PNK",
            net_types={"http://www.informatik.hu-berlin.de/top/pntd/ptNet": "pre-ISO PNML P/T net (PNK)"}),
    Dialect("JARP, Petri Net Plans", net_types={"PTNet": "JARP, Petri Net Plans"}),
    Dialect("PIPE",
            net_types={"P/T net": "PIPE"},
            tags={"net": frozenset({"token"}), "place": frozenset({"capacity"}), "transition": _GSPN_TAGS,
                  "arc": frozenset({"type", "tagged"})},
            losses=(Loss("transition", _GSPN_TAGS, "GSPN timing (<rate>, <timed>, <infiniteServer>,"
                         " <priority>) is not representable; read as an untimed P/T net"),)),
    Dialect("SNAKES"),
    Dialect("petriflow", tools={PETRIFLOW_TOOL: ToolData(read_petriflow)}),
)

#: Net types read as place/transition nets, with the tools that write them. A ``<net>``
#: without a ``type`` (SNAKES, course material) is read as a P/T net too; any other
#: type is refused.
PT_NET_TYPES: dict[str, str] = {uri: what for dialect in DIALECTS for uri, what in dialect.net_types.items()}

#: Every ``<toolspecific>`` data read, by ``tool`` name.
TOOLS: dict[str, ToolData] = {tool: data for dialect in DIALECTS for tool, data in dialect.tools.items()}


def tags_of(kind: str) -> frozenset[str]:
    """The children the dialects add to a ``kind`` element (see :attr:`Dialect.tags`)."""
    return frozenset().union(*(dialect.tags.get(kind, frozenset()) for dialect in DIALECTS))


def losses_of(kind: str) -> list[Loss]:
    """The losses reported on a ``kind`` element, in the order of :data:`DIALECTS`."""
    return [loss for dialect in DIALECTS for loss in dialect.losses if loss.kind == kind]
