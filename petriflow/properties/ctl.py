"""Explicit CTL model checking on the reachability graph, by fixpoints, with witnesses.

Every subformula is evaluated once on every state (a Boolean vector), bottom up:
``EX`` by one step back along the edges; ``E[φ U ψ]`` (and ``EF``) as the states that
reach ``ψ`` through ``φ`` states (a backward search, linear in the edges); ``EG φ`` as
the ``φ`` states that reach, through ``φ`` states, a non-trivial strongly connected
component of the graph restricted to ``φ`` (linear too). The universal operators are
their duals: ``AX φ = ¬EX¬φ``, ``AF φ = ¬EG¬φ``, ``AG φ = ¬EF¬φ``,
``A[φ U ψ] = ¬(E[¬ψ U (¬φ ∧ ¬ψ)] ∨ EG¬ψ)``.

Deadlocks: paths are the maximal ones, a run that stops ending in its deadlock. For
``F``, ``G`` and ``U`` that is the same as a deadlock repeating itself forever (the
stutter edges of :mod:`~petriflow.properties.kripke`): ``EG p`` holds in a deadlock
satisfying ``p``. ``X`` needs a next marking, which a deadlock lacks: there ``EX p`` is
false and ``AX p`` true, whatever ``p``. That is the Model Checking Contest's reading;
its verdicts on ``AG(AX EX p ∨ …)`` in nets with deadlocks tell the two apart.

The verdict is the value at the initial marking. The evidence (:func:`ctl_witness`) is
the path of the outermost operator: for a true ``E`` formula (or a false ``A`` one, by
its dual), the firing sequence to the state that fulfils ``F``/``U``/``X``, or a lasso
for ``G`` (prefix and cycle). Formulas whose outermost operator is Boolean get no path.

Examples:
    >>> from petriflow.classic import dining_philosophers
    >>> from petriflow.analysis.reachability import reachability_graph
    >>> from petriflow.properties.kripke import STUTTER, Kripke
    >>> from petriflow.properties.language import AllPaths, ExistsPath, Finally, Globally, Fireable
    >>> kripke = Kripke(reachability_graph(dining_philosophers(3)))
    >>> live = AllPaths(Globally(ExistsPath(Finally(Fireable(("take_0",))))))
    >>> bool(evaluate(kripke, live)[0])
    True
"""

from __future__ import annotations

import numpy as np

from petriflow.analysis import components, reachable
from petriflow.properties.kripke import STUTTER, Kripke
from petriflow.properties.language import (
    AllPaths, And, ExistsPath, Finally, Formula, Globally, Next, Not, Or, Until, is_state_formula
)

__all__ = ["ctl_witness", "evaluate"]


def evaluate(kripke: Kripke, formula: Formula, cache: dict | None = None) -> np.ndarray:
    """Boolean vector: the states where the CTL ``formula`` holds."""
    cache = {} if cache is None else cache
    if formula in cache:
        return cache[formula]
    if is_state_formula(formula):
        result = kripke.holds(formula)
    elif isinstance(formula, Not):
        result = ~evaluate(kripke, formula.operand, cache)
    elif isinstance(formula, (And, Or)):
        parts = [evaluate(kripke, f, cache) for f in formula.operands]
        result = np.logical_and.reduce(parts) if isinstance(formula, And) else np.logical_or.reduce(parts)
    elif isinstance(formula, ExistsPath):
        result = _exists(kripke, formula.operand, cache)
    elif isinstance(formula, AllPaths):
        result = ~_exists(kripke, _negated_path(formula.operand), cache)
    else:
        raise ValueError(f"not a CTL formula: {formula}")
    cache[formula] = result
    return result


def _negated_path(path: Formula) -> Formula:
    """The path formula ``E`` must find for ``A path`` to fail (as a formula to evaluate)."""
    if isinstance(path, Next):
        return Next(Not(path.operand))
    if isinstance(path, Finally):
        return Globally(Not(path.operand))
    if isinstance(path, Globally):
        return Finally(Not(path.operand))
    if isinstance(path, Until):
        # ¬(φ U ψ) ≡ G¬ψ ∨ (¬ψ U (¬φ ∧ ¬ψ)); kept as one node: evaluated by _exists
        return _Release(path.left, path.right)
    raise ValueError(f"not a path formula: {path}")


class _Release(Formula):
    """``¬(left U right)``, a path formula used only for ``A[left U right]``."""

    def __init__(self, left: Formula, right: Formula) -> None:
        self.left, self.right = left, right

    def children(self) -> tuple[Formula, ...]:
        return (self.left, self.right)


def _exists(kripke: Kripke, path: Formula, cache: dict) -> np.ndarray:
    if isinstance(path, Next):
        return exists_next(kripke, evaluate(kripke, path.operand, cache))
    if isinstance(path, Finally):
        return exists_until(kripke, np.ones(kripke.n, dtype=bool), evaluate(kripke, path.operand, cache))
    if isinstance(path, Until):
        return exists_until(kripke, evaluate(kripke, path.left, cache), evaluate(kripke, path.right, cache))
    if isinstance(path, Globally):
        return exists_globally(kripke, evaluate(kripke, path.operand, cache))
    if isinstance(path, _Release):
        left, right = evaluate(kripke, path.left, cache), evaluate(kripke, path.right, cache)
        return exists_until(kripke, ~right, ~left & ~right) | exists_globally(kripke, ~right)
    raise ValueError(f"not a CTL path formula under a quantifier: {path}")


