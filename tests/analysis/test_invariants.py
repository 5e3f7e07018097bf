"""P- and T-semiflows on nets whose semiflows are known by hand."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from petriflow.analysis.invariants import (
    InvariantLimit,
    is_covered_by_p_semiflows,
    p_semiflows,
    semiflows,
    structural_bounds,
    t_semiflows,
)
from petriflow.analysis.reachability import reachability_graph
from petriflow.classic import dining_philosophers, independent_cycles, producer_consumer
from petriflow.engine import CompiledNet
from petriflow.io.yaml import loads_net
from tests.analysis.strategies import bounded_nets


def as_sets(flows):
    return {frozenset(f.items()) for f in flows}


def test_philosophers_semiflows():
    """Each philosopher thinks or eats; each fork is free or held by one neighbour; each
    philosopher's take/release pair is a T-semiflow."""
    n = 4
    flows = as_sets(p_semiflows(dining_philosophers(n)))
    expected = {frozenset({(f"think_{k}", 1), (f"eat_{k}", 1)}) for k in range(n)}
    expected |= {frozenset({(f"fork_{k}", 1), (f"eat_{k}", 1), (f"eat_{(k - 1) % n}", 1)})
                 for k in range(n)}
    assert flows == expected
    assert as_sets(t_semiflows(dining_philosophers(n))) == {
        frozenset({(f"take_{k}", 1), (f"release_{k}", 1)}) for k in range(n)}


def test_weighted_semiflow_has_coprime_weights():
    """i -t-> 2 o gives the P-semiflow 2i + o (entries without a common divisor)."""
    net = loads_net("""
petriflow: 1
places: [{id: i, tokens: 1}, o]
transitions: [{id: t, in: [i], out: {o: 2}}, {id: u, in: {o: 2}, out: [i]}]
""")
    assert p_semiflows(net) == [{"i": 2, "o": 1}]
    assert t_semiflows(net) == [{"t": 1, "u": 1}]
    assert structural_bounds(net) == {"i": 1, "o": 2}


def test_producer_consumer_bounds_from_semiflows():
    """buffer + free = capacity bounds the buffer by the capacity."""
    bounds = structural_bounds(producer_consumer(7, 3))
    assert bounds["buffer"] == 7 and bounds["free"] == 7 and bounds["ready_to_put"] == 1


def test_uncovered_place_has_no_structural_bound():
    """A place only ever filled is in no P-semiflow."""
    net = loads_net("""
petriflow: 1
places: [{id: a, tokens: 1}, log]
transitions: [{id: t, in: [a], out: [a, log]}]
""")
    assert p_semiflows(net) == [{"a": 1}]
    assert not is_covered_by_p_semiflows(net)
    assert "log" not in structural_bounds(net)


def test_no_semiflow():
    """A net that only creates tokens has neither P- nor T-semiflows."""
    net = loads_net("""
petriflow: 1
places: [p]
transitions: [{id: t, in: [], out: [p]}]
""")
    assert p_semiflows(net) == [] and t_semiflows(net) == []


def test_minimal_supports_only():
    """x0 - x1 + x2 = 0: Farkas keeps (1,1,0) and (0,1,1), not their sum (1,2,1)."""
    found = [list(map(int, y)) for y in semiflows(np.array([[1], [-1], [1]]))]
    assert found == [[1, 1, 0], [0, 1, 1]]


def test_row_limit_raises():
    """A tiny row limit stops Farkas' algorithm with InvariantLimit."""
    with pytest.raises(InvariantLimit):
        semiflows(np.array([[1], [1], [1], [-1], [-1], [-1]]), max_rows=3)


def test_cycles_are_covered():
    """Independent cycles: one P-semiflow and one T-semiflow per cycle."""
    net = independent_cycles(3)
    assert is_covered_by_p_semiflows(net)
    assert len(p_semiflows(net)) == 3 and len(t_semiflows(net)) == 3


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(bounded_nets())
def test_semiflows_are_invariant_on_every_reachable_marking(net):
    """y·M is constant over the reachability graph for every P-semiflow y, and the
    structural bounds hold; every T-semiflow x has x·C = 0."""
    compiled = CompiledNet(net)
    space = reachability_graph(net)
    markings = space.markings.astype(np.int64)
    for flow in p_semiflows(net):
        y = np.array([flow.get(p, 0) for p in compiled.places])
        weighted = markings @ y
        assert (weighted == weighted[0]).all() and (y >= 0).all()
    bounds = dict(zip(space.places, space.place_bounds()))
    for place, bound in structural_bounds(net).items():
        assert bounds[place] <= bound
    for flow in t_semiflows(net):
        x = np.array([flow.get(t, 0) for t in compiled.transitions])
        assert not (x @ compiled.incidence).any()


