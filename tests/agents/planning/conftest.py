"""Shared helpers for the planning tests: an exact shortest-path oracle on grids."""

from __future__ import annotations

import math

import numpy as np
import pytest

SQRT2 = math.sqrt(2.0)


def grid_distances(grid: np.ndarray, start: tuple[int, int], *, diagonal_cost: float = SQRT2,
                   cut_corners: bool = False) -> np.ndarray:
    """Exact distances from ``start`` over the 8-connected free cells (scipy Dijkstra),
    with the planner's rules: straight moves cost 1, diagonal ones ``diagonal_cost``,
    a diagonal move needs both cells it passes between free unless ``cut_corners``."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import dijkstra

    rows, cols = grid.shape
    free = ~np.asarray(grid, bool)
    index = np.arange(rows * cols).reshape(rows, cols)
    sources, targets, costs = [], [], []
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            if dr == 0 and dc == 0:
                continue
            r0, r1 = max(0, -dr), rows - max(0, dr)
            c0, c1 = max(0, -dc), cols - max(0, dc)
            ok = free[r0:r1, c0:c1] & free[r0 + dr:r1 + dr, c0 + dc:c1 + dc]
            if dr and dc and not cut_corners:
                ok &= free[r0 + dr:r1 + dr, c0:c1] & free[r0:r1, c0 + dc:c1 + dc]
            sources.append(index[r0:r1, c0:c1][ok])
            targets.append(index[r0 + dr:r1 + dr, c0 + dc:c1 + dc][ok])
            costs.append(np.full(int(ok.sum()), diagonal_cost if dr and dc else 1.0))
    matrix = csr_matrix((np.concatenate(costs), (np.concatenate(sources), np.concatenate(targets))),
                        shape=(rows * cols, rows * cols))
    return dijkstra(matrix, directed=True, indices=start[0] * cols + start[1]).reshape(rows, cols)


@pytest.fixture
def oracle():
    """The exact distance function :func:`grid_distances`."""
    return grid_distances
