"""``petriflow check``: every analysis of one net, as JSON-ready data and as text.

:func:`check_net` runs the structure checks (WF-net, free-choice), P-semiflows,
boundedness (structurally by P-semiflows, else by a budgeted depth-first Karp–Miller
search before any state space, else on the fly during reachability), the reachability
graph and the properties read off it, and, for WF-nets, classical soundness with
witnesses, then T-semiflows. Each step has its own budget (docs/analysis.md, "Budgets"):
semiflows over budget are "not computed (over budget)"; an exploration stopped at the
state limit still reports every fact it found (``partial``) and lists what stays
``undecided``.

Which marking is explored: the net's initial marking; for a WF-net whose file marks
no place at all (several editors store WF-nets that way), one token in the source place
``i``. Soundness is always decided for ``[i]``.

``states``, ``edges``, ``max_tokens_place`` and ``max_tokens_marking`` mean what the
Model Checking Contest's StateSpace examination means: reachable markings; (marking,
fired transition) pairs; the most tokens one place holds in one reachable marking; the
most tokens one reachable marking holds. They are ``null`` for unbounded nets.

Exit codes (:func:`exit_code`), as the rest of the command line:

* ``0`` — the net is a sound WF-net, or (not a WF-net) bounded and deadlock-free, where
  a dead marking equal to the net's declared final marking counts as proper termination
  (``deadlock_free`` keeps the MCC's strict meaning; ``stuck_markings`` counts the dead
  markings other than the final one);
* ``1`` — a property fails (the ``violations`` say which, with witnesses), also when
  found before the state limit or by another method;
* ``2`` — no verdict: the state space exceeds ``--max-states`` (``"complete": false`` in
  the JSON, a one-line message on standard error) and nothing found before the limit
  fails (a deadlock, or for a WF-net improper completion or a dead end, found before it
  gives ``1``), or the net file is bad input.

A state space stopped at the limit when the verdict was reached anyway (``0`` or ``1``)
is no error: ``check`` prints nothing on standard error, and :func:`format_report` ends
with a note naming the properties left undecided. The text gives each property with its
verdict and the method that decided it (docs/analysis.md, "The text report"); for a sound
WF-net it says why ``deadlock_free``, ``live`` and ``reversible`` are false for the net as
given (its runs end in the dead final marking) and that the short-circuited net has them.

Examples:
    >>> from petriflow.classic import dining_philosophers
    >>> result = check_net(dining_philosophers(5))
    >>> result["states"], result["edges"], result["bounded"], result["deadlock_free"]
    (11, 30, True, True)
    >>> exit_code(result)
    0
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from petriflow import limits
from petriflow.analysis.coverability import (
    DEFAULT_MAX_COVERABILITY,
    CoverabilitySearch,
    coverability_search,
)
from petriflow.analysis.invariants import (
    DEFAULT_BUDGET,
    DEFAULT_MAX_ROWS,
    InvariantLimit,
    p_semiflows,
    structural_bounds,
    t_semiflows,
)
from petriflow.analysis.properties import (
    dead_transitions,
    deadlocks,
    is_reversible,
    non_live_witness,
    strongly_connected_components,
)
from petriflow.analysis.reachability import (
    DEFAULT_MAX_STATES,
    StateSpace,
    StateSpaceLimit,
    UnboundedNetError,
    reachability_graph,
)
from petriflow.analysis.soundness import (
    Violation,
    check_soundness,
    is_free_choice,
    workflow_structure,
)
from petriflow.engine import CompiledNet
from petriflow.errors import PetriflowError
from petriflow.marking import Marking
from petriflow.net import Net

__all__ = [
    "EXIT_OK",
    "EXIT_PROBLEM",
    "EXIT_UNDECIDED",
    "check_net",
    "exit_code",
    "format_report",
    "plain",
]

EXIT_OK, EXIT_PROBLEM, EXIT_UNDECIDED = 0, 1, 2

#: Farkas' algorithm row limit used by :func:`check_net`.
INVARIANT_ROWS = DEFAULT_MAX_ROWS

#: Why a kind of semiflow was not computed, as the report says it.
_NOT_COMPUTED = {"budget": "over budget", "rows": "over budget", "size": "net too large",
                 "skipped": "skipped"}


def _format(marking: dict[str, int] | Marking) -> str:
    return ", ".join(f"{p}={c}" for p, c in marking.items()) or "(empty)"


def _semiflows(section: dict[str, Any], kind: str, compiled: CompiledNet, budget: int):
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


def _invariants(compiled: CompiledNet, start: Marking, budget: int) -> tuple[dict[str, Any], set[str]]:
    """The ``invariants`` section (P-semiflows) and the places they bound."""
    section: dict[str, Any] = {"p_budget": budget}
    flows = _semiflows(section, "p", compiled, budget)
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
            explored (:data:`T_BUDGET_PER_EDGE` each, from :data:`T_BUDGET_FLOOR` up to
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
    _check_range(net)
    if method is not None:     # None: the explicit exploration itself, for the methods module
        from petriflow.analysis.methods import check_with_method

        return check_with_method(net, method, max_states=max_states,
                                 max_coverability=max_coverability,
                                 invariant_budget=invariant_budget)
    compiled = CompiledNet(net)
    structure = workflow_structure(net)
    start = net.initial_marking
    if not start and structure.is_wf_net:
        start = Marking({structure.source: 1})
    result = _skeleton(net, structure, start)
    p_budget = DEFAULT_BUDGET if invariant_budget is None else invariant_budget
    result["invariants"], covered = _invariants(compiled, start, p_budget)
    structurally_bounded = bool(result["invariants"].get("covered_by_p_semiflows"))
    result["structurally_bounded"] = structurally_bounded
    if structurally_bounded:
        result["algorithm"].append("P-semiflows cover every place: bounded for any marking")
    violations: list[Violation] = []
    probe: CoverabilitySearch | None = None
    try:
        soundness = None
        if structure.is_wf_net:
            soundness = check_soundness(net, max_states=max_states, max_coverability=max_coverability,
                                        bounded=structurally_bounded or None)
            result["sound"] = soundness.sound
            result["soundness"] = {
                "option_to_complete": soundness.option_to_complete,
                "proper_completion": soundness.proper_completion,
                "no_dead_transitions": soundness.no_dead_transitions,
                "final_marking": soundness.final_marking,
                "crosscheck": soundness.crosscheck,
            }
            result["algorithm"].append(f"soundness: {soundness.algorithm}")
            violations.extend(soundness.violations)
        else:
            violations.append(Violation("not_wf_net", f"not a WF-net: {structure.problem}",
                                        elements=structure.not_on_path))
        same_start = soundness is not None and start == Marking({structure.source: 1})
        probe = soundness.coverability if same_start else None
        if same_start and soundness.space is not None:
            space = soundness.space
        elif same_start and soundness.bounded is False:
            space = None
            witness = next((v for v in soundness.violations if v.kind == "unbounded"), None)
            _unbounded_result(result, probe, witness.elements if witness else [], covered,
                              compiled.places)
            if witness is not None and result["unbounded_places_complete"]:
                # P-semiflows bound every other place: the list is exact after all
                witness.message = witness.message.replace("places (at least):", "places:")
        else:
            space = None
            if not same_start and not structurally_bounded and max_coverability > 0 \
                    and not getattr(compiled, "has_resets", False):
                probe = coverability_search(net, start, max_nodes=max_coverability, compiled=compiled)
            exc = probe.witness if probe is not None and probe.bounded is False else None
            _coverability_note(result, probe, max_coverability)
            if exc is None:
                known = structurally_bounded or (probe is not None and probe.bounded)
                try:
                    space = reachability_graph(net, start, max_states=max_states, compiled=compiled,
                                               detect_unbounded=not known)
                except UnboundedNetError as found:
                    exc = found
            if exc is not None:
                _unbounded_result(result, probe, exc.places, covered, compiled.places)
                violations.append(_unbounded_violation(result, exc))
        _coverability_note(result, probe, max_coverability)
        if space is not None:
            _bounded_result(result, space, violations, structure.is_wf_net, net.final_marking)
    except StateSpaceLimit as exc:
        _coverability_note(result, probe or getattr(exc, "coverability", None), max_coverability)
        result["complete"] = False
        result["error"] = str(exc)
        # Stopped in the soundness check (from [i]) or, soundness decided, in the
        # exploration of the net's own initial marking.
        from_i = structure.is_wf_net and soundness is None
        if from_i or not structure.is_wf_net:
            result["sound"] = None if structure.is_wf_net else False
        if exc.partial is not None:
            _partial_result(result, exc.partial, violations, structure.is_wf_net, from_i,
                            net.final_marking, soundness_final(net, structure))
    t_budget = invariant_budget
    if t_budget is None:
        explored = (result["states"] or 0) + (result["edges"] or 0)
        explored += sum((result.get(k) or {}).get(n, 0) for k, n in (
            ("partial", "states_explored"), ("partial", "edges_explored"),
            ("coverability", "nodes"), ("coverability", "edges")))
        t_budget = min(DEFAULT_BUDGET, max(T_BUDGET_FLOOR, T_BUDGET_PER_EDGE * explored))
    result["invariants"]["t_budget"] = t_budget
    _semiflows(result["invariants"], "t", compiled, t_budget)
    result["violations"] = [v.to_dict() for v in violations]
    result["algorithm"] = "; ".join(result["algorithm"])
    return result


def _skeleton(net: Net, structure, start: Marking) -> dict[str, Any]:
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


def _final_marking(net: Net, structure) -> dict[str, int] | None:
    """The ``final_marking`` key: soundness's for a WF-net, else the declared one (or None)."""
    final = soundness_final(net, structure) if structure.is_wf_net else net.final_marking
    return None if final is None else final.to_dict()


