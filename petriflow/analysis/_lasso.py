"""An accepting lasso of a graph times a Büchi automaton, found on the fly.

The product's states are ``(s, q)`` pairs numbered ``s * q_count + q``; its edges are
built only when the search reaches them: ``(s, q) → (s', q')`` for every graph edge
``s → s'`` and automaton edge ``q → q'`` whose guard holds in ``s``. The search is
Couvreur's SCC-based emptiness check (a Tarjan depth-first search keeping a stack of
component roots, each with the acceptance seen inside its component): it stops at the
first strongly connected component holding an accepting edge, so a violated property
costs only the product states up to its counterexample, a satisfied one only the
product states reachable from ``(s0, q0)``. The lasso is then read off: a shortest path
to an accepting edge of that component, and a shortest way back around it.

The loops are compiled by numba (:mod:`petriflow.analysis._numba`) for a product of
:data:`COMPILED_FROM_EDGES` edges or more, and run as plain Python otherwise (and
without numba).
"""

from __future__ import annotations

import numpy as np

from petriflow.analysis._graph import COMPILED_FROM_EDGES
from petriflow.analysis._numba import njit

__all__ = ["accepting_lasso"]

_jit = njit(__name__)



def _loops(edges: int) -> tuple:
    """``(search, accepting edge, shortest path)``: compiled, or their Python for a small product."""
    loops = (_search, _accepting_edge, _shortest)
    if edges < COMPILED_FROM_EDGES:
        return tuple(getattr(loop, "py_func", loop) for loop in loops)
    return loops


def accepting_lasso(offsets: np.ndarray, targets: np.ndarray, guard: np.ndarray,
                    automaton_offsets: np.ndarray, automaton_targets: np.ndarray,
                    accepting: np.ndarray, start: int) -> tuple[list[int], list[int], int] | None:
    """``(prefix, cycle, explored)`` of the product, or ``None`` when no accepting cycle is reachable.

    Args:
        offsets, targets: the graph in compressed rows (every state needs a successor
            for the runs to be infinite).
        guard: ``guard[j, s]``: automaton edge ``j`` may be taken from graph state ``s``.
        automaton_offsets, automaton_targets: the automaton's edges in compressed rows
            (edge ``j`` leaves the state ``q`` with ``automaton_offsets[q] <= j <
            automaton_offsets[q + 1]``).
        accepting: per automaton edge: whether it is accepting.
        start: the product's initial state ``s0 * q_count + q0``.

    ``prefix`` and ``cycle`` are graph edge ids (the cycle starts and ends in the
    prefix's last product state); ``explored``: how many product states were visited.

    Examples:
        >>> import numpy as np
        >>> offsets, targets = np.array([0, 1, 2]), np.array([1, 0])   # 0 -> 1 -> 0
        >>> # an automaton of one state whose only edge is accepting where the graph is at 1
        >>> guard = np.array([[False, True], [True, True]])
        >>> accepting_lasso(offsets, targets, guard, np.array([0, 2]), np.array([0, 0]),
        ...                 np.array([True, False]), 0)
        ([0], [1, 0], 2)
        >>> guard[0] = False                  # the accepting edge is never enabled
        >>> accepting_lasso(offsets, targets, guard, np.array([0, 2]), np.array([0, 0]),
        ...                 np.array([True, False]), 0) is None
        True
    """
    q_count = len(automaton_offsets) - 1
    size = (len(offsets) - 1) * q_count
    number = np.zeros(size, dtype=np.int64)
    edges = len(targets) * len(automaton_targets)
    search, accepting_edge, shortest = _loops(edges)
    # plain Python starts with room for every product state: it never grows its stacks
    capacity = 1024 if edges >= COMPILED_FROM_EDGES else size + 1
    found = search(offsets, targets, guard, automaton_offsets, automaton_targets, accepting,
                   q_count, start, number, capacity)
    explored = int(found[1])
    if found[0] < 0:
        return None
    member = number >= found[0]             # the accepting component: still open, numbered late
    edge = accepting_edge(offsets, targets, guard, automaton_offsets, automaton_targets,
                           accepting, q_count, member)
    u, v, graph_edge = int(edge[0]), int(edge[1]), int(edge[2])
    prefix = shortest(offsets, targets, guard, automaton_offsets, automaton_targets, q_count,
                       start, u, np.ones(size, dtype=np.bool_))
    back = shortest(offsets, targets, guard, automaton_offsets, automaton_targets, q_count,
                     v, u, member)
    return prefix.tolist(), [graph_edge] + back.tolist(), explored


