"""The graph helpers behind the properties: compiled loops against pure Python and networkx.

``_graph`` runs numba-compiled loops from :data:`~petriflow.analysis._graph.COMPILED_FROM_EDGES`
edges and pure Python below; the ``compiled`` fixture sets that threshold to 0 so that
every graph here, however small, reaches the compiled loops.
"""

from __future__ import annotations

import os
import subprocess
import sys

import networkx as nx
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from petriflow.analysis import _graph
from petriflow.analysis.properties import (
    dead_transitions,
    deadlock_witness,
    deadlocks,
    non_live_transitions,
    non_live_witness,
    strongly_connected_components,
    terminal_components,
)
from petriflow.analysis.reachability import reachability_graph
from petriflow.classic import dining_philosophers, producer_consumer
from petriflow.io.yaml import loads_net
from tests.analysis.strategies import bounded_nets
from tests.analysis.test_properties import GREEDY

needs_numba = pytest.mark.skipif(not _graph._compile(), reason="numba missing or disabled")


def examples(count: int) -> settings:
    """Hypothesis settings for ``count`` examples (no deadline: the first compiled call
    loads numba's cache; fixtures are per test, set up once for all examples)."""
    return settings(max_examples=count, deadline=None, suppress_health_check=[
        HealthCheck.too_slow, HealthCheck.function_scoped_fixture])


@pytest.fixture
def compiled(monkeypatch):
    """Compiled loops for every graph (pure Python stays reachable with compiled=False)."""
    monkeypatch.setattr(_graph, "COMPILED_FROM_EDGES", 0)


@st.composite
def graphs(draw, max_nodes: int = 24, max_edges: int = 80):
    """``(n, source, target)``: any edges, unsorted, with self loops, parallel edges and
    isolated nodes; int32 or int64 arrays."""
    n = draw(st.integers(0, max_nodes))
    pairs = [] if n == 0 else draw(st.lists(
        st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)), max_size=max_edges))
    if draw(st.booleans()):
        pairs.sort()                     # grouped by source, as a StateSpace keeps them
    dtype = draw(st.sampled_from([np.int32, np.int64]))
    source = np.array([u for u, _ in pairs], dtype=dtype)
    target = np.array([v for _, v in pairs], dtype=dtype)
    return n, source, target


def to_networkx(n, source, target) -> nx.DiGraph:
    graph = nx.DiGraph()
    graph.add_nodes_from(range(n))
    graph.add_edges_from(zip(source.tolist(), target.tolist()))
    return graph


def partition(labels: np.ndarray) -> set[frozenset[int]]:
    return {frozenset(np.flatnonzero(labels == c).tolist()) for c in np.unique(labels)}


@needs_numba
@examples(300)
@given(graphs())
def test_compiled_components_equal_tarjan_and_networkx(compiled, graph):
    """Pearce's compiled loop gives _tarjan's labels exactly, and networkx's components."""
    n, source, target = graph
    labels = _graph.strong_components(n, source, target)
    pure = _graph.strong_components(n, source, target, compiled=False)
    assert labels.dtype == pure.dtype == np.int64
    assert labels.tolist() == pure.tolist()
    assert sorted(set(labels.tolist())) == list(range(len(set(labels.tolist()))))
    assert partition(labels) == {frozenset(c) for c in
                                 nx.strongly_connected_components(to_networkx(n, source, target))}


@needs_numba
@examples(200)
@given(graphs(), st.data())
def test_compiled_reachability_equals_networkx(compiled, graph, data):
    n, source, target = graph
    starts = data.draw(st.lists(st.integers(0, max(n - 1, 0)), max_size=3)) if n else []
    nxg = to_networkx(n, source, target)
    forward = set(starts).union(*(nx.descendants(nxg, s) for s in starts))
    backward = set(starts).union(*(nx.ancestors(nxg, s) for s in starts))
    for use in (True, False):
        assert set(np.flatnonzero(_graph.reachable_from(n, source, target, starts,
                                                        compiled=use)).tolist()) == forward
        assert set(np.flatnonzero(_graph.can_reach(n, source, target, starts,
                                                   compiled=use)).tolist()) == backward
        offsets, neighbours = _graph.csr(n, source, target, compiled=use)
        assert set(np.flatnonzero(_graph.reaching(offsets, neighbours, starts,
                                                  compiled=use)).tolist()) == backward


