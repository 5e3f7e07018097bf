"""The compiled step of Farkas' algorithm behind :mod:`petriflow.analysis.invariants`.

Each step of the algorithm eliminates one column: every row that is positive there is
combined with every row that is negative there. Only the combinations that are new
*minimal-support* semiflows are worth keeping, and which those are is decided on the
supports alone, before any arithmetic (the combinatorial adjacency test of the double
description method): the rows ``p`` and ``q`` give a new minimal semiflow exactly when
no third row's support lies inside ``supp(p) | supp(q)``. A support is a bit set, one
``uint64`` word per 64 entries, so a subset test is a few word operations.

:func:`adjacent_pairs` runs that test for every (positive, negative) pair, compiled by
numba (cached on disk like the exploration loops; plain Python with the same results
where numba is missing), and counts its work so the caller can stop it at a budget.
"""

from __future__ import annotations

import numpy as np

from petriflow.analysis._numba import njit

_jit = njit(__name__)

__all__ = ["OK", "OVER_BUDGET", "FULL", "adjacent_pairs", "popcounts"]

#: Status codes of :func:`adjacent_pairs`.
OK, OVER_BUDGET, FULL = 0, 1, 2

_K1 = np.uint64(0x5555555555555555)
_K2 = np.uint64(0x3333333333333333)
_K4 = np.uint64(0x0F0F0F0F0F0F0F0F)
_H01 = np.uint64(0x0101010101010101)


@_jit
def _popcount(x):
    x = x - ((x >> np.uint64(1)) & _K1)
    x = (x & _K2) + ((x >> np.uint64(2)) & _K2)
    x = (x + (x >> np.uint64(4))) & _K4
    return np.int64((x * _H01) >> np.uint64(56))


@_jit
def popcounts(supports):
    """Per row, the number of bits set (the support's size)."""
    sizes = np.zeros(supports.shape[0], dtype=np.int64)
    for r in range(supports.shape[0]):
        for w in range(supports.shape[1]):
            sizes[r] += _popcount(supports[r, w])
    return sizes


@_jit
def adjacent_pairs(supports, order, sizes, pos, neg, max_size, budget, out, counters):
    """The (positive, negative) row pairs whose combination is a new minimal semiflow.

    Args:
        supports: ``rows x words`` bit sets, one per row of the current matrix (every
            row: those zero in the eliminated column too).
        order: the row indices by increasing support size; ``sizes`` those sizes.
        pos, neg: the rows positive and negative in the eliminated column.
        max_size: the largest support a new minimal semiflow can have (one more than
            the rank of the columns eliminated so far, or an upper bound of it).
        budget: stop with :data:`OVER_BUDGET` once ``counters[1]`` passes this.
        out: ``(k, 2)`` buffer for the pairs found.
        counters: ``[pairs found, work done]``; work counts the words and rows read.

    Returns:
        :data:`OK`; :data:`FULL` when ``out`` has no room left (more new rows than the
        caller allows); :data:`OVER_BUDGET`.
    """
    n_words = supports.shape[1]
    n_rows = order.shape[0]
    union = np.empty(n_words, dtype=np.uint64)
    found = counters[0]
    work = counters[1]
    status = OK
    for a in range(pos.shape[0]):
        p = pos[a]
        for b in range(neg.shape[0]):
            q = neg[b]
            size = np.int64(0)
            for w in range(n_words):
                u = supports[p, w] | supports[q, w]
                union[w] = u
                size += _popcount(u)
            work += n_words
            if size > max_size:
                continue
            adjacent = True
            for k in range(n_rows):
                r = order[k]
                if sizes[r] > size:
                    break              # rows only get larger: none fits inside the union
                work += 1
                if r == p or r == q:
                    continue
                inside = True
                for w in range(n_words):
                    if supports[r, w] & ~union[w]:
                        inside = False
                        break
                if inside:
                    adjacent = False
                    break
            if adjacent:
                if found >= out.shape[0]:
                    status = FULL
                    break
                out[found, 0] = p
                out[found, 1] = q
                found += 1
            if work > budget:
                status = OVER_BUDGET
                break
        if status != OK:
            break
    counters[0] = found
    counters[1] = work
    return status
