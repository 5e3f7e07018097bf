"""Explicit state-space exploration of bounded nets: the reachability graph.

:func:`reachability_graph` explores every marking reachable from the initial one,
breadth first, and returns a :class:`StateSpace`: the markings as a 2-D array of counts
(one row per state, columns in :class:`~petriflow.engine.CompiledNet` place order), the
edges as three arrays (source state, transition index, target state) and, per state,
the edge it was first reached by, so that a shortest firing sequence from the initial
marking to any state can be rebuilt (:meth:`StateSpace.path`).

How it is fast:

* **Thin start in plain Python, wide frontiers in numpy.** States are numbered in the
  order they are found, so the BFS queue is a range of state ids. While the queue is
  short (fewer than 512 states), a plain Python BFS on tuples and a dict is fastest;
  once it is wide, numpy takes over and expands the queue in chunks of up to 2**23
  (state, transition) pairs with no per-state Python code. Long thin state spaces
  (a producer and a consumer around a large buffer) never leave the Python engine.
* **Safe nets as bitmasks.** While every marking is safe, a marking is a row of
  ``uint64`` words, one bit a place. For each transition ``t``, one pass over the
  chunk's words finds the states with no input place of ``t`` missing
  (``~m & pre[t] == 0``); the successor is ``m ^ (pre[t] ^ post[t])``. A successor that
  would put a second token in a place (``m & post[t] & ~pre[t] != 0``) makes the
  exploration start again with count rows, unless P-semiflows already prove the net
  safe, in which case the check is skipped.
* **Other bounded nets as count rows.** Small unsigned integers (uint8, widened to
  uint16, uint32, uint64 when a count could overflow); enabled when every input place
  holds the arc weight, successor ``m + C[t]``.
* **Compact, exact keys.** Every reachable marking is ``M0 + x·C`` (C the incidence
  matrix), so it is fixed by its counts on the places whose incidence columns form a
  basis of C's column space (computed exactly; 30 of the 90 places of 30 philosophers).
  Those places come first in the row. On safe nets whose basis fits in 64 bits the key
  is those bits; on count rows it is their counts packed in the bit widths the
  P-semiflow bounds allow. Otherwise it is a 64-bit hash and two states only count as
  equal when their key columns are equal too; a hash collision restarts the
  exploration with an exact dictionary index.
* **Deduplication by one sort.** Each successor is packed as ``key << b | source << t_b
  | t`` in one uint64 (on safe nets that is a single gather and xor per enabled pair)
  and the chunk's array is sorted with ``ndarray.sort``: equal keys become neighbours
  and the first of a run is the first discovery (lowest source, then transition),
  which keeps the BFS parents, hence shortest witnesses. The distinct keys are looked
  up with ``np.searchsorted`` in a sorted index of the states seen (two runs, newest
  first, merged like a small log-structured merge tree).

Reset arcs (a transition's cancellation region) are honoured by both engines: the
successor empties those places; keys are then whole markings.

Unbounded nets: the bitmask path cannot loop forever (it has at most 2^|P| states); on
count rows, each new state is compared with the states on its BFS-tree path from M0. A
marking that strictly covers an ancestor proves the net unbounded (the firing sequence
between them can be repeated forever) and, by Dickson's lemma and König's lemma, some
state of an unbounded net's BFS tree always does, so the check finds every unbounded
net in finite time. It raises :class:`UnboundedNetError` with both firing sequences.
Only states whose token total exceeds the smallest total on their path are compared, so
conservative nets pay nothing, and nets covered by P-semiflows skip the check. With
reset arcs the covering argument fails (a reset can undo the gain), so such nets are
only stopped by ``max_states``.

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
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from petriflow.analysis._linear import pivot_columns
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

#: Default limit on the number of states :func:`reachability_graph` stores.
DEFAULT_MAX_STATES = 2_000_000

_UINT = (np.uint8, np.uint16, np.uint32, np.uint64)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_S30, _S27, _S31 = np.uint64(30), np.uint64(27), np.uint64(31)


class StateSpaceLimit(PetriflowError):
    """The reachable state space has more states than the limit allows.

    Attributes:
        limit: the ``max_states`` that was exceeded.
        explored: states stored when the exploration stopped.
        expanded: states whose successors had all been computed.
    """

    def __init__(self, limit: int, explored: int, expanded: int) -> None:
        self.limit = limit
        self.explored = explored
        self.expanded = expanded
        super().__init__(
            f"state space exceeds max_states={limit}: stopped after {explored} states "
            f"({expanded} fully expanded); raise the limit (--max-states) to explore further"
        )


class UnboundedNetError(PetriflowError):
    """The net is unbounded: a reachable marking strictly covers an earlier one.

    Firing ``prefix`` from the initial marking reaches ``covered``; firing ``pump`` from
    there reaches ``covering`` >= ``covered`` with more tokens in ``places``. Since
    ``pump`` is enabled again in ``covering`` (monotonicity), repeating it grows those
    places without bound.

    Attributes:
        places: ids of the places that strictly grow along ``pump`` (all unbounded).
        prefix: transition ids from the initial marking to ``covered``.
        pump: transition ids from ``covered`` to ``covering``.
        covered: the earlier marking.
        covering: the later marking.
    """

    def __init__(self, places: list[str], prefix: list[str], pump: list[str],
                 covered: Marking, covering: Marking) -> None:
        self.places = places
        self.prefix = prefix
        self.pump = pump
        self.covered = covered
        self.covering = covering
        super().__init__(
            f"net is unbounded: firing {pump} from the marking reached by {prefix} adds tokens"
            f" to {places} and can be repeated forever"
        )


class _HashCollision(Exception):
    """Two different markings share a 64-bit hash (restart with an exact index)."""


class _NotSafe(Exception):
    """A successor puts a second token in a place (leave the bitmask path)."""


@dataclass(eq=False)
class StateSpace:
    """The reachability graph of a bounded net, as numpy arrays.

    States are numbered ``0 .. num_states - 1`` in breadth-first order; state 0 is the
    initial marking, so state ids never decrease with the distance from it. Edges are
    in exploration order (grouped by chunks of source states, not sorted);
    :meth:`successors` and :meth:`out_degree` index them.

    Attributes:
        places: place ids; column ``j`` of :attr:`markings` is ``places[j]``.
        transitions: the ids of the :class:`~petriflow.engine.CompiledNet` rows, which
            :attr:`edge_transition` indexes: transition ids, and ``t@failed``-style ids
            for the outcome variants of transitions with routed action outcomes.
        origins: per row, the id of the net transition it belongs to.
        edge_source: source state of each edge.
        edge_transition: index of the transition fired on each edge.
        edge_target: target state of each edge.
        parent: per state, the state it was first reached from (-1 for state 0).
        parent_transition: per state, the transition index of that edge (-1 for state 0).
        representation: ``"bitmask"`` (the exploration stayed safe) or ``"counts"``.
    """

    places: tuple[str, ...]
    transitions: tuple[str, ...]
    origins: tuple[str, ...]
    edge_source: np.ndarray
    edge_transition: np.ndarray
    edge_target: np.ndarray
    parent: np.ndarray
    parent_transition: np.ndarray
    representation: str
    _rows: np.ndarray = field(repr=False)
    _column_of_place: np.ndarray = field(repr=False)
    _markings: np.ndarray | None = field(default=None, repr=False)
    _csr: tuple[np.ndarray, np.ndarray] | None = field(default=None, repr=False)

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
    def out_degree(self) -> np.ndarray:
        """Number of enabled transitions in each state."""
        return np.bincount(self.edge_source, minlength=self.num_states)

    def successors(self, state: int) -> list[tuple[str, int]]:
        """``(transition id, target state)`` of every edge leaving ``state``, by transition."""
        if self._csr is None:
            order = np.lexsort((self.edge_transition, self.edge_source))
            offsets = np.zeros(self.num_states + 1, dtype=np.int64)
            np.cumsum(self.out_degree(), out=offsets[1:])
            self._csr = (order, offsets)
        order, offsets = self._csr
        edges = order[offsets[state]: offsets[state + 1]]
        return [(self.transitions[t], int(s)) for t, s in
                zip(self.edge_transition[edges], self.edge_target[edges])]

    def deadlocks(self) -> np.ndarray:
        """Ids of the states that enable no transition, in increasing order.

        The first one is a deadlock nearest to the initial marking (BFS numbering).
        """
        return np.flatnonzero(self.out_degree() == 0)

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
        petriflow.analysis.reachability.StateSpaceLimit: state space exceeds max_states=10: stopped after 10 states (7 fully expanded); raise the limit (--max-states) to explore further
    """
    compiled = compiled or CompiledNet(net)
    start = net.initial_marking if marking is None else net.check_marking(marking)
    if max_states < 1:
        raise ValueError(f"max_states must be >= 1, got {max_states}")
    return _explore(compiled, np.array(compiled.vector(start), dtype=np.int64), max_states,
                    detect_unbounded)


