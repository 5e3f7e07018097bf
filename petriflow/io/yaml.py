"""petriflow's YAML net format (``petriflow: 1``), read and written.

The format is the constructor in data: every key maps onto an argument of
:meth:`Net.add_place`, :meth:`Net.add_transition`, :meth:`Net.add_arc` or
:func:`~petriflow.workflow.add_operator`. See ``docs/yaml-format.md``.

Files are parsed with a safe loader (:mod:`petriflow.io.safe_yaml`: no Python tags,
bounded) into containers that record line numbers, so an error names the line:
``nets/relay.yaml:14: 't9': unknown place 'p9'``. The reader keeps those lines on the
net (:attr:`Net.lines`) for the errors found later, when actions are bound.

Examples:
    >>> net = loads_net('''
    ... petriflow: 1
    ... net: demo
    ... places: [{id: i, tokens: 1}, o]
    ... transitions:
    ...   - {id: work, action: robot.move, params: {x: 1}, in: [i], out: [o]}
    ... ''')
    >>> net, net.initial_marking, net.transition("work").action
    (<Net 'demo': 2 places, 1 transitions, 2 arcs>, Marking({'i': 1}), 'robot.move')
    >>> loads_net(dumps_net(net)).structure() == net.structure()
    True
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

import yaml

from petriflow import limits
from petriflow.collector import paused
from petriflow.errors import NetFormatError, NumberError, PetriflowError, did_you_mean
from petriflow.io.files import read_text_file, write_atomic
from petriflow.io.safe_yaml import LineDict, line_of, parse_yaml, plain, yaml_problem
from petriflow.net import OPERATOR_KINDS, OUTCOMES, Net, Operator, Transition
from petriflow.workflow import add_operator, operator_groups

__all__ = ["FORMAT_VERSION", "load_yaml", "loads_net", "dumps_net", "save_yaml", "net_to_dict", "parse_yaml",
           "yaml_problem"]

#: The name runtime/session.py imports (allowlisted in tests/test_architecture.py): drop it
#: once it imports :func:`yaml_problem`.
_yaml_problem = yaml_problem

#: The version of the YAML format this module reads and writes.
FORMAT_VERSION = 1

_TOP_KEYS = {"petriflow", "net", "label", "subnets", "places", "transitions", "arcs", "final", "meta", "run",
             "properties"}
_SUBNET_KEYS = {"id", "label", "agent", "state", "places", "transitions"}
_PLACE_KEYS = {"id", "label", "tokens", "channel", "meta"}
_TRANSITION_KEYS = {
    "id", "label", "action", "params", "guard", "priority", "silent", "timeout", "cancels",
    "in", "out", "outcomes", "split", "join", "operator", "meta",
}
_ARC_KEYS = {"from", "to", "weight", "id", "when"}



class _Reader:
    """Builds a :class:`Net` from parsed YAML, raising errors with line numbers."""

    def __init__(self, data: Any, name: str) -> None:
        self.data = data
        self.name = name
        self.net = Net(name)
        self.pending_arcs: list[tuple[str, str, Any, int | None, str | None, str | None]] = []

    def fail(self, message: str, item: Any = None, element: str | None = None, line=None):
        raise NetFormatError(message, line=line or line_of(item), element=element)

    def check_keys(self, item: Any, allowed: set[str], what: str, element: str | None = None):
        if not isinstance(item, dict):
            self.fail(f"{what} must be a mapping, got {type(item).__name__}", item, element)
        for key in item:
            if key not in allowed:
                hint = did_you_mean(str(key), allowed)
                self.fail(f"unknown key {key!r} in {what}{hint}", item, element)

    def read(self) -> Net:
        data = self.data
        if not isinstance(data, dict):
            self.fail("a petriflow net file is a mapping with 'petriflow: 1' at the top", data, line=1)
        self.check_keys(data, _TOP_KEYS, "net")
        version = data.get("petriflow")
        if version is None:
            self.fail("missing 'petriflow: 1' version key", data)
        if type(version) is not int or version != FORMAT_VERSION:
            self.fail(f"unsupported format version {version!r}; this petriflow reads {FORMAT_VERSION}", data)
        if "net" in data:
            self.net.id = self.ident(data["net"], "the net's id", data)
        self.net.label = _text(data.get("label"), "the net's label", lambda m: self.fail(m, data))
        self.net.meta = _meta(data.get("meta"), lambda m: self.fail(m, data))
        if data.get("run") is not None:
            run = data["run"]
            if not isinstance(run, (str, dict)):
                self.fail("'run' must name a run configuration file or be one (a mapping)", data,
                          line=data.key_lines.get("run"))
            self.net.run = _exact(run, "an inline 'run' configuration", lambda m: self.fail(
                m, data, line=data.key_lines.get("run")))
            self.net.lines["run"] = data.key_lines.get("run", data.line)
            for key, at in getattr(run, "key_lines", {}).items():  # where each setting is, for its errors
                self.net.lines[f"run.{key}"] = at
                for i, item_at in enumerate(getattr(run[key], "item_lines", ())):
                    self.net.lines[f"run.{key}/{i}"] = item_at
        for subnet in self.as_list(data.get("subnets"), "subnets", data):
            self.read_subnet(subnet)
        places = self.as_list(data.get("places"), "places", data)
        for place in places:
            self.read_place(place, None, line_of(places))
        transitions = self.as_list(data.get("transitions"), "transitions", data)
        for subnet in self.as_list(data.get("subnets"), "subnets", data):
            members = self.as_list(subnet.get("transitions"), "transitions", subnet)
            for transition in members:
                subnet_id = self.ident(subnet.get("id"), "a subnet id", subnet)
                self.read_transition(transition, subnet_id, line_of(members))
        for transition in transitions:
            self.read_transition(transition, None, line_of(transitions))
        for arc in self.as_list(data.get("arcs"), "arcs", data):
            self.read_arc(arc)
        self.add_pending_arcs()
        try:
            self.net.check_references()
        except PetriflowError as exc:
            self.fail(str(exc), data)
        if data.get("final") is not None:
            final = data["final"]
            self.net.set_final_marking(self.read_marking(final, "final marking"))
        if data.get("properties") is not None:
            # what the mission must guarantee (petriflow.properties): read and checked
            # against the net's names now, so that a typo fails at load time
            from petriflow.properties.yaml_props import check_property_names, parse_properties

            self.net.properties = parse_properties(data["properties"], None,
                                                   data.key_lines.get("properties", data.line))
            check_property_names(self.net, self.net.properties)
        return self.net

    def as_list(self, value: Any, what: str, parent: Any) -> list:
        if value is None:
            return []
        if not isinstance(value, list):
            self.fail(f"'{what}' must be a list", value if hasattr(value, "line") else parent)
        return value

    def read_subnet(self, item: Any) -> None:
        self.check_keys(item, _SUBNET_KEYS, "subnet")
        if "id" not in item:
            self.fail("subnet without 'id'", item)
        sid = self.ident(item["id"], "a subnet id", item)
        if sid in self.net.subnets:
            self.fail("duplicate subnet id", item, sid)
        fail = (lambda m: self.fail(m, item, sid))
        try:
            self.net.add_subnet(sid, _text(item.get("label"), "label", fail), _text(item.get("agent"), "agent", fail),
                                _text(item.get("state"), "state", fail))
        except NetFormatError:
            raise
        except PetriflowError as exc:
            self.fail(str(exc), item, sid)
        places = self.as_list(item.get("places"), "places", item)
        for place in places:
            self.read_place(place, sid, line_of(places))

    def read_place(self, item: Any, subnet: str | None, list_line: int | None = None) -> None:
        if not isinstance(item, dict):
            item = LineDict(id=self.ident(item, "a place id", None, line=list_line))
            item.line = list_line or 0
        self.check_keys(item, _PLACE_KEYS, "place", item.get("id"))
        if "id" not in item:
            self.fail("place without 'id'", item)
        pid = self.ident(item["id"], "a place id", item)
        tokens = self.whole(item.get("tokens", 0), "tokens", 0, item, pid)
        if pid in self.net.places or pid in self.net.transitions:
            self.fail("duplicate id", item, pid)
        channel = item.get("channel")
        if channel is not None and not isinstance(channel, str):
            self.fail("'channel' must be a channel name (a string)", item, pid)
        fail = (lambda m: self.fail(m, item, pid))
        try:
            self.net.add_place(pid, tokens=tokens, label=_text(item.get("label"), "label", fail), subnet=subnet,
                               meta=_meta(item.get("meta"), fail), channel=channel)
        except NetFormatError:
            raise
        except PetriflowError as exc:
            self.fail(str(exc), item, pid)
        self.net.lines[pid] = item.line

    def read_branches(self, value: Any, item: Any, tid: str, key: str) -> dict[str, int]:
        if value is None:
            return {}
        if isinstance(value, str):
            value = [value]
        if isinstance(value, list):
            pairs = [(self.ident(p, f"a place in '{key}'", item), 1) for p in value]
        elif isinstance(value, dict):
            pairs = [(self.ident(p, f"a place in '{key}'", item), w) for p, w in value.items()]
        else:
            self.fail(f"'{key}' must be a list of places or a mapping place: weight", item, tid)
        branches: dict[str, int] = {}
        for place, weight in pairs:
            self.check_weight(weight, item, tid)
            if place not in self.net.places:
                hint = did_you_mean(place, self.net.places)
                self.fail(f"'{key}' names unknown place {place!r}{hint}", item, tid)
            if place in branches:
                self.fail(f"'{key}' names place {place!r} twice", item, tid)
            branches[place] = weight
        return branches

    def check_weight(self, weight: Any, item: Any, element: str | None) -> None:
        self.whole(weight, "arc weight", 1, item, element)

    def whole(self, value: Any, what: str, minimum: int | None, item: Any = None, element: str | None = None,
              line: int | None = None) -> int:
        """A count, weight or priority: a YAML integer (the builder has applied the one rule
        to how it is written: decimal ASCII digits, at most 2**60) of at least ``minimum``.
        A number in quotes is text, and refused."""
        if isinstance(value, str):
            try:
                limits.parse_integer(value, what)  # not a number at all: the rule's own message
            except NumberError as exc:
                self.fail(str(exc), item, element, line=line)
            self.fail(f"{what} must be a whole number, got the text {value!r}: write it without quotes",
                      item, element, line=line)
        if isinstance(value, bool) or not isinstance(value, int):
            shown = {True: "true", False: "false", None: "null"}.get(value, repr(value)) \
                if isinstance(value, (bool, type(None))) else repr(value)
            at_least = "" if minimum is None else f" >= {minimum}"
            self.fail(f"{what} must be a whole number{at_least}, got {shown}", item, element, line=line)
        try:
            return limits.parse_integer(value, what, minimum=minimum)
        except NumberError as exc:
            self.fail(str(exc), item, element, line=line)

    def read_transition(self, item: Any, subnet: str | None, list_line: int | None = None) -> None:
        if not isinstance(item, dict):
            item = LineDict(id=self.ident(item, "a transition id", None, line=list_line))
            item.line = list_line or 0
        self.check_keys(item, _TRANSITION_KEYS, "transition", item.get("id"))
        if "id" not in item:
            self.fail("transition without 'id'", item)
        tid = self.ident(item["id"], "a transition id", item)
        if tid in self.net.places or tid in self.net.transitions:
            self.fail("duplicate id", item, tid)
        params = item.get("params") or {}
        if not isinstance(params, dict):
            self.fail("'params' must be a mapping", item, tid)
        self.record_lines(tid, item, params)
        priority = self.whole(item.get("priority", 0), "priority", None, item, tid)
        timeout = item.get("timeout")
        if timeout is not None and (isinstance(timeout, bool) or not isinstance(timeout, (int, float))
                                    or not timeout > 0):
            self.fail(f"timeout must be a number of seconds > 0, got {timeout!r}", item, tid)
        cancels = item.get("cancels") or []
        if isinstance(cancels, str):
            cancels = [cancels]
        if not isinstance(cancels, list):
            self.fail("'cancels' must be a list of place and transition ids", item, tid)
        attributes: dict[str, Any] = dict(
            timeout=None if timeout is None else float(timeout),
            cancels=tuple(self.ident(c, "an id in 'cancels'", item) for c in cancels),
            label=_text(item.get("label"), "label", lambda m: self.fail(m, item, tid)),
            action=item.get("action"),
            params=_exact(params, "'params'", lambda m: self.fail(m, item, tid)),
            guard=item.get("guard"),
            subnet=subnet,
            silent=bool(item.get("silent", False)),
            priority=priority,
            meta=_meta(item.get("meta"), lambda m: self.fail(m, item, tid)),
        )
        for key in ("action", "guard"):
            if attributes[key] is not None and not isinstance(attributes[key], str):
                self.fail(f"'{key}' must be a name (a string)", item, tid)
        inputs = self.read_branches(item.get("in"), item, tid, "in")
        outputs = self.read_branches(item.get("out"), item, tid, "out")
        outcomes = item.get("outcomes") or {}
        if not isinstance(outcomes, dict):
            self.fail("'outcomes' must map an outcome (failed, timeout, cancelled) to places", item, tid)
        routed = {}
        for outcome, branches in outcomes.items():
            if outcome not in OUTCOMES:
                self.fail(f"unknown outcome {outcome!r} in 'outcomes'{did_you_mean(str(outcome), OUTCOMES)}"
                          f" (one of {', '.join(OUTCOMES)})", item, tid)
            routed[outcome] = self.read_branches(branches, item, tid, f"outcomes.{outcome}")
        split, join = item.get("split"), item.get("join")
        if routed and (split is not None or join is not None):
            self.fail("'outcomes' cannot be combined with 'split'/'join'", item, tid)
        try:
            if split is not None or join is not None:
                if "operator" in item:
                    self.fail("give either 'split'/'join' or 'operator', not both", item, tid)
                if attributes["label"] is None:
                    attributes["label"] = tid
                add_operator(self.net, tid, inputs=inputs, outputs=outputs, split=split,
                             join=join, **attributes)
                return
            operator = item.get("operator")
            if operator is not None:
                if not isinstance(operator, dict) or "group" not in operator:
                    self.fail("'operator' must be a mapping with 'group' (and 'split'/'join')", item, tid)
                for side in ("split", "join"):
                    if operator.get(side) is not None and operator.get(side) not in OPERATOR_KINDS:
                        self.fail(f"operator {side} must be one of {', '.join(OPERATOR_KINDS)}, got"
                                  f" {operator.get(side)!r}", item, tid)
                attributes["operator"] = Operator(self.ident(operator["group"], "an operator group", item), operator.get("split"),
                                                  operator.get("join"))
            self.net.add_transition(tid, **attributes)
            for place, weight in inputs.items():
                self.net.add_arc(place, tid, weight)
            for place, weight in outputs.items():
                self.net.add_arc(tid, place, weight)
            for outcome, branches in routed.items():
                for place, weight in branches.items():
                    self.net.add_arc(tid, place, weight, outcome=outcome)
        except NetFormatError:
            raise
        except PetriflowError as exc:
            self.fail(str(exc), item, tid)

    def record_lines(self, tid: str, item: Any, params: Any) -> None:
        """Remember where the transition, its action, guard and parameters are written."""
        lines = self.net.lines
        lines[tid] = item.line
        key_lines = getattr(item, "key_lines", {})
        for key in ("action", "guard", "params"):
            if key in key_lines:
                lines[f"{tid}/{key}"] = key_lines[key]
        for key, line in getattr(params, "key_lines", {}).items():
            lines[f"{tid}/params/{key}"] = line

    def read_arc(self, item: Any) -> None:
        if isinstance(item, list) and len(item) in (2, 3):
            source, target = (self.ident(end, "an arc's end", item) for end in item[:2])
            weight = item[2] if len(item) == 3 else 1
            self.pending_arcs.append((source, target, weight, line_of(item), None, None))
            return
        self.check_keys(item, _ARC_KEYS, "arc")
        for key in ("from", "to"):
            if key not in item:
                self.fail(f"arc without '{key}'", item)
        when = item.get("when")
        if when is not None and when != "ok" and when not in OUTCOMES:
            self.fail(f"'when' must be ok or one of {', '.join(OUTCOMES)}, got {when!r}", item)
        self.pending_arcs.append(
            (self.ident(item["from"], "an arc's 'from'", item), self.ident(item["to"], "an arc's 'to'", item),
             item.get("weight", 1), line_of(item), item.get("id"), when)
        )

    def add_pending_arcs(self) -> None:
        for source, target, weight, line, arc_id, when in self.pending_arcs:
            element = f"{source} -> {target}"
            self.whole(weight, "arc weight", 1, line=line, element=element)
            nodes = list(self.net.places) + list(self.net.transitions)
            for end in (source, target):
                if end not in self.net.places and end not in self.net.transitions:
                    self.fail(f"arc to unknown node {end!r}{did_you_mean(end, nodes)}", line=line,
                              element=element)
            try:
                self.net.add_arc(source, target, weight, arc_id, outcome=when)
            except PetriflowError as exc:
                self.fail(str(exc), line=line, element=element)

    def read_marking(self, value: Any, what: str) -> dict[str, int]:
        if not isinstance(value, dict):
            self.fail(f"{what} must be a mapping place: tokens", value)
        marking: dict[str, int] = {}
        for key, count in value.items():
            place = self.ident(key, f"a place in the {what}", value)
            if place not in self.net.places:
                self.fail(f"{what} names unknown place {place!r}{did_you_mean(place, self.net.places)}", value)
            marking[place] = self.whole(count, f"{what}: tokens of {place!r}", 0, value,
                                        line=getattr(value, "key_lines", {}).get(key))
        return marking

    def ident(self, value: Any, what: str, item: Any, line: int | None = None) -> str:
        """An id as written: text, or a whole number taken as its decimal text (``1`` is
        ``'1'``). Anything else YAML reads as another type (``yes``, ``null``, ``1.50``,
        a date) is refused, since the text would not be what the file says."""
        if isinstance(value, str):
            if not value.strip():
                self.fail(f"{what} must be non-empty text, got {value!r}", item, line=line)
            if not value.isprintable():
                self.fail(f"{what} must be printable text (no control characters), got {value!r}", item, line=line)
            return value
        if isinstance(value, int) and not isinstance(value, bool):
            return str(value)
        shown = {True: "true", False: "false", None: "null"}.get(value, repr(value)) \
            if isinstance(value, (bool, type(None))) else repr(value)
        kind = {bool: "a boolean", type(None): "null", float: "a number"}.get(type(value), type(value).__name__)
        self.fail(f"{what} must be text; YAML reads this one as {kind} ({shown}): put it in quotes",
                  item, line=line)


def _exact(value: Any, what: str, fail) -> Any:
    """Plain data that JSON (and so PNML, journals and traces) keeps exactly: text keys,
    finite numbers; ``fail`` is told the first thing that is not."""
    import math

    value = plain(value)
    stack: list[tuple[Any, str]] = [(value, "")]
    while stack:
        item, where = stack.pop()
        if isinstance(item, dict):
            for key, inner in item.items():
                if not isinstance(key, str):
                    fail(f"{what}: key {key!r}{where and f' in {where}'} must be text (quote it)")
                stack.append((inner, f"{where}.{key}" if where else repr(key)))
        elif isinstance(item, list):
            stack.extend((inner, f"{where}[{i}]") for i, inner in enumerate(item))
        elif isinstance(item, float) and not math.isfinite(item):
            fail(f"{what}: {where or 'the value'} must be a finite number, got {item!r}")
        elif not (item is None or isinstance(item, (str, int, float, bool))):
            fail(f"{what}: {where or 'the value'} must be text, a number, a list or a mapping, "
                 f"got {type(item).__name__}")
    return value


def _text(value: Any, what: str, fail) -> str | None:
    """A label or name: text (a number is taken as its text); ``None`` when absent."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        fail(f"{what} must be text, got {value!r}")
    return str(value)


