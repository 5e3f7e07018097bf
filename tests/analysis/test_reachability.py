"""The reachability graph: known state counts, witnesses, limits, and three oracles.

The exploration has two engines (plain Python while the BFS queue is short, numpy
frontiers when it is wide) and, within numpy, bitmask and count rows with exact or
hashed keys. ``explore(net, numpy=True)`` forces the numpy engine from the first state,
so every test that uses it covers those paths even on tiny nets.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings

from petriflow.analysis import reachability
from petriflow.analysis.reachability import (
    StateSpaceLimit,
    UnboundedNetError,
    reachability_graph,
    to_networkx,
)
from petriflow.classic import dining_philosophers, independent_cycles, producer_consumer
from petriflow.engine import CompiledNet, fire, fire_sequence
from petriflow.io.yaml import loads_net
from petriflow.marking import Marking
from petriflow.net import Net
from tests.analysis.strategies import bounded_nets, reference_exploration, to_pm4py

SETTINGS = settings(max_examples=150, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])


def explore(net: Net, marking=None, *, numpy: bool = False, max_states: int = 10**6,
            detect_unbounded: bool = True):
    """The state space, optionally with the numpy engine from the very first state."""
    if not numpy:
        return reachability_graph(net, marking, max_states=max_states,
                                  detect_unbounded=detect_unbounded)
    compiled = CompiledNet(net)
    start = net.initial_marking if marking is None else marking
    m0 = np.array(compiled.vector(start), dtype=np.int64)
    return reachability._explore(compiled, m0, max_states, detect_unbounded, switch=0)


def lucas(n: int) -> int:
    a, b = 2, 1
    for _ in range(n):
        a, b = b, a + b
    return a


def assert_consistent(net: Net, space) -> None:
    """Every state is reached by its path, every edge is a firing, states are distinct."""
    markings = [space.marking(s) for s in range(space.num_states)]
    assert len(set(markings)) == space.num_states
    assert markings[0] == net.initial_marking
    for state in range(space.num_states):
        assert fire_sequence(net, net.initial_marking, space.path(state)) == markings[state]
    for source, t, target in zip(space.edge_source, space.edge_transition, space.edge_target):
        assert fire(net, markings[source], space.transitions[t]) == markings[target]


@pytest.mark.parametrize("n", range(2, 17))
def test_philosopher_states_are_lucas_numbers(n):
    """Dining philosophers with atomic fork taking have L(n) reachable markings."""
    assert reachability_graph(dining_philosophers(n)).num_states == lucas(n)


@pytest.mark.parametrize("numpy", [False, True])
@pytest.mark.parametrize("n", [3, 5, 8])
def test_philosopher_graph_matches_reference(n, numpy):
    """States, edges and markings equal the textbook BFS on both engines."""
    net = dining_philosophers(n)
    space = explore(net, numpy=numpy)
    expected, edges = reference_exploration(net)
    assert {space.marking(s) for s in range(space.num_states)} == expected
    assert space.num_edges == edges
    assert_consistent(net, space)


@pytest.mark.parametrize("numpy", [False, True])
@pytest.mark.parametrize("n", [1, 4, 10, 13])
def test_independent_cycles_have_two_to_the_n_states(n, numpy):
    """n independent two-place cycles: 2**n markings, each enabling exactly n transitions."""
    space = explore(independent_cycles(n), numpy=numpy)
    assert (space.num_states, space.num_edges) == (2**n, n * 2**n)
    assert space.safe and space.max_tokens_marking == n


@pytest.mark.parametrize("numpy", [False, True])
@pytest.mark.parametrize("capacity,batch", [(1, 1), (3, 1), (3, 2), (10, 4), (300, 7)])
def test_producer_consumer_counts_by_hand(capacity, batch, numpy):
    """Producer (2 states) x consumer (2 states) x buffer level 0..c: 4(c+1) markings.

    Edges: produce and consume fire in half the markings each (2(c+1) each), take
    whenever the buffer is non-empty (2c), put whenever c - b >= batch (2(c - batch + 1)).
    """
    space = explore(producer_consumer(capacity, batch), numpy=numpy)
    assert space.num_states == 4 * (capacity + 1)
    assert space.num_edges == 8 * capacity + 6 - 2 * batch
    assert space.max_tokens_place == capacity
    assert space.safe == (capacity == 1)


def test_paths_and_edges_are_firings_on_a_weighted_net():
    """On a non-safe weighted net every path reaches its state and every edge fires."""
    net = producer_consumer(6, 3)
    assert_consistent(net, explore(net, numpy=True))
    assert_consistent(net, explore(net))


def test_markings_array_is_in_compiled_place_order():
    """Column j of ``markings`` is ``places[j]``, as in CompiledNet."""
    net = producer_consumer(2)
    space = reachability_graph(net)
    assert list(space.places) == CompiledNet(net).places
    assert space.markings.shape == (space.num_states, len(net.places))
    assert list(space.markings[0]) == CompiledNet(net).vector(net.initial_marking)


def test_index_finds_reachable_markings_only():
    """``index`` maps a reachable marking to its state and anything else to None."""
    net = dining_philosophers(4)
    space = reachability_graph(net)
    state = space.num_states - 1
    assert space.index(space.marking(state)) == state
    assert space.index({"eat_0": 1, "eat_1": 1}) is None
    assert space.index({"nowhere": 1}) is None


def test_successors_list_transitions_and_targets():
    """``successors`` gives (transition, target) pairs of one state."""
    space = reachability_graph(independent_cycles(2))
    targets = {t: space.marking(s) for t, s in space.successors(0)}
    assert set(targets) == {"go_0", "go_1"}
    assert targets["go_0"] == {"b_0": 1, "a_1": 1}


def test_to_networkx_has_states_markings_and_keyed_edges():
    """The MultiDiGraph has one node per state with its marking, edges keyed by transition."""
    net = dining_philosophers(3)
    space = reachability_graph(net)
    graph = to_networkx(space)
    assert graph.number_of_nodes() == space.num_states
    assert graph.number_of_edges() == space.num_edges
    assert graph.nodes[0]["marking"] == net.initial_marking
    for source, target, key, data in graph.edges(keys=True, data=True):
        assert data["transition"] == key
        assert fire(net, graph.nodes[source]["marking"], key) == graph.nodes[target]["marking"]


@pytest.mark.parametrize("numpy", [False, True])
def test_state_limit_raises_with_count(numpy):
    """Exceeding max_states raises StateSpaceLimit naming the limit and the states stored."""
    with pytest.raises(StateSpaceLimit) as caught:
        explore(dining_philosophers(12), max_states=100, numpy=numpy)
    assert caught.value.limit == 100 and caught.value.explored <= 100
    assert "max_states=100" in str(caught.value) and "states" in str(caught.value)


def test_state_limit_on_a_wide_net_goes_through_numpy():
    """A limit hit deep in a wide exploration (numpy frontiers) raises too."""
    with pytest.raises(StateSpaceLimit):
        reachability_graph(dining_philosophers(22), max_states=20_000)


GENERATOR = """
petriflow: 1
places: [{id: idle, tokens: 1}, queue, done]
transitions:
  - {id: arrive, in: [idle], out: [idle, queue]}
  - {id: serve, in: [queue], out: [done]}
