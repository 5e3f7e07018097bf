"""Soundness of a WF-net decided on a stubborn-set reduced graph, up to symmetry.

The full state space of a team of ``N`` interchangeable agents grows like ``k^N``, and
even one canonical marking per orbit of the agents (:mod:`~petriflow.analysis.symmetry`)
leaves ``C(N + k - 1, k - 1)`` orbits. This module decides the three soundness
conditions on a much smaller graph: each canonical marking fires only a *stubborn set*
of the transitions that change the marking (:func:`~petriflow.analysis.stubborn.relations`
lists the D1/D2 relations; the compiled search is
:func:`~petriflow.analysis.symmetry.symmetric_graph` with ``stubborn=True``).

Why the answer is exact (docs/analysis.md, "Soundness on the reduced graph"):

* **Option to complete.** Transitions whose preset equals their postset are left out:
  they never change the marking, so the reachability relation, and with it the option
  to complete, is the same without them. In that net, the final marking ``Mf`` (it
  enables nothing, every transition of a WF-net has an input place) is reachable from
  every reachable marking exactly when (a) every reachable dead marking is ``Mf`` and
  (b) a dead marking is reachable from every reachable marking. Stubborn sets (D1, D2,
  every enabled member a key transition) keep (a): every reachable dead marking is in
  the reduced graph (Valmari). They keep (b) too, without any condition against
  ignoring: from a marking of the reduced graph a dead marking is reachable in the
  reduced graph exactly when it is in the full one, and if every marking of the
  reduced graph reaches a dead marking, so does every reachable marking (the proof in
  docs/analysis.md moves the first stubborn transition of a path to the front, and
  follows the reduced path to a dead marking otherwise). Both arguments hold on the
  quotient by the agents' permutations, which map paths onto paths and dead markings
  onto dead markings.
* **Proper completion and boundedness** come from a P-semiflow ``y`` that is positive
  on every place: ``y . M`` is the same for every reachable ``M``, so the net is bounded,
  and once ``Mf`` is reachable, a reachable ``M >= Mf`` has ``y . (M - Mf) = 0``, so
  ``M = Mf``. Without such a semiflow soundness is left undecided.
* **No dead transitions**: every transition enabled in an explored marking (each a
  reachable marking) is not dead, nor is any transition of its orbit. A transition
  never seen enabled may still be enabled in a marking the reduction skipped: if any
  is left, soundness is undecided (never "dead" on this evidence).

Every violation found comes with a concrete firing sequence from ``[i]``.

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> net = loads_net('''
    ... petriflow: 1
    ... places: [i, a1, a2, b1, b2, o]
    ... transitions:
    ...   - {id: split, in: [i], out: [a1, b1]}
    ...   - {id: ta, in: [a1], out: [a2]}
    ...   - {id: tb, in: [b1], out: [b2]}
    ...   - {id: join, in: [a2, b2], out: [o]}
    ... ''')
    >>> found = reduced_soundness(net)     # ta and tb in one order only: 5 of 6 markings
    >>> found.sound, found.states, found.method
    (True, 5, 'stubborn')
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from petriflow.analysis._graph import reaching
from petriflow.analysis.reachability import DEFAULT_MAX_STATES, StateSpaceLimit
from petriflow.analysis.check_result import invariants_section, soundness_final
from petriflow.analysis.soundness import Violation
from petriflow.engine import CompiledNet
from petriflow.marking import Marking, format_marking
from petriflow.net import Net
from petriflow.workflow import workflow_structure

__all__ = ["ReducedSoundness", "reduced_soundness"]


@dataclass
class ReducedSoundness:
    """The answer of :func:`reduced_soundness`.

    Attributes:
        sound: ``True``/``False``, or ``None`` when undecided (``reason`` says why).
        option_to_complete, proper_completion, no_dead_transitions: each condition,
            ``None`` when undecided.
        violations: each with a concrete witness from ``[i]``.
        states, edges: canonical markings and edges of the reduced graph.
        groups: the interchangeable agents used (empty: stubborn sets alone).
        unseen: transitions never seen enabled (their deadness is undecided).
        complete: ``False`` when ``max_states`` stopped the search.
        reason: why something is undecided (empty when all is decided).
        final: the final marking soundness is decided for (as a dict).
    """

    sound: bool | None
    option_to_complete: bool | None = None
    proper_completion: bool | None = None
    no_dead_transitions: bool | None = None
    violations: list[Violation] = field(default_factory=list)
    states: int = 0
    edges: int = 0
    groups: list[list[str]] = field(default_factory=list)
    unseen: list[str] = field(default_factory=list)
    complete: bool = True
    reason: str = ""
    final: dict[str, int] = field(default_factory=dict)

    @property
    def method(self) -> str:
        """How it was decided, as ``check``'s ``methods`` names it."""
        return "stubborn+symmetry" if self.groups else "stubborn"