def _meta(value: Any, fail) -> dict[str, Any]:
    """Free-form ``meta`` data: a mapping with text keys (what PNML and JSON can keep)."""
    if value is None:
        return {}
    if not isinstance(value, dict):
        fail(f"'meta' must be a mapping, got {type(value).__name__}")

    def check(item: Any) -> None:
        if isinstance(item, dict):
            for key, inner in item.items():
                if not isinstance(key, str):
                    fail(f"'meta' keys must be text, got {key!r}")
                check(inner)
        elif isinstance(item, list):
            for inner in item:
                check(inner)

    check(value)
    return plain(value)


def loads_net(text: str, *, path: str | None = None, name: str | None = None) -> Net:
    """Read a net from YAML text.

    Args:
        text: the YAML document.
        path: the file it came from, named in errors.
        name: the net id to use when the file has no ``net:`` key.

    Raises:
        NetFormatError: malformed YAML or a net that breaks the format's rules.
    """
    default = name or (Path(path).stem if path else "net")
    try:
        with paused():  # no cycles among what is built (petriflow.collector)
            net = _Reader(parse_yaml(text), default).read()
        net.path = path
        return net
    except NetFormatError as exc:
        raise exc.at(path) if path else exc from None
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark else None
        problem = exc.problem or exc.context or "malformed YAML"
        raise NetFormatError(f"malformed YAML: {problem}", path=path, line=line) from None
    except yaml.YAMLError as exc:
        raise NetFormatError(f"malformed YAML: {yaml_problem(exc)}", path=path) from None