def soundness_final(net: Net, structure) -> Marking | None:
    """The final marking soundness is decided for: the net's, else one token in ``o``."""
    if not structure.is_wf_net:
        return None
    from petriflow.workflow import final_marking_of

    return final_marking_of(net)


def _coverability_note(result: dict[str, Any], probe: CoverabilitySearch | None, budget: int) -> None:
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


def _partial_result(result: dict[str, Any], space: StateSpace, violations: list[Violation],
                    workflow: bool, from_i: bool, final, sound_final) -> None:
    """What a state space stopped at the limit still proves (each a fact about the net).

    Reached markings are reachable: a place holding ``k`` tokens in one proves its bound
    is at least ``k`` (and the net not safe when ``k >= 2``); a transition fired is not
    dead; an expanded marking that enables nothing is a deadlock, with its path; for a
    WF-net, a marking covering the final one with tokens left elsewhere is improper
    completion, and a dead marking other than the final one has lost the option to
    complete. Everything else stays undecided (``null``).
    """
    bounds = space.place_bounds()
    names = space.places
    top = int(bounds.max(initial=0))
    dead_states = deadlocks(space)
    fired = np.zeros(len(space.transitions), dtype=bool)
    fired[space.edge_transition] = True
    not_dead = list(dict.fromkeys(space.origins[t] for t in np.flatnonzero(fired)))
    stuck = dead_states
    if final is not None and dead_states.size:
        stuck = np.asarray([s for s in dead_states.tolist() if space.marking(int(s)) != final],
                           dtype=dead_states.dtype)
    found = {
        "states_explored": space.num_states,
        "states_expanded": int(space.expanded),
        "edges_explored": space.num_edges,
        "max_tokens_place_at_least": top,
        "max_tokens_marking_at_least": space.max_tokens_marking,
        "k_bound_at_least": {p: int(k) for p, k in zip(names, bounds)},
        "deadlock_markings_found": int(dead_states.size),
        "not_dead_transitions": not_dead,
    }
    result["partial"] = found
    if top >= 2:
        result["safe"] = False
    if dead_states.size:
        result["deadlock_free"] = False
    result["stuck_markings"] = None
    # Proved without the state space: bounded by P-semiflows or by the Karp-Miller search,
    # safe when the P-semiflows bound every place by 1.
    search = result.get("coverability") or {}
    if result.get("structurally_bounded") or (search.get("complete") and result.get("bounded") is None):
        result["bounded"] = True
    limits_found = (result.get("invariants") or {}).get("structural_bounds") or {}
    if result["safe"] is None and len(limits_found) == len(names) and max(limits_found.values(), default=0) <= 1:
        result["safe"] = True
    undecided = ["states", "edges", "live", "reversible", "dead_transitions",
                 "max_tokens_place", "max_tokens_marking", "k_bound"]
    undecided += [k for k in ("bounded", "safe", "deadlock_free") if result[k] is None]
    if workflow and from_i:
        undecided.append("sound")
    if workflow and from_i and sound_final is not None:
        final_vector = np.array([sound_final.get(p, 0) for p in names], dtype=np.int64)
        markings = space.markings
        improper = np.flatnonzero((markings >= final_vector).all(axis=1)
                                  & (markings != final_vector).any(axis=1))
        if improper.size:
            state = int(improper[0])
            reached = space.marking(state)
            violations.append(Violation(
                "improper_completion",
                f"improper completion: a reachable marking covers the final marking"
                f" {_format(sound_final)} with tokens left elsewhere: {_format(reached)}"
                " (found before the state limit)", space.path(state), reached.to_dict()))
        dead_ends = [s for s in dead_states.tolist() if space.marking(int(s)) != sound_final]
        if dead_ends:
            state = int(dead_ends[0])
            reached = space.marking(state)
            violations.append(Violation(
                "no_option_to_complete",
                f"no option to complete: {_format(reached)} is a deadlock other than the final"
                f" marking {_format(sound_final)} (found before the state limit)",
                space.path(state), reached.to_dict()))
        if improper.size or dead_ends:
            result["sound"] = False
            undecided.remove("sound")
    elif stuck.size and not workflow:
        state = int(stuck[0])
        reached = space.marking(state)
        violations.append(Violation(
            "deadlock", f"deadlock: {_format(reached)} enables no transition (found before the"
                        " state limit; more may exist)", space.path(state), reached.to_dict()))
    result["undecided"] = undecided


