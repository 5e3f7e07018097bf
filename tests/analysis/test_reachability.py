"""The reachability graph: known state counts, witnesses, limits, and three oracles.

The exploration has two compiled loops (bitmask rows for safe markings, count rows for
the rest) and two kinds of keys (whole rows, or the places of an incidence basis).
``explore(net, mode=...)`` picks them: ``"default"`` as :func:`reachability_graph` does,
``"basis"`` bitmask rows keyed on basis places even on tiny nets, ``"counts"`` count
rows keyed on basis places even on safe nets; tests parametrised over :data:`MODES`
cover every path on small nets.
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


MODES = ("default", "basis", "counts")


def explore(net: Net, marking=None, *, mode: str = "default", max_states: int = 10**6,
            detect_unbounded: bool = True):
    """The state space, through the loop and keys ``mode`` names (see the module doc)."""
    if mode == "default":
        return reachability_graph(net, marking, max_states=max_states,
                                  detect_unbounded=detect_unbounded)
    compiled = CompiledNet(net)
    start = net.initial_marking if marking is None else marking
    m0 = np.array(compiled.vector(start), dtype=np.int64)
    return reachability._explore(compiled, m0, max_states, detect_unbounded,
                                 bits=mode == "basis", basis_from=0)


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


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("n", [3, 5, 8])
def test_philosopher_graph_matches_reference(n, mode):
    """States, edges and markings equal the textbook BFS in every mode."""
    net = dining_philosophers(n)
    space = explore(net, mode=mode)
    expected, edges = reference_exploration(net)
    assert {space.marking(s) for s in range(space.num_states)} == expected
    assert space.num_edges == edges
    assert_consistent(net, space)


@pytest.mark.parametrize("mode", MODES)
def test_edges_come_by_source_then_transition(mode):
    """The documented edge order: by source state, then transition index."""
    space = explore(dining_philosophers(9), mode=mode)
    order = np.lexsort((space.edge_transition, space.edge_source))
    assert (order == np.arange(space.num_edges)).all()
    offsets = space.edge_offsets
    assert offsets[0] == 0 and offsets[-1] == space.num_edges and len(offsets) == len(space) + 1
    assert space.successors(7) == [(space.transitions[t], int(s)) for t, s in zip(
        space.edge_transition[offsets[7]: offsets[8]], space.edge_target[offsets[7]: offsets[8]])]


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("n", [1, 4, 10, 13])
def test_independent_cycles_have_two_to_the_n_states(n, mode):
    """n independent two-place cycles: 2**n markings, each enabling exactly n transitions."""
    space = explore(independent_cycles(n), mode=mode)
    assert (space.num_states, space.num_edges) == (2**n, n * 2**n)
    assert space.safe and space.max_tokens_marking == n


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("capacity,batch", [(1, 1), (3, 1), (3, 2), (10, 4), (300, 7)])
def test_producer_consumer_counts_by_hand(capacity, batch, mode):
    """Producer (2 states) x consumer (2 states) x buffer level 0..c: 4(c+1) markings.

    Edges: produce and consume fire in half the markings each (2(c+1) each), take
    whenever the buffer is non-empty (2c), put whenever c - b >= batch (2(c - batch + 1)).
    """
    space = explore(producer_consumer(capacity, batch), mode=mode)
    assert space.num_states == 4 * (capacity + 1)
    assert space.num_edges == 8 * capacity + 6 - 2 * batch
    assert space.max_tokens_place == capacity
    assert space.safe == (capacity == 1)


def test_paths_and_edges_are_firings_on_a_weighted_net():
    """On a non-safe weighted net every path reaches its state and every edge fires."""
    net = producer_consumer(6, 3)
    assert_consistent(net, explore(net, mode="counts"))
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


@pytest.mark.parametrize("mode", MODES)
def test_state_limit_raises_with_count(mode):
    """Exceeding max_states raises StateSpaceLimit naming the limit and the states stored."""
    with pytest.raises(StateSpaceLimit) as caught:
        explore(dining_philosophers(12), max_states=100, mode=mode)
    assert caught.value.limit == 100 and caught.value.explored <= 100
    assert "max_states=100" in str(caught.value) and "states" in str(caught.value)


def test_state_limit_deep_in_a_large_exploration():
    """A limit hit after the buffers and the table have grown several times raises too."""
    with pytest.raises(StateSpaceLimit):
        reachability_graph(dining_philosophers(22), max_states=20_000)


GENERATOR = """
petriflow: 1
places: [{id: idle, tokens: 1}, queue, done]
transitions:
  - {id: arrive, in: [idle], out: [idle, queue]}
  - {id: serve, in: [queue], out: [done]}
