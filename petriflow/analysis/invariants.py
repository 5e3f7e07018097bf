"""P- and T-semiflows (invariants) by Farkas' algorithm, and structural boundedness.

With ``C`` the incidence matrix (one row per transition, one column per place, as in
:class:`~petriflow.engine.CompiledNet`):

* a **P-semiflow** is a vector ``y >= 0, y != 0`` over places with ``C @ y = 0``: the
  weighted token sum ``y·M`` is the same in every reachable marking;
* a **T-semiflow** is a vector ``x >= 0, x != 0`` over transitions with ``x @ C = 0``:
  firing each transition ``x[t]`` times (in an enabled order) reproduces the marking.

Farkas' algorithm yields the *minimal* semiflows (minimal supports, entries with no
common divisor); every semiflow is a non-negative rational combination of them. Rows
whose support contains another row's support are pruned after every step, which keeps
the intermediate matrix small on the nets met in practice; a row limit stops runaway
cases with :class:`InvariantLimit`.

A net whose every place lies in the support of some P-semiflow ("covered by positive
P-invariants") is bounded from any initial marking: ``M(p) <= (y·M0) // y[p]``.

Examples:
    >>> from petriflow.classic import dining_philosophers
    >>> net = dining_philosophers(3)
    >>> flows = p_semiflows(net)
    >>> len(flows), {'eat_0': 1, 'think_0': 1} in flows, {'eat_0': 1, 'eat_2': 1, 'fork_0': 1} in flows
    (6, True, True)
    >>> t_semiflows(net)[0]
    {'take_0': 1, 'release_0': 1}
    >>> structural_bounds(net)["fork_1"]
    1
"""

from __future__ import annotations

import weakref
from collections.abc import Mapping
from math import gcd

import numpy as np

from petriflow import limits
from petriflow.engine import CompiledNet
from petriflow.errors import PetriflowError
from petriflow.net import Net

__all__ = [
    "InvariantLimit",
    "is_covered_by_p_semiflows",
    "p_semiflows",
    "semiflows",
    "structural_bounds",
    "t_semiflows",
]

#: Default cap on the rows of Farkas' intermediate matrix.
DEFAULT_MAX_ROWS = 2000



class InvariantLimit(PetriflowError):
    """Farkas' algorithm needed more intermediate rows than the limit allows."""


def _support_bits(rows: np.ndarray) -> list[int]:
    """Support of each row as a Python int bitset (bit j set when entry j > 0)."""
    if rows.shape[1] == 0:
        return [0] * rows.shape[0]
    packed = np.packbits(rows > 0, axis=1, bitorder="little")
    return [int.from_bytes(r.tobytes(), "little") for r in packed]


def _prune(rows: np.ndarray) -> np.ndarray:
    """Drop rows whose support (right part) strictly contains another's, and duplicates."""
    if rows.shape[0] <= 1:
        return rows
    supports = _support_bits(rows)
    order = sorted(range(len(supports)), key=lambda r: supports[r].bit_count())
    kept: list[int] = []
    kept_supports: list[int] = []
    seen: set[bytes] = set()
    for r in order:
        s = supports[r]
        if any((k & s) == k and k != s for k in kept_supports):
            continue
        key = rows[r].tobytes()
        if key in seen:
            continue
        seen.add(key)
        kept.append(r)
        kept_supports.append(s)
    kept.sort()
    return rows[kept]


def _normalise(rows: np.ndarray) -> np.ndarray:
    if rows.dtype == object:
        for r in rows:
            g = 0
            for v in r:
                g = gcd(g, int(v))
            if g > 1:
                r //= g
        return rows
    g = np.gcd.reduce(rows, axis=1)
    g[g == 0] = 1
    return rows // g[:, None]


