"""The net model: building, querying, validation."""

import pytest

from petriflow.errors import NetStructureError, UnknownElementError
from petriflow.net import Net


def build():
    net = Net("n")
    net.add_place("p", tokens=2)
    net.add_place("q")
    net.add_transition("t", action="robot.move", params={"speed": 1})
    net.add_arc("p", "t", 2)
    net.add_arc("t", "q")
    return net


def test_initial_marking_collects_place_tokens():
    """Tokens given to add_place form the initial marking."""
    assert build().initial_marking == {"p": 2}


def test_preset_and_postset_carry_weights():
    """Presets and postsets map places to arc weights."""
    net = build()
    assert net.preset("t") == {"p": 2}
    assert net.postset("t") == {"q": 1}
    assert net.place_postset("p") == {"t": 2}
    assert net.place_preset("q") == {"t": 1}


def test_duplicate_ids_are_rejected():
    """A place and a transition cannot share an id."""
    net = build()
    with pytest.raises(NetStructureError, match="duplicate id 'p'"):
        net.add_transition("p")


def test_arc_between_two_places_is_rejected():
    """Arcs join a place and a transition."""
    net = build()
    with pytest.raises(NetStructureError, match="joins two places"):
        net.add_arc("p", "q")


def test_arc_to_unknown_node_names_it_with_hint():
    """A dangling arc names the missing node and a close match."""
    with pytest.raises(NetStructureError, match="unknown node 'tt'.*did you mean 't'"):
        build().add_arc("p", "tt")


@pytest.mark.parametrize("weight", [0, -1, 1.5, True])
def test_bad_arc_weights_are_rejected(weight):
    """Weights are whole numbers >= 1."""
    net = Net()
    net.add_place("p")
    net.add_transition("t")
    with pytest.raises(NetStructureError, match="weight"):
        net.add_arc("p", "t", weight)


def test_duplicate_arc_is_rejected():
    """The same arc cannot be added twice."""
    net = build()
    with pytest.raises(NetStructureError, match="duplicate arc"):
        net.add_arc("p", "t")


def test_unknown_transition_lookup_gives_hint():
    """Looking up a misspelt transition suggests the right one."""
    with pytest.raises(UnknownElementError, match="did you mean 't'"):
        build().transition("tt")


def test_subnet_membership_must_name_a_known_subnet():
    """Nodes can only join subnets the net declares."""
    net = Net()
    with pytest.raises(NetStructureError, match="unknown subnet"):
        net.add_place("p", subnet="robot")
    net.add_subnet("robot", "Robot", agent="r1")
    net.add_place("p", subnet="robot")
    assert net.nodes_of("robot") == (["p"], [])


def test_copy_is_independent():
    """Changing a copy leaves the original alone."""
    net = build()
    other = net.copy()
    other.add_place("r")
    other.add_arc("t", "r")
    assert "r" not in net.places and net.postset("t") == {"q": 1}
    assert other.structure() != net.structure()


def test_structure_ignores_graphics_meta():
    """Graphics kept in meta do not change the net's meaning."""
    a, b = Net(), Net()
    a.add_place("p", meta={"position": [1, 2]})
    b.add_place("p")
    assert a.structure() == b.structure()


def test_actions_lists_bound_transitions():
    """actions() maps each bound transition to its action name."""
    assert build().actions() == {"t": "robot.move"}
