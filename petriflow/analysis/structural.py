"""Soundness decided from the structure, in polynomial time, where the net class allows.

A WF-net is sound exactly when its short-circuited net (an extra transition ``o -> i``)
is live and bounded from ``[i]`` (van der Aalst 1997). For **free-choice** nets the Rank
Theorem (Desel and Esparza 1995, Theorem 6.24) decides liveness and boundedness without
the state space: a connected free-choice system is live and bounded iff

1. it has a positive P-semiflow (``y > 0``, ``y·C = 0``),
2. it has a positive T-semiflow (``x > 0``, ``C·x = 0``),
3. ``rank(C) = |clusters| - 1`` (a cluster: the transitions sharing input places,
   with those places, closed under that relation),
4. the initial marking marks every non-empty siphon (here: every siphon contains ``i``).

State machines (one input and one output place per transition) and marked graphs (one
input and one output transition per place) are free-choice, so the same test covers
them; the report names the class.

What it needs: an ordinary net (every weight 1), no cancellation regions (reset arcs),
free-choice on the compiled rows (outcome variants are transitions with the same preset,
which keeps a net free-choice), final marking ``[o]``. Otherwise it answers ``None``
and the state space decides.

How each condition is decided: the rank exactly (integer elimination); the siphon by
the greatest siphon avoiding ``i`` (places removed until every transition putting
tokens into the set takes one from it); the positive semiflows by linear programming
(scipy's HiGHS), each solution checked exactly in integers before it is believed. An
infeasible linear program is not a proof, so a missing positive semiflow leaves the
answer to the state space; a rank mismatch or an unmarked siphon proves the net unsound.

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> net = loads_net('''
    ... petriflow: 1
    ... places: [i, p, q, o]
    ... transitions:
    ...   - {id: split, in: [i], out: [p, q]}
    ...   - {id: left, in: [p], out: [o]}
    ...   - {id: right, in: [q], out: [o]}
    ... ''')
    >>> found = structural_soundness(net)
    >>> found.sound, found.net_class, found.reason
    (False, 'free-choice', 'rank of the incidence matrix is 4, not |clusters| - 1 = 3')
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from petriflow.analysis._linear import pivot_columns
from petriflow.engine import CompiledNet
from petriflow.net import Net

__all__ = ["StructuralVerdict", "structural_soundness"]


@dataclass
class StructuralVerdict:
    """The structural answer.

    Attributes:
        sound: ``True``/``False`` when decided, ``None`` when the net is outside the
            class or a condition could not be certified.
        net_class: ``state machine``, ``marked graph``, ``free-choice`` (or ``None``).
        reason: why it answered as it did (the failed condition, or why not decided).
        conditions: each Rank Theorem condition checked: ``True``/``False``/``None``.
    """

    sound: bool | None
    net_class: str | None
    reason: str
    conditions: dict


def _clusters(pre: list[list[int]], n_places: int) -> int:
    parent = list(range(n_places + len(pre)))

    def root(x: int) -> int:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for t, places in enumerate(pre):
        for p in places:
            a, b = root(n_places + t), root(p)
            if a != b:
                parent[a] = b
    return len({root(x) for x in range(n_places + len(pre))})


def _positive_semiflow(matrix: np.ndarray) -> bool | None:
    """Whether ``z >= 1`` with ``z·matrix = 0`` exists: ``True`` with an exactly checked
    integer solution, ``None`` when the linear program finds none (not a proof)."""
    try:
        from scipy.optimize import linprog
    except ImportError:  # pragma: no cover - scipy is a dependency
        return None
    n = matrix.shape[0]
    if matrix.shape[1] == 0:
        return True
    solved = linprog(np.ones(n), A_eq=matrix.T.astype(float), b_eq=np.zeros(matrix.shape[1]),
                     bounds=[(1, None)] * n, method="highs")
    if solved.status != 0:
        return None
    values = [Fraction(float(v)).limit_denominator(10**6) for v in solved.x]
    scale = 1
    for v in values:
        scale = scale * v.denominator // np.gcd(scale, v.denominator)
    z = [int(v * scale) for v in values]
    if min(z) < 1:
        return None
    total = [sum(z[i] * int(matrix[i, j]) for i in range(n)) for j in range(matrix.shape[1])]
    return True if not any(total) else None


def structural_soundness(net: Net, compiled: CompiledNet | None = None) -> StructuralVerdict:
    """Decide soundness of a free-choice WF-net by the Rank Theorem (see the module)."""
    from petriflow.analysis.soundness import workflow_structure

    structure = workflow_structure(net)
    if not structure.is_wf_net:
        return StructuralVerdict(None, None, "not a WF-net", {})
    compiled = compiled or CompiledNet(net)
    if compiled.has_resets:
        return StructuralVerdict(None, None, "cancellation regions (reset arcs)", {})
    if any(w != 1 for rows in (compiled.pre, compiled.post) for row in rows for _, w in row):
        return StructuralVerdict(None, None, "arc weights other than 1", {})
    final = net.final_marking
    if final is not None and final.to_dict() != {structure.sink: 1}:
        return StructuralVerdict(None, None, "a final marking other than [o]", {})
    n_places = len(compiled.places)
    i, o = compiled.place_index[structure.source], compiled.place_index[structure.sink]
    pre = [sorted(p for p, _ in row) for row in compiled.pre] + [[o]]
    post = [sorted(p for p, _ in row) for row in compiled.post] + [[i]]
    consumers: dict[int, set[int]] = {}
    for t, places in enumerate(pre):
        for p in places:
            consumers.setdefault(p, set()).add(t)
    for t, places in enumerate(pre):
        if len(places) > 1 and any(consumers[p] != {t} and
                                   any(set(pre[u]) != set(places) for u in consumers[p])
                                   for p in places):
            return StructuralVerdict(None, None, "not free-choice", {})
    producers: dict[int, set[int]] = {}
    for t, places in enumerate(post):
        for p in places:
            producers.setdefault(p, set()).add(t)
    if all(len(pre[t]) == 1 and len(post[t]) == 1 for t in range(len(pre))):
        kind = "state machine"
    elif all(len(consumers.get(p, ())) == 1 and len(producers.get(p, ())) == 1
             for p in range(n_places)):
        kind = "marked graph"
    else:
        kind = "free-choice"
    matrix = np.zeros((len(pre), n_places), dtype=np.int64)      # rows: transitions
    for t in range(len(pre)):
        for p in pre[t]:
            matrix[t, p] -= 1
        for p in post[t]:
            matrix[t, p] += 1
    conditions: dict = {}
    # 4. every siphon contains i: the greatest siphon inside P \ {i} is empty
    inside = set(range(n_places)) - {i}
    changed = True
    while changed:
        changed = False
        for p in list(inside):
            if any(not (set(pre[t]) & inside) for t in producers.get(p, ())):
                inside.discard(p)
                changed = True
    conditions["siphons_marked"] = not inside
    rank = len(pivot_columns(matrix))
    clusters = _clusters(pre, n_places)
    conditions["rank"] = rank == clusters - 1
    if inside:
        names = ", ".join(compiled.places[p] for p in sorted(inside))
        return StructuralVerdict(False, kind, f"the siphon {{{names}}} is never marked from [i]",
                                 conditions)
    if not conditions["rank"]:
        return StructuralVerdict(False, kind, f"rank of the incidence matrix is {rank}, not"
                                 f" |clusters| - 1 = {clusters - 1}", conditions)
    conditions["positive_p_semiflow"] = _positive_semiflow(matrix.T)
    conditions["positive_t_semiflow"] = _positive_semiflow(matrix)
    if conditions["positive_p_semiflow"] and conditions["positive_t_semiflow"]:
        return StructuralVerdict(True, kind, "Rank Theorem: positive P- and T-semiflows,"
                                 " rank = |clusters| - 1, every siphon marked", conditions)
    return StructuralVerdict(None, kind, "no positive semiflow found by linear programming"
                             " (not a proof): left to the state space", conditions)
