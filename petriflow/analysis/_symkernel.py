"""The compiled loop of the symmetry-reduced exploration (private).

One breadth-first search over canonical markings: a marking is a row of ``uint8``
counts; its canonical form sorts, for each group of interchangeable agents, the agents'
blocks of places lexicographically (insertion sort: a successor differs from its sorted
parent in one or two blocks, so the sort is close to linear). States live in an
open-addressing hash table keyed by a 64-bit FNV-1a hash of the whole row, confirmed
on the row. The loop returns to Python when a buffer is full (status 1, Python grows
it and calls again), when the table is half full (3, Python rehashes), when the state
limit is reached (2), or when a count would exceed 255 (4: the caller falls back).

Compiled by numba (cached on disk); the same code runs as plain Python without it.
"""

from __future__ import annotations

import numpy as np

from petriflow.analysis._numba import njit

_jit = njit(__name__)

__all__ = ["canonicalise", "explore", "rehash", "row_hash"]

OK, GROW, LIMIT, REHASH, OVERFLOW = 0, 1, 2, 3, 4

_FNV_OFFSET = np.uint64(14695981039346656037)
_FNV_PRIME = np.uint64(1099511628211)


@_jit
def row_hash(row):
    h = np.uint64(14695981039346656037)
    for x in row:
        h = (h ^ np.uint64(x)) * np.uint64(1099511628211)
    h ^= h >> np.uint64(29)
    return h


@_jit
def _less(row, a, b, width):
    """Whether block ``a`` (its first place indices ``a``) sorts before block ``b``."""
    for j in range(width):
        x = row[a[j]]
        y = row[b[j]]
        if x != y:
            return x < y
    return False


@_jit
def canonicalise(row, group_k, group_b, group_off, blocks, scratch):
    """Sort each group's blocks of ``row`` in place (lexicographic, ascending).

    ``blocks[group_off[g] + a * group_b[g] + j]`` is the place index of local place
    ``j`` of agent ``a`` of group ``g``; ``scratch`` holds at least one group's places.
    """
    for g in range(group_k.shape[0]):
        k = group_k[g]
        b = group_b[g]
        off = group_off[g]
        # copy out the block values, insertion-sort them as rows, write them back
        for a in range(k):
            for j in range(b):
                scratch[a * b + j] = row[blocks[off + a * b + j]]
        for a in range(1, k):
            i = a
            while i > 0:
                smaller = False
                for j in range(b):
                    x = scratch[i * b + j]
                    y = scratch[(i - 1) * b + j]
                    if x != y:
                        smaller = x < y
                        break
                if not smaller:
                    break
                for j in range(b):
                    t = scratch[i * b + j]
                    scratch[i * b + j] = scratch[(i - 1) * b + j]
                    scratch[(i - 1) * b + j] = t
                i -= 1
        for a in range(k):
            for j in range(b):
                row[blocks[off + a * b + j]] = scratch[a * b + j]


@_jit
def _find(rows, hashes, table, row, h, n_cols):
    mask = np.uint64(table.shape[0] - 1)
    slot = h & mask
    while True:
        s = table[slot]
        if s == 0:
            return -1, slot
        s -= 1
        if hashes[s] == h:
            same = True
            for c in range(n_cols):
                if rows[s, c] != row[c]:
                    same = False
                    break
            if same:
                return s, slot
        slot = (slot + np.uint64(1)) & mask


@_jit
def rehash(hashes, n, table):
    """Insert states ``0..n-1`` into the empty ``table`` by their hashes."""
    mask = np.uint64(table.shape[0] - 1)
    for s in range(n):
        slot = hashes[s] & mask
        while table[slot] != 0:
            slot = (slot + np.uint64(1)) & mask
        table[slot] = s + 1


@_jit
def _room(n, ne, n_rows, rows, edge_target, table, max_states):
    """What sends the loop back to Python before the next state (buffers that one more
    state's successors could overflow, a half-full table, the limit), else ``OK``."""
    if n + n_rows > rows.shape[0] or ne + n_rows > edge_target.shape[0]:
        return GROW
    if 2 * (n + n_rows) > table.shape[0]:
        return REHASH
    if n > max_states:
        return LIMIT
    return OK


@_jit
def _run_arrays(group_k):
    """The arrays :func:`_runs` fills (a row per group, a column per agent)."""
    max_k = 1
    for g in range(group_k.shape[0]):
        max_k = max(max_k, group_k[g])
    rows = max(1, group_k.shape[0])
    return np.zeros((rows, max_k), dtype=np.int64), np.ones((rows, max_k), dtype=np.int64)


@_jit
def _runs(state, run, run_len, group_k, group_b, group_off, blocks):
    """Runs of equal blocks of a canonical marking: ``run[g, a]`` the first agent of
    agent ``a``'s run in group ``g``, ``run_len[g, a]`` the run's length."""
    for g in range(group_k.shape[0]):
        b = group_b[g]
        off = group_off[g]
        k = group_k[g]
        run[g, 0] = 0
        for a in range(1, k):
            same = True
            for j in range(b):
                if state[blocks[off + a * b + j]] != state[blocks[off + (a - 1) * b + j]]:
                    same = False
                    break
            run[g, a] = run[g, a - 1] if same else a
        a = k - 1
        while a >= 0:
            first = run[g, a]
            for x in range(first, a + 1):
                run_len[g, x] = a + 1 - first
            a = first - 1


