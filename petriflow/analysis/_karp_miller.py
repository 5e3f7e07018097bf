"""The compiled Karp–Miller search behind :func:`petriflow.analysis.coverability.coverability_search`.

Depth first, so that a pump behind a long firing sequence is found without first
enumerating every marking closer to the start (a breadth-first search drowns in a
large bounded part first). Nodes are ω-markings, rows of ``int64`` counts with
:data:`OMEGA` for ω; equal ω-markings are one node (a coverability graph), found again
through an open-addressing hash table of ``(hash, id + 1)`` slots as in
:mod:`petriflow.analysis._kernel`.

Acceleration: a new ω-marking is compared with its ancestors on the search path (the
depth-first stack) that have the same ω places (the path's current *segment*: ω places
only ever grow along a path). If it strictly covers one, the places where it is larger
become ω. Only ancestors whose token total (ω places left out) is smaller can be
strictly covered, and each node keeps the smallest total of its segment up to it, so
the walk stops as soon as no such ancestor is left above. Comparing with the current
segment only is still sound (every ω comes from a real pump) and still terminates: an
infinite path would stay in one segment from some point on, and by Dickson's lemma two
of its markings there would be comparable, which accelerates.
"""

from __future__ import annotations

import numpy as np

from petriflow.analysis._kernel import mix
from petriflow.analysis._numba import njit

__all__ = ["OK", "LIMIT", "FULL", "OVERFLOW", "OMEGA", "search"]

_jit = njit(__name__)

#: Status codes (as in :mod:`petriflow.analysis._kernel`).
OK, LIMIT, OVERFLOW, FULL = 0, 1, 3, 5
#: ω in a row: larger than every count the search keeps (counts beyond 2**61 stop it).
OMEGA = np.int64(2**62)
_TOP = np.int64(2**61)
_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_ONE = np.uint64(1)


@_jit
def _hash_row(row):
    h = _GOLDEN
    for p in range(row.shape[0]):
        h = (h ^ np.uint64(row[p])) * _M1
    return mix(h)


@_jit
def search(pre_at, pre_place, pre_weight, change_at, change_place, change_delta, max_nodes,
           rows, parent, parent_t, totals, seg_root, seg_min, table, stack, stack_next,
           fired, counters):
    """Depth-first Karp–Miller search, resumable after :data:`FULL`.

    Args:
        pre_at, pre_place, pre_weight, change_at, change_place, change_delta: presets
            and net changes in compressed-row form (as for ``expand_counts``).
        max_nodes: stop with :data:`LIMIT` rather than store more nodes.
        rows: node ω-markings (row 0 is the start, set by the caller).
        parent, parent_t: per node the node and transition of its first discovery.
        totals, seg_root, seg_min: per node its token total (ω left out), the first
            node of its segment, the smallest total from there to it.
        table: the hash table, at most half full.
        stack, stack_next: the search path and, per level, how many transitions have
            been tried (node ``n`` tries them from a pseudo-random one on, cyclically).
        fired: per transition, 1 once it fired from some node.
        counters: ``[nodes, edges, depth, first covering node, its ancestor, its
            transition]``; the last three are -1 until the first acceleration, which
            happens on an ω-free path: a plain firing sequence proves it.

    Returns:
        :data:`OK` (the graph is complete), :data:`LIMIT`, :data:`OVERFLOW` (a count
        passed 2**61) or :data:`FULL` (grow ``rows`` and the per-node arrays, or the
        table, and call again).
    """
    n_t = pre_at.shape[0] - 1
    n_p = rows.shape[1]
    mask = np.uint64(table.shape[0] // 2 - 1)
    successor = np.empty(n_p, dtype=np.int64)
    nodes, edges, depth = counters[0], counters[1], counters[2]
    if nodes == 0:
        h = _hash_row(rows[0])
        table[2 * (h & mask)] = h
        table[2 * (h & mask) + 1] = _ONE
        total = np.int64(0)
        for p in range(n_p):
            if rows[0, p] != OMEGA:
                total += rows[0, p]
        parent[0] = -1
        parent_t[0] = -1
        totals[0] = total
        seg_root[0] = 0
        seg_min[0] = total
        stack[0] = 0
        stack_next[0] = 0
        nodes, depth = 1, 1
    status = OK
    while depth > 0:
        if nodes >= rows.shape[0] or 2 * (nodes + 1) > table.shape[0] // 2:
            status = FULL
            break
        node = stack[depth - 1]
        tried = stack_next[depth - 1]
        if tried >= n_t:
            depth -= 1
            continue
        stack_next[depth - 1] = tried + 1
        # Each node tries the transitions from its own pseudo-random first one on, so
        # the search goes deep in varied directions instead of always taking the same
        # transitions first (which can circle in one bounded part for ever).
        t = np.int64((mix(np.uint64(node) + _GOLDEN) + np.uint64(tried)) % np.uint64(n_t))
        enabled = True
        for a in range(pre_at[t], pre_at[t + 1]):
            if rows[node, pre_place[a]] < pre_weight[a]:
                enabled = False
                break
        if not enabled:
            continue
        fired[t] = 1
        for p in range(n_p):
            successor[p] = rows[node, p]
        for a in range(change_at[t], change_at[t + 1]):
            p = change_place[a]
            if successor[p] != OMEGA:
                successor[p] += change_delta[a]
                if successor[p] > _TOP:
                    status = OVERFLOW
        if status != OK:
            break
        total = np.int64(0)
        for p in range(n_p):
            if successor[p] != OMEGA:
                total += successor[p]
        # Acceleration against the ancestors of this segment with a smaller total.
        accelerated = False
        ancestor = node
        root = seg_root[node]
        while seg_min[ancestor] < total:
            if totals[ancestor] < total:
                covers = True
                for p in range(n_p):
                    if successor[p] < rows[ancestor, p]:
                        covers = False
                        break
                if covers:
                    if counters[3] < 0:
                        counters[3], counters[4], counters[5] = node, ancestor, t
                    for p in range(n_p):
                        if successor[p] > rows[ancestor, p]:
                            successor[p] = OMEGA
                    accelerated = True
                    break
            if ancestor == root:
                break
            ancestor = parent[ancestor]
        if accelerated:
            total = np.int64(0)
            for p in range(n_p):
                if successor[p] != OMEGA:
                    total += successor[p]
        h = _hash_row(successor)
        i = h & mask
        target = -1
        while table[2 * i + 1] != 0:
            if table[2 * i] == h:
                candidate = np.int64(table[2 * i + 1]) - 1
                same = True
                for p in range(n_p):
                    if rows[candidate, p] != successor[p]:
                        same = False
                        break
                if same:
                    target = candidate
                    break
            i = (i + _ONE) & mask
        edges += 1
        if target >= 0:
            continue
        if nodes >= max_nodes:
            status = LIMIT
            edges -= 1
            stack_next[depth - 1] = tried  # resumable: this firing is tried again
            break
        target = nodes
        nodes += 1
        for p in range(n_p):
            rows[target, p] = successor[p]
        table[2 * i] = h
        table[2 * i + 1] = np.uint64(target + 1)
        parent[target] = node
        parent_t[target] = t
        totals[target] = total
        if accelerated:
            seg_root[target] = target
            seg_min[target] = total
        else:
            seg_root[target] = root
            seg_min[target] = min(seg_min[node], total)
        stack[depth] = target
        stack_next[depth] = 0
        depth += 1
    counters[0], counters[1], counters[2] = nodes, edges, depth
    return status
