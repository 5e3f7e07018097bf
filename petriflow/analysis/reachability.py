"""Explicit state-space exploration of bounded nets: the reachability graph.

:func:`reachability_graph` explores every marking reachable from the initial one,
breadth first, and returns a :class:`StateSpace`: the markings as a 2-D array of counts
(one row per state, columns in :class:`~petriflow.engine.CompiledNet` place order), the
edges as three arrays (source state, transition index, target state) and, per state,
the edge it was first reached by, so that a shortest firing sequence from the initial
marking to any state can be rebuilt (:meth:`StateSpace.path`).

How it is fast: the breadth-first search runs compiled by numba
(:mod:`petriflow.analysis._kernel`), over the ids of the states found so far (the BFS
queue is a range of ids), with no Python code per state.

* **Safe nets as bitmasks.** While every marking is safe, a marking is a row of
  ``uint64`` words, one bit a place; ``t`` is enabled when ``m & pre[t] == pre[t]`` and
  fires as ``(m & keep[t]) | post[t]``. A firing that would put a second token in a
  place makes the exploration start again with count rows.
* **Other bounded nets as count rows** of small unsigned integers (uint8, widened to
  uint16, uint32, uint64, and the search started again, when a count outgrows them).
* **Compact, exact keys.** Every reachable marking is ``M0 + x·C`` (C the incidence
  matrix), so it is fixed by its counts on the places whose incidence columns form a
  basis of C's column space (computed exactly; 30 of the 90 places of 30 philosophers).
  On large nets those places come first in the row and only they are hashed and
  compared. A safe key that fits in one word beside the state id is stored as that one
  word in the open-addressing hash table; otherwise a slot is a (64-bit hash, id) pair
  and a hash match is confirmed on the key columns, so collisions cost time, never
  correctness.
* **Memory latency overlapped.** The slots of all successors of a state are prefetched
  before the first is probed. Buffers double while small; large ones move once to
  reserved mappings that the system commits page by page (no copies after that).

Reset arcs (a transition's cancellation region) are honoured by both loops: the
successor empties those places; keys are then whole markings.

Unbounded nets: the bitmask loop cannot run forever (at most 2^|P| states); on count
rows, each new state is compared with the states on its BFS-tree path from M0. A
marking that strictly covers an ancestor proves the net unbounded (the firing sequence
between them can be repeated forever) and, by Dickson's lemma and König's lemma, some
state of an unbounded net's BFS tree always does, so the check finds every unbounded
P/T net in finite time. It raises :class:`UnboundedNetError` with both firing
sequences. Only states whose token total exceeds the smallest total on their path are
compared, so conservative nets pay nothing. With reset arcs a covering marking only
counts when some strictly grown place is reset by no firing between the two (then
those firings still add the same tokens to it each time): a sound test, but an
unbounded reset net need not show such a pair, and may only be stopped by
``max_states``.

Examples:
    >>> from petriflow.classic import dining_philosophers
    >>> space = reachability_graph(dining_philosophers(5))
    >>> space.num_states, space.num_edges, space.safe
    (11, 30, True)
    >>> space.path(space.num_states - 1)
    ['take_2', 'take_4']
    >>> space.marking(0) == dining_philosophers(5).initial_marking
    True
"""

from __future__ import annotations

import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from petriflow import limits
from petriflow.analysis._linear import pivot_columns
from petriflow.analysis.exploration import (
    DEFAULT_MAX_STATES,
    StateSpaceLimit,
    UnboundedNetError,
    row_changes,
    row_origins,
    row_resets,
)
from petriflow.engine import CompiledNet
from petriflow.errors import PetriflowError
from petriflow.marking import Marking
from petriflow.net import Net

__all__ = [
    "DEFAULT_MAX_STATES",
    "StateSpace",
    "StateSpaceLimit",
    "UnboundedNetError",
    "reachability_graph",
    "to_networkx",
]

