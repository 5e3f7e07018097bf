"""``petriflow check``: every analysis of one net, as JSON-ready data.

:func:`check_net` runs the structure checks (WF-net, free-choice), P-semiflows,
boundedness (structurally by P-semiflows, else by a budgeted depth-first Karp–Miller
search before any state space, else on the fly during reachability), the reachability
graph and the properties read off it, and, for WF-nets, classical soundness with
witnesses, then T-semiflows. Each step has its own budget (docs/analysis.md, "Budgets"):
semiflows over budget are "not computed (over budget)"; an exploration stopped at the
state limit still reports every fact it found (``partial``) and lists what stays
``undecided``. How: by the explicit state space (:mod:`~petriflow.analysis.explicit`)
or a reduction (:mod:`~petriflow.analysis.methods`); the parts every way fills alike
are in :mod:`~petriflow.analysis.check_result`.

Which marking is explored: the net's initial marking; for a WF-net whose file marks
no place at all (several editors store WF-nets that way), one token in the source place
``i``. Soundness is always decided for ``[i]``.

``states``, ``edges``, ``max_tokens_place`` and ``max_tokens_marking`` mean what the
Model Checking Contest's StateSpace examination means: reachable markings; (marking,
fired transition) pairs; the most tokens one place holds in one reachable marking; the
most tokens one reachable marking holds. They are ``null`` for unbounded nets.

The exit code a result gives is :func:`~petriflow.analysis.verdict.exit_code`'s; its
text, :func:`~petriflow.analysis.report.format_report`.

Examples:
    >>> from petriflow.classic import dining_philosophers
    >>> result = check_net(dining_philosophers(5))
    >>> result["states"], result["edges"], result["bounded"], result["deadlock_free"]
    (11, 30, True, True)
"""

from __future__ import annotations

from typing import Any

from petriflow.analysis.check_result import check_range
from petriflow.analysis.coverability import DEFAULT_MAX_COVERABILITY
from petriflow.analysis.explicit import explicit_check
from petriflow.analysis.methods import check_with_method
from petriflow.analysis.reachability import DEFAULT_MAX_STATES
from petriflow.net import Net

__all__ = ["check_net"]


def check_net(net: Net, *, max_states: int = DEFAULT_MAX_STATES,
              max_coverability: int = DEFAULT_MAX_COVERABILITY,
              invariant_budget: int | None = None, method: str | None = "auto") -> dict[str, Any]:
    """Analyse ``net`` and return the JSON-ready result ``petriflow check`` prints.

    ``method`` (:data:`~petriflow.analysis.methods.METHODS`) picks how: ``explicit``
    explores the full state space as described below; ``auto``, ``symmetry``,
    ``stubborn`` and ``structural`` use the reductions of
    :mod:`~petriflow.analysis.methods` (docs/analysis.md), falling back to the explicit
    exploration where a reduction does not apply. The result's ``methods`` says which
    method answered each property, ``states_visited`` how many markings were stored.

    In order, each within its own budget: the structure (WF-net, free-choice);
    P-semiflows (``invariant_budget``), which may prove every place bounded; unless they
    do, a depth-first Karp–Miller search (``max_coverability`` nodes), which reports an
    unbounded net with its pumping witness without exploring further; the state space
    (``max_states``) and the properties read off it, or, when it stops at the limit,
    every definite fact found so far; T-semiflows (``invariant_budget``).

    Args:
        net: the net.
        max_states: the most reachable markings to explore; beyond it the result has
            ``"complete": false`` and ``"error"``, with what was found so far.
        max_coverability: the node budget of the Karp–Miller search (0: none; the
            exploration then tests boundedness on the fly only).
        invariant_budget: the work budget of each semiflow computation (0: none); by
            default :data:`~petriflow.analysis.invariants.DEFAULT_BUDGET` for the
            P-semiflows and, for the T-semiflows, in proportion to the states and edges
            explored (:data:`~petriflow.analysis.check_result.T_BUDGET_PER_EDGE` each, from
            :data:`~petriflow.analysis.check_result.T_BUDGET_FLOOR` up to
            the same default).

    Returns:
        A dict; see the module documentation for the meaning of its keys.

    Examples:
        >>> from petriflow.io.yaml import loads_net
        >>> net = loads_net('''
        ... petriflow: 1
        ... places: [i, a, o]
        ... transitions: [{id: t1, in: [i], out: [a]}, {id: t2, in: [a], out: [o]}]
        ... ''')
        >>> result = check_net(net)
        >>> result["workflow_net"], result["sound"], result["states"], result["violations"]
        (True, True, 3, [])
    """
    check_range(net)
    if method is None:         # the explicit exploration itself
        return explicit_check(net, max_states=max_states, max_coverability=max_coverability,
                              invariant_budget=invariant_budget)
    return check_with_method(net, method, max_states=max_states,
                             max_coverability=max_coverability,
                             invariant_budget=invariant_budget)
