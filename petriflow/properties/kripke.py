"""A reachability graph as the Kripke structure temporal properties are checked on.

:class:`Kripke` wraps a :class:`~petriflow.analysis.reachability.StateSpace`: its states
are the reachable markings, its edges the firings, and every **deadlock** (a marking
that enables nothing) gets one *stutter* edge to itself, so that every path is infinite
and a run that stops stays in its last marking forever. That is the convention of the
Model Checking Contest (a maximal finite path is extended by repeating its last state),
and the one its published verdicts agree with: ``EG p`` holds in a deadlock satisfying
``p``, and the LTL formula ``F G p`` holds of a run that stops in a ``p`` marking. (CTL's
``EX``/``AX`` look at firings only: :mod:`~petriflow.properties.ctl`.) A stutter edge fires no
transition: witnesses show it as the end of the firing sequence (an empty cycle).

:meth:`Kripke.holds` evaluates a state predicate on every state at once (a Boolean
vector); ``enabled(t)`` (the contest's ``is-fireable``) is read off the graph's own edges,
so it agrees with the exploration on every arc kind the engine has (weights, resets,
outcome variants of one transition).

Examples:
    >>> from petriflow.classic import dining_philosophers
    >>> from petriflow.analysis.reachability import reachability_graph
    >>> from petriflow.properties.language import Fireable
    >>> kripke = Kripke(reachability_graph(dining_philosophers(3)))
    >>> kripke.n, int(kripke.holds(Fireable(("take_0",))).sum())
    (4, 1)
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from petriflow.analysis import csr, shortest_path, transpose
from petriflow.analysis.reachability import StateSpace
from petriflow.errors import PetriflowError
from petriflow.properties.language import (
    And, Compare, Constant, Deadlock, Fireable, Formula, Linear, Not, Or
)

__all__ = ["STUTTER", "Kripke", "PropertyNameError"]

#: The label of a stutter edge (a deadlock repeating itself).
STUTTER = -1


class PropertyNameError(PetriflowError):
    """A property names a place or transition the net does not have."""


class Kripke:
    """The reachability graph with deadlocks stuttering: every state has a successor.

    Attributes:
        space: the state space.
        n: number of states (state 0 is the initial marking).
        offsets, targets, labels: the edges in compressed rows: state ``s``'s edges are
            ``offsets[s]:offsets[s + 1]``; ``labels`` holds the transition index (into
            ``space.transitions``) of each edge, :data:`STUTTER` for a stutter edge.
    """

    def __init__(self, space: StateSpace) -> None:
        self.space = space
        self.n = space.num_states
        dead = np.flatnonzero(space.out_degree() == 0)
        source = np.concatenate([space.edge_source, dead])
        target = np.concatenate([space.edge_target, dead]).astype(np.int64)
        label = np.concatenate([space.edge_transition.astype(np.int64), np.full(dead.size, STUTTER)])
        order = np.argsort(source, kind="stable")
        self.offsets, self.targets = csr(self.n, source[order], target[order])
        self.labels = label[order]
        self.sources = source[order]
        self._reverse: tuple[np.ndarray, np.ndarray] | None = None
        self._by_place: np.ndarray | None = None
        self._places = {p: j for j, p in enumerate(space.places)}
        self._origin_ids: dict[str, list[int]] = {}
        for row, origin in enumerate(space.origins):
            self._origin_ids.setdefault(origin, []).append(row)
        self.deadlocks = np.zeros(self.n, dtype=bool)
        self.deadlocks[dead] = True

    @property
    def reverse(self) -> tuple[np.ndarray, np.ndarray]:
        """``(offsets, predecessors)``: the reversed graph in compressed rows."""
        if self._reverse is None:
            self._reverse = transpose(self.offsets, self.targets)
        return self._reverse

    def check_names(self, formula: Formula) -> None:
        """Raise :class:`PropertyNameError` for a place or transition the net lacks."""
        from petriflow.properties.language import names_used

        places, transitions = names_used(formula)
        for place in sorted(places - set(self._places)):
            raise PropertyNameError(f"unknown place {place!r}")
        for transition in sorted(transitions - set(self._origin_ids)):
            raise PropertyNameError(f"unknown transition {transition!r}")

    def value(self, expression: Linear) -> np.ndarray:
        """The integer expression's value in every state."""
        if self._by_place is None:      # one column per place, contiguous: read place by place
            self._by_place = np.asfortranarray(self.space.markings)
        markings = self._by_place
        total = np.full(self.n, expression.offset, dtype=np.int64)
        for place, k in expression.terms:
            if place not in self._places:
                raise PropertyNameError(f"unknown place {place!r}")
            total += k * markings[:, self._places[place]].astype(np.int64, copy=False)
        return total

    def fireable(self, transitions: Sequence[str]) -> np.ndarray:
        """States enabling at least one of ``transitions``."""
        rows = []
        for name in transitions:
            if name not in self._origin_ids:
                raise PropertyNameError(f"unknown transition {name!r}")
            rows.extend(self._origin_ids[name])
        wanted = np.zeros(len(self.space.transitions) + 1, dtype=bool)
        wanted[rows] = True
        hit = wanted[self.labels]               # STUTTER (-1) reads the spare last entry: False
        found = np.zeros(self.n, dtype=bool)
        found[self.sources[hit]] = True
        return found

    def holds(self, formula: Formula) -> np.ndarray:
        """Boolean vector: where the state predicate ``formula`` holds."""
        if isinstance(formula, Constant):
            return np.full(self.n, formula.value, dtype=bool)
        if isinstance(formula, Compare):
            left, right = self.value(formula.left), self.value(formula.right)
            return {"<=": np.less_equal, "<": np.less, ">=": np.greater_equal, ">": np.greater,
                    "==": np.equal, "!=": np.not_equal}[formula.op](left, right)
        if isinstance(formula, Fireable):
            return self.fireable(formula.transitions)
        if isinstance(formula, Deadlock):
            return self.deadlocks.copy()
        if isinstance(formula, Not):
            return ~self.holds(formula.operand)
        if isinstance(formula, And):
            out = np.ones(self.n, dtype=bool)
            for operand in formula.operands:
                out &= self.holds(operand)
            return out
        if isinstance(formula, Or):
            out = np.zeros(self.n, dtype=bool)
            for operand in formula.operands:
                out |= self.holds(operand)
            return out
        raise ValueError(f"not a state predicate: {formula}")

    def edge_name(self, edge: int) -> str | None:
        """The transition an edge fires (``None``: a deadlock's stutter edge)."""
        label = int(self.labels[edge])
        return None if label == STUTTER else self.space.transitions[label]

    def shortest_path(self, starts: Sequence[int], goal: np.ndarray, allowed: np.ndarray | None = None
                      ) -> list[int] | None:
        """Edges of a shortest path from a start state to a ``goal`` state through
        ``allowed`` states (the goal itself need not be allowed), or ``None``.

        A start that is a goal gives the empty path.
        """
        return shortest_path(self.offsets, self.targets, starts, goal, allowed)

    def names(self, edges: Sequence[int]) -> list[str]:
        """The transitions a path of edges fires (stutter edges left out)."""
        return [name for name in (self.edge_name(e) for e in edges) if name is not None]

    def end_of(self, edges: Sequence[int], start: int = 0) -> int:
        """The state a path of edges ends in."""
        return int(self.targets[edges[-1]]) if edges else start
