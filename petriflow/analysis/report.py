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
* ``1`` — a property fails (the ``violations`` say which, with witnesses);
* ``2`` — no verdict: the state space exceeds ``--max-states`` (``"complete": false`` in
  the JSON, a one-line message on standard error) and nothing found before the limit
  fails (a deadlock, or for a WF-net improper completion or a dead end, found before it
  gives ``1``), or the net file is bad input.

Examples:
    >>> from petriflow.classic import dining_philosophers
    >>> result = check_net(dining_philosophers(5))
    >>> result["states"], result["edges"], result["bounded"], result["deadlock_free"]
    (11, 30, True, True)
    >>> exit_code(result)
    0
"""

from __future__ import annotations

from typing import Any

import numpy as np

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


def soundness_final(net: Net, structure) -> Marking | None:
    """The final marking soundness is decided for: the net's, else one token in ``o``."""
    if not structure.is_wf_net:
        return None
    return net.final_marking if net.final_marking is not None else Marking({structure.sink: 1})


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


def _yes(value: Any) -> str:
    return {True: "yes", False: "no", None: "unknown"}[value]


def format_report(result: dict[str, Any]) -> str:
    """A short readable report of a :func:`check_net` result.

    Examples:
        >>> from petriflow.classic import dining_philosophers
        >>> print(format_report(check_net(dining_philosophers(3))).splitlines()[0])
        philosophers-3: 9 places, 6 transitions -- OK
    """
    verdict = {EXIT_OK: "OK", EXIT_PROBLEM: "PROBLEM", EXIT_UNDECIDED: "UNDECIDED"}[exit_code(result)]
    lines = [(f"{result['net']}: {result['places']} places, {result['transitions']} transitions"
              f" -- {verdict}")]
    lines.append(f"  initial marking: {_format(result['initial_marking'])}")
    if result["workflow_net"]:
        sound = result["sound"]
        lines.append(f"  WF-net (i = {result['source_place']}, o = {result['sink_place']}):"
                     f" {'sound' if sound else 'not sound' if sound is False else 'undecided'}"
                     f"{', free-choice' if result['free_choice'] else ''}")
    else:
        problem = next((v["message"] for v in result["violations"] if v["kind"] == "not_wf_net"), "")
        lines.append(f"  {problem or 'not a WF-net'}")
    methods = result.get("methods")
    if methods:
        answered = {}
        for key, how in methods.items():
            if how is not None:
                answered.setdefault(how, []).append(key)
        visited = ", ".join(f"{how} {count:,}" for how, count in
                            (result.get("states_visited") or {}).items() if count is not None)
        lines.append(f"  method ({result.get('method', 'auto')}): "
                     + "; ".join(f"{how}: {', '.join(keys)}" for how, keys in answered.items())
                     + (f" (markings stored: {visited})" if visited else ""))
        lines.extend(f"    {note}" for note in result.get("method_notes") or ())
    if not result["complete"]:
        lines.append(f"  state space: {result['error']}")
        found = result.get("partial")
        if found:
            facts = [f"{_count(found['states_explored'], 'state')} ({found['states_expanded']} expanded),"
                     f" {_count(found['edges_explored'], 'edge')}"]
            if result.get("safe") is False:
                top = max(found["k_bound_at_least"].items(), key=lambda item: item[1])
                facts.append(f"not safe ({top[0]} reaches {top[1]} tokens)")
            if found["deadlock_markings_found"]:
                facts.append(f"{_count(found['deadlock_markings_found'], 'deadlock')} found")
            facts.append(f"{len(found['not_dead_transitions'])} of {result['transitions']}"
                         " transitions fire (not dead)")
            lines.append("  found before the limit: " + "; ".join(facts))
            lines.append(f"  undecided: {', '.join(result.get('undecided', []))}")
    elif result["bounded"]:
        safety = "safe" if result["safe"] else f"{result['max_tokens_place']}-bounded"
        lines.append(f"  state space: {_count(result['states'], 'state')}, {_count(result['edges'], 'edge')};"
                     f" bounded ({safety}); at most {_count(result['max_tokens_marking'], 'token')} in a marking")
        ending = ""
        if not result["deadlock_free"] and result.get("stuck_markings") == 0:
            ending = " (the only dead marking is the declared final marking)"
        lines.append(f"  deadlock-free: {_yes(result['deadlock_free'])}{ending}"
                     f"   live: {_yes(result['live'])}   reversible: {_yes(result['reversible'])}")
    else:
        more = "" if result.get("unbounded_places_complete", True) else (
            " (at least; the others are undecided: coverability over its budget)")
        lines.append(f"  UNBOUNDED: places {', '.join(result['unbounded_places'])}{more}")
    dead = result.get("dead_transitions")
    if dead is not None:
        lines.append(f"  dead transitions: {', '.join(dead) if dead else 'none'}")
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
    for violation in result["violations"]:
        if violation["kind"] == "not_wf_net" and not result["workflow_net"]:
            continue
        lines.append(f"  - {violation['message']}")
        if violation["transitions"]:
            lines.append(f"      witness: {' '.join(violation['transitions'])}")
    return "\n".join(lines)


#: The largest arc weight or initial token count the analysis takes: counts are exact
#: 64-bit integers inside the compiled exploration, and a weight this size keeps every
#: sum exact (larger values are refused, never wrapped).
MAX_EXACT = 2**60


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
