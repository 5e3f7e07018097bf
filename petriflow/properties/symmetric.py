"""Properties on the symmetry quotient, beyond the full state space.

A team net's state space grows with the permutations of its interchangeable agents
(:mod:`petriflow.analysis.symmetry`); its quotient keeps one canonical marking per
orbit, with an edge to the canonical form of each successor. Where every atomic
proposition of a formula (each maximal state subformula) has the same value on all the
markings of an orbit, the quotient labelled by them is bisimilar to the reachability
graph (Emerson and Sistla 1996; Clarke, Enders, Filkorn and Jha 1996): relate each
marking to its canonical form; a firing ``m -> m'`` is matched by the quotient's edge
from ``canon(m)`` to ``canon(m')`` and back, deadlocks are deadlocks on both sides. So
CTL and LTL (CTL*) verdicts at the initial marking, which every permutation fixes, are
the same on both: :func:`decide_on_quotient` runs the existing fixpoints
(:mod:`~petriflow.properties.ctl`) and the Büchi product
(:mod:`~petriflow.properties.ltl`) on :class:`QuotientKripke`.

A proposition's invariance is *checked*, never assumed: for each group, swapping its
first agent with each other one (the transpositions generate the group) must map the
predicate onto itself, up to the order of the operands of ``&&``/``||`` and of the
terms of a sum; ``enabled(T)`` must name a union of the transitions' orbits
(:func:`~petriflow.analysis.symmetry.transition_orbits`); ``deadlock`` always is.

A formula with atoms an agent's permutation moves (``box_robot1 >= 1``) is bounded
instead: CTL and LTL are monotone in every atom occurrence under an even number of
negations, so replacing such an atom by the conjunction of its orbit (``box_robot1 >= 1
&& ... && box_robot20 >= 1``) where it occurs positively and by the disjunction where it
occurs negated gives a formula that implies the original in every state (``lower``),
the other way round one implied by it (``upper``); an ``enabled`` the orbit closure
does not name exactly, or an orbit of more than :data:`ORBIT_LIMIT` atoms, is replaced
by ``false``/``true``. ``lower`` true proves the formula, ``upper`` false refutes it;
otherwise it stays undecided.

Evidence stays concrete: a quotient path is replayed from the initial marking, each
step renamed by the permutation that maps the canonical marking onto the concrete one
(:func:`~petriflow.analysis.symmetry.concrete_path`); a quotient cycle comes back to
the same canonical marking but to a permuted concrete one, so it is replayed until the
concrete marking at its start repeats (:func:`concrete_evidence`).

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> from petriflow.analysis.symmetry import find_symmetries
    >>> from petriflow.properties.yaml_props import parse_formula
    >>> worker = ("- {{id: a{k}, state: worker, places: [{{id: a{k}_idle, tokens: 1}}, a{k}_busy], transitions: ["
    ...           "{{id: a{k}_go, in: [a{k}_idle, lock], out: [a{k}_busy]}},"
    ...           " {{id: a{k}_back, in: [a{k}_busy], out: [a{k}_idle, lock]}}]}}\\n")
    >>> net = loads_net("petriflow: 1\\nplaces: [{id: lock, tokens: 1}]\\nsubnets:\\n"
    ...                 + worker.format(k=1) + worker.format(k=2))
    >>> groups = find_symmetries(net)
    >>> symmetric(parse_formula("a1_busy + a2_busy <= 1"), groups, net), symmetric(
    ...     parse_formula("a1_busy <= 0"), groups, net)
    (True, False)
    >>> store = {}
    >>> found = decide_on_quotient(net, parse_formula("AG(EF(lock == 1))"), "ctl", net.initial_marking,
    ...                            max_states=1000, store=store)
    >>> found["verdict"], store["space"].num_states
    (True, 2)
    >>> decide_on_quotient(net, parse_formula("EF(a1_busy + a2_busy == 1 && EX(lock == 1))"), "ctl",
    ...                    net.initial_marking, max_states=1000, store=store)["witness"]
    ['a1_go']
    >>> found = decide_on_quotient(net, parse_formula("AG(a2_busy == 1 -> EF(a2_busy == 0))"), "ctl",
    ...                            net.initial_marking, max_states=1000, store=store)
    >>> found["verdict"], found["method"].split(":")[0]
    (True, 'symmetry quotient, a stronger formula')
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from petriflow.analysis.exploration import StateSpaceLimit, row_origins
from petriflow.analysis.reachability import StateSpace
from petriflow.analysis.symmetry import (
    SymmetricSpace,
    SymmetryGroup,
    SymmetryUnsupported,
    concrete_path,
    find_symmetries,
    symmetric_graph,
    transition_orbits,
)
from petriflow.engine import CompiledNet
from petriflow.marking import Marking
from petriflow.net import Net
from petriflow.properties.ctl import ctl_witness, evaluate
from petriflow.properties.kripke import Kripke
from petriflow.properties.language import (
    AllPaths,
    And,
    Compare,
    Constant,
    Deadlock,
    ExistsPath,
    Finally,
    Fireable,
    Formula,
    Globally,
    Linear,
    Next,
    Not,
    Or,
    Until,
    atoms,
    is_state_formula,
)
from petriflow.properties.ltl import check_ltl

__all__ = ["ORBIT_LIMIT", "QuotientKripke", "concrete_evidence", "decide_on_quotient",
           "symmetric", "symmetric_bounds"]

#: The most atoms an orbit may have for its conjunction/disjunction to replace an atom
#: (beyond: ``false``/``true``).
ORBIT_LIMIT = 256

#: The most times a quotient cycle is replayed in search of a concrete cycle (each pass
#: is a function of the concrete marking it starts in, all of one orbit, so they repeat).
CYCLE_ROUNDS = 10_000


def _shape(formula: Formula, rename: dict[str, str],
           closed: Callable[[Fireable], bool] = lambda _: False) -> Any:
    """A hashable form of the predicate with places renamed, blind to the order of
    ``&&``/``||`` operands and of a sum's terms; ``None`` outside the predicates it can
    compare (an ``enabled`` whose transitions are not ``closed`` under the groups)."""
    if isinstance(formula, Constant):
        return formula.value
    if isinstance(formula, Deadlock):
        return "deadlock"
    if isinstance(formula, Fireable):           # a union of orbits: every swap fixes it
        return ("enabled", frozenset(formula.transitions)) if closed(formula) else None
    if isinstance(formula, Compare):
        def side(linear: Linear) -> tuple:
            return frozenset((rename.get(p, p), k) for p, k in linear.terms), linear.offset
        return "cmp", formula.op, side(formula.left), side(formula.right)
    if isinstance(formula, Not):
        inner = _shape(formula.operand, rename, closed)
        return None if inner is None else ("not", inner)
    if isinstance(formula, (And, Or)):
        parts = [_shape(f, rename, closed) for f in formula.operands]
        return None if None in parts else (type(formula).__name__, frozenset(parts))
    return None


def _swaps(groups: list[SymmetryGroup], places: tuple[str, ...] | list[str]) -> list[dict[str, str]]:
    """Place renamings of the transpositions (first agent, other agent) of each group."""
    found = []
    for group in groups:
        first = group.blocks[0]
        for other in group.blocks[1:]:
            mapping = {}
            for a, b in zip(first.tolist(), other.tolist()):
                mapping[places[a]], mapping[places[b]] = places[b], places[a]
            found.append(mapping)
    return found


class _Orbits:
    """The groups' action on one compiled net: place swaps and transition orbits."""

    def __init__(self, groups: list[SymmetryGroup], compiled: CompiledNet) -> None:
        self.groups, self.compiled = groups, compiled
        self.swaps = _swaps(groups, compiled.places)
        self.origins = row_origins(compiled)
        self.orbit_of = transition_orbits(compiled, groups) if groups else \
            np.arange(len(compiled.transitions))

    def rows(self, names: Sequence[str]) -> set[int]:
        wanted = set(names)
        return {r for r, origin in enumerate(self.origins) if origin in wanted}

    def closure(self, names: Sequence[str]) -> set[int]:
        """The rows of every transition orbit that meets ``names``' rows."""
        orbits = {int(self.orbit_of[r]) for r in self.rows(names)}
        return {r for r in range(len(self.origins)) if int(self.orbit_of[r]) in orbits}

    def closed(self, atom: Fireable) -> bool:
        return self.rows(atom.transitions) == self.closure(atom.transitions)

    def invariant(self, predicate: Formula) -> bool:
        plain = _shape(predicate, {}, self.closed)
        return plain is not None and all(
            _shape(predicate, swap, self.closed) == plain for swap in self.swaps)

    def orbit(self, atom: Compare, limit: int) -> list[Formula] | None:
        """The images of ``atom`` under the groups (``None``: more than ``limit``)."""
        seen: dict[Any, Formula] = {_shape(atom, {}): atom}
        frontier: list[Formula] = [atom]
        while frontier:
            found = []
            for f in frontier:
                for swap in self.swaps:
                    image = self.renamed(f, swap)
                    key = _shape(image, {})
                    if key not in seen:
                        seen[key] = image
                        found.append(image)
                        if len(seen) > limit:
                            return None
            frontier = found
        return list(seen.values())

    def renamed(self, node: Formula, mapping: dict[str, str]) -> Formula | None:
        """``node`` with its places renamed (``None``: an ``enabled`` not closed)."""
        if isinstance(node, Compare):
            def side(linear: Linear) -> Linear:
                return Linear(tuple((mapping.get(p, p), k) for p, k in linear.terms), linear.offset)
            return Compare(node.op, side(node.left), side(node.right))
        if isinstance(node, Fireable):
            return node if self.closed(node) else None
        if isinstance(node, (Constant, Deadlock)):
            return node
        children = [self.renamed(c, mapping) for c in node.children()]
        if any(c is None for c in children):
            return None
        if isinstance(node, (And, Or)):
            return type(node)(tuple(children))
        return type(node)(*children)

    def representatives(self, formula: Formula) -> Formula:
        """``AG(c1 && ... && cn)`` with one conjunct per orbit of the groups (the rest
        follow: ``AG c`` holds at the initial marking exactly when ``AG π(c)`` does, for
        every permutation ``π`` of the agents, which fixes that marking)."""
        if not (isinstance(formula, AllPaths) and isinstance(formula.operand, Globally)
                and isinstance(formula.operand.operand, And)):
            return formula
        covered: set[Formula] = set()
        kept = []
        for conjunct in formula.operand.operand.operands:
            if conjunct in covered:
                continue
            kept.append(conjunct)
            seen, frontier = {conjunct}, [conjunct]
            while frontier and len(seen) <= ORBIT_LIMIT:
                images = [self.renamed(f, swap) for f in frontier for swap in self.swaps]
                frontier = [f for f in dict.fromkeys(images) if f is not None and f not in seen]
                seen.update(frontier)
            covered |= seen
        return AllPaths(Globally(And(tuple(kept)))) if len(kept) > 1 else AllPaths(Globally(kept[0]))

    def fixing(self, formula: Formula) -> list[SymmetryGroup] | None:
        """The groups less every agent whose places the formula's moved atoms read (a
        group left with one agent dropped); ``None``: a moved ``enabled``."""
        owner = {int(p): (g, a) for g, group in enumerate(self.groups)
                 for a, row in enumerate(group.blocks) for p in row}
        index = self.compiled.place_index
        named: set[tuple[int, int]] = set()
        for atom in atoms(formula):
            if self.invariant(atom):
                continue
            for node in atom.walk():
                if isinstance(node, Fireable) and not self.closed(node):
                    return None
                if isinstance(node, Compare):
                    named |= {owner[index[p]] for p, _ in node.left.terms + node.right.terms
                              if index[p] in owner}
        groups = []
        for g, group in enumerate(self.groups):
            keep = [a for a in range(group.size) if (g, a) not in named]
            if len(keep) > 1:
                groups.append(SymmetryGroup([group.agents[a] for a in keep], group.blocks[keep]))
        return groups

    def bounds(self, node: Formula, limit: int) -> tuple[Formula, Formula]:
        """``(lower, upper)``: see the module documentation."""
        if is_state_formula(node) and self.invariant(node):
            return node, node
        if isinstance(node, Compare):
            orbit = self.orbit(node, limit)
            if orbit is None:
                return Constant(False), Constant(True)
            return And(tuple(orbit)), Or(tuple(orbit))
        if isinstance(node, Fireable):
            closure = self.closure(node.transitions)
            names = tuple(dict.fromkeys(self.origins[r] for r in sorted(closure)))
            upper = Fireable(names)
            return Constant(False), upper if self.rows(names) == closure else Constant(True)
        if isinstance(node, Not):
            lower, upper = self.bounds(node.operand, limit)
            return Not(upper), Not(lower)
        if isinstance(node, (And, Or)):
            pairs = [self.bounds(f, limit) for f in node.operands]
            return type(node)(tuple(p[0] for p in pairs)), type(node)(tuple(p[1] for p in pairs))
        if isinstance(node, Until):
            (left_lo, left_hi), (right_lo, right_hi) = (self.bounds(node.left, limit),
                                                        self.bounds(node.right, limit))
            return Until(left_lo, right_lo), Until(left_hi, right_hi)
        if isinstance(node, (Next, Finally, Globally, AllPaths, ExistsPath)):
            lower, upper = self.bounds(node.operand, limit)
            return type(node)(lower), type(node)(upper)
        return Constant(False), Constant(True)      # pragma: no cover - every node is above