@_jit
def _multiplicity(t, run, run_len, named_g, named_a, named_n):
    """0 when row ``t`` is not the representative of its orbit under the marking's
    stabiliser (each agent it names, in order, the lowest of its run not named before
    it), else the number of rows of that orbit (all enabled or none)."""
    size = 1
    for k in range(named_n[t]):
        g = named_g[t, k]
        a = named_a[t, k]
        start = run[g, a]
        before = 0
        for q in range(k):
            if named_g[t, q] == g and run[g, named_a[t, q]] == start:
                before += 1
        if a != start + before:
            return 0
        size *= run_len[g, a] - before
    return size


@_jit
def _enabled(state, t, pre_p, pre_w, pre_n):
    for k in range(pre_n[t]):
        if state[pre_p[t, k]] < pre_w[t, k]:
            return False
    return True


@_jit
def _representatives(state, pre_p, pre_w, pre_n, run, run_len, named_g, named_a, named_n,
                     moves, reps, seen_enabled):
    """The enabled rows of ``state`` that represent their orbit under its stabiliser:
    those with ``moves`` go to ``reps``, every one is marked in ``seen_enabled``.
    Returns how many went to ``reps`` and how many rows their orbits hold."""
    n_reps = 0
    count = 0
    for t in range(pre_n.shape[0]):
        if not _enabled(state, t, pre_p, pre_w, pre_n):
            continue
        size = _multiplicity(t, run, run_len, named_g, named_a, named_n)
        if size == 0:
            continue
        seen_enabled[t] = True
        if moves[t]:
            reps[n_reps] = t
            n_reps += 1
            count += size
    return n_reps, count


@_jit
def _successor(rows, hashes, table, parent, parent_row, seen_by, edge_target, edge_row,
               row, scratch, head, t, n, ne, pre_p, pre_w, pre_n, post_p, post_w, post_n,
               reset_p, reset_n, group_k, group_b, group_off, blocks):
    """Fire ``t`` in state ``head``, store the canonical successor if new and the edge
    if not yet there. Returns ``(n, ne, overflow)``."""
    n_cols = rows.shape[1]
    for c in range(n_cols):
        row[c] = rows[head, c]
    for k in range(pre_n[t]):
        row[pre_p[t, k]] -= pre_w[t, k]
    for k in range(reset_n[t]):
        row[reset_p[t, k]] = 0
    for k in range(post_n[t]):
        value = np.int64(row[post_p[t, k]]) + post_w[t, k]
        if value > 255:
            return n, ne, True
        row[post_p[t, k]] = value
    canonicalise(row, group_k, group_b, group_off, blocks, scratch)
    h = row_hash(row)
    found, slot = _find(rows, hashes, table, row, h, n_cols)
    if found < 0:
        found = n
        for c in range(n_cols):
            rows[n, c] = row[c]
        hashes[n] = h
        table[slot] = n + 1
        parent[n] = head
        parent_row[n] = t
        seen_by[n] = -1
        n += 1
    if seen_by[found] != head:
        seen_by[found] = head
        edge_target[ne] = found
        edge_row[ne] = t
        ne += 1
    return n, ne, False


@_jit
def _closure(state, seed, pre_p, pre_w, pre_n, inside, mark, stack,
             conf_ptr, conf_idx, inc_ptr, inc_idx, limit, work_cap, members):
    """The D1/D2 closure of ``seed`` in the marking ``state``: its enabled members go to
    ``members``; returns how many (-1 once that reaches ``limit`` or the work, relations
    followed, exceeds ``work_cap``) and the work done. ``inside[u] == mark`` marks the
    set."""
    inside[seed] = mark
    stack[0] = seed
    top = 1
    n_in = 0
    work = 0
    while top > 0:
        top -= 1
        t = stack[top]
        if _enabled(state, t, pre_p, pre_w, pre_n):
            members[n_in] = t
            n_in += 1
            if n_in >= limit:
                return -1, work
            lo = conf_ptr[t]
            hi = conf_ptr[t + 1]
            work += hi - lo
            for i in range(lo, hi):
                u = conf_idx[i]
                if inside[u] != mark:
                    inside[u] = mark
                    stack[top] = u
                    top += 1
        else:
            # D2: one input place short of tokens (its scapegoat), the one with the
            # fewest producers outside the set; all its producers join
            best_p = -1
            best_c = 1 << 62
            for k in range(pre_n[t]):
                p = pre_p[t, k]
                if state[p] < pre_w[t, k]:
                    c = 0
                    for i in range(inc_ptr[p], inc_ptr[p + 1]):
                        if inside[inc_idx[i]] != mark:
                            c += 1
                    work += inc_ptr[p + 1] - inc_ptr[p]
                    if c < best_c:
                        best_c = c
                        best_p = p
                        if c == 0:
                            break
            for i in range(inc_ptr[best_p], inc_ptr[best_p + 1]):
                u = inc_idx[i]
                if inside[u] != mark:
                    inside[u] = mark
                    stack[top] = u
                    top += 1
        if work > work_cap:
            return -1, work
    return n_in, work


