"""Folded drawings of big nets: one box per agent, the places between agents as circles.

A team net (20 robots, each a subnet with its work loop and a mailbox) drawn node by node
is a hairball: thousands of arcs into a few hub places. Folded, each agent subnet is one
box naming the agent, its label, how many places and transitions it holds and the tokens
in them; a place stays a circle when it joins more than one agent or the envelope (a
mailbox other agents send into, a shared resource, the net's source and sink);
transitions outside every subnet stay as they are. Arcs between the same two nodes are
drawn once, with how many they stand for beside them; the flow between agents is kept
(a mailbox every agent sends into keeps its senders' arcs, or, in a net where that would
be hundreds of arcs, one arc from a dashed "N agents" node that bundles them, see
:func:`_arcs`), so no node loses its incoming arc. An arc that only stands for output arcs
of a failed, timed-out or cancelled action is drawn dashed and named like them.

:func:`folded_dot` makes the DOT text; ``petriflow export NET -o net.png --fold`` draws
it, and :func:`should_fold` says when ``export`` folds without being asked (a net of more
than :data:`FOLD_ABOVE` nodes that has agent subnets). Layout stays Graphviz's ``dot``:
folding is what removes the hairball, and ``dot`` lays out the folded graph (tens of
nodes) cleanly.

Examples:
    >>> from petriflow.net import Net
    >>> net = Net("team")
    >>> for r in ("r1", "r2"):
    ...     _ = net.add_subnet(r, agent=r)
    ...     _ = net.add_place(f"{r}_idle", tokens=1, subnet=r)
    ...     _ = net.add_transition(f"{r}_send", subnet=r)
    ...     _ = net.add_arc(f"{r}_idle", f"{r}_send"); _ = net.add_arc(f"{r}_send", f"{r}_idle")
    >>> _ = net.add_place("box", subnet="r2", channel="radio")
    >>> _ = net.add_arc("r1_send", "box"); _ = net.add_transition("r2_take", subnet="r2")
    >>> _ = net.add_arc("box", "r2_take")
    >>> source = folded_dot(net)
    >>> '"agent:r1" -> "box"' in source, '"box" -> "agent:r2"' in source, '"r1_idle"' in source
    (True, True, False)
"""

from __future__ import annotations

import math
from collections import Counter
from typing import Mapping

from petriflow.dot import CLUSTER_COLOURS, FONT, arc_look, attributes, html_text, quote, tokens_text
from petriflow.net import Net

__all__ = ["folded_dot", "should_fold", "agent_net", "FOLD_ABOVE", "FAN", "FAN_ARCS", "CROWD"]

#: ``export`` folds a picture without being asked when the net has more nodes than this
#: and at least two agent subnets.
FOLD_ABOVE = 150
#: Arcs between one node and this many agents or more are drawn as a note, not arcs.
FAN = 4


def should_fold(net: Net) -> bool:
    """Whether a picture of ``net`` is folded by default (see :data:`FOLD_ABOVE`)."""
    return len(net.places) + len(net.transitions) > FOLD_ABOVE and len(net.subnets) >= 2