def symmetric(predicate: Formula, groups: list[SymmetryGroup], net: Net,
              compiled: CompiledNet | None = None) -> bool:
    """Whether every permutation of the groups' agents maps ``predicate`` (a state
    predicate: token counts, ``enabled``, ``deadlock``) onto itself."""
    return _Orbits(groups, compiled or CompiledNet(net)).invariant(predicate)


def symmetric_bounds(formula: Formula, groups: list[SymmetryGroup], net: Net,
                     compiled: CompiledNet | None = None) -> tuple[Formula, Formula]:
    """``(lower, upper)`` with symmetric atoms only, ``lower`` implying ``formula`` and
    ``formula`` implying ``upper`` in every state (the module documentation says how).

    Examples:
        >>> from petriflow.io.yaml import loads_net
        >>> from petriflow.analysis.symmetry import find_symmetries
        >>> from petriflow.properties.yaml_props import parse_formula
        >>> net = loads_net("petriflow: 1\\nsubnets:\\n" + "".join(
        ...     f"- {{id: a{k}, state: w, places: [{{id: a{k}_x, tokens: 1}}], transitions: []}}\\n"
        ...     for k in (1, 2)))
        >>> [str(f) for f in symmetric_bounds(parse_formula("AG(!(a1_x >= 1))"),
        ...                                   find_symmetries(net), net)]
        ['AG(!((a1_x >= 1 || a2_x >= 1)))', 'AG(!((a1_x >= 1 && a2_x >= 1)))']
    """
    return _Orbits(groups, compiled or CompiledNet(net)).bounds(formula, ORBIT_LIMIT)


