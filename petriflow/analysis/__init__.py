"""Analysis of nets as free functions: reachability, coverability, properties, soundness,
invariants, and the ``petriflow check`` report.

One concept per module:

* :mod:`~petriflow.analysis.reachability` — the state space (:func:`reachability_graph`,
  :class:`StateSpace`, :func:`to_networkx`);
* :mod:`~petriflow.analysis.coverability` — Karp–Miller coverability graph, unbounded places,
  and the budgeted depth-first search that decides boundedness before the state space;
* :mod:`~petriflow.analysis.properties` — bounds, deadlocks, dead transitions, liveness,
  reversibility, read off a state space;
* :mod:`~petriflow.analysis.soundness` — WF-net structure and classical soundness;
* :mod:`~petriflow.analysis.invariants` — P- and T-semiflows (Farkas);
* :mod:`~petriflow.analysis.symmetry` — the state space up to permutations of
  interchangeable agents;
* :mod:`~petriflow.analysis.stubborn` — stubborn sets: deadlocks, reaching a marking;
* :mod:`~petriflow.analysis.structural` — soundness of free-choice WF-nets by the Rank Theorem;
* :mod:`~petriflow.analysis.check` — :func:`check_net`, what ``petriflow check`` answers,
  by the explicit state space (:mod:`~petriflow.analysis.explicit`) or a reduction
  (:mod:`~petriflow.analysis.methods`: which of them answers what), each filling the
  result of :mod:`~petriflow.analysis.check_result`;
* graph algorithms on compressed-row arrays (:func:`csr`, :func:`transpose`,
  :func:`components`, :func:`reachable`, :func:`reaching`), which
  :mod:`petriflow.properties` runs on state spaces and their products with automata;
* :mod:`~petriflow.analysis.verdict` — the exit code of a check; and
  :mod:`~petriflow.analysis.report` — its text.

Examples:
    >>> from petriflow.classic import dining_philosophers
    >>> space = reachability_graph(dining_philosophers(5))
    >>> space.num_states, is_live(space)
    (11, True)
"""

from petriflow.analysis.coverability import (
    DEFAULT_MAX_COVERABILITY,
    OMEGA,
    CoverabilityGraph,
    CoverabilitySearch,
    coverability_graph,
    coverability_search,
    unbounded_places,
)
from petriflow.analysis.invariants import (
    InvariantLimit,
    is_covered_by_p_semiflows,
    p_semiflows,
    structural_bounds,
    t_semiflows,
)
from petriflow.analysis.properties import (
    dead_transitions,
    deadlock_witness,
    deadlocks,
    is_live,
    is_reversible,
    is_safe,
    non_live_transitions,
    place_bounds,
)
from petriflow.analysis.reachability import (
    DEFAULT_MAX_STATES,
    StateSpace,
    StateSpaceLimit,
    UnboundedNetError,
    reachability_graph,
    to_networkx,
)
from petriflow.analysis._lasso import accepting_lasso
from petriflow.analysis._graph import components, csr, reachable, reaching, shortest_path, transpose
from petriflow.analysis.check import check_net
from petriflow.analysis.report import format_report
from petriflow.analysis.soundness import (
    SoundnessReport,
    Violation,
    WorkflowStructure,
    check_soundness,
    is_free_choice,
    workflow_structure,
)
from petriflow.analysis.verdict import exit_code

__all__ = [
    "DEFAULT_MAX_COVERABILITY", "DEFAULT_MAX_STATES", "OMEGA", "CoverabilityGraph",
    "CoverabilitySearch", "InvariantLimit", "SoundnessReport", "accepting_lasso",
    "StateSpace", "StateSpaceLimit", "UnboundedNetError", "Violation", "WorkflowStructure",
    "check_net", "check_soundness", "components", "csr", "coverability_graph", "coverability_search", "dead_transitions",
    "deadlock_witness", "deadlocks", "exit_code", "format_report", "is_covered_by_p_semiflows",
    "is_free_choice", "is_live", "is_reversible", "is_safe", "non_live_transitions",
    "p_semiflows", "place_bounds", "reachability_graph", "reachable", "reaching", "shortest_path", "structural_bounds", "t_semiflows",
    "to_networkx", "transpose", "unbounded_places", "workflow_structure",
]