def load_yaml(path: str | Path) -> Net:
    """Read a net from a YAML file (see :func:`loads_net`)."""
    path = Path(path)
    return loads_net(read_text_file(path), path=str(path))


# Writing -----------------------------------------------------------------------------


def _transition_dict(net: Net, t: Transition, with_arcs: bool = True) -> dict[str, Any]:
    entry: dict[str, Any] = {"id": t.id}
    if t.label is not None:
        entry["label"] = t.label
    if t.action is not None:
        entry["action"] = t.action
    if t.params:
        entry["params"] = t.params
    if t.guard is not None:
        entry["guard"] = t.guard
    if t.priority:
        entry["priority"] = t.priority
    if t.silent:
        entry["silent"] = True
    if t.timeout is not None:
        entry["timeout"] = t.timeout
    if t.cancels:
        entry["cancels"] = list(t.cancels)
    if t.operator is not None:
        entry["operator"] = {k: v for k, v in vars(t.operator).items() if v is not None}
    if with_arcs:
        entry["in"] = _branches(net.preset(t.id))
        entry["out"] = _branches(net.postset(t.id))
        if net.outcomes(t.id):
            entry["outcomes"] = {o: _branches(net.postset(t.id, o)) for o in net.outcomes(t.id)}
    if t.meta:
        entry["meta"] = t.meta
    return entry


