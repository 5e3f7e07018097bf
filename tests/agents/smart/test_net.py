"""The SMART nets: the corrected one loads, binds, is a sound WF-net, and matches its
PNML copy; the paper's net as published is not a WF-net."""

from __future__ import annotations

from collections import deque

import networkx as nx
import pytest

from petriflow.engine import enabled, fire
from petriflow.io import load_net
from petriflow.runtime.binding import bind
from petriflow.workflow import sink_places, source_places
from tests.agents.smart.conftest import SMART

PAPER_PLACES = [f"P{k}" for k in range(1, 12)]
PAPER_TRANSITIONS = [f"T{k}" for k in range(1, 10)]


def reachable(net, start):
    """Every marking reachable from ``start`` (the nets are small and safe), each action
    ending ``ok`` or with any outcome the net routes (a failed re-plan, say)."""
    seen, queue = {start}, deque([start])
    while queue:
        marking = queue.popleft()
        for t in enabled(net, marking):
            for outcome in [None, *net.outcomes(t)]:
                after = fire(net, marking, t, outcome)
                if after not in seen:
                    seen.add(after)
                    queue.append(after)
    return seen


def is_wf_net(net) -> bool:
    """One source place i, one sink place o, every node on a path from i to o."""
    sources, sinks = source_places(net), sink_places(net)
    if len(sources) != 1 or len(sinks) != 1:
        return False
    graph = nx.DiGraph()
    graph.add_nodes_from([*net.places, *net.transitions])
    graph.add_edges_from((a.source, a.target) for a in net.arcs)
    on_path = nx.descendants(graph, sources[0]) & nx.ancestors(graph, sinks[0])
    return on_path | {sources[0], sinks[0]} == set(graph.nodes)


def sound(net) -> bool:
    """Classical soundness by state-space search: from every marking reachable from [i]
    the final marking is reachable, it is reached only properly, no transition is dead."""
    start, final = net.initial_marking, net.final_marking
    markings = reachable(net, start)
    can_finish = all(final in reachable(net, m) for m in markings)
    proper = all(m == final or not all(m.get(p, 0) >= n for p, n in final.items()) for m in markings)
    fired = {t for m in markings for t in enabled(net, m)}
    return can_finish and proper and fired == set(net.transitions)


@pytest.mark.parametrize("name", ["smart.yaml", "smart.pnml", "reinsertion.yaml", "crossing.yaml"])
def test_net_loads_and_binds_to_registered_actions(name):
    """Every transition's action and guard resolve and its parameters check."""
    net = load_net(SMART / name)
    bound = bind(net, path=name)
    assert set(bound.actions()) == {t for t, tr in net.transitions.items() if tr.action}


def test_smart_net_keeps_the_papers_places_and_transitions(net):
    """P1..P11 and T1..T9 keep the paper's meanings; T5 is the AND-split."""
    assert set(PAPER_PLACES) <= set(net.places)
    assert set(PAPER_TRANSITIONS) <= set(net.transitions)
    assert net.place("P7").label == "crashed robot waits for help"
    assert net.transition("T5").operator is not None and net.transition("T5").operator.split == "and"
    assert {"P7", "P8"} <= set(net.postset("T5"))


def test_smart_net_subnets_are_the_papers_agents(net):
    """One subnet per agent: camera, image processing, decision maker, helper, fallen robot."""
    agents = {s.id: s.agent for s in net.subnets.values()}
    assert agents == {"camera": "camera", "image": "image", "decision": "decision",
                      "helper": "robot3l", "fallen": "robot4l"}
    assert net.transition("T6").subnet == "fallen" and net.transition("T8").subnet == "helper"


def test_smart_net_is_a_wf_net_with_source_i_and_sink_o(net):
    """Structural check: source place i, sink place o, every node on a path from i to o."""
    assert source_places(net) == ["i"] and sink_places(net) == ["o"]
    assert is_wf_net(net)
    assert net.initial_marking == {"i": 1} and net.final_marking == {"o": 1}


def test_t0_puts_the_papers_initial_marking(net):
    """T0 puts M0 = (P1, P5) of the paper (plus the task token P13 and the latest-scene
    place S)."""
    assert fire(net, net.initial_marking, "T0") == {"P1": 1, "P5": 1, "P13": 1, "S": 1}


@pytest.mark.parametrize("name", ["smart.yaml", "reinsertion.yaml", "crossing.yaml"])
def test_scenario_nets_are_sound(name):
    """Option to complete, proper completion, no dead transitions (guards ignored)."""
    assert sound(load_net(SMART / name))


def test_paper_net_is_not_a_wf_net_and_strands_tokens():
    """The published net has no source or sink place, and its only complete run leaves
    the camera and processing standby tokens behind (the README's witness)."""
    paper = load_net(SMART / "smart-paper.yaml")
    assert not is_wf_net(paper)
    assert source_places(paper) == [] and sink_places(paper) == []
    witness = ["T1", "T3", "T4", "T5", "T7", "T8", "T6", "T9"]
    marking = paper.initial_marking
    for t in witness:
        marking = fire(paper, marking, t)
    assert marking == {"P2": 1, "P5": 1} and enabled(paper, marking) == []


def test_pnml_copy_equals_the_yaml_net(net):
    """nets/smart/smart.pnml is `petriflow export -f pnml` of smart.yaml, bindings included."""
    copy = load_net(SMART / "smart.pnml")
    assert copy.structure() == net.structure()
    for t in net.transitions:
        mine, theirs = net.transition(t), copy.transition(t)
        assert (mine.action, mine.params, mine.guard, mine.priority) == (
            theirs.action, theirs.params, theirs.guard, theirs.priority)


def test_analysis_says_sound_where_available(net):
    """`petriflow check`'s analysis agrees, when the analysis package is installed."""
    soundness = pytest.importorskip("petriflow.analysis.soundness")
    check = getattr(soundness, "check_soundness", None)
    if check is None:
        pytest.skip("petriflow.analysis has no check_soundness")
    assert check(net).sound
    assert not check(load_net(SMART / "smart-paper.yaml")).sound
