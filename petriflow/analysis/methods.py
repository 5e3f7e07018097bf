"""How ``petriflow check`` answers: the explicit state space, or a reduction.

:func:`check_with_method` runs :func:`~petriflow.analysis.check.check_net` with one
of :data:`METHODS`:

* ``explicit`` — the full state space (:mod:`~petriflow.analysis.explicit`);
* ``symmetry`` — the state space up to permutations of interchangeable agents
  (:mod:`~petriflow.analysis.symmetry`); falls back to ``explicit`` (and says so) when
  the net has no verified symmetric agents, its boundedness is not proved first, or a
  place could hold more than 255 tokens;
* ``stubborn`` — deadlocks by stubborn sets (:mod:`~petriflow.analysis.stubborn`);
  no state space: the properties it does not preserve stay undecided;
* ``structural`` — soundness of free-choice WF-nets by the Rank Theorem
  (:mod:`~petriflow.analysis.structural`), the other properties from the explicit
  state space;
* ``auto`` — the Rank Theorem where it applies, the symmetry reduction where the net
  has symmetric agents (else the explicit state space), and, when that exploration
  stops at ``--max-states``, stubborn sets for deadlocks.

The result says which method answered each property (``methods``) and how many
markings each exploration stored (``states_visited``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from petriflow.analysis._graph import components, reaching
from petriflow.analysis.reachability import StateSpaceLimit
from petriflow.analysis.check_result import (
    add_p_semiflows,
    add_t_semiflows,
    coverability_note,
    explored_marking,
    skeleton,
    soundness_final,
)
from petriflow.analysis.explicit import explicit_check
from petriflow.analysis.soundness import Violation
from petriflow.workflow import workflow_structure
from petriflow.engine import CompiledNet
from petriflow.errors import PetriflowError
from petriflow.marking import Marking, format_marking
from petriflow.net import Net

__all__ = ["METHODS", "check_with_method"]

#: The values of ``petriflow check --method``.
METHODS = ("auto", "explicit", "symmetry", "stubborn", "structural")

#: With ``auto``, the stubborn-set search that follows an exploration stopped at
#: ``max_states`` stores at most ``max_states // AUTO_STUBBORN_SHARE`` markings (it runs
#: in Python, about a hundred times slower a marking than the compiled explorations).
AUTO_STUBBORN_SHARE = 10
#: ... and at most this many (marking, transition) enabledness tests (about a minute).
AUTO_STUBBORN_WORK = 100_000_000

#: The properties ``methods`` names.
PROPERTIES = ("sound", "bounded", "deadlock_free", "dead_transitions", "live", "reversible",
              "states")



def check_with_method(net: Net, method: str, **budgets) -> dict[str, Any]:
    """``check_net`` by ``method`` (see the module); ``budgets`` are ``check_net``'s."""
    if method not in METHODS:
        raise PetriflowError(f"--method must be one of {', '.join(METHODS)}, got {method!r}")
    structure = workflow_structure(net)
    start = explored_marking(net, structure)
    notes: list[str] = []
    result = None
    used = "explicit"
    if method in ("auto", "symmetry"):
        result, why = _symmetric(net, structure, start, budgets)
        if result is not None:
            used = "symmetry"
        elif method == "symmetry" or why != "no symmetric agents":
            notes.append(f"symmetry reduction not used ({why}): explicit state space")
    if result is None and method == "stubborn":
        result = explicit_check(net, **dict(budgets, max_states=1))
        result["error"] = ("--method stubborn explores no full state space: deadlocks (and a"
                           " WF-net's soundness) by stubborn sets, the properties they do not"
                           " preserve undecided")
        result["partial"] = None
        result["undecided"] = [k for k in ("states", "edges", "live", "reversible", "dead_transitions",
                                           "max_tokens_place", "max_tokens_marking", "k_bound",
                                           "deadlock_free", "sound") if result.get(k) is None
                               and (k != "sound" or structure.is_wf_net)]
        for key in ("safe", "states", "edges", "k_bound", "dead_transitions"):
            if key in result and result.get("complete") is False and key != "safe":
                result[key] = None
        used = "stubborn"
    if result is None:
        result = explicit_check(net, **budgets)
    result["method"] = method
    methods = {key: (used if used != "stubborn" else None) for key in PROPERTIES}
    if used == "explicit" or used == "symmetry":
        visited = result.pop("_visited", None)
        if visited is None:
            visited = result["states"] if result["complete"] else (result.get("partial") or {}).get(
                "states_explored")
        result["states_visited"] = {used: visited}
    else:
        result["states_visited"] = {}
    for key in PROPERTIES:
        if result.get(key) is None:
            methods[key] = None
    if result.get("bounded") is not None and (used == "stubborn" or result.get("structurally_bounded")
                                              or (result.get("coverability") or {}).get("complete")):
        methods["bounded"] = ("P-semiflows" if result.get("structurally_bounded") else
                              "Karp-Miller" if (result.get("coverability") or {}).get("complete")
                              else methods["bounded"] or "explicit")
    if not structure.is_wf_net:
        methods["sound"] = "WF-net structure"
    result["methods"] = methods
    if used == "symmetry" and result.get("live") is None and result["complete"]:
        _liveness_fallback(net, start, result, methods, notes, budgets)
    if structure.is_wf_net and method in ("auto", "structural"):
        _structural(net, result, methods, notes)
    reduced = structure.is_wf_net and start == Marking({structure.source: 1})
    if reduced and (method == "stubborn" or (method == "auto" and not result["complete"]
                                             and result.get("sound") is None)):
        _reduced(net, result, methods, notes, budgets)
    # deadlocks by the Python search where nothing above decided them
    if (method == "stubborn" or (method == "auto" and not result["complete"])) and \
            result.get("deadlock_free") is None and not (structure.is_wf_net
                                                         and result.get("sound") is not None):
        _stubborn(net, structure, start, result, methods, notes, budgets)
    if notes:
        result["method_notes"] = notes
        result["algorithm"] = "; ".join([result["algorithm"]] + notes) if result["algorithm"] else \
            "; ".join(notes)
    return result


