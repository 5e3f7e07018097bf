"""Exact integer linear algebra on small incidence matrices (private helpers).

Only what the analyses need: which columns of an integer matrix form a basis of its
column space, computed exactly (no floating point), so that results built on it are
proofs rather than estimates.
"""

from __future__ import annotations

import numpy as np

__all__ = ["pivot_columns"]

# Entries stay below this after each elimination step, so a*b - c*d never overflows int64.
_SAFE = 2**30


def pivot_columns(matrix: np.ndarray) -> list[int]:
    """Indices of columns of ``matrix`` that form a basis of its column space.

    Fraction-free Gaussian elimination over the integers (rows divided by their gcd
    after each step), in int64 while entries are small and in exact Python integers
    when they grow, so the answer is exact: the returned columns are linearly
    independent over the rationals and every other column is a rational combination
    of them.

    Args:
        matrix: a 2-D integer array.

    Returns:
        Increasing column indices; their number is the rank of ``matrix``.

    Examples:
        >>> pivot_columns(np.array([[1, -1, 0], [0, 1, -1]]))
        [0, 1]
        >>> pivot_columns(np.array([[1, 1], [2, 2]]))
        [0]
        >>> pivot_columns(np.zeros((2, 3), dtype=int))
        []
    """
    work = np.array(matrix, dtype=np.int64)
    if work.ndim != 2:
        raise ValueError("pivot_columns needs a 2-D matrix")
    rows, cols = work.shape
    pivots: list[int] = []
    rank = 0
    # An upper bound of every |entry| (only the rows a step updates can grow), so the
    # overflow test does not read the whole matrix at every step.
    top = int(np.abs(work).max(initial=0))
    for col in range(cols):
        if rank == rows:
            break
        nonzero = np.flatnonzero(work[rank:, col])
        if nonzero.size == 0:
            continue
        r = rank + int(nonzero[0])
        if r != rank:
            work[[rank, r]] = work[[r, rank]]
        pivot_row = work[rank]
        below = work[rank + 1:]
        factors = below[:, col].copy()
        hit = factors != 0
        if hit.any():
            piv = pivot_row[col]
            if work.dtype != object and top >= _SAFE:
                work = work.astype(object)
                pivot_row, below = work[rank], work[rank + 1:]
                piv = pivot_row[col]
            updated = below[hit] * piv - np.outer(factors[hit], pivot_row)
            if work.dtype != object:
                g = np.gcd.reduce(updated, axis=1)
                g[g == 0] = 1
                updated //= g[:, None]
                top = max(top, int(np.abs(updated).max(initial=0)))
            below[hit] = updated
        pivots.append(col)
        rank += 1
    return pivots
