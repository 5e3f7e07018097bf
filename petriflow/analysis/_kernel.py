"""Compiled breadth-first exploration loops behind :mod:`petriflow.analysis.reachability`.

Two loops, compiled by numba (once, then cached on disk; plain Python where numba is
missing, with the same results, a few hundred times slower):

* :func:`expand_bits` for safe markings: a marking is a row of ``uint64`` words, one
  bit a place; a transition is enabled when its preset bits are all set
  (``m & pre == pre``, tested without branches) and its successor is
  ``(m & keep) | post`` (``keep`` clears the preset and the reset places). It stops
  with :data:`NOT_SAFE` as soon as a firing would put a second token in a place.
* :func:`expand_counts` for every other net: a marking is a row of small unsigned
  counts; it stops with :data:`OVERFLOW` when a count would not fit the row's dtype
  (the caller widens it and starts again) and with :data:`UNBOUNDED` when a new state
  strictly covers one of its breadth-first-tree ancestors (with reset arcs, in a place
  no firing between them resets).

Both number states in discovery order, expand them in that order and transitions in
index order, so a state's parent edge is its first discovery: the BFS tree gives
shortest firing sequences. Visited states live in an open-addressing hash table
(linear probing, power-of-two size, at most half full). Only the first ``key`` columns
of a row tell states apart: the caller puts first the places that determine a
reachable marking. A slot is a ``(hash, state id + 1)`` pair, the row read back to
confirm a hash match, except on safe nets whose key fits in one word beside the state
id: then a slot is the one word ``key << id_bits | (id + 1)`` and nothing else is read.
The safe loop first computes all successors of a state and prefetches their slots,
then probes them, so the cache misses of one state overlap.

The caller owns every array (numpy arrays, large ones on reserved mappings) and
grows them: a loop stops with :data:`FULL` before a state whose successors might not
fit, and the caller doubles what is short and calls again. A loop never reassigns an
array, which keeps numba's reference counting out of it.
"""

from __future__ import annotations

import numpy as np

try:
    import numba
    from llvmlite import ir
    from numba.extending import intrinsic

    # numba's on-disk cache is keyed by source file but re-imports the module by name
    # when it loads; only the installed name caches (see agents/planning/astar.py).
    _cache = __name__ == "petriflow.analysis._kernel"
    _jit = numba.njit(cache=_cache, nogil=True)
    # Bodies compiled into each caller (specialised there on its constant arguments).
    _inline = numba.njit(cache=_cache, nogil=True, inline="always")
    COMPILED = not numba.config.DISABLE_JIT

    @intrinsic
    def _prefetch(typingctx, address):
        """Hint the CPU to load the cache line at ``address`` (LLVM's llvm.prefetch)."""
        if not isinstance(address, numba.types.Integer):
            return None

        def codegen(context, builder, signature, args):
            i32, i8p = ir.IntType(32), ir.IntType(8).as_pointer()
            function = builder.module.declare_intrinsic(
                "llvm.prefetch", (i8p,), ir.FunctionType(ir.VoidType(), [i8p, i32, i32, i32]))
            # read, high temporal locality, data cache
            builder.call(function, [builder.inttoptr(args[0], i8p), ir.Constant(i32, 0),
                                    ir.Constant(i32, 3), ir.Constant(i32, 1)])
            return context.get_dummy_value()

        return numba.types.void(address), codegen

    if COMPILED:
        prefetch = _prefetch
    else:                      # NUMBA_DISABLE_JIT=1: the loops run as Python
        def prefetch(address):
            """No-op when the loops run as plain Python."""

except ImportError:  # pragma: no cover - exercised only where numba is missing
    def _jit(function):
        return function

    _inline = _jit

    def prefetch(address):
        """No-op without numba."""

    COMPILED = False

__all__ = ["OK", "LIMIT", "NOT_SAFE", "OVERFLOW", "UNBOUNDED", "FULL", "COMPILED",
           "expand_bits", "expand_counts", "rehash", "prefetch", "mix"]