def _branches(weights: Mapping[str, int]) -> list[str] | dict[str, int]:
    if all(w == 1 for w in weights.values()):
        return list(weights)
    return dict(weights)


def _folded_operator(net: Net, group: str, parts: list[str]) -> dict[str, Any] | None:
    """The ``split``/``join`` form of an operator, if it rebuilds exactly ``parts``."""
    first = net.transitions[parts[0]]
    operator = first.operator
    assert operator is not None
    if any(net.outcomes(p) for p in parts):
        return None
    if any(
        net.transitions[p].operator != operator
        or _transition_dict(net, net.transitions[p], False) | {"id": ""}
        != _transition_dict(net, first, False) | {"id": ""}
        or net.transitions[p].subnet != first.subnet
        for p in parts
    ):
        return None
    inputs: dict[str, int] = {}
    outputs: dict[str, int] = {}
    for p in parts:
        inputs.update(net.preset(p))
        outputs.update(net.postset(p))
    trial = Net()
    for place in net.places:
        trial.add_place(place)
    try:
        made = add_operator(trial, group, inputs=inputs, outputs=outputs, split=operator.split,
                            join=operator.join)
    except PetriflowError:
        return None
    if sorted(made) != sorted(parts) or any(
        trial.preset(p) != net.preset(p) or trial.postset(p) != net.postset(p) for p in made
    ):
        return None
    entry = _transition_dict(net, first, False)
    del entry["operator"]
    entry["id"] = group
    if entry.get("label") == group:
        del entry["label"]
    if operator.join:
        entry["join"] = operator.join
    if operator.split:
        entry["split"] = operator.split
    entry["in"] = _branches(inputs)
    entry["out"] = _branches(outputs)
    return entry