@needs_numba
@examples(200)
@given(graphs())
def test_transpose_lists_each_node_s_predecessors_in_order(compiled, graph):
    n, source, target = graph
    for use in (True, False):
        offsets, neighbours = _graph.csr(n, source, target, compiled=use)
        reverse, predecessors = _graph.transpose(offsets, neighbours, compiled=use)
        assert len(reverse) == n + 1
        for v in range(n):
            expected = sorted(source[target == v].tolist())
            assert predecessors[reverse[v]: reverse[v + 1]].tolist() == expected


@needs_numba
@examples(200)
@given(graphs(), st.data())
def test_compiled_terminal_summary_equals_pure_and_condensation(compiled, graph, data):
    n, source, target = graph
    kinds = data.draw(st.integers(1, 5))
    edge_label = np.array(data.draw(st.lists(st.integers(0, kinds - 1), min_size=len(source),
                                             max_size=len(source))), dtype=np.int16)
    labels = _graph.strong_components(n, source, target)
    terminal, first, present = _graph.terminal_summary(source, target, labels, edge_label, kinds)
    pure = _graph.terminal_summary(source, target, labels, edge_label, kinds, compiled=False)
    assert [a.tolist() for a in (terminal, first, present)] == [a.tolist() for a in pure]
    condensed = nx.condensation(to_networkx(n, source, target))
    sinks = {frozenset(condensed.nodes[c]["members"]) for c in condensed if not condensed.out_degree(c)}
    assert {frozenset(np.flatnonzero(labels == c).tolist()) for c in terminal} == sinks
    for c, smallest, row in zip(terminal.tolist(), first.tolist(), present):
        members = set(np.flatnonzero(labels == c).tolist())
        assert smallest == min(members)
        inside = {int(x) for u, x in zip(source.tolist(), edge_label) if u in members}
        assert set(np.flatnonzero(row).tolist()) == inside


@needs_numba
@examples(100)
@given(graphs())
def test_compiled_csr_groups_edges_stably(compiled, graph):
    """Grouped edges keep ``target`` itself as the neighbour array; others are sorted
    stably, as numpy's argsort does."""
    n, source, target = graph
    offsets, neighbours = _graph.csr(n, source, target)
    expected = _graph.csr(n, source, target, compiled=False)
    assert offsets.tolist() == expected[0].tolist()
    assert neighbours.tolist() == expected[1].tolist()
    if np.all(source[1:] >= source[:-1]):
        assert neighbours is target


@needs_numba
def test_empty_graph_and_isolated_nodes(compiled):
    empty = np.zeros(0, dtype=np.int32)
    assert _graph.strong_components(0, empty, empty).tolist() == []
    assert _graph.strong_components(4, empty, empty).tolist() == [0, 1, 2, 3]
    assert _graph.reachable_from(4, empty, empty, [2]).tolist() == [False, False, True, False]
    terminal, first, present = _graph.terminal_summary(empty, empty, np.arange(4), empty, 2)
    assert terminal.tolist() == [0, 1, 2, 3] and first.tolist() == [0, 1, 2, 3]
    assert present.shape == (4, 2) and not present.any()
    assert _graph.occurring(empty, 3).tolist() == [False, False, False]


@needs_numba
def test_self_loops_only(compiled):
    nodes = np.array([2, 0, 2], dtype=np.int64)
    labels = _graph.strong_components(3, nodes, nodes)
    assert labels.tolist() == _graph.strong_components(3, nodes, nodes, compiled=False).tolist()
    terminal, _, present = _graph.terminal_summary(nodes, nodes, labels, np.array([1, 0, 0]), 2)
    assert len(terminal) == 3 and present.sum() == 3