def _bounded_result(result: dict[str, Any], space, violations: list[Violation],
                    workflow: bool, final=None) -> None:
    bounds = space.place_bounds()
    labels = strongly_connected_components(space)
    dead = dead_transitions(space)
    dead_states = deadlocks(space)
    # deadlock_free keeps the Model Checking Contest's strict meaning (no dead marking at
    # all); a dead marking that is the net's declared final marking is where the net is
    # meant to end, so only the other dead markings ("stuck") make a non-WF net fail
    deadlock_states = dead_states
    if final is not None and dead_states.size:
        deadlock_states = np.asarray([s for s in dead_states.tolist() if space.marking(int(s)) != final],
                                     dtype=dead_states.dtype)
    result["stuck_markings"] = int(deadlock_states.size)
    result["final_marking_reached"] = None if final is None else bool(
        dead_states.size > deadlock_states.size or _reaches(space, final))
    not_live = non_live_witness(space, labels)
    result.update(
        bounded=True,
        safe=bool(space.safe),
        states=space.num_states,
        edges=space.num_edges,
        max_tokens_place=space.max_tokens_place,
        max_tokens_marking=space.max_tokens_marking,
        k_bound={p: int(k) for p, k in zip(space.places, bounds)},
        deadlock_free=not dead_states.size,
        deadlock_markings=int(dead_states.size),
        dead_transitions=dead,
        live=not_live is None,
        reversible=is_reversible(space, labels),
    )
    result["algorithm"].append(
        f"reachability graph: explicit breadth-first search ({space.representation} markings)")
    if not_live is not None:
        sequence, transitions = not_live
        result["non_live"] = {"transitions": transitions, "witness": sequence}
    if deadlock_states.size and not workflow:
        state = int(deadlock_states[0])
        reached = space.marking(state)
        count = int(deadlock_states.size)
        violations.append(Violation(
            "deadlock", f"deadlock: {_count(count, 'reachable marking')} "
            f"{'enables' if count == 1 else 'enable'} no transition, e.g. {_format(reached)}",
            space.path(state), reached.to_dict()))


