"""Stubborn sets for properties: reachability by up-sets, LTL without ``X`` by visibility.

Both searches explore, in each marking ``M``, only the enabled rows of a *stubborn set*
``S`` (:class:`~petriflow.analysis.stubborn.StubbornSets`: D1, no row outside ``S``
disables an enabled member or is disabled by it, so they commute; D2, no sequence
outside ``S`` enables a disabled member). What else ``S`` must hold depends on the
property:

* **Reachability** (``EF p``; ``AG p`` as ``EF ¬p``): in a marking where ``p`` is
  false, ``S`` holds an *up-set* of ``p`` (Schmidt 1999): rows of which every firing
  sequence from ``M`` to a marking satisfying ``p`` fires at least one. From the
  formula: for ``a·M <= k`` violated, the rows that lower ``a·M``; for ``a·M >= k``,
  those that raise it (``==``: the side it is on; ``!=``: both); ``enabled(t)`` false,
  the rows that raise one input place of ``t`` short of tokens; ``enabled(t)`` true
  where it must become false, the rows that lower an input place of ``t``; ``deadlock``,
  the same for one enabled transition; a conjunction, the up-set of one false conjunct
  (the smallest); a disjunction, the union of all. The first row of ``S`` on a shortest
  sequence to ``p`` is enabled (D2) and can be fired first (D1), leaving a sequence one
  shorter: so the reduced graph reaches a marking satisfying ``p`` whenever the full one
  does (by induction on that distance; no cycle proviso is needed), and the search stops
  at the first one with a real firing sequence. An empty up-set (``p`` cannot become
  true: ``false``, a transition with no input place that must become disabled) and a
  stubborn set with no enabled row both prune the marking: no sequence from it reaches
  ``p``.
* **LTL without X** (stutter-invariant): Peled's ample-set conditions on the product of
  the markings and the Büchi automaton, searched on the fly
  (:func:`~petriflow.properties.ltl.check_ltl_on_net`). A row is *visible* when it
  changes the count of a place some atom reads (a token count's places, the input
  places of the transitions ``enabled(...)`` names, of every transition for
  ``deadlock``). A marking is reduced only to a stubborn set grown from an enabled
  invisible row whose enabled members are all invisible (C2), fewer than all enabled
  rows; and a product state with a reduced successor on the depth-first stack is fully
  expanded (C3, the stack proviso: every cycle of the reduced product holds a fully
  expanded state). Formulas with ``X`` keep the full search.

Nets with reset arcs (cancellation regions) are never reduced: every enabled row is
explored.

Examples:
    >>> from petriflow.classic import dining_philosophers
    >>> from petriflow.properties.yaml_props import parse_formula
    >>> net = dining_philosophers(5)
    >>> found = reach_stubborn(net, net.initial_marking, parse_formula("eat_0 + eat_2 == 2"),
    ...                        max_states=1000)
    >>> found.found, found.witness
    (True, ['take_0', 'take_2'])
    >>> reach_stubborn(net, net.initial_marking, parse_formula("eat_0 + eat_1 == 2"),
    ...                max_states=1000).found       # neighbours share a fork
    False
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from petriflow.analysis.exploration import StateSpaceLimit
from petriflow.analysis.stubborn import StubbornSets
from petriflow.engine import CompiledNet
from petriflow.net import Net
from petriflow.properties.language import (
    And, Compare, Constant, Deadlock, Fireable, Formula, Next, Not, Or
)
from petriflow.properties.monitor import compile_predicate

__all__ = ["LTL_SEEDS", "PropertyStubbornSets", "ReachResult", "has_next", "reach_stubborn"]

#: Enabled invisible rows tried as seeds of an LTL stubborn set per marking (the
#: smallest closure with no enabled visible row is kept).
LTL_SEEDS = 8

_NEGATED = {"<=": ">", "<": ">=", ">=": "<", ">": "<=", "==": "!=", "!=": "=="}


def has_next(formula: Formula) -> bool:
    """Whether ``X`` occurs in the formula (then no stubborn-set reduction applies)."""
    return any(isinstance(node, Next) for node in formula.walk())


@dataclass
class ReachResult:
    """The answer of :func:`reach_stubborn`.

    Attributes:
        found: a marking satisfying the goal is reachable.
        witness: row ids of a firing sequence from the start to it (``None`` if none).
        states: markings the reduced search stored.
        edges: firings it made.
        reduced: ``False`` when the net has reset arcs and was explored in full.
    """

    found: bool
    witness: list[str] | None
    states: int
    edges: int
    reduced: bool


class PropertyStubbornSets:
    """The stubborn sets of one net for the properties of the module documentation."""

    def __init__(self, net: Net, compiled: CompiledNet | None = None) -> None:
        self.net = net
        self.compiled = compiled or CompiledNet(net)
        self.sets = StubbornSets(self.compiled)
        self.reduced = self.sets.reduced
        self.effect = self.compiled.incidence
        index = self.compiled.place_index
        self.lowerers = [np.flatnonzero(self.effect[:, p] < 0).tolist() for p in range(len(index))]
        self.preset = {t: [(index[p], w) for p, w in net.preset(t).items()] for t in net.transitions}
        self._checks: dict[Formula, object] = {}
        self._slopes: dict[Formula, tuple] = {}

    def holds(self, formula: Formula, m) -> bool:
        """The state predicate in marking ``m`` (compiled once per formula)."""
        check = self._checks.get(formula)
        if check is None:
            check = self._checks[formula] = compile_predicate(self.net, formula, self.compiled.place_index)
        return bool(check(m))  # type: ignore[operator]

    def fire(self, m, t: int) -> tuple[int, ...]:
        return self.sets.fire(m, t)

    # -- reachability -------------------------------------------------------------------

    def up_set(self, goal: Formula, m) -> set[int]:
        """Rows of which every firing sequence from ``m`` (where ``goal`` is false) to a
        marking where it holds fires one (module documentation)."""
        if isinstance(goal, Not):
            return self._up_negated(goal.operand, m)
        if isinstance(goal, Constant):
            return set()
        if isinstance(goal, Compare):
            return self._up_compare(goal.op, goal, m)
        if isinstance(goal, Fireable):
            rows: set[int] = set()
            for t in goal.transitions:
                short = [p for p, w in self.preset[t] if m[p] < w]
                rows.update(self.sets.producers[short[0]])
            return rows
        if isinstance(goal, Deadlock):
            return self._up_disable(m)
        if isinstance(goal, And):
            options = [self.up_set(f, m) for f in goal.operands if not self.holds(f, m)]
            return min(options, key=len)
        if isinstance(goal, Or):
            rows = set()
            for f in goal.operands:
                rows.update(self.up_set(f, m))
            return rows
        raise ValueError(f"not a state predicate: {goal}")

    def _up_negated(self, inner: Formula, m) -> set[int]:
        """Up-set of ``¬inner`` (``inner`` true in ``m``): negation pushed inwards."""
        if isinstance(inner, Not):
            return self.up_set(inner.operand, m)
        if isinstance(inner, Constant):
            return set()
        if isinstance(inner, Compare):
            return self._up_compare(_NEGATED[inner.op], inner, m)
        if isinstance(inner, Fireable):        # every named transition must become disabled
            enabled = [t for t in inner.transitions if all(m[p] >= w for p, w in self.preset[t])]
            return min((self._lowering(t) for t in enabled), key=len)
        if isinstance(inner, Deadlock):        # m is dead: any row (none is enabled anyway)
            return set(range(len(self.compiled.transitions)))
        if isinstance(inner, (And, Or)):
            flipped = Or if isinstance(inner, And) else And
            return self.up_set(flipped(tuple(Not(f) for f in inner.operands)), m)
        raise ValueError(f"not a state predicate: {inner}")

    def _lowering(self, t: str) -> set[int]:
        """Rows that lower an input place of ``t``: one fires before ``t`` is disabled."""
        rows: set[int] = set()
        for p, _ in self.preset[t]:
            rows.update(self.lowerers[p])
        return rows

    def _up_disable(self, m) -> set[int]:
        """Up-set of ``deadlock``: every enabled transition must become disabled; one of them
        (the one fewest rows can disable) is enough."""
        enabled = [t for t, pre in self.preset.items() if all(m[p] >= w for p, w in pre)]
        return min((self._lowering(t) for t in enabled), key=len)

    def _up_compare(self, op: str, node: Compare, m) -> set[int]:
        """Up-set of ``left op right`` (false in ``m``)."""
        known = self._slopes.get(node)
        if known is None:
            index = self.compiled.place_index
            expression = node.left.plus(node.right, -1)
            slope = np.zeros(len(self.compiled.transitions), dtype=np.int64)
            for place, k in expression.terms:
                slope += k * self.effect[:, index[place]]
            terms = [(index[p], k) for p, k in expression.terms]
            known = self._slopes[node] = (terms, expression.offset, set(np.flatnonzero(slope < 0).tolist()),
                                          set(np.flatnonzero(slope > 0).tolist()),
                                          set(np.flatnonzero(slope != 0).tolist()))
        terms, offset, lowering, raising, changing = known
        if op in ("<=", "<"):
            return lowering
        if op in (">=", ">"):
            return raising
        if op == "==":
            return lowering if sum(k * m[p] for p, k in terms) + offset > 0 else raising
        return changing

    def reach_set(self, goal: Formula, m) -> list[int]:
        """The enabled rows to explore from ``m`` (where ``goal`` is false)."""
        enabled = self.compiled.enabled(m)
        if not enabled or not self.reduced:
            return enabled
        seeds = self.up_set(goal, m)
        if not seeds:
            return []
        return self.closure(m, enabled, sorted(seeds)) or []

    def closure(self, m, enabled: list[int], seeds, visible: np.ndarray | None = None) -> list[int] | None:
        """The enabled rows of the D1/D2 closure of ``seeds`` in ``m``; ``None`` when an
        enabled ``visible`` row would join it."""
        on = set(enabled)
        inside = set(seeds)
        todo = list(seeds)
        conflicts, producers, pre = self.sets.conflicts, self.sets.producers, self.compiled.pre
        met = len(on.intersection(inside))        # enabled members met so far
        add, push = inside.add, todo.append
        while todo:
            t = todo.pop()
            if t in on:
                if visible is not None and visible[t]:
                    return None
                if visible is None and met == len(on):
                    return enabled                # every enabled row is in: no reduction
                nxt = conflicts[t]
            else:                                 # D2: the raisers of its first place short of tokens
                for p, w in pre[t]:
                    if m[p] < w:
                        nxt = producers[p]
                        break
            for u in nxt:
                if u not in inside:
                    add(u)
                    push(u)
                    if u in on:
                        met += 1
        return [t for t in enabled if t in inside]

    # -- LTL without X ------------------------------------------------------------------

    def visible(self, atoms: list[Formula]) -> np.ndarray:
        """Per row: whether it changes the count of a place one of ``atoms`` reads."""
        index = self.compiled.place_index
        read: set[int] = set()
        for atom in atoms:
            for node in atom.walk():
                if isinstance(node, Compare):
                    read.update(index[p] for p, _ in node.left.terms + node.right.terms)
                elif isinstance(node, Fireable):
                    read.update(p for t in node.transitions for p, _ in self.preset[t])
                elif isinstance(node, Deadlock):
                    read.update(p for pre in self.preset.values() for p, _ in pre)
        columns = sorted(read)
        if not columns:
            return np.zeros(len(self.compiled.transitions), dtype=bool)
        return (self.effect[:, columns] != 0).any(axis=1)

    def ltl_set(self, m, enabled: list[int], visible: np.ndarray) -> list[int] | None:
        """A stubborn set's enabled rows, all invisible and fewer than ``enabled`` (C0-C2),
        or ``None`` (explore every enabled row)."""
        if len(enabled) < 2 or not self.reduced:
            return None
        best: list[int] | None = None
        for seed in [t for t in enabled if not visible[t]][:LTL_SEEDS]:
            chosen = self.closure(m, enabled, [seed], visible)
            if chosen is not None and len(chosen) < len(enabled) and (best is None or len(chosen) < len(best)):
                best = chosen
                if len(best) == 1:
                    break
        return best


def reach_stubborn(net: Net, start: Mapping[str, int], goal: Formula, *, max_states: int,
                   sets: PropertyStubbornSets | None = None) -> ReachResult:
    """Whether a marking satisfying the state predicate ``goal`` is reachable from
    ``start``: a depth-first search of the up-set-reduced graph, stopped at the first
    such marking (module documentation).

    Raises:
        StateSpaceLimit: more than ``max_states`` markings stored before deciding.
    """
    sets = sets or PropertyStubbornSets(net)
    compiled = sets.compiled
    m0 = tuple(compiled.vector(start))
    parents: dict = {m0: None}
    if sets.holds(goal, m0):
        return ReachResult(True, [], 1, 0, sets.reduced)
    stack = [m0]
    edges = 0
    while stack:
        m = stack.pop()
        for t in reversed(sets.reach_set(goal, m)):
            nxt = sets.fire(m, t)
            edges += 1
            if nxt in parents:
                continue
            parents[nxt] = (m, t)
            if sets.holds(goal, nxt):
                rows = []
                state = nxt
                while parents[state] is not None:
                    state, u = parents[state]
                    rows.append(compiled.transitions[u])
                return ReachResult(True, rows[::-1], len(parents), edges, sets.reduced)
            if len(parents) > max_states:
                raise StateSpaceLimit(max_states, len(parents), len(parents) - len(stack))
            stack.append(nxt)
    return ReachResult(False, None, len(parents), edges, sets.reduced)
