"""Writing PNML: one ISO/IEC 15909-2 P/T net that other tools open and petriflow restores.

Use it through :mod:`petriflow.io.pnml` (``dumps_pnml``, ``save_pnml``).

The file is a standard P/T net (namespace, ``ptnet`` type, one ``<page>``, ``<name>``,
``<initialMarking>``, ``<inscription>`` for weights above 1, node positions) plus what
other tools read:

* PM4Py's ``<finalmarkings>`` block when the net has a final marking;
* ProM's ``activity="$invisible$"`` marker on silent transitions.

What only petriflow knows goes into ``<toolspecific tool="petriflow" version="1">``
elements, which other tools keep or skip:

* on the net: ``<subnet id label agent state/>`` per subnet, ``<meta>`` (JSON);
* on places: ``<subnet>``, ``<channel>``, ``<meta>`` (JSON);
* on transitions: ``<action>``, ``<params>`` (JSON), ``<guard>``, ``<priority>``,
  ``<subnet>``, ``<operator group split join/>``, ``<timeout>``, one
  ``<cancel node/>`` per member of the cancellation region, one
  ``<outcome kind place weight/>`` per output arc reserved for an action outcome, and
  ``<meta>`` (JSON).

Output arcs reserved for an outcome (``failed``, ``timeout``, ``cancelled``) are not
written as PNML arcs: other tools see the net of the ``ok`` runs, never a transition
that produces its success and failure outputs at once.

Labels live in ``<name><text>``; a label that text cannot carry exactly (empty, with
surrounding whitespace, a carriage return or a character XML forbids) is also stored as
a JSON string in the petriflow ``<label>``, which wins on reading.
"""

from __future__ import annotations

import json
import math
import re
import uuid
import warnings
from pathlib import Path
from typing import Any
from xml.etree.ElementTree import Element, SubElement, indent, tostring

from petriflow.errors import NetFormatError
from petriflow.io.files import write_atomic
from petriflow.io.pnml_dialects import PETRIFLOW_TOOL, PETRIFLOW_TOOL_VERSION, PNML_NAMESPACE, PTNET_TYPE
from petriflow.io.pnml_read import PnmlWarning
from petriflow.net import OPERATOR_KINDS, Net, Place, Transition

__all__ = ["dumps_pnml", "save_pnml"]

_XML_INVALID = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def _text_carries(text: str) -> bool:
    """Whether ``<text>`` content reads back as exactly ``text`` (names are stripped)."""
    return bool(text) and text == text.strip() and "\r" not in text and not _XML_INVALID.search(text)


def _json_exact(value: Any) -> str | None:
    """``value`` as JSON, or ``None`` when JSON would not give the same value back."""
    try:
        text = json.dumps(value, ensure_ascii=True, allow_nan=False)
    except (TypeError, ValueError):
        return None
    return text if json.loads(text) == value else None


def _is_position(value: Any) -> bool:
    return (
        isinstance(value, (list, tuple)) and len(value) == 2
        and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                for v in value)
    )


def _sub(parent: Element, tag: str, text: str | None = None, **attributes: str) -> Element:
    element = SubElement(parent, tag, {k: v for k, v in attributes.items() if v is not None})
    if text is not None:
        element.text = text
    return element