# Exploration ---------------------------------------------------------------------------


def _mix(x: np.ndarray) -> np.ndarray:
    """splitmix64's finaliser: a bijection of uint64 that spreads every input bit."""
    x = x ^ (x >> _S30)
    x = x * _M1
    x = x ^ (x >> _S27)
    x = x * _M2
    return x ^ (x >> _S31)


def _hash_words(words: np.ndarray) -> np.ndarray:
    """64-bit hash of each row of a 2-D uint64 array."""
    h = _mix(words[:, 0] + _GOLDEN)
    for j in range(1, words.shape[1]):
        h = _mix(h ^ words[:, j])
    return h


def _as_words(block: np.ndarray) -> np.ndarray:
    """Rows of unsigned ints as rows of uint64 words (zero padded)."""
    per_word = 8 // block.dtype.itemsize
    width = max(1, -(-block.shape[1] // per_word)) * per_word
    buffer = np.zeros((block.shape[0], width), dtype=block.dtype)
    buffer[:, : block.shape[1]] = block
    return buffer.view(np.uint64)


class _Growing:
    """An array with amortised O(1) appends of blocks of rows."""

    def __init__(self, first: np.ndarray, capacity: int = 1024) -> None:
        shape = (max(capacity, len(first)),) + first.shape[1:]
        self.data = np.empty(shape, dtype=first.dtype)
        self.size = len(first)
        self.data[: self.size] = first

    def append(self, block: np.ndarray) -> None:
        need = self.size + len(block)
        if need > len(self.data):
            bigger = np.empty((max(need, 2 * len(self.data)),) + self.data.shape[1:],
                              dtype=self.data.dtype)
            bigger[: self.size] = self.data[: self.size]
            self.data = bigger
        self.data[self.size: need] = block
        self.size = need

    def view(self) -> np.ndarray:
        return self.data[: self.size]

    def astype(self, dtype) -> None:
        self.data = self.data.astype(dtype)


class _VisitedIndex:
    """Sorted arrays mapping uint64 keys to state ids, searched with ``np.searchsorted``.

    Two sorted runs, like a tiny log-structured merge tree: new keys are merged into
    the small run, which is merged into the big one once it reaches a quarter of its
    size, so adding keys never copies the whole index on every chunk. Looking up keys
    in increasing order keeps ``searchsorted`` cache friendly.
    """

    def __init__(self) -> None:
        self.runs = [(np.zeros(0, dtype=np.uint64), np.zeros(0, dtype=np.int64))] * 2

    def find(self, keys: np.ndarray) -> np.ndarray:
        """State id of each key (keys increasing), -1 where absent.

        The newest run is searched first: in a breadth-first search most successors are
        recent states, so few keys go on to the big run.
        """
        result = np.full(len(keys), -1, dtype=np.int64)
        todo = None
        for run_keys, run_ids in reversed(self.runs):
            if not len(run_keys):
                continue
            needles = keys if todo is None else keys.take(todo)
            pos = np.searchsorted(run_keys, needles)
            np.minimum(pos, len(run_keys) - 1, out=pos)
            hit = run_keys.take(pos) == needles
            where = np.flatnonzero(hit) if todo is None else todo[hit]
            result[where] = run_ids.take(pos[hit])
            todo = np.flatnonzero(~hit) if todo is None else todo[~hit]
            if not todo.size:
                break
        return result

    def add(self, keys: np.ndarray, ids: np.ndarray) -> None:
        """Insert keys not in the index yet (increasing, distinct)."""
        (big_keys, big_ids), (small_keys, small_ids) = self.runs
        where = np.searchsorted(small_keys, keys)
        small_keys, small_ids = np.insert(small_keys, where, keys), np.insert(small_ids, where, ids)
        if 4 * len(small_keys) > len(big_keys):
            where = np.searchsorted(big_keys, small_keys)
            big_keys = np.insert(big_keys, where, small_keys)
            big_ids = np.insert(big_ids, where, small_ids)
            small_keys, small_ids = small_keys[:0], small_ids[:0]
        self.runs = [(big_keys, big_ids), (small_keys, small_ids)]


class _Explorer:
    """One breadth-first exploration, on bitmask rows or on count rows.

    Rows hold the places in "layout" order: first the places whose incidence columns
    form a basis (``n_key`` of them; they determine a reachable marking), then the rest.
    """

    def __init__(self, compiled: CompiledNet, m0: np.ndarray, max_states: int,
                 detect_unbounded: bool, bitmask: bool, exact_index: bool,
                 bounds: np.ndarray | None, prefix: _Prefix | None = None) -> None:
        self.compiled = compiled
        self.prefix = prefix
        self.max_states = max_states
        self.bitmask = bitmask
        self.exact_index = exact_index
        pre, post, incidence = compiled.pre_matrix, compiled.post_matrix, compiled.incidence
        self.n_transitions, self.n_places = pre.shape
        resets = np.zeros(pre.shape, dtype=bool)
        for t, places in enumerate(_resets_of(compiled)):
            resets[t, list(places)] = True
        self.has_resets = bool(resets.any())
        # Reachable markings are M0 + x·C only without reset arcs; with them, keys are
        # whole markings.
        if self.has_resets:
            basis = list(range(self.n_places))
        else:
            basis = pivot_columns(incidence) if incidence.size else []
        in_basis = set(basis)
        rest = [p for p in range(self.n_places) if p not in in_basis]
        self.layout = np.array(basis + rest, dtype=np.int64)     # column -> place
        self.column_of_place = np.argsort(self.layout)            # place -> column
        self.n_key = len(basis)
        # bounds: per place an upper bound proved by P-semiflows, or -1 when unknown.
        self.bounds = None if bounds is None else bounds[self.layout]
        proven_bounded = self.bounds is not None and bool((self.bounds >= 0).all())
        conservative = bool((incidence.sum(axis=1) == 0).all()) if incidence.size else True
        # Strictly covering an ancestor proves nothing once places can be reset.
        self.check_unbounded = (detect_unbounded and not bitmask and not conservative
                                and not proven_bounded and not self.has_resets)
        self.proven_safe = proven_bounded and bool((self.bounds <= 1).all())
        self.pre = pre[:, self.layout]
        self.post = post[:, self.layout]
        self.resets = resets[:, self.layout]
        self.t_bits = max(1, int(self.n_transitions - 1).bit_length())
        m0 = m0[self.layout]
        if bitmask:
            self._init_bitmask(m0)
        else:
            self._init_counts(m0)
        if prefix is not None:              # continue a breadth-first search begun in Python
            rows = prefix.rows[:, self.layout]
            if bitmask:
                self.rows = _Growing(self._words_of(rows))
            else:
                dtype = self.dtype
                while int(rows.max(initial=0)) + self.max_gain > np.iinfo(dtype).max:
                    dtype = _UINT[_UINT.index(dtype) + 1]
                self.rows = _Growing(rows.astype(dtype))
                self._set_dtype(dtype)

    # Representations --------------------------------------------------------------------
    def _words_of(self, matrix: np.ndarray) -> np.ndarray:
        bits = np.zeros((matrix.shape[0], self.n_words * 64), dtype=np.uint8)
        bits[:, : self.n_places] = matrix > 0
        return np.packbits(bits, axis=1, bitorder="little").view("<u8").astype(np.uint64)

    def _init_bitmask(self, m0: np.ndarray) -> None:
        self.n_words = max(1, -(-self.n_places // 64))
        pre_words, post_words = self._words_of(self.pre), self._words_of(self.post)
        # A transition needing two tokens from a place is never enabled in a safe marking;
        # one putting two tokens in a place makes the marking unsafe as soon as it fires.
        self.usable = [int(t) for t in np.flatnonzero((self.pre <= 1).all(axis=1))]
        self.doubling = (self.post > 1).any(axis=1)
        self.tests = {t: [(w, pre_words[t, w]) for w in range(self.n_words) if pre_words[t, w]]
                      for t in self.usable}
        # Firing t maps m to (m & keep) ^ flip while the marking stays safe. Without reset
        # arcs keep is all ones and flip = pre ^ post (pre is in m: xor removes it); with
        # them keep also clears the preset and the reset places, and flip = post.
        if self.has_resets:
            keep_words = ~(pre_words | self._words_of(self.resets))
            self.flip_words = post_words
            self.keep_words = keep_words
        else:
            keep_words = np.full_like(pre_words, np.uint64(2**64 - 1))
            self.flip_words = pre_words ^ post_words
            self.keep_words = None
        gain = post_words & keep_words & ~pre_words        # places that gain a token
        self.gains = {t: [(w, gain[t, w]) for w in range(self.n_words) if gain[t, w]]
                      for t in self.usable}
        self.key_words = max(1, -(-self.n_key // 64))
        self.key_flip = self.flip_words[:, : self.key_words].copy()
        self.key_keep = keep_words[:, : self.key_words].copy()
        if self.n_key <= 64:
            self.key_bits = self.n_key
            self.key_mask = np.uint64((1 << self.n_key) - 1 if self.n_key < 64 else 2**64 - 1)
            self.key_flip &= self.key_mask
            self.key_keep &= self.key_mask
        else:
            self.key_bits = 64
        self.rows = _Growing(self._words_of(m0[None, :]))

    def _init_counts(self, m0: np.ndarray) -> None:
        self.usable = list(range(self.n_transitions))
        self.delta = self.post - self.pre
        self.max_gain = int(self.delta.max(initial=0))
        self.tests = {t: [(int(p), int(self.pre[t, p])) for p in np.flatnonzero(self.pre[t])]
                      for t in self.usable}
        need = max(int(m0.max(initial=0)) + self.max_gain, int(self.pre.max(initial=0)))
        dtype = np.uint8
        while need > np.iinfo(dtype).max:
            dtype = _UINT[_UINT.index(dtype) + 1]
        self.rows = _Growing(m0[None, :].astype(dtype))
        self._set_dtype(dtype)

    def _set_dtype(self, dtype) -> None:
        self.dtype = dtype
        self.delta_cast = self.delta.astype(dtype)     # wraps modulo 2**bits: m + delta is exact
        # With reset arcs: successor = (m - pre) * kept + post, kept 0 on reset places.
        self.kept = (~self.resets).astype(dtype)
        self.pre_cast = self.pre.astype(dtype)
        self.post_cast = self.post.astype(dtype)
        self.key_delta = np.ascontiguousarray(self.delta_cast[:, : self.n_key])
        self.widths = None
        self.key_bits = 64
        bounds = None if self.bounds is None else self.bounds[: self.n_key]
        if bounds is not None and (bounds >= 0).all():
            widths = [max(1, int(b).bit_length()) for b in bounds]
            if sum(widths) <= 64:
                self.widths = widths
                self.key_bits = sum(widths)

    # Keys -------------------------------------------------------------------------------
    @property
    def exact_key(self) -> bool:
        """Whether a key is the marking's basis part itself (no hashing, no verification)."""
        if self.bitmask:
            return self.n_key <= 64
        return self.widths is not None

    def _key_part(self, rows: np.ndarray) -> np.ndarray:
        """The columns a key is made of (they determine a reachable marking)."""
        width = self.key_words if self.bitmask else self.n_key
        return np.ascontiguousarray(rows[:, :width])

    def _key_of_part(self, part: np.ndarray) -> np.ndarray:
        if self.bitmask:
            if self.n_key <= 64:
                return part[:, 0] & self.key_mask
            return _hash_words(part)
        if self.widths is not None:
            key = np.zeros(part.shape[0], dtype=np.uint64)
            shift = 0
            for j, width in enumerate(self.widths):
                key |= part[:, j].astype(np.uint64) << np.uint64(shift)
                shift += width
            return key
        return _hash_words(_as_words(part))

    def _successor_rows(self, frontier: np.ndarray, i: np.ndarray, t: np.ndarray) -> np.ndarray:
        rows = frontier.take(i, axis=0)
        if self.bitmask:
            if self.keep_words is not None:
                rows &= self.keep_words.take(t, axis=0)
            return rows ^ self.flip_words.take(t, axis=0)
        if self.has_resets:
            return ((rows - self.pre_cast.take(t, axis=0)) * self.kept.take(t, axis=0)
                    + self.post_cast.take(t, axis=0))
        return rows + self.delta_cast.take(t, axis=0)

    def _rebuild_index(self) -> None:
        parts = self._key_part(self.rows.view())
        if self.exact_index:
            self.table = {parts[s].tobytes(): s for s in range(len(parts))}
            return
        keys = self._key_of_part(parts)
        order = np.argsort(keys, kind="stable")
        self.index = _VisitedIndex()
        self.index.add(keys[order], order)

    # The loop ---------------------------------------------------------------------------
    def run(self) -> StateSpace:
        prefix = self.prefix
        if prefix is None:
            self.parent = _Growing(np.array([-1], dtype=np.int64))
            self.parent_t = _Growing(np.array([-1], dtype=np.int32))
            head = 0
            sources, fired, targets = [], [], []
        else:
            self.parent = _Growing(np.array(prefix.parent, dtype=np.int64))
            self.parent_t = _Growing(np.array(prefix.parent_t, dtype=np.int32))
            head = prefix.head
            sources, fired, targets = ([np.array(prefix.sources, dtype=np.int64)],
                                       [np.array(prefix.fired, dtype=np.int64)],
                                       [np.array(prefix.targets, dtype=np.int64)])
        if self.check_unbounded:
            totals = self.rows.view().sum(axis=1, dtype=np.int64)
            path_min = totals.copy()
            parent = self.parent.view()
            for state in range(1, len(totals)):          # parents come before children
                path_min[state] = min(totals[state], path_min[parent[state]])
            self.totals = _Growing(totals)
            self.path_min = _Growing(path_min)
        self._rebuild_index()
        id_type = np.int32 if self.max_states < 2**31 else np.int64
        t_type = np.int16 if self.n_transitions < 2**15 else np.int32
        sources = [a.astype(id_type) for a in sources]
        fired = [a.astype(t_type) for a in fired]
        targets = [a.astype(id_type) for a in targets]
        # About 2**23 (state, transition) tests a chunk: large enough that few successors
        # are looked up twice, small enough to bound the temporaries (~100 MB at most).
        chunk = min(1 << 18, max(64, (1 << 23) // max(1, len(self.usable))))
        while head < self.rows.size:
            hi = min(self.rows.size, head + chunk)
            if not self.bitmask:
                self._widen_if_needed(head, hi)
            frontier = self.rows.view()[head:hi]
            keys, parts, codes, packed = self._successors(frontier)
            source, transition, target = self._lookup_and_add(frontier, keys, parts, codes,
                                                              packed, head)
            sources.append(source.astype(id_type, copy=False))
            fired.append(transition.astype(t_type, copy=False))
            targets.append(target.astype(id_type, copy=False))
            head = hi

        def joined(parts: list[np.ndarray], dtype) -> np.ndarray:
            return np.concatenate(parts) if parts else np.zeros(0, dtype)

        return StateSpace(
            places=tuple(self.compiled.places),
            transitions=tuple(self.compiled.transitions),
            origins=_origins(self.compiled),
            edge_source=joined(sources, id_type),
            edge_transition=joined(fired, t_type),
            edge_target=joined(targets, id_type),
            parent=self.parent.view().astype(id_type),
            parent_transition=self.parent_t.view(),
            representation="bitmask" if self.bitmask else "counts",
            _rows=self.rows.view(),
            _column_of_place=self.column_of_place,
        )

    def _widen_if_needed(self, head: int, hi: int) -> None:
        top = int(self.rows.view()[head:hi].max(initial=0))
        if top + self.max_gain <= np.iinfo(self.dtype).max:
            return
        dtype = self.dtype
        while top + self.max_gain > np.iinfo(dtype).max:
            dtype = _UINT[_UINT.index(dtype) + 1]
        self.rows.astype(dtype)
        self._set_dtype(dtype)
        self._rebuild_index()

    def _successors(self, frontier: np.ndarray):
        """Every enabled (state, transition) pair of the frontier and its successor's key.

        Works transition by transition on the frontier's columns (long contiguous
        vectors). Returns ``(keys, parts, codes, packed)``: the successor keys, their key
        parts (``None`` when keys are exact), the pairs as codes ``row << t_bits | t``,
        and, on the fast path, ``packed = key << code_bits | code`` in place of the three.
        """
        n, t_bits = frontier.shape[0], np.uint64(self.t_bits)
        ok = np.empty(n, dtype=bool)
        key_list, part_list, code_list, packed_list = [], [], [], []
        rows = np.arange(n, dtype=np.uint64) << t_bits
        code_bits = max(1, ((n - 1) << self.t_bits | (self.n_transitions - 1)).bit_length())
        # Fast path (safe net, exact key, no reset arcs): with kshift = key << code_bits |
        # row << t_bits, the packed successor of (row, t) is kshift[row] ^ (flip_t <<
        # code_bits | t), since the three bit fields do not overlap: one gather, one xor.
        fast = (self.bitmask and self.exact_key and self.keep_words is None
                and self.key_bits + code_bits <= 64)
        if self.bitmask:
            missing = np.ascontiguousarray((~frontier).T)   # per word: the places without a token
            words = np.ascontiguousarray(frontier.T)
            acc, tmp = np.empty(n, dtype=np.uint64), np.empty(n, dtype=np.uint64)
            if self.exact_key:
                key_column = words[0] & self.key_mask
                if fast:
                    kshift = (key_column << np.uint64(code_bits)) | rows
            else:
                key_block = self._key_part(frontier)
        else:
            columns = np.ascontiguousarray(frontier.T)
            key_block = np.ascontiguousarray(frontier[:, : self.n_key])
        for t in self.usable:
            tests = self.tests[t]
            if not tests:
                ok[:] = True
            elif self.bitmask:
                w, bits = tests[0]
                np.bitwise_and(missing[w], bits, out=acc)
                for w, bits in tests[1:]:
                    np.bitwise_and(missing[w], bits, out=tmp)
                    np.bitwise_or(acc, tmp, out=acc)
                np.equal(acc, 0, out=ok)
            else:
                p, weight = tests[0]
                np.greater_equal(columns[p], weight, out=ok)
                for p, weight in tests[1:]:
                    ok &= columns[p] >= weight
            idx = np.flatnonzero(ok)
            if not idx.size:
                continue
            if self.bitmask:
                if not self.proven_safe:
                    if self.doubling[t]:
                        raise _NotSafe
                    for w, bits in self.gains[t]:
                        if (words[w].take(idx) & bits).any():
                            raise _NotSafe
                if fast:
                    packed_list.append(kshift.take(idx) ^ np.uint64(
                        (int(self.key_flip[t, 0]) << code_bits) | t))
                    continue
                if self.exact_key:
                    column = key_column.take(idx)
                    if self.keep_words is not None:
                        column &= self.key_keep[t, 0]
                    key_list.append(column ^ self.key_flip[t, 0])
                else:
                    block = key_block.take(idx, axis=0)
                    if self.keep_words is not None:
                        block &= self.key_keep[t]
                    part_list.append(block ^ self.key_flip[t])
            elif self.has_resets:
                part_list.append(self._successor_rows(frontier, idx, np.full(idx.size, t))
                                 [:, : self.n_key])
            else:
                part_list.append(key_block.take(idx, axis=0) + self.key_delta[t])
            code_list.append(rows.take(idx) | np.uint64(t))
        if packed_list:
            return None, None, None, (np.concatenate(packed_list), code_bits)
        if not code_list:
            empty = np.zeros(0, dtype=np.uint64)
            return empty, None, empty, None
        codes = np.concatenate(code_list)
        if key_list:
            return np.concatenate(key_list), None, codes, None
        parts = np.concatenate(part_list)
        return self._key_of_part(parts), (None if self.exact_key else parts), codes, None

    def _lookup_and_add(self, frontier: np.ndarray, keys, parts, codes, packed, head: int):
        """(source, transition, target) of every enabled pair, storing the new states."""
        t_bits, t_mask = np.uint64(self.t_bits), np.uint64((1 << self.t_bits) - 1)
        if packed is not None:
            packed, code_bits = packed
            n = len(packed)
            if self.exact_index:
                codes = packed & np.uint64((1 << code_bits) - 1)
                keys = packed >> np.uint64(code_bits)
        else:
            n = len(codes)
            code_bits = max(1, int(codes.max(initial=0)).bit_length())
        if n == 0:
            empty = np.zeros(0, dtype=np.int64)
            return empty, empty, empty
        if self.exact_index:
            return self._lookup_exact(frontier, keys, parts, codes, head)
        # One sort groups equal successors; the smallest code of a group is its first
        # discovery (lowest source state, then lowest transition).
        if packed is not None or self.key_bits + code_bits <= 64:
            if packed is None:
                packed = (keys << np.uint64(code_bits)) | codes
            packed.sort()
            sorted_keys = packed >> np.uint64(code_bits)
            sorted_codes = packed & np.uint64((1 << code_bits) - 1)
            order = None
        else:
            order = np.argsort(keys, kind="stable")
            sorted_keys, sorted_codes = keys.take(order), codes.take(order)
        starts = np.flatnonzero(sorted_keys[1:] != sorted_keys[:-1]) + 1
        starts = np.concatenate((np.zeros(1, dtype=starts.dtype), starts))
        counts = np.diff(np.append(starts, n))
        unique_keys = sorted_keys.take(starts)
        first = (sorted_codes.take(starts) if order is None
                 else np.minimum.reduceat(sorted_codes, starts))
        if parts is not None:
            sorted_parts = parts.take(order, axis=0)
            if not (sorted_parts == np.repeat(sorted_parts.take(starts, axis=0), counts,
                                              axis=0)).all():
                raise _HashCollision
        target_of_key = self.index.find(unique_keys)
        hit = target_of_key >= 0
        if parts is not None and hit.any():
            stored = self._key_part(self.rows.view().take(target_of_key[hit], axis=0))
            if not (stored == sorted_parts.take(starts[hit], axis=0)).all():
                raise _HashCollision
        fresh = np.flatnonzero(~hit)
        if fresh.size:
            base = self.rows.size
            if base + fresh.size > self.max_states:
                raise StateSpaceLimit(self.max_states, base, head)
            discovery = np.argsort(first.take(fresh))        # new states in BFS order
            ids = np.empty(fresh.size, dtype=np.int64)
            ids[discovery] = np.arange(base, base + fresh.size)
            target_of_key[fresh] = ids
            self.index.add(unique_keys.take(fresh), ids)
            pairs = first.take(fresh.take(discovery))
            i = (pairs >> t_bits).astype(np.int64)
            t = (pairs & t_mask).astype(np.int64)
            self._store(self._successor_rows(frontier, i, t), i + head, t)
        id_type = np.int32 if self.max_states < 2**31 else np.int64
        source = (sorted_codes >> t_bits).astype(id_type)
        source += head
        transition = (sorted_codes & t_mask).astype(np.int16 if self.n_transitions < 2**15
                                                    else np.int32)
        return source, transition, np.repeat(target_of_key.astype(id_type), counts)

    def _store(self, rows: np.ndarray, parents: np.ndarray, transitions: np.ndarray) -> None:
        base = self.rows.size
        self.rows.append(rows)
        self.parent.append(parents)
        self.parent_t.append(transitions.astype(np.int32))
        if self.check_unbounded:
            self._check_covering(np.arange(base, base + len(rows)), parents)

    def _lookup_exact(self, frontier, keys, parts, codes, head):
        """The slow exact index (a dict of key bytes), used after a hash collision."""
        t_bits = np.uint64(self.t_bits)
        i_all = (codes >> t_bits).astype(np.int64)
        t_all = (codes & np.uint64((1 << self.t_bits) - 1)).astype(np.int64)
        order = np.argsort(codes, kind="stable")          # handle pairs in BFS order
        if parts is None:
            parts = self._key_part(self._successor_rows(frontier, i_all, t_all))
        parts = np.ascontiguousarray(parts)
        targets = np.empty(len(codes), dtype=np.int64)
        for e in order:
            key = parts[e].tobytes()
            state = self.table.get(key)
            if state is None:
                state = self.rows.size
                if state + 1 > self.max_states:
                    raise StateSpaceLimit(self.max_states, state, head)
                self.table[key] = state
                self._store(self._successor_rows(frontier, i_all[e: e + 1], t_all[e: e + 1]),
                            i_all[e: e + 1] + head, t_all[e: e + 1])
            targets[e] = state
        return i_all + head, t_all, targets

    # Unboundedness ----------------------------------------------------------------------
    def _check_covering(self, ids: np.ndarray, parents: np.ndarray) -> None:
        """Raise :class:`UnboundedNetError` if a new state strictly covers an ancestor."""
        rows = self.rows.view()
        totals = rows.take(ids, axis=0).sum(axis=1, dtype=np.int64)
        self.totals.append(totals)
        self.path_min.append(np.minimum(totals, self.path_min.view()[parents]))
        all_totals, all_min, parent = self.totals.view(), self.path_min.view(), self.parent.view()
        # Only a state with more tokens than some ancestor can strictly cover one.
        keep = totals > all_min[parents]
        candidates, ancestors, wanted = ids[keep], parents[keep], totals[keep]
        while candidates.size:
            covers = (wanted > all_totals[ancestors]) & (
                rows.take(candidates, axis=0) >= rows.take(ancestors, axis=0)).all(axis=1)
            if covers.any():
                k = int(np.flatnonzero(covers)[0])
                self._unbounded(int(candidates[k]), int(ancestors[k]))
            ancestors = parent[ancestors]
            alive = ancestors >= 0
            alive[alive] = all_min[ancestors[alive]] < wanted[alive]
            candidates, ancestors, wanted = candidates[alive], ancestors[alive], wanted[alive]

    def _unbounded(self, state: int, ancestor: int) -> None:
        compiled = self.compiled
        rows = self.rows.view()
        parent, parent_t = self.parent.view(), self.parent_t.view()

        def walk(s: int, stop: int) -> list[str]:
            sequence = []
            while s != stop:
                sequence.append(compiled.transitions[int(parent_t[s])])
                s = int(parent[s])
            return sequence[::-1]

        def marking(s: int) -> Marking:
            return compiled.marking([int(c) for c in rows[s][self.column_of_place]])

        covered, covering = marking(ancestor), marking(state)
        grown = [p for p in compiled.places if covering[p] > covered[p]]
        raise UnboundedNetError(grown, walk(ancestor, 0), walk(state, ancestor), covered, covering)


def _structural_bounds(compiled: CompiledNet, m0: np.ndarray) -> np.ndarray | None:
    """Per place a bound proved by P-semiflows (-1 where none), or None if too costly.

    ``y·M <= y·M0`` for every P-semiflow ``y`` and reachable ``M`` (equality without reset
    arcs; resets only remove tokens), so ``M(p) <= (y·M0) // y[p]``.
    """
    from petriflow.analysis.invariants import DEFAULT_MAX_ROWS, InvariantLimit, _cached_semiflows

    if compiled.incidence.size == 0 or compiled.incidence.size > 250_000:
        return None
    try:
        flows = _cached_semiflows(compiled, "p", DEFAULT_MAX_ROWS)
    except InvariantLimit:
        return None
    bounds = np.full(len(compiled.places), -1, dtype=np.int64)
    for y in flows:
        total = int(y @ m0)
        support = np.flatnonzero(y)
        limit = total // y[support]
        current = bounds[support]
        bounds[support] = np.where((current < 0) | (limit < current), limit, current)
    return bounds


@dataclass
class _Prefix:
    """A breadth-first search begun in plain Python, to be continued with numpy."""

    rows: np.ndarray            # states so far, counts in place order
    parent: list[int]
    parent_t: list[int]
    sources: list[int]
    fired: list[int]
    targets: list[int]
    head: int                   # first state whose successors are not computed yet
    complete: bool
    safe: bool


#: A breadth-first search stays in plain Python while its queue is shorter than this:
#: numpy's per-call overhead only pays off on wide frontiers.
_NUMPY_FROM_QUEUE = 512


def _python_bfs(compiled: CompiledNet, m0: np.ndarray, max_states: int, check_unbounded: bool,
                switch: int) -> _Prefix:
    """Breadth-first search on tuples and a dict, until the queue grows past ``switch``.

    Thin state spaces (long chains of small levels, e.g. a producer and a consumer around
    a large buffer) never get wide enough for numpy and are explored here completely.
    """
    transitions = []
    for t, resets in enumerate(_resets_of(compiled)):
        change: dict[int, int] = {}
        for p, w in compiled.pre[t]:
            change[p] = change.get(p, 0) - w
        for p, w in compiled.post[t]:
            change[p] = change.get(p, 0) + w
        transitions.append((t, compiled.pre[t], tuple((p, d) for p, d in change.items() if d),
                            tuple(resets), compiled.post[t]))
    start = tuple(int(c) for c in m0)
    states = [start]
    index = {start: 0}
    parent, parent_t = [-1], [-1]
    sources: list[int] = []
    fired: list[int] = []
    targets: list[int] = []
    safe = max(start, default=0) <= 1
    totals, path_min = [sum(start)], [sum(start)]
    head = 0
    while head < len(states):
        if len(states) - head > switch:
            break
        marking = states[head]
        for t, pre, change, resets, post in transitions:
            for p, w in pre:
                if marking[p] < w:
                    break
            else:
                successor = list(marking)
                if resets:
                    for p, w in pre:
                        successor[p] -= w
                    for p in resets:
                        successor[p] = 0
                    for p, w in post:
                        successor[p] += w
                else:
                    for p, d in change:
                        successor[p] += d
                key = tuple(successor)
                target = index.get(key)
                if target is None:
                    target = len(states)
                    if target + 1 > max_states:
                        raise StateSpaceLimit(max_states, target, head)
                    index[key] = target
                    states.append(key)
                    parent.append(head)
                    parent_t.append(t)
                    if safe and max(key) > 1:
                        safe = False
                    if check_unbounded:
                        total = sum(key)
                        totals.append(total)
                        path_min.append(min(total, path_min[head]))
                        if total > path_min[head]:
                            _python_covering(compiled, states, parent, parent_t, totals,
                                             path_min, target)
                sources.append(head)
                fired.append(t)
                targets.append(target)
        head += 1
    rows = np.array(states, dtype=np.int64).reshape(len(states), len(start))
    return _Prefix(rows, parent, parent_t, sources, fired, targets, head,
                   head == len(states), safe)


def _python_covering(compiled, states, parent, parent_t, totals, path_min, state) -> None:
    """Raise :class:`UnboundedNetError` if ``state`` strictly covers one of its ancestors."""
    marking, total = states[state], totals[state]
    ancestor = parent[state]
    while ancestor >= 0 and path_min[ancestor] < total:
        if totals[ancestor] < total and all(a >= b for a, b in zip(marking, states[ancestor])):
            def walk(s: int, stop: int) -> list[str]:
                sequence = []
                while s != stop:
                    sequence.append(compiled.transitions[parent_t[s]])
                    s = parent[s]
                return sequence[::-1]

            covered = compiled.marking(states[ancestor])
            covering = compiled.marking(marking)
            grown = [p for p in compiled.places if covering[p] > covered[p]]
            raise UnboundedNetError(grown, walk(ancestor, 0), walk(state, ancestor),
                                    covered, covering)
        ancestor = parent[ancestor]


def _space_from_prefix(compiled: CompiledNet, prefix: _Prefix, max_states: int) -> StateSpace:
    id_type = np.int32 if max_states < 2**31 else np.int64
    t_type = np.int16 if len(compiled.transitions) < 2**15 else np.int32
    top = int(prefix.rows.max(initial=0))
    dtype = next((d for d in _UINT if top <= np.iinfo(d).max), np.uint64)
    return StateSpace(
        places=tuple(compiled.places),
        transitions=tuple(compiled.transitions),
        origins=_origins(compiled),
        edge_source=np.array(prefix.sources, dtype=id_type),
        edge_transition=np.array(prefix.fired, dtype=t_type),
        edge_target=np.array(prefix.targets, dtype=id_type),
        parent=np.array(prefix.parent, dtype=id_type),
        parent_transition=np.array(prefix.parent_t, dtype=np.int32),
        representation="counts",
        _rows=prefix.rows.astype(dtype),
        _column_of_place=np.arange(len(compiled.places)),
    )


def _origins(compiled: CompiledNet) -> tuple[str, ...]:
    """Per row, the net transition it belongs to (rows are transitions or outcome variants)."""
    origin = getattr(compiled, "origin", None)
    return tuple(o[0] for o in origin) if origin else tuple(compiled.transitions)


def _resets_of(compiled: CompiledNet) -> list[tuple[int, ...]]:
    """Per row, the places its cancellation region empties (reset arcs)."""
    return list(getattr(compiled, "reset", None) or [()] * len(compiled.transitions))


def _explore(compiled: CompiledNet, m0: np.ndarray, max_states: int,
             detect_unbounded: bool, switch: int = _NUMPY_FROM_QUEUE) -> StateSpace:
    bounds = _structural_bounds(compiled, m0)
    incidence = compiled.incidence
    conservative = bool((incidence.sum(axis=1) == 0).all()) if incidence.size else True
    proven_bounded = bounds is not None and bool((bounds >= 0).all())
    has_resets = any(_resets_of(compiled))
    prefix = _python_bfs(compiled, m0, max_states, detect_unbounded and not conservative
                         and not proven_bounded and not has_resets, switch)
    if prefix.complete:
        return _space_from_prefix(compiled, prefix, max_states)
    bitmask = prefix.safe
    exact_index = False
    while True:
        explorer = _Explorer(compiled, m0, max_states, detect_unbounded, bitmask,
                             exact_index, bounds, prefix)
        try:
            return explorer.run()
        except _NotSafe:
            bitmask = False
        except _HashCollision:
            exact_index = True