# Farkas' algorithm with the compiled adjacency test --------------------------------------

def reference_semiflows(matrix) -> set[tuple[int, ...]]:
    """The textbook Farkas algorithm: combine every positive row with every negative one,
    then drop rows whose support contains another's (slow, obviously right)."""
    from math import gcd

    matrix = np.asarray(matrix, dtype=object)
    n, m = matrix.shape
    rows = [list(matrix[i]) + [int(i == k) for k in range(n)] for i in range(n)]
    for j in range(m):
        pos = [r for r in rows if r[j] > 0]
        neg = [r for r in rows if r[j] < 0]
        rows = [r for r in rows if r[j] == 0]
        rows += [[-q[j] * a + p[j] * b for a, b in zip(p, q)] for p in pos for q in neg]
        normal = set()
        for r in rows:
            g = 0
            for v in r:
                g = gcd(g, int(v))
            normal.add(tuple(int(v) // g for v in r))
        support = {r: frozenset(k for k in range(n) if r[m + k]) for r in normal}
        rows = [list(r) for r in normal if not any(support[o] < support[r] for o in normal)]
    return {tuple(r[m:]) for r in rows}


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(1, 7).flatmap(lambda n: st.integers(1, 5).flatmap(
    lambda m: st.lists(st.lists(st.integers(-3, 3), min_size=m, max_size=m), min_size=n, max_size=n))))
def test_farkas_agrees_with_the_textbook_algorithm(matrix):
    """Minimal semiflows from the adjacency-tested algorithm are exactly the textbook
    algorithm's, on random small integer matrices (weights and zero columns included)."""
    found = {tuple(int(v) for v in x) for x in semiflows(np.array(matrix))}
    assert found == reference_semiflows(matrix)


def test_t_semiflows_of_a_complete_state_machine_are_its_cycles():
    """A token moving among 7 places, every pair linked: one minimal T-semiflow per
    elementary cycle of the complete digraph (2365). The former implementation gave up
    at 2000 rows; each is a cycle here, and they come within a small budget."""
    from tests.analysis.nets import complete_state_machine

    net = complete_state_machine(7)
    compiled = CompiledNet(net)
    found = semiflows(compiled.incidence, budget=20_000_000)
    assert len(found) == 2365
    for x in found[:200]:
        assert not (x @ compiled.incidence).any() and set(x.tolist()) <= {0, 1}


def test_a_budget_stops_an_exploding_computation_quickly():
    """Lamport's fast mutex for 3 processes has a small state space but T-semiflows past
    any useful number: the default budget stops them in well under a few seconds of CPU,
    deterministically (the budget counts work, not time)."""
    import time

    from tests.analysis.nets import lamport_fast_mutex

    net = lamport_fast_mutex(3)
    started = time.process_time()
    with pytest.raises(InvariantLimit) as caught:
        t_semiflows(net)
    assert caught.value.reason in ("budget", "rows")
    assert time.process_time() - started < 5
    with pytest.raises(InvariantLimit) as caught:
        semiflows(CompiledNet(net).incidence, budget=1000)
    assert caught.value.reason == "budget" and "1,000" in str(caught.value)
    assert len(p_semiflows(net)) == 8          # the P-semiflows are few and cheap


def test_large_entries_switch_to_exact_integers():
    """Weights whose products would overflow int64 are combined as Python integers."""
    big = 2**40
    found = semiflows(np.array([[big], [-(big - 1)], [-3]]))
    assert {tuple(int(v) for v in x) for x in found} == {(big - 1, big, 0), (3, 0, big)}


def test_a_long_cycle_costs_in_proportion():
    """One token around a cycle of 900 places: one P-semiflow and one T-semiflow. The
    former implementation rebuilt and pruned the whole dense matrix at every one of the
    900 steps (24 s each); rows that a step does not touch now cost it nothing."""
    import time

    from tests.analysis.nets import long_cycle

    net = long_cycle(900)
    started = time.process_time()
    assert p_semiflows(net) == [{f"p{k}": 1 for k in range(900)}]
    assert t_semiflows(net) == [{f"t{k}": 1 for k in range(900)}]
    assert time.process_time() - started < 5
