"""Partial-order reduction: stubborn sets for deadlocks and for reaching a marking.

In a marking ``M`` a set ``S`` of transitions is *stubborn* (Valmari 1988, 1991) when

* **D0**: ``S`` holds an enabled transition, if ``M`` enables any;
* **D1**: for every enabled ``t`` in ``S``: every transition that lowers the count of
  an input place of ``t``, and every transition with an input place whose count ``t``
  lowers, is in ``S`` (net effects: a transition that puts back what it takes lowers
  nothing), so firing transitions outside ``S`` never disables ``t`` nor is disabled
  by it, and ``t`` commutes with every sequence outside ``S``;
* **D2**: for every disabled ``t`` in ``S``: for one input place ``p`` with
  ``M(p) < W(p, t)`` (its *scapegoat*), every transition that raises the count of
  ``p`` is in ``S`` (no sequence outside ``S`` can enable ``t``).

Exploring only the enabled transitions of a stubborn set in each marking reaches every
reachable deadlock (Valmari's theorem: a sequence to a deadlock can be permuted to start
with an enabled stubborn transition), so **deadlock-freedom is preserved exactly**, and
each deadlock's witness is a real firing sequence.

**Reaching a marking** ``M*`` needs more: D0 alone may pick transitions that never lead
towards ``M*``. In a marking ``M != M*`` one place ``p`` with ``M(p) != M*(p)`` is
chosen and every transition that can move ``p`` towards ``M*`` (producing into it when
``M(p) < M*(p)``, consuming from it when ``M(p) > M*(p)``) joins ``S`` before the
closure (Schmidt 1999): any sequence from ``M`` to ``M*`` contains one of them, and it
can be moved to the front. The *ignoring problem* (a cycle of the reduced graph on which
the needed transitions are put off forever) is handled by the stack proviso of the
depth-first search: a marking with a stubborn successor on the search stack is fully
expanded.

Cancellation regions (reset arcs) change places no arc names, so nets with them are
explored with full expansion (no reduction, said in ``reduced``). Outcome routes are
separate rows sharing their transition's preset: they are in conflict with each other
and are handled by D1 like any other pair of transitions.

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> net = loads_net('''
    ... petriflow: 1
    ... places: [{id: a, tokens: 1}, {id: b, tokens: 1}, a2, b2]
    ... transitions: [{id: ta, in: [a], out: [a2]}, {id: tb, in: [b], out: [b2]}]
    ... ''')
    >>> found = stubborn_deadlocks(net)
    >>> found.deadlock, found.witness, found.states
    (True, ['ta', 'tb'], 3)
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from petriflow.analysis.reachability import DEFAULT_MAX_STATES, StateSpaceLimit
from petriflow.engine import CompiledNet
from petriflow.marking import Marking
from petriflow.net import Net

__all__ = ["Relations", "StubbornResult", "StubbornSets", "reaches_marking", "relations",
           "stubborn_deadlocks"]

#: Seeds tried per marking by the compiled search (:func:`relations`), and the most
#: relations its closures may follow in all before the search stops trying (then the
#: smallest closure found so far is fired, or every enabled row: always stubborn).
COMPILED_SEEDS = 4
COMPILED_WORK_CAP = 4096


@dataclass
class Relations:
    """The static relations of the compiled stubborn-set search, as arrays.

    Only rows that change the marking (``moves``) take part: a row whose preset equals
    its postset leads back to the marking it fires in.

    Attributes:
        moves: per row, whether firing it changes the marking.
        conf_ptr, conf_idx: per moving row ``t``, in compressed-row form, the moving rows
            that can disable ``t`` (lower the count of one of its input places) or that
            ``t`` can disable (it lowers the count of one of their input places): an
            enabled member of a stubborn set brings them all in (D1).
        inc_ptr, inc_idx: per place, the moving rows that raise its count: a disabled
            member brings in those of one input place short of tokens (D2).
        seed_rank: per row, its place among the moving rows ordered by fewest D1
            relations (seeds are tried lowest first).
        seeds, work_cap: :data:`COMPILED_SEEDS`, :data:`COMPILED_WORK_CAP`.
    """

    moves: np.ndarray
    conf_ptr: np.ndarray
    conf_idx: np.ndarray
    inc_ptr: np.ndarray
    inc_idx: np.ndarray
    seed_rank: np.ndarray
    seeds: int = COMPILED_SEEDS
    work_cap: int = COMPILED_WORK_CAP

    @classmethod
    def everything(cls, compiled: CompiledNet) -> "Relations":
        """No reduction: every row takes part and no seed is tried, so every enabled row
        is stubborn (the full search, reset arcs allowed)."""
        n_rows, n_places = len(compiled.transitions), len(compiled.places)
        empty = np.zeros(0, dtype=np.int64)
        return cls(np.ones(n_rows, dtype=np.bool_), np.zeros(n_rows + 1, dtype=np.int64), empty,
                   np.zeros(n_places + 1, dtype=np.int64), empty, np.zeros(n_rows, dtype=np.int64),
                   seeds=0)


def relations(compiled: CompiledNet, *, moving_only: bool = True) -> Relations:
    """The :class:`Relations` of a net without reset arcs (arc weights taken into
    account: a row that puts back what it takes from a place neither lowers nor raises
    it). With ``moving_only=False`` every row takes part (rows that never change the
    marking still count as enabled: a search for dead markings needs them)."""
    n_rows = len(compiled.transitions)
    n_places = len(compiled.places)
    net_effect = compiled.post_matrix - compiled.pre_matrix
    moves = (net_effect != 0).any(axis=1) if n_rows else np.zeros(0, dtype=bool)
    taking_part = moves if moving_only else np.ones(n_rows, dtype=bool)
    needers: list[list[int]] = [[] for _ in range(n_places)]
    lowerers: list[list[int]] = [[] for _ in range(n_places)]
    raisers: list[list[int]] = [[] for _ in range(n_places)]
    for t in np.flatnonzero(taking_part).tolist():
        for p, _ in compiled.pre[t]:
            needers[p].append(t)
        for p in np.flatnonzero(net_effect[t] < 0).tolist():
            lowerers[p].append(t)
        for p in np.flatnonzero(net_effect[t] > 0).tolist():
            raisers[p].append(t)
    conf: list[list[int]] = [[] for _ in range(n_rows)]
    for t in np.flatnonzero(taking_part).tolist():
        found: set[int] = set()
        for p, _ in compiled.pre[t]:
            found.update(lowerers[p])
        for p in np.flatnonzero(net_effect[t] < 0).tolist():
            found.update(needers[p])
        found.discard(t)
        conf[t] = sorted(found)
    conf_ptr, conf_idx = _csr(conf)
    inc_ptr, inc_idx = _csr(raisers)
    order = sorted(np.flatnonzero(taking_part).tolist(), key=lambda t: (len(conf[t]), t))
    rank = np.full(n_rows, n_rows, dtype=np.int64)
    rank[order] = np.arange(len(order), dtype=np.int64)
    return Relations(taking_part.astype(np.bool_), conf_ptr, conf_idx, inc_ptr, inc_idx, rank)


def _csr(lists: list[list[int]]) -> tuple[np.ndarray, np.ndarray]:
    ptr = np.zeros(len(lists) + 1, dtype=np.int64)
    ptr[1:] = np.cumsum([len(x) for x in lists])
    idx = np.asarray([u for x in lists for u in x], dtype=np.int64)
    return ptr, idx


@dataclass
class StubbornResult:
    """The answer of a stubborn-set search.

    Attributes:
        deadlock: a dead marking was found (:func:`stubborn_deadlocks`); for
            :func:`reaches_marking`, whether the target was reached.
        witness: the firing sequence from the start marking to it (``None`` if none).
        marking: the marking the witness reaches.
        states: markings the reduced search stored.
        edges: transitions it fired.
        reduced: ``False`` when the net has reset arcs and was explored in full.
        deadlocks: the dead markings found (:func:`stubborn_deadlocks`, up to ``keep``).
    """

    deadlock: bool
    witness: list[str] | None
    marking: Marking | None
    states: int
    edges: int
    reduced: bool = True
    deadlocks: list[Marking] | None = None


class StubbornSets:
    """Stubborn sets of one compiled net: :meth:`stubborn` is the D1/D2 closure of seed
    rows in a marking (a tuple indexed like the compiled net's places), its enabled
    members returned; ``reduced`` is ``False`` for a net with reset arcs (then every
    enabled row is returned); ``producers[p]`` are the rows that raise place ``p``."""

    def __init__(self, compiled: CompiledNet) -> None:
        self.compiled = compiled
        self.consumers = compiled.consumers
        self.reduced = not compiled.has_resets
        # D1 and D2 as the compiled search has them (:func:`relations`), every row taking
        # part: per row the rows it conflicts with, per place the rows that raise it
        rel = relations(compiled, moving_only=False)
        self.conflicts = [rel.conf_idx[a:b].tolist() for a, b in zip(rel.conf_ptr[:-1], rel.conf_ptr[1:])]
        self.producers = [rel.inc_idx[a:b].tolist() for a, b in zip(rel.inc_ptr[:-1], rel.inc_ptr[1:])]

    def enabled(self, m: tuple[int, ...]) -> list[int]:
        return [t for t, pre in enumerate(self.compiled.pre) if all(m[p] >= w for p, w in pre)]

    def scapegoat(self, m, t: int) -> int:
        for p, w in self.compiled.pre[t]:
            if m[p] < w:
                return p
        raise AssertionError("scapegoat of an enabled transition")  # pragma: no cover

    def stubborn(self, m, enabled: list[int], seeds: list[int]) -> list[int]:
        """The enabled transitions of the D1/D2 closure of ``seeds`` (all of ``enabled``
        when the net has reset arcs)."""
        if not self.reduced:
            return enabled
        on = set(enabled)
        best: list[int] | None = None
        # try each seed set given, and each enabled transition alone: keep the smallest
        starts = [seeds] if seeds else [[t] for t in enabled[:16]]
        for start in starts:
            inside = set(start)
            todo = list(start)
            while todo:
                t = todo.pop()
                nxt = self.conflicts[t] if t in on else self.producers[self.scapegoat(m, t)]
                for u in nxt:
                    if u not in inside:
                        inside.add(u)
                        todo.append(u)
            chosen = [t for t in enabled if t in inside]
            if chosen and (best is None or len(chosen) < len(best)):
                best = chosen
                if len(best) == 1:
                    break
        return best if best is not None else enabled

    def fire(self, m, t: int) -> tuple[int, ...]:
        vector = list(m)
        self.compiled.consume(vector, t)
        self.compiled.produce(vector, t)
        return tuple(vector)


def _path(parents: dict, state) -> list[int]:
    rows = []
    while parents[state] is not None:
        state, t = parents[state]
        rows.append(t)
    return rows[::-1]


def stubborn_deadlocks(net: Net, start: Mapping[str, int] | None = None, *,
                       max_states: int = DEFAULT_MAX_STATES, first: bool = False,
                       compiled: CompiledNet | None = None, ignore=None) -> StubbornResult:
    """Search the deadlocks of ``net`` with stubborn sets (depth first, so that a
    deadlock far from the start is met without enumerating the markings before it).

    Args:
        start: the marking to start from (default the initial marking).
        max_states: the most markings to store (beyond: :class:`StateSpaceLimit` whose
            ``partial`` is the :class:`StubbornResult` so far).
        first: stop at the first deadlock found (else collect them all).
        ignore: a marking that does not count as a deadlock (a WF-net's final marking).

    Returns:
        A :class:`StubbornResult`; ``deadlock`` is exact (D0, D1, D2 preserve every
        reachable deadlock); ``witness`` is the reduced graph's path to it (a real firing
        sequence, not always the shortest).
    """
    compiled = compiled or CompiledNet(net)
    stub = StubbornSets(compiled)
    start_marking = net.initial_marking if start is None else Marking(start)
    m0 = tuple(compiled.vector(start_marking))
    skip = tuple(compiled.vector(ignore)) if ignore is not None else None
    parents: dict = {m0: None}
    queue = [m0]
    edges = 0
    found: list[tuple[int, ...]] = []
    head = 0
    while queue:
        m = queue.pop()
        head += 1
        enabled = stub.enabled(m)
        if not enabled:
            if m != skip:
                found.append(m)
                if first:
                    break
            continue
        for t in reversed(stub.stubborn(m, enabled, [])):
            nxt = stub.fire(m, t)
            edges += 1
            if nxt not in parents:
                parents[nxt] = (m, t)
                queue.append(nxt)
                if len(parents) > max_states:
                    exc = StateSpaceLimit(max_states, len(parents), head)
                    exc.partial = _result(compiled, parents, found, len(parents), edges, stub.reduced)
                    raise exc
    return _result(compiled, parents, found, len(parents), edges, stub.reduced)


def _result(compiled, parents, found, states, edges, reduced) -> StubbornResult:
    if not found:
        return StubbornResult(False, None, None, states, edges, reduced, [])
    m = found[0]
    witness = [compiled.transitions[t] for t in _path(parents, m)]
    return StubbornResult(True, witness, compiled.marking(list(m)), states, edges, reduced,
                          [compiled.marking(list(x)) for x in found[:100]])


def reaches_marking(net: Net, target: Mapping[str, int], start: Mapping[str, int] | None = None,
                    *, max_states: int = DEFAULT_MAX_STATES,
                    compiled: CompiledNet | None = None) -> StubbornResult:
    """Whether the marking ``target`` (places not named hold no token) is reachable, by a depth-first stubborn-set search with the
    target's places in every stubborn set and the stack proviso against ignoring.

    Raises:
        StateSpaceLimit: more than ``max_states`` markings stored.

    Examples:
        >>> from petriflow.classic import dining_philosophers
        >>> net = dining_philosophers(4)
        >>> found = reaches_marking(net, {"eat_0": 1, "eat_2": 1, "think_1": 1, "think_3": 1})
        >>> found.deadlock, found.witness
        (True, ['take_0', 'take_2'])
    """
    compiled = compiled or CompiledNet(net)
    stub = StubbornSets(compiled)
    m0 = tuple(compiled.vector(net.initial_marking if start is None else Marking(start)))
    goal = tuple(compiled.vector(Marking(target)))
    parents: dict = {m0: None}
    edges = 0
    if m0 == goal:
        return StubbornResult(True, [], compiled.marking(list(m0)), 1, 0, stub.reduced)
    on_stack = {m0}
    stack = [(m0, None)]
    while stack:
        m, pending = stack[-1]
        if pending is None:
            enabled = stub.enabled(m)
            seeds: list[int] = []
            for p, (have, want) in enumerate(zip(m, goal)):
                if have != want:
                    seeds = stub.producers[p] if have < want else list(stub.consumers[p])
                    break
            if stub.reduced and seeds:
                chosen = stub.stubborn(m, enabled, seeds)
            else:
                chosen = enabled
            if any(stub.fire(m, t) in on_stack for t in chosen):
                chosen = enabled          # stack proviso: a cycle closes here
            pending = list(reversed(chosen))
            stack[-1] = (m, pending)
        if not pending:
            stack.pop()
            on_stack.discard(m)
            continue
        t = pending.pop()
        nxt = stub.fire(m, t)
        edges += 1
        if nxt in parents:
            continue
        parents[nxt] = (m, t)
        if nxt == goal:
            witness = [compiled.transitions[u] for u in _path(parents, nxt)]
            return StubbornResult(True, witness, compiled.marking(list(nxt)), len(parents), edges,
                                  stub.reduced)
        if len(parents) > max_states:
            raise StateSpaceLimit(max_states, len(parents), len(parents) - len(stack))
        stack.append((nxt, None))
        on_stack.add(nxt)
    return StubbornResult(False, None, None, len(parents), edges, stub.reduced)