def net_to_dict(net: Net) -> dict[str, Any]:
    """The YAML form of ``net`` as plain data (what :func:`dumps_net` writes)."""
    transitions_by_subnet: dict[str | None, list[dict[str, Any]]] = {}
    done: set[str] = set()
    groups = operator_groups(net)
    for t in net.transitions.values():
        if t.id in done:
            continue
        entry = None
        if t.operator is not None:
            parts = groups[t.operator.group]
            if t.operator.group not in net.places and (
                t.operator.group not in net.transitions or parts == [t.operator.group]
            ):
                entry = _folded_operator(net, t.operator.group, parts)
            if entry is not None:
                done.update(parts)
        if entry is None:
            entry = _transition_dict(net, t)
            done.add(t.id)
        transitions_by_subnet.setdefault(t.subnet, []).append(entry)

    def place_entry(place) -> dict[str, Any] | str:
        entry: dict[str, Any] = {"id": place.id}
        if place.label is not None:
            entry["label"] = place.label
        if net.initial_marking[place.id]:
            entry["tokens"] = net.initial_marking[place.id]
        if place.channel is not None:
            entry["channel"] = place.channel
        if place.meta:
            entry["meta"] = place.meta
        return entry if len(entry) > 1 else place.id

    data: dict[str, Any] = {"petriflow": FORMAT_VERSION, "net": net.id}
    if net.label is not None:
        data["label"] = net.label
    if net.subnets:
        data["subnets"] = []
        for subnet in net.subnets.values():
            entry: dict[str, Any] = {"id": subnet.id}
            if subnet.label is not None:
                entry["label"] = subnet.label
            if subnet.agent is not None:
                entry["agent"] = subnet.agent
            if subnet.state is not None:
                entry["state"] = subnet.state
            entry["places"] = [place_entry(p) for p in net.places.values() if p.subnet == subnet.id]
            entry["transitions"] = transitions_by_subnet.get(subnet.id, [])
            data["subnets"].append(entry)
    data["places"] = [place_entry(p) for p in net.places.values() if p.subnet is None]
    data["transitions"] = transitions_by_subnet.get(None, [])
    if net.final_marking is not None:
        data["final"] = net.final_marking.to_dict()
    if net.meta:
        data["meta"] = net.meta
    if net.run is not None:
        data["run"] = net.run
    if net.properties:
        from petriflow.properties.yaml_props import property_entry

        data["properties"] = [property_entry(p) for p in net.properties]
    return data


class _Dumper(yaml.SafeDumper):
    pass


def _represent_list(dumper: yaml.SafeDumper, value: list) -> yaml.Node:
    flow = all(isinstance(v, (str, int, float)) for v in value)
    return dumper.represent_sequence("tag:yaml.org,2002:seq", value, flow_style=flow)


def _represent_dict(dumper: yaml.SafeDumper, value: dict) -> yaml.Node:
    flow = len(value) <= 3 and all(isinstance(v, (str, int, float, bool)) for v in value.values())
    return dumper.represent_mapping("tag:yaml.org,2002:map", value.items(), flow_style=flow)


_Dumper.add_representer(dict, _represent_dict)
_Dumper.add_representer(list, _represent_list)
_Dumper.add_representer(tuple, _represent_list)


def dumps_net(net: Net) -> str:
    """The net as YAML text in petriflow's format."""
    return yaml.dump(net_to_dict(net), Dumper=_Dumper, sort_keys=False, allow_unicode=True,
                     default_flow_style=False, width=100)


def save_yaml(net: Net, path: str | Path) -> None:
    """Write ``net`` to ``path`` as YAML (atomically: a failed write leaves the old file)."""
    write_atomic(path, dumps_net(net))