def _reaches(space, final) -> bool:
    """Whether the declared final marking is among the reachable markings."""
    try:
        return space.index(final) is not None
    except (KeyError, ValueError, IndexError):
        return False


def _unbounded_result(result: dict[str, Any], probe: CoverabilitySearch | None,
                      pumped: list[str], covered: set[str], every_place) -> None:
    """Fill the result for an unbounded net from the Karp–Miller search (if any) and the
    places a witness pumps. The list is exact when the search finished, or when every
    place it leaves out is bounded by a P-semiflow."""
    result.update(bounded=False, safe=False, live=None, deadlock_free=None)
    places = list(pumped)
    if probe is not None:
        places = list(dict.fromkeys(probe.unbounded_places + places))
        if probe.complete:
            result["dead_transitions"] = probe.dead_transitions
            result["k_bound"] = probe.place_bounds
        else:
            result["not_dead_transitions"] = probe.fired
    order = {p: k for k, p in enumerate(every_place)}
    result["unbounded_places"] = sorted(places, key=order.__getitem__)
    exact = (probe is not None and probe.complete) or covered | set(places) >= set(every_place)
    result["unbounded_places_complete"] = bool(exact)
    if probe is not None and probe.unbounded_places:
        result["algorithm"].append("Karp-Miller coverability search (depth first): unbounded"
                                   + ("" if probe.complete else ", graph over its budget"))
    else:
        result["algorithm"].append("reachability graph stopped: a marking strictly covers an"
                                   " earlier one on its path (unbounded)")