@dataclass(eq=False)
class StateSpace:
    """The reachability graph of a bounded net, as numpy arrays.

    States are numbered ``0 .. num_states - 1`` in breadth-first order; state 0 is the
    initial marking, so state ids never decrease with the distance from it. Edges are
    in exploration order: by source state, then by transition index, so the graph is
    held in compressed-row form: state ``s``'s edges are
    ``edge_offsets[s]:edge_offsets[s + 1]``.

    Attributes:
        places: place ids; column ``j`` of :attr:`markings` is ``places[j]``.
        transitions: the ids of the :class:`~petriflow.engine.CompiledNet` rows, which
            :attr:`edge_transition` indexes: transition ids, and ``t@failed``-style ids
            for the outcome variants of transitions with routed action outcomes.
        origins: per row, the id of the net transition it belongs to.
        edge_offsets: ``num_states + 1`` edge indices: where each state's edges start
            (and, last, the number of edges).
        edge_transition: index of the transition fired on each edge.
        edge_target: target state of each edge.
        parent: per state, the state it was first reached from (-1 for state 0).
        parent_transition: per state, the transition index of that edge (-1 for state 0).
        representation: ``"bitmask"`` (the exploration stayed safe) or ``"counts"``.
        expanded: ``None`` for a complete state space; for the part explored before a
            limit stopped the search (:attr:`StateSpaceLimit.partial`), the number of
            states, the first ones, whose edges are all there (the others have none
            yet: they are not deadlocks).

    :attr:`edge_source` (the source state of each edge) is expanded from
    ``edge_offsets`` on first use.
    """

    places: tuple[str, ...]
    transitions: tuple[str, ...]
    origins: tuple[str, ...]
    edge_offsets: np.ndarray
    edge_transition: np.ndarray
    edge_target: np.ndarray
    parent: np.ndarray
    parent_transition: np.ndarray
    representation: str
    _rows: np.ndarray = field(repr=False)
    _column_of_place: np.ndarray = field(repr=False)
    _markings: np.ndarray | None = field(default=None, repr=False)
    _edge_source: np.ndarray | None = field(default=None, repr=False)
    expanded: int | None = None

    # Sizes ----------------------------------------------------------------------------
    @property
    def num_states(self) -> int:
        """Number of reachable markings."""
        return int(self.parent.shape[0])

    @property
    def num_edges(self) -> int:
        """Number of (marking, fired transition) pairs: the MCC's ``TRANSITIONS``."""
        return int(self.edge_target.shape[0])

    def __len__(self) -> int:
        return self.num_states

    # Markings -------------------------------------------------------------------------
    @property
    def markings(self) -> np.ndarray:
        """``num_states x len(places)`` array of token counts (computed once, then cached)."""
        if self._markings is None:
            if self.representation == "bitmask":
                words = self._rows
                if sys.byteorder != "little":
                    words = words.astype("<u8")
                bits = np.unpackbits(np.ascontiguousarray(words).view(np.uint8), axis=1,
                                     bitorder="little")
                self._markings = np.ascontiguousarray(bits[:, self._column_of_place])
            else:
                self._markings = np.ascontiguousarray(self._rows[:, self._column_of_place])
        return self._markings

    def marking(self, state: int) -> Marking:
        """The :class:`~petriflow.marking.Marking` of one state."""
        if self._markings is not None:
            row = self._markings[state]
        elif self.representation == "bitmask":      # decode one row, not the whole array
            words = self._rows[state: state + 1].astype("<u8")
            row = np.unpackbits(words.view(np.uint8), bitorder="little")[self._column_of_place]
        else:
            row = self._rows[state][self._column_of_place]
        return Marking({self.places[j]: int(row[j]) for j in np.flatnonzero(row)})

    def index(self, marking: Mapping[str, int]) -> int | None:
        """The state id of ``marking``, or ``None`` when it is not reachable."""
        where = {p: j for j, p in enumerate(self.places)}
        vector = np.zeros(len(self.places), dtype=np.int64)
        for place, count in marking.items():
            if place not in where:
                return None
            vector[where[place]] = count
        if vector.max(initial=0) > np.iinfo(self.markings.dtype).max:
            return None
        hits = np.flatnonzero((self.markings == vector.astype(self.markings.dtype)).all(axis=1))
        return int(hits[0]) if hits.size else None

    def place_bounds(self) -> np.ndarray:
        """Per place (``places`` order), the largest count in any reachable marking."""
        if self.representation == "bitmask":
            ever = np.bitwise_or.reduce(self._rows, axis=0)
            bits = np.unpackbits(ever.astype("<u8").view(np.uint8), bitorder="little")
            return bits[self._column_of_place].astype(np.int64)
        return self._rows.max(axis=0).astype(np.int64)[self._column_of_place]

    @property
    def safe(self) -> bool:
        """Whether no reachable marking has two tokens in a place."""
        return self.representation == "bitmask" or int(self.place_bounds().max(initial=0)) <= 1

    @property
    def max_tokens_place(self) -> int:
        """Largest token count of one place in one reachable marking (MCC)."""
        return int(self.place_bounds().max(initial=0))

    @property
    def max_tokens_marking(self) -> int:
        """Largest total token count of a reachable marking (MCC)."""
        if self.representation == "bitmask":
            return int(np.bitwise_count(self._rows).sum(axis=1, dtype=np.int64).max())
        return int(self._rows.sum(axis=1, dtype=np.int64).max())

    # Graph ----------------------------------------------------------------------------
    @property
    def edge_source(self) -> np.ndarray:
        """Source state of each edge (expanded from :attr:`edge_offsets`, then cached)."""
        if self._edge_source is None:
            ids = np.arange(self.num_states, dtype=self.edge_target.dtype)
            self._edge_source = np.repeat(ids, self.out_degree())
        return self._edge_source

    def out_degree(self) -> np.ndarray:
        """Number of enabled transitions in each state."""
        return np.diff(self.edge_offsets)

    def successors(self, state: int) -> list[tuple[str, int]]:
        """``(transition id, target state)`` of every edge leaving ``state``, by transition."""
        edges = slice(self.edge_offsets[state], self.edge_offsets[state + 1])
        return [(self.transitions[t], int(s)) for t, s in
                zip(self.edge_transition[edges], self.edge_target[edges])]

    def deadlocks(self) -> np.ndarray:
        """Ids of the states that enable no transition, in increasing order.

        The first one is a deadlock nearest to the initial marking (BFS numbering). In a
        partial state space, only the expanded states are candidates.
        """
        dead = np.flatnonzero(self.edge_offsets[1:] == self.edge_offsets[:-1])
        return dead if self.expanded is None else dead[dead < self.expanded]

    @property
    def complete(self) -> bool:
        """Whether this is the whole reachability graph (not a partial one)."""
        return self.expanded is None

    def path(self, state: int) -> list[str]:
        """A shortest firing sequence (transition ids) from the initial marking to ``state``."""
        if not 0 <= state < self.num_states:
            raise IndexError(f"no state {state}; states are 0..{self.num_states - 1}")
        sequence = []
        while state > 0:
            sequence.append(self.transitions[int(self.parent_transition[state])])
            state = int(self.parent[state])
        sequence.reverse()
        return sequence

    def __repr__(self) -> str:
        return (f"<StateSpace: {self.num_states} states, {self.num_edges} edges,"
                f" {self.representation}>")