class QuotientKripke(Kripke):
    """The symmetry quotient as the Kripke structure the CTL and LTL checkers walk: its
    states the canonical markings, an edge to each distinct canonical successor (one
    row that leads there as its label), deadlocks stuttering.

    ``enabled(T)`` is read off the canonical marking (every row's preset), not off the
    edges: the quotient keeps one row per canonical successor.
    """

    def __init__(self, quotient: SymmetricSpace) -> None:
        compiled = quotient.compiled
        super().__init__(StateSpace(
            places=quotient.places, transitions=quotient.transitions,
            origins=row_origins(compiled), edge_offsets=quotient.edge_offsets,
            edge_transition=quotient.edge_row, edge_target=quotient.edge_target,
            parent=quotient.parent, parent_transition=quotient.parent_row,
            representation="counts", _rows=quotient.markings,
            _column_of_place=np.arange(len(quotient.places))))
        self.quotient = quotient
        self._row_origins = row_origins(compiled)

    def fireable(self, transitions: Sequence[str]) -> np.ndarray:
        wanted = set(transitions)
        markings = self.space.markings
        found = np.zeros(self.n, dtype=bool)
        for row, origin in enumerate(self._row_origins):
            if origin in wanted:
                enabled = np.ones(self.n, dtype=bool)
                for place, weight in self.quotient.compiled.pre[row]:
                    enabled &= markings[:, place] >= weight
                found |= enabled
        return found