"""


@pytest.mark.parametrize("numpy", [False, True])
def test_unbounded_net_raises_with_a_pumping_witness(numpy):
    """A transition that only adds tokens is found to be unbounded, with a witness."""
    net = loads_net(GENERATOR)
    with pytest.raises(UnboundedNetError) as caught:
        explore(net, numpy=numpy)
    error = caught.value
    assert error.places and set(error.places) <= {"queue", "done"}
    covered = fire_sequence(net, net.initial_marking, error.prefix)
    covering = fire_sequence(net, covered, error.pump)
    assert covered == error.covered and covering == error.covering
    assert all(covering[p] >= covered[p] for p in net.places)
    assert all(covering[p] > covered[p] for p in error.places)


def test_unbounded_detection_can_be_turned_off():
    """Without detection an unbounded net runs into the state limit instead."""
    with pytest.raises(StateSpaceLimit):
        explore(loads_net(GENERATOR), detect_unbounded=False, max_states=500)


def test_source_transition_makes_a_safe_start_unbounded():
    """A transition with no input place, on a safe start marking, is unbounded."""
    net = loads_net("""
petriflow: 1
places: [p]
transitions: [{id: make, in: [], out: [p]}]
""")
    with pytest.raises(UnboundedNetError) as caught:
        explore(net, numpy=True)
    assert caught.value.places == ["p"] and caught.value.pump == ["make"]


def test_bitmask_falls_back_to_counts_when_a_place_gets_two_tokens():
    """A net that starts safe and later doubles a token is still explored exactly."""
    net = loads_net("""
