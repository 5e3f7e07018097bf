"""Karp–Miller coverability graph: boundedness and unbounded places for any P/T net.

The reachability graph of an unbounded net is infinite. The coverability graph folds
it into a finite graph by writing ω ("as many tokens as you like") for a place as soon
as a marking strictly covers one of its ancestors: the firing sequence between the two
can be repeated to pump those places without bound.

Nodes are ω-markings (tuples of counts, :data:`OMEGA` for ω). The graph built here
merges nodes with equal ω-markings (a *coverability graph*, not a tree); every
reachable marking is covered by some node, and every node is the limit of reachable
markings, so:

* a place is unbounded exactly when some node has ω in it;
* a transition is dead (never enabled) exactly when no node enables it.

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> net = loads_net('''
    ... petriflow: 1
    ... places: [{id: idle, tokens: 1}, mailbox]
    ... transitions:
    ...   - {id: send, in: [idle], out: [idle, mailbox]}
    ...   - {id: read, in: [mailbox], out: []}
    ... ''')
    >>> graph = coverability_graph(net)
    >>> graph.unbounded_places, graph.bounded
    (['mailbox'], False)
    >>> [graph.format_marking(m) for m in graph.markings]
    ['idle=1', 'idle=1, mailbox=ω']
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass

from petriflow.analysis.reachability import DEFAULT_MAX_STATES, StateSpaceLimit
from petriflow.engine import CompiledNet
from petriflow.errors import PetriflowError
from petriflow.net import Net

__all__ = ["OMEGA", "CoverabilityGraph", "coverability_graph", "coverability_graph_if_any",
           "unbounded_places"]

#: The ω of an ω-marking: more tokens than any bound (compares above every integer).
OMEGA = float("inf")


@dataclass
class CoverabilityGraph:
    """A Karp–Miller coverability graph.

    Attributes:
        places: place ids, the positions of every ω-marking.
        transitions: row ids of the compiled net (transitions and ``t@failed``-style
            outcome variants), indexed by the edges.
        markings: node ω-markings (tuples of ints and :data:`OMEGA`); node 0 is the start.
        edges: ``(source node, transition index, target node)`` triples.
        parent: per node, the node it was first reached from (-1 for node 0).
        parent_transition: per node, the transition index of that edge (-1 for node 0).
    """

    places: tuple[str, ...]
    transitions: tuple[str, ...]
    markings: list[tuple]
    edges: list[tuple[int, int, int]]
    parent: list[int]
    parent_transition: list[int]
    origins: tuple[str, ...] = ()

    @property
    def unbounded_places(self) -> list[str]:
        """Places with ω in some node: exactly the unbounded places, in net order."""
        return [p for j, p in enumerate(self.places)
                if any(m[j] == OMEGA for m in self.markings)]

    @property
    def bounded(self) -> bool:
        """Whether no node has an ω (then this graph is the reachability graph)."""
        return not self.unbounded_places

    def place_bounds(self) -> dict[str, int | None]:
        """Per place the largest count over the nodes, ``None`` for an unbounded place."""
        bounds: dict[str, int | None] = {}
        for j, place in enumerate(self.places):
            top = max((m[j] for m in self.markings), default=0)
            bounds[place] = None if top == OMEGA else int(top)
        return bounds

    def dead_transitions(self) -> list[str]:
        """Transitions enabled in no reachable marking (no edge of the graph fires them)."""
        fired = {t for _, t, _ in self.edges}
        origins = self.origins or self.transitions
        return list(dict.fromkeys(origins[t] for t in range(len(self.transitions)) if t not in fired))

    def path(self, node: int) -> list[str]:
        """A firing sequence from the start to a marking that agrees with ``node`` on its
        finite places (ω places: the pumping sequences are left out)."""
        sequence = []
        while node > 0:
            sequence.append(self.transitions[self.parent_transition[node]])
            node = self.parent[node]
        return sequence[::-1]

    def format_marking(self, marking: tuple) -> str:
        """``"p=1, q=ω"`` (places holding no token left out)."""
        shown = [f"{p}={'ω' if c == OMEGA else int(c)}" for p, c in zip(self.places, marking) if c]
        return ", ".join(shown) or "(empty)"


def coverability_graph(
    net: Net,
    marking: Mapping[str, int] | None = None,
    *,
    max_nodes: int = DEFAULT_MAX_STATES,
    compiled: CompiledNet | None = None,
) -> CoverabilityGraph:
    """Build the Karp–Miller coverability graph (breadth first).

    A new ω-marking ``M'`` reached from node ``n`` is compared with every node on the
    tree path from the start to ``n``; if it strictly covers one, the places where it
    is larger become ω. This is repeated until nothing changes (a new ω may make ``M'``
    cover another ancestor).

    Args:
        net: the net.
        marking: the start marking (default: the net's initial marking).
        max_nodes: stop with :class:`~petriflow.analysis.reachability.StateSpaceLimit`
            beyond this many nodes (the graph of a bounded net is its whole
            reachability graph, which can be large).
        compiled: a :class:`~petriflow.engine.CompiledNet` of ``net`` to reuse.

    Raises:
        StateSpaceLimit: more than ``max_nodes`` nodes.
        PetriflowError: the net has cancellation regions (reset arcs); Karp–Miller
            acceleration is unsound for them.
    """
    compiled = compiled or CompiledNet(net)
    if getattr(compiled, "has_resets", False):
        raise PetriflowError("the Karp-Miller coverability graph does not apply to nets with"
                             " cancellation regions (reset arcs)")
    start_marking = net.initial_marking if marking is None else net.check_marking(marking)
    start = tuple(compiled.vector(start_marking))
    moves = []
    for t in range(len(compiled.transitions)):
        change: dict[int, int] = {}
        for p, w in compiled.pre[t]:
            change[p] = change.get(p, 0) - w
        for p, w in compiled.post[t]:
            change[p] = change.get(p, 0) + w
        moves.append((t, compiled.pre[t], tuple((p, d) for p, d in change.items() if d)))
    markings = [start]
    index = {start: 0}
    parent, parent_t = [-1], [-1]
    edges: list[tuple[int, int, int]] = []
    queue = deque([0])
    while queue:
        node = queue.popleft()
        current = markings[node]
        for t, pre, change in moves:
            if any(current[p] < w for p, w in pre):
                continue
            successor = list(current)
            for p, d in change:
                successor[p] += d          # OMEGA + d stays OMEGA
            successor = _accelerate(successor, node, markings, parent)
            key = tuple(successor)
            target = index.get(key)
            if target is None:
                target = len(markings)
                if target + 1 > max_nodes:
                    raise StateSpaceLimit(max_nodes, target, node)
                index[key] = target
                markings.append(key)
                parent.append(node)
                parent_t.append(t)
                queue.append(target)
            edges.append((node, t, target))
    origin = getattr(compiled, "origin", None)
    origins = tuple(o[0] for o in origin) if origin else tuple(compiled.transitions)
    return CoverabilityGraph(tuple(compiled.places), tuple(compiled.transitions), markings,
                             edges, parent, parent_t, origins)


def _accelerate(successor: list, node: int, markings: list[tuple], parent: list[int]) -> list:
    """Put ω where ``successor`` strictly exceeds an ancestor it covers, until stable."""
    changed = True
    while changed:
        changed = False
        ancestor = node
        while ancestor >= 0:
            older = markings[ancestor]
            if all(a >= b for a, b in zip(successor, older)) and any(
                    a > b for a, b in zip(successor, older)):
                for p, (a, b) in enumerate(zip(successor, older)):
                    if a > b and a != OMEGA:
                        successor[p] = OMEGA
                        changed = True
            ancestor = parent[ancestor]
    return successor


def coverability_graph_if_any(net: Net, marking: Mapping[str, int] | None = None, *,
                              max_nodes: int = DEFAULT_MAX_STATES,
                              compiled: CompiledNet | None = None) -> CoverabilityGraph | None:
    """The Karp–Miller graph, or ``None`` where it does not apply (cancellation regions)
    or has more than ``max_nodes`` nodes: for reports that fall back to a witness."""
    compiled = compiled or CompiledNet(net)
    if getattr(compiled, "has_resets", False):
        return None
    try:
        return coverability_graph(net, marking, max_nodes=max_nodes, compiled=compiled)
    except StateSpaceLimit:
        return None


def unbounded_places(
    net: Net, marking: Mapping[str, int] | None = None, *, max_nodes: int = DEFAULT_MAX_STATES
) -> list[str]:
    """Ids of the places that can hold arbitrarily many tokens (empty for a bounded net).

    Raises:
        StateSpaceLimit: the coverability graph has more than ``max_nodes`` nodes.

    Examples:
        >>> from petriflow.classic import producer_consumer
        >>> unbounded_places(producer_consumer(2))
        []
    """
    return coverability_graph(net, marking, max_nodes=max_nodes).unbounded_places
