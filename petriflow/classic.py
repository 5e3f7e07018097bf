"""Classic nets built in code, for examples, tests and benchmarks.

Examples:
    >>> dining_philosophers(5)
    <Net 'philosophers-5': 15 places, 10 transitions, 40 arcs>
    >>> independent_cycles(3).initial_marking.total
    3
"""

from __future__ import annotations

from petriflow.net import Net

__all__ = ["dining_philosophers", "independent_cycles", "producer_consumer"]


def dining_philosophers(n: int) -> Net:
    """Dining philosophers with atomic fork taking.

    Philosopher ``k`` takes forks ``k`` and ``k+1 mod n`` in one firing of ``take_k``
    and puts both back with ``release_k``. Its reachable state count is the Lucas
    number L(n) (11 for n = 5).
    """
    if n < 2:
        raise ValueError("dining philosophers needs n >= 2")
    net = Net(f"philosophers-{n}", f"{n} dining philosophers")
    for k in range(n):
        net.add_place(f"think_{k}", tokens=1)
        net.add_place(f"eat_{k}")
        net.add_place(f"fork_{k}", tokens=1)
    for k in range(n):
        left, right = f"fork_{k}", f"fork_{(k + 1) % n}"
        net.add_transition(f"take_{k}")
        net.add_arc(f"think_{k}", f"take_{k}")
        net.add_arc(left, f"take_{k}")
        net.add_arc(right, f"take_{k}")
        net.add_arc(f"take_{k}", f"eat_{k}")
        net.add_transition(f"release_{k}")
        net.add_arc(f"eat_{k}", f"release_{k}")
        net.add_arc(f"release_{k}", f"think_{k}")
        net.add_arc(f"release_{k}", left)
        net.add_arc(f"release_{k}", right)
    return net


def independent_cycles(n: int) -> Net:
    """``n`` disjoint two-place cycles with one token each: 2**n reachable markings."""
    net = Net(f"cycles-{n}")
    for k in range(n):
        net.add_place(f"a_{k}", tokens=1)
        net.add_place(f"b_{k}")
        net.add_transition(f"go_{k}")
        net.add_transition(f"back_{k}")
        net.add_arc(f"a_{k}", f"go_{k}")
        net.add_arc(f"go_{k}", f"b_{k}")
        net.add_arc(f"b_{k}", f"back_{k}")
        net.add_arc(f"back_{k}", f"a_{k}")
    return net


def producer_consumer(capacity: int, batch: int = 1) -> Net:
    """A producer and a consumer around a buffer of ``capacity`` slots.

    The producer puts ``batch`` items per firing (an arc of weight ``batch``); free
    slots are a complementary place, so the net is bounded by ``capacity``.
    """
    if capacity < batch or batch < 1:
        raise ValueError("producer_consumer needs capacity >= batch >= 1")
    net = Net(f"producer-consumer-{capacity}")
    net.add_place("ready_to_produce", tokens=1)
    net.add_place("ready_to_put")
    net.add_place("buffer")
    net.add_place("free", tokens=capacity)
    net.add_place("ready_to_take", tokens=1)
    net.add_place("ready_to_consume")
    for t in ("produce", "put", "take", "consume"):
        net.add_transition(t)
    net.add_arc("ready_to_produce", "produce")
    net.add_arc("produce", "ready_to_put")
    net.add_arc("ready_to_put", "put")
    net.add_arc("free", "put", batch)
    net.add_arc("put", "buffer", batch)
    net.add_arc("put", "ready_to_produce")
    net.add_arc("ready_to_take", "take")
    net.add_arc("buffer", "take")
    net.add_arc("take", "free")
    net.add_arc("take", "ready_to_consume")
    net.add_arc("ready_to_consume", "consume")
    net.add_arc("consume", "ready_to_take")
    return net