petriflow: 1
places: [{id: a, tokens: 1}, {id: b, tokens: 1}, c, d]
transitions:
  - {id: ac, in: [a], out: [c]}
  - {id: bc, in: [b], out: [c]}
  - {id: cd, in: {c: 2}, out: {d: 2}}
  - {id: back, in: {d: 2}, out: [a, b]}
""")
    space = explore(net, numpy=True)
    expected, edges = reference_exploration(net)
    assert {space.marking(s) for s in range(space.num_states)} == expected
    assert space.num_edges == edges and not space.safe and space.representation == "counts"


def test_more_than_64_basis_places_use_hashed_keys():
    """A token walking a 70-place ring: the key needs 69 bits, so it is a verified hash."""
    net = Net("ring")
    for k in range(70):
        net.add_place(f"p{k}", tokens=int(k == 0))
    for k in range(70):
        net.add_transition(f"t{k}")
        net.add_arc(f"p{k}", f"t{k}")
        net.add_arc(f"t{k}", f"p{(k + 1) % 70}")
    space = explore(net, numpy=True)
    assert (space.num_states, space.num_edges) == (70, 70)
    assert_consistent(net, space)


def test_hash_collisions_restart_with_an_exact_index(monkeypatch):
    """With a hash that collides all the time the result is still exact."""
    monkeypatch.setattr(reachability, "_hash_words", lambda words: words[:, 0] & np.uint64(3))
    net = Net("ring")
    for k in range(70):
        net.add_place(f"p{k}", tokens=int(k % 35 == 0))
    for k in range(70):
        net.add_transition(f"t{k}")
        net.add_arc(f"p{k}", f"t{k}")
        net.add_arc(f"t{k}", f"p{(k + 1) % 70}")
    space = explore(net, numpy=True, max_states=10**5)
    expected, edges = reference_exploration(net)
    assert space.num_states == len(expected) and space.num_edges == edges


def test_counts_without_structural_bounds_use_hashed_keys():
    """A bounded but not conservative net whose place c no P-semiflow covers."""
    net = loads_net("""
petriflow: 1
places: [{id: a, tokens: 3}, b, c]
transitions:
  - {id: plain, in: [a], out: [b]}
  - {id: extra, in: [a], out: [b, c]}
  - {id: back, in: [b], out: [a]}
""")
    with pytest.raises(UnboundedNetError):   # back + extra pumps c
        explore(net, numpy=True)
    bounded = loads_net("""
petriflow: 1
places: [{id: a, tokens: 3}, b, c]
transitions:
  - {id: plain, in: [a], out: [b]}
  - {id: extra, in: [a], out: [b, c]}
