"""The result of ``petriflow check`` as data, and the parts every way of checking fills alike.

:func:`~petriflow.analysis.check.check_net` answers with one dict (its keys are
described in :mod:`~petriflow.analysis.check`). Whichever method answers
(:mod:`~petriflow.analysis.explicit`, or a reduction of
:mod:`~petriflow.analysis.methods`), it starts from the same :func:`skeleton` and fills
the same sections the same way: P-semiflows first (:func:`add_p_semiflows`), the
Karp–Miller search's note (:func:`coverability_note`), T-semiflows last within a budget
that follows the exploration's size (:func:`add_t_semiflows`). The analysis counts
exactly up to :data:`MAX_EXACT` (:func:`check_range` refuses larger weights and counts),
and :func:`plain` makes a result JSON-safe.

Examples:
    >>> from petriflow.classic import dining_philosophers
    >>> from petriflow.engine import CompiledNet
    >>> from petriflow.workflow import workflow_structure
    >>> net = dining_philosophers(3)
    >>> result = skeleton(net, workflow_structure(net), net.initial_marking)
    >>> result["places"], result["bounded"], result["violations"]
    (9, None, [])
    >>> covered = add_p_semiflows(result, CompiledNet(net), net.initial_marking, None)
    >>> result["structurally_bounded"], result["algorithm"]
    (True, ['P-semiflows cover every place: bounded for any marking'])
"""

from __future__ import annotations

from typing import Any

import numpy as np

from petriflow import limits
from petriflow.analysis.coverability import CoverabilitySearch
from petriflow.analysis.invariants import (
    DEFAULT_BUDGET,
    DEFAULT_MAX_ROWS,
    InvariantLimit,
    p_semiflows,
    structural_bounds,
    t_semiflows,
)
from petriflow.analysis.soundness import is_free_choice
from petriflow.engine import CompiledNet
from petriflow.errors import PetriflowError
from petriflow.marking import Marking
from petriflow.net import Net
from petriflow.workflow import WorkflowStructure, final_marking_of

__all__ = [
    "INVARIANT_ROWS", "MAX_EXACT", "T_BUDGET_FLOOR", "T_BUDGET_PER_EDGE",
    "add_p_semiflows", "add_t_semiflows", "check_range", "coverability_note", "explored_marking",
    "invariants_section", "plain", "quantity", "semiflows_section", "skeleton", "soundness_final",
]

#: Farkas' algorithm row limit used by :func:`~petriflow.analysis.check.check_net`.
INVARIANT_ROWS = DEFAULT_MAX_ROWS

#: Why a kind of semiflow was not computed, as the report says it.
_NOT_COMPUTED = {"budget": "over budget", "rows": "over budget", "size": "net too large",
                 "skipped": "skipped"}


def semiflows_section(section: dict[str, Any], kind: str, compiled: CompiledNet, budget: int):
    """P- or T-semiflows into ``section`` (``None`` and the reason when not computed)."""
    key = f"{kind}_semiflows"
    if budget <= 0:
        section[key] = None
        section.setdefault("not_computed", {})[key] = "skipped"
        return None
    try:
        found = (p_semiflows if kind == "p" else t_semiflows)(compiled, max_rows=INVARIANT_ROWS,
                                                              budget=budget)
    except InvariantLimit as exc:
        section[key] = None
        section.setdefault("not_computed", {})[key] = _NOT_COMPUTED[exc.reason]
        section.setdefault("note", str(exc))
        return None
    section[key] = found
    return found


def invariants_section(compiled: CompiledNet, start: Marking, budget: int) -> tuple[dict[str, Any], set[str]]:
    """The ``invariants`` section (P-semiflows) and the places they bound."""
    section: dict[str, Any] = {"p_budget": budget}
    flows = semiflows_section(section, "p", compiled, budget)
    covered: set[str] = set()
    if flows is None:
        section.update(covered_by_p_semiflows=None, structural_bounds=None)
    else:
        covered = {p for y in flows for p in y}
        section["covered_by_p_semiflows"] = len(covered) == len(compiled.places)
        section["structural_bounds"] = structural_bounds(compiled, start, semiflows_found=flows)
    if getattr(compiled, "has_resets", False):
        section["note"] = ("cancellation regions (reset arcs) only remove tokens: P-semiflows"
                           " give upper bounds y·M <= y·M0, not equalities")
    return section, covered


#: With the default budget, T-semiflows (which no verdict needs) get this many steps per
#: state and edge explored (about 2.5 times the exploration's own time), at least
#: :data:`T_BUDGET_FLOOR` and at most the P-semiflows' budget.
T_BUDGET_PER_EDGE = 100
T_BUDGET_FLOOR = 10_000_000


def add_p_semiflows(result: dict[str, Any], compiled: CompiledNet, start: Marking,
                    invariant_budget: int | None) -> set[str]:
    """Fill ``result["invariants"]`` with the P-semiflows (``invariant_budget``, by
    default :data:`~petriflow.analysis.invariants.DEFAULT_BUDGET`) and say whether they
    bound every place (``structurally_bounded``); returns the places they cover."""
    p_budget = DEFAULT_BUDGET if invariant_budget is None else invariant_budget
    result["invariants"], covered = invariants_section(compiled, start, p_budget)
    structurally_bounded = bool(result["invariants"].get("covered_by_p_semiflows"))
    result["structurally_bounded"] = structurally_bounded
    if structurally_bounded:
        result["algorithm"].append("P-semiflows cover every place: bounded for any marking")
    return covered


