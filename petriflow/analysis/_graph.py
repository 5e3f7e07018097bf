"""Graph algorithms on edge arrays (private helpers for the analyses).

Strongly connected components and multi-source reachability on graphs given as
``(source, target)`` integer arrays. On large graphs scipy's compiled ``csgraph``
routines are used when scipy is installed (it is not a dependency of petriflow);
otherwise, and on small graphs, iterative pure-Python versions do the same work.
"""

from __future__ import annotations

import numpy as np

__all__ = ["can_reach", "reachable_from", "strong_components"]


#: Below this many edges the pure-Python versions are used: importing scipy costs more.
SCIPY_FROM_EDGES = 200_000


def _scipy_csgraph(edges: int = SCIPY_FROM_EDGES):
    if edges < SCIPY_FROM_EDGES:
        return None
    try:
        from scipy import sparse
        from scipy.sparse import csgraph
    except ImportError:  # pragma: no cover - exercised with scipy hidden in tests
        return None
    return sparse, csgraph


def _csr(n: int, source: np.ndarray, target: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(offsets, neighbours) of the graph, neighbours grouped by source."""
    order = np.argsort(source, kind="stable")
    offsets = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(source, minlength=n), out=offsets[1:])
    return offsets, np.asarray(target)[order]


def strong_components(n: int, source: np.ndarray, target: np.ndarray,
                      *, use_scipy: bool = True) -> np.ndarray:
    """Component label of each of the ``n`` nodes (labels are 0 .. k-1).

    Examples:
        >>> labels = strong_components(4, np.array([0, 1, 2]), np.array([1, 0, 3]))
        >>> bool(labels[0] == labels[1]), bool(labels[1] == labels[2]), bool(labels[2] == labels[3])
        (True, False, False)
    """
    source, target = np.asarray(source, dtype=np.int64), np.asarray(target, dtype=np.int64)
    found = _scipy_csgraph(len(source)) if use_scipy else None
    if found is not None and n:
        sparse, csgraph = found
        graph = sparse.csr_matrix((np.ones(len(source), dtype=np.int8), (source, target)),
                                  shape=(n, n))
        _, labels = csgraph.connected_components(graph, directed=True, connection="strong")
        return labels.astype(np.int64)
    return _tarjan(n, *_csr(n, source, target))


def _tarjan(n: int, offsets: np.ndarray, neighbours: np.ndarray) -> np.ndarray:
    """Iterative Tarjan: strongly connected components without recursion."""
    offsets_list, neighbours_list = offsets.tolist(), neighbours.tolist()
    index = [-1] * n
    low = [0] * n
    on_stack = [False] * n
    labels = [-1] * n
    stack: list[int] = []
    counter = 0
    components = 0
    for root in range(n):
        if index[root] != -1:
            continue
        work = [(root, offsets_list[root])]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack[root] = True
        while work:
            node, edge = work[-1]
            if edge < offsets_list[node + 1]:
                work[-1] = (node, edge + 1)
                nxt = neighbours_list[edge]
                if index[nxt] == -1:
                    index[nxt] = low[nxt] = counter
                    counter += 1
                    stack.append(nxt)
                    on_stack[nxt] = True
                    work.append((nxt, offsets_list[nxt]))
                elif on_stack[nxt] and index[nxt] < low[node]:
                    low[node] = index[nxt]
                continue
            work.pop()
            if work:
                up = work[-1][0]
                low[up] = min(low[up], low[node])
            if low[node] == index[node]:
                while True:
                    member = stack.pop()
                    on_stack[member] = False
                    labels[member] = components
                    if member == node:
                        break
                components += 1
    return np.array(labels, dtype=np.int64)


def reachable_from(n: int, source: np.ndarray, target: np.ndarray, starts,
                   *, use_scipy: bool = True) -> np.ndarray:
    """Boolean mask of the nodes reachable from any node in ``starts`` (included).

    Examples:
        >>> reachable_from(4, np.array([0, 1]), np.array([1, 2]), [1]).tolist()
        [False, True, True, False]
    """
    seen = np.zeros(n, dtype=bool)
    starts = np.unique(np.asarray(starts, dtype=np.int64))
    if not starts.size:
        return seen
    source, target = np.asarray(source, dtype=np.int64), np.asarray(target, dtype=np.int64)
    found = _scipy_csgraph(len(source)) if use_scipy else None
    if found is not None:
        sparse, csgraph = found
        # One extra node pointing at every start turns many sources into one.
        extra = np.full(starts.size, n, dtype=np.int64)
        rows, cols = np.concatenate((source, extra)), np.concatenate((target, starts))
        graph = sparse.csr_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)),
                                  shape=(n + 1, n + 1))
        order = csgraph.breadth_first_order(graph, n, directed=True, return_predecessors=False)
        seen[order[order < n]] = True
        return seen
    offsets, neighbours = _csr(n, source, target)
    offsets_list, neighbours_list = offsets.tolist(), neighbours.tolist()
    seen_list = [False] * n
    queue = [int(s) for s in starts]
    for s in queue:
        seen_list[s] = True
    for node in queue:  # the list grows while we walk it: a FIFO queue
        for k in range(offsets_list[node], offsets_list[node + 1]):
            nxt = neighbours_list[k]
            if not seen_list[nxt]:
                seen_list[nxt] = True
                queue.append(nxt)
    return np.array(seen_list, dtype=bool)


def can_reach(n: int, source: np.ndarray, target: np.ndarray, goals,
              *, use_scipy: bool = True) -> np.ndarray:
    """Boolean mask of the nodes from which some node in ``goals`` is reachable.

    Examples:
        >>> can_reach(4, np.array([0, 1]), np.array([1, 2]), [2]).tolist()
        [True, True, True, False]
    """
    return reachable_from(n, target, source, goals, use_scipy=use_scipy)