def _liveness_fallback(net: Net, start, result: dict, methods: dict, notes: list[str],
                       budgets: dict) -> None:
    """Liveness the symmetry reduction left open, from the full state space when its
    (exactly known) size is within ``max_states``."""
    from petriflow.analysis.properties import non_live_witness
    from petriflow.analysis.reachability import reachability_graph

    limit = budgets.get("max_states") or 2_000_000
    if result["states"] > limit:
        notes.append(f"liveness undecided: the symmetry reduction cannot decide it and the full"
                     f" state space ({result['states']:,} markings) is over --max-states")
        return
    space = reachability_graph(net, start, max_states=limit)
    found = non_live_witness(space)
    result["live"] = found is None
    if found is not None:
        result["non_live"] = {"transitions": found[1], "witness": found[0]}
    methods["live"] = "explicit"
    result["states_visited"]["explicit"] = space.num_states
    if "live" in (result.get("undecided") or []):
        result["undecided"].remove("live")
    notes.append("liveness: not decided by the symmetry reduction; from the full state space"
                 f" ({space.num_states:,} markings)")


# Structural --------------------------------------------------------------------------

def _structural(net: Net, result: dict, methods: dict, notes: list[str]) -> None:
    from petriflow.analysis.structural import structural_soundness

    verdict = structural_soundness(net)
    result["structural"] = {"sound": verdict.sound, "net_class": verdict.net_class,
                            "reason": verdict.reason, "conditions": verdict.conditions}
    if verdict.sound is None:
        notes.append(f"structural soundness not decided ({verdict.reason})")
        return
    if result.get("sound") is None:
        result["sound"] = verdict.sound
        methods["sound"] = "structural"
        if "undecided" in result and "sound" in result["undecided"]:
            result["undecided"].remove("sound")
        result["structural"]["agrees"] = None
        notes.append(f"soundness: Rank Theorem ({verdict.net_class}): {verdict.reason}")
        if verdict.sound is False:
            result.setdefault("violations", []).append(Violation(
                "not_sound_structural", f"not sound ({verdict.net_class} WF-net): {verdict.reason}"
            ).to_dict())
    else:
        result["structural"]["agrees"] = result["sound"] == verdict.sound
        methods["sound"] = f"{methods['sound']} (structural agrees)" if verdict.sound == result[
            "sound"] else methods["sound"]


