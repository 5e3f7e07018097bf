"""Generated nets that stress the analyses the way Model Checking Contest models do.

* :func:`lamport_fast_mutex`: Lamport's fast mutual exclusion algorithm for ``n``
  processes (the algorithm behind the MCC's LamportFastMutEx models), written from the
  algorithm: per process a program counter, shared variables ``b[i]``, ``x`` and ``y``
  as one place per value, reads as self-loops. Its T-semiflows explode under naive
  Farkas (every assignment ``x := i`` from every old value, every way back to the
  start), while its state space is small.
* :func:`shared_cycles`: ``k`` parallel cycles of ``length`` steps sharing ``hubs``
  places, each step with two alternatives: many T-semiflows sharing places.
* :func:`complete_state_machine`: one token among ``n`` places with a transition
  between every pair: ``n`` markings, one T-semiflow per elementary cycle (2365 for
  ``n = 7``, where the old Farkas implementation gave up at its 2000 rows).
* :func:`pumped_after_bounded`: an unbounded net whose bounded part is large (``2**k``
  markings at a small depth) and whose pump only starts after a chain of ``depth``
  steps, so a breadth-first search drowns in the bounded part first.
* :func:`deadlock_beyond_limit`: a bounded net with a deadlock close to the initial
  marking and a state space far larger than a small ``max_states``.

Examples:
    >>> lamport_fast_mutex(2)
    <Net 'lamport-fast-mutex-2': 38 places, 52 transitions, 208 arcs>
"""

from __future__ import annotations

from petriflow.net import Net

__all__ = ["complete_state_machine", "deadlock_beyond_limit", "lamport_fast_mutex", "long_cycle",
           "philosophers_one_fork", "pumped_after_bounded", "shared_cycles"]


def _move(net: Net, name: str, before: list[str], after: list[str], read: tuple[str, ...] = ()) -> None:
    net.add_transition(name)
    for place in before + list(read):
        net.add_arc(place, name)
    for place in after + list(read):
        net.add_arc(name, place)


def lamport_fast_mutex(n: int) -> Net:
    """Lamport's fast mutual exclusion algorithm for ``n`` processes (``1..n``)::

        start: b[i] := true; x := i
               if y != 0 then b[i] := false; await y = 0; goto start
               y := i
               if x != i then
                   b[i] := false
                   for j in 1..n: await not b[j]
                   if y != i then await y = 0; goto start
               critical section
               y := 0; b[i] := false; goto start
    """
    net = Net(f"lamport-fast-mutex-{n}")
    procs = range(1, n + 1)
    values = range(0, n + 1)
    for v in values:
        net.add_place(f"x_{v}", tokens=1 if v == 0 else 0)
        net.add_place(f"y_{v}", tokens=1 if v == 0 else 0)
    labels = ["start", "set_x", "test_y", "clear_b", "wait_y", "set_y", "test_x", "clear_b2"]
    labels += [f"await_{j}" for j in procs] + ["test_y2", "wait_y2", "cs", "release"]
    for i in procs:
        net.add_place(f"b_{i}_false", tokens=1)
        net.add_place(f"b_{i}_true")
        for label in labels:
            net.add_place(f"{label}_{i}", tokens=1 if label == "start" else 0)
    for i in procs:
        def at(label: str) -> str:
            return f"{label}_{i}"
        _move(net, f"set_b_{i}", [at("start"), f"b_{i}_false"], [at("set_x"), f"b_{i}_true"])
        for v in values:
            _move(net, f"x_{v}_to_{i}_by_{i}", [at("set_x"), f"x_{v}"], [at("test_y"), f"x_{i}"])
            _move(net, f"y_{v}_to_{i}_by_{i}", [at("set_y"), f"y_{v}"], [at("test_x"), f"y_{i}"])
            _move(net, f"y_{v}_to_0_by_{i}", [at("cs"), f"y_{v}"], [at("release"), "y_0"])
            if v:
                _move(net, f"y_busy_{v}_{i}", [at("test_y")], [at("clear_b")], (f"y_{v}",))
            if v != i:
                _move(net, f"x_other_{v}_{i}", [at("test_x")], [at("clear_b2")], (f"x_{v}",))
                _move(net, f"y_other_{v}_{i}", [at("test_y2")], [at("wait_y2")], (f"y_{v}",))
        _move(net, f"y_free_{i}", [at("test_y")], [at("set_y")], ("y_0",))
        _move(net, f"back_off_{i}", [at("clear_b"), f"b_{i}_true"], [at("wait_y"), f"b_{i}_false"])
        _move(net, f"retry_{i}", [at("wait_y")], [at("start")], ("y_0",))
        _move(net, f"x_mine_{i}", [at("test_x")], [at("cs")], (f"x_{i}",))
        _move(net, f"clear_{i}", [at("clear_b2"), f"b_{i}_true"], [at("await_1"), f"b_{i}_false"])
        for j in procs:
            after = f"await_{j + 1}_{i}" if j < n else at("test_y2")
            _move(net, f"seen_{j}_by_{i}", [at(f"await_{j}")], [after], (f"b_{j}_false",))
        _move(net, f"y_mine_{i}", [at("test_y2")], [at("cs")], (f"y_{i}",))
        _move(net, f"retry2_{i}", [at("wait_y2")], [at("start")], ("y_0",))
        _move(net, f"leave_{i}", [at("release"), f"b_{i}_true"], [at("start"), f"b_{i}_false"])
    return net