def to_networkx(space: StateSpace):
    """The reachability graph as a :class:`networkx.MultiDiGraph`.

    Nodes are state ids with a ``marking`` attribute (a :class:`Marking`); each edge is
    keyed by the id of the transition fired and has it as ``transition`` attribute too.
    Meant for small graphs: it builds Python objects for every state and edge.

    Examples:
        >>> from petriflow.classic import independent_cycles
        >>> graph = to_networkx(reachability_graph(independent_cycles(2)))
        >>> graph.number_of_nodes(), graph.number_of_edges()
        (4, 8)
        >>> sorted(graph[0][1])
        ['go_0']
    """
    import networkx as nx

    graph = nx.MultiDiGraph()
    for state in range(space.num_states):
        graph.add_node(state, marking=space.marking(state))
    names = space.transitions
    for source, t, target in zip(space.edge_source.tolist(), space.edge_transition.tolist(),
                                 space.edge_target.tolist()):
        graph.add_edge(source, target, key=names[t], transition=names[t])
    return graph


def reachability_graph(
    net: Net,
    marking: Mapping[str, int] | None = None,
    *,
    max_states: int = DEFAULT_MAX_STATES,
    detect_unbounded: bool = True,
    compiled: CompiledNet | None = None,
) -> StateSpace:
    """Explore every marking reachable from ``marking`` (default: the initial marking).

    Args:
        net: the net.
        marking: the start marking (state 0).
        max_states: stop with :class:`StateSpaceLimit` when more states than this are
            found; memory stays proportional to it.
        detect_unbounded: compare new states with their BFS-tree ancestors and raise
            :class:`UnboundedNetError` on a strictly covering marking. Turn it off only
            when boundedness is already known (it is free on conservative nets anyway).
        compiled: a :class:`~petriflow.engine.CompiledNet` of ``net`` to reuse.

    Returns:
        The :class:`StateSpace`.

    Raises:
        StateSpaceLimit: more than ``max_states`` reachable markings.
        UnboundedNetError: the net is unbounded (only with ``detect_unbounded``).

    Examples:
        >>> from petriflow.classic import producer_consumer
        >>> space = reachability_graph(producer_consumer(3))
        >>> space.num_states, space.safe, space.max_tokens_place
        (16, False, 3)
        >>> reachability_graph(producer_consumer(3), max_states=10)
        Traceback (most recent call last):
        ...
        petriflow.analysis.exploration.StateSpaceLimit: state space exceeds max_states=10: stopped after 10 states (7 fully expanded); raise the limit (--max-states) to explore further
    """
    compiled = compiled or CompiledNet(net)
    start = net.initial_marking if marking is None else net.check_marking(marking)
    if max_states < 1:
        raise ValueError(f"max_states must be >= 1, got {max_states}")
    return _explore(compiled, compiled.vector(start), max_states, detect_unbounded)