def agent_net(net: Net, subnet: str) -> Net:
    """One agent's part of ``net`` as a net of its own, to draw it in full beside the
    folded picture: the subnet's places and transitions, the places outside it that its
    transitions take from or put into (outside the subnet's cluster), and the arcs between
    them. Ids are those of ``net``, so a marking of ``net`` draws on it.

    Examples:
        >>> from petriflow.net import Net
        >>> net = Net("team")
        >>> _ = net.add_subnet("r1", agent="robot 1")
        >>> _ = net.add_place("idle", tokens=1, subnet="r1"); _ = net.add_place("box")
        >>> _ = net.add_transition("send", subnet="r1", action="radio.send")
        >>> _ = net.add_arc("idle", "send"); _ = net.add_arc("send", "box", outcome="failed")
        >>> part = agent_net(net, "r1")
        >>> sorted(part.places), part.places["box"].subnet, part.arc("send", "box", "failed") is not None
        (['box', 'idle'], None, True)
    """
    from dataclasses import fields

    if subnet not in net.subnets:
        from petriflow.errors import UnknownElementError

        raise UnknownElementError("subnet", subnet, list(net.subnets))
    spec = net.subnets[subnet]
    part = Net(net.id, f"{spec.agent or spec.id}: {spec.label or spec.id}")
    part.add_subnet(spec.id, label=spec.label, agent=spec.agent, state=spec.state)
    places, transitions = net.nodes_of(subnet)
    own = set(places) | set(transitions)
    touched = [p for arc in net.arcs for p in (arc.source, arc.target)
               if p in net.places and p not in own and ({arc.source, arc.target} & set(transitions))]
    for place in [*places, *dict.fromkeys(touched)]:
        p = net.places[place]
        part.add_place(p.id, tokens=net.initial_marking[p.id], label=p.label,
                       subnet=subnet if p.id in own else None, channel=p.channel)
    for transition in transitions:
        t = net.transitions[transition]
        copied = {f.name: getattr(t, f.name) for f in fields(t) if f.name not in ("id", "meta")}
        part.add_transition(t.id, **copied)
    for arc in net.arcs:
        if arc.source in part.places or arc.source in part.transitions:
            if arc.target in part.places or arc.target in part.transitions:
                part.add_arc(arc.source, arc.target, weight=arc.weight, outcome=arc.outcome)
    return part


def _groups(net: Net) -> tuple[dict[str, str], set[str]]:
    """``({node: drawn node}, kept places)``: what each node is drawn as."""
    owner: dict[str, str] = {}
    for t in net.transitions.values():
        owner[t.id] = f"agent:{t.subnet}" if t.subnet is not None else t.id
    neighbours: dict[str, set[str]] = {p: set() for p in net.places}
    for arc in net.arcs:
        place, transition = (arc.source, arc.target) if arc.source in net.places else (arc.target, arc.source)
        neighbours[place].add(owner[transition])
    kept = set()
    for p in net.places.values():
        home = f"agent:{p.subnet}" if p.subnet is not None else None
        if home is None or (p.channel is not None and neighbours[p.id] - {home}):
            kept.add(p.id)
            owner[p.id] = p.id
        else:
            owner[p.id] = home
    return owner, kept


#: Fan arcs (an agent box to or from a place many agents share) drawn one by one in a
#: folded picture, at most; the fans beyond go through one "the agents" node instead.
FAN_ARCS = 60
#: Id of the node that stands for many agents at once in a folded drawing.
CROWD = "crowd:agents"


