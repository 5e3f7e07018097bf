"""Reachability properties on the symmetry quotient, beyond the full state space.

A team net's state space grows with the permutations of its interchangeable agents
(:mod:`petriflow.analysis.symmetry`); its quotient keeps one canonical marking per
orbit. A state predicate ``p`` that every permutation of the agents leaves unchanged
(``box_robot1 <= 1 && ... && box_robot20 <= 1``) has the same value on all markings of
an orbit, so ``AG p`` holds exactly when ``p`` holds in every reachable canonical
marking, and ``EF p`` exactly when it holds in one. The predicate's invariance is
*checked*, never assumed: for each group, swapping its first agent with each other
one (the transpositions generate the group) must map the predicate onto itself, up to
the order of the operands of ``&&``/``||`` and of the terms of a sum. Predicates on
token counts only (``enabled``/``deadlock`` are left to the full state space). A
witness (a marking violating ``AG p``, one satisfying ``EF p``) is replayed as a concrete
firing sequence from the initial marking (:meth:`SymmetricSpace.path`).

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
"""

from __future__ import annotations

from typing import Any

import numpy as np

from petriflow.analysis.symmetry import SymmetricSpace, SymmetryGroup
from petriflow.engine import CompiledNet
from petriflow.net import Net
from petriflow.properties.language import And, Compare, Constant, Formula, Linear, Not, Or

__all__ = ["holds_on_quotient", "symmetric"]


def _shape(formula: Formula, rename: dict[str, str]) -> Any:
    """A hashable form of the predicate with places renamed, blind to the order of
    ``&&``/``||`` operands and of a sum's terms; ``None`` outside token-count predicates."""
    if isinstance(formula, Constant):
        return formula.value
    if isinstance(formula, Compare):
        def side(linear: Linear) -> tuple:
            return frozenset((rename.get(p, p), k) for p, k in linear.terms), linear.offset
        return "cmp", formula.op, side(formula.left), side(formula.right)
    if isinstance(formula, Not):
        inner = _shape(formula.operand, rename)
        return None if inner is None else ("not", inner)
    if isinstance(formula, (And, Or)):
        parts = [_shape(f, rename) for f in formula.operands]
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


def symmetric(predicate: Formula, groups: list[SymmetryGroup], net: Net,
              compiled: CompiledNet | None = None) -> bool:
    """Whether every permutation of the groups' agents maps ``predicate`` onto itself."""
    places = (compiled or CompiledNet(net)).places
    plain = _shape(predicate, {})
    if plain is None:
        return False
    return all(_shape(predicate, swap) == plain for swap in _swaps(groups, places))


def holds_on_quotient(space: SymmetricSpace, predicate: Formula) -> np.ndarray:
    """Where a token-count predicate holds, on every canonical marking of ``space``."""
    columns = {p: j for j, p in enumerate(space.places)}
    rows = space.markings

    def total(linear: Linear) -> np.ndarray:
        out = np.full(len(rows), linear.offset, dtype=np.int64)
        for place, k in linear.terms:
            out += k * rows[:, columns[place]].astype(np.int64)
        return out

    def value(node: Formula) -> np.ndarray:
        if isinstance(node, Constant):
            return np.full(len(rows), node.value, dtype=bool)
        if isinstance(node, Compare):
            compare = {"<=": np.less_equal, "<": np.less, ">=": np.greater_equal, ">": np.greater,
                       "==": np.equal, "!=": np.not_equal}[node.op]
            return compare(total(node.left), total(node.right))
        if isinstance(node, Not):
            return ~value(node.operand)
        combine = np.logical_and if isinstance(node, And) else np.logical_or
        return combine.reduce([value(f) for f in node.operands], axis=0) if node.operands else \
            np.full(len(rows), isinstance(node, And), dtype=bool)

    return value(predicate)