def shared_cycles(k: int, length: int = 3, hubs: int = 2) -> Net:
    """``k`` cycles of ``length`` places, one token each; step 0 of cycle ``c`` takes a
    token from every hub and gives it back at step 1, and each cycle can also skip
    through either of two alternative steps: many T-semiflows that share places."""
    net = Net(f"shared-cycles-{k}x{length}")
    for h in range(hubs):
        net.add_place(f"hub_{h}", tokens=1)
    for c in range(k):
        for s in range(length):
            net.add_place(f"c{c}_{s}", tokens=1 if s == 0 else 0)
        for s in range(length):
            here, there = f"c{c}_{s}", f"c{c}_{(s + 1) % length}"
            for alt in ("a", "b"):
                name = f"c{c}_{s}_{alt}"
                net.add_transition(name)
                net.add_arc(here, name)
                net.add_arc(name, there)
                if s == 0:
                    for h in range(hubs):
                        net.add_arc(f"hub_{h}", name)
                elif s == 1:
                    for h in range(hubs):
                        net.add_arc(name, f"hub_{h}")
    return net


def pumped_after_bounded(k: int, depth: int) -> Net:
    """``k`` independent two-place cycles (``2**k`` markings, all within ``k`` firings),
    beside a chain of ``depth`` steps whose last place enables ``pump``, which puts a
    token in ``heap`` and gives its input back: unbounded in ``heap`` only."""
    net = Net(f"pumped-after-bounded-{k}-{depth}")
    for c in range(k):
        net.add_place(f"a_{c}", tokens=1)
        net.add_place(f"b_{c}")
        _move(net, f"go_{c}", [f"a_{c}"], [f"b_{c}"])
        _move(net, f"back_{c}", [f"b_{c}"], [f"a_{c}"])
    for s in range(depth + 1):
        net.add_place(f"chain_{s}", tokens=1 if s == 0 else 0)
    for s in range(depth):
        _move(net, f"step_{s}", [f"chain_{s}"], [f"chain_{s + 1}"])
    net.add_place("heap")
    _move(net, "pump", [f"chain_{depth}"], [f"chain_{depth}", "heap"])
    _move(net, "drain", ["heap", "a_0"], ["a_0"])
    return net


def deadlock_beyond_limit(k: int) -> Net:
    """``k`` independent two-place cycles (``2**k`` markings) and ``all_stop``, which
    takes the token of every cycle at once (each in its first place): after it no
    transition is enabled, a deadlock one firing from the start."""
    net = Net(f"deadlock-beyond-limit-{k}")
    for c in range(k):
        net.add_place(f"a_{c}", tokens=1)
        net.add_place(f"b_{c}")
        _move(net, f"go_{c}", [f"a_{c}"], [f"b_{c}"])
        _move(net, f"back_{c}", [f"b_{c}"], [f"a_{c}"])
    net.add_place("stopped")
    _move(net, "all_stop", [f"a_{c}" for c in range(k)], ["stopped"])
    return net


def complete_state_machine(n: int) -> Net:
    """One token moving between ``n`` places, with a transition between every ordered pair:
    ``n`` reachable markings, and one minimal T-semiflow per elementary cycle of the
    complete digraph (409 for ``n = 6``, 2365 for ``n = 7``)."""
    net = Net(f"complete-state-machine-{n}")
    for p in range(n):
        net.add_place(f"p{p}", tokens=1 if p == 0 else 0)
    for p in range(n):
        for q in range(n):
            if p != q:
                _move(net, f"t{p}_{q}", [f"p{p}"], [f"p{q}"])
    return net


def long_cycle(n: int) -> Net:
    """One token around a cycle of ``n`` places: ``n`` markings, one P- and one
    T-semiflow, and a Farkas matrix of ``n`` rows and columns that every step of a dense
    implementation rebuilds (the former one took 24 s for ``n = 900``)."""
    net = Net(f"long-cycle-{n}")
    for k in range(n):
        net.add_place(f"p{k}", tokens=1 if k == 0 else 0)
    for k in range(n):
        _move(net, f"t{k}", [f"p{k}"], [f"p{(k + 1) % n}"])
    return net


def philosophers_one_fork(n: int) -> Net:
    """The textbook dining philosophers: each takes the left fork, then the right one,
    eats, and puts both back. Deadlocks when every philosopher holds a left fork (the
    classic of ``petriflow.classic`` takes both forks at once and never deadlocks).

    Examples:
        >>> philosophers_one_fork(3)
        <Net 'philosophers-one-fork-3': 12 places, 9 transitions, 30 arcs>
    """
    net = Net(f"philosophers-one-fork-{n}")
    for k in range(n):
        for place in (f"think_{k}", f"left_{k}", f"eat_{k}", f"fork_{k}"):
            net.add_place(place)
    for k in range(n):
        right = f"fork_{(k + 1) % n}"
        _move(net, f"take_left_{k}", [f"think_{k}", f"fork_{k}"], [f"left_{k}"])
        _move(net, f"take_right_{k}", [f"left_{k}", right], [f"eat_{k}"])
        _move(net, f"release_{k}", [f"eat_{k}"], [f"think_{k}", f"fork_{k}", right])
    from petriflow.marking import Marking

    net.set_initial_marking(Marking({p: 1 for k in range(n) for p in (f"think_{k}", f"fork_{k}")}))
    return net
