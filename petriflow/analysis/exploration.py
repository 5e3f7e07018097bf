"""What every state-space search of the analysis shares.

The reachability graph (:mod:`~petriflow.analysis.reachability`), the Karp–Miller
search (:mod:`~petriflow.analysis.coverability`), the symmetry-reduced and the
stubborn-set searches all stop the same way and read the compiled net the same way:

* their budget, :data:`DEFAULT_MAX_STATES`, and :class:`StateSpaceLimit`, raised with
  what was found when a search reaches it;
* :class:`UnboundedNetError`, a proof that the net is unbounded (a firing sequence that
  pumps tokens into places, repeatable forever);
* the rows of a :class:`~petriflow.engine.CompiledNet` as the searches read them: the
  net transition a row belongs to (:func:`row_origins`), the places it changes
  (:func:`row_changes`) and the places its cancellation region empties (:func:`row_resets`).

Examples:
    >>> from petriflow.classic import producer_consumer
    >>> from petriflow.engine import CompiledNet
    >>> compiled = CompiledNet(producer_consumer(1))
    >>> row_origins(compiled) == tuple(compiled.transitions), row_resets(compiled)[0]
    (True, ())
    >>> row_changes(compiled)[0]   # the first row: the places it changes, by how much
    [(0, -1), (1, 1)]
"""

from __future__ import annotations

from typing import Any

from petriflow.engine import CompiledNet
from petriflow.errors import PetriflowError
from petriflow.marking import Marking

__all__ = ["DEFAULT_MAX_STATES", "StateSpaceLimit", "UnboundedNetError", "row_changes", "row_origins",
           "row_resets"]

#: Default limit on the number of states :func:`reachability_graph` stores.
DEFAULT_MAX_STATES = 2_000_000



class StateSpaceLimit(PetriflowError):
    """The reachable state space has more states than the limit allows.

    Attributes:
        limit: the ``max_states`` that was exceeded.
        explored: states stored when the exploration stopped.
        expanded: states whose successors had all been computed.
        partial: what was explored, as the search that stopped keeps it (for the
            reachability graph a :class:`~petriflow.analysis.reachability.StateSpace`
            whose ``expanded`` says how many of its states, the first ones, have all
            their edges); every fact read off it is a fact about the net (``None`` where
            the search keeps no graph).
    """

    def __init__(self, limit: int, explored: int, expanded: int,
                 partial: Any = None) -> None:
        self.limit = limit
        self.explored = explored
        self.expanded = expanded
        self.partial = partial
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


def row_origins(compiled: CompiledNet) -> tuple[str, ...]:
    """Per row, the net transition it belongs to (rows are transitions or outcome variants)."""
    origin = getattr(compiled, "origin", None)
    return tuple(o[0] for o in origin) if origin else tuple(compiled.transitions)


def row_resets(compiled: CompiledNet) -> list[tuple[int, ...]]:
    """Per row, the places its cancellation region empties (reset arcs)."""
    return list(getattr(compiled, "reset", None) or [()] * len(compiled.transitions))


def row_changes(compiled: CompiledNet) -> list[list[tuple[int, int]]]:
    """Per row, ``(place, post - pre)`` of the places whose count it changes: the
    incidence matrix row by row, sparse (a dense one of a large net costs gigabytes)."""
    rows = []
    for pre, post in zip(compiled.pre, compiled.post):
        delta: dict[int, int] = {}
        for p, w in pre:
            delta[p] = delta.get(p, 0) - w
        for p, w in post:
            delta[p] = delta.get(p, 0) + w
        rows.append(sorted((p, d) for p, d in delta.items() if d))
    return rows