#: Status codes returned as the first element of a kernel's result.
OK, LIMIT, NOT_SAFE, OVERFLOW, UNBOUNDED = 0, 1, 2, 3, 4
#: The buffers need to grow before the next state is expanded (call again after).
FULL = 5

_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_S27, _S30, _S31 = np.uint64(27), np.uint64(30), np.uint64(31)
_ONE = np.uint64(1)


@_jit
def mix(x):
    """splitmix64's finaliser: a bijection of uint64 that spreads every input bit."""
    x = x ^ (x >> _S30)
    x = x * _M1
    x = x ^ (x >> _S27)
    x = x * _M2
    return x ^ (x >> _S31)


@_jit
def rehash(table, stride, id_bits, bigger):
    """Move the entries of ``table`` into the empty, larger table ``bigger``.

    ``stride`` 2: slots are ``(hash, id + 1)`` pairs. ``stride`` 1: slots are
    ``key << id_bits | (id + 1)``, placed by the hash of the key. Both tables have a
    power-of-two number of slots; a hash ``h`` is first probed at ``h & (slots - 1)``.
    """
    mask = np.uint64(bigger.shape[0] // stride - 1)
    for slot in range(table.shape[0] // stride):
        entry = table[stride * slot + stride - 1]
        if entry == 0:
            continue
        h = table[2 * slot] if stride == 2 else mix(entry >> np.uint64(id_bits))
        i = h & mask
        while bigger[stride * i + stride - 1] != 0:
            i = (i + _ONE) & mask
        if stride == 2:
            bigger[2 * i] = h
            bigger[2 * i + 1] = entry
        else:
            bigger[i] = entry


@_jit
def _hash_bits(row, key_mask):
    h = _GOLDEN
    for w in range(row.shape[0]):
        h = mix(h ^ (row[w] & key_mask[w]))
    return h


def expand_bits(pre, post, keep, kind, key_mask, id_bits, max_states, rows, parent,
                parent_t, first_edge, table, e_transition, e_target, counters):
    """Breadth-first search over safe markings held as rows of ``uint64`` words.

    Args:
        pre, post, keep: ``T x W`` words per transition: preset, postset, and the bits
            that survive firing (neither consumed nor reset).
        kind: per transition 0 (ordinary), 1 (never enabled in a safe marking: an input
            arc of weight >= 2) or 2 (firing it makes the marking unsafe: an output arc
            of weight >= 2).
        key_mask: ``W`` words; the bits that tell two states apart.
        id_bits: 0 for a table of ``(hash, id + 1)`` pairs; otherwise the key lies in
            word 0 and is stored as ``key << id_bits | (id + 1)`` (one word a slot).
        max_states: stop with :data:`LIMIT` beyond this many states.
        rows, parent, parent_t: per state its words, BFS parent and parent transition;
            ``rows[0]`` is the initial marking.
        first_edge: per state, the index of its first edge (its edges are consecutive,
            in transition order); written when the state is expanded.
        table: the visited-state hash table (zeros at first), a power-of-two number of
            slots of ``2`` words (or ``1`` with ``id_bits``).
        e_transition, e_target: the edges (their sources are given by ``first_edge``).
        counters: ``[states, edges, expanded]``, all 0 at first; updated in place.

    Returns:
        A status: :data:`OK`, :data:`FULL`, :data:`LIMIT` or :data:`NOT_SAFE`.

    Rows of one and of two words run loops compiled for that width (their word loops
    unrolled); wider rows share one loop.
    """
    n_w = pre.shape[1]
    loop = _expand_bits_1 if n_w == 1 else _expand_bits_2 if n_w == 2 else _expand_bits_n
    return loop(pre, post, keep, kind, key_mask, id_bits, max_states, rows, parent,
                parent_t, first_edge, table, e_transition, e_target, counters)


@_jit
def _expand_bits_1(pre, post, keep, kind, key_mask, id_bits, max_states, rows, parent,
                   parent_t, first_edge, table, e_transition, e_target, counters):
    return _expand_bits(1, pre, post, keep, kind, key_mask, id_bits, max_states, rows,
                        parent, parent_t, first_edge, table, e_transition, e_target, counters)


@_jit
def _expand_bits_2(pre, post, keep, kind, key_mask, id_bits, max_states, rows, parent,
                   parent_t, first_edge, table, e_transition, e_target, counters):
    return _expand_bits(2, pre, post, keep, kind, key_mask, id_bits, max_states, rows,
                        parent, parent_t, first_edge, table, e_transition, e_target, counters)


@_jit
def _expand_bits_n(pre, post, keep, kind, key_mask, id_bits, max_states, rows, parent,
                   parent_t, first_edge, table, e_transition, e_target, counters):
    return _expand_bits(pre.shape[1], pre, post, keep, kind, key_mask, id_bits, max_states,
                        rows, parent, parent_t, first_edge, table, e_transition, e_target,
                        counters)


@_inline
def _expand_bits(n_w, pre, post, keep, kind, key_mask, id_bits, max_states, rows, parent,
                 parent_t, first_edge, table, e_transition, e_target, counters):
    """:func:`expand_bits` for rows of ``n_w`` words."""
    n_t = pre.shape[0]
    stride = 1 if id_bits > 0 else 2
    shift = np.uint64(id_bits)
    one_word = True
    for w in range(1, n_w):
        if key_mask[w] != 0:
            one_word = False
    mask = np.uint64(table.shape[0] // stride - 1)
    states, edges, head = counters[0], counters[1], counters[2]
    if states == 0:
        parent[0] = -1
        parent_t[0] = -1
        key = rows[0, 0] & key_mask[0]
        h = mix(key) if stride == 1 else _hash_bits(rows[0], key_mask)
        if stride == 1:
            table[h & mask] = (key << shift) | _ONE
        else:
            table[2 * (h & mask)] = h
            table[2 * (h & mask) + 1] = _ONE
        states = 1
    status = OK
    base = table.ctypes.data
    fired = np.empty(n_t, dtype=np.int64)
    # The enabledness test runs over transitions for one word at a time (a loop the
    # compiler vectorises): presets transposed, and a never-enabled row always missing.
    pre_t = np.ascontiguousarray(pre.T)
    missing = np.empty(n_t, dtype=np.uint64)
    never = np.zeros(n_t, dtype=np.uint64)
    for t in range(n_t):
        if kind[t] == 1:
            never[t] = ~np.uint64(0)
    where = np.empty(n_t, dtype=np.uint64)
    found = np.empty((n_t, n_w), dtype=np.uint64)
    hashes = np.empty(n_t, dtype=np.uint64)
    current = np.empty(n_w, dtype=np.uint64)
    while head < states:
        if (edges + n_t > e_target.shape[0] or states + n_t > rows.shape[0]
                or 2 * (states + n_t) > table.shape[0] // stride):
            status = FULL
            break
        first_edge[head] = edges
        for w in range(n_w):
            current[w] = rows[head, w]
        # Branch-free enabledness test; the enabled transitions are collected in order.
        for t in range(n_t):
            missing[t] = never[t] | ((current[0] & pre_t[0, t]) ^ pre_t[0, t])
        for w in range(1, n_w):
            word = current[w]
            for t in range(n_t):
                missing[t] |= (word & pre_t[w, t]) ^ pre_t[w, t]
        count = 0
        for t in range(n_t):
            fired[count] = t
            count += missing[t] == 0
        for c in range(count):
            t = fired[c]
            if kind[t] == 2:
                status = NOT_SAFE
                break
            for w in range(n_w):
                kept = current[w] & keep[t, w]
                if kept & post[t, w] != 0:
                    status = NOT_SAFE
                found[c, w] = kept | post[t, w]
            if stride == 1:
                h = mix(found[c, 0] & key_mask[0])
            else:
                h = _hash_bits(found[c], key_mask)
            hashes[c] = h
            where[c] = h & mask
            prefetch(base + 8 * stride * (h & mask))
        if status != OK:
            break
        for c in range(count):
            t = fired[c]
            i = where[c]
            h = hashes[c]
            target = -1
            if stride == 1:
                key = found[c, 0] & key_mask[0]
                while table[i] != 0:
                    if table[i] >> shift == key:
                        target = np.int64(table[i] & ((_ONE << shift) - _ONE)) - 1
                        break
                    i = (i + _ONE) & mask
            else:
                while table[2 * i + 1] != 0:
                    if table[2 * i] == h:
                        candidate = np.int64(table[2 * i + 1]) - 1
                        same = True
                        if not one_word:
                            for w in range(n_w):
                                if (rows[candidate, w] ^ found[c, w]) & key_mask[w] != 0:
                                    same = False
                                    break
                        if same:
                            target = candidate
                            break
                    i = (i + _ONE) & mask
            if target < 0:
                if states >= max_states:
                    status = LIMIT
                    break
                target = states
                for w in range(n_w):
                    rows[target, w] = found[c, w]
                parent[target] = head
                parent_t[target] = t
                if stride == 1:
                    table[i] = (key << shift) | np.uint64(target + 1)
                else:
                    table[2 * i] = h
                    table[2 * i + 1] = np.uint64(target + 1)
                states += 1
            e_transition[edges] = t
            e_target[edges] = target
            edges += 1
        if status != OK:
            break
        head += 1
    counters[0], counters[1], counters[2] = states, edges, head
    return status


@_jit
def _hash_counts(row, key):
    h = _GOLDEN
    for p in range(key):
        h = (h ^ np.uint64(row[p])) * _M1
    return mix(h)


@_jit
def _reset_on_path(parent, parent_t, reset_at, reset_place, state, ancestor, place):
    """Whether a firing on the BFS-tree path from ``ancestor`` to ``state`` resets ``place``."""
    while state != ancestor:
        t = parent_t[state]
        for a in range(reset_at[t], reset_at[t + 1]):
            if reset_place[a] == place:
                return True
        state = np.int64(parent[state])
    return False


@_jit
def expand_counts(pre_at, pre_place, pre_weight, post_at, post_place, post_weight,
                  change_at, change_place, change_delta, reset_at, reset_place, key, top,
                  check_unbounded, max_states, rows, parent, parent_t, first_edge, table,
                  e_transition, e_target, totals, path_min, counters):
    """Breadth-first search over markings held as rows of unsigned counts.

    Args:
        pre_at, pre_place, pre_weight: the presets in compressed-row form (transition
            ``t``'s arcs are ``pre_at[t]:pre_at[t + 1]``); likewise the postsets, the
            net changes (place, post - pre) and the reset places.
        key: the number of leading columns that tell two states apart.
        top: the largest count the rows' dtype holds.
        check_unbounded: look for a new state strictly covering an ancestor (with reset
            arcs: in a place that no firing between the two resets, so that repeating
            those firings grows it forever).
        max_states, rows, parent, parent_t, first_edge, e_transition, e_target: as for
            :func:`expand_bits`; the table always has ``(hash, id + 1)`` slots.
        totals, path_min: per state its token total and the smallest total on its
            BFS-tree path (used and grown only with ``check_unbounded``).
        counters: ``[states, edges, expanded, covering, covered]``; the last two name
            the states proving unboundedness.

    Returns:
        A status: :data:`OK`, :data:`FULL`, :data:`LIMIT`, :data:`OVERFLOW` or
        :data:`UNBOUNDED`.
    """
    n_t = pre_at.shape[0] - 1
    n_p = rows.shape[1]
    mask = np.uint64(table.shape[0] // 2 - 1)
    successor = np.empty(n_p, dtype=np.int64)
    states, edges, head = counters[0], counters[1], counters[2]
    if states == 0:
        parent[0] = -1
        parent_t[0] = -1
        h = _hash_counts(rows[0], key)
        table[2 * (h & mask)] = h
        table[2 * (h & mask) + 1] = _ONE
        if check_unbounded:
            total = np.int64(0)
            for p in range(n_p):
                total += np.int64(rows[0, p])
            totals[0] = total
            path_min[0] = total
        states = 1
    status = OK
    while head < states:
        if (edges + n_t > e_target.shape[0] or states + n_t > rows.shape[0]
                or 2 * (states + n_t) > table.shape[0] // 2
                or (check_unbounded and states + n_t > totals.shape[0])):
            status = FULL
            break
        first_edge[head] = edges
        for t in range(n_t):
            enabled = True
            for a in range(pre_at[t], pre_at[t + 1]):
                if np.int64(rows[head, pre_place[a]]) < pre_weight[a]:
                    enabled = False
                    break
            if not enabled:
                continue
            for p in range(n_p):
                successor[p] = np.int64(rows[head, p])
            if reset_at[t + 1] > reset_at[t]:
                for a in range(pre_at[t], pre_at[t + 1]):
                    successor[pre_place[a]] -= pre_weight[a]
                for a in range(reset_at[t], reset_at[t + 1]):
                    successor[reset_place[a]] = 0
                for a in range(post_at[t], post_at[t + 1]):
                    successor[post_place[a]] += post_weight[a]
            else:
                for a in range(change_at[t], change_at[t + 1]):
                    successor[change_place[a]] += change_delta[a]
            for a in range(post_at[t], post_at[t + 1]):
                if successor[post_place[a]] > top:
                    status = OVERFLOW
            if status != OK:
                break
            h = _hash_counts(successor, key)
            i = h & mask
            target = -1
            while table[2 * i + 1] != 0:
                if table[2 * i] == h:
                    candidate = np.int64(table[2 * i + 1]) - 1
                    same = True
                    for p in range(key):
                        if np.int64(rows[candidate, p]) != successor[p]:
                            same = False
                            break
                    if same:
                        target = candidate
                        break
                i = (i + _ONE) & mask
            if target < 0:
                if states >= max_states:
                    status = LIMIT
                    break
                target = states
                for p in range(n_p):
                    rows[target, p] = successor[p]
                parent[target] = head
                parent_t[target] = t
                table[2 * i] = h
                table[2 * i + 1] = np.uint64(target + 1)
                states += 1
                if check_unbounded:
                    total = np.int64(0)
                    for p in range(n_p):
                        total += successor[p]
                    totals[target] = total
                    path_min[target] = min(total, path_min[head])
                    # Only an ancestor with fewer tokens can be strictly covered; path_min
                    # stops the walk where no such ancestor is left above.
                    ancestor = np.int64(head)
                    while ancestor >= 0 and path_min[ancestor] < total:
                        if totals[ancestor] < total:
                            covers = True
                            for p in range(n_p):
                                if successor[p] < np.int64(rows[ancestor, p]):
                                    covers = False
                                    break
                            # With reset arcs a grown place only pumps if no firing
                            # between the two markings resets it.
                            if covers and reset_at[n_t] > 0:
                                covers = False
                                for p in range(n_p):
                                    if (successor[p] > np.int64(rows[ancestor, p])
                                            and not _reset_on_path(parent, parent_t, reset_at,
                                                                   reset_place, target,
                                                                   ancestor, p)):
                                        covers = True
                                        break
                            if covers:
                                counters[3], counters[4] = target, ancestor
                                status = UNBOUNDED
                                break
                        ancestor = np.int64(parent[ancestor])
            e_transition[edges] = t
            e_target[edges] = target
            edges += 1
            if status != OK:
                break
        if status != OK:
            break
        head += 1
    counters[0], counters[1], counters[2] = states, edges, head
    return status
