"""``petriflow check`` by the explicit state space: every property of one net, with witnesses.

:func:`explicit_check` is the ``explicit`` method of
:func:`~petriflow.analysis.check.check_net`, and the fallback of the reductions of
:mod:`~petriflow.analysis.methods`. In order, each within its own budget: the
structure (WF-net, free-choice); P-semiflows, which may prove every place bounded;
unless they do, a depth-first Karp–Miller search, which reports an unbounded net with
its pumping witness without exploring further; for a WF-net, classical soundness from
``[i]`` (:func:`~petriflow.analysis.soundness.check_soundness`), whose state space is
reused when the net starts in ``[i]``; the state space and the properties read off it,
or, when it stops at the limit, every definite fact found so far; T-semiflows last.

Examples:
    >>> from petriflow.classic import dining_philosophers
    >>> result = explicit_check(dining_philosophers(5))
    >>> result["states"], result["deadlock_free"], result["live"], "methods" in result
    (11, True, True, False)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from petriflow.analysis.check_result import (
    add_p_semiflows,
    add_t_semiflows,
    check_range,
    coverability_note,
    explored_marking,
    quantity,
    skeleton,
    soundness_final,
)
from petriflow.analysis.coverability import (
    DEFAULT_MAX_COVERABILITY,
    CoverabilitySearch,
    coverability_search,
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
from petriflow.analysis.soundness import Violation, check_soundness
from petriflow.engine import CompiledNet
from petriflow.marking import Marking, format_marking
from petriflow.net import Net
from petriflow.workflow import workflow_structure

__all__ = ["explicit_check"]


def explicit_check(net: Net, *, max_states: int = DEFAULT_MAX_STATES,
                   max_coverability: int = DEFAULT_MAX_COVERABILITY,
                   invariant_budget: int | None = None) -> dict[str, Any]:
    """The result of :func:`~petriflow.analysis.check.check_net` by the explicit state
    space (its arguments; no ``methods`` key).

    Raises:
        PetriflowError: a weight or count beyond what the analysis counts exactly.
    """
    check_range(net)
    compiled = CompiledNet(net)
    structure = workflow_structure(net)
    start = explored_marking(net, structure)
    result = skeleton(net, structure, start)
    covered = add_p_semiflows(result, compiled, start, invariant_budget)
    structurally_bounded = result["structurally_bounded"]
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
            coverability_note(result, probe, max_coverability)
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
        coverability_note(result, probe, max_coverability)
        if space is not None:
            _bounded_result(result, space, violations, structure.is_wf_net, net.final_marking)
    except StateSpaceLimit as exc:
        coverability_note(result, probe or getattr(exc, "coverability", None), max_coverability)
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
    explored = (result["states"] or 0) + (result["edges"] or 0)
    explored += sum((result.get(k) or {}).get(n, 0) for k, n in (
        ("partial", "states_explored"), ("partial", "edges_explored"),
        ("coverability", "nodes"), ("coverability", "edges")))
    add_t_semiflows(result, compiled, invariant_budget, explored)
    result["violations"] = [v.to_dict() for v in violations]
    result["algorithm"] = "; ".join(result["algorithm"])
    return result


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
    if (result["safe"] is None and len(limits_found) == len(names)
            and max(limits_found.values(), default=0) <= 1):
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
                f" {format_marking(sound_final)} with tokens left elsewhere: {format_marking(reached)}"
                " (found before the state limit)", space.path(state), reached.to_dict()))
        dead_ends = [s for s in dead_states.tolist() if space.marking(int(s)) != sound_final]
        if dead_ends:
            state = int(dead_ends[0])
            reached = space.marking(state)
            violations.append(Violation(
                "no_option_to_complete",
                f"no option to complete: {format_marking(reached)} is a deadlock other than the final"
                f" marking {format_marking(sound_final)} (found before the state limit)",
                space.path(state), reached.to_dict()))
        if improper.size or dead_ends:
            result["sound"] = False
            undecided.remove("sound")
    elif stuck.size and not workflow:
        state = int(stuck[0])
        reached = space.marking(state)
        violations.append(Violation(
            "deadlock", f"deadlock: {format_marking(reached)} enables no transition (found before the"
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
            "deadlock", f"deadlock: {quantity(count, 'reachable marking')} "
            f"{'enables' if count == 1 else 'enable'} no transition, e.g. {format_marking(reached)}",
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