def semiflows(matrix: np.ndarray, *, max_rows: int = DEFAULT_MAX_ROWS) -> list[np.ndarray]:
    """Minimal non-negative integer solutions ``x`` of ``x @ matrix = 0`` (Farkas).

    Args:
        matrix: an ``n x m`` integer matrix.
        max_rows: the most rows the intermediate matrix may hold.

    Returns:
        The minimal-support solutions, each a length-``n`` int array whose entries have
        no common divisor, sorted by their support.

    Raises:
        InvariantLimit: the intermediate matrix grew beyond ``max_rows``.

    Examples:
        >>> [list(map(int, x)) for x in semiflows(np.array([[1], [-1], [-2]]))]
        [[1, 1, 0], [2, 0, 1]]
    """
    matrix = np.asarray(matrix, dtype=np.int64)
    n, m = matrix.shape
    if n * (n + m) > limits.INVARIANT_CELLS:
        raise InvariantLimit(f"a {n} x {n + m} Farkas matrix is more than {limits.INVARIANT_CELLS:,} entries:"
                             " invariants not computed for a net this large")
    rows = np.concatenate([matrix, np.eye(n, dtype=np.int64)], axis=1)
    remaining = list(range(m))
    while remaining:
        # Next, the column that creates the fewest new rows.
        block = rows[:, remaining]
        pos, neg = (block > 0).sum(axis=0), (block < 0).sum(axis=0)
        j = remaining.pop(int(np.argmin(pos * neg - pos - neg)))
        column = rows[:, j]
        zero, pos, neg = rows[column == 0], rows[column > 0], rows[column < 0]
        if len(pos) and len(neg):
            if len(pos) * len(neg) + len(zero) > 50 * max_rows:
                raise InvariantLimit(f"Farkas' algorithm exceeds {max_rows} rows")
            a = pos[:, j].reshape(-1, 1, 1)
            b = -neg[:, j].reshape(1, -1, 1)
            big = rows.dtype != object and max(int(np.abs(rows).max()), 1) ** 2 * 2 >= 2**62
            if big:
                pos, neg, a, b = (x.astype(object) for x in (pos, neg, a, b))
                zero = zero.astype(object)
            combined = (b * pos[:, None, :] + a * neg[None, :, :]).reshape(-1, rows.shape[1])
            combined = _normalise(combined)
            rows = np.concatenate([zero, combined]) if len(zero) else combined
        else:
            rows = zero
        rows = _prune(rows)
        if len(rows) > max_rows:
            raise InvariantLimit(f"Farkas' algorithm exceeds {max_rows} rows")
        if len(rows) == 0:
            return []
    result = [np.array([int(v) for v in r[m:]], dtype=np.int64) for r in _normalise(rows)]
    result.sort(key=lambda x: tuple(-int(v > 0) for v in x))
    return result


def _compiled(net: Net | CompiledNet) -> CompiledNet:
    return net if isinstance(net, CompiledNet) else CompiledNet(net)


# Semiflows per compiled net (a CompiledNet is never changed once built), so the
# analyses that each need them compute them once.
_CACHE: weakref.WeakKeyDictionary[CompiledNet, dict] = weakref.WeakKeyDictionary()


def _cached_semiflows(compiled: CompiledNet, kind: str, max_rows: int) -> list[np.ndarray]:
    """P- (``kind="p"``) or T-semiflows of a compiled net, computed once per limit."""
    entry = _CACHE.setdefault(compiled, {})
    key = (kind, max_rows)
    if key not in entry:
        n_p, n_t = len(compiled.places), len(compiled.transitions)
        n, m = (n_p, n_t) if kind == "p" else (n_t, n_p)
        try:
            if n * (n + m) > limits.INVARIANT_CELLS:  # before the dense incidence matrix is even built
                raise InvariantLimit(f"a {n} x {n + m} Farkas matrix is more than {limits.INVARIANT_CELLS:,} entries:"
                                     " invariants not computed for a net this large")
            matrix = compiled.incidence.T if kind == "p" else compiled.incidence
            entry[key] = semiflows(matrix, max_rows=max_rows)
        except InvariantLimit as exc:
            entry[key] = exc
    found = entry[key]
    if isinstance(found, InvariantLimit):
        raise InvariantLimit(str(found))
    return found