# Exploration ---------------------------------------------------------------------------

#: Count rows start in the smallest of these dtypes that holds the initial marking and
#: are widened (the exploration starts again) when a count outgrows them.
_UINT = (np.uint8, np.uint16, np.uint32, np.uint64)

#: Count rows of nets with more places than this put the places of an incidence basis
#: first and key states on those columns only; smaller nets key on whole rows, which is
#: as fast and skips the elimination. (Bitmask rows do so beyond 64 places.)
_BASIS_FROM_PLACES = 16
#: Nets whose incidence matrix has more entries than this key on every place: finding a
#: basis of its columns (cubic elimination) would cost more than the keys save.


def warm_up() -> None:
    """Compile (or load from numba's disk cache) the exploration loops, the Karp–Miller
    search and Farkas' adjacency test now.

    The first exploration in a process otherwise pays this (a fraction of a second from
    the cache; several seconds the very first time after installation).
    """
    from petriflow.classic import independent_cycles, producer_consumer

    reachability_graph(independent_cycles(10))     # bitmask rows, a growing table
    for unused in (70, 140):                       # bitmask rows of two and three words
        net = independent_cycles(1)
        for k in range(unused):
            net.add_place(f"unused_{k}")
        reachability_graph(net)
    reachability_graph(producer_consumer(2))       # count rows, unboundedness checks
    from petriflow.analysis.coverability import coverability_search
    from petriflow.analysis.invariants import semiflows
    coverability_search(producer_consumer(2))      # the depth-first Karp-Miller search
    semiflows(np.array([[1], [-1], [1]]))          # Farkas' compiled adjacency test
    for tokens in (300, 70_000, 2**40):            # count rows of every wider dtype
        net = independent_cycles(1)
        net.add_place("stock", tokens=tokens)
        reachability_graph(net)


def _layout(compiled: CompiledNet, has_resets: bool,
            threshold: int) -> tuple[list[int], list[int], int]:
    """``(column -> place, place -> column, number of key columns)``.

    Without reset arcs every reachable marking is ``M0 + x·C``, so its counts on the
    places whose incidence columns form a basis determine the rest: those come first and
    are the key. Small nets, very large ones and nets with reset arcs key on every place.
    """
    n_places = len(compiled.places)
    too_big = n_places * len(compiled.transitions) > limits.BASIS_ENTRIES  # elimination is cubic
    if has_resets or n_places <= threshold or too_big or not any(row_changes(compiled)):
        identity = list(range(n_places))
        return identity, identity, n_places
    basis = pivot_columns(compiled.incidence)
    chosen = set(basis)
    layout = basis + [p for p in range(n_places) if p not in chosen]
    column = [0] * n_places
    for col, place in enumerate(layout):
        column[place] = col
    return layout, column, len(basis)


