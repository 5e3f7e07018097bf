"""Karp–Miller coverability: unbounded places found, bounded nets left alone."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from petriflow.analysis.coverability import OMEGA, coverability_graph, coverability_search, unbounded_places
from petriflow.analysis.reachability import (
    StateSpaceLimit,
    UnboundedNetError,
    reachability_graph,
)
from petriflow.classic import dining_philosophers, producer_consumer
from petriflow.errors import PetriflowError
from petriflow.io.yaml import loads_net
from petriflow.marking import Marking
from petriflow.net import Net
from tests.analysis.strategies import PLACE_NAMES, reference_exploration

MAILBOX = """
petriflow: 1
places: [{id: idle, tokens: 1}, mailbox, read]
transitions:
  - {id: send, in: [idle], out: [idle, mailbox]}
  - {id: fetch, in: [mailbox], out: [read]}
  - {id: never, in: {read: 1, idle: 1, mailbox: 5}, out: [idle]}
"""


def test_mailbox_places_are_unbounded():
    """send pumps mailbox, fetch carries it on to read: both unbounded, idle bounded."""
    graph = coverability_graph(loads_net(MAILBOX))
    assert graph.unbounded_places == ["mailbox", "read"]
    assert graph.place_bounds() == {"idle": 1, "mailbox": None, "read": None}
    assert not graph.bounded


def test_transition_enabled_only_by_omega_is_not_dead():
    """'never' needs 5 mailbox tokens: reachable by pumping, so it is not dead."""
    assert coverability_graph(loads_net(MAILBOX)).dead_transitions() == []


def test_dead_transition_of_an_unbounded_net():
    """A transition needing a token no marking ever has is dead."""
    net = loads_net(MAILBOX.replace("read: 1, idle: 1, mailbox: 5", "nowhere: 1")
                    .replace("[{id: idle, tokens: 1}, mailbox, read]",
                             "[{id: idle, tokens: 1}, mailbox, read, nowhere]"))
    assert coverability_graph(net).dead_transitions() == ["never"]


def test_path_to_an_omega_node_fires():
    """A node's path fires from the start (ω places aside)."""
    net = loads_net(MAILBOX)
    graph = coverability_graph(net)
    node = next(k for k, m in enumerate(graph.markings) if m[1] == OMEGA)
    assert graph.path(node)[0] == "send"
    assert "ω" in graph.format_marking(graph.markings[node])


def test_bounded_net_graph_is_the_reachability_graph():
    """Without ω the coverability graph has exactly the reachable markings and edges."""
    net = dining_philosophers(5)
    graph = coverability_graph(net)
    space = reachability_graph(net)
    assert graph.bounded and unbounded_places(net) == []
    assert len(graph.markings) == space.num_states and len(graph.edges) == space.num_edges


def test_node_limit_raises():
    """A large bounded net hits the node limit with StateSpaceLimit."""
    with pytest.raises(StateSpaceLimit):
        coverability_graph(producer_consumer(500), max_nodes=100)


def test_reset_arcs_are_refused():
    """Karp-Miller does not apply to nets with cancellation regions."""
    net = loads_net("""
petriflow: 1
places: [{id: a, tokens: 1}, b]
transitions: [{id: t, in: [a], out: [a, b], cancels: [b]}]
""")
    with pytest.raises(PetriflowError, match="reset"):
        coverability_graph(net)


