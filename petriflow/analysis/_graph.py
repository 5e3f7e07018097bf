"""Graph algorithms on edge arrays (private helpers for the analyses).

Strongly connected components, multi-source reachability and per-component summaries
on graphs in compressed-row form, ``(offsets, neighbours)`` with node ``u``'s edges at
``offsets[u]:offsets[u + 1]``, as a :class:`~petriflow.analysis.reachability.StateSpace`
keeps its edges (``components``, ``reachable``, ``reaching``, ``terminal_summary_csr``),
or given as ``(source, target)`` integer arrays (``strong_components``,
``reachable_from``, ``can_reach``, ``terminal_summary``), which :func:`csr` groups:
edges already grouped by source are used as they are, others are grouped by a stable
counting sort. On large graphs (from :data:`COMPILED_FROM_EDGES` edges) the loops run
compiled by numba. Small graphs, and every graph where numba is missing or disabled
(``NUMBA_DISABLE_JIT=1``), take iterative pure-Python versions with the same results.

numba is imported on the first large graph only (importing it costs a third of a
second), and the loops are compiled then, or loaded from numba's disk cache.
"""

from __future__ import annotations

import numpy as np

__all__ = ["can_reach", "components", "csr", "occurring", "reachable", "reachable_from",
           "reaching", "shortest_path", "strong_components", "terminal_summary",
           "terminal_summary_csr", "transpose"]


#: Below this many edges the pure-Python versions are used: loading the compiled
#: loops (numba's import and disk cache) costs more than they save.
COMPILED_FROM_EDGES = 30_000

_LOOPS: dict | None = None


def _compiled(edges: int):
    """The compiled loops (a dict by name), or ``None`` for a small graph or without numba."""
    global _LOOPS
    if edges < COMPILED_FROM_EDGES:
        return None
    if _LOOPS is None:
        _LOOPS = _compile()
    return _LOOPS or None


def _compile() -> dict:
    """Wrap the ``_*_loop`` functions with ``numba.njit`` (an empty dict without numba)."""
    try:
        import numba
    except ImportError:  # pragma: no cover - exercised only where numba is missing
        return {}
    if numba.config.DISABLE_JIT:
        return {}
    # numba's on-disk cache is keyed by source file but re-imports the module by name
    # when it loads; only the installed name caches (see petriflow/analysis/_kernel.py).
    jit = numba.njit(cache=__name__ == "petriflow.analysis._graph", nogil=True)
    return {name: jit(function) for name, function in _LOOP_FUNCTIONS.items()}


def _ids(values) -> np.ndarray:
    """``values`` as an int16, int32 or int64 array, copied only when it is none of them
    (each dtype is one more compiled version of a loop)."""
    values = np.asarray(values)
    if values.dtype in (np.int16, np.int32, np.int64):
        return values
    return values.astype(np.int64)


def _node_dtype(n: int):
    """The dtype of per-node scratch arrays that hold node ids and DFS indices (up to n)."""
    return np.int32 if n < 2**31 - 1 else np.int64


# CSR ---------------------------------------------------------------------------------

