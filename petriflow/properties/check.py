"""``petriflow check --properties``: decide each property of a net, with its evidence.

:func:`check_properties` explores the reachability graph once (within ``max_states``)
and decides every property on it:

* **reachability** (``EF p``, ``AG p``, a state predicate alone): the states are
  numbered breadth first, so the first state satisfying ``p`` (or violating it) gives
  a shortest firing sequence as witness (counterexample); when the graph is over
  budget or the net unbounded, ``EF p``/``AG p`` by a stubborn-set search from the net
  (:mod:`~petriflow.properties.partial_order`, at most :data:`ON_THE_FLY_STATES`
  markings per formula);
* **bound** (the places' token total): P-semiflows first
  (:func:`~petriflow.properties.bounds.invariant_bound`), the explored markings second;
  the witness reaches a marking with the bound; with ``at_most`` the verdict is whether
  the bound stays within it;
* **ctl**: fixpoints (:mod:`~petriflow.properties.ctl`);
* **ltl**: Spot's Büchi automaton times the graph, searched on the fly
  (:mod:`~petriflow.properties.ltl`); when the graph is over budget or the net
  unbounded, times markings generated from the net as the search goes (at most
  :data:`ON_THE_FLY_STATES` of them per formula), reduced by stubborn sets when the
  formula has no ``X``;
* **boolean** (``A G F p && A F q``): each quantified operand by its own checker, the
  verdicts combined (no evidence: each operand's is its own property's).

Each result is ``{"id", "formula", "kind", "verdict", "method", "witness"}`` and, for a
lasso, ``"cycle"`` (the firings repeated forever; empty: the last marking is a deadlock,
which repeats); ``verdict`` is ``true``/``false``, the bound (an integer), or ``null``
with a ``"reason"`` (state space over budget, unbounded net, a formula outside CTL and
LTL). A verdict is never guessed: a partial state space (the markings found before the
limit; for an unbounded net, the first :data:`UNBOUNDED_STATES`) decides only what a
state found in it proves (a reachable witness, a reached value meeting the invariant
bound or exceeding ``at_most``).

Examples:
    >>> from petriflow.classic import producer_consumer
    >>> from petriflow.properties.yaml_props import parse_property
    >>> net = producer_consumer(2)
    >>> [r["verdict"] for r in check_properties(net, [
    ...     parse_property({"id": "full", "reachable": "buffer == 2"}),
    ...     parse_property({"id": "cap", "bound": "buffer"})])]
    [True, 2]
    >>> check_properties(net, [parse_property({"id": "fills", "eventually": "buffer == 2"})])[0]["cycle"]
    ['produce', 'put', 'take', 'consume']
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from petriflow.analysis.check_result import explored_marking
from petriflow.analysis.exploration import DEFAULT_MAX_STATES, StateSpaceLimit, UnboundedNetError
from petriflow.analysis.invariants import InvariantLimit, p_semiflows
from petriflow.analysis.reachability import StateSpace, reachability_graph
from petriflow.net import Net
from petriflow.properties.bounds import invariant_bound, reached_bound
from petriflow.properties.ctl import ctl_witness, evaluate
from petriflow.properties.kripke import Kripke
from petriflow.analysis.stubborn import stubborn_deadlocks
from petriflow.properties.language import (
    AllPaths, And, Deadlock, ExistsPath, Finally, Fireable, Globally, Not, Or, Property
)
from petriflow.properties.ltl import check_ltl, check_ltl_on_net
from petriflow.properties.partial_order import has_next, reach_stubborn
from petriflow.properties.yaml_props import check_property_names
from petriflow.workflow import workflow_structure

__all__ = ["LTL_STUBBORN_OVER_BUDGET", "REDUCTIONS", "check_properties"]

#: The ``reduction`` choices of :func:`check_properties`.
REDUCTIONS = ("auto", "stubborn", "none")

#: Whether ``auto`` reduces the LTL search from the net (graph over budget) by stubborn
#: sets when the formula has no ``X`` (chosen by measurement: docs/benchmarks.md).
LTL_STUBBORN_OVER_BUDGET = True


def check_properties(net: Net, properties: Sequence[Property], *,
                     max_states: int = DEFAULT_MAX_STATES, reduction: str = "auto") -> list[dict[str, Any]]:
    """Decide every property of ``net`` (see the module documentation for the entries).

    ``reduction`` (one of :data:`REDUCTIONS`): ``auto`` uses stubborn sets where the
    reachability graph is over budget; ``stubborn`` decides every ``EF p``/``AG p`` and
    every LTL formula without ``X`` by stubborn sets, graph or no graph; ``none`` never
    uses them (:mod:`~petriflow.properties.partial_order`).

    Raises:
        NetFormatError: a property names a place or transition the net lacks (its file
            and line).
    """
    if reduction not in REDUCTIONS:
        raise ValueError(f"unknown reduction {reduction!r}: one of {', '.join(REDUCTIONS)}")
    check_property_names(net, properties)
    start = explored_marking(net, workflow_structure(net))
    space: StateSpace | None = None
    reason = None
    partial: StateSpace | None = None
    try:
        space = reachability_graph(net, start, max_states=max_states)
    except StateSpaceLimit as exc:
        reason = f"state space over budget: more than {max_states} states (--max-states)"
        partial = exc.partial if isinstance(exc.partial, StateSpace) else None
    except UnboundedNetError as exc:
        reason = f"unbounded net: firing {' '.join(exc.pump)} repeats forever, adding tokens to" \
                 f" {', '.join(exc.places)}"
        partial = _explored_part(net, start, min(max_states, UNBOUNDED_STATES))
    kripke = Kripke(space) if space is not None else None
    cache: dict = {}
    quotient: dict = {}            # the symmetry quotient, explored once when needed
    semiflows: list | None = None
    results = []
    for prop in properties:
        entry: dict[str, Any] = {"id": prop.id, "kind": prop.kind,
                                 "formula": _describe(prop), "verdict": None, "method": None,
                                 "witness": None}
        if reduction == "stubborn" and prop.kind in ("reachability", "ltl"):
            _by_stubborn_sets(entry, prop, net, start, max_states)
        if entry["verdict"] is not None:
            pass
        elif prop.formula is None:
            if semiflows is None:
                try:
                    semiflows = p_semiflows(net)
                except InvariantLimit:
                    semiflows = []
            _bound(entry, prop, space or partial, invariant_bound(net, prop.bound, start, semiflows),
                   space is not None)
        elif prop.kind == "ctl*":
            entry["reason"] = "a CTL* formula (neither CTL nor LTL): not decided"
        elif kripke is None:
            if prop.kind == "reachability" and partial is not None:
                _partial_reachability(entry, prop, partial)
            if entry["verdict"] is None and prop.kind == "reachability" and reduction == "auto":
                _deadlock_by_stubborn_sets(entry, prop, net, start, max_states)
                if entry["verdict"] is None:
                    _by_stubborn_sets(entry, prop, net, start, min(max_states, ON_THE_FLY_STATES))
            if entry["verdict"] is None and prop.kind == "reachability" and space is None \
                    and reason is not None and reason.startswith("state space over budget"):
                _by_symmetry(entry, prop, net, start, max_states, quotient)
            if prop.kind == "ltl":
                _ltl_on_the_fly(entry, prop, net, start, min(max_states, ON_THE_FLY_STATES),
                                reduction == "auto" and LTL_STUBBORN_OVER_BUDGET)
        elif prop.kind == "boolean":
            verdict = _boolean(prop.formula, kripke, cache)
            entry.update(verdict=verdict, method="Boolean combination: each quantified formula decided"
                         " on the reachability graph (LTL: Spot Büchi automaton; CTL: fixpoints)")
        else:
            _decide(entry, prop, kripke, cache)
        if entry["verdict"] is None and "reason" not in entry:
            entry["reason"] = reason
        results.append(entry)
    return results


#: How many markings of an unbounded net are still explored, in search of markings that
#: decide reachability properties (``EF p`` true, ``AG p`` false) or exceed a bound.
UNBOUNDED_STATES = 100_000


#: How many markings the LTL search from the net (no reachability graph: over budget or
#: unbounded) may generate per formula: about 5 CPU s of Python.
ON_THE_FLY_STATES = 100_000


def _explored_part(net: Net, start, max_states: int) -> StateSpace | None:
    """The first ``max_states`` markings of an unbounded net, breadth first."""
    try:
        reachability_graph(net, start, max_states=max_states, detect_unbounded=False)
    except StateSpaceLimit as exc:
        return exc.partial if isinstance(exc.partial, StateSpace) else None
    return None             # finite after all: cannot happen for a net found unbounded


def _describe(prop: Property) -> str:
    if prop.formula is not None:
        return str(prop.formula)
    text = "bound(" + " + ".join(prop.bound) + ")"
    return text if prop.at_most is None else f"{text} <= {prop.at_most}"


def _reachability_shape(formula) -> tuple[bool, object]:
    """``(universal, p)`` for ``AG p`` (true) / ``EF p`` (false) / ``p`` (``EF``-free: as
    the predicate at the initial marking, returned as universal None)."""
    if isinstance(formula, AllPaths) and isinstance(formula.operand, Globally):
        return True, formula.operand.operand
    if isinstance(formula, ExistsPath) and isinstance(formula.operand, Finally):
        return False, formula.operand.operand
    return None, formula  # type: ignore[return-value]


def _decide(entry: dict, prop: Property, kripke: Kripke, cache: dict) -> None:
    formula = prop.formula
    if prop.kind == "reachability":
        universal, predicate = _reachability_shape(formula)
        if universal is None:
            entry.update(verdict=bool(kripke.holds(predicate)[0]), method="initial marking",
                         witness=[])
            return
        holds = kripke.holds(predicate)
        bad = np.flatnonzero(~holds if universal else holds)
        entry["method"] = "reachability graph (breadth first: shortest witness)"
        entry["verdict"] = (not bad.size) if universal else bool(bad.size)
        if bad.size:
            entry["witness"] = kripke.space.path(int(bad[0]))
        return
    if prop.kind == "ltl":
        verdict, lasso = check_ltl(kripke, formula)
        entry.update(verdict=verdict, method="LTL: Spot Büchi automaton x reachability graph")
        if lasso is not None:
            entry.update(lasso)
        return
    verdict = bool(evaluate(kripke, formula, cache)[0])
    entry.update(verdict=verdict, method="CTL: fixpoints on the reachability graph")
    evidence = ctl_witness(kripke, formula, verdict, cache)
    if evidence is not None:
        entry.update(evidence)


def _boolean(formula, kripke: Kripke, cache: dict) -> bool | None:
    """A Boolean combination of quantified formulas at the initial marking: each operand
    decided by its own checker, combined (``None``: some operand that matters undecided)."""
    if isinstance(formula, Not):
        value = _boolean(formula.operand, kripke, cache)
        return None if value is None else not value
    if isinstance(formula, (And, Or)):
        decisive = isinstance(formula, Or)          # the value that settles the whole
        values = [_boolean(f, kripke, cache) for f in formula.operands]
        if decisive in values:
            return decisive
        return None if None in values else not decisive
    sub = Property(id="", formula=formula)
    if sub.kind == "ctl*":
        return None
    entry: dict[str, Any] = {"verdict": None}
    _decide(entry, sub, kripke, cache)
    return entry["verdict"]


def _partial_reachability(entry: dict, prop: Property, partial: StateSpace) -> None:
    """A state found before the limit can settle ``EF p`` (true) or ``AG p`` (false)."""
    universal, predicate = _reachability_shape(prop.formula)
    if universal is None:
        return
    holds = Kripke(partial).holds(predicate)
    bad = np.flatnonzero(~holds if universal else holds)
    if partial.expanded is not None and any(isinstance(n, (Fireable, Deadlock)) for n in predicate.walk()):
        # what a state enables is known only once it is expanded (the others look dead)
        bad = bad[bad < partial.expanded]
    if bad.size:
        entry.update(verdict=not universal, witness=partial.path(int(bad[0])),
                     method="reachability graph (stopped at the limit; the witness is reachable)")


def _deadlock_by_stubborn_sets(entry: dict, prop: Property, net: Net, start, max_states: int) -> None:
    """``EF deadlock`` / ``AG !deadlock`` beyond the full state space: a stubborn-set
    search preserves every reachable deadlock (:mod:`petriflow.analysis.stubborn`)."""
    universal, predicate = _reachability_shape(prop.formula)
    wanted = Not(Deadlock()) if universal else Deadlock()
    if universal is None or predicate != wanted:
        return
    try:
        found = stubborn_deadlocks(net, start, max_states=max_states, first=True)
    except StateSpaceLimit:
        return
    entry.update(verdict=found.deadlock != bool(universal), witness=found.witness,
                 method="stubborn sets (every reachable deadlock preserved)")


def _ltl_on_the_fly(entry: dict, prop: Property, net: Net, start, max_states: int,
                    stubborn: bool = False) -> None:
    """LTL beyond the reachability graph: the product searched from the net, markings
    generated only as far as the search goes (at most ``max_states`` of them); with
    ``stubborn`` and no ``X``, reduced by stubborn sets."""
    stats: dict = {}
    try:
        verdict, lasso = check_ltl_on_net(net, start, prop.formula, max_states=max_states,
                                          stubborn=stubborn, stats=stats)
    except StateSpaceLimit:
        return
    method = "LTL: Spot Büchi automaton x markings generated on the fly"
    if stats.get("reduced"):
        method += f", stubborn sets (visibility, stack proviso; {stats['markings']} markings)"
    entry.update(verdict=verdict, method=method)
    if lasso is not None:
        entry.update(lasso)


def _by_stubborn_sets(entry: dict, prop: Property, net: Net, start, max_states: int) -> None:
    """``EF p`` / ``AG p`` by the up-set search, LTL without ``X`` by the reduced product
    (:mod:`~petriflow.properties.partial_order`); nothing for other shapes."""
    if prop.kind == "ltl":
        if not has_next(prop.formula):
            _ltl_on_the_fly(entry, prop, net, start, max_states, stubborn=True)
        return
    universal, predicate = _reachability_shape(prop.formula)
    if universal is None:
        return
    try:
        found = reach_stubborn(net, start, Not(predicate) if universal else predicate,
                               max_states=max_states)
    except StateSpaceLimit:
        return
    entry.update(verdict=found.found != bool(universal), witness=found.witness,
                 method=f"stubborn sets (up-set of the predicate; {found.states} markings)"
                 if found.reduced else f"on-the-fly search ({found.states} markings; reset arcs:"
                 " no reduction)")


def _by_symmetry(entry: dict, prop: Property, net: Net, start, max_states: int, quotient: dict) -> None:
    """``AG p`` / ``EF p`` with ``p`` invariant under the agents' permutations, on the
    quotient (:mod:`~petriflow.properties.symmetric`) when the full space is over budget."""
    from petriflow.analysis.symmetry import SymmetryUnsupported, find_symmetries, symmetric_graph
    from petriflow.properties.symmetric import holds_on_quotient, symmetric

    universal, predicate = _reachability_shape(prop.formula)
    if universal is None:
        return
    if "groups" not in quotient:
        quotient["groups"] = find_symmetries(net)
    groups = quotient["groups"]
    if not groups or not symmetric(predicate, groups, net):
        return
    if "space" not in quotient:
        try:
            quotient["space"] = symmetric_graph(net, start, groups=groups, max_states=max_states)
        except (StateSpaceLimit, SymmetryUnsupported):
            quotient["space"] = None
    space = quotient["space"]
    if space is None:
        return
    holds = holds_on_quotient(space, predicate)
    bad = np.flatnonzero(~holds if universal else holds)
    entry.update(verdict=(not bad.size) if universal else bool(bad.size),
                 method=f"symmetry quotient ({space.num_states} canonical markings; the predicate"
                        " is invariant under the agents' permutations)")
    if bad.size:
        entry["witness"] = space.path(int(bad[0]))


def _bound(entry: dict, prop: Property, space: StateSpace | None, proved: int | None,
           complete: bool) -> None:
    reached, state = reached_bound(space, prop.bound) if space is not None else (None, None)
    exact = None
    if complete:
        exact, entry["method"] = reached, "reachability graph"
    elif reached is not None and proved is not None and reached >= proved:
        exact, entry["method"] = reached, "P-semiflows (upper bound) met by a reachable marking"
    if exact is not None:
        entry["witness"] = space.path(state)
        entry["verdict"] = exact if prop.at_most is None else exact <= prop.at_most
        entry["bound"] = exact
    elif prop.at_most is not None and proved is not None and proved <= prop.at_most:
        entry.update(verdict=True, method="P-semiflows (upper bound)", bound_at_most=proved)
    elif prop.at_most is not None and reached is not None and reached > prop.at_most:
        entry.update(verdict=False, witness=space.path(state), bound_at_least=reached,
                     method="reachability graph (stopped at the limit; the marking is reachable)")
    else:
        if reached is not None:
            entry["bound_at_least"] = reached
        if proved is not None:
            entry["bound_at_most"] = proved