def _bit_program(compiled: CompiledNet, column: list[int], resets: list[tuple[int, ...]],
                 n_key: int, marked: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """The bitmask loop's inputs: ``(words, kind)``.

    ``words`` has ``3·|rows| + 2`` rows of uint64 words (bit ``j`` of a row = column
    ``j``; ``column[p]`` is place ``p``'s): per row its preset, its postset and the
    columns it leaves alone (``keep``: neither consumed from nor reset), then the key
    columns, then the initial marking (``marked``: the places holding a token). ``kind``
    is 1 for a row needing two tokens from a place (never enabled in a safe marking), 2
    for one putting two into a place (it makes the marking unsafe), else 0.

    Built with Python integers, one per row: on small nets this set-up costs more
    than the exploration itself.
    """
    bit = [1 << c for c in column]
    every = (1 << len(column)) - 1
    pre, post, keep, kind = [], [], [], []
    for row_pre, row_post, row_reset in zip(compiled.pre, compiled.post, resets):
        taken = put = k = 0
        for p, w in row_pre:
            taken |= bit[p]
            if w > 1:
                k = 1
        for p, w in row_post:
            put |= bit[p]
            if w > 1 and not k:
                k = 2
        pre.append(taken)
        post.append(put)
        for p in row_reset:
            taken |= bit[p]
        keep.append(every ^ taken)
        kind.append(k)
    size = 8 * max(1, -(-len(column) // 64))
    rows = pre + post + keep + [(1 << n_key) - 1, sum([bit[p] for p in marked])]
    data = b"".join([r.to_bytes(size, "little") for r in rows])
    words = np.frombuffer(data, dtype="<u8").astype(np.uint64).reshape(len(rows), size // 8)
    return words, np.array(kind, dtype=np.int8)


class _Buffers:
    """The arrays a kernel fills, owned and grown (by doubling) here.

    ``state`` arrays have a row per state (the row, parent, parent transition, first
    edge, then ``extra_state``), ``edge`` arrays an entry per edge (transition, target);
    ``table``
    is the kernel's hash table (``stride`` words a slot) and is rebuilt twice as large
    whenever it would get more than half full.
    """

    def __init__(self, kernel, row: np.ndarray, max_states: int, n_transitions: int,
                 stride: int, id_bits: int, extra_state: tuple[type, ...] = ()) -> None:
        self.kernel, self.stride, self.id_bits = kernel, stride, id_bits
        id_type = np.int32 if max_states < 2**31 else np.int64
        t_type = np.int16 if n_transitions < 2**15 else np.int32
        # The most rows an array can ever need (margin included): reservations stop there.
        self.bounds = (max_states + n_transitions,
                       (max_states + n_transitions) * max(1, n_transitions))
        states = 256
        rows = np.empty((states, len(row)), dtype=row.dtype)
        rows[0] = row
        self.state = [rows, np.empty(states, dtype=id_type), np.empty(states, dtype=np.int32),
                      np.empty(states, dtype=np.int64)]
        self.state += [np.empty(states, dtype=d) for d in extra_state]
        self.edge = [np.empty(1024, dtype=t_type), np.empty(1024, dtype=id_type)]
        self.table = np.zeros(1024 * stride, dtype=np.uint64)
        self.counters = np.zeros(5, dtype=np.int64)

    def grow(self, margin: int) -> None:
        """Make room for ``margin`` more states and edges than counted now."""
        states, edges = int(self.counters[0]), int(self.counters[1])
        self.state = _grown(self.state, states, states + margin, self.bounds[0])
        self.edge = _grown(self.edge, edges, edges + margin, self.bounds[1])
        slots = len(self.table) // self.stride
        if 2 * (states + margin) > slots:          # at most half full
            while 2 * (states + margin) > slots:
                slots *= 2
            bigger = np.zeros(slots * self.stride, dtype=np.uint64)
            self.kernel.rehash(self.table, self.stride, self.id_bits, bigger)
            self.table = bigger


#: An array whose doubling would pass this many bytes moves to a reservation.
_RESERVE_FROM = 32 * 2**20
#: The largest reservation, in bytes (beyond it arrays grow by copying).
_RESERVE_MAX = 2**33


def _grown(arrays: list[np.ndarray], used: int, need: int, bound: int) -> list[np.ndarray]:
    """``arrays`` (of one length: the loops check one of them) with room for ``need``
    rows, at least twice as many, their first ``used`` rows kept; ``bound`` is the most
    rows they can ever need.

    Small arrays double. Large ones move, once, to reservations: anonymous private
    mappings of every row they may ever need (up to 8 GiB each), asking for huge pages,
    whose pages the operating system only commits when the loop first writes them; from
    then on nothing is copied or zero-filled twice.
    """
    if need <= len(arrays[0]):
        return arrays
    rows = max(need, 2 * len(arrays[0]))
    row_bytes = [a.itemsize * int(np.prod(a.shape[1:], dtype=np.int64)) for a in arrays]
    if rows * sum(row_bytes) >= _RESERVE_FROM:
        most = min(bound, _RESERVE_MAX // max(row_bytes))
        reserved = [_reserve(a.dtype, a.shape[1:], b, most, need)
                    for a, b in zip(arrays, row_bytes)]
        if all(r is not None for r in reserved):
            for r, a in zip(reserved, arrays):
                r[:used] = a[:used]
            return reserved
    grown = []
    for a in arrays:
        bigger = np.empty((rows,) + a.shape[1:], dtype=a.dtype)
        bigger[:used] = a[:used]
        grown.append(bigger)
    return grown


def _reserve(dtype, tail: tuple[int, ...], row_bytes: int, rows: int,
             need: int) -> np.ndarray | None:
    """An uninitialised array of ``rows`` rows on a lazily committed mapping, or
    ``None`` where the system refuses one (then the caller copies as usual)."""
    import mmap

    if rows < need:
        return None
    try:
        region = mmap.mmap(-1, rows * row_bytes, flags=mmap.MAP_PRIVATE | mmap.MAP_ANONYMOUS)
        if hasattr(mmap, "MADV_HUGEPAGE"):
            region.madvise(mmap.MADV_HUGEPAGE)
    except (OSError, ValueError, OverflowError, AttributeError):   # no such mapping here
        return None
    return np.frombuffer(region, dtype=dtype).reshape((rows,) + tail)


def _explore(compiled: CompiledNet, m0: Sequence[int], max_states: int,
             detect_unbounded: bool, *, bits: bool = True,
             basis_from: int | None = None) -> StateSpace:
    """The exploration behind :func:`reachability_graph`.

    ``bits=False`` skips the bitmask loop and ``basis_from`` overrides the place counts
    from which keys are basis places (tests use both to reach every path on small nets).
    """
    from petriflow.analysis import _kernel

    resets = row_resets(compiled)
    has_resets = any(resets)
    if bits and max(m0, default=0) <= 1:
        space = _explore_bits(_kernel, compiled, m0, max_states, resets, has_resets,
                              basis_from)
        if space is not None:
            return space
    return _explore_counts(_kernel, compiled, m0, max_states, resets, has_resets,
                           detect_unbounded, basis_from)


def _explore_bits(kernel, compiled: CompiledNet, m0: Sequence[int], max_states: int,
                  resets: list[tuple[int, ...]], has_resets: bool,
                  basis_from: int | None) -> StateSpace | None:
    """Explore with bitmask rows; ``None`` when some reachable marking is not safe."""
    # Rows of more than one word are keyed on basis places: their key usually fits in
    # one word, often beside the state id in one table slot.
    id_bits = max(1, int(max_states).bit_length())
    _, column, n_key = _layout(compiled, has_resets, 64 if basis_from is None else basis_from)
    words, kind = _bit_program(compiled, column, resets, n_key,
                               [p for p, count in enumerate(m0) if count])
    n_t = len(kind)
    id_bits = id_bits if n_key + id_bits <= 64 else 0
    buffers = _Buffers(kernel, words[-1], max_states, n_t, 1 if id_bits else 2, id_bits)
    fixed = (words[:n_t], words[n_t: 2 * n_t], words[2 * n_t: 3 * n_t], kind, words[-2],
             id_bits, max_states)
    while True:
        status = kernel.expand_bits(*fixed, *buffers.state, buffers.table, *buffers.edge,
                                    buffers.counters)
        if status != kernel.FULL:
            break
        buffers.grow(n_t)
    if status == kernel.NOT_SAFE:
        return None
    if status == kernel.LIMIT:
        raise StateSpaceLimit(max_states, int(buffers.counters[0]), int(buffers.counters[2]),
                              _space(compiled, "bitmask", buffers, column, partial=True))
    return _space(compiled, "bitmask", buffers, column)


def _explore_counts(kernel, compiled: CompiledNet, m0: Sequence[int], max_states: int,
                    resets: list[tuple[int, ...]], has_resets: bool,
                    detect_unbounded: bool, basis_from: int | None) -> StateSpace:
    """Explore with count rows, widening their dtype whenever a count outgrows it."""
    layout, col, n_key = _layout(compiled, has_resets,
                                 _BASIS_FROM_PLACES if basis_from is None else basis_from)
    order = np.array(layout, dtype=np.int64)

    def csr(lists: list) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        at = np.zeros(len(lists) + 1, dtype=np.int64)
        at[1:] = np.cumsum([len(items) for items in lists])
        flat = [item for items in lists for item in items]
        return (at, np.array([col[p] for p, _ in flat], dtype=np.int64),
                np.array([w for _, w in flat], dtype=np.int64))

    changes = row_changes(compiled)
    reset_at, reset_place, _ = csr([[(p, 0) for p in places] for places in resets])
    conservative = all(sum(d for _, d in row) == 0 for row in changes)
    check = detect_unbounded and not conservative
    fixed = (*csr(compiled.pre), *csr(compiled.post), *csr(changes), reset_at, reset_place,
             n_key)
    n_t = len(compiled.transitions)
    start = np.asarray(m0, dtype=np.int64)[order]
    need = int(start.max(initial=0))
    dtype = next((d for d in _UINT if need <= np.iinfo(d).max), np.uint64)
    while True:
        top = min(int(np.iinfo(dtype).max), 2**62)  # with weights <= 2**60 no sum can wrap int64
        buffers = _Buffers(kernel, start.astype(dtype), max_states, n_t, 2, 0,
                           (np.int64, np.int64) if check else ())
        unused = np.zeros(1, dtype=np.int64)     # same array types: one compiled loop
        while True:
            totals, path_min = buffers.state[4:] if check else (unused, unused)
            status = kernel.expand_counts(*fixed, top, check, max_states, *buffers.state[:4],
                                          buffers.table, *buffers.edge, totals, path_min,
                                          buffers.counters)
            if status != kernel.FULL:
                break
            buffers.grow(n_t)
        if status == kernel.OVERFLOW and dtype is not np.uint64:
            dtype = _UINT[_UINT.index(dtype) + 1]
            continue
        if status == kernel.OVERFLOW:
            raise PetriflowError("a token count exceeds 2**63 - 1: the net is too large to"
                                 " explore")
        if status == kernel.LIMIT:
            raise StateSpaceLimit(max_states, int(buffers.counters[0]), int(buffers.counters[2]),
                                  _space(compiled, "counts", buffers, col, partial=True))
        if status == kernel.UNBOUNDED:
            _unbounded(compiled, buffers, col)
        return _space(compiled, "counts", buffers, col)


def _space(compiled: CompiledNet, representation: str, buffers: _Buffers,
           column: list[int], partial: bool = False) -> StateSpace:
    """The :class:`StateSpace` a kernel left in ``buffers``; ``partial``: it stopped at
    the state limit, so only the states before ``counters[2]`` have all their edges."""
    states, edges = int(buffers.counters[0]), int(buffers.counters[1])
    rows, parent, parent_t, first_edge = buffers.state[:4]
    e_transition, e_target = buffers.edge
    offsets = np.empty(states + 1, dtype=np.int64)
    expanded = None
    if partial:
        expanded = min(int(buffers.counters[2]), states)
        edges = int(first_edge[expanded]) if expanded < states else edges
        offsets[:expanded] = first_edge[:expanded]
        offsets[expanded:] = edges
    else:
        offsets[:states] = first_edge[:states]
    offsets[states] = edges
    return StateSpace(
        places=tuple(compiled.places),
        transitions=tuple(compiled.transitions),
        origins=row_origins(compiled),
        edge_offsets=offsets,
        edge_transition=e_transition[:edges],
        edge_target=e_target[:edges],
        parent=parent[:states],
        parent_transition=parent_t[:states],
        representation=representation,
        _rows=rows[:states],
        _column_of_place=np.asarray(column, dtype=np.int64),
        expanded=expanded,
    )


def _unbounded(compiled: CompiledNet, buffers: _Buffers, column: list[int]) -> None:
    """Raise :class:`UnboundedNetError` from the covering pair a count exploration found."""
    rows, parent, parent_t = buffers.state[:3]
    state, ancestor = int(buffers.counters[3]), int(buffers.counters[4])

    def walk(s: int, stop: int) -> list[str]:
        sequence = []
        while s != stop:
            sequence.append(compiled.transitions[int(parent_t[s])])
            s = int(parent[s])
        return sequence[::-1]

    def marking(s: int) -> Marking:
        return compiled.marking([int(c) for c in rows[s][column]])

    covered, covering = marking(ancestor), marking(state)
    pump = walk(state, ancestor)
    resets = row_resets(compiled)
    reset = {compiled.places[p] for t in pump for p in resets[compiled.transitions.index(t)]}
    grown = [p for p in compiled.places if covering[p] > covered[p] and p not in reset]
    raise UnboundedNetError(grown, walk(ancestor, 0), pump, covered, covering)
