"""LTL model checking: Spot's Büchi automaton of the negation, times the reachability graph.

``A ψ`` holds when no infinite path from the initial marking satisfies ``¬ψ``. Spot
(:mod:`spot`, the ``spottl`` wheel: the LTL-to-automaton translator contest tools use)
translates ``¬ψ`` into a state-based Büchi automaton whose edges carry Boolean guards over
ψ's atoms (its maximal state predicates: ``p0``, ``p1``...). Each guard is evaluated on
every marking at once; the product's edges are then built as arrays: ``(s, q) → (s', q')``
for every firing ``s → s'`` and automaton edge ``q → q'`` whose guard holds in ``s``
(the automaton reads the marking being left). The search keeps the product states
reachable from ``(M0, q0)`` and looks for a strongly connected component holding an
accepting edge: one exists exactly when some path violates ψ, and the counterexample is
a lasso (a firing sequence to the cycle, then the cycle). ``E ψ`` is ``¬A¬ψ``, with the
lasso as its witness.

Paths are infinite: a deadlock repeats its marking forever
(:mod:`~petriflow.properties.kripke`), as in the Model Checking Contest. ``X`` is then
well defined everywhere (the next marking of a deadlock is itself).

Examples:
    >>> from petriflow.classic import dining_philosophers
    >>> from petriflow.analysis.reachability import reachability_graph
    >>> from petriflow.properties.kripke import Kripke
    >>> from petriflow.properties.language import Finally, Fireable, Globally
    >>> kripke = Kripke(reachability_graph(dining_philosophers(3)))
    >>> check_ltl(kripke, Globally(Finally(Fireable(("take_0",)))))  # every cycle passes M0
    (True, None)
    >>> verdict, lasso = check_ltl(kripke, Finally(Fireable(("release_0",))))
    >>> verdict, lasso["witness"], lasso["cycle"]
    (False, [], ['take_1', 'release_1'])
"""

from __future__ import annotations

from collections import deque

import numpy as np

from petriflow.analysis import accepting_lasso, components, csr, reachable, shortest_path
from petriflow.analysis.exploration import StateSpaceLimit
from petriflow.engine import CompiledNet
from petriflow.errors import PetriflowError
from petriflow.marking import Marking
from petriflow.net import Net
from petriflow.properties.kripke import Kripke
from petriflow.properties.monitor import compile_predicate
from petriflow.properties.partial_order import PropertyStubbornSets, has_next
from petriflow.properties.language import (
    AllPaths, And, Constant, ExistsPath, Finally, Formula, Globally, Next, Not, Or, Until, atoms
)

__all__ = ["PRODUCTS", "check_ltl", "check_ltl_on_net", "to_spot"]


def to_spot(formula: Formula, names: dict[Formula, str]) -> str:
    """Spot's syntax for a quantifier-free path formula, atoms named by ``names``."""
    if formula in names:
        return names[formula]
    if isinstance(formula, Constant):
        return "1" if formula.value else "0"
    if isinstance(formula, Not):
        return f"!({to_spot(formula.operand, names)})"
    if isinstance(formula, (And, Or)):
        if not formula.operands:
            return "1" if isinstance(formula, And) else "0"
        joiner = " & " if isinstance(formula, And) else " | "
        return "(" + joiner.join(to_spot(f, names) for f in formula.operands) + ")"
    if isinstance(formula, (Next, Finally, Globally)):
        op = {Next: "X", Finally: "F", Globally: "G"}[type(formula)]
        return f"{op}({to_spot(formula.operand, names)})"
    if isinstance(formula, Until):
        return f"(({to_spot(formula.left, names)}) U ({to_spot(formula.right, names)}))"
    raise ValueError(f"not an LTL path formula: {formula}")


def _spot():
    try:
        import spot
    except ImportError as exc:  # pragma: no cover - spottl is a dependency
        raise PetriflowError("LTL needs Spot: pip install spottl") from exc
    return spot