def concrete_evidence(quotient: SymmetricSpace, evidence: dict) -> dict | None:
    """A quotient path (``{"witness": rows fired}``, and ``"cycle"`` for a lasso) as a
    concrete firing sequence from the initial marking; a cycle is repeated until the
    concrete marking at its start comes back (``None``: not within
    :data:`CYCLE_ROUNDS` passes)."""
    compiled, groups = quotient.compiled, quotient.groups
    index = compiled.transition_index
    prefix, vector = concrete_path(compiled, groups, quotient.markings[0],
                                   [index[name] for name in evidence.get("witness") or []])
    if "cycle" not in evidence:
        return {"witness": prefix}
    cycle = [index[name] for name in evidence["cycle"]]
    if not cycle:                       # the run ends in a deadlock, repeated
        return {"witness": prefix, "cycle": []}
    seen = {tuple(vector): 0}
    rounds: list[list[str]] = []
    while len(rounds) < CYCLE_ROUNDS:
        fired, vector = concrete_path(compiled, groups, vector, cycle)
        rounds.append(fired)
        first = seen.setdefault(tuple(vector), len(rounds))
        if first < len(rounds):
            return {"witness": prefix + [t for r in rounds[:first] for t in r],
                    "cycle": [t for r in rounds[first:] for t in r]}
    return None