@_jit
def _search(offsets, targets, guard, a_off, a_dst, accepting, q_count, start, number, capacity):
    """Couvreur's check: ``[root number of an accepting component or -1, states visited]``;
    ``number`` keeps each state's depth-first number (``-1``: its component is closed);
    the stacks start with room for ``capacity`` states and double when full."""
    stack = np.empty(capacity, dtype=np.int64)      # depth-first path: product states
    cursor = np.empty(capacity, dtype=np.int64)     # and how far each has read its edges
    live = np.empty(capacity, dtype=np.int64)       # states of components not yet closed
    roots = np.empty(capacity, dtype=np.int64)      # component roots' numbers
    root_acc = np.empty(capacity, dtype=np.bool_)   # acceptance seen inside the component
    root_in = np.empty(capacity, dtype=np.bool_)    # acceptance of the edge entering the root
    out = np.full(2, -1, dtype=np.int64)
    count = 1
    number[start] = 1
    stack[0], cursor[0], live[0], roots[0], root_acc[0], root_in[0] = start, 0, start, 1, False, False
    top, live_top, root_top = 1, 1, 1
    while top > 0:
        p = stack[top - 1]
        s, q = p // q_count, p % q_count
        first, degree = offsets[s], offsets[s + 1] - offsets[s]
        a_first, a_degree = a_off[q], a_off[q + 1] - a_off[q]
        c = cursor[top - 1]
        pushed = False
        while c < degree * a_degree:
            jj = c // degree
            j = a_first + jj
            if not guard[j, s]:
                c = (jj + 1) * degree
                continue
            e = first + c % degree
            c += 1
            w = targets[e] * q_count + a_dst[j]
            if number[w] == 0:
                cursor[top - 1] = c
                if top == capacity or live_top == capacity or root_top == capacity:
                    capacity *= 2
                    stack, cursor, live = _grow(stack, capacity), _grow(cursor, capacity), _grow(live, capacity)
                    roots, root_acc, root_in = _grow(roots, capacity), _grow(root_acc, capacity), \
                        _grow(root_in, capacity)
                count += 1
                number[w] = count
                stack[top], cursor[top] = w, 0
                live[live_top] = w
                roots[root_top], root_acc[root_top], root_in[root_top] = count, False, accepting[j]
                top, live_top, root_top = top + 1, live_top + 1, root_top + 1
                pushed = True
                break
            if number[w] > 0:                       # a cycle: merge the components on it
                acc = accepting[j]
                while roots[root_top - 1] > number[w]:
                    acc = acc or root_acc[root_top - 1] or root_in[root_top - 1]
                    root_top -= 1
                root_acc[root_top - 1] = root_acc[root_top - 1] or acc
                if root_acc[root_top - 1]:
                    out[0], out[1] = roots[root_top - 1], count
                    return out
        if pushed:
            continue
        top -= 1
        if roots[root_top - 1] == number[p]:        # p closes its component
            root_top -= 1
            while True:
                live_top -= 1
                x = live[live_top]
                number[x] = -1
                if x == p:
                    break
    out[1] = count
    return out


@_jit
def _grow(array, capacity):
    bigger = np.empty(capacity, dtype=array.dtype)
    bigger[:len(array)] = array
    return bigger


@_jit
def _accepting_edge(offsets, targets, guard, a_off, a_dst, accepting, q_count, member):
    """``[u, v, graph edge]`` of an accepting product edge between two members."""
    out = np.full(3, -1, dtype=np.int64)
    for p in range(len(member)):
        if not member[p]:
            continue
        s, q = p // q_count, p % q_count
        for j in range(a_off[q], a_off[q + 1]):
            if not accepting[j] or not guard[j, s]:
                continue
            for e in range(offsets[s], offsets[s + 1]):
                w = targets[e] * q_count + a_dst[j]
                if member[w]:
                    out[0], out[1], out[2] = p, w, e
                    return out
    return out


@_jit
def _shortest(offsets, targets, guard, a_off, a_dst, q_count, start, goal, allowed):
    """Graph edge ids of a shortest product path ``start → goal`` through ``allowed``
    states (at least one edge: from ``goal`` to itself it is a cycle)."""
    size = len(allowed)
    parent = np.full(size, -1, dtype=np.int64)
    via = np.full(size, -1, dtype=np.int64)
    queue = np.empty(size, dtype=np.int64)
    head, tail = 0, 1
    queue[0] = start
    reached = start == goal
    while head < tail and not reached:
        p = queue[head]
        head += 1
        s, q = p // q_count, p % q_count
        for j in range(a_off[q], a_off[q + 1]):
            if not guard[j, s]:
                continue
            for e in range(offsets[s], offsets[s + 1]):
                w = targets[e] * q_count + a_dst[j]
                if not allowed[w] or parent[w] >= 0 or w == start:
                    continue
                parent[w], via[w] = p, e
                if w == goal:
                    reached = True
                    break
                queue[tail] = w
                tail += 1
            if reached:
                break
    length = 0
    x = goal
    while x != start:
        length += 1
        x = parent[x]
    path = np.empty(length, dtype=np.int64)
    x = goal
    while x != start:
        length -= 1
        path[length] = via[x]
        x = parent[x]
    return path
