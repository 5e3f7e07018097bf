"""Bounds, deadlocks, dead transitions, liveness and reversibility on small known nets."""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings

from petriflow.analysis import _graph
from petriflow.analysis.properties import (
    dead_transitions,
    deadlock_witness,
    deadlocks,
    is_live,
    is_reversible,
    is_safe,
    non_live_transitions,
    non_live_witness,
    place_bounds,
    strongly_connected_components,
    terminal_components,
)
from petriflow.analysis.reachability import reachability_graph, to_networkx
from petriflow.classic import dining_philosophers, producer_consumer
from petriflow.engine import enabled, fire_sequence
from petriflow.io.yaml import loads_net
from tests.analysis.strategies import bounded_nets

# Two philosophers who take their forks one at a time: both can hold one fork and wait.
GREEDY = """
petriflow: 1
places: [{id: f1, tokens: 1}, {id: f2, tokens: 1}, {id: a, tokens: 1}, {id: b, tokens: 1},
         a_has_1, b_has_2, a_eats, b_eats]
transitions:
  - {id: a_takes_1, in: [a, f1], out: [a_has_1]}
  - {id: a_takes_2, in: [a_has_1, f2], out: [a_eats]}
  - {id: a_done, in: [a_eats], out: [a, f1, f2]}
  - {id: b_takes_2, in: [b, f2], out: [b_has_2]}
  - {id: b_takes_1, in: [b_has_2, f1], out: [b_eats]}
  - {id: b_done, in: [b_eats], out: [b, f1, f2]}
"""

# A start-up step, then a loop that never fires 'setup' again; 'broken' is dead.
STARTUP = """
petriflow: 1
places: [{id: idle, tokens: 1}, ready, busy, never]
transitions:
  - {id: setup, in: [idle], out: [ready]}
  - {id: work, in: [ready], out: [busy]}
  - {id: rest, in: [busy], out: [ready]}
  - {id: broken, in: [never], out: [ready]}
"""


def test_deadlock_witness_is_a_shortest_sequence_to_a_dead_marking():
    """Greedy fork taking deadlocks after two steps; the witness says which."""
    net = loads_net(GREEDY)
    space = reachability_graph(net)
    witness = deadlock_witness(space)
    assert sorted(witness) == ["a_takes_1", "b_takes_2"]
    assert enabled(net, fire_sequence(net, net.initial_marking, witness)) == []
    assert len(deadlocks(space)) == 1


def test_deadlock_free_net_has_no_witness():
    """Atomic fork taking never deadlocks."""
    space = reachability_graph(dining_philosophers(4))
    assert deadlock_witness(space) is None and deadlocks(space).size == 0


def test_place_bounds_and_safety():
    """k-bounds per place, and safety, on a buffer of capacity 3."""
    space = reachability_graph(producer_consumer(3))
    bounds = place_bounds(space)
    assert bounds["buffer"] == 3 and bounds["ready_to_put"] == 1
    assert not is_safe(space) and is_safe(reachability_graph(dining_philosophers(3)))


def test_dead_transition_and_liveness_after_startup():
    """'broken' is dead; 'setup' fires once only, so the net is not live; not reversible."""
    space = reachability_graph(loads_net(STARTUP))
    assert dead_transitions(space) == ["broken"]
    assert non_live_transitions(space) == ["setup", "broken"]
    assert not is_live(space) and not is_reversible(space)
    sequence, transitions = non_live_witness(space)
    assert sequence == ["setup"] and transitions == ["setup", "broken"]


def test_live_and_reversible_net():
    """Atomic dining philosophers are live and reversible."""
    space = reachability_graph(dining_philosophers(5))
    assert is_live(space) and is_reversible(space) and non_live_witness(space) is None


def test_deadlocked_net_is_not_live():
    """A deadlock is a terminal component without any transition; the eating cycle can
    still run into it, so it is not terminal."""
    space = reachability_graph(loads_net(GREEDY))
    assert not is_live(space)
    labels = strongly_connected_components(space)
    terminal = terminal_components(space, labels)
    assert len(terminal) == 1
    assert (labels == terminal[0]).sum() == 1 and deadlocks(space)[0] in np.flatnonzero(labels == terminal[0])


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(bounded_nets())
def test_components_agree_with_networkx_compiled_and_pure(net):
    """Strongly connected components equal networkx's, by the compiled loops and by pure Python."""
    space = reachability_graph(net)
    graph = to_networkx(space)
    expected = {frozenset(c) for c in nx.strongly_connected_components(graph)}
    for compiled in (True, False):
        old = _graph.COMPILED_FROM_EDGES
        _graph.COMPILED_FROM_EDGES = 0 if compiled else old
        try:
            labels = _graph.strong_components(space.num_states, space.edge_source,
                                              space.edge_target, compiled=compiled)
            reach = _graph.can_reach(space.num_states, space.edge_source, space.edge_target,
                                     [space.num_states - 1], compiled=compiled)
        finally:
            _graph.COMPILED_FROM_EDGES = old
        found = {frozenset(np.flatnonzero(labels == c).tolist()) for c in np.unique(labels)}
        assert found == expected
        ancestors = nx.ancestors(graph, space.num_states - 1) | {space.num_states - 1}
        assert set(np.flatnonzero(reach).tolist()) == ancestors


@pytest.mark.parametrize("net_yaml", [GREEDY, STARTUP])
def test_liveness_matches_a_definition_check(net_yaml):
    """L4-liveness from terminal components equals the definition: from every reachable
    state, every transition labels some edge reachable from it."""
    space = reachability_graph(loads_net(net_yaml))
    graph = to_networkx(space)
    live_everywhere = set(space.transitions)
    for state in graph:
        reachable = nx.descendants(graph, state) | {state}
        fired = {key for u, _, key in graph.edges(reachable, keys=True)}
        live_everywhere &= fired
    assert set(non_live_transitions(space)) == set(space.transitions) - live_everywhere