"""


@pytest.mark.parametrize("mode", MODES)
def test_unbounded_net_raises_with_a_pumping_witness(mode):
    """A transition that only adds tokens is found to be unbounded, with a witness."""
    net = loads_net(GENERATOR)
    with pytest.raises(UnboundedNetError) as caught:
        explore(net, mode=mode)
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
        explore(net, mode="counts")
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
    space = explore(net, mode="counts")
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
    space = explore(net, mode="counts")
    assert (space.num_states, space.num_edges) == (70, 70)
    assert_consistent(net, space)


def two_rings(size: int = 35) -> Net:
    """Two rings of ``size`` places with a token each: safe, size**2 states, keys of
    2 * size - 2 basis places (more than one word)."""
    net = Net("two-rings")
    for ring in "ab":
        for k in range(size):
            net.add_place(f"{ring}{k}", tokens=int(k == 0))
        for k in range(size):
            net.add_transition(f"{ring}t{k}")
            net.add_arc(f"{ring}{k}", f"{ring}t{k}")
            net.add_arc(f"{ring}t{k}", f"{ring}{(k + 1) % size}")
    return net


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("size", [20, 40, 65])
def test_rows_of_one_two_and_three_words(size, mode):
    """40, 80 and 130 places: bitmask rows of one, two and three words (each width has
    its own compiled loop)."""
    net = two_rings(size)
    space = explore(net, mode=mode)
    assert (space.num_states, space.num_edges) == (size**2, 2 * size**2)
    assert space.representation == ("counts" if mode == "counts" else "bitmask")
    assert_consistent(net, space)


COLLIDING = """
import numpy as np
from petriflow.analysis import _kernel
assert not _kernel.COMPILED
_kernel.mix = lambda x: x & np.uint64(255)   # hashes collide all the time
from petriflow.analysis import reachability
from petriflow.engine import CompiledNet
from tests.analysis.test_reachability import two_rings

net = two_rings()
compiled = CompiledNet(net)
m0 = np.array(compiled.vector(net.initial_marking), dtype=np.int64)
for bits in (True, False):
    space = reachability._explore(compiled, m0, 10**5, True, bits=bits)
    print(space.representation, space.num_states, space.num_edges)
"""


def test_hash_collisions_are_told_apart_by_the_rows():
    """With a hash that collides all the time the result is still exact.

    Runs the loops as plain Python (``NUMBA_DISABLE_JIT=1``, also the path taken where
    numba is missing) in a subprocess, with the hash replaced by an eight-bit one.
    """
    import os
    import subprocess
    import sys

    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    done = subprocess.run([sys.executable, "-c", COLLIDING], env=env, capture_output=True,
                          text=True, timeout=300, check=True)
    expected, edges = reference_exploration(two_rings())
    assert done.stdout.split() == ["bitmask", str(len(expected)), str(edges),
                                   "counts", str(len(expected)), str(edges)]


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
        explore(net, mode="counts")
    bounded = loads_net("""
petriflow: 1
places: [{id: a, tokens: 3}, b, c]
transitions:
  - {id: plain, in: [a], out: [b]}
  - {id: extra, in: [a], out: [b, c]}
