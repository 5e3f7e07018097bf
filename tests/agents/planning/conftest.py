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

    from petriflow.agents.planning.maps import grid_edges

    rows, cols = grid.shape
    sources, targets, costs = grid_edges(grid, diagonal_cost=diagonal_cost, cut_corners=cut_corners)
    matrix = csr_matrix((costs, (sources, targets)),
                        shape=(rows * cols, rows * cols))
    return dijkstra(matrix, directed=True, indices=start[0] * cols + start[1]).reshape(rows, cols)


@pytest.fixture
def oracle():
    """The exact distance function :func:`grid_distances`."""
    return grid_distances
