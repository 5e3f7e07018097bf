"""Symmetry reduction: interchangeable agents explored up to permutation.

A net built from one template for several agents (the robots of a team) has
*automorphisms*: permutations of its places and transitions that map every arc, weight,
outcome route and cancellation region onto one of the same kind. Permuting the agents
of a marking then changes nothing about what can happen next, so the state space can be
explored with one canonical marking per orbit (Starke 1991; Jensen 1996; Emerson and
Sistla 1996; Schmidt 2000).

**Finding the agents.** Candidates are the subnets built from one template: the same
agent state (``state:``) and as many places and transitions, or the groups a net
declares in ``meta.symmetric_agents`` (lists of subnet ids). For two candidates ``a``
and ``b`` the swap renames ``a`` to ``b`` and back in every node id (as whole words:
``robot1_work`` <-> ``robot2_work``, ``robot3_send_robot1`` <-> ``robot3_send_robot2``)
and is *verified*: every row of the compiled net (outcome variants included) must map
onto a row with the same preset, postset and cancellation region, and the initial and
final markings must not change. Agents whose swaps with a group's first agent all
verify form a group acting as the full symmetric group (transpositions ``(a b)``
generate it, and a composition of automorphisms is one). A candidate whose swap fails
is left out; nothing unverified is ever used. A group's agents must each own a block of
places (the places whose id names that agent and no other of the group), mapped onto
each other in the same local order; a place naming two agents of one group rules the
group out.

**Canonical markings.** Within each group the agents' blocks of counts are sorted
lexicographically: two markings have the same canonical form exactly when a
permutation of the agents maps one onto the other.

**What it preserves** (docs/analysis.md, "Symmetry reduction"): reachable markings are
the orbits of the canonical ones; the number of markings of an orbit is the multinomial
``k! / (m1! m2! ...)`` over the multiplicities of equal blocks, so ``states``, ``edges``
and the deadlock count of the full space are computed exactly. Bounds, safeness, token
maxima, deadlocks, dead transitions (up to the transitions' orbits), the three
soundness conditions and reversibility (the initial and final markings are fixed by
every permutation) are exact. Liveness is exact when it fails in some terminal
component, and when every transition is fixed by the group; otherwise it is left
undecided.

Witnesses stay concrete: the quotient path is replayed from the initial marking, each
step's transition renamed by the permutation that maps the canonical marking onto the
concrete one.

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> net = loads_net('''
    ... petriflow: 1
    ... subnets:
    ... - {id: a1, state: worker, places: [{id: a1_idle, tokens: 1}, a1_busy], transitions: [
    ...     {id: a1_go, in: [a1_idle, lock], out: [a1_busy]},
    ...     {id: a1_back, in: [a1_busy], out: [a1_idle, lock]}]}
    ... - {id: a2, state: worker, places: [{id: a2_idle, tokens: 1}, a2_busy], transitions: [
    ...     {id: a2_go, in: [a2_idle, lock], out: [a2_busy]},
    ...     {id: a2_back, in: [a2_busy], out: [a2_idle, lock]}]}
    ... places: [{id: lock, tokens: 1}]
    ... ''')
    >>> groups = find_symmetries(net)
    >>> [g.agents for g in groups]
    [['a1', 'a2']]
    >>> space = symmetric_graph(net, groups=groups)
    >>> space.num_states, space.full_states, space.full_edges
    (2, 3, 4)
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from petriflow.analysis import _symkernel as kernel
from petriflow.analysis.reachability import DEFAULT_MAX_STATES, StateSpaceLimit
from petriflow.engine import CompiledNet
from petriflow.errors import PetriflowError
from petriflow.marking import Marking
from petriflow.net import Net

__all__ = [
    "SymmetricSpace",
    "SymmetryGroup",
    "SymmetryUnsupported",
    "find_symmetries",
    "symmetric_graph",
]


class SymmetryUnsupported(PetriflowError):
    """The symmetry-reduced exploration cannot run on this net (the reason says why)."""


@dataclass
class SymmetryGroup:
    """Interchangeable agents: every permutation of them is a verified automorphism.

    Attributes:
        agents: the agent (subnet) ids, in the order of the group's blocks.
        blocks: ``len(agents) x b`` place indices (:class:`CompiledNet` order): row ``a``
            is agent ``a``'s places, in one local order shared by all agents.
    """

    agents: list[str]
    blocks: np.ndarray

    @property
    def size(self) -> int:
        return len(self.agents)


def _namer(names: list[str]):
    """A function renaming ``names`` as whole words in an id by a mapping."""
    pattern = re.compile(r"(?<![A-Za-z0-9])(" + "|".join(
        re.escape(n) for n in sorted(names, key=len, reverse=True)) + r")(?![A-Za-z0-9])")

    def rename(identifier: str, mapping: Mapping[str, str]) -> str:
        return pattern.sub(lambda m: mapping.get(m.group(1), m.group(1)), identifier)

    return rename, pattern


def _rows(compiled: CompiledNet) -> dict[str, tuple]:
    return {t: (tuple(sorted(compiled.pre[k])), tuple(sorted(compiled.post[k])),
                tuple(sorted(compiled.reset[k])))
            for k, t in enumerate(compiled.transitions)}


def _is_automorphism(compiled: CompiledNet, rows: dict[str, tuple], rename, mapping,
                     markings: list[list[int]]) -> bool:
    """Whether renaming by ``mapping`` maps the compiled net onto itself (and fixes
    ``markings``)."""
    index = compiled.place_index
    place_map = []
    for p in compiled.places:
        q = rename(p, mapping)
        if q not in index:
            return False
        place_map.append(index[q])
    if len(set(place_map)) != len(place_map):
        return False
    for vector in markings:
        if any(vector[place_map[i]] != vector[i] for i in range(len(vector))):
            return False
    for t, (pre, post, reset) in rows.items():
        u = rename(t, mapping)
        image = rows.get(u)
        if image is None:
            return False
        mapped = (tuple(sorted((place_map[p], w) for p, w in pre)),
                  tuple(sorted((place_map[p], w) for p, w in post)),
                  tuple(sorted(place_map[p] for p in reset)))
        if mapped != image:
            return False
    return True


def _candidates(net: Net) -> list[list[str]]:
    declared = (net.meta or {}).get("symmetric_agents") if isinstance(net.meta, dict) else None
    if declared:
        return [list(group) for group in declared if isinstance(group, (list, tuple))]
    places: dict[str, int] = {}
    transitions: dict[str, int] = {}
    for p in net.places.values():
        if p.subnet is not None:
            places[p.subnet] = places.get(p.subnet, 0) + 1
    for t in net.transitions.values():
        if t.subnet is not None:
            transitions[t.subnet] = transitions.get(t.subnet, 0) + 1
    by_template: dict[tuple, list[str]] = {}
    for sid, subnet in net.subnets.items():
        key = (getattr(subnet, "state", None), places.get(sid, 0), transitions.get(sid, 0))
        by_template.setdefault(key, []).append(sid)
    return [group for group in by_template.values() if len(group) > 1]


def find_symmetries(net: Net, *, compiled: CompiledNet | None = None,
                    start: Mapping[str, int] | None = None,
                    final: Mapping[str, int] | None = None) -> list[SymmetryGroup]:
    """The verified groups of interchangeable agents of ``net`` (possibly none).

    Args:
        net: the net.
        compiled: its compiled form (built when not given).
        start: the marking explored from (default: the net's initial marking); every
            permutation must fix it.
        final: a marking every permutation must also fix (the final marking of a
            WF-net, for soundness); default: the net's final marking, if any.
    """
    compiled = compiled or CompiledNet(net)
    start = net.initial_marking if start is None else start
    final = net.final_marking if final is None else final
    markings = [compiled.vector(start)] + ([compiled.vector(final)] if final else [])
    rows = _rows(compiled)
    groups: list[SymmetryGroup] = []
    used: set[str] = set()
    for candidate in _candidates(net):
        candidate = [a for a in candidate if a not in used and a in net.subnets]
        while len(candidate) > 1:
            first, rest = candidate[0], candidate[1:]
            members = [first]
            for other in rest:
                rename, _ = _namer([first, other])
                if _is_automorphism(compiled, rows, rename, {first: other, other: first}, markings):
                    members.append(other)
            candidate = [a for a in rest if a not in members]
            if len(members) > 1:
                group = _blocks(compiled, members)
                if group is not None:
                    groups.append(group)
                    used.update(members)
    return groups


def _blocks(compiled: CompiledNet, agents: list[str]) -> SymmetryGroup | None:
    """The agents' blocks of places, or ``None`` when a place names two of them."""
    rename, pattern = _namer(agents)
    owned: dict[str, list[int]] = {a: [] for a in agents}
    for i, p in enumerate(compiled.places):
        named = set(pattern.findall(p))
        if len(named) > 1:
            return None
        if named:
            owned[named.pop()].append(i)
    first = agents[0]
    local = owned[first]
    blocks = [local]
    for other in agents[1:]:
        mapping = {first: other, other: first}
        block = [compiled.place_index[rename(compiled.places[i], mapping)] for i in local]
        if sorted(block) != sorted(owned[other]):
            return None
        blocks.append(block)
    if not local:
        return None
    return SymmetryGroup(list(agents), np.asarray(blocks, dtype=np.int64))


def _padded(entries: list[tuple], width_of) -> tuple[np.ndarray, ...]:
    n = len(entries)
    width = max([len(e) for e in entries] + [1])
    places = np.zeros((n, width), dtype=np.int64)
    weights = np.zeros((n, width), dtype=np.int64)
    counts = np.zeros(n, dtype=np.int64)
    for t, entry in enumerate(entries):
        counts[t] = len(entry)
        for k, item in enumerate(entry):
            places[t, k], weights[t, k] = width_of(item)
    return places, weights, counts


@dataclass(eq=False)
class SymmetricSpace:
    """The quotient state space: one canonical marking per orbit.

    Attributes:
        places, transitions: as :class:`~petriflow.analysis.reachability.StateSpace`.
        groups: the symmetry groups used.
        markings: one row per canonical state (``uint8`` counts).
        edge_offsets, edge_target, edge_row: the quotient's edges in compressed-row form
            (state ``s``'s edges are ``edge_offsets[s]:edge_offsets[s + 1]``): each
            distinct canonical successor once, with one row that leads to it.
        parent, parent_row: the BFS tree (witnesses).
        enabled_count: per state, the rows its canonical marking enables (the
            out-degree of every marking of its orbit in the full graph).
        fired: per row, whether it was fired (one row per orbit of each marking's
            stabiliser is; :func:`transition_orbits` gives the rest).
        orbit: per state, the number of markings of its orbit (Python integers).
        complete: ``False`` when ``max_states`` stopped the exploration (the first
            ``expanded`` states then have all their edges).
        stubborn: explored with stubborn sets (:func:`symmetric_graph`): the edges are
            a reduced graph's, ``enabled_count`` counts the enabled rows that change the
            marking, ``seen_enabled`` marks the rows enabled in an explored marking.
    """

    compiled: CompiledNet = field(repr=False)
    groups: list[SymmetryGroup]
    markings: np.ndarray = field(repr=False)
    edge_offsets: np.ndarray = field(repr=False)
    edge_target: np.ndarray = field(repr=False)
    edge_row: np.ndarray = field(repr=False)
    parent: np.ndarray = field(repr=False)
    parent_row: np.ndarray = field(repr=False)
    enabled_count: np.ndarray = field(repr=False)
    fired: np.ndarray = field(repr=False)
    expanded: int
    complete: bool = True
    seen_enabled: np.ndarray | None = field(default=None, repr=False)
    stubborn: bool = False
    _orbit: list[int] | None = field(default=None, repr=False)

    @property
    def places(self) -> tuple[str, ...]:
        return tuple(self.compiled.places)

    @property
    def transitions(self) -> tuple[str, ...]:
        return tuple(self.compiled.transitions)

    @property
    def num_states(self) -> int:
        """Canonical states (orbits) found."""
        return int(self.markings.shape[0])

    @property
    def num_edges(self) -> int:
        return int(self.edge_target.shape[0])

    @property
    def out_degree(self) -> np.ndarray:
        """Per state, the rows enabled in its marking (the full graph's out-degree)."""
        return self.enabled_count

    @property
    def orbit(self) -> list[int]:
        """Per state, how many markings its orbit has (exact)."""
        if self._orbit is None:
            self._orbit = _orbit_sizes(self.markings, self.groups)
        return self._orbit

    @property
    def full_states(self) -> int:
        """Markings of the full state space (the sum of the orbits)."""
        return sum(self.orbit)

    @property
    def full_edges(self) -> int:
        """(marking, transition) pairs of the full state space."""
        degree = self.out_degree.tolist()
        return sum(o * d for o, d in zip(self.orbit, degree))

    def deadlocks(self) -> np.ndarray:
        """Canonical states enabling nothing (expanded ones only)."""
        return np.flatnonzero(self.out_degree[: self.expanded] == 0)

    def place_bounds(self) -> np.ndarray:
        """The most tokens each place holds in a reachable marking (over the orbits)."""
        top = self.markings.max(axis=0).astype(np.int64) if self.num_states else \
            np.zeros(len(self.places), dtype=np.int64)
        for group in self.groups:
            local = top[group.blocks].max(axis=0)
            top[group.blocks] = local
        return top

    def marking(self, state: int) -> Marking:
        """The canonical marking of ``state``."""
        return self.compiled.marking(self.markings[state].tolist())

    def index(self, marking: Mapping[str, int]) -> int | None:
        """The state of ``marking``'s orbit, or ``None``."""
        row = np.asarray(self.compiled.vector(marking), dtype=np.int64)
        if row.max(initial=0) > 255 or row.min(initial=0) < 0:
            return None
        canonical = canonical_row(row, self.groups)
        hits = np.flatnonzero((self.markings == canonical).all(axis=1))
        return int(hits[0]) if hits.size else None

    def quotient_path(self, state: int) -> list[int]:
        rows = []
        while state > 0:
            rows.append(int(self.parent_row[state]))
            state = int(self.parent[state])
        return rows[::-1]

    def path(self, state: int) -> list[str]:
        """A concrete firing sequence from the initial marking to a marking of
        ``state``'s orbit (the quotient path, each step renamed by the permutation
        that maps the canonical marking onto the concrete one)."""
        return concrete_path(self.compiled, self.groups, self.markings[0],
                             self.quotient_path(state))[0]

    def concrete(self, state: int) -> tuple[list[str], Marking]:
        """:meth:`path` and the concrete marking it reaches."""
        names, vector = concrete_path(self.compiled, self.groups, self.markings[0],
                                      self.quotient_path(state))
        return names, self.compiled.marking(vector)


def canonical_row(row: np.ndarray, groups: list[SymmetryGroup]) -> np.ndarray:
    """The canonical form of a count row (each group's blocks sorted)."""
    out = np.array(row, dtype=np.int64)
    for group in groups:
        values = out[group.blocks]
        order = np.lexsort(values.T[::-1])
        out[group.blocks] = values[order]
    return out


def _orbit_sizes(markings: np.ndarray, groups: list[SymmetryGroup]) -> list[int]:
    """Per canonical row, ``prod over groups of k! / prod(multiplicities!)``."""
    n = markings.shape[0]
    if not groups or n == 0:
        return [1] * n
    signatures = []
    for group in groups:
        values = markings[:, group.blocks]           # n x k x b, blocks sorted
        same = (values[:, 1:, :] == values[:, :-1, :]).all(axis=2)   # n x (k-1)
        signatures.append(same)
    keys = np.concatenate(signatures, axis=1) if len(signatures) > 1 else signatures[0]
    unique, inverse = np.unique(keys, axis=0, return_inverse=True)
    sizes = []
    for key in unique:
        total, at = 1, 0
        for group in groups:
            k = group.size
            flags = key[at: at + k - 1]
            at += k - 1
            size, run = math.factorial(k), 1
            for flag in flags:
                if flag:
                    run += 1
                else:
                    size //= math.factorial(run)
                    run = 1
            size //= math.factorial(run)
            total *= size
        sizes.append(total)
    inverse = np.asarray(inverse).reshape(-1)
    return [sizes[i] for i in inverse.tolist()]


def _renamers(compiled: CompiledNet, groups: list[SymmetryGroup]):
    names = [a for g in groups for a in g.agents]
    return _namer(names)[0] if names else None


def concrete_path(compiled: CompiledNet, groups: list[SymmetryGroup], start_row,
                  rows: list[int]) -> tuple[list[str], list[int]]:
    """Replay a quotient path (rows fired in canonical markings) from the concrete
    initial marking: ``(transition ids fired, the concrete marking reached)``.

    ``start_row`` may be any concrete marking (the initial marking, fixed by every
    permutation, is its own canonical form): before each step the concrete marking is
    mapped onto its canonical form by sorting each group's blocks, and that order
    renames the next transition."""
    rename = _renamers(compiled, groups)
    vector = [int(x) for x in start_row]
    start = np.asarray(vector, dtype=np.int64)
    # canonical agent j = concrete agent order[j]
    order = [np.lexsort(start[g.blocks].T[::-1]).tolist() for g in groups]
    fired: list[str] = []
    for row in rows:
        mapping = {g.agents[j]: g.agents[order[gi][j]] for gi, g in enumerate(groups)
                   for j in range(g.size)}
        name = compiled.transitions[row]
        concrete = rename(name, mapping) if rename else name
        t = compiled.transition_index[concrete]
        if any(vector[p] < w for p, w in compiled.pre[t]):   # pragma: no cover - a bug if hit
            raise RuntimeError(f"symmetry witness: {concrete} is not enabled")
        compiled.consume(vector, t)
        compiled.produce(vector, t)
        fired.append(concrete)
        array = np.asarray(vector, dtype=np.int64)
        for gi, group in enumerate(groups):
            values = array[group.blocks]
            order[gi] = np.lexsort(values.T[::-1]).tolist()
    return fired, vector


def transition_orbits(compiled: CompiledNet, groups: list[SymmetryGroup]) -> np.ndarray:
    """Per row, the id of its orbit under the groups (the smallest row index in it)."""
    n = len(compiled.transitions)
    parent = list(range(n))

    def root(x: int) -> int:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for group in groups:
        first = group.agents[0]
        for other in group.agents[1:]:
            rename, _ = _namer([first, other])
            mapping = {first: other, other: first}
            for t, name in enumerate(compiled.transitions):
                u = compiled.transition_index[rename(name, mapping)]
                a, b = root(t), root(u)
                if a != b:
                    parent[max(a, b)] = min(a, b)
    return np.asarray([root(t) for t in range(n)], dtype=np.int64)


def symmetric_graph(net: Net, start: Mapping[str, int] | None = None, *,
                    groups: list[SymmetryGroup] | None = None,
                    max_states: int = DEFAULT_MAX_STATES,
                    compiled: CompiledNet | None = None,
                    stubborn: bool = False) -> SymmetricSpace:
    """Explore the canonical markings reachable from ``start``.

    With ``stubborn``, each marking fires only a stubborn set of the rows that change
    the marking (:func:`~petriflow.analysis.stubborn.relations`): the quotient of a
    stubborn-set reduced graph, which keeps every deadlock and, from each of its
    markings, whether a deadlock can be reached (docs/analysis.md); ``enabled_count``
    then counts the enabled rows that change the marking, and ``seen_enabled`` marks
    the rows enabled in some explored marking. The net must have no reset arcs.

    The net must be bounded with at most 255 tokens in a place (the caller proves
    boundedness first; a count beyond 255 raises :class:`SymmetryUnsupported`).

    Raises:
        StateSpaceLimit: more than ``max_states`` canonical markings; ``partial`` is
            the :class:`SymmetricSpace` explored so far.
        SymmetryUnsupported: counts beyond 255, or a start marking some permutation
            moves.
    """
    compiled = compiled or CompiledNet(net)
    start = net.initial_marking if start is None else Marking(start)
    groups = find_symmetries(net, compiled=compiled, start=start) if groups is None else groups
    vector = np.asarray(compiled.vector(start), dtype=np.int64)
    if vector.max(initial=0) > 255:
        raise SymmetryUnsupported("more than 255 tokens in a place")
    if not np.array_equal(canonical_row(vector, groups), vector) or any(
            (vector[g.blocks] != vector[g.blocks][0]).any() for g in groups):
        raise SymmetryUnsupported("the start marking is not fixed by the agents' permutations")
    pre_p, pre_w, pre_n = _padded([compiled.pre[t] for t in range(len(compiled.transitions))],
                                  lambda e: e)
    post_p, post_w, post_n = _padded([compiled.post[t] for t in range(len(compiled.transitions))],
                                     lambda e: e)
    reset_p, _, reset_n = _padded([compiled.reset[t] for t in range(len(compiled.transitions))],
                                  lambda e: (e, 0))
    group_k = np.asarray([g.size for g in groups], dtype=np.int64)
    group_b = np.asarray([g.blocks.shape[1] for g in groups], dtype=np.int64)
    group_off = np.zeros(len(groups), dtype=np.int64)
    if groups:
        group_off[1:] = np.cumsum(group_k * group_b)[:-1]
    blocks = (np.concatenate([g.blocks.reshape(-1) for g in groups]) if groups
              else np.zeros(0, dtype=np.int64)).astype(np.int64)
    n_cols = len(compiled.places)
    cap = 1024
    ecap = 4096
    rows = np.zeros((cap, n_cols), dtype=np.uint8)
    rows[0] = vector
    hashes = np.zeros(cap, dtype=np.uint64)
    with np.errstate(over="ignore"):
        hashes[0] = kernel.row_hash(rows[0])
    table = np.zeros(4096, dtype=np.int64)
    kernel.rehash(hashes, 1, table)
    offsets = np.zeros(cap + 1, dtype=np.int64)
    edge_target = np.zeros(ecap, dtype=np.int32)
    edge_row = np.zeros(ecap, dtype=np.int32)
    parent = np.full(cap, -1, dtype=np.int32)
    parent_row = np.full(cap, -1, dtype=np.int32)
    enabled_count = np.zeros(cap, dtype=np.int32)
    seen_by = np.full(cap, -1, dtype=np.int64)
    fired = np.zeros(len(compiled.transitions), dtype=np.bool_)
    named_g, named_a, named_n = _named(compiled, groups)
    counters = np.asarray([1, 0, 0], dtype=np.int64)
    seen_enabled = np.zeros(len(compiled.transitions), dtype=np.bool_)
    from petriflow.analysis.stubborn import Relations, relations
    if stubborn and compiled.has_resets:
        raise SymmetryUnsupported("stubborn sets need a net without reset arcs")
    rel = relations(compiled) if stubborn else Relations.everything(compiled)
    while True:
        with np.errstate(over="ignore"):     # the hash wraps on purpose (plain Python)
            status = kernel.explore(rows, hashes, table, counters, offsets, edge_target, edge_row,
                                    parent, parent_row, enabled_count, seen_by, fired,
                                    seen_enabled, pre_p, pre_w, pre_n, post_p, post_w, post_n,
                                    reset_p, reset_n, group_k, group_b, group_off, blocks,
                                    named_g, named_a, named_n, rel.moves, rel.conf_ptr,
                                    rel.conf_idx, rel.inc_ptr, rel.inc_idx, rel.seed_rank,
                                    rel.seeds, rel.work_cap, max_states)
        if status == kernel.OK or status == kernel.LIMIT:
            break
        if status == kernel.OVERFLOW:
            raise SymmetryUnsupported("more than 255 tokens in a place")
        if status == kernel.GROW:
            n, ne = int(counters[0]), int(counters[2])
            if n + len(compiled.transitions) > rows.shape[0]:
                cap = min(2 * rows.shape[0], max_states + 1) + len(compiled.transitions) + 1
                rows = _grown(rows, cap)
                hashes = _grown(hashes, cap)
                offsets = _grown(offsets, cap + 1)
                parent = _grown(parent, cap)
                parent_row = _grown(parent_row, cap)
                enabled_count = _grown(enabled_count, cap)
                seen_by = _grown(seen_by, cap)
            if ne + len(compiled.transitions) > edge_target.shape[0]:
                ecap = 2 * edge_target.shape[0] + len(compiled.transitions)
                edge_target = _grown(edge_target, ecap)
                edge_row = _grown(edge_row, ecap)
        elif status == kernel.REHASH:
            table = np.zeros(table.shape[0] * 4, dtype=np.int64)
            kernel.rehash(hashes, int(counters[0]), table)
    n, head, ne = (int(x) for x in counters)
    space = SymmetricSpace(compiled, groups, rows[:n].copy(), offsets[: head + 1].copy(),
                           edge_target[:ne].copy(), edge_row[:ne].copy(), parent[:n].copy(),
                           parent_row[:n].copy(), enabled_count[:n].copy(), fired,
                           expanded=head, complete=head == n, seen_enabled=seen_enabled,
                           stubborn=stubborn)
    if not space.complete:
        # states beyond the expanded ones have no edges yet
        offsets_full = np.concatenate([space.edge_offsets,
                                       np.full(n - head, ne, dtype=np.int64)])
        space.edge_offsets = offsets_full
        raise StateSpaceLimit(max_states, n, head, partial=space)
    return space


def _named(compiled: CompiledNet, groups: list[SymmetryGroup]):
    """Per row, the distinct agents its id names, in order of first appearance, as
    (group, agent index) arrays padded to the widest row."""
    names = {a: (g, k) for g, group in enumerate(groups) for k, a in enumerate(group.agents)}
    found = []
    if names:
        _, pattern = _namer(list(names))
        for t in compiled.transitions:
            seen = list(dict.fromkeys(pattern.findall(t)))
            found.append([names[a] for a in seen])
    else:
        found = [[] for _ in compiled.transitions]
    width = max([len(f) for f in found] + [1])
    named_g = np.zeros((len(found), width), dtype=np.int64)
    named_a = np.zeros((len(found), width), dtype=np.int64)
    named_n = np.asarray([len(f) for f in found], dtype=np.int64)
    for t, pairs in enumerate(found):
        for k, (g, a) in enumerate(pairs):
            named_g[t, k], named_a[t, k] = g, a
    return named_g, named_a, named_n


def _grown(array: np.ndarray, size: int) -> np.ndarray:
    out = np.zeros((size,) + array.shape[1:], dtype=array.dtype)
    out[: array.shape[0]] = array
    return out