""")
    space = explore(bounded, mode="counts")
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
    for mode in MODES:
        space = explore(net, mode=mode)
        markings = {space.marking(s) for s in range(space.num_states)}
        assert Marking({"stop": 1}) in markings
        assert all(not (m["stop"] and m["work"]) for m in markings)
        assert space.num_states == len(reference_exploration(net)[0])


@pytest.mark.parametrize("reservations", [True, False])
def test_large_buffers_move_to_reservations_or_copies(monkeypatch, reservations):
    """Buffers past the reservation threshold (here tiny) keep every state and edge,
    whether the system grants the reserved mapping or refuses it (copies then)."""
    monkeypatch.setattr(reachability, "_RESERVE_FROM", 2**10)
    if not reservations:
        monkeypatch.setattr(reachability, "_reserve", lambda *args: None)
    for mode in MODES:
        space = explore(dining_philosophers(12), mode=mode)
        assert (space.num_states, space.num_edges) == (lucas(12), reachability_graph(
            dining_philosophers(12)).num_edges)
        assert_consistent(dining_philosophers(12), space)
        assert _on_a_mapping(space.edge_target) == reservations


def _on_a_mapping(array) -> bool:
    import mmap

    while array is not None:
        if isinstance(array, mmap.mmap):
            return True
        array = getattr(array, "base", None) if not isinstance(array, memoryview) else array.obj
    return False


def test_reset_net_that_resets_its_growing_place_is_bounded():
    """t covers the start marking but resets the place it grows: two states, no error."""
    net = loads_net("""
petriflow: 1
places: [{id: a, tokens: 1}, b]
transitions: [{id: t, in: [a], out: [a, b], cancels: [b]}]
""")
    space = explore(net)
    assert (space.num_states, space.num_edges) == (2, 2)


def test_reset_net_growing_a_place_nothing_resets_is_unbounded():
    """With a cancellation region elsewhere, a place that only grows is still caught."""
    net = loads_net("""
petriflow: 1
places: [{id: a, tokens: 1}, b, c]
transitions:
  - {id: t, in: [a], out: [a, b, c], cancels: [c]}
""")
    for mode in ("default", "counts"):
        with pytest.raises(UnboundedNetError) as caught:
            explore(net, mode=mode)
        assert caught.value.places == ["b"] and caught.value.pump == ["t"]


@SETTINGS
@given(bounded_nets())
def test_random_nets_match_the_reference_exploration(net):
    """Markings and edge counts equal the textbook BFS, in every mode."""
    expected, edges = reference_exploration(net)
    for mode in MODES:
        space = explore(net, mode=mode)
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


@pytest.mark.parametrize("mode", MODES)
def test_degenerate_nets(mode):
    """No transitions: one state; no places: one state with a self-loop per transition."""
    lonely = loads_net("petriflow: 1\nplaces: [{id: p, tokens: 2}]\n")
    space = explore(lonely, mode=mode)
    assert (space.num_states, space.num_edges) == (1, 0)
    empty = Net("empty")
    empty.add_transition("tick")
    space = explore(empty, mode=mode)
    assert (space.num_states, space.num_edges) == (1, 1) and space.successors(0) == [("tick", 0)]


@pytest.mark.parametrize("bits", [True, False])
def test_the_limit_keeps_what_was_explored(bits):
    """StateSpaceLimit.partial: the states found, the first ``expanded`` with all their
    edges (as in the full graph), the others with none and not counted as deadlocks."""
    from petriflow.analysis.reachability import _explore
    from petriflow.engine import CompiledNet

    net = dining_philosophers(10)
    full = reachability_graph(net)
    compiled = CompiledNet(net)
    with pytest.raises(StateSpaceLimit) as caught:
        _explore(compiled, compiled.vector(net.initial_marking), 40, True, bits=bits)
    partial = caught.value.partial
    assert partial.num_states == 40 and not partial.complete
    assert partial.expanded == caught.value.expanded < 40
    for state in range(partial.expanded):
        assert partial.successors(state) == full.successors(state)
        assert partial.marking(state) == full.marking(state)
    assert partial.num_edges == full.edge_offsets[partial.expanded]
    assert partial.deadlocks().size == 0 and full.complete
