"""WF operators expand into plain P/T structure."""

import pytest

from petriflow.engine import enabled, fire
from petriflow.errors import NetStructureError
from petriflow.net import Net
from petriflow.workflow import add_operator, operator_groups, sink_places, source_places


def places(*ids):
    net = Net()
    for p in ids:
        net.add_place(p)
    return net


def test_and_split_is_one_transition_feeding_every_branch():
    """An AND-split marks all branches at once."""
    net = places("i", "a", "b")
    assert add_operator(net, "s", inputs=["i"], outputs=["a", "b"], split="and") == ["s"]
    assert fire(net, {"i": 1}, "s") == {"a": 1, "b": 1}


def test_xor_split_makes_one_transition_per_branch():
    """An XOR-split is a free choice between branches."""
    net = places("i", "a", "b")
    parts = add_operator(net, "s", inputs=["i"], outputs=["a", "b"], split="xor")
    assert enabled(net, {"i": 1}) == parts
    assert {p: fire(net, {"i": 1}, p) for p in parts} == {parts[0]: {"a": 1}, parts[1]: {"b": 1}}


def test_xor_join_fires_on_any_branch():
    """An XOR-join needs only one input branch."""
    net = places("a", "b", "o")
    parts = add_operator(net, "j", inputs=["a", "b"], outputs=["o"], join="xor")
    assert enabled(net, {"b": 1}) == [parts[1]]


def test_and_join_waits_for_every_branch():
    """An AND-join needs all input branches."""
    net = places("a", "b", "o")
    add_operator(net, "j", inputs=["a", "b"], outputs=["o"], join="and")
    assert enabled(net, {"a": 1}) == []
    assert enabled(net, {"a": 1, "b": 1}) == ["j"]


def test_xor_join_and_split_pairs_every_input_with_all_outputs():
    """XOR-join + AND-split: one part per input branch, each feeding all outputs."""
    net = places("a", "b", "x", "y")
    parts = add_operator(net, "op", inputs=["a", "b"], outputs=["x", "y"], join="xor", split="and")
    assert len(parts) == 2
    assert all(net.postset(p) == {"x": 1, "y": 1} for p in parts)


def test_operator_parts_are_grouped():
    """Every part remembers its operator group."""
    net = places("i", "a", "b")
    parts = add_operator(net, "s", inputs=["i"], outputs=["a", "b"], split="xor", action="plan")
    assert operator_groups(net) == {"s": parts}
    assert all(net.transitions[p].action == "plan" for p in parts)


def test_unknown_operator_kind_is_rejected():
    """Only and/xor are operator kinds."""
    with pytest.raises(NetStructureError, match="split must be one of"):
        add_operator(places("i"), "s", inputs=["i"], outputs=[], split="or")


def test_source_and_sink_places():
    """Source places have no producer, sink places no consumer."""
    net = places("i", "p", "o")
    add_operator(net, "a", inputs=["i"], outputs=["p"])
    add_operator(net, "b", inputs=["p"], outputs=["o"])
    assert source_places(net) == ["i"] and sink_places(net) == ["o"]