def _arcs(net: Net, owner: dict[str, str]) -> tuple[Counter, set[tuple[str, str]], dict[str, str], int]:
    """The folded arcs ``{(source, target): arcs folded into it}``, the pairs drawn as one
    two-way arc, the notes of the fans, and how many agents the crowd node stands for
    (0: none drawn).

    Nothing loses its flow. A place that :data:`FAN` or more agents send into (or take
    from) gets a note ("from N agents"); its fan is drawn as one arc per agent (an agent
    that both sends and takes: one two-way arc) when all the fans together stay under
    :data:`FAN_ARCS`; otherwise each fan is one arc from (or to) the :data:`CROWD` node,
    labelled with how many agents it stands for. Two agent boxes
    joined by an arc keep it, labelled with the count, except between two agents that are
    bundled: an agent coupled to :data:`FAN` or more others, or to more than one agent
    and one of them such a hub, gets one two-way arc to the crowd node, labelled with how
    many agents it is coupled to, instead of an arc to each of them."""
    arcs: Counter[tuple[str, str]] = Counter()
    for arc in net.arcs:
        source, target = owner[arc.source], owner[arc.target]
        if source != target:
            arcs[source, target] += 1
    agent = lambda node: node.startswith("agent:")  # noqa: E731
    notes: dict[str, list[str]] = {}
    fans: dict[str, tuple[set[str], set[str]]] = {}
    for node in sorted({n for pair in arcs for n in pair if not agent(n)}):
        senders = {pair[0] for pair in arcs if pair[1] == node and agent(pair[0])}
        takers = {pair[1] for pair in arcs if pair[0] == node and agent(pair[1])}
        if len(senders) >= FAN:
            notes.setdefault(node, []).append(f"from {len(senders)} agents")
        if len(takers) >= FAN:
            notes.setdefault(node, []).append(f"to {len(takers)} agents")
        if len(senders) >= FAN or len(takers) >= FAN:
            fans[node] = (senders if len(senders) >= FAN else set(), takers if len(takers) >= FAN else set())
    both: set[tuple[str, str]] = set()
    crowd: set[str] = set()
    one_by_one = sum(len(senders | takers) for senders, takers in fans.values()) <= FAN_ARCS
    for node, (senders, takers) in fans.items():
        if one_by_one:
            for box in senders & takers:
                arcs[box, node] += arcs.pop((node, box))
                both.add((box, node))
            continue
        for side, boxes in ((0, senders), (1, takers)):
            if boxes:
                for box in boxes:
                    del arcs[(box, node) if side == 0 else (node, box)]
                arcs[(CROWD, node) if side == 0 else (node, CROWD)] += len(boxes)
                crowd |= boxes
    coupled: dict[str, set[str]] = {}
    for source, target in arcs:
        if agent(source) and agent(target):
            coupled.setdefault(source, set()).add(target)
            coupled.setdefault(target, set()).add(source)
    for node, others in coupled.items():
        if len(others) >= FAN:
            notes.setdefault(node, []).append(f"coupled to {len(others)} agents")
    bundled = {box for box, others in coupled.items()
               if len(others) >= FAN or (len(others) > 1 and any(len(coupled[o]) >= FAN for o in others))}
    for pair in [p for p in arcs if p[0] in bundled and p[1] in bundled]:
        del arcs[pair]
    for box in bundled:
        arcs[box, CROWD] = len(coupled[box])
        both.add((box, CROWD))
        crowd.add(box)
    return arcs, both, {node: ", ".join(words) for node, words in notes.items()}, len(crowd)


def _outcomes(net: Net, owner: dict[str, str]) -> dict[tuple[str, str], str]:
    """The folded arcs that only stand for output arcs of one routed outcome (``failed``,
    ...): drawn like them (:func:`petriflow.dot.arc_look`)."""
    seen: dict[tuple[str, str], set[str | None]] = {}
    for arc in net.arcs:
        pair = owner[arc.source], owner[arc.target]
        if pair[0] != pair[1]:
            seen.setdefault(pair, set()).add(arc.outcome)
    return {pair: next(iter(kinds)) for pair, kinds in seen.items() if len(kinds) == 1 and None not in kinds}


def _xlabel(name: str, note: str | None) -> str:
    """The small text beside a kept place: its name and its note."""
    text = html_text(name) + (f"<BR/><I>{html_text(note)}</I>" if note else "")
    return f'<FONT POINT-SIZE="8">{text}</FONT>'


def _components(net: Net, owner: dict[str, str], arcs: Counter) -> int:
    """How many pieces the folded drawing falls into (Graphviz packs them in a grid:
    with about three times as many rows as columns left to right, where the pieces are
    wide, and the other way top to bottom)."""
    # a union-find over the boxes (networkx would cost a live page a third of a second to import)
    parent = {n: n for n in set(owner.values()) | {n for pair in arcs for n in pair}}

    def root(n: str) -> str:
        while parent[n] != n:
            parent[n] = parent[parent[n]]
            n = parent[n]
        return n

    for a, b in arcs:
        parent[root(a)] = root(b)
    return sum(1 for n in parent if parent[n] == n)