def exists_next(kripke: Kripke, phi: np.ndarray) -> np.ndarray:
    """States with a successor in ``phi``: a firing, never a stutter edge, so that ``EX``
    is false and ``AX`` true in a deadlock (it has no next marking)."""
    return np.logical_or.reduceat(phi[kripke.targets] & (kripke.labels != STUTTER), kripke.offsets[:-1])


def exists_until(kripke: Kripke, phi: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """``E[φ U ψ]``: states reaching ``psi`` through ``phi`` states (backward search)."""
    offsets, predecessors = kripke.reverse
    # keep the reversed edges v <- u whose source u may continue (φ and not yet ψ)
    keep = phi[predecessors] & ~psi[predecessors]
    counts = np.add.reduceat(keep.astype(np.int64), offsets[:-1]) if len(predecessors) else \
        np.zeros(kripke.n, dtype=np.int64)
    counts[np.diff(offsets) == 0] = 0          # reduceat repeats a value for empty rows
    sub_offsets = np.zeros(kripke.n + 1, dtype=np.int64)
    np.cumsum(counts, out=sub_offsets[1:])
    starts = np.flatnonzero(psi)
    return reachable(sub_offsets, predecessors[keep], starts) if starts.size else psi.copy()


def _restricted(kripke: Kripke, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(offsets, targets, edge ids)`` of the graph keeping only edges inside ``phi``."""
    keep = phi[kripke.sources] & phi[kripke.targets]
    counts = np.bincount(kripke.sources[keep], minlength=kripke.n)
    offsets = np.zeros(kripke.n + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    return offsets, kripke.targets[keep], np.flatnonzero(keep)


def cyclic_core(kripke: Kripke, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(core, labels)``: the states of ``phi`` on a cycle inside ``phi`` (a component
    with an inner edge), and the component label of every state of the restricted graph."""
    offsets, targets, edges = _restricted(kripke, phi)
    labels = components(offsets, targets)
    sources = kripke.sources[edges]
    inner = labels[sources] == labels[targets]
    core = np.zeros(kripke.n, dtype=bool)
    cyclic = np.zeros(int(labels.max(initial=-1)) + 1, dtype=bool)
    cyclic[labels[sources[inner]]] = True
    core[phi] = cyclic[labels[phi]]
    return core, labels


def exists_globally(kripke: Kripke, phi: np.ndarray) -> np.ndarray:
    """``EG φ``: ``phi`` states reaching, through ``phi``, a cycle inside ``phi``."""
    core, _ = cyclic_core(kripke, phi)
    return exists_until(kripke, phi, core)


def lasso(kripke: Kripke, phi: np.ndarray, start: int = 0) -> tuple[list[int], list[int]] | None:
    """Edges ``(prefix, cycle)`` of a path from ``start`` that stays in ``phi`` forever."""
    core, labels = cyclic_core(kripke, phi)
    prefix = kripke.shortest_path([start], core, phi)
    if prefix is None:
        return None
    entry = kripke.end_of(prefix, start)
    same = labels == labels[entry]
    same &= phi
    # one step inside the component, then back to the entry within it
    for edge in range(kripke.offsets[entry], kripke.offsets[entry + 1]):
        nxt = int(kripke.targets[edge])
        if same[nxt]:
            goal = np.zeros(kripke.n, dtype=bool)
            goal[entry] = True
            back = kripke.shortest_path([nxt], goal, same)
            if back is not None:
                return prefix, [edge] + back
    return None


def ctl_witness(kripke: Kripke, formula: Formula, value: bool, cache: dict | None = None
                ) -> dict | None:
    """The path that shows the outermost operator's verdict at the initial marking:
    ``{"witness": [transitions], "cycle": [transitions]}`` (``cycle`` only for a lasso;
    an empty cycle: the last marking is a deadlock, repeated forever), or ``None``."""
    cache = {} if cache is None else cache
    while isinstance(formula, Not):
        formula, value = formula.operand, not value
    if isinstance(formula, AllPaths):
        if value:
            return None
        path = _negated_path(formula.operand)
    elif isinstance(formula, ExistsPath):
        if not value:
            return None
        path = formula.operand
    else:
        return None
    if isinstance(path, Next):
        target = evaluate(kripke, path.operand, cache)
        for edge in range(kripke.offsets[0], kripke.offsets[1]):
            if target[kripke.targets[edge]] and kripke.labels[edge] != STUTTER:
                return {"witness": kripke.names([edge])}
        return None
    if isinstance(path, (Finally, Until)):
        phi = np.ones(kripke.n, dtype=bool) if isinstance(path, Finally) else evaluate(kripke, path.left, cache)
        psi = evaluate(kripke, path.operand if isinstance(path, Finally) else path.right, cache)
        edges = kripke.shortest_path([0], psi, phi)
        return None if edges is None else {"witness": kripke.names(edges)}
    if isinstance(path, Globally):
        found = lasso(kripke, evaluate(kripke, path.operand, cache))
    else:           # _Release: ¬ψ until a state with ¬φ ∧ ¬ψ, or ¬ψ forever
        left, right = evaluate(kripke, path.left, cache), evaluate(kripke, path.right, cache)
        edges = kripke.shortest_path([0], ~left & ~right, ~right)
        if edges is not None:
            return {"witness": kripke.names(edges)}
        found = lasso(kripke, ~right)
    if found is None:
        return None
    prefix, cycle = found
    return {"witness": kripke.names(prefix), "cycle": kripke.names(cycle)}