def reduced_soundness(net: Net, *, max_states: int = DEFAULT_MAX_STATES,
                      compiled: CompiledNet | None = None,
                      covered: bool | None = None) -> ReducedSoundness:
    """Decide soundness of the WF-net ``net`` from ``[i]`` on the stubborn-set graph,
    with its verified symmetric agents (if any) explored up to permutation.

    Args:
        max_states: the most canonical markings to store.
        covered: whether a P-semiflow covers every place (a positive one exists), if
            the caller knows; computed otherwise.

    Returns:
        A :class:`ReducedSoundness`. Not a WF-net, reset arcs, or a start marking the
        permutations move: ``sound`` is ``None`` with the reason.
    """
    from petriflow.analysis.symmetry import (
        SymmetryUnsupported,
        find_symmetries,
        symmetric_graph,
        transition_orbits,
    )
    from petriflow.analysis.invariants import DEFAULT_BUDGET

    structure = workflow_structure(net)
    if not structure.is_wf_net:
        return ReducedSoundness(None, reason=f"not a WF-net: {structure.problem}")
    compiled = compiled or CompiledNet(net)
    if compiled.has_resets:
        return ReducedSoundness(None, reason="cancellation regions (reset arcs): no stubborn sets")
    start = Marking({structure.source: 1})
    final = soundness_final(net, structure)
    if covered is None:
        section, _ = invariants_section(compiled, start, DEFAULT_BUDGET)
        covered = bool(section.get("covered_by_p_semiflows"))
    groups = find_symmetries(net, compiled=compiled, start=start, final=final)
    found = ReducedSoundness(None, groups=[g.agents for g in groups], final=final.to_dict())
    reasons = [] if covered else ["no P-semiflow covers every place (boundedness and proper"
                                  " completion not proved)"]
    try:
        space = symmetric_graph(net, start, groups=groups, max_states=max_states,
                                compiled=compiled, stubborn=True)
    except SymmetryUnsupported as exc:
        found.reason = "; ".join(reasons + [str(exc)])
        return found
    except StateSpaceLimit as exc:
        space = exc.partial
        found.complete = False
    found.states, found.edges = space.num_states, space.num_edges
    final_row = np.asarray(compiled.vector(final), dtype=np.int64)
    dead = space.deadlocks()
    stuck = [int(s) for s in dead.tolist() if not np.array_equal(space.markings[s], final_row)]
    if stuck:
        path, reached = space.concrete(stuck[0])
        found.violations.append(Violation(
            "no_option_to_complete", f"no option to complete: {format_marking(reached)} enables no transition"
            f" that changes the marking, and it is not the final marking {format_marking(final)}"
            " (stubborn-set search)", path, reached.to_dict()))
        found.option_to_complete = False
    if not found.complete:
        found.sound = False if stuck else None
        found.reason = "; ".join(reasons + [f"the reduced search stopped at --max-states"
                                            f" ({max_states:,} markings)"])
        return found
    finishing = reaching(space.edge_offsets, space.edge_target, dead) if dead.size else \
        np.zeros(space.num_states, dtype=bool)
    if not finishing.all():
        state = int(np.flatnonzero(~finishing)[0])
        path, reached = space.concrete(state)
        found.violations.append(Violation(
            "no_option_to_complete", f"no option to complete: from {format_marking(reached)} no marking"
            " without a move is reachable, so neither is the final marking"
            f" {format_marking(final)} (stubborn-set search)", path, reached.to_dict()))
        found.option_to_complete = False
    if found.option_to_complete is None:
        found.option_to_complete = True
    if covered and found.option_to_complete:
        found.proper_completion = True
    orbits = transition_orbits(compiled, space.groups)
    seen = set(orbits[space.seen_enabled].tolist())
    unseen_rows = [t for t in range(len(orbits)) if int(orbits[t]) not in seen]
    found.unseen = list(dict.fromkeys(compiled.origin[t][0] for t in unseen_rows))
    found.no_dead_transitions = True if not found.unseen else None
    if found.unseen:
        reasons.append(f"{len(found.unseen)} transitions never enabled in the reduced graph"
                       f" (e.g. {found.unseen[0]}): dead or not, the reduction cannot tell")
    if found.option_to_complete is False:
        found.sound = False
    elif found.proper_completion and found.no_dead_transitions:
        found.sound = True
    else:
        found.reason = "; ".join(reasons)
    return found
