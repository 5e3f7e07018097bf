"""LTL model checking: Spot's Büchi automaton of the negation, times the reachability graph.

``A ψ`` holds when no infinite path from the initial marking satisfies ``¬ψ``. Spot
(:mod:`spot`, the ``spottl`` wheel: the LTL-to-automaton translator contest tools use)
translates ``¬ψ`` into a state-based Büchi automaton whose edges carry Boolean guards over
ψ's atoms (its maximal state predicates: ``p0``, ``p1``...). Each guard is evaluated on
every marking at once; the product's edges are then built as arrays: ``(s, q) → (s', q')``
for every firing ``s → s'`` and automaton edge ``q → q'`` whose guard holds in ``s``
(the automaton reads the marking being left). The search keeps the product states
reachable from ``(M0, q0)`` and looks for a strongly connected component holding an
accepting edge: one exists exactly when some path violates ψ, and the counterexample is
a lasso (a firing sequence to the cycle, then the cycle). ``E ψ`` is ``¬A¬ψ``, with the
lasso as its witness.

Paths are infinite: a deadlock repeats its marking forever
(:mod:`~petriflow.properties.kripke`), as in the Model Checking Contest. ``X`` is then
well defined everywhere (the next marking of a deadlock is itself).

Examples:
    >>> from petriflow.classic import dining_philosophers
    >>> from petriflow.analysis.reachability import reachability_graph
    >>> from petriflow.properties.kripke import Kripke
    >>> from petriflow.properties.language import Finally, Fireable, Globally
    >>> kripke = Kripke(reachability_graph(dining_philosophers(3)))
    >>> check_ltl(kripke, Globally(Finally(Fireable(("take_0",)))))  # every cycle passes M0
    (True, None)
    >>> verdict, lasso = check_ltl(kripke, Finally(Fireable(("release_0",))))
    >>> verdict, lasso["witness"], lasso["cycle"]
    (False, [], ['take_1', 'release_1'])
"""

from __future__ import annotations

import numpy as np

from petriflow.analysis import components, csr, reachable, shortest_path
from petriflow.errors import PetriflowError
from petriflow.properties.kripke import Kripke
from petriflow.properties.language import (
    AllPaths, And, Constant, ExistsPath, Finally, Formula, Globally, Next, Not, Or, Until, atoms
)

__all__ = ["check_ltl", "to_spot"]


def to_spot(formula: Formula, names: dict[Formula, str]) -> str:
    """Spot's syntax for a quantifier-free path formula, atoms named by ``names``."""
    if formula in names:
        return names[formula]
    if isinstance(formula, Constant):
        return "1" if formula.value else "0"
    if isinstance(formula, Not):
        return f"!({to_spot(formula.operand, names)})"
    if isinstance(formula, (And, Or)):
        if not formula.operands:
            return "1" if isinstance(formula, And) else "0"
        joiner = " & " if isinstance(formula, And) else " | "
        return "(" + joiner.join(to_spot(f, names) for f in formula.operands) + ")"
    if isinstance(formula, (Next, Finally, Globally)):
        op = {Next: "X", Finally: "F", Globally: "G"}[type(formula)]
        return f"{op}({to_spot(formula.operand, names)})"
    if isinstance(formula, Until):
        return f"(({to_spot(formula.left, names)}) U ({to_spot(formula.right, names)}))"
    raise ValueError(f"not an LTL path formula: {formula}")


def _spot():
    try:
        import spot
    except ImportError as exc:  # pragma: no cover - spottl is a dependency
        raise PetriflowError("LTL needs Spot: pip install spottl") from exc
    return spot


def _guard(spot, formula, values: dict[str, np.ndarray], n: int) -> np.ndarray:
    """A Spot Boolean formula (an automaton edge's guard) on every state."""
    kind = formula.kind()
    if kind == spot.op_tt:
        return np.ones(n, dtype=bool)
    if kind == spot.op_ff:
        return np.zeros(n, dtype=bool)
    if kind == spot.op_ap:
        return values[formula.ap_name()]
    if kind == spot.op_Not:
        return ~_guard(spot, formula[0], values, n)
    parts = [_guard(spot, f, values, n) for f in formula]
    if kind == spot.op_And:
        return np.logical_and.reduce(parts)
    if kind == spot.op_Or:
        return np.logical_or.reduce(parts)
    raise ValueError(f"unexpected guard {formula}")