def _unbounded_violation(result: dict[str, Any], exc: UnboundedNetError) -> Violation:
    places = result["unbounded_places"]
    more = "" if result["unbounded_places_complete"] else " (at least)"
    return Violation(
        "unbounded",
        f"unbounded: firing {' '.join(exc.pump)} from the marking reached by"
        f" [{' '.join(exc.prefix)}] adds tokens to {', '.join(exc.places)} and can be repeated"
        f" forever; unbounded places{more}: {', '.join(places)}",
        exc.prefix + exc.pump, exc.covering.to_dict(), places)


def exit_code(result: dict[str, Any]) -> int:
    """0: sound WF-net, or bounded and deadlock-free; 1: a property fails; 2: no verdict.

    A result stopped at the state limit (``complete`` false) is 1 when what was found
    before the limit already fails (a deadlock, improper completion, a dead end in a
    WF-net), else 2.

    Examples:
        >>> exit_code({"complete": False})
        2
        >>> exit_code({"complete": True, "workflow_net": False, "bounded": True,
        ...            "deadlock_free": False})
        1
    """
    if not result.get("complete", True):
        # Stopped at the limit: a definite failure found on the way still fails; a
        # verdict another method reached (the Rank Theorem, stubborn sets) still holds.
        decided = result.get("methods") or {}
        if result.get("workflow_net"):
            if result.get("sound") is False:
                return EXIT_PROBLEM
            return EXIT_OK if result.get("sound") and decided.get("sound") else EXIT_UNDECIDED
        found = any(v.get("kind") == "deadlock" for v in result.get("violations", ()))
        if found or result.get("bounded") is False:
            return EXIT_PROBLEM
        return EXIT_OK if result.get("bounded") and result.get("stuck_markings") == 0 \
            and decided.get("stuck_markings") else EXIT_UNDECIDED
    if result.get("workflow_net"):
        return EXIT_OK if result.get("sound") else EXIT_PROBLEM
    stuck = result.get("stuck_markings")
    terminates = result.get("deadlock_free") if stuck is None else stuck == 0
    return EXIT_OK if result.get("bounded") and terminates else EXIT_PROBLEM


#: How the text names each method of ``methods``.
_METHOD_NAMES = {"explicit": "state space", "symmetry": "state space up to symmetry",
                 "stubborn": "stubborn sets", "stubborn+symmetry": "stubborn sets up to symmetry",
                 "structural": "Rank Theorem", "Karp-Miller": "Karp-Miller search"}

#: The properties each report line gives, and the name the text prints.
_PROPERTIES = (("sound", "sound"), ("bounded", "bounded"), ("deadlock_free", "deadlock-free"),
               ("live", "live"), ("reversible", "reversible"), ("dead_transitions", "dead transitions"))

_AGREES = " (structural agrees)"


def _yes(value: Any) -> str:
    return {True: "yes", False: "no", None: "undecided"}[value]