def _quotient(net: Net, start: Marking, max_states: int, store: dict) -> QuotientKripke | None:
    """The quotient's Kripke structure, explored once per ``store`` (``None``: no
    symmetric agents, over ``max_states``, or a net the exploration refuses)."""
    if "kripke" not in store:
        store["kripke"] = None
        groups = store["groups"]
        try:
            space = symmetric_graph(net, start, groups=groups, max_states=max_states,
                                    compiled=store["compiled"])
        except (StateSpaceLimit, SymmetryUnsupported):
            return None
        store["space"] = space
        store["kripke"] = QuotientKripke(space)
        store["cache"] = {}
    return store["kripke"]


def decide_on_quotient(net: Net, formula: Formula, kind: str, start: Marking, *,
                       max_states: int, store: dict) -> dict | None:
    """Decide a ``reachability``, ``ctl`` or ``ltl`` formula on the symmetry quotient:
    ``{"verdict", "method", "witness"?, "cycle"?}``, or ``None`` when the net has no
    symmetric agents, the quotient is over ``max_states``, or nothing settles the
    formula (neither bound, nor the quotient by the agents it leaves unnamed). ``store``
    keeps the groups and the quotients between calls."""
    if kind not in ("reachability", "ctl", "ltl"):
        return None
    if "groups" not in store:
        store["compiled"] = CompiledNet(net)
        store["groups"] = find_symmetries(net, compiled=store["compiled"])
        store["orbits"] = _Orbits(store["groups"], store["compiled"])
    if not store["groups"]:
        return None
    orbits: _Orbits = store["orbits"]
    exact = all(orbits.invariant(atom) for atom in atoms(formula))
    lower, upper = (formula, formula) if exact else orbits.bounds(formula, ORBIT_LIMIT)
    if not all(orbits.invariant(atom) for f in (lower, upper) for atom in atoms(f)):
        return None             # pragma: no cover - bounds() builds symmetric atoms only
    kripke = _quotient(net, start, max_states, store)
    if kripke is None:
        return None
    states = f"{kripke.n:,} canonical markings"
    for candidate, wanted in ((lower, True), (upper, False)):
        (value, evidence), checker = _run(kripke, candidate, kind, store["cache"])
        if value == wanted or exact:
            break
    else:
        return _on_sub_quotient(net, formula, kind, start, max_states, store)
    if exact:
        method = (f"symmetry quotient: {checker} ({states}; every atom invariant under the"
                  " agents' permutations, the quotient bisimilar to the reachability graph)")
    else:
        method = (f"symmetry quotient, a {'stronger' if wanted else 'weaker'} formula: {checker}"
                  f" ({states}) {'proves' if wanted else 'refutes'} it with each atom the agents'"
                  " permutations move replaced by its orbit's "
                  f"{'conjunction (disjunction where negated)' if wanted else 'disjunction (conjunction where negated)'}")
    return _entry(kripke, kind, candidate, value, evidence, method)