# Stubborn sets -----------------------------------------------------------------------

def _stubborn(net: Net, structure, start, result: dict, methods: dict, notes: list[str],
              budgets: dict) -> None:
    from petriflow.analysis.stubborn import stubborn_deadlocks

    final = soundness_final(net, structure) if structure.is_wf_net else net.final_marking
    limit = budgets.get("max_states") or 2_000_000
    if result.get("method") == "auto":
        # after an exploration that already stopped at the limit: a tenth of it, and at
        # most AUTO_STUBBORN_WORK enabledness tests (markings x transitions)
        rows = max(1, len(CompiledNet(net).transitions))
        limit = max(1, min(limit // AUTO_STUBBORN_SHARE, AUTO_STUBBORN_WORK // rows))
    try:
        found = stubborn_deadlocks(net, start, max_states=limit, first=True, ignore=final)
    except StateSpaceLimit as exc:
        found = exc.partial
        notes.append(f"stubborn sets: stopped at {limit:,} markings without finding a deadlock")
        result["states_visited"]["stubborn"] = found.states
        return
    result["states_visited"]["stubborn"] = found.states
    reduced = "" if found.reduced else " (cancellation regions: no reduction)"
    result["stubborn"] = {"states": found.states, "edges": found.edges, "reduced": found.reduced,
                          "dead_marking_found": found.deadlock}
    violations = result.setdefault("violations", [])
    if found.deadlock:
        result["deadlock_free"] = False
        methods["deadlock_free"] = "stubborn"
        if result.get("stuck_markings") is None:
            result["stuck_markings_at_least"] = 1
        message = (f"deadlock: {format_marking(found.marking)} enables no transition (stubborn-set search;"
                   " more may exist)")
        if structure.is_wf_net:
            if result.get("sound") is None:
                result["sound"] = False
                methods["sound"] = "stubborn"
            violations.append(Violation(
                "no_option_to_complete", f"no option to complete: {format_marking(found.marking)} is a"
                f" deadlock other than the final marking {format_marking(final)} (stubborn-set search)",
                found.witness, found.marking.to_dict()).to_dict())
        elif not any(v["kind"] == "deadlock" for v in violations):
            violations.append(Violation("deadlock", message, found.witness,
                                        found.marking.to_dict()).to_dict())
        notes.append(f"deadlocks: stubborn sets{reduced}, {found.states:,} markings")
    else:
        if final is None:
            result["deadlock_free"] = True
            methods["deadlock_free"] = "stubborn"
        result["stuck_markings"] = 0
        methods["stuck_markings"] = "stubborn"
        notes.append(f"no dead marking other than the final one: stubborn sets{reduced},"
                     f" {found.states:,} markings")
    for key in ("deadlock_free", "sound"):
        if result.get(key) is not None and key in result.get("undecided", []):
            result["undecided"].remove(key)


def _reduced(net: Net, result: dict, methods: dict, notes: list[str], budgets: dict) -> None:
    """Soundness on the stubborn-set graph up to symmetry, when nothing else decided it."""
    from petriflow.analysis.reduced_soundness import reduced_soundness

    covered = (result.get("invariants") or {}).get("covered_by_p_semiflows")
    found = reduced_soundness(net, max_states=budgets.get("max_states") or 2_000_000,
                              covered=covered)
    result["reduced"] = {"states": found.states, "edges": found.edges, "groups": found.groups,
                         "complete": found.complete, "sound": found.sound,
                         "option_to_complete": found.option_to_complete,
                         "proper_completion": found.proper_completion,
                         "no_dead_transitions": found.no_dead_transitions,
                         "transitions_not_seen_enabled": found.unseen[:100]}
    result["states_visited"][found.method] = found.states
    where = (f"stubborn sets up to permutations of {', '.join(str(len(g)) for g in found.groups)}"
             f" agents" if found.groups else "stubborn sets")
    result.setdefault("violations", []).extend(v.to_dict() for v in found.violations)
    if found.sound is None:
        notes.append(f"soundness not decided on the reduced graph ({where}, {found.states:,}"
                     f" markings): {found.reason}")
        return
    result["sound"] = found.sound
    methods["sound"] = found.method
    if found.proper_completion:
        result["bounded"] = True
        methods["bounded"] = "P-semiflows"
    if found.no_dead_transitions and found.option_to_complete:
        result["dead_transitions"] = []
        methods["dead_transitions"] = found.method
    if found.option_to_complete:
        # the final marking is reachable and enables nothing: a dead marking, where no
        # transition can fire again and from which [i] is not reached
        result["deadlock_markings"] = 1         # every dead marking is the final one
        result["stuck_markings"] = 0 if net.final_marking is not None else 1
        result["deadlock_free"] = False
        methods["deadlock_free"] = found.method
        if result.get("initial_marking") != (found.final or {}):
            result["live"] = result["reversible"] = False
            methods["live"] = methods["reversible"] = found.method
    for key in ("sound", "bounded", "dead_transitions", "deadlock_free", "live", "reversible"):
        if result.get(key) is not None and key in (result.get("undecided") or []):
            result["undecided"].remove(key)
    notes.append(f"soundness: {'sound' if found.sound else 'not sound'} on the reduced graph"
                 f" ({where}, {found.states:,} markings)")


# Symmetry ----------------------------------------------------------------------------

def _symmetric(net: Net, structure, start, budgets: dict) -> tuple[dict | None, str]:
    """The symmetry-reduced check, or ``(None, why not)``."""
    from petriflow.analysis.coverability import DEFAULT_MAX_COVERABILITY, coverability_search
    from petriflow.analysis.symmetry import (
        SymmetryUnsupported,
        find_symmetries,
        symmetric_graph,
    )

    compiled = CompiledNet(net)
    final_sound = soundness_final(net, structure)
    if structure.is_wf_net and start != Marking({structure.source: 1}):
        return None, "a WF-net explored from a marking other than [i]"
    final = final_sound if structure.is_wf_net else net.final_marking
    groups = find_symmetries(net, compiled=compiled, start=start, final=final)
    if not groups:
        return None, "no symmetric agents"
    result = skeleton(net, structure, start)
    invariant_budget = budgets.get("invariant_budget")
    add_p_semiflows(result, compiled, start, invariant_budget)
    if not result["structurally_bounded"]:
        budget = budgets.get("max_coverability", DEFAULT_MAX_COVERABILITY)
        if budget <= 0 or compiled.has_resets:
            return None, "boundedness not proved by P-semiflows"
        probe = coverability_search(net, start, max_nodes=budget, compiled=compiled)
        coverability_note(result, probe, budget)
        if not probe.bounded:
            return None, "boundedness not proved by P-semiflows or the Karp-Miller search"
    max_states = budgets.get("max_states") or 2_000_000
    try:
        space = symmetric_graph(net, start, groups=groups, max_states=max_states, compiled=compiled)
    except SymmetryUnsupported as exc:
        return None, str(exc)
    except StateSpaceLimit as exc:
        space = exc.partial
        result["complete"] = False
        result["error"] = f"{exc} (states here: canonical markings, one per orbit of the agents)"
    result["symmetry"] = {"groups": [g.agents for g in groups], "canonical_states": space.num_states,
                          "canonical_edges": space.num_edges}
    agents = "; ".join(f"{g.size} agents ({g.agents[0]}, ...)" for g in groups)
    result["algorithm"].append(f"symmetry reduction: {agents} interchangeable;"
                               f" {space.num_states:,} canonical markings")
    result["_visited"] = space.num_states
    violations: list[Violation] = []
    if not structure.is_wf_net:
        violations.append(Violation("not_wf_net", f"not a WF-net: {structure.problem}",
                                    elements=structure.not_on_path))
    _fill_symmetric(result, space, compiled, structure, final, violations)
    add_t_semiflows(result, compiled, invariant_budget, space.num_states + space.num_edges)
    result["violations"] = [v.to_dict() for v in violations]
    result["algorithm"] = "; ".join(result["algorithm"])
    return result, ""


def _fill_symmetric(result: dict, space, compiled: CompiledNet, structure, final,
                    violations: list[Violation]) -> None:
    from petriflow.analysis.symmetry import transition_orbits

    names = compiled.places
    bounds = space.place_bounds()
    markings = space.markings
    orbits = transition_orbits(compiled, space.groups)
    fired_orbits = set(orbits[np.flatnonzero(space.fired)].tolist())
    fired_rows = np.asarray([o in fired_orbits for o in orbits.tolist()], dtype=bool)
    dead = list(dict.fromkeys(compiled.origin[t][0] for t in np.flatnonzero(~fired_rows)))
    dead_states = space.deadlocks()
    final_vector = None if final is None else np.asarray(compiled.vector(final), dtype=np.int64)
    stuck = [int(s) for s in dead_states.tolist()
             if final_vector is None or not np.array_equal(markings[s], final_vector)]
    if not space.complete:
        result["partial"] = {
            "states_explored": space.num_states, "states_expanded": int(space.expanded),
            "edges_explored": space.num_edges, "canonical": True,
            "max_tokens_place_at_least": int(bounds.max(initial=0)),
            "max_tokens_marking_at_least": int(markings.sum(axis=1).max(initial=0)),
            "k_bound_at_least": {p: int(k) for p, k in zip(names, bounds)},
            "deadlock_markings_found": int(dead_states.size),
            "not_dead_transitions": [t for t in dict.fromkeys(o for o, _ in compiled.origin)
                                     if t not in dead],
        }
        result["bounded"] = True
        if bounds.max(initial=0) >= 2:
            result["safe"] = False
        undecided = ["states", "edges", "live", "reversible", "dead_transitions",
                     "max_tokens_place", "max_tokens_marking", "k_bound"]
        if dead_states.size:
            result["deadlock_free"] = False
        else:
            undecided.append("deadlock_free")
        if result["safe"] is None:
            undecided.append("safe")
        if structure.is_wf_net:
            result["sound"] = None
            if stuck:
                state = stuck[0]
                path, reached = space.concrete(state)
                violations.append(Violation(
                    "no_option_to_complete", f"no option to complete: {format_marking(reached)} is a deadlock"
                    f" other than the final marking {format_marking(final)} (found before the state limit)",
                    path, reached.to_dict()))
                result["sound"] = False
            else:
                undecided.append("sound")
        elif stuck:
            path, reached = space.concrete(stuck[0])
            violations.append(Violation(
                "deadlock", f"deadlock: {format_marking(reached)} enables no transition (found before the"
                " state limit; more may exist)", path, reached.to_dict()))
        result["stuck_markings"] = None
        result["undecided"] = undecided
        return
    orbit = space.orbit
    top = int(bounds.max(initial=0))
    result.update(
        bounded=True, safe=top <= 1, states=space.full_states, edges=space.full_edges,
        max_tokens_place=top, max_tokens_marking=int(markings.sum(axis=1).max(initial=0)),
        k_bound={p: int(k) for p, k in zip(names, bounds)},
        deadlock_free=not dead_states.size,
        deadlock_markings=sum(orbit[s] for s in dead_states.tolist()),
        dead_transitions=dead,
    )
    result["stuck_markings"] = sum(orbit[s] for s in stuck)
    final_state = space.index(final) if final is not None else None
    result["final_marking_reached"] = None if final is None else final_state is not None
    n = space.num_states
    result["reversible"] = bool(reaching(space.edge_offsets, space.edge_target, [0]).all())
    # liveness: terminal components of the quotient
    labels = components(space.edge_offsets, space.edge_target)
    source = np.repeat(np.arange(n), np.diff(space.edge_offsets))
    leaving = np.unique(labels[source[labels[source] != labels[space.edge_target]]])
    terminal_states = np.flatnonzero(~np.isin(labels, leaving))
    pre = compiled.pre_matrix
    lacking_rows: set[int] = set()
    witness_state = None
    for label in np.unique(labels[terminal_states]).tolist():
        states = terminal_states[labels[terminal_states] == label]
        enabled = np.zeros(len(compiled.transitions), dtype=bool)
        for chunk in range(0, states.size, 4096):
            rows = markings[states[chunk: chunk + 4096]].astype(np.int64)
            enabled |= (rows[:, None, :] >= pre[None, :, :]).all(axis=2).any(axis=0)
        present = set(orbits[enabled].tolist())
        missing = [t for t in range(len(orbits)) if orbits[t] not in present]
        if missing and witness_state is None:
            witness_state = int(states.min())
            lacking_rows.update(missing)
    singleton = len(set(orbits.tolist())) == len(orbits)
    if witness_state is not None:
        result["live"] = False
        path = space.path(witness_state)
        result["non_live"] = {"transitions": list(dict.fromkeys(compiled.origin[t][0]
                                                                for t in sorted(lacking_rows))),
                              "witness": path}
    elif singleton:
        result["live"] = True
    else:
        result["live"] = None
        result["undecided"] = ["live"]
        result["algorithm"].append("liveness undecided: the symmetry reduction preserves it only"
                                   " when it fails or every transition is fixed by the permutations")
    if stuck and not structure.is_wf_net:
        path, reached = space.concrete(stuck[0])
        count = result["stuck_markings"]
        violations.append(Violation(
            "deadlock", f"deadlock: {count} reachable marking{'s' if count != 1 else ''} enable no"
            f" transition, e.g. {format_marking(reached)}", path, reached.to_dict()))
    if not structure.is_wf_net:
        return
    # soundness from [i]: Mf and [i] are fixed by every permutation
    proper = (markings >= final_vector).all(axis=1) & (markings != final_vector).any(axis=1)
    improper = np.flatnonzero(proper)
    if improper.size:
        path, reached = space.concrete(int(improper[0]))
        violations.append(Violation(
            "improper_completion", f"improper completion: {sum(orbit[s] for s in improper.tolist())}"
            f" reachable markings cover the final marking {format_marking(final)} with tokens left elsewhere,"
            f" e.g. {format_marking(reached)}", path, reached.to_dict()))
    can_finish = np.zeros(n, dtype=bool) if final_state is None else reaching(
        space.edge_offsets, space.edge_target, [final_state])
    if not can_finish.all():
        stuck_states = np.flatnonzero(~can_finish)
        dead_stuck = [s for s in stuck if not can_finish[s]]
        state = dead_stuck[0] if dead_stuck else int(stuck_states[0])
        path, reached = space.concrete(state)
        kind = "a deadlock" if dead_stuck else "no firing sequence leads back"
        violations.append(Violation(
            "no_option_to_complete", f"no option to complete: from {format_marking(reached)} the final"
            f" marking {format_marking(final)} can no longer be reached ({kind})", path, reached.to_dict()))
    if dead:
        violations.append(Violation(
            "dead_transition", f"{len(dead)} dead transitions (enabled in no marking reachable"
            f" from [{structure.source}]): {', '.join(dead)}", elements=dead))
    result["soundness"] = {"option_to_complete": bool(can_finish.all()),
                           "proper_completion": not improper.size,
                           "no_dead_transitions": not dead,
                           "final_marking": final.to_dict(), "crosscheck": None}
    result["sound"] = bool(can_finish.all() and not improper.size and not dead)
    result["algorithm"].append("soundness: on the symmetry-reduced graph from [i]"
                               " ([i] and the final marking are fixed by every permutation)")