def _decided_by(result: dict[str, Any], key: str) -> str:
    """The method that decided ``key``, as the text names it.

    Examples:
        >>> _decided_by({"workflow_net": True, "complete": True,
        ...              "methods": {"sound": "explicit (structural agrees)"}}, "sound")
        'state space; the Rank Theorem agrees'
        >>> _decided_by({"workflow_net": False, "complete": True, "methods": {}}, "sound")
        'WF-net structure'
    """
    if key == "sound" and not result["workflow_net"]:
        return "WF-net structure"
    how = (result.get("methods") or {}).get(key)
    algorithm = result.get("algorithm") or ""
    if result.get("bounded") is False and (
            key == "dead_transitions" or (key == "bounded" and "Karp-Miller coverability search (depth"
                                          " first): unbounded" in algorithm)):
        how = "Karp-Miller"           # the search that found the pump
    if how is None:                   # check_net(method=None): no ``methods``
        if key == "bounded" and result.get("structurally_bounded"):
            how = "P-semiflows"
        elif key == "bounded" and (result.get("coverability") or {}).get("complete"):
            how = "Karp-Miller"
        else:
            how = "explicit"
    agrees = how.endswith(_AGREES)
    how = how[:-len(_AGREES)] if agrees else how
    name = _METHOD_NAMES.get(how, how)
    if how in ("explicit", "symmetry") and not result["complete"]:
        name += ", found before the limit"
    return name + ("; the Rank Theorem agrees" if agrees else "")


def _limit(result: dict[str, Any]) -> str:
    """Why the state space is not complete, in a few words."""
    if result.get("method") == "stubborn":
        return "--method stubborn builds no full state space"
    found = re.search(r"max_states=(\d+)", result.get("error") or "")
    return f"state space over --max-states{'=' + found.group(1) if found else ''}"


def _why_undecided(result: dict[str, Any], key: str) -> str:
    """Why ``key`` is undecided, in a few words."""
    if result.get("bounded") is False and key in ("deadlock_free", "live", "reversible"):
        return "unbounded: no finite state space"
    if key == "dead_transitions" and result.get("bounded") is False:
        return "Karp-Miller search over its budget"
    why = []
    if not result["complete"]:
        why.append(_limit(result))
    elif key == "live" and result.get("symmetry"):
        why.append("the symmetry reduction does not preserve it")
    if key == "bounded" and result.get("coverability") and not result["coverability"]["complete"]:
        why.append("Karp-Miller search over its budget")
    if key == "deadlock_free" and "stubborn" in (result.get("states_visited") or {}):
        why.append("stubborn sets stopped before finding one: see the note below")
    if key == "sound" and (result.get("reduced") or {}).get("sound", True) is None:
        why.append("not decided on the stubborn-set graph: see the note below")
    return "; ".join(why) or "not decided"


def _run_end(result: dict[str, Any]) -> str | None:
    """Where a run ends, when that is the only dead marking reached (else None).

    For a sound WF-net explored from ``[i]``, a dead marking reached is the final marking
    (soundness: from every reachable marking the final one is reachable); for another
    net, when ``stuck_markings`` is 0, it is the declared final marking.
    """
    final = result.get("final_marking")
    if result.get("deadlock_free") is not False or final is None:
        return None
    if result["workflow_net"]:
        start = {result["source_place"]: 1}
        if result.get("sound") is True and result["initial_marking"] == start:
            return f"the final marking {_format(final)}"
        return None
    return f"the declared final marking {_format(final)}" if result.get("stuck_markings") == 0 else None


def _witnessed(result: dict[str, Any], kinds: set[str]) -> bool:
    return any(v["kind"] in kinds and v.get("transitions") for v in result["violations"])