def add_t_semiflows(result: dict[str, Any], compiled: CompiledNet, invariant_budget: int | None,
                    explored: int) -> None:
    """Fill in the T-semiflows, last: within ``invariant_budget``, by default in
    proportion to the states and edges ``explored`` (:data:`T_BUDGET_PER_EDGE` each,
    from :data:`T_BUDGET_FLOOR` up to the P-semiflows' default budget)."""
    t_budget = invariant_budget
    if t_budget is None:
        t_budget = min(DEFAULT_BUDGET, max(T_BUDGET_FLOOR, T_BUDGET_PER_EDGE * explored))
    result["invariants"]["t_budget"] = t_budget
    semiflows_section(result["invariants"], "t", compiled, t_budget)


def explored_marking(net: Net, structure: WorkflowStructure) -> Marking:
    """The marking ``check`` explores: the net's initial marking; for a WF-net whose file
    marks no place at all (several editors store WF-nets that way), one token in ``i``.
    Soundness is always decided for ``[i]``."""
    start = net.initial_marking
    if not start and structure.is_wf_net:
        start = Marking({structure.source: 1})
    return start


def skeleton(net: Net, structure: WorkflowStructure, start: Marking) -> dict[str, Any]:
    """The result with every key present and nothing decided yet."""
    return {
        "net": net.id,
        "places": len(net.places),
        "transitions": len(net.transitions),
        "initial_marking": start.to_dict(),
        "complete": True,
        "workflow_net": structure.is_wf_net,
        "source_place": structure.source if structure.is_wf_net else None,
        "sink_place": structure.sink if structure.is_wf_net else None,
        "free_choice": is_free_choice(net),
        "final_marking": _final_marking(net, structure),
        "sound": False,
        "bounded": None,
        "safe": None,
        "deadlock_free": None,
        "dead_transitions": None,
        "live": None,
        "reversible": None,
        "states": None,
        "edges": None,
        "max_tokens_place": None,
        "max_tokens_marking": None,
        "unbounded_places": [],
        "unbounded_places_complete": None,
        "k_bound": None,
        "coverability": None,
        "violations": [],
        "algorithm": [],
    }


def _final_marking(net: Net, structure: WorkflowStructure) -> dict[str, int] | None:
    """The ``final_marking`` key: soundness's for a WF-net, else the declared one (or None)."""
    final = soundness_final(net, structure) if structure.is_wf_net else net.final_marking
    return None if final is None else final.to_dict()


def soundness_final(net: Net, structure: WorkflowStructure) -> Marking | None:
    """The final marking soundness is decided for: the net's, else one token in ``o``."""
    if not structure.is_wf_net:
        return None
    return final_marking_of(net)


def coverability_note(result: dict[str, Any], probe: CoverabilitySearch | None, budget: int) -> None:
    """The ``coverability`` section and its line in ``algorithm`` (once)."""
    if probe is None or result["coverability"] is not None:
        return
    result["coverability"] = {"nodes": probe.nodes, "edges": probe.edges, "complete": probe.complete,
                              "budget": budget}
    if not probe.complete and probe.bounded is None:
        result["algorithm"].append(f"Karp-Miller coverability search: over its budget ({budget:,} nodes)"
                                   " without finding a pump; boundedness tested during the exploration")
    elif probe.bounded:
        result["algorithm"].append("Karp-Miller coverability search: bounded (no pump)")


#: The largest arc weight or initial token count the analysis takes: counts are exact
#: 64-bit integers inside the compiled exploration, and a weight this size keeps every
#: sum exact (larger values are refused, never wrapped).
MAX_EXACT = limits.MAX_INTEGER


def check_range(net: Net) -> None:
    """Refuse weights, initial and final tokens beyond the analysis's exact range (exit 2).

    Raises:
        PetriflowError: naming the arc or place.
    """
    for arc in net.arcs:
        if arc.weight > MAX_EXACT:
            raise PetriflowError(f"arc {arc.source!r} -> {arc.target!r}: weight {arc.weight} is beyond what"
                                 f" the analysis counts exactly (at most 2**60)")
    for place, count in net.initial_marking.items():
        if count > MAX_EXACT:
            raise PetriflowError(f"place {place!r}: {count} initial tokens are beyond what the analysis"
                                 f" counts exactly (at most 2**60)")
    for place, count in (net.final_marking or {}).items():
        if count > MAX_EXACT:
            raise PetriflowError(f"place {place!r}: a final marking of {count} tokens is beyond what the"
                                 f" analysis counts exactly (at most 2**60)")


def quantity(number: int, noun: str) -> str:
    """``number`` and ``noun``, plural unless the number is one.

    Examples:
        >>> quantity(1, "token"), quantity(3, "reachable marking")
        ('1 token', '3 reachable markings')
    """
    return f"{number} {noun}" if number == 1 else f"{number} {noun}s"


def plain(value: Any) -> Any:
    """A JSON-safe copy of a :func:`check_net` result (numpy scalars to Python numbers)."""
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value