@st.composite
def any_nets(draw: st.DrawFn) -> Net:
    """Small nets whose transitions may create or destroy tokens (possibly unbounded)."""
    places = PLACE_NAMES[: draw(st.integers(1, 4))]
    net = Net("any")
    for place in places:
        net.add_place(place)
    for k in range(draw(st.integers(1, 4))):
        name = f"t{k}"
        net.add_transition(name)
        for place, weight in draw(st.dictionaries(st.sampled_from(places), st.integers(1, 2),
                                                  max_size=2)).items():
            net.add_arc(place, name, weight)
        for place, weight in draw(st.dictionaries(st.sampled_from(places), st.integers(1, 2),
                                                  max_size=2)).items():
            net.add_arc(name, place, weight)
    tokens = draw(st.lists(st.sampled_from(places), max_size=3))
    net.set_initial_marking(Marking({p: tokens.count(p) for p in set(tokens)}))
    return net


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(any_nets())
def test_on_the_fly_detection_agrees_with_karp_miller(net):
    """The reachability graph raises UnboundedNetError exactly on nets Karp-Miller finds
    unbounded, naming only unbounded places; otherwise it matches the textbook BFS."""
    try:
        graph = coverability_graph(net, max_nodes=5000)
    except StateSpaceLimit:
        return
    if graph.bounded:
        space = reachability_graph(net)
        expected, edges = reference_exploration(net)
        assert space.num_states == len(expected) and space.num_edges == edges
    else:
        with pytest.raises(UnboundedNetError) as caught:
            reachability_graph(net, max_states=10**5)
        assert set(caught.value.places) <= set(graph.unbounded_places)


# The budgeted depth-first search -------------------------------------------------------

def _replays(net, prefix, pump, covered, covering):
    """The witness fires from the initial marking and the pump strictly adds tokens."""
    from petriflow.engine import fire_sequence

    reached = fire_sequence(net, net.initial_marking, prefix)
    assert reached == covered
    assert fire_sequence(net, reached, pump) == covering
    assert all(covering[p] >= covered[p] for p in net.places) and covering != covered


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(any_nets())
def test_search_agrees_with_the_textbook_graph(net):
    """Finished within its budget, the depth-first search finds exactly the unbounded
    places, dead transitions and bounds of the breadth-first Karp-Miller graph; its
    witness replays. Stopped early, every place it names is unbounded."""
    try:
        graph = coverability_graph(net, max_nodes=5000)
    except StateSpaceLimit:
        return
    found = coverability_search(net)
    assert found.complete
    assert found.unbounded_places == graph.unbounded_places
    assert found.dead_transitions == graph.dead_transitions()
    assert found.place_bounds == graph.place_bounds()
    assert found.bounded == graph.bounded
    if found.witness is not None:
        w = found.witness
        _replays(net, w.prefix, w.pump, w.covered, w.covering)
        assert set(w.places) <= set(graph.unbounded_places)
    small = coverability_search(net, max_nodes=2)
    assert set(small.unbounded_places) <= set(graph.unbounded_places)
    assert small.complete or small.bounded in (None, False)


def test_search_finds_a_pump_behind_a_large_bounded_part():
    """2**20 markings within 20 firings, the pump 30 steps down a chain: a breadth-first
    search (and the former check) fills 2,000,000 states without reaching it; the
    depth-first search finds it within its default budget, with a short witness."""
    from tests.analysis.nets import pumped_after_bounded

    net = pumped_after_bounded(20, 30)
    found = coverability_search(net)
    assert found.unbounded_places == ["heap"] and found.bounded is False
    assert not found.complete and found.stopped == "budget" and found.nodes == 100_000
    w = found.witness
    assert w.prefix == [f"step_{s}" for s in range(30)] and w.pump == ["pump"]
    _replays(net, w.prefix, w.pump, w.covered, w.covering)
    assert found.dead_transitions is None and "pump" in found.fired


def test_search_refuses_reset_arcs_and_bad_budgets():
    """Reset arcs and a budget under one node are refused; a bounded net is finished."""
    cancelling = loads_net("""
petriflow: 1
places: [{id: a, tokens: 1}, b]
transitions: [{id: t, in: [a], out: [a, b], cancels: [b]}]
""")
    with pytest.raises(PetriflowError, match="reset"):
        coverability_search(cancelling)
    net = dining_philosophers(3)
    with pytest.raises(ValueError):
        coverability_search(net, max_nodes=0)
    bounded = coverability_search(net)
    assert bounded.complete and bounded.bounded and bounded.nodes == 4
    assert bounded.place_bounds["fork_0"] == 1 and bounded.dead_transitions == []