def _property_lines(result: dict[str, Any]) -> list[str]:
    """One line per property: its verdict and the method that decided it, or why not."""
    lines = []
    ends = _run_end(result)

    def line(key: str, name: str, text: str, inside: str = "") -> None:
        value = result.get(key)
        if value is None:
            lines.append(f"  {name}: undecided ({_why_undecided(result, key)}){text}")
        else:
            lines.append(f"  {name}: {_yes(value)} ({_decided_by(result, key)}{inside}){text}")

    sound = result.get("sound")
    line("sound", "sound", "", "; witnesses below" if result["workflow_net"] and sound is False and _witnessed(
        result, {"improper_completion", "no_option_to_complete", "dead_transition", "unbounded"}) else "")
    bounded, safe = result.get("bounded"), result.get("safe")
    found = result.get("partial") or {}
    if safe is False and found.get("k_bound_at_least"):
        top = max(found["k_bound_at_least"].items(), key=lambda item: item[1])
        extra = f", not safe ({top[0]} reaches {top[1]} tokens)"
    elif bounded and safe is False and result.get("max_tokens_place") is not None:
        extra = f", {result['max_tokens_place']}-bounded"
    elif bounded and safe:
        extra = ", safe"
    else:
        extra = ""
    if bounded is False:
        more = "" if result.get("unbounded_places_complete", True) else (
            " (at least; the others are undecided: coverability over its budget)")
        extra = f" -- UNBOUNDED: places {', '.join(result['unbounded_places'])}{more}"
    line("bounded", "bounded", extra, "; witness below" if bounded is False and _witnessed(
        result, {"unbounded"}) else "")
    if result.get("deadlock_free") is None and result.get("stuck_markings") == 0:
        by = _METHOD_NAMES.get((result.get("methods") or {}).get("stuck_markings") or "explicit")
        lines.append(f"  deadlock-free: undecided; no dead marking other than the declared final marking"
                     f" {_format(result.get('final_marking') or {})} ({by})")
    else:
        witnessed = result.get("deadlock_free") is False and _witnessed(result, {"deadlock"})
        line("deadlock_free", "deadlock-free", f" -- only at {ends}, where a run ends" if ends else "",
             "; witness below" if witnessed and not ends else "")
    line("live", "live", f" -- no transition fires again once {ends} is reached"
         if ends and result.get("live") is False else "")
    line("reversible", "reversible", f" -- the initial marking {_format(result['initial_marking'])}"
         " is not reached again"
         f" from {ends}" if ends and result.get("reversible") is False else "")
    if ends and result["workflow_net"] and result.get("final_marking") == {result["sink_place"]: 1} \
            and result.get("live") is False:
        lines.append(f"    (short-circuited, {result['sink_place']} connected back to {result['source_place']}"
                     " as WF-net tools analyse it: deadlock-free, live and reversible, as soundness"
                     " implies)")
    dead = result.get("dead_transitions")
    fired = found.get("not_dead_transitions") or result.get("not_dead_transitions")
    if dead is None and fired is not None:
        line("dead_transitions", "dead transitions",
             f"; {len(fired)} of {result['transitions']} fire (not dead)")
    elif dead is None:
        line("dead_transitions", "dead transitions", "")
    else:
        lines.append(f"  dead transitions: {', '.join(dead) if dead else 'none'}"
                     f" ({_decided_by(result, 'dead_transitions')})")
    return lines


def _answer(result: dict[str, Any], code: int) -> str:
    """What the exit code rests on, in a few words."""
    workflow = result["workflow_net"]
    if code == EXIT_OK:
        if workflow:
            return "sound"
        return "bounded, deadlock-free" if result.get("final_marking") is None else (
            "bounded, no dead marking other than the declared final one")
    if code == EXIT_PROBLEM:
        if workflow:
            return "not sound"
        return "unbounded" if result.get("bounded") is False else "a deadlock"
    if workflow:
        return "sound"
    missing = ["bounded"] if result.get("bounded") is None else []
    return ", ".join(missing + ["deadlock-free"]) if not any(
        v["kind"] == "deadlock" for v in result["violations"]) else ", ".join(missing)


