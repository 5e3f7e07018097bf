"""Workflow nets: classical soundness, with witnesses.

A **WF-net** has exactly one source place ``i`` (no arc into it), exactly one sink
place ``o`` (no arc out of it), and every place and transition lies on a path from
``i`` to ``o`` — equivalently, the *short-circuited* net, with an extra transition
``o -> i``, is strongly connected.

A WF-net is **sound** (van der Aalst) for one token in ``i`` and the final marking
``Mf`` (the net's ``final_marking`` if it has one, else one token in ``o``) when:

1. *option to complete*: from every marking reachable from ``[i]``, ``Mf`` is reachable;
2. *proper completion*: every reachable marking that covers ``Mf`` equals ``Mf``;
3. *no dead transitions*: every transition is enabled in some reachable marking.

An unbounded WF-net is never sound (proper completion or the option to complete
fails), so unboundedness is checked first, on the fly, and reported as such.

The structure check itself is :func:`~petriflow.workflow.workflow_structure` (kept
importable from here).

:func:`check_soundness` decides all three on the reachability graph from ``[i]`` and
returns every violation with a witness: the shortest firing sequence from ``[i]`` to a
marking that shows it. For **free-choice** nets (every arc from a place ``p`` to a
transition ``t`` has ``p`` as ``t``'s only input or ``t`` as ``p``'s only output) it
cross-checks the verdict with the theorem that such a net is sound exactly when its
short-circuited net is live and bounded.

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> net = loads_net('''
    ... petriflow: 1
    ... places: [i, p, q, o]
    ... transitions:
    ...   - {id: split, in: [i], out: [p, q]}
    ...   - {id: left, in: [p], out: [o]}
    ...   - {id: right, in: [q], out: [o]}
    ... ''')
    >>> report = check_soundness(net)
    >>> report.sound, [v.kind for v in report.violations]
    (False, ['improper_completion', 'no_option_to_complete'])
    >>> report.violations[0].transitions
    ['split', 'left']
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from petriflow.analysis._graph import reaching
from petriflow.analysis.coverability import (
    DEFAULT_MAX_COVERABILITY,
    CoverabilitySearch,
    coverability_search,
)
from petriflow.analysis.properties import dead_transitions, deadlocks, is_live
from petriflow.analysis.reachability import (
    DEFAULT_MAX_STATES,
    StateSpace,
    StateSpaceLimit,
    UnboundedNetError,
    reachability_graph,
)
from petriflow.engine import CompiledNet
from petriflow.marking import Marking, format_marking
from petriflow.net import Net
from petriflow.workflow import WorkflowStructure, workflow_structure

__all__ = [
    "VIOLATION_KINDS",
    "SoundnessReport",
    "Violation",
    "WorkflowStructure",
    "check_soundness",
    "is_free_choice",
    "workflow_structure",
]

#: The kinds of :class:`Violation` the analyses report.
VIOLATION_KINDS = ("not_wf_net", "no_option_to_complete", "improper_completion",
                   "dead_transition", "unbounded", "deadlock")


@dataclass
class Violation:
    """One way a property fails, with its witness.

    Attributes:
        kind: one of :data:`VIOLATION_KINDS`.
        message: one readable sentence.
        transitions: the witness firing sequence from the start marking (empty when the
            violation is structural or is about something that never happens).
        marking: the marking the witness sequence reaches, if any.
        elements: the places or transitions concerned (dead transitions, unbounded
            places, nodes not on a path from ``i`` to ``o``).
    """

    kind: str
    message: str
    transitions: list[str] = field(default_factory=list)
    marking: dict[str, int] | None = None
    elements: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """Plain data for JSON."""
        return {"kind": self.kind, "transitions": list(self.transitions),
                "message": self.message, "marking": self.marking,
                "elements": list(self.elements)}


def is_free_choice(net: Net) -> bool:
    """Whether the net is free-choice: for every arc ``p -> t``, either ``t`` is the only
    transition consuming from ``p`` or ``p`` is the only input place of ``t``.

    Examples:
        >>> from petriflow.classic import dining_philosophers
        >>> is_free_choice(dining_philosophers(3))
        False
    """
    consumers: dict[str, int] = {}
    for transition in net.transitions:
        for place in net.preset(transition):
            consumers[place] = consumers.get(place, 0) + 1
    for transition in net.transitions:
        preset = net.preset(transition)
        if len(preset) > 1 and any(consumers[p] > 1 for p in preset):
            return False
    return True


@dataclass
class SoundnessReport:
    """The verdict of :func:`check_soundness` and the evidence behind it.

    Attributes:
        sound: the verdict (``False`` for a net that is not a WF-net).
        structure: the WF-net structure check.
        violations: every failed criterion, each with a witness.
        bounded: ``None`` when not a WF-net.
        option_to_complete, proper_completion, no_dead_transitions: the three criteria
            (``None`` when not decided: not a WF-net, or unbounded).
        dead_transitions: transitions never enabled from ``[i]``.
        free_choice: whether the net is free-choice.
        algorithm: how the verdict was reached.
        initial_marking: ``[i]``; final_marking: the ``Mf`` used.
        crosscheck: for free-choice WF-nets, the short-circuited net's liveness and
            boundedness and whether they agree with the verdict.
        space: the reachability graph from ``[i]`` (bounded WF-nets only).
        coverability: the budgeted Karp–Miller search from ``[i]`` run before the
            state space (``None`` when it was not run).
        unbounded_places_complete: for an unbounded net, whether the unbounded places
            listed are all of them (``False``: at least these).
    """

    sound: bool
    structure: WorkflowStructure
    violations: list[Violation]
    bounded: bool | None = None
    option_to_complete: bool | None = None
    proper_completion: bool | None = None
    no_dead_transitions: bool | None = None
    dead_transitions: list[str] = field(default_factory=list)
    free_choice: bool = False
    algorithm: str = ""
    initial_marking: dict[str, int] | None = None
    final_marking: dict[str, int] | None = None
    crosscheck: dict[str, Any] | None = None
    space: StateSpace | None = field(default=None, repr=False)
    coverability: CoverabilitySearch | None = field(default=None, repr=False)
    unbounded_places_complete: bool | None = None


def check_soundness(
    net: Net,
    *,
    final_marking: Mapping[str, int] | None = None,
    max_states: int = DEFAULT_MAX_STATES,
    crosscheck: bool = True,
    max_coverability: int = DEFAULT_MAX_COVERABILITY,
    bounded: bool | None = None,
) -> SoundnessReport:
    """Decide classical soundness of a WF-net for one token in its source place.

    Boundedness comes first and cheap: unless ``bounded`` says it is known, a
    Karp–Miller search of at most ``max_coverability`` nodes
    (:func:`~petriflow.analysis.coverability.coverability_search`) runs before the state
    space; an unbounded net is reported from it without exploring further.

    Args:
        net: the net (its own initial marking is ignored: soundness is about ``[i]``).
        final_marking: ``Mf``; default the net's ``final_marking``, else ``[o]``.
        max_states: passed to the reachability graph.
        crosscheck: for free-choice WF-nets, also check that the short-circuited net is
            live and bounded exactly when the net was found sound.
        max_coverability: the node budget of the Karp–Miller search (0: none).
        bounded: ``True`` when the net is known to be bounded (P-semiflows cover every
            place): no search, no on-the-fly unboundedness test.

    Returns:
        A :class:`SoundnessReport`.

    Raises:
        StateSpaceLimit: more than ``max_states`` markings are reachable from ``[i]``;
            its ``partial`` state space holds what was explored and its
            ``coverability`` the search run before (``check_net`` reports what they prove).
    """
    structure = workflow_structure(net)
    free_choice = is_free_choice(net)
    if not structure.is_wf_net:
        violation = Violation("not_wf_net", f"not a WF-net: {structure.problem}",
                              elements=structure.not_on_path)
        return SoundnessReport(False, structure, [violation], free_choice=free_choice,
                               algorithm="structure check")
    source, sink = structure.source, structure.sink
    start = Marking({source: 1})
    final = Marking(final_marking) if final_marking is not None else (
        net.final_marking if net.final_marking is not None else Marking({sink: 1}))
    final = net.check_marking(final)
    compiled = CompiledNet(net)
    report = SoundnessReport(False, structure, [], free_choice=free_choice,
                             initial_marking=start.to_dict(), final_marking=final.to_dict())
    probe = None
    if not bounded and max_coverability > 0 and not getattr(compiled, "has_resets", False):
        probe = coverability_search(net, start, max_nodes=max_coverability, compiled=compiled)
        report.coverability = probe
        if probe.bounded is False:
            return _unbounded(probe.witness, report, probe)
    known = bounded or (probe is not None and probe.bounded)
    try:
        space = reachability_graph(net, start, max_states=max_states, compiled=compiled,
                                   detect_unbounded=not known)
    except UnboundedNetError as exc:
        return _unbounded(exc, report, probe)
    except StateSpaceLimit as exc:
        exc.coverability = probe             # what the search proved, for the report
        raise
    report.space = space
    report.bounded = True
    report.algorithm = "reachability graph from [i] (explicit breadth-first search)"
    markings = space.markings
    final_vector = np.array(compiled.vector(final), dtype=np.int64)

    covering = (markings >= final_vector).all(axis=1) & (markings != final_vector).any(axis=1)
    improper = np.flatnonzero(covering)
    report.proper_completion = not improper.size
    if improper.size:
        state = int(improper[0])
        reached = space.marking(state)
        report.violations.append(Violation(
            "improper_completion",
            f"improper completion: {len(improper)} reachable markings cover the final marking"
            f" {format_marking(final)} with tokens left elsewhere, e.g. {format_marking(reached)}",
            space.path(state), reached.to_dict()))

    final_state = space.index(final)
    stuck = np.ones(space.num_states, dtype=bool) if final_state is None else ~reaching(
        space.edge_offsets, space.edge_target, [final_state])
    report.option_to_complete = not stuck.any()
    if stuck.any():
        deadlocked = deadlocks(space)
        # Point at a deadlock when there is one among the stuck markings: it says more
        # than the first stuck marking (which is [i] when Mf is unreachable altogether).
        stuck_deadlocks = deadlocked[stuck[deadlocked]]
        state = int(stuck_deadlocks[0] if final_state is None and stuck_deadlocks.size
                    else np.flatnonzero(stuck)[0])
        reached = space.marking(state)
        dead_end = bool((deadlocked == state).any())
        if final_state is None:
            why = f"the final marking {format_marking(final)} is not reachable from [{source}] at all"
            if dead_end:
                why += f"; e.g. {format_marking(reached)} is a deadlock"
        else:
            kind = "a deadlock" if dead_end else "no firing sequence leads back"
            why = (f"from {format_marking(reached)} the final marking {format_marking(final)} can no longer"
                   f" be reached ({kind}); {int(stuck.sum())} of {space.num_states} reachable"
                   " markings are like this")
        report.violations.append(Violation("no_option_to_complete", f"no option to complete: {why}",
                                           space.path(state), reached.to_dict()))

    dead = dead_transitions(space)
    report.dead_transitions = dead
    report.no_dead_transitions = not dead
    if dead:
        report.violations.append(Violation(
            "dead_transition",
            f"{len(dead)} dead transitions (enabled in no marking reachable from [{source}]):"
            f" {', '.join(dead)}", elements=dead))
    report.sound = not report.violations
    if crosscheck and free_choice and final == Marking({sink: 1}):
        report.crosscheck = _free_choice_crosscheck(net, source, sink, report.sound, max_states)
        report.algorithm += "; free-choice cross-check: short-circuited net live and bounded"
    return report


def _unbounded(exc: UnboundedNetError, report: SoundnessReport,
               probe: CoverabilitySearch | None) -> SoundnessReport:
    """The report for an unbounded WF-net: unsound, with the pumping witness."""
    report.bounded = False
    places = list(exc.places)
    if probe is not None and probe.unbounded_places:
        report.algorithm = ("Karp-Miller coverability search from [i] (depth first): a marking"
                            " strictly covers an earlier one on its path (unbounded)")
        places = list(dict.fromkeys(probe.unbounded_places + places))
    else:
        report.algorithm = ("reachability graph from [i] stopped: a marking strictly covers an"
                            " earlier one on its path (unbounded)")
    report.unbounded_places_complete = probe is not None and probe.complete
    more = "" if report.unbounded_places_complete else " (at least)"
    report.violations.append(Violation(
        "unbounded",
        f"unbounded: firing {' '.join(exc.pump)} from the marking reached by"
        f" [{' '.join(exc.prefix)}] adds tokens to {', '.join(exc.places)} and can be repeated"
        f" forever; unbounded places{more}: {', '.join(places)}",
        exc.prefix + exc.pump, exc.covering.to_dict(), places))
    if probe is not None and probe.complete:
        dead = probe.dead_transitions
        report.dead_transitions = dead
        report.no_dead_transitions = not dead
        if dead:
            report.violations.append(Violation(
                "dead_transition",
                f"{len(dead)} dead transitions (enabled in no marking reachable from [i]):"
                f" {', '.join(dead)}", elements=dead))
    report.sound = False
    return report


def _free_choice_crosscheck(net: Net, source: str, sink: str, sound: bool,
                            max_states: int) -> dict[str, Any]:
    """Soundness of a free-choice WF-net <=> its short-circuited net is live and bounded."""
    closed = net.copy()
    name = "short_circuit"
    while name in closed.places or name in closed.transitions:
        name = "_" + name
    closed.add_transition(name, silent=True)
    closed.add_arc(sink, name)
    closed.add_arc(name, source)
    try:
        space = reachability_graph(closed, {source: 1}, max_states=max_states)
    except UnboundedNetError:
        return {"short_circuit_bounded": False, "short_circuit_live": None,
                "agrees": not sound}
    except StateSpaceLimit:
        return {"short_circuit_bounded": None, "short_circuit_live": None, "agrees": None}
    live = is_live(space)
    return {"short_circuit_bounded": True, "short_circuit_live": live, "agrees": live == sound}