""")
    space = explore(bounded, numpy=True)
    expected, edges = reference_exploration(bounded)
    assert space.num_states == len(expected) and space.num_edges == edges
    assert space.max_tokens_place == 3


def test_cancellation_region_empties_places():
    """A transition with a cancellation region (reset arcs) empties those places."""
    net = loads_net("""
petriflow: 1
places: [{id: go, tokens: 1}, {id: work, tokens: 2}, stop]
transitions:
  - {id: abort, in: [go], out: [stop], cancels: [work]}
  - {id: step, in: [work], out: []}
""")
    for numpy in (False, True):
        space = explore(net, numpy=numpy)
        markings = {space.marking(s) for s in range(space.num_states)}
        assert Marking({"stop": 1}) in markings
        assert all(not (m["stop"] and m["work"]) for m in markings)
        assert space.num_states == len(reference_exploration(net)[0])


@SETTINGS
@given(bounded_nets())
def test_random_nets_match_the_reference_exploration(net):
    """Markings and edge counts equal the textbook BFS, on both engines."""
    expected, edges = reference_exploration(net)
    for numpy in (False, True):
        space = explore(net, numpy=numpy)
        assert {space.marking(s) for s in range(space.num_states)} == expected
        assert space.num_edges == edges


@SETTINGS
@given(bounded_nets(max_places=5, max_transitions=5, max_tokens=4))
def test_random_nets_match_snakes_state_graph(net):
    """State and edge counts equal SNAKES' StateGraph (edges: (marking, transition, mode)
    triples; a P/T transition has one mode, so they are (marking, transition) pairs)."""
    snakes_nets = pytest.importorskip("snakes.nets")
    from petriflow.interop.snakes import to_snakes

    graph = snakes_nets.StateGraph(to_snakes(net))
    graph.build()
    snakes_edges = sum(len(list(graph.successors(state))) for state in range(len(graph)))
    space = reachability_graph(net)
    assert (space.num_states, space.num_edges) == (len(graph), snakes_edges)


@SETTINGS
@given(bounded_nets(max_places=5, max_transitions=5, max_tokens=4))
def test_random_nets_match_pm4py_reachability_graph(net):
    """State and edge counts equal PM4Py's reachability graph.

    PM4Py keys a graph edge by (transition name, source, target), so two transitions
    leading from one marking to the same successor are two edges, like the MCC count.
    """
    module = pytest.importorskip("pm4py.objects.petri_net.utils.reachability_graph")
    pn, initial, _ = to_pm4py(net)
    graph = module.construct_reachability_graph(pn, initial)
    space = reachability_graph(net)
    assert (space.num_states, space.num_edges) == (len(graph.states), len(graph.transitions))


def test_outcome_variants_are_explored_as_their_own_rows():
    """A transition with a routed 'failed' outcome fires as 't' and 't@failed'."""
    net = loads_net("""
petriflow: 1
places: [{id: ready, tokens: 1}, done, broken]
transitions:
  - {id: grab, in: [ready], out: [done], outcomes: {failed: [broken]}}
  - {id: repair, in: [broken], out: [ready]}
""")
    space = reachability_graph(net)
    assert space.num_states == 3 and space.num_edges == 3
    assert set(space.transitions) == {"grab", "grab@failed", "repair"}
    assert space.origins[space.transitions.index("grab@failed")] == "grab"
    broken = space.index({"broken": 1})
    assert space.path(broken) == ["grab@failed"]


@pytest.mark.parametrize("numpy", [False, True])
def test_degenerate_nets(numpy):
    """No transitions: one state; no places: one state with a self-loop per transition."""
    lonely = loads_net("petriflow: 1\nplaces: [{id: p, tokens: 2}]\n")
    space = explore(lonely, numpy=numpy)
    assert (space.num_states, space.num_edges) == (1, 0)
    empty = Net("empty")
    empty.add_transition("tick")
    space = explore(empty, numpy=numpy)
    assert (space.num_states, space.num_edges) == (1, 1) and space.successors(0) == [("tick", 0)]