def format_report(result: dict[str, Any]) -> str:
    """A short readable report of a :func:`check_net` result.

    After the header (the exit code's word: ``OK``, ``PROBLEM``, ``UNDECIDED``), one line
    per property: its verdict and the method that decided it, or ``undecided`` and why;
    then the state space, the semiflows, the method's notes and the violations with
    their witnesses. When the state space is not complete the last line says what that
    leaves undecided: a ``note`` when the exit code's verdict was reached anyway,
    ``no verdict`` when it was not (exit 2).

    Examples:
        >>> from petriflow.classic import dining_philosophers
        >>> print(format_report(check_net(dining_philosophers(3))).splitlines()[0])
        philosophers-3: 9 places, 6 transitions -- OK
    """
    code = exit_code(result)
    verdict = {EXIT_OK: "OK", EXIT_PROBLEM: "PROBLEM", EXIT_UNDECIDED: "UNDECIDED"}[code]
    lines = [(f"{result['net']}: {result['places']} places, {result['transitions']} transitions"
              f" -- {verdict}")]
    lines.append(f"  initial marking: {_format(result['initial_marking'])}")
    if result["workflow_net"]:
        lines.append(f"  WF-net (i = {result['source_place']}, o = {result['sink_place']})"
                     f"{', free-choice' if result['free_choice'] else ''}")
    else:
        problem = next((v["message"] for v in result["violations"] if v["kind"] == "not_wf_net"), "")
        lines.append(f"  {problem or 'not a WF-net'}")
    lines.extend(_property_lines(result))
    if not result["complete"]:
        error = result.get("error") or ""
        if result.get("method") == "stubborn":
            error = "not built (--method stubborn)"
        lines.append(f"  state space: {error[len('state space '):] if error.startswith('state space ') else error}")
        found = result.get("partial")
        if found:
            facts = [f"{_count(found['states_explored'], 'state')} ({found['states_expanded']} expanded),"
                     f" {_count(found['edges_explored'], 'edge')}"]
            if found["deadlock_markings_found"]:
                facts.append(f"{_count(found['deadlock_markings_found'], 'deadlock')} found")
            lines.append("  found before the limit: " + "; ".join(facts))
    elif result["states"] is not None:
        lines.append(f"  state space: {_count(result['states'], 'state')}, {_count(result['edges'], 'edge')};"
                     f" at most {_count(result['max_tokens_place'], 'token')} in a place,"
                     f" {result['max_tokens_marking']} in a marking")
    invariants = result.get("invariants") or {}
    p_flows, t_flows = invariants.get("p_semiflows"), invariants.get("t_semiflows")
    why = invariants.get("not_computed") or {}

    def counted(flows, key):
        if flows is not None:
            return str(len(flows))
        return f"not computed ({why[key]})" if key in why else "not computed"

    too_large = invariants.get("note") if "net too large" in why.values() else None
    lines.append(
        f"  P-semiflows: {counted(p_flows, 'p_semiflows')}"
        f"{' (cover every place)' if invariants.get('covered_by_p_semiflows') else ''};"
        f" T-semiflows: {counted(t_flows, 't_semiflows')}" + (f" ({too_large})" if too_large else ""))
    if result.get("methods") is not None:
        visited = ", ".join(f"{how} {count:,}" for how, count in
                            (result.get("states_visited") or {}).items() if count is not None)
        lines.append(f"  method: {result.get('method', 'auto')}"
                     + (f" (markings stored: {visited})" if visited else ""))
        lines.extend(f"    {note}" for note in result.get("method_notes") or ())
    for violation in result["violations"]:
        if violation["kind"] == "not_wf_net" and not result["workflow_net"]:
            continue
        lines.append(f"  - {violation['message']}")
        if violation["transitions"]:
            lines.append(f"      witness: {' '.join(violation['transitions'])}")
    if not result["complete"]:
        open_ = [name for key, name in _PROPERTIES if result.get(key) is None
                 and (key != "sound" or result["workflow_net"])]
        if code == EXIT_UNDECIDED:
            missing = _answer(result, code)
            key = "sound" if result["workflow_net"] else "bounded" if missing == "bounded" else "deadlock_free"
            lines.append(f"  no verdict: {missing} undecided ({_why_undecided(result, key)})")
        elif open_:
            lines.append(f"  note: {', '.join(open_)} undecided ({_limit(result)}); the verdict"
                         f" ({_answer(result, code)}) does not depend on them")
        else:
            lines.append(f"  note: {_limit(result)}; every property above was decided without it")
    return "\n".join(lines)


#: The largest arc weight or initial token count the analysis takes: counts are exact
#: 64-bit integers inside the compiled exploration, and a weight this size keeps every
#: sum exact (larger values are refused, never wrapped).
MAX_EXACT = limits.MAX_INTEGER


def _check_range(net: Net) -> None:
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


def _count(number: int, noun: str) -> str:
    """``number`` and ``noun``, plural unless the number is one.

    Examples:
        >>> _count(1, "token"), _count(3, "reachable marking")
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