def _guard(spot, formula, values: dict[str, np.ndarray], n: int) -> np.ndarray:
    """A Spot Boolean formula (an automaton edge's guard) on every state."""
    kind = formula.kind()
    if kind == spot.op_tt:
        return np.ones(n, dtype=bool)
    if kind == spot.op_ff:
        return np.zeros(n, dtype=bool)
    if kind == spot.op_ap:
        return values[formula.ap_name()]
    if kind == spot.op_Not:
        return ~_guard(spot, formula[0], values, n)
    parts = [_guard(spot, f, values, n) for f in formula]
    if kind == spot.op_And:
        return np.logical_and.reduce(parts)
    if kind == spot.op_Or:
        return np.logical_or.reduce(parts)
    raise ValueError(f"unexpected guard {formula}")


#: The product searches :func:`check_ltl` knows: ``"on-the-fly"`` (the default) builds
#: the product's states as its depth-first search reaches them and stops at the first
#: accepting cycle; ``"whole"`` builds every product edge as arrays, then its components.
PRODUCTS = ("on-the-fly", "whole")


def check_ltl(kripke: Kripke, formula: Formula, product: str = "on-the-fly"
              ) -> tuple[bool, dict | None]:
    """``(verdict, evidence)`` of an LTL formula at the initial marking.

    ``formula`` is ``A ψ``, ``E ψ`` or a bare path formula ``ψ`` (read as ``A ψ``).
    The evidence is a lasso ``{"witness": prefix, "cycle": cycle}`` (firing sequences):
    a run violating ``A ψ``, or a run satisfying ``E ψ``; ``None`` otherwise.
    ``product`` is one of :data:`PRODUCTS` (both give the same verdicts).
    """
    if product not in PRODUCTS:
        raise ValueError(f"unknown product search {product!r}: one of {', '.join(PRODUCTS)}")
    exists = isinstance(formula, ExistsPath)
    body = formula.operand if isinstance(formula, (AllPaths, ExistsPath)) else formula
    search = _lasso_on_the_fly if product == "on-the-fly" else _accepting_lasso
    found = search(kripke, body if exists else Not(body))
    if exists:
        return found is not None, found
    return found is None, found


def _automaton(kripke: Kripke, path: Formula):
    """Spot's Büchi automaton of ``path`` and its atoms' values on every state."""
    spot = _spot()
    names = {atom: f"p{k}" for k, atom in enumerate(atoms(path))}
    automaton = spot.translate(to_spot(path, names), "Buchi", "SBAcc")
    values = {name: kripke.holds(atom) for atom, name in names.items()}
    return spot, automaton, values


def _lasso_on_the_fly(kripke: Kripke, path: Formula) -> dict | None:
    """:func:`_accepting_lasso` by :func:`~petriflow.analysis.accepting_lasso`: the
    product explored from ``(M0, q0)`` only as far as its first accepting cycle."""
    spot, automaton, values = _automaton(kripke, path)
    condition = automaton.acc()
    dictionary = automaton.get_dict()
    edges = sorted(automaton.edges(), key=lambda edge: edge.src)
    q_count = automaton.num_states()
    guard = np.empty((max(len(edges), 1), kripke.n), dtype=bool)
    for j, edge in enumerate(edges):
        guard[j] = _guard(spot, spot.bdd_to_formula(edge.cond, dictionary), values, kripke.n)
    automaton_offsets = np.searchsorted([edge.src for edge in edges], np.arange(q_count + 1))
    automaton_targets = np.array([edge.dst for edge in edges] or [0], dtype=np.int64)
    accepting = np.array([condition.is_t() or (not condition.is_f() and bool(edge.acc))
                          for edge in edges] or [False])
    found = accepting_lasso(kripke.offsets, kripke.targets, guard, automaton_offsets.astype(np.int64),
                            automaton_targets, accepting, automaton.get_init_state_number())
    if found is None:
        return None
    prefix, cycle, _ = found
    return {"witness": kripke.names(prefix), "cycle": kripke.names(cycle)}