def p_semiflows(net: Net | CompiledNet, *, max_rows: int = DEFAULT_MAX_ROWS) -> list[dict[str, int]]:
    """Minimal P-semiflows as ``{place: weight}`` (places with weight 0 left out).

    Raises:
        InvariantLimit: see :func:`semiflows`.

    Examples:
        >>> from petriflow.classic import producer_consumer
        >>> for y in p_semiflows(producer_consumer(2, batch=2)):
        ...     print(y)
        {'ready_to_produce': 1, 'ready_to_put': 1}
        {'buffer': 1, 'free': 1}
        {'ready_to_take': 1, 'ready_to_consume': 1}
    """
    compiled = _compiled(net)
    found = _cached_semiflows(compiled, "p", max_rows)
    return [{compiled.places[p]: int(v) for p, v in enumerate(y) if v} for y in found]


def t_semiflows(net: Net | CompiledNet, *, max_rows: int = DEFAULT_MAX_ROWS) -> list[dict[str, int]]:
    """Minimal T-semiflows as ``{transition: count}`` (transitions with 0 left out).

    Raises:
        InvariantLimit: see :func:`semiflows`.

    Examples:
        >>> from petriflow.classic import producer_consumer
        >>> t_semiflows(producer_consumer(2))
        [{'produce': 1, 'put': 1, 'take': 1, 'consume': 1}]
    """
    compiled = _compiled(net)
    found = _cached_semiflows(compiled, "t", max_rows)
    return [{compiled.transitions[t]: int(v) for t, v in enumerate(x) if v} for x in found]


def structural_bounds(
    net: Net | CompiledNet,
    marking: Mapping[str, int] | None = None,
    *,
    semiflows_found: list[dict[str, int]] | None = None,
    max_rows: int = DEFAULT_MAX_ROWS,
) -> dict[str, int]:
    """Upper bounds on token counts proved by P-semiflows, for the places they cover.

    For a P-semiflow ``y`` and a place ``p`` with ``y[p] > 0``, every reachable marking
    has ``M(p) <= (y·M0) // y[p]``; the bound given is the smallest over all semiflows.
    Places no semiflow covers are left out (they may or may not be bounded).

    Args:
        net: the net (or its compiled form).
        marking: the initial marking (default: the net's).
        semiflows_found: P-semiflows already computed with :func:`p_semiflows`.
        max_rows: passed to :func:`p_semiflows`.

    Raises:
        InvariantLimit: see :func:`semiflows`.

    Examples:
        >>> from petriflow.classic import producer_consumer
        >>> structural_bounds(producer_consumer(5))
        {'ready_to_produce': 1, 'ready_to_put': 1, 'buffer': 5, 'free': 5, 'ready_to_take': 1, 'ready_to_consume': 1}
    """
    compiled = _compiled(net)
    start = compiled.net.initial_marking if marking is None else marking
    flows = p_semiflows(compiled, max_rows=max_rows) if semiflows_found is None else semiflows_found
    bounds: dict[str, int] = {}
    for y in flows:
        total = sum(w * start.get(p, 0) for p, w in y.items())
        for place, weight in y.items():
            bound = total // weight
            if place not in bounds or bound < bounds[place]:
                bounds[place] = bound
    return {p: bounds[p] for p in compiled.places if p in bounds}


def is_covered_by_p_semiflows(net: Net | CompiledNet, *, max_rows: int = DEFAULT_MAX_ROWS) -> bool:
    """Whether every place lies in some P-semiflow (then the net is bounded for any M0).

    Examples:
        >>> from petriflow.classic import independent_cycles
        >>> is_covered_by_p_semiflows(independent_cycles(2))
        True
    """
    compiled = _compiled(net)
    covered = set()
    for y in p_semiflows(compiled, max_rows=max_rows):
        covered.update(y)
    return len(covered) == len(compiled.places)
