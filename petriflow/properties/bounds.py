"""Upper bounds on the tokens a set of places holds together: P-semiflows, then the states.

The contest's UpperBounds examination asks, for a set of places ``Q``, the most tokens
``Σ_{p∈Q} M(p)`` of any reachable marking ``M``. Two facts bound it: every P-semiflow
``y`` (``y·M = y·M0`` in every reachable ``M``) that covers all of ``Q`` gives
``Σ_Q M(p) ≤ ⌊y·M0 / min_{p∈Q} y[p]⌋``, and the per-place bounds it proves add up
(:func:`invariant_bound`); a reachable marking reaching a value proves the bound at
least that (:func:`reached_bound`, with its firing sequence). When the two meet, the
bound is exact without exploring further; a complete state space always makes it exact.

Examples:
    >>> from petriflow.classic import producer_consumer
    >>> invariant_bound(producer_consumer(5), ["buffer"])
    5
    >>> invariant_bound(producer_consumer(5), ["buffer", "free"])
    5
    >>> invariant_bound(producer_consumer(5), [])
    0
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from petriflow.analysis.invariants import InvariantLimit, p_semiflows
from petriflow.analysis.reachability import StateSpace
from petriflow.net import Net

__all__ = ["invariant_bound", "reached_bound"]


def invariant_bound(net: Net, places: Sequence[str], marking: Mapping[str, int] | None = None,
                    semiflows: list[dict[str, int]] | None = None) -> int | None:
    """The least upper bound the P-semiflows prove for ``Σ places``, or ``None``."""
    marking = net.initial_marking if marking is None else marking
    if semiflows is None:
        try:
            semiflows = p_semiflows(net)
        except InvariantLimit:
            return None
    wanted = list(dict.fromkeys(places))
    if not wanted:
        return 0                        # no place: the empty sum (the contest's empty place-bound)
    best: int | None = None
    per_place: dict[str, int] = {}
    for flow in semiflows:
        total = sum(w * marking.get(p, 0) for p, w in flow.items())
        for p in wanted:
            if flow.get(p, 0) > 0:
                bound = total // flow[p]
                per_place[p] = min(per_place.get(p, bound), bound)
        if all(flow.get(p, 0) > 0 for p in wanted):
            bound = total // min(flow[p] for p in wanted)
            best = bound if best is None else min(best, bound)
    if len(per_place) == len(wanted):
        summed = sum(per_place.values())
        best = summed if best is None else min(best, summed)
    return best


def reached_bound(space: StateSpace, places: Sequence[str]) -> tuple[int, int]:
    """``(value, state)``: the largest ``Σ places`` among the explored markings (a state
    reaching it first, so its :meth:`~StateSpace.path` is a shortest witness)."""
    index = {p: j for j, p in enumerate(space.places)}
    columns = [index[p] for p in dict.fromkeys(places)]
    totals = space.markings[:, columns].astype(np.int64).sum(axis=1)
    state = int(np.argmax(totals)) if totals.size else 0
    return (int(totals[state]) if totals.size else 0), state
