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

Two ways to build it:

* :func:`coverability_graph`: breadth first, in Python, every node and edge kept (the
  textbook graph, for small nets and for drawing);
* :func:`coverability_search`: depth first, compiled (:mod:`petriflow.analysis._karp_miller`),
  within a node budget, keeping only what decides boundedness: the unbounded places,
  a pumping witness (shortened), the transitions that fire, and, when it finishes, the
  dead transitions and bounds. ``petriflow check`` runs it before the state space.

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

from petriflow.analysis.exploration import (
    DEFAULT_MAX_STATES,
    StateSpaceLimit,
    UnboundedNetError,
    row_changes,
    row_origins,
)
from petriflow.engine import CompiledNet
from petriflow.errors import PetriflowError
from petriflow.net import Net

__all__ = ["DEFAULT_MAX_COVERABILITY", "OMEGA", "CoverabilityGraph", "CoverabilitySearch",
           "coverability_graph", "coverability_graph_if_any", "coverability_search",
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
        max_nodes: stop with :class:`~petriflow.analysis.exploration.StateSpaceLimit`
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
    return CoverabilityGraph(tuple(compiled.places), tuple(compiled.transitions), markings,
                             edges, parent, parent_t, row_origins(compiled))


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


#: Default node budget of :func:`coverability_search` (``petriflow check --max-coverability``).
DEFAULT_MAX_COVERABILITY = 100_000


@dataclass
class CoverabilitySearch:
    """What a budgeted Karp–Miller search (:func:`coverability_search`) established.

    Attributes:
        complete: the search finished: its nodes form a coverability graph, so
            ``unbounded_places`` are exactly the unbounded places, ``dead_transitions``
            exactly the dead ones and ``place_bounds`` the bounds.
        nodes, edges: the graph's size when the search stopped.
        unbounded_places: places with ω in some node: unbounded, all of them when
            ``complete``, at least these otherwise.
        witness: an :class:`~petriflow.analysis.exploration.UnboundedNetError` built
            from the first pump found (a plain firing sequence and the pump that can be
            repeated), ``None`` when none was found.
        dead_transitions: transitions no node enables (``None`` unless ``complete``).
        fired: transitions some node enables (never dead).
        place_bounds: per place the most tokens (``None`` for ω), when ``complete``.
        stopped: why an incomplete search stopped (``"budget"`` or ``"overflow"``).
    """

    complete: bool
    nodes: int
    edges: int
    unbounded_places: list[str]
    witness: object | None
    dead_transitions: list[str] | None
    fired: list[str]
    place_bounds: dict[str, int | None] | None
    stopped: str | None = None

    @property
    def bounded(self) -> bool | None:
        """``True`` (complete, no ω), ``False`` (some ω), ``None`` (not decided)."""
        if self.unbounded_places:
            return False
        return True if self.complete else None


def coverability_search(
    net: Net,
    marking: Mapping[str, int] | None = None,
    *,
    max_nodes: int = DEFAULT_MAX_COVERABILITY,
    compiled: CompiledNet | None = None,
    max_cells: int = 25_000_000,
) -> CoverabilitySearch:
    """A Karp–Miller coverability graph searched depth first, compiled, within a budget.

    Meant to decide boundedness before (and instead of) a full state space: it stops
    after ``max_nodes`` nodes and says what it proved by then. Depth first, a pump far
    from the start is found without enumerating the markings closer to it; ω-markings
    fold the unbounded places, so the graph of an unbounded net is finite too.

    Args:
        net: the net (without reset arcs: Karp–Miller acceleration is unsound for them).
        marking: the start marking (default: the net's initial marking).
        max_nodes: the node budget (memory: 8 bytes a place a node, plus about 50).
        compiled: a :class:`~petriflow.engine.CompiledNet` of ``net`` to reuse.
        max_cells: the most node-place entries to hold (200 MB at the default): on nets
            with many places the node budget shrinks to fit.

    Raises:
        PetriflowError: the net has cancellation regions (reset arcs).

    Examples:
        >>> from petriflow.io.yaml import loads_net
        >>> net = loads_net('''
        ... petriflow: 1
        ... places: [{id: idle, tokens: 1}, mailbox]
        ... transitions:
        ...   - {id: send, in: [idle], out: [idle, mailbox]}
        ...   - {id: read, in: [mailbox], out: []}
        ... ''')
        >>> found = coverability_search(net)
        >>> found.complete, found.unbounded_places, found.witness.pump
        (True, ['mailbox'], ['send'])
    """
    import numpy as np

    from petriflow.analysis import _karp_miller as km
    from petriflow.analysis import _kernel

    compiled = compiled or CompiledNet(net)
    if getattr(compiled, "has_resets", False):
        raise PetriflowError("the Karp-Miller coverability graph does not apply to nets with"
                             " cancellation regions (reset arcs)")
    if max_nodes < 1:
        raise ValueError(f"max_nodes must be >= 1, got {max_nodes}")
    start_marking = net.initial_marking if marking is None else net.check_marking(marking)
    start = np.asarray(compiled.vector(start_marking), dtype=np.int64)
    n_p, n_t = len(compiled.places), len(compiled.transitions)
    max_nodes = max(1, min(max_nodes, max_cells // max(1, n_p)))

    def csr(lists):
        at = np.zeros(len(lists) + 1, dtype=np.int64)
        at[1:] = np.cumsum([len(items) for items in lists])
        flat = [item for items in lists for item in items]
        return (at, np.array([p for p, _ in flat], dtype=np.int64),
                np.array([w for _, w in flat], dtype=np.int64))

    fixed = (*csr(compiled.pre), *csr(row_changes(compiled)), max_nodes)
    size = min(1024, max_nodes + 1)
    per_node = [np.empty((size, n_p), dtype=np.int64)] + [
        np.empty(size, dtype=np.int64) for _ in range(7)]
    per_node[0][0] = start
    table = np.zeros(2 * 2 * 1024, dtype=np.uint64)
    fired = np.zeros(n_t, dtype=np.int8)
    counters = np.array([0, 0, 0, -1, -1, -1], dtype=np.int64)
    while True:
        rows, parent, parent_t, totals, seg_root, seg_min, stack, stack_next = per_node
        status = km.search(*fixed, rows, parent, parent_t, totals, seg_root, seg_min, table,
                           stack, stack_next, fired, counters)
        if status != km.FULL:
            break
        nodes = int(counters[0])
        if nodes >= len(rows):
            grown = []
            for a in per_node:
                bigger = np.empty((min(2 * len(a), max_nodes + 1),) + a.shape[1:], dtype=a.dtype)
                bigger[:len(a)] = a
                grown.append(bigger)
            per_node = grown
        slots = len(table) // 2
        if 2 * (nodes + 1) > slots // 2:
            bigger = np.zeros(4 * len(table), dtype=np.uint64)
            _kernel.rehash(table, 2, 0, bigger)
            table = bigger
    rows, parent, parent_t = per_node[0], per_node[1], per_node[2]
    nodes = int(counters[0])
    rows = rows[:nodes]
    omega = (rows == km.OMEGA).any(axis=0) if nodes else np.zeros(n_p, dtype=bool)
    places = [compiled.places[p] for p in np.flatnonzero(omega)]
    witness = None
    if counters[3] >= 0:
        node, ancestor, t = int(counters[3]), int(counters[4]), int(counters[5])

        def walk(s: int, stop: int) -> list[str]:
            sequence = []
            while s != stop:
                sequence.append(compiled.transitions[int(parent_t[s])])
                s = int(parent[s])
            return sequence[::-1]

        covered_row = rows[ancestor]
        covering_row = rows[node].copy()
        for p, d in row_changes(compiled)[t]:
            covering_row[p] += d
        prefix, pump = walk(ancestor, 0), walk(node, ancestor) + [compiled.transitions[t]]
        prefix, pump, covered_row, covering_row = _shorter(compiled, start, prefix, pump)
        grown = [compiled.places[p] for p in range(n_p) if covering_row[p] > covered_row[p]]
        witness = UnboundedNetError(grown, prefix, pump,
                                    compiled.marking([int(c) for c in covered_row]),
                                    compiled.marking([int(c) for c in covering_row]))
    complete = status == km.OK
    origin_of = row_origins(compiled)
    fired_names = list(dict.fromkeys(origin_of[t] for t in np.flatnonzero(fired)))
    dead = bounds = None
    if complete:
        dead = list(dict.fromkeys(origin_of[t] for t in range(n_t) if not fired[t]))
        dead = [d for d in dead if d not in set(fired_names)]
        top = rows.max(axis=0) if nodes else np.zeros(n_p, dtype=np.int64)
        bounds = {p: (None if omega[j] else int(top[j])) for j, p in enumerate(compiled.places)}
    return CoverabilitySearch(complete, nodes, int(counters[1]), places, witness, dead,
                              fired_names, bounds,
                              None if complete else ("budget" if status == km.LIMIT else "overflow"))


#: Entries :func:`_shorter` may compare while it shortens a witness (about 0.1 s of numpy).
_SHORTEN_WORK = 20_000_000


def _shorter(compiled: CompiledNet, start, prefix: list[str], pump: list[str]):
    """A shorter unboundedness witness: ``(prefix, pump, covered, covering)``.

    A depth-first search finds its pump at the end of a long, wandering path. Any prefix
    that ends where the pump can fire will do (the pump adds ``Δ >= 0``, ``Δ != 0``
    wherever it can fire), so firings are dropped from the prefix while the rest stays
    firable and ends in the same marking: each firing that changes nothing, and each
    pair of firings that undo each other (the wandering of a depth-first search through
    a bounded part is mostly such pairs), checked on the markings between the two only;
    then blocks of firings, halving the block size (delta debugging), while the pump
    can still fire at the end. All within a fixed amount of work.
    """
    import numpy as np

    index = {t: k for k, t in enumerate(compiled.transitions)}
    n_p, n_t = len(compiled.places), len(compiled.transitions)
    start = np.asarray(start, dtype=np.int64)
    if n_p * n_t > 4_000_000 or not prefix:   # too large for dense rows, or nothing to drop
        def fire(m, seq):
            m = m.copy()
            for t in seq:
                for p, w in compiled.pre[index[t]]:
                    m[p] -= w
                for p, w in compiled.post[index[t]]:
                    m[p] += w
            return m

        covered = fire(start, prefix)
        return prefix, pump, covered, fire(covered, pump)
    pre = np.zeros((n_t, n_p), dtype=np.int64)
    change = np.zeros((n_t, n_p), dtype=np.int64)
    for t in range(n_t):
        for p, w in compiled.pre[t]:
            pre[t, p] += w
            change[t, p] -= w
        for p, w in compiled.post[t]:
            change[t, p] += w
    budget = [_SHORTEN_WORK]

    def before(m, ids):
        """The marking before each firing of ``ids`` from ``m``."""
        budget[0] -= len(ids) * n_p
        steps = np.cumsum(change[ids], axis=0) if len(ids) else np.zeros((0, n_p), np.int64)
        return np.vstack([m[None, :], m + steps[:-1]]) if len(ids) else steps

    def firable(m, ids):
        return bool((before(m, ids) >= pre[ids]).all()) if len(ids) else True

    ids = np.array([index[t] for t in prefix], dtype=np.int64)
    pump_ids = np.array([index[t] for t in pump], dtype=np.int64)
    # Firings that change nothing.
    ids = ids[change[ids].any(axis=1)]
    # Pairs that undo each other, nearest first.
    changed = True
    while changed and budget[0] > 0:
        changed = False
        marks = before(start, ids)
        keys = [change[t].tobytes() for t in ids]
        undo = {}
        for k, t in enumerate(ids):
            undo.setdefault((-change[t]).tobytes(), []).append(k)
        k = 0
        keep = np.ones(len(ids), dtype=bool)
        while k < len(ids) and budget[0] > 0:
            if keep[k]:
                for j in undo.get(keys[k], ()):
                    if j <= k or not keep[j]:
                        continue
                    inner = np.flatnonzero(keep[k + 1:j]) + k + 1
                    budget[0] -= len(inner) * n_p
                    if (marks[inner] - change[ids[k]] >= pre[ids[inner]]).all():
                        keep[k] = keep[j] = False
                        marks[k + 1:j] -= change[ids[k]]
                        changed = True
                    break
            k += 1
        ids = ids[keep]
    end = start + change[ids].sum(axis=0)

    def pump_ok(m, seq):
        if not firable(m, seq):
            return False
        delta = change[seq].sum(axis=0)
        return bool((delta >= 0).all() and (delta > 0).any())

    def prefix_ok(seq):
        return firable(start, seq) and pump_ok(start + change[seq].sum(axis=0), pump_ids)

    def reduce(seq, good):
        block = max(1, len(seq) // 2)
        while block >= 1 and budget[0] > 0:
            k = 0
            while k < len(seq) and budget[0] > 0:
                candidate = np.concatenate([seq[:k], seq[k + block:]])
                if good(candidate):
                    seq = candidate
                else:
                    k += block
            block //= 2
        return seq

    pump_ids = reduce(pump_ids, lambda seq: pump_ok(end, seq))
    ids = reduce(ids, prefix_ok)
    covered = start + change[ids].sum(axis=0)
    covering = covered + change[pump_ids].sum(axis=0)
    names = compiled.transitions
    return [names[t] for t in ids], [names[t] for t in pump_ids], covered, covering
