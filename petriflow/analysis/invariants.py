"""P- and T-semiflows (invariants) by Farkas' algorithm, and structural boundedness.

With ``C`` the incidence matrix (one row per transition, one column per place, as in
:class:`~petriflow.engine.CompiledNet`):

* a **P-semiflow** is a vector ``y >= 0, y != 0`` over places with ``C @ y = 0``: the
  weighted token sum ``y·M`` is the same in every reachable marking;
* a **T-semiflow** is a vector ``x >= 0, x != 0`` over transitions with ``x @ C = 0``:
  firing each transition ``x[t]`` times (in an enabled order) reproduces the marking.

Farkas' algorithm yields the *minimal* semiflows (minimal supports, entries with no
common divisor); every semiflow is a non-negative rational combination of them. At each
step only the pairs of rows whose combination is a new minimal semiflow are combined,
chosen on their supports (bit sets, compiled subset tests in
:mod:`petriflow.analysis._farkas`), so the intermediate matrix only ever holds minimal
supports. Their number can still grow exponentially with the net (one T-semiflow per
elementary cycle of a state machine): a row limit and a work budget stop such cases
with :class:`InvariantLimit`, in about a second at the defaults.

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
from petriflow.analysis._linear import pivot_columns
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

#: Default cap on the rows of Farkas' intermediate matrix (and on the semiflows found).
DEFAULT_MAX_ROWS = 20_000
#: Default work budget of one semiflow computation: support words and rows read by the
#: adjacency tests, plus entries written by the combinations (about a fifth of a second of
#: compiled work on a 2020s laptop core; :func:`semiflows` stops with
#: :class:`InvariantLimit` beyond it).
DEFAULT_BUDGET = 100_000_000


#: Matrices up to this many entries have their rank computed exactly (it bounds the
#: support of a minimal semiflow); larger ones use min(rows, columns).
_RANK_ENTRIES = 200_000


class InvariantLimit(PetriflowError):
    """Farkas' algorithm was stopped before it finished.

    Attributes:
        reason: ``"size"`` (the starting matrix is beyond ``limits.INVARIANT_CELLS``),
            ``"rows"`` (more intermediate rows than ``max_rows``) or ``"budget"`` (more
            work than ``budget``).
    """

    def __init__(self, message: str, reason: str = "rows") -> None:
        super().__init__(message)
        self.reason = reason


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


def _too_large(n: int, m: int) -> InvariantLimit | None:
    if n * (n + m) > limits.INVARIANT_CELLS:
        return InvariantLimit(f"a {n} x {n + m} Farkas matrix is more than {limits.INVARIANT_CELLS:,} entries:"
                              " invariants not computed for a net this large", "size")
    return None


def semiflows(matrix: np.ndarray, *, max_rows: int = DEFAULT_MAX_ROWS,
              budget: int = DEFAULT_BUDGET) -> list[np.ndarray]:
    """Minimal non-negative integer solutions ``x`` of ``x @ matrix = 0`` (Farkas).

    Farkas' algorithm eliminates the columns one at a time (next the one that creates
    the fewest combinations). At each step only the pairs of rows whose combination is
    a new minimal-support solution are combined: those whose joint support contains no
    third row's support (tested on bit sets by compiled code, before any arithmetic), so
    no row is ever built only to be pruned. Arithmetic is exact: int64 while the entries
    are small, Python integers beyond.

    Args:
        matrix: an ``n x m`` integer matrix.
        max_rows: the most rows the intermediate matrix may hold.
        budget: the most work to spend: support words and rows read by the adjacency
            tests, matrix entries read to choose each column and written by the
            combinations.

    Returns:
        The minimal-support solutions, each a length-``n`` int array whose entries have
        no common divisor, sorted by their support.

    Raises:
        InvariantLimit: the matrix is too large to start, or the intermediate matrix
            grew beyond ``max_rows``, or the work beyond ``budget``.

    Examples:
        >>> [list(map(int, x)) for x in semiflows(np.array([[1], [-1], [-2]]))]
        [[1, 1, 0], [2, 0, 1]]
    """
    from petriflow.analysis import _farkas

    matrix = np.asarray(matrix, dtype=np.int64)
    n, m = matrix.shape
    if (error := _too_large(n, m)) is not None:
        raise error
    pool = _Pool(matrix, max_rows)
    remaining = matrix.any(axis=0)
    # A minimal support has at most rank + 1 entries (its rows of the eliminated columns
    # have a one-dimensional left kernel): the rank of the whole matrix bounds them all.
    rank = len(pivot_columns(matrix)) if n * m <= _RANK_ENTRIES else min(n, m)
    counters = np.zeros(2, dtype=np.int64)
    eliminated = 0

    def over_budget() -> InvariantLimit:
        return InvariantLimit(f"Farkas' algorithm exceeds its budget of {budget:,} steps", "budget")

    while remaining.any():
        # Next, the column that creates the fewest new rows (the first of them).
        score = np.where(remaining, pool.pos * pool.neg - pool.pos - pool.neg, np.iinfo(np.int64).max)
        j = int(np.argmin(score))
        remaining[j] = False
        eliminated += 1
        column = pool.c[:pool.used, j]
        live = pool.live[:pool.used]
        pos = np.flatnonzero(live & (column > 0))
        neg = np.flatnonzero(live & (column < 0))
        counters[1] += pool.used
        if len(pos) and len(neg):
            ids = np.flatnonzero(live)
            order = ids[np.argsort(pool.size[ids], kind="stable")]
            counters[1] += len(ids)
            room = max(0, max_rows - (len(ids) - len(pos) - len(neg)))
            out = np.empty((room, 2), dtype=np.int64)
            counters[0] = 0
            status = _farkas.adjacent_pairs(pool.s, order, pool.size, pos, neg,
                                            min(eliminated, rank) + 1, budget, out, counters)
            if status == _farkas.OVER_BUDGET:
                raise over_budget()
            if status == _farkas.FULL:
                raise InvariantLimit(f"Farkas' algorithm exceeds {max_rows} rows", "rows")
            pairs = out[:counters[0]]
            counters[1] += len(pairs) * (n + m)
            if counters[1] > budget:
                raise over_budget()
            pool.drop(np.concatenate([pos, neg]), remaining)
            pool.combine(pairs, j, remaining)
        else:
            pool.drop(np.concatenate([pos, neg]), remaining)
        if counters[1] > budget:
            raise over_budget()
        if pool.count == 0:
            return []
    found = _normalise(pool.x[np.flatnonzero(pool.live[:pool.used])])
    # by support: rows using the first entries first (lexicographic on "entry unused")
    order = np.lexsort((found == 0).T[::-1]) if n else np.arange(len(found))
    if found.dtype == object:
        return [np.array([int(v) for v in found[r]], dtype=np.int64) for r in order]
    return list(found[order].astype(np.int64))


class _Pool:
    """The rows of Farkas' matrix: a pool that only grows (rows dropped are marked dead,
    and the pool is compacted when most are), so a step costs what it changes.

    Per row: ``c``, its values on the columns of the matrix (eliminated ones are zero),
    ``x``, its semiflow part, ``s`` the support of ``x`` as bit words, ``size`` its number
    of bits, ``mag`` its largest absolute entry; per column, ``pos``/``neg``: how many
    live rows are positive/negative there.
    """

    def __init__(self, matrix: np.ndarray, max_rows: int) -> None:
        n, m = matrix.shape
        self.max_rows = max_rows
        self.used = self.count = n
        self.c = matrix.copy()
        self.x = np.eye(n, dtype=np.int64)
        self.s = np.zeros((n, max(1, -(-n // 64))), dtype=np.uint64)
        ids = np.arange(n)
        self.s[ids, ids // 64] = np.left_shift(np.uint64(1), (ids % 64).astype(np.uint64))
        self.size = np.ones(n, dtype=np.int64)
        self.mag = np.maximum(np.abs(matrix).max(axis=1, initial=0), 1)
        self.live = np.ones(n, dtype=bool)
        self.pos = (matrix > 0).sum(axis=0)
        self.neg = (matrix < 0).sum(axis=0)

    def drop(self, rows: np.ndarray, remaining: np.ndarray) -> None:
        if not len(rows):
            return
        self.live[rows] = False
        self.count -= len(rows)
        self.pos -= ((self.c[rows] > 0) & remaining).sum(axis=0)
        self.neg -= ((self.c[rows] < 0) & remaining).sum(axis=0)

    def combine(self, pairs: np.ndarray, j: int, remaining: np.ndarray) -> None:
        if not len(pairs):
            return
        p, q = pairs[:, 0], pairs[:, 1]
        if self.c.dtype != object and int(self.mag[p].max()) * int(self.mag[q].max()) * 2 >= 2**62:
            self.c, self.x = self.c.astype(object), self.x.astype(object)
        a, b = self.c[p, j:j + 1], -self.c[q, j:j + 1]
        rows = _normalise(np.concatenate([b * self.c[p] + a * self.c[q],
                                          b * self.x[p] + a * self.x[q]], axis=1))
        m = self.c.shape[1]
        c, x = rows[:, :m], rows[:, m:]
        supports = self.s[p] | self.s[q]
        self._room(len(pairs))          # may compact the pool: p and q are stale after it
        new = slice(self.used, self.used + len(pairs))
        self.c[new], self.x[new] = c, x
        self.s[new] = supports
        self.size[new] = _popcount_rows(supports)
        self.mag[new] = np.maximum(np.abs(rows).max(axis=1), 1) if rows.dtype != object else [
            max(max(abs(int(v)) for v in r), 1) for r in rows]
        self.live[new] = True
        self.used += len(pairs)
        self.count += len(pairs)
        self.pos += ((c > 0) & remaining).sum(axis=0)
        self.neg += ((c < 0) & remaining).sum(axis=0)

    def _room(self, extra: int) -> None:
        """Make room for ``extra`` rows: compact when most rows are dead, else grow."""
        if self.used + extra <= len(self.live):
            return
        if self.count < self.used // 2:
            keep = np.flatnonzero(self.live[:self.used])
            for name in ("c", "x", "s", "size", "mag", "live"):
                array = getattr(self, name)
                array[:len(keep)] = array[keep]
            self.used = len(keep)
            if self.used + extra <= len(self.live):
                return
        rows = max(2 * len(self.live), self.used + extra)
        for name in ("c", "x", "s", "size", "mag", "live"):
            array = getattr(self, name)
            bigger = np.zeros((rows,) + array.shape[1:], dtype=array.dtype)
            bigger[:self.used] = array[:self.used]
            setattr(self, name, bigger)


def _popcount_rows(words: np.ndarray) -> np.ndarray:
    return np.unpackbits(words.view(np.uint8), axis=1).sum(axis=1, dtype=np.int64)


def _compiled(net: Net | CompiledNet) -> CompiledNet:
    return net if isinstance(net, CompiledNet) else CompiledNet(net)


# Semiflows per compiled net (a CompiledNet is never changed once built), so the
# analyses that each need them compute them once.
_CACHE: weakref.WeakKeyDictionary[CompiledNet, dict] = weakref.WeakKeyDictionary()


def _cached_semiflows(compiled: CompiledNet, kind: str, max_rows: int,
                      budget: int = DEFAULT_BUDGET) -> list[np.ndarray]:
    """P- (``kind="p"``) or T-semiflows of a compiled net, computed once per limit."""
    entry = _CACHE.setdefault(compiled, {})
    key = (kind, max_rows, budget)
    if key not in entry:
        n_p, n_t = len(compiled.places), len(compiled.transitions)
        n, m = (n_p, n_t) if kind == "p" else (n_t, n_p)
        try:
            if (error := _too_large(n, m)) is not None:  # before the dense incidence matrix is even built
                raise error
            matrix = compiled.incidence.T if kind == "p" else compiled.incidence
            entry[key] = semiflows(matrix, max_rows=max_rows, budget=budget)
        except InvariantLimit as exc:
            entry[key] = exc
    found = entry[key]
    if isinstance(found, InvariantLimit):
        raise InvariantLimit(str(found), found.reason)
    return found


def p_semiflows(net: Net | CompiledNet, *, max_rows: int = DEFAULT_MAX_ROWS,
                budget: int = DEFAULT_BUDGET) -> list[dict[str, int]]:
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
    found = _cached_semiflows(compiled, "p", max_rows, budget)
    names = compiled.places
    return [{names[p]: int(y[p]) for p in np.flatnonzero(y)} for y in found]


def t_semiflows(net: Net | CompiledNet, *, max_rows: int = DEFAULT_MAX_ROWS,
                budget: int = DEFAULT_BUDGET) -> list[dict[str, int]]:
    """Minimal T-semiflows as ``{transition: count}`` (transitions with 0 left out).

    Raises:
        InvariantLimit: see :func:`semiflows`.

    Examples:
        >>> from petriflow.classic import producer_consumer
        >>> t_semiflows(producer_consumer(2))
        [{'produce': 1, 'put': 1, 'take': 1, 'consume': 1}]
    """
    compiled = _compiled(net)
    found = _cached_semiflows(compiled, "t", max_rows, budget)
    names = compiled.transitions
    return [{names[t]: int(x[t]) for t in np.flatnonzero(x)} for x in found]


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