class _Writer:
    """Builds the XML tree of one net."""

    def __init__(self, net: Net) -> None:
        self.net = net
        self.dropped: list[str] = []

    def check(self, text: str | None, what: str, element: str | None = None) -> str | None:
        """Refuse text XML cannot hold (ids, attributes, plain petriflow fields)."""
        if text is not None and _XML_INVALID.search(text):
            raise NetFormatError(f"{what} {text!r} holds characters XML cannot represent",
                                 element=element)
        return text

    def check_plain(self, text: str, what: str, element: str) -> str:
        """Element text is read back verbatim, except that XML turns ``\\r`` into ``\\n``."""
        self.check(text, what, element)
        if "\r" in text:
            raise NetFormatError(f"{what} {text!r} holds a carriage return, which PNML text cannot keep",
                                 element=element)
        return text

    def write(self) -> str:
        net = self.net
        root = Element("pnml", {"xmlns": PNML_NAMESPACE})
        net_element = _sub(root, "net", id=self.check(net.id, "net id", net.id), type=PTNET_TYPE)
        tool = Element("toolspecific", tool=PETRIFLOW_TOOL, version=PETRIFLOW_TOOL_VERSION)
        self.name(net_element, tool, net.label)
        for subnet in net.subnets.values():
            _sub(tool, "subnet", id=self.check(subnet.id, "subnet id", subnet.id),
                 label=self.check(subnet.label, "subnet label", subnet.id),
                 agent=self.check(subnet.agent, "subnet agent", subnet.id),
                 state=self.check(subnet.state, "subnet state", subnet.id))
        self.meta(tool, net.meta, f"net {net.id!r}")
        if net.run is not None:
            run = _json_exact(net.run)
            if run is None:
                raise NetFormatError("the run configuration cannot be written as JSON", element=net.id)
            _sub(tool, "run", run)
        if net.properties:
            from petriflow.properties.yaml_props import property_entry

            _sub(tool, "properties", _json_exact([property_entry(p) for p in net.properties]))
        if len(tool):
            net_element.append(tool)
        page = _sub(net_element, "page", id=self.fresh_id("page"))
        for place in net.places.values():
            self.place(page, place)
        for transition in net.transitions.values():
            self.transition(page, transition)
        self.arcs(page)
        if net.final_marking is not None:
            marking = _sub(_sub(net_element, "finalmarkings"), "marking")
            for place_id, count in net.final_marking.items():
                _sub(_sub(marking, "place", idref=place_id), "text", str(count))
        indent(root, space="  ")
        return '<?xml version="1.0" encoding="UTF-8"?>\n' + tostring(root, encoding="unicode") + "\n"

    def fresh_id(self, stem: str, taken: set[str] | None = None) -> str:
        used = set(self.net.places) | set(self.net.transitions) | (taken or set())
        candidate, number = stem, 0
        while candidate in used:
            number += 1
            candidate = f"{stem}{number}"
        return candidate

    # Parts --------------------------------------------------------------------------
    def name(self, element: Element, tool: Element, label: str | None) -> None:
        """Write ``<name>``; a label the name cannot carry also goes to petriflow data."""
        if label is None:
            return
        if not _text_carries(label):
            _sub(tool, "label", json.dumps(label, ensure_ascii=True))
            label = _XML_INVALID.sub("", label).replace("\r", " ").strip()
        if label:
            _sub(_sub(element, "name"), "text", label)

    def meta(self, tool: Element, meta: dict[str, Any], owner: str) -> None:
        data = {k: v for k, v in meta.items() if not (k == "position" and _is_position(v))}
        if not data:
            return
        kept = {k: v for k, v in data.items() if isinstance(k, str) and _json_exact(v) is not None}
        dropped = [k for k in data if k not in kept]
        if dropped:
            self.dropped.append(f"{owner}: meta {', '.join(repr(k) for k in dropped)} is not JSON "
                                "data; not written to PNML")
        if kept:
            _sub(tool, "meta", json.dumps(kept, ensure_ascii=True))

    def graphics(self, element: Element, meta: dict[str, Any]) -> None:
        position = meta.get("position")
        if _is_position(position):
            x, y = (repr(v) if isinstance(v, float) else str(v) for v in position)
            _sub(_sub(element, "graphics"), "position", x=x, y=y)

    def place(self, page: Element, place: Place) -> None:
        element = _sub(page, "place", id=self.check(place.id, "place id", place.id))
        tool = Element("toolspecific", tool=PETRIFLOW_TOOL, version=PETRIFLOW_TOOL_VERSION)
        self.name(element, tool, place.label)
        self.graphics(element, place.meta)
        tokens = self.net.initial_marking[place.id]
        if tokens:
            _sub(_sub(element, "initialMarking"), "text", str(tokens))
        if place.subnet is not None:
            _sub(tool, "subnet", self.check_plain(place.subnet, "subnet", place.id))
        if place.channel is not None:
            _sub(tool, "channel", self.check_plain(place.channel, "channel", place.id))
        self.meta(tool, place.meta, f"place {place.id!r}")
        if len(tool):
            element.append(tool)

    def transition(self, page: Element, transition: Transition) -> None:
        t = transition
        element = _sub(page, "transition", id=self.check(t.id, "transition id", t.id))
        tool = Element("toolspecific", tool=PETRIFLOW_TOOL, version=PETRIFLOW_TOOL_VERSION)
        self.name(element, tool, t.label)
        self.graphics(element, t.meta)
        if t.silent:
            node_id = uuid.uuid5(uuid.NAMESPACE_URL, f"petriflow:{self.net.id}:{t.id}")
            _sub(element, "toolspecific", tool="ProM", version="6.4", activity="$invisible$",
                 localNodeID=str(node_id))
        if t.action is not None:
            _sub(tool, "action", self.check_plain(t.action, "action", t.id))
        if t.params:
            params = _json_exact(t.params)
            if params is None:
                raise NetFormatError("params are not plain JSON data (strings as keys; strings, "
                                     "numbers, booleans, null, lists, objects as values)", element=t.id)
            _sub(tool, "params", params)
        if t.guard is not None:
            _sub(tool, "guard", self.check_plain(t.guard, "guard", t.id))
        if isinstance(t.priority, bool) or not isinstance(t.priority, int):
            raise NetFormatError(f"priority must be a whole number, got {t.priority!r}", element=t.id)
        if t.priority:
            _sub(tool, "priority", str(t.priority))
        if t.subnet is not None:
            _sub(tool, "subnet", self.check_plain(t.subnet, "subnet", t.id))
        if t.timeout is not None:
            _sub(tool, "timeout", repr(float(t.timeout)))
        for node in t.cancels:
            _sub(tool, "cancel", node=self.check(node, "cancellation region member", t.id))
        for outcome in self.net.outcomes(t.id):
            for place, weight in self.net.postset(t.id, outcome).items():
                arc = self.net.arc(t.id, place, outcome)
                _sub(tool, "outcome", kind=outcome, place=place, weight=str(weight),
                     id=arc.id if arc is not None and arc.id else None)
        if t.operator is not None:
            op = t.operator
            for side, kind in (("split", op.split), ("join", op.join)):
                if kind is not None and kind not in OPERATOR_KINDS:
                    raise NetFormatError(f"operator {side} must be one of {', '.join(OPERATOR_KINDS)},"
                                         f" got {kind!r}", element=t.id)
            _sub(tool, "operator", group=self.check(op.group, "operator group", t.id),
                 split=self.check(op.split, "operator split", t.id),
                 join=self.check(op.join, "operator join", t.id))
        self.meta(tool, t.meta, f"transition {t.id!r}")
        if len(tool):
            element.append(tool)

    def arcs(self, page: Element) -> None:
        taken: set[str] = {page.get("id", "")}
        for number, arc in enumerate(self.net.arcs, start=1):
            if arc.outcome is not None:  # written with its transition's petriflow data
                continue
            arc_id = arc.id
            if not arc_id or arc_id in taken or arc_id in self.net.places or arc_id in self.net.transitions \
                    or _XML_INVALID.search(arc_id):
                arc_id = self.fresh_id(f"a{number}", taken)
            taken.add(arc_id)
            element = _sub(page, "arc", id=arc_id, source=arc.source, target=arc.target)
            if arc.weight != 1:
                _sub(_sub(element, "inscription"), "text", str(arc.weight))


def dumps_pnml(net: Net) -> str:
    """The net as ISO PNML text (see the module docstring for what goes where).

    Raises:
        NetFormatError: an id, name or parameter cannot be written to XML losslessly
            (characters XML forbids, params that are not plain JSON data).
    """
    return _dumps(net, stacklevel=3)


def _dumps(net: Net, stacklevel: int) -> str:
    writer = _Writer(net)
    text = writer.write()
    for message in writer.dropped:
        warnings.warn(message, PnmlWarning, stacklevel=stacklevel)
    return text


def save_pnml(net: Net, path: str | Path) -> None:
    """Write ``net`` to ``path`` as PNML (atomically: a failed write keeps the old file).

    Raises:
        NetFormatError: as :func:`dumps_pnml`, naming ``path``.
    """
    try:
        text = _dumps(net, stacklevel=3)
    except NetFormatError as exc:
        raise exc.at(str(path)) from None
    write_atomic(path, text)
