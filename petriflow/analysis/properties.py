"""Behavioural properties read off a reachability graph: bounds, deadlocks, liveness.

Every function takes the :class:`~petriflow.analysis.reachability.StateSpace` of a
bounded net (build it once with
:func:`~petriflow.analysis.reachability.reachability_graph`, then ask it many things):

* :func:`place_bounds` / :func:`is_safe` — the k-bound of every place;
* :func:`deadlocks` and :func:`deadlock_witness` — markings enabling nothing, and a
  shortest firing sequence to one;
* :func:`dead_transitions` — transitions no reachable marking enables (not L1-live);
* :func:`is_live` / :func:`non_live_transitions` — L4-liveness: from every reachable
  marking every transition can fire again. In a finite reachability graph this holds
  exactly when every terminal strongly connected component (one no edge leaves) contains
  an edge of every transition;
* :func:`is_reversible` — the initial marking is a home marking (reachable from every
  reachable marking), i.e. the graph is strongly connected.

Examples:
    >>> from petriflow.classic import dining_philosophers
    >>> from petriflow.analysis.reachability import reachability_graph
    >>> space = reachability_graph(dining_philosophers(3))
    >>> is_safe(space), deadlocks(space).tolist(), dead_transitions(space)
    (True, [], [])
    >>> is_live(space), is_reversible(space)
    (True, True)
"""

from __future__ import annotations

import numpy as np

from petriflow.analysis._graph import components, occurring, terminal_summary_csr
from petriflow.analysis.reachability import StateSpace

__all__ = [
    "dead_transitions",
    "deadlock_witness",
    "deadlocks",
    "is_live",
    "is_reversible",
    "is_safe",
    "non_live_transitions",
    "non_live_witness",
    "place_bounds",
    "strongly_connected_components",
    "terminal_components",
]


def place_bounds(space: StateSpace) -> dict[str, int]:
    """``{place: k}``: the most tokens the place holds in any reachable marking.

    Examples:
        >>> from petriflow.classic import producer_consumer
        >>> from petriflow.analysis.reachability import reachability_graph
        >>> place_bounds(reachability_graph(producer_consumer(2)))["buffer"]
        2
    """
    return {p: int(k) for p, k in zip(space.places, space.place_bounds())}


def is_safe(space: StateSpace) -> bool:
    """Whether no reachable marking puts two tokens in one place (1-bounded)."""
    return space.safe


def deadlocks(space: StateSpace) -> np.ndarray:
    """Ids of the reachable states that enable no transition (increasing; the first one is
    nearest to the initial marking, states being numbered breadth first)."""
    return space.deadlocks()


def deadlock_witness(space: StateSpace) -> list[str] | None:
    """A shortest firing sequence from the initial marking to a deadlock, or ``None``.

    Examples:
        >>> from petriflow.io.yaml import loads_net
        >>> from petriflow.analysis.reachability import reachability_graph
        >>> net = loads_net('''
        ... petriflow: 1
        ... places: [{id: a, tokens: 1}, b, c]
        ... transitions: [{id: go, in: [a], out: [b]}, {id: stop, in: [b], out: [c]}]
        ... ''')
        >>> deadlock_witness(reachability_graph(net))
        ['go', 'stop']
    """
    found = deadlocks(space)
    return space.path(int(found[0])) if found.size else None


def _net_transitions(space: StateSpace, rows) -> list[str]:
    """Net transition ids of some rows (outcome variants fold into their transition)."""
    return list(dict.fromkeys(space.origins[int(r)] for r in rows))


def dead_transitions(space: StateSpace) -> list[str]:
    """Transitions enabled in no reachable marking, in net order.

    (The outcome variants ``t@failed`` of a transition share its preset, so they are
    enabled exactly when it is; the answer names net transitions.)
    """
    fired = occurring(space.edge_transition, len(space.transitions))
    return _net_transitions(space, np.flatnonzero(~fired))


def strongly_connected_components(space: StateSpace) -> np.ndarray:
    """Component label of every state (equal labels: mutually reachable states)."""
    return components(space.edge_offsets, space.edge_target)


def terminal_components(space: StateSpace, labels: np.ndarray | None = None) -> list[int]:
    """Labels of the components no edge leaves (every run ends up in one of them)."""
    labels = strongly_connected_components(space) if labels is None else labels
    return _terminal(space, labels)[0].tolist()


def _terminal(space: StateSpace, labels: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(terminal, first, present)``: the terminal components' labels, their smallest
    states, and which transitions fire inside each (one row per component)."""
    return terminal_summary_csr(space.edge_offsets, space.edge_target, labels,
                                space.edge_transition, len(space.transitions))


def non_live_transitions(space: StateSpace, labels: np.ndarray | None = None) -> list[str]:
    """Transitions that are not live: some reachable marking never lets them fire again.

    Examples:
        >>> from petriflow.classic import producer_consumer
        >>> from petriflow.analysis.reachability import reachability_graph
        >>> non_live_transitions(reachability_graph(producer_consumer(2)))
        []
    """
    labels = strongly_connected_components(space) if labels is None else labels
    missing = ~_terminal(space, labels)[2].all(axis=0)
    return _net_transitions(space, np.flatnonzero(missing))


def non_live_witness(space: StateSpace, labels: np.ndarray | None = None
                     ) -> tuple[list[str], list[str]] | None:
    """``(sequence, transitions)``: a shortest firing sequence into a terminal component
    where ``transitions`` can never fire again, or ``None`` when the net is live."""
    labels = strongly_connected_components(space) if labels is None else labels
    _, first, present = _terminal(space, labels)
    lacking = np.flatnonzero(~present.all(axis=1))
    if not lacking.size:
        return None
    row = lacking[np.argmin(first[lacking])]
    return space.path(int(first[row])), _net_transitions(space, np.flatnonzero(~present[row]))


def is_live(space: StateSpace, labels: np.ndarray | None = None) -> bool:
    """Whether every transition is live (L4) from the initial marking."""
    return not non_live_transitions(space, labels)


def is_reversible(space: StateSpace, labels: np.ndarray | None = None) -> bool:
    """Whether the initial marking can be reached again from every reachable marking."""
    labels = strongly_connected_components(space) if labels is None else labels
    return bool((labels == labels[0]).all())