def check_ltl(kripke: Kripke, formula: Formula) -> tuple[bool, dict | None]:
    """``(verdict, evidence)`` of an LTL formula at the initial marking.

    ``formula`` is ``A ψ``, ``E ψ`` or a bare path formula ``ψ`` (read as ``A ψ``).
    The evidence is a lasso ``{"witness": prefix, "cycle": cycle}`` (firing sequences):
    a run violating ``A ψ``, or a run satisfying ``E ψ``; ``None`` otherwise.
    """
    exists = isinstance(formula, ExistsPath)
    body = formula.operand if isinstance(formula, (AllPaths, ExistsPath)) else formula
    found = _accepting_lasso(kripke, body if exists else Not(body))
    if exists:
        return found is not None, found
    return found is None, found


def _accepting_lasso(kripke: Kripke, path: Formula) -> dict | None:
    """A lasso of the graph that satisfies ``path``, or ``None`` when there is none."""
    spot = _spot()
    names = {atom: f"p{k}" for k, atom in enumerate(atoms(path))}
    automaton = spot.translate(to_spot(path, names), "Buchi", "SBAcc")
    condition = automaton.acc()
    values = {name: kripke.holds(atom) for atom, name in names.items()}
    n, q_count = kripke.n, automaton.num_states()
    dictionary = automaton.get_dict()
    sources, targets, graph_edges, accepting = [], [], [], []
    for edge in automaton.edges():
        guard = _guard(spot, spot.bdd_to_formula(edge.cond, dictionary), values, n)
        chosen = np.flatnonzero(guard[kripke.sources])      # graph edges leaving a guard state
        if not chosen.size:
            continue
        sources.append(kripke.sources[chosen] * q_count + edge.src)
        targets.append(kripke.targets[chosen] * q_count + edge.dst)
        graph_edges.append(chosen)
        marked = condition.is_t() or (not condition.is_f() and bool(edge.acc))
        accepting.append(np.full(chosen.size, marked))
    if not sources:
        return None
    source, target = np.concatenate(sources), np.concatenate(targets)
    graph_edge, accept = np.concatenate(graph_edges), np.concatenate(accepting)
    order = np.argsort(source, kind="stable")
    source, target, graph_edge, accept = source[order], target[order], graph_edge[order], accept[order]
    size = n * q_count
    offsets, neighbours = csr(size, source, target)
    start = automaton.get_init_state_number()        # product state (M0, q0) = 0 * q + q0
    seen = reachable(offsets, neighbours, [start])
    live = seen[source]
    labels = components(offsets, neighbours)
    good = np.flatnonzero(live & accept & (labels[source] == labels[target]))
    if not good.size:
        return None
    return _lasso(kripke, offsets, neighbours, source, target, graph_edge, labels, int(good[0]), start)


def _path(offsets, neighbours, start: int, goal: int, allowed: np.ndarray | None) -> list[int] | None:
    """Product edge ids of a shortest path ``start → goal`` through ``allowed`` nodes."""
    wanted = np.zeros(len(offsets) - 1, dtype=bool)
    wanted[goal] = True
    if allowed is not None and not allowed[start]:
        allowed = allowed.copy()
        allowed[start] = True               # the start is left whatever it is
    return shortest_path(offsets, neighbours, [start], wanted, allowed)


def _lasso(kripke: Kripke, offsets, neighbours, source, target, graph_edge, labels,
           accepting_edge: int, start: int) -> dict:
    u, v = int(source[accepting_edge]), int(target[accepting_edge])
    prefix = _path(offsets, neighbours, start, u, None)
    back = _path(offsets, neighbours, v, u, labels == labels[u])
    assert prefix is not None and back is not None   # u is reachable; u and v share a component
    cycle = [accepting_edge] + back
    return {"witness": kripke.names(graph_edge[prefix].tolist()),
            "cycle": kripke.names(graph_edge[cycle].tolist())}