def _run(kripke: QuotientKripke, formula: Formula, kind: str, cache: dict
         ) -> tuple[tuple[bool, dict | None], str]:
    """``((verdict, quotient evidence), checker)`` of ``formula`` on ``kripke``."""
    if kind == "ltl":
        return check_ltl(kripke, formula), "LTL: Spot Büchi automaton x the quotient"
    value = bool(evaluate(kripke, formula, cache)[0])
    return (value, ctl_witness(kripke, formula, value, cache)), "CTL fixpoints on the quotient"


def _entry(kripke: QuotientKripke, kind: str, formula: Formula, value: bool,
           evidence: dict | None, method: str) -> dict:
    entry: dict[str, Any] = {"verdict": value, "method": method, "witness": None}
    if evidence is not None:
        concrete = concrete_evidence(kripke.quotient, evidence)
        if concrete is None:
            entry["method"] += "; its cycle was not closed concretely (no evidence)"
        else:
            entry.update(concrete)
    elif kind != "ltl" and not is_state_formula(formula):
        entry["method"] += "; no single path shows this verdict"
    return entry


def _on_sub_quotient(net: Net, formula: Formula, kind: str, start: Marking, max_states: int,
                     store: dict) -> dict | None:
    """The formula decided exactly on the quotient by the agents none of its moved atoms
    names (after ``AG`` of a conjunction keeps one conjunct per orbit), or ``None``."""
    orbits: _Orbits = store["orbits"]
    reduced = orbits.representatives(formula) if kind != "ltl" else formula
    groups = orbits.fixing(reduced)
    if not groups:
        return None
    sub = _Orbits(groups, store["compiled"])
    if not all(sub.invariant(atom) for atom in atoms(reduced)):
        return None
    key = tuple(tuple(g.agents) for g in groups)
    inner = store.setdefault("sub", {}).setdefault(key, {"groups": groups, "compiled": store["compiled"]})
    kripke = _quotient(net, start, max_states, inner)
    if kripke is None:
        return None
    (value, evidence), checker = _run(kripke, reduced, kind, inner["cache"])
    fixed = sorted({a for g in store["groups"] for a in g.agents} - {a for g in groups for a in g.agents})
    method = (f"symmetry quotient by the agents the formula leaves unnamed: {checker} ({kripke.n:,}"
              f" canonical markings, {', '.join(fixed)} kept apart; every atom invariant under the"
              " other agents' permutations"
              + ("; of AG's conjuncts, one per orbit of the agents' permutations" if reduced != formula
                 else "") + ")")
    return _entry(kripke, kind, reduced, value, evidence, method)
