"""``petriflow check``: every analysis of one net, as JSON-ready data and as text.

:func:`check_net` runs the structure checks (WF-net, free-choice), P/T-semiflows,
boundedness (structurally by P-semiflows, then on the fly during reachability, with a
Karp–Miller coverability graph to name the unbounded places), the reachability graph
and the properties read off it, and, for WF-nets, classical soundness with witnesses.

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
  the JSON, a one-line message on standard error), or the net file is bad input.

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

from petriflow.analysis.coverability import coverability_graph_if_any
from petriflow.analysis.invariants import (
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


def _format(marking: dict[str, int] | Marking) -> str:
    return ", ".join(f"{p}={c}" for p, c in marking.items()) or "(empty)"


def _invariants(compiled: CompiledNet, start: Marking) -> tuple[dict[str, Any], bool]:
    """The ``invariants`` section and whether P-semiflows prove the net bounded."""
    section: dict[str, Any] = {}
    try:
        flows = p_semiflows(compiled, max_rows=INVARIANT_ROWS)
    except InvariantLimit as exc:
        section.update(p_semiflows=None, covered_by_p_semiflows=None, structural_bounds=None,
                       note=str(exc))
        flows = None
    if flows is not None:
        covered = {p for y in flows for p in y}
        section["p_semiflows"] = flows
        section["covered_by_p_semiflows"] = len(covered) == len(compiled.places)
        section["structural_bounds"] = structural_bounds(compiled, start, semiflows_found=flows)
    try:
        section["t_semiflows"] = t_semiflows(compiled, max_rows=INVARIANT_ROWS)
    except InvariantLimit as exc:
        section["t_semiflows"] = None
        section.setdefault("note", str(exc))
    if getattr(compiled, "has_resets", False):
        section["note"] = ("cancellation regions (reset arcs) only remove tokens: P-semiflows"
                           " give upper bounds y·M <= y·M0, not equalities")
    return section, bool(section.get("covered_by_p_semiflows"))


def check_net(net: Net, *, max_states: int = DEFAULT_MAX_STATES) -> dict[str, Any]:
    """Analyse ``net`` and return the JSON-ready result ``petriflow check`` prints.

    Args:
        net: the net.
        max_states: the most reachable markings to explore; beyond it the result has
            ``"complete": false`` and ``"error"`` (the structural parts are still there).

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
    compiled = CompiledNet(net)
    structure = workflow_structure(net)
    start = net.initial_marking
    if not start and structure.is_wf_net:
        start = Marking({structure.source: 1})
    result: dict[str, Any] = {
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
        "k_bound": None,
        "violations": [],
        "algorithm": [],
    }
    result["invariants"], structurally_bounded = _invariants(compiled, start)
    result["structurally_bounded"] = structurally_bounded
    if structurally_bounded:
        result["algorithm"].append("P-semiflows cover every place: bounded for any marking")
    violations: list[Violation] = []
    try:
        soundness = None
        if structure.is_wf_net:
            soundness = check_soundness(net, max_states=max_states)
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
        if same_start and soundness.space is not None:
            space = soundness.space
        elif same_start and soundness.bounded is False:
            space = None
            _unbounded_result(result, net, compiled, start, None, max_states, soundness)
        else:
            try:
                space = reachability_graph(net, start, max_states=max_states, compiled=compiled,
                                           detect_unbounded=not structurally_bounded)
            except UnboundedNetError as exc:
                space = None
                violations.append(_unbounded_result(result, net, compiled, start, exc,
                                                    max_states, None))
        if space is not None:
            _bounded_result(result, space, violations, structure.is_wf_net, net.final_marking)
    except StateSpaceLimit as exc:
        result["complete"] = False
        result["error"] = str(exc)
        result["sound"] = None if structure.is_wf_net else False
    result["violations"] = [v.to_dict() for v in violations]
    result["algorithm"] = "; ".join(result["algorithm"])
    return result


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


def _unbounded_result(result, net, compiled, start, exc, max_states, soundness) -> Violation | None:
    """Fill the result for an unbounded net; returns the violation for a non-WF net."""
    result.update(bounded=False, safe=False, live=None, deadlock_free=None)
    places = list(exc.places) if exc is not None else []
    graph = coverability_graph_if_any(net, start, max_nodes=max_states, compiled=compiled)
    if graph is None:
        result["algorithm"].append("Karp-Miller coverability graph: too large or not"
                                   " applicable (reset arcs), unbounded places listed are"
                                   " those the witness pumps")
    if graph is not None:
        places = graph.unbounded_places
        result["dead_transitions"] = graph.dead_transitions()
        result["k_bound"] = graph.place_bounds()
        result["algorithm"].append("Karp-Miller coverability graph (unbounded places, dead"
                                   " transitions)")
    elif soundness is not None:
        places = next((v.elements for v in soundness.violations if v.kind == "unbounded"), [])
    result["unbounded_places"] = places
    if exc is None:
        return None
    return Violation(
        "unbounded",
        f"unbounded: firing {' '.join(exc.pump)} from the marking reached by"
        f" [{' '.join(exc.prefix)}] adds tokens to {', '.join(exc.places)} and can be repeated"
        f" forever; unbounded places: {', '.join(places)}",
        exc.prefix + exc.pump, exc.covering.to_dict(), places)


def exit_code(result: dict[str, Any]) -> int:
    """0: sound WF-net, or bounded and deadlock-free; 1: a property fails; 2: no verdict.

    Examples:
        >>> exit_code({"complete": False})
        2
        >>> exit_code({"complete": True, "workflow_net": False, "bounded": True,
        ...            "deadlock_free": False})
        1
    """
    if not result.get("complete", True):
        return EXIT_UNDECIDED
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
    if not result["complete"]:
        lines.append(f"  state space: {result['error']}")
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
        lines.append(f"  UNBOUNDED: places {', '.join(result['unbounded_places'])}")
    dead = result.get("dead_transitions")
    if dead is not None:
        lines.append(f"  dead transitions: {', '.join(dead) if dead else 'none'}")
    invariants = result.get("invariants") or {}
    p_flows, t_flows = invariants.get("p_semiflows"), invariants.get("t_semiflows")
    lines.append(
        f"  P-semiflows: {'not computed' if p_flows is None else len(p_flows)}"
        f"{' (cover every place)' if invariants.get('covered_by_p_semiflows') else ''};"
        f" T-semiflows: {'not computed' if t_flows is None else len(t_flows)}"
        + (f" ({invariants['note']})" if invariants.get("note") and (p_flows is None or t_flows is None) else ""))
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