def _accepting_lasso(kripke: Kripke, path: Formula) -> dict | None:
    """A lasso of the graph that satisfies ``path``, or ``None`` when there is none."""
    spot, automaton, values = _automaton(kripke, path)
    condition = automaton.acc()
    n, q_count = kripke.n, automaton.num_states()
    dictionary = automaton.get_dict()
    sources, targets, graph_edges, accepting = [], [], [], []
    for edge in automaton.edges():
        guard = _guard(spot, spot.bdd_to_formula(edge.cond, dictionary), values, n)
        chosen = np.flatnonzero(guard[kripke.sources])      # graph edges leaving a guard state
        if not chosen.size:
            continue
        sources.append(kripke.sources[chosen] * q_count + edge.src)
        targets.append(kripke.targets[chosen] * q_count + edge.dst)
        graph_edges.append(chosen)
        marked = condition.is_t() or (not condition.is_f() and bool(edge.acc))
        accepting.append(np.full(chosen.size, marked))
    if not sources:
        return None
    source, target = np.concatenate(sources), np.concatenate(targets)
    graph_edge, accept = np.concatenate(graph_edges), np.concatenate(accepting)
    order = np.argsort(source, kind="stable")
    source, target, graph_edge, accept = source[order], target[order], graph_edge[order], accept[order]
    size = n * q_count
    offsets, neighbours = csr(size, source, target)
    start = automaton.get_init_state_number()        # product state (M0, q0) = 0 * q + q0
    seen = reachable(offsets, neighbours, [start])
    live = seen[source]
    labels = components(offsets, neighbours)
    good = np.flatnonzero(live & accept & (labels[source] == labels[target]))
    if not good.size:
        return None
    return _lasso(kripke, offsets, neighbours, source, target, graph_edge, labels, int(good[0]), start)


def _path(offsets, neighbours, start: int, goal: int, allowed: np.ndarray | None) -> list[int] | None:
    """Product edge ids of a shortest path ``start → goal`` through ``allowed`` nodes."""
    wanted = np.zeros(len(offsets) - 1, dtype=bool)
    wanted[goal] = True
    if allowed is not None and not allowed[start]:
        allowed = allowed.copy()
        allowed[start] = True               # the start is left whatever it is
    return shortest_path(offsets, neighbours, [start], wanted, allowed)


def _lasso(kripke: Kripke, offsets, neighbours, source, target, graph_edge, labels,
           accepting_edge: int, start: int) -> dict:
    u, v = int(source[accepting_edge]), int(target[accepting_edge])
    prefix = _path(offsets, neighbours, start, u, None)
    back = _path(offsets, neighbours, v, u, labels == labels[u])
    assert prefix is not None and back is not None   # u is reachable; u and v share a component
    cycle = [accepting_edge] + back
    return {"witness": kripke.names(graph_edge[prefix].tolist()),
            "cycle": kripke.names(graph_edge[cycle].tolist())}


def check_ltl_on_net(net: Net, start: Marking, formula: Formula, *, max_states: int,
                     stubborn: bool = False, stats: dict | None = None) -> tuple[bool, dict | None]:
    """:func:`check_ltl` without the reachability graph: the markings are generated from
    the net only as the product's search reaches them.

    The same Couvreur search as :func:`~petriflow.analysis.accepting_lasso`, in Python
    over markings: a violated ``A ψ`` (a satisfied ``E ψ``) costs only the markings up
    to its lasso, a satisfied one the product's reachable part. It is what decides LTL
    when the reachability graph is over budget or the net unbounded; with the graph
    built, :func:`check_ltl` is faster (compiled, and the graph is shared by all the
    formulas).

    With ``stubborn`` and a formula without ``X``, each marking is reduced to a stubborn
    set under the visibility condition and the stack proviso
    (:mod:`~petriflow.properties.partial_order`): the same verdicts, fewer markings;
    a formula with ``X`` is searched in full. ``stats``, when given, receives
    ``markings`` (how many the search stored) and ``reduced`` (whether the reduction
    was applied).

    Raises:
        StateSpaceLimit: the search stored more than ``max_states`` markings before
            deciding.

    Examples:
        >>> from petriflow.classic import dining_philosophers
        >>> from petriflow.properties.language import Finally, Fireable
        >>> net = dining_philosophers(3)
        >>> verdict, lasso = check_ltl_on_net(net, net.initial_marking,
        ...                                   Finally(Fireable(("release_0",))), max_states=100)
        >>> verdict, lasso["witness"], lasso["cycle"]
        (False, [], ['take_1', 'release_1'])
    """
    exists = isinstance(formula, ExistsPath)
    body = formula.operand if isinstance(formula, (AllPaths, ExistsPath)) else formula
    path = body if exists else Not(body)
    product = _NetProduct(net, start, path, max_states, stubborn and not has_next(path))
    try:
        found = product.lasso()
    finally:
        if stats is not None:
            stats.update(markings=len(product.vectors), reduced=product.reduction is not None)
    if exists:
        return found is not None, found
    return found is None, found