def folded_dot(net: Net, marking: Mapping[str, int] | None = None, *, title: str | None = None,
               rankdir: str = "LR") -> str:
    """Graphviz DOT text of ``net`` folded (see the module)."""
    marking = net.initial_marking if marking is None else net.check_marking(marking)
    owner, kept = _groups(net)
    arcs, both, notes, crowd = _arcs(net, owner)
    outcomes = _outcomes(net, owner)
    title = (net.label or net.id) if title is None else title
    out = [f"digraph {quote(net.id)} {{"]
    label = f' label=<<B>{html_text(title)}</B><BR/><FONT POINT-SIZE="10">folded: one box per agent' \
            f'</FONT>>, labelloc=t,' if title else ""
    pieces = _components(net, owner, arcs)
    columns = max(1, round(math.sqrt(pieces / 3 if rankdir == "LR" else pieces * 1.5)))
    out.append(f'  graph [rankdir={rankdir}, nodesep=0.25, ranksep=0.6,{label}'
               f' fontname="{FONT}", fontsize=14, pad=0.2, pack=true, packmode="array_u{columns}"];')
    out.append(f'  node [fontname="{FONT}", fontsize=10];')
    out.append(f'  edge [fontname="{FONT}", fontsize=9, arrowsize=0.6, penwidth=0.9, color="#555555"];')
    for number, subnet in enumerate(net.subnets.values()):
        fill, border = CLUSTER_COLOURS[number % len(CLUSTER_COLOURS)]
        places, transitions = net.nodes_of(subnet.id)
        inside = [p for p in places if p not in kept]
        tokens = sum(marking[p] for p in inside)
        name = subnet.agent or subnet.id
        text = f"<B>{html_text(name)}</B>"
        if subnet.label and subnet.label != name:
            text += f'<BR/><FONT POINT-SIZE="9">{html_text(subnet.label)}</FONT>'
        text += (f'<BR/><FONT POINT-SIZE="8">{len(inside)} places, {len(transitions)} transitions'
                 f'{f", {tokens} token" + ("s" if tokens != 1 else "") if tokens else ""}</FONT>')
        if f"agent:{subnet.id}" in notes:
            text += f'<BR/><FONT POINT-SIZE="8"><I>{html_text(notes[f"agent:{subnet.id}"])}</I></FONT>'

        out.append(f'  {quote("agent:" + subnet.id)} [shape=box, style="rounded,filled", fillcolor="{fill}",'
                   f' color="{border}", penwidth=1.4, label=<{text}>];')
    for p in net.places.values():
        if p.id in kept:
            count = marking[p.id]
            inner = tokens_text(count) if count else ""
            out.append(f'  {quote(p.id)} [shape=circle, fixedsize=true, width=0.3, height=0.3,'
                       f' label=<{inner}>, xlabel=<{_xlabel(p.label or p.id, notes.get(p.id))}>];')
    for t in net.transitions.values():
        if t.subnet is None:
            note = (f'<BR/><FONT POINT-SIZE="8"><I>{html_text(notes[t.id])}</I></FONT>'
                    if t.id in notes else "")
            out.append(f'  {quote(t.id)} [shape=box, style="filled", fillcolor="#dfe6ee", height=0.3,'
                       f' label=<<B>{html_text(t.label or t.id)}</B>{note}>];')
    if crowd:
        out.append(f'  {quote(CROWD)} [shape=box, style="rounded,dashed", color="#555555", height=0.3,'
                   f' label=<<I>{crowd} agents</I><BR/><FONT POINT-SIZE="8">(arcs of many agents,'
                   f' bundled)</FONT>>];')
    for (source, target), count in arcs.items():
        attrs = {"xlabel": f'"{count}"'} if count > 1 else {}
        if (source, target) in both:
            attrs["dir"] = "both"
        outcome = outcomes.get((source, target))
        if outcome is not None:
            attrs.update(arc_look(outcome, count))
        out.append(f"  {quote(source)} -> {quote(target)}{' ' + attributes(attrs) if attrs else ''};")
    out.append("}")
    return "\n".join(out) + "\n"
