"""Workflow nets: AND/XOR operators as plain P/T structure, and the WF-net structure.

Workflow editors (WoPeD, YAWL) and nets drawn in their style draw operators such as an
AND-split or an XOR-join as one box. Their meaning is plain P/T structure:

* an AND side is one transition touching every branch place;
* an XOR side is one transition per branch place.

:func:`add_operator` builds that structure. Every transition it makes carries an
:class:`~petriflow.net.Operator` naming the group, so writers can fold it back.

A **WF-net** has one source place ``i``, one sink place ``o``, and every node on a path
from ``i`` to ``o``: :func:`workflow_structure` checks that, and :func:`final_marking_of`
names the marking a run of the net should end in.

Examples:
    >>> from petriflow.net import Net
    >>> net = Net()
    >>> for p in ("i", "a", "b"):
    ...     _ = net.add_place(p)
    >>> add_operator(net, "choose", inputs=["i"], outputs=["a", "b"], split="xor")
    ['choose_op_1', 'choose_op_2']
    >>> net.postset("choose_op_2")
    {'b': 1}
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping, Sequence

from petriflow.errors import NetStructureError
from petriflow.marking import Marking
from petriflow.net import OPERATOR_KINDS, Net, Operator

__all__ = ["add_operator", "operator_groups", "source_places", "sink_places", "final_marking_of",
           "WorkflowStructure", "workflow_structure"]


def _weights(branches: Sequence[str] | Mapping[str, int]) -> list[tuple[str, int]]:
    if isinstance(branches, Mapping):
        return [(p, int(w)) for p, w in branches.items()]
    return [(p, 1) for p in branches]


def add_operator(
    net: Net,
    id: str,
    *,
    inputs: Sequence[str] | Mapping[str, int],
    outputs: Sequence[str] | Mapping[str, int],
    split: str | None = None,
    join: str | None = None,
    **attributes: Any,
) -> list[str]:
    """Add a WF operator ``id`` and return the ids of the transitions it expands to.

    Args:
        net: the net to extend (the branch places must exist).
        id: the operator's id. With no XOR side this is the id of the one transition
            made; otherwise the parts are ``{id}_op_1``, ``{id}_op_2``, ...
        inputs: input places (a list, or ``{place: weight}``).
        outputs: output places (a list, or ``{place: weight}``).
        split: ``"and"`` or ``"xor"`` routing over ``outputs`` (``None`` = ``"and"``).
        join: ``"and"`` or ``"xor"`` routing over ``inputs`` (``None`` = ``"and"``).
        **attributes: fields of :class:`~petriflow.net.Transition` (action, params...)
            given to every part.

    Raises:
        NetStructureError: unknown kind, or an XOR side with no branch.
    """
    for side, kind in (("split", split), ("join", join)):
        if kind is not None and kind not in OPERATOR_KINDS:
            raise NetStructureError(
                f"operator {id!r}: {side} must be one of {', '.join(OPERATOR_KINDS)}, got {kind!r}"
            )
    ins, outs = _weights(inputs), _weights(outputs)
    in_groups = [[b] for b in ins] if join == "xor" else [ins]
    out_groups = [[b] for b in outs] if split == "xor" else [outs]
    if (join == "xor" and not ins) or (split == "xor" and not outs):
        raise NetStructureError(f"operator {id!r}: an XOR side needs at least one branch")
    parts = [(i, o) for i in in_groups for o in out_groups]
    operator = Operator(id, split, join) if (split or join) else None
    attributes.setdefault("label", id)
    made = []
    for number, (in_part, out_part) in enumerate(parts, start=1):
        part_id = id if len(parts) == 1 else f"{id}_op_{number}"
        net.add_transition(part_id, operator=operator, **attributes)
        for place, weight in in_part:
            net.add_arc(place, part_id, weight)
        for place, weight in out_part:
            net.add_arc(part_id, place, weight)
        made.append(part_id)
    return made


def operator_groups(net: Net) -> dict[str, list[str]]:
    """``{operator id: [transition ids]}`` for every operator in ``net``."""
    groups: dict[str, list[str]] = {}
    for transition in net.transitions.values():
        if transition.operator is not None:
            groups.setdefault(transition.operator.group, []).append(transition.id)
    return groups


def source_places(net: Net) -> list[str]:
    """Places no transition puts tokens into (a WF-net has exactly one: ``i``)."""
    fed = {a.target for a in net.arcs if a.target in net.places}
    return [p for p in net.places if p not in fed]


def final_marking_of(net: Net) -> Marking | None:
    """The marking a run of ``net`` should end in, the one rule ``run`` and ``check`` share:
    the net's declared final marking, else, for a WF-net, one token in its sink place ``o``
    (WoPeD, PM4Py and ProM files often declare none); else ``None`` (the run simply ends
    when nothing is enabled).

    Examples:
        >>> from petriflow.io.yaml import loads_net
        >>> final_marking_of(loads_net("{petriflow: 1, places: [i, o], transitions: [{id: t, in: [i], out: [o]}]}"))
        Marking({'o': 1})
        >>> final_marking_of(loads_net("{petriflow: 1, places: [a], transitions: [{id: t, in: [a], out: [a]}]}"))
    """
    if net.final_marking is not None:
        return net.final_marking
    structure = workflow_structure(net)
    return Marking({structure.sink: 1}) if structure.is_wf_net else None


def sink_places(net: Net) -> list[str]:
    """Places no transition takes tokens from (a WF-net has exactly one: ``o``)."""
    drained = {a.source for a in net.arcs if a.source in net.places}
    return [p for p in net.places if p not in drained]


@dataclass
class WorkflowStructure:
    """The result of the WF-net structure check.

    Attributes:
        is_wf_net: whether the net is a WF-net.
        source: the source place ``i`` (``None`` unless there is exactly one).
        sink: the sink place ``o`` (``None`` unless there is exactly one).
        source_places: every place without an incoming arc.
        sink_places: every place without an outgoing arc.
        not_on_path: nodes not on any path from ``i`` to ``o``.
        problem: why the net is not a WF-net (``None`` when it is).
    """

    is_wf_net: bool
    source: str | None
    sink: str | None
    source_places: list[str]
    sink_places: list[str]
    not_on_path: list[str]
    problem: str | None


def workflow_structure(net: Net) -> WorkflowStructure:
    """Check the WF-net structure: one source place, one sink place, all nodes on a path.

    Examples:
        >>> from petriflow.io.yaml import loads_net
        >>> net = loads_net('''
        ... petriflow: 1
        ... places: [i, o, stray]
        ... transitions: [{id: t, in: [i], out: [o]}, {id: u, in: [stray], out: [stray]}]
        ... ''')
        >>> found = workflow_structure(net)
        >>> found.is_wf_net, found.not_on_path
        (False, ['stray', 'u'])
    """
    sources, sinks = source_places(net), sink_places(net)
    if len(sources) != 1 or len(sinks) != 1:
        problems = []
        if not sources:
            problems.append("no source place (every place has an incoming arc)")
        elif len(sources) > 1:
            problems.append(f"{len(sources)} source places: {', '.join(sources)}")
        if not sinks:
            problems.append("no sink place (every place has an outgoing arc)")
        elif len(sinks) > 1:
            problems.append(f"{len(sinks)} sink places: {', '.join(sinks)}")
        return WorkflowStructure(False, sources[0] if len(sources) == 1 else None,
                                 sinks[0] if len(sinks) == 1 else None, sources, sinks, [],
                                 "; ".join(problems))
    source, sink = sources[0], sinks[0]
    if source == sink:
        return WorkflowStructure(False, source, sink, sources, sinks, [],
                                 f"place {source!r} is both the source and the sink")
    forward: dict[str, list[str]] = {node: [] for node in net}
    backward: dict[str, list[str]] = {node: [] for node in net}
    for arc in net.arcs:
        forward[arc.source].append(arc.target)
        backward[arc.target].append(arc.source)

    def closure(start: str, edges: dict[str, list[str]]) -> set[str]:
        seen, todo = {start}, [start]
        while todo:
            for nxt in edges[todo.pop()]:
                if nxt not in seen:
                    seen.add(nxt)
                    todo.append(nxt)
        return seen

    on_path = closure(source, forward) & closure(sink, backward)
    missing = [node for node in net if node not in on_path]
    problem = None
    if missing:
        shown = ", ".join(missing[:10]) + (" ..." if len(missing) > 10 else "")
        problem = f"{len(missing)} nodes are not on a path from {source!r} to {sink!r}: {shown}"
    return WorkflowStructure(not missing, source, sink, sources, sinks, missing, problem)