@needs_numba
def test_long_paths_need_no_recursion(compiled):
    """A 300,000-node path (300,000 components, DFS as deep as the graph) and the same
    path closed into a ring (one component)."""
    n = 300_000
    source = np.arange(n - 1, dtype=np.int32)
    target = source + 1
    labels = _graph.strong_components(n, source, target)
    assert (labels == np.arange(n - 1, -1, -1)).all()    # the deepest completes first
    ring = _graph.strong_components(n, np.append(source, n - 1), np.append(target, 0))
    assert not ring.any()
    assert _graph.can_reach(n, source, target, [n - 1]).all()


@needs_numba
def test_bad_edges_are_errors_not_memory_faults(compiled):
    with pytest.raises(ValueError):
        _graph.strong_components(2, np.array([0, 2]), np.array([1, 0]))
    with pytest.raises(ValueError):
        _graph.strong_components(2, np.array([0, 1]), np.array([1, -1]))
    labels = np.array([0, 1])
    with pytest.raises(ValueError):
        _graph.terminal_summary(np.array([0, 1]), np.array([1, 5]), labels, np.array([0, 0]), 1)
    with pytest.raises(ValueError):
        _graph.terminal_summary(np.array([0, 1]), np.array([1, 1]), labels, np.array([0, 3]), 1)
    for use in (True, False):
        with pytest.raises(ValueError):
            _graph.occurring(np.array([0, 4]), 3, compiled=use)
        with pytest.raises(ValueError):
            _graph.reachable_from(2, np.array([0]), np.array([1]), [2], compiled=use)


def greedy_with_a_dead_transition():
    """test_properties' GREEDY philosophers plus a transition that never fires."""
    net = loads_net(GREEDY)
    net.add_place("spare", tokens=1)
    net.add_transition("never")
    for place in ("a_eats", "b_eats"):
        net.add_arc(place, "never")
    net.add_arc("never", "spare")
    return net


def properties_of(space):
    labels = strongly_connected_components(space)
    return (labels.tolist(), terminal_components(space, labels), dead_transitions(space),
            deadlocks(space).tolist(), deadlock_witness(space), non_live_transitions(space),
            non_live_witness(space, labels))


def assert_compiled_equals_pure(net, monkeypatch) -> None:
    space = reachability_graph(net)
    monkeypatch.setattr(_graph, "COMPILED_FROM_EDGES", 10**12)
    pure = properties_of(space)
    monkeypatch.setattr(_graph, "COMPILED_FROM_EDGES", 0)
    assert properties_of(space) == pure


@needs_numba
@pytest.mark.parametrize("net", [dining_philosophers(6), producer_consumer(4),
                                 greedy_with_a_dead_transition()],
                         ids=["philosophers", "producer_consumer", "greedy"])
def test_properties_agree_compiled_and_pure(net, monkeypatch):
    assert_compiled_equals_pure(net, monkeypatch)


@needs_numba
@examples(60)
@given(bounded_nets())
def test_properties_of_random_nets_agree_compiled_and_pure(monkeypatch, net):
    assert_compiled_equals_pure(net, monkeypatch)


def test_without_numba_the_pure_versions_run(monkeypatch):
    """No compiled loops (numba missing): every helper still answers, in pure Python."""
    monkeypatch.setattr(_graph, "COMPILED_FROM_EDGES", 0)
    monkeypatch.setattr(_graph, "_LOOPS", {})
    source, target = np.array([1, 0, 2]), np.array([0, 1, 2])
    assert _graph._compiled(10**9) is None
    assert _graph.strong_components(3, source, target).tolist() == [0, 0, 1]
    assert _graph.can_reach(3, source, target, [0]).tolist() == [True, True, False]
    assert _graph.occurring(target, 4).tolist() == [True, True, True, False]


def test_numba_disable_jit_takes_the_pure_versions():
    code = ("from petriflow.analysis import _graph; import numpy as np;"
            "assert _graph._compiled(10**9) is None;"
            "print(_graph.strong_components(2, np.array([0, 1]), np.array([1, 0])).tolist())")
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                          check=True)
    assert done.stdout.strip() == "[0, 0]"