def csr(n: int, source, target, *, compiled: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """``(offsets, neighbours)``: the targets of node ``u``'s edges are
    ``neighbours[offsets[u]:offsets[u + 1]]``, in edge order.

    When the edges are already grouped by source, ``neighbours`` is ``target`` itself.

    Examples:
        >>> offsets, neighbours = csr(3, np.array([2, 0, 2]), np.array([0, 1, 1]))
        >>> offsets.tolist(), neighbours.tolist()
        ([0, 1, 1, 3], [1, 0, 1])
    """
    offsets, (neighbours,) = _group(n, source, target, compiled=compiled)
    return offsets, neighbours


def _group(n: int, source, target, *more, compiled: bool = True
           ) -> tuple[np.ndarray, list[np.ndarray]]:
    """``(offsets, [target, *more])`` with the per-edge arrays reordered (stably) so
    that node ``u``'s edges are ``offsets[u]:offsets[u + 1]``; arrays already grouped
    by source are returned as they are."""
    source, columns = _ids(source), [_ids(target), *(_ids(m) for m in more)]
    loops = _compiled(len(source)) if compiled else None
    if loops is None:
        if source.size and not (0 <= source.min() and source.max() < n
                                and 0 <= columns[0].min() and columns[0].max() < n):
            raise ValueError(f"edges must join nodes 0 .. {n - 1}")
        order = np.argsort(source, kind="stable")
        offsets = np.zeros(n + 1, dtype=np.int64)
        np.cumsum(np.bincount(source, minlength=n), out=offsets[1:])
        return offsets, [c[order] for c in columns]
    offsets = np.zeros(n + 1, dtype=np.int64)
    grouped = loops["offsets"](source, columns[0], offsets)
    if grouped < 0:
        raise ValueError(f"edges must join nodes 0 .. {n - 1}")
    if grouped:
        return offsets, columns
    reordered = []
    for column in columns:
        out = np.empty_like(column)
        loops["scatter"](source, column, offsets, out)
        reordered.append(out)
    return offsets, reordered


def transpose(offsets: np.ndarray, neighbours: np.ndarray, *, compiled: bool = True
              ) -> tuple[np.ndarray, np.ndarray]:
    """The compressed rows of the reversed graph (each node's predecessors, increasing).

    Examples:
        >>> offsets, neighbours = transpose(np.array([0, 2, 2, 3]), np.array([1, 2, 1]))
        >>> offsets.tolist(), neighbours.tolist()
        ([0, 0, 2, 3], [0, 2, 0])
    """
    n = len(offsets) - 1
    loops = _compiled(len(neighbours)) if compiled else None
    if loops is None:
        sources = np.repeat(np.arange(n, dtype=_node_dtype(n)), np.diff(offsets))
        return csr(n, neighbours, sources, compiled=False)
    reverse = np.zeros(n + 1, dtype=np.int64)
    predecessors = np.empty(len(neighbours), dtype=_node_dtype(n))
    if not loops["transpose"](offsets, neighbours, reverse, predecessors):
        raise ValueError(f"edges must join nodes 0 .. {n - 1}")
    return reverse, predecessors


def _transpose_loop(offsets, neighbours, reverse, predecessors):
    """Fill ``reverse`` (zeros, n + 1) and ``predecessors`` with the reversed graph's
    compressed rows; False when a neighbour is not a node."""
    n = offsets.shape[0] - 1
    for e in range(neighbours.shape[0]):
        v = neighbours[e]
        if v < 0 or v >= n:
            return False
        reverse[v + 1] += 1
    for v in range(1, n + 1):
        reverse[v] += reverse[v - 1]
    position = reverse[:-1].copy()
    for u in range(n):
        for e in range(offsets[u], offsets[u + 1]):
            v = neighbours[e]
            predecessors[position[v]] = u
            position[v] += 1
    return True


def _offsets_loop(keys, values, offsets):
    """Fill ``offsets`` (zeros, length n + 1) with the cumulative counts of ``keys``;
    return 1 when ``keys`` never decreases (the edges are grouped by key), else 0, and
    -1 when a key or a value is not a node."""
    n = offsets.shape[0] - 1
    grouped = 1
    previous = -1
    for e in range(keys.shape[0]):
        key = keys[e]
        if key < 0 or key >= n or values[e] < 0 or values[e] >= n:
            return -1
        offsets[key + 1] += 1
        if key < previous:
            grouped = 0
        previous = key
    for u in range(1, offsets.shape[0]):
        offsets[u] += offsets[u - 1]
    return grouped


def _scatter_loop(keys, values, offsets, out):
    """Stable counting sort: ``out`` gets ``values`` grouped by ``keys`` (offsets as
    :func:`_offsets_loop` made them)."""
    position = offsets[:-1].copy()
    for e in range(keys.shape[0]):
        key = keys[e]
        out[position[key]] = values[e]
        position[key] += 1


# Strongly connected components ---------------------------------------------------------

def strong_components(n: int, source, target, *, compiled: bool = True) -> np.ndarray:
    """Component label of each of the ``n`` nodes (labels are 0 .. k-1).

    Labels are numbered as Tarjan's algorithm completes the components, roots tried in
    node order and edges in edge order: every edge between two components goes from a
    higher label to a lower one. Both versions number them the same way.

    Examples:
        >>> labels = strong_components(4, np.array([0, 1, 2]), np.array([1, 0, 3]))
        >>> bool(labels[0] == labels[1]), bool(labels[1] == labels[2]), bool(labels[2] == labels[3])
        (True, False, False)
    """
    return components(*csr(n, source, target, compiled=compiled), compiled=compiled)


def components(offsets: np.ndarray, neighbours: np.ndarray, *, compiled: bool = True
               ) -> np.ndarray:
    """:func:`strong_components` of a graph in compressed-row form (see :func:`csr`)."""
    n = len(offsets) - 1
    # the pure-Python search visits every node: a graph of many nodes and few edges
    # (a restriction of a large one) is compiled too
    loops = _compiled(max(len(neighbours), n)) if compiled else None
    if loops is None:
        return _tarjan(n, offsets, neighbours)
    dtype = _node_dtype(n)
    rindex, stack, path = (np.empty(n, dtype=dtype) for _ in range(3))
    loops["pearce"](offsets, neighbours, rindex, stack, path, np.empty(n, dtype=np.int64),
                    np.empty(n, dtype=bool))
    return np.subtract(n - 1, rindex, dtype=np.int64)


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


def _pearce_loop(offsets, neighbours, rindex, stack, path, path_edge, path_root):
    """Pearce's iterative variant of Tarjan's algorithm; return the number of components.

    One array, ``rindex``, replaces Tarjan's index, low-link and on-stack flags: a node's
    DFS index (from 1) while its component is open, then its component number, counted
    down from n - 1 so that it compares above every open index. Components complete in
    Tarjan's order, so component ``n - 1 - rindex`` is :func:`_tarjan`'s label.
    ``stack`` (open nodes that are not roots), the DFS ``path``, the next edge of each
    node on it (``path_edge``) and whether it is still a root (``path_root``) are
    scratch space of n entries. Pearce, "A space-efficient algorithm for finding strongly
    connected components", Information Processing Letters 116 (2016), algorithm 3.
    """
    n = rindex.shape[0]
    for u in range(n):
        rindex[u] = 0
    index = 1
    component = n - 1
    top = 0
    for start in range(n):
        if rindex[start] != 0:
            continue
        rindex[start] = index
        index += 1
        path[0] = start
        path_edge[0] = offsets[start]
        path_root[0] = True
        depth = 1
        while depth > 0:
            node = path[depth - 1]
            edge = path_edge[depth - 1]
            end = offsets[node + 1]
            low = rindex[node]
            root = path_root[depth - 1]
            descended = False
            while edge < end:
                nxt = neighbours[edge]
                edge += 1
                seen = rindex[nxt]
                if seen == 0:
                    rindex[node] = low
                    path_edge[depth - 1] = edge
                    path_root[depth - 1] = root
                    rindex[nxt] = index
                    index += 1
                    path[depth] = nxt
                    path_edge[depth] = offsets[nxt]
                    path_root[depth] = True
                    depth += 1
                    descended = True
                    break
                if seen < low:
                    low = seen
                    root = False
            if descended:
                continue
            depth -= 1
            if root:
                index -= 1
                while top > 0 and low <= rindex[stack[top - 1]]:
                    top -= 1
                    rindex[stack[top]] = component
                    index -= 1
                rindex[node] = component
                component -= 1
            else:
                rindex[node] = low
                stack[top] = node
                top += 1
            if depth > 0 and rindex[node] < rindex[path[depth - 1]]:
                rindex[path[depth - 1]] = rindex[node]
                path_root[depth - 1] = False
    return n - 1 - component


# Reachability --------------------------------------------------------------------------

def reachable_from(n: int, source, target, starts, *, compiled: bool = True) -> np.ndarray:
    """Boolean mask of the nodes reachable from any node in ``starts`` (included).

    Examples:
        >>> reachable_from(4, np.array([0, 1]), np.array([1, 2]), [1]).tolist()
        [False, True, True, False]
    """
    return reachable(*csr(n, source, target, compiled=compiled), starts, compiled=compiled)


def reachable(offsets: np.ndarray, neighbours: np.ndarray, starts, *,
              compiled: bool = True) -> np.ndarray:
    """:func:`reachable_from` on a graph in compressed-row form (see :func:`csr`)."""
    n = len(offsets) - 1
    seen = np.zeros(n, dtype=bool)
    starts = _distinct(starts)
    if not starts.size:
        return seen
    if starts[0] < 0 or starts[-1] >= n:
        raise ValueError(f"start nodes must be 0 .. {n - 1}")
    loops = _compiled(max(len(neighbours), n)) if compiled else None
    if loops is not None:
        parent = np.full(n, -2, dtype=np.int64)      # the search of shortest_path, no goal
        loops["parents"](offsets, neighbours, starts, seen, np.ones(n, dtype=bool), parent,
                         np.empty(n, dtype=np.int64))
        return parent != -2
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


def _distinct(nodes) -> np.ndarray:
    """``nodes`` sorted without repeats (as they come when already so: ``flatnonzero``)."""
    nodes = np.asarray(nodes, dtype=np.int64)
    if nodes.size < 2 or bool(np.all(nodes[1:] > nodes[:-1])):
        return nodes
    return np.unique(nodes)


def shortest_path(offsets: np.ndarray, neighbours: np.ndarray, starts, goal: np.ndarray,
                  allowed: np.ndarray | None = None, *, compiled: bool = True) -> list[int] | None:
    """Edge ids (positions in ``neighbours``) of a shortest path from a node of
    ``starts`` to a ``goal`` node whose inner nodes are all ``allowed`` (the goal itself
    need not be), or ``None``; a start in ``goal`` gives ``[]``.

    Examples:
        >>> offsets, neighbours = csr(4, np.array([0, 1, 2, 0]), np.array([1, 2, 3, 3]))
        >>> goal = np.array([False, False, False, True])
        >>> shortest_path(offsets, neighbours, [0], goal)
        [1]
        >>> shortest_path(offsets, neighbours, [0], goal, np.array([True, True, True, False]), compiled=False)
        [1]
    """
    n = len(offsets) - 1
    starts = _distinct(starts)
    allowed = np.ones(n, dtype=bool) if allowed is None else np.asarray(allowed, dtype=bool)
    parent = np.full(n, -2, dtype=np.int64)
    loops = _compiled(max(len(neighbours), n)) if compiled else None
    search = loops["parents"] if loops is not None else _parents_loop
    found = int(search(offsets, neighbours, starts, np.asarray(goal, dtype=bool), allowed, parent,
                       np.empty(n, dtype=np.int64)))
    if found < 0:
        return None
    edges = []
    node = found
    while parent[node] >= 0:
        edge = int(parent[node])
        edges.append(edge)
        node = int(np.searchsorted(offsets, edge, side="right") - 1)
    return edges[::-1]


def _parents_loop(offsets, neighbours, starts, goal, allowed, parent, queue):
    """Breadth first from ``starts`` through ``allowed`` nodes: ``parent[v]`` the edge
    that reached ``v`` (-1: a start, -2: not reached); return the first ``goal`` node
    taken from the queue, or -1."""
    tail = 0
    for s in starts:
        parent[s] = -1
        queue[tail] = s
        tail += 1
    head = 0
    while head < tail:
        node = queue[head]
        head += 1
        if goal[node]:
            return node
        if not allowed[node]:
            continue
        for edge in range(offsets[node], offsets[node + 1]):
            nxt = neighbours[edge]
            if parent[nxt] == -2:
                parent[nxt] = edge
                queue[tail] = nxt
                tail += 1
    return -1


def can_reach(n: int, source, target, goals, *, compiled: bool = True) -> np.ndarray:
    """Boolean mask of the nodes from which some node in ``goals`` is reachable.

    Examples:
        >>> can_reach(4, np.array([0, 1]), np.array([1, 2]), [2]).tolist()
        [True, True, True, False]
    """
    return reachable_from(n, target, source, goals, compiled=compiled)


def reaching(offsets: np.ndarray, neighbours: np.ndarray, goals, *,
             compiled: bool = True) -> np.ndarray:
    """:func:`can_reach` on a graph in compressed-row form (see :func:`csr`)."""
    return reachable(*transpose(offsets, neighbours, compiled=compiled), goals,
                     compiled=compiled)


# Per-component summaries ---------------------------------------------------------------

def terminal_summary(source, target, labels: np.ndarray, edge_label, n_labels: int,
                     *, compiled: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(terminal, first, present)`` for the components no edge leaves.

    ``terminal``: their labels, increasing; ``first``: the smallest node of each;
    ``present``: a ``len(terminal) x n_labels`` boolean array, ``present[i, x]`` when an
    edge inside ``terminal[i]`` carries ``edge_label`` ``x``. ``labels`` numbers the
    components 0 .. k-1, as :func:`strong_components` does.

    Examples:
        >>> labels = strong_components(3, np.array([0, 1, 2]), np.array([1, 2, 1]))
        >>> terminal, first, present = terminal_summary(
        ...     np.array([0, 1, 2]), np.array([1, 2, 1]), labels, np.array([0, 1, 2]), 3)
        >>> first.tolist(), present.tolist()
        ([1], [[False, True, True]])
    """
    offsets, (neighbours, edge_label) = _group(len(labels), source, target, edge_label,
                                               compiled=compiled)
    return terminal_summary_csr(offsets, neighbours, labels, edge_label, n_labels,
                                compiled=compiled)


def terminal_summary_csr(offsets: np.ndarray, neighbours: np.ndarray, labels: np.ndarray,
                         edge_label, n_labels: int, *, compiled: bool = True
                         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`terminal_summary` on a graph in compressed-row form (see :func:`csr`),
    ``edge_label`` in the same edge order as ``neighbours``."""
    neighbours, edge_label = _ids(neighbours), _ids(edge_label)
    labels = np.asarray(labels, dtype=np.int64)
    components = int(labels.max(initial=-1)) + 1
    loops = _compiled(len(neighbours)) if compiled else None
    if loops is None:
        return _terminal_summary(offsets, neighbours, labels, edge_label, n_labels,
                                 components)
    if labels.size and labels.min() < 0:
        raise ValueError("component labels must be 0 .. k-1")
    row = np.zeros(components, dtype=np.int64)
    terminal = np.zeros(components, dtype=np.int64)
    if components == 1:          # a strongly connected graph: no edge can leave it
        rows = 1
    else:
        rows = loops["exits"](offsets, neighbours, labels, row, terminal)
    first = np.empty(max(rows, 0), dtype=np.int64)
    present = np.zeros((max(rows, 0), n_labels), dtype=bool)
    if rows < 0 or not loops["presence"](offsets, labels, edge_label, row, first, present):
        raise ValueError(f"edges must join nodes 0 .. {len(labels) - 1} and carry labels"
                         f" 0 .. {n_labels - 1}")
    return terminal[:rows].copy(), first, present


def _terminal_summary(offsets, neighbours, labels, edge_label, n_labels, components):
    """:func:`terminal_summary_csr` with numpy (small graphs, no numba)."""
    if edge_label.size and not 0 <= edge_label.min() <= edge_label.max() < n_labels:
        raise ValueError(f"edge labels must be 0 .. {n_labels - 1}")
    source = np.repeat(np.arange(len(labels)), np.diff(offsets))
    from_label = labels[source]
    leaving = from_label != labels[neighbours]
    exits = np.zeros(components, dtype=bool)
    exits[from_label[leaving]] = True
    terminal = np.flatnonzero(~exits)
    row = np.full(components, -1, dtype=np.int64)
    row[terminal] = np.arange(terminal.size)
    first = np.full(components, len(labels), dtype=np.int64)
    np.minimum.at(first, labels, np.arange(len(labels)))
    present = np.zeros((terminal.size, n_labels), dtype=bool)
    inside = row[from_label]
    keep = inside >= 0
    present[inside[keep], edge_label[keep]] = True
    return terminal, first[terminal], present


def _exits_loop(offsets, neighbours, labels, row, terminal):
    """Number the components no edge leaves: ``row[c]`` is c's rank among them (-1 for
    the others) and ``terminal`` starts with their labels; return how many there are
    (-1 when an edge end is not a node)."""
    n = labels.shape[0]
    leaves = np.zeros(row.shape[0], dtype=np.bool_)
    for u in range(n):
        c = labels[u]
        for e in range(offsets[u], offsets[u + 1]):
            v = neighbours[e]
            if v < 0 or v >= n:
                return -1
            if c != labels[v]:
                leaves[c] = True
    rows = 0
    for c in range(row.shape[0]):
        row[c] = -1
        if not leaves[c]:
            row[c] = rows
            terminal[rows] = c
            rows += 1
    return rows


def _presence_loop(offsets, labels, edge_label, row, first, present):
    """Fill ``first`` (smallest node) and ``present`` (edge labels inside) per terminal
    component, ``row`` giving each component's row (-1: not terminal); return False
    when an edge label is out of range."""
    first[:] = -1
    size = present.shape[1]
    for u in range(labels.shape[0]):
        r = row[labels[u]]
        if r < 0:
            continue
        if first[r] == -1:
            first[r] = u
        for e in range(offsets[u], offsets[u + 1]):
            x = edge_label[e]
            if x < 0 or x >= size:
                return False
            present[r, x] = True
    return True


# Occurrences ---------------------------------------------------------------------------

def occurring(values, size: int, *, compiled: bool = True) -> np.ndarray:
    """Boolean mask of length ``size``: which of 0 .. size-1 occur in ``values``.

    Examples:
        >>> occurring(np.array([3, 0, 3], dtype=np.int16), 5).tolist()
        [True, False, False, True, False]
    """
    values = _ids(values)
    loops = _compiled(len(values)) if compiled else None
    seen = np.zeros(size, dtype=bool)
    if loops is None:
        if values.size and not 0 <= values.min() <= values.max() < size:
            raise ValueError(f"values must be 0 .. {size - 1}")
        seen[values] = True
    elif not loops["occurring"](values, seen):
        raise ValueError(f"values must be 0 .. {size - 1}")
    return seen


def _occurring_loop(values, seen):
    """Mark in ``seen`` the values that occur; False when one is out of range."""
    size = seen.shape[0]
    for e in range(values.shape[0]):
        x = values[e]
        if x < 0 or x >= size:
            return False
        seen[x] = True
    return True


_LOOP_FUNCTIONS = {
    "offsets": _offsets_loop,
    "scatter": _scatter_loop,
    "pearce": _pearce_loop,
    "parents": _parents_loop,
    "transpose": _transpose_loop,
    "exits": _exits_loop,
    "presence": _presence_loop,
    "occurring": _occurring_loop,
}