class _NetProduct:
    """The product of the net's markings and the Büchi automaton of ``path``, explored
    lazily (states ``(marking id, q)``; a deadlock stutters, as in the Kripke structure)."""

    def __init__(self, net: Net, start: Marking, path: Formula, max_states: int,
                 stubborn: bool = False) -> None:
        spot = _spot()
        self.compiled = CompiledNet(net)
        names = {atom: f"p{k}" for k, atom in enumerate(atoms(path))}
        # stubborn sets (visibility, stack proviso) for a formula without X
        self.reduction = PropertyStubbornSets(net, self.compiled) if stubborn else None
        if self.reduction is not None and not self.reduction.reduced:
            self.reduction = None
        self.visible = self.reduction.visible(list(names)) if self.reduction is not None else None
        self.reduced: dict[int, list[tuple[str | None, int]] | None] = {}
        automaton = spot.translate(to_spot(path, names), "Buchi", "SBAcc")
        index = self.compiled.place_index
        self.atoms = [compile_predicate(net, atom, index) for atom in names]
        position = {name: k for k, name in enumerate(names.values())}
        condition, dictionary = automaton.acc(), automaton.get_dict()
        self.edges: list[list[tuple[object, int, bool]]] = [[] for _ in range(automaton.num_states())]
        for edge in automaton.edges():
            guard = _guard_function(spot, spot.bdd_to_formula(edge.cond, dictionary), position)
            accepting = condition.is_t() or (not condition.is_f() and bool(edge.acc))
            self.edges[edge.src].append((guard, edge.dst, accepting))
        self.q0 = automaton.get_init_state_number()
        self.max_states = max_states
        self.markings: dict[tuple[int, ...], int] = {}
        self.vectors: list[tuple[int, ...]] = []
        self.values: list[tuple[bool, ...]] = []
        self.moves: list[list[tuple[str | None, int]] | None] = []
        self.start = self._marking(tuple(self.compiled.vector(start)))

    def _marking(self, vector: tuple[int, ...]) -> int:
        found = self.markings.get(vector)
        if found is None:
            if len(self.vectors) >= self.max_states:
                raise StateSpaceLimit(self.max_states, len(self.vectors), 0)
            found = self.markings[vector] = len(self.vectors)
            self.vectors.append(vector)
            self.values.append(tuple(bool(atom(vector)) for atom in self.atoms))
            self.moves.append(None)
        return found

    def _moves(self, m: int) -> list[tuple[str | None, int]]:
        """The firings from marking ``m``: ``(row id, target)``; a deadlock's stutter: ``(None, m)``."""
        moves = self.moves[m]
        if moves is None:
            compiled, vector = self.compiled, self.vectors[m]
            moves = []
            for t in compiled.enabled(vector):
                after = list(vector)
                compiled.consume(after, t)
                compiled.produce(after, t)
                moves.append((compiled.transitions[t], self._marking(tuple(after))))
            self.moves[m] = moves = moves or [(None, m)]
        return moves

    def _reduced_moves(self, m: int) -> list[tuple[str | None, int]] | None:
        """The firings of a stubborn set of marking ``m`` (C0-C2), or ``None``: all of them."""
        if m not in self.reduced:
            compiled, vector = self.compiled, self.vectors[m]
            rows = self.reduction.ltl_set(vector, compiled.enabled(vector), self.visible)
            moves = None
            if rows is not None:
                moves = []
                for t in rows:
                    after = list(vector)
                    compiled.consume(after, t)
                    compiled.produce(after, t)
                    moves.append((compiled.transitions[t], self._marking(tuple(after))))
            self.reduced[m] = moves
        return self.reduced[m]

    def successors(self, state: tuple[int, int], on_stack: set | None = None):
        """``(successor, accepting, row id)`` of a product state ``(marking, q)``: every
        firing, or with ``on_stack`` (the search's depth-first stack) and the reduction
        on, a stubborn set's unless one of its successors is on the stack (C3)."""
        m, q = state
        values = self.values[m]
        taken = [(target, accepting) for guard, target, accepting in self.edges[q] if guard(values)]
        moves = None
        if on_stack is not None and self.reduction is not None and taken:
            moves = self._reduced_moves(m)
            if moves is not None and any((after, target) in on_stack
                                         for _, after in moves for target, _ in taken):
                moves = None
        if moves is None:
            moves = self._moves(m)
        return [((after, target), accepting, name) for target, accepting in taken for name, after in moves]

    def _known(self, state: tuple[int, int]):
        """:meth:`successors` through the firings already generated from the state's
        marking (every firing, or a stubborn set's): real edges, no new marking."""
        m, q = state
        moves = self.moves[m] if self.moves[m] is not None else self.reduced.get(m)
        if moves is None:
            return self.successors(state)
        values = self.values[m]
        return [((after, target), accepting, name) for guard, target, accepting in self.edges[q]
                if guard(values) for name, after in moves]

    def lasso(self) -> dict | None:
        """Couvreur's search from ``(M0, q0)``, then the lasso around the component found."""
        start = (self.start, self.q0)
        number = {start: 1}
        on_stack = {start}
        stack = [(start, iter(self.successors(start, on_stack)))]
        live, roots = [start], [(1, False, False)]      # (number, acceptance inside, entering)
        while stack:
            state, moves = stack[-1]
            for after, accepting, _ in moves:
                seen = number.get(after, 0)
                if seen == 0:
                    number[after] = len(number) + 1
                    on_stack.add(after)
                    stack.append((after, iter(self.successors(after, on_stack))))
                    live.append(after)
                    roots.append((number[after], False, accepting))
                    break
                if seen > 0:                            # a cycle: merge its components
                    acc = accepting
                    while roots[-1][0] > seen:
                        _, inside, entering = roots.pop()
                        acc = acc or inside or entering
                    root, inside, entering = roots[-1]
                    roots[-1] = (root, inside or acc, entering)
                    if inside or acc:
                        # with the reduction, the prefix keeps to the states searched
                        visited = set(number) if self.reduction is not None else None
                        return self._lasso(start, [s for s in live if number[s] >= root], visited)
            else:
                stack.pop()
                on_stack.discard(state)
                if roots[-1][0] == number[state]:       # the component closes
                    roots.pop()
                    while True:
                        closed = live.pop()
                        number[closed] = -1
                        if closed == state:
                            break
        return None

    def _lasso(self, start, component: list, visited: set | None) -> dict:
        members = set(component)
        for u in component:                             # in depth-first order
            for v, accepting, name in self._known(u):
                if accepting and v in members:
                    prefix = self._shortest(start, u, visited)
                    back = self._shortest(v, u, members)
                    return {"witness": [n for n in prefix if n is not None],
                            "cycle": [n for n in [name] + back if n is not None]}
        raise AssertionError("an accepting component has an accepting edge")  # pragma: no cover

    def _shortest(self, start, goal, allowed: set | None) -> list[str | None]:
        """Row ids (``None``: a stutter) of a shortest product path ``start → goal``."""
        parent: dict = {start: None}
        queue = deque([start])
        while queue and goal not in parent:
            state = queue.popleft()
            for after, _, name in self._known(state):
                if after not in parent and (allowed is None or after in allowed):
                    parent[after] = (state, name)
                    queue.append(after)
        path = []
        while goal != start:
            goal, name = parent[goal]
            path.append(name)
        return path[::-1]


def _guard_function(spot, formula, position: dict[str, int]):
    """A Spot Boolean formula as a function of the atoms' values (a tuple)."""
    def source(node) -> str:
        kind = node.kind()
        if kind == spot.op_tt:
            return "True"
        if kind == spot.op_ff:
            return "False"
        if kind == spot.op_ap:
            return f"v[{int(position[node.ap_name()])}]"
        if kind == spot.op_Not:
            return f"(not {source(node[0])})"
        if kind in (spot.op_And, spot.op_Or):
            return "(" + (" and " if kind == spot.op_And else " or ").join(source(f) for f in node) + ")"
        raise ValueError(f"unexpected guard {node}")

    return eval(compile(f"lambda v: {source(formula)}", "<guard>", "eval"), {"__builtins__": {}})  # noqa: S307