@_jit
def explore(rows, hashes, table, counters, offsets, edge_target, edge_row, parent, parent_row,
            enabled_count, seen_by, fired, seen_enabled,
            pre_p, pre_w, pre_n, post_p, post_w, post_n, reset_p, reset_n,
            group_k, group_b, group_off, blocks, named_g, named_a, named_n,
            moves, conf_ptr, conf_idx, inc_ptr, inc_idx, seed_rank, n_seeds, work_cap,
            max_states):
    """Expand states ``counters[1]`` .. while any are left; ``counters`` = ``[states,
    next state to expand, edges]`` is updated in place. Returns a status code.

    In a canonical marking agents with equal blocks are interchangeable (its
    stabiliser), so of each orbit of rows under it only the representative
    (:func:`_multiplicity`) is tested and fired, and counted as many times as its orbit
    has rows. Only rows with ``moves`` count (``enabled_count``: how many of them each
    marking of the orbit enables) and are fired; ``seen_enabled`` marks a row of every
    orbit of rows enabled in some explored marking. Each distinct successor is one edge
    (``seen_by`` deduplicates); ``fired`` marks the rows fired.

    With ``n_seeds`` > 0 (stubborn sets, nets without reset arcs), up to ``n_seeds``
    enabled representatives (lowest ``seed_rank`` first) are tried as seeds of a D1/D2
    closure (``conf_*``: the rows that can disable a row or be disabled by it;
    ``inc_*``: per place, the rows that raise its count), all of them within
    ``work_cap`` relations followed; the smallest is fired, every member of it. With no
    closure smaller than all enabled rows (or no seeds), the representatives are fired."""
    n_rows = pre_n.shape[0]
    row = np.empty(rows.shape[1], dtype=np.uint8)
    scratch = np.empty(max(1, blocks.shape[0]), dtype=np.uint8)
    run, run_len = _run_arrays(group_k)
    reps = np.empty(n_rows + 1, dtype=np.int64)
    inside = np.full(n_rows, -1, dtype=np.int64)
    stack = np.empty(n_rows + 1, dtype=np.int64)
    members = np.empty(n_rows + 1, dtype=np.int64)
    chosen = np.empty(n_rows + 1, dtype=np.int64)
    mark = 0
    n = counters[0]
    head = counters[1]
    ne = counters[2]
    while head < n:
        status = _room(n, ne, n_rows, rows, edge_target, table, max_states)
        if status != OK:
            counters[0], counters[1], counters[2] = n, head, ne
            return status
        offsets[head] = ne
        state = rows[head]
        _runs(state, run, run_len, group_k, group_b, group_off, blocks)
        n_reps, n_en = _representatives(state, pre_p, pre_w, pre_n, run, run_len, named_g,
                                        named_a, named_n, moves, reps, seen_enabled)
        enabled_count[head] = n_en
        n_chosen = 0
        if n_seeds > 0 and n_en > 0:
            # seeds: the representatives (a closure from another row of the orbit is its
            # image), fewest relations first
            for j in range(1, n_reps):
                t = reps[j]
                i = j
                while i > 0 and seed_rank[reps[i - 1]] > seed_rank[t]:
                    reps[i] = reps[i - 1]
                    i -= 1
                reps[i] = t
            budget = work_cap
            for i in range(min(n_reps, n_seeds)):
                mark += 1
                limit = n_en if n_chosen == 0 else n_chosen
                got, work = _closure(state, reps[i], pre_p, pre_w, pre_n, inside, mark, stack,
                                     conf_ptr, conf_idx, inc_ptr, inc_idx, limit, budget,
                                     members)
                budget -= work
                if got > 0:
                    n_chosen = got
                    for j in range(got):
                        chosen[j] = members[j]
                    if got == 1:
                        break
                if budget <= 0:
                    break
        if n_chosen == 0:
            # every enabled row is stubborn: the representatives
            for j in range(n_reps):
                chosen[j] = reps[j]
            n_chosen = n_reps
        for j in range(n_chosen):
            t = chosen[j]
            fired[t] = True
            n, ne, overflow = _successor(rows, hashes, table, parent, parent_row, seen_by,
                                         edge_target, edge_row, row, scratch, head, t, n, ne,
                                         pre_p, pre_w, pre_n, post_p, post_w, post_n,
                                         reset_p, reset_n, group_k, group_b, group_off, blocks)
            if overflow:
                counters[0], counters[1], counters[2] = n, head, ne
                return OVERFLOW
        head += 1
        offsets[head] = ne
    counters[0], counters[1], counters[2] = n, head, ne
    if n > max_states:
        return LIMIT
    return OK
