"""The on-the-fly LTL products and the whole product agree on every contest LTL formula.

Both searches of :func:`petriflow.properties.ltl.check_ltl`, and
:func:`~petriflow.properties.ltl.check_ltl_on_net` (markings generated from the net as
the search goes), run on the 8 public contest
models' LTLCardinality and LTLFireability formulas (256): the verdicts must be equal
(and the contest's, which tests/properties/test_mcc_oracle.py checks for the default),
and every lasso the on-the-fly searches give must replay: its prefix fireable from the
initial marking, its cycle fireable from there and back to the same marking.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from petriflow.analysis import accepting_lasso
from petriflow.analysis.reachability import reachability_graph
from petriflow.engine import fire_sequence
from petriflow.io import load_net
from petriflow.properties.kripke import Kripke
from petriflow.properties.ltl import check_ltl, check_ltl_on_net
from petriflow.properties.mcc_xml import load_mcc_properties
from tests.conftest import ORACLE

MCC = ORACLE / "mcc"
MODELS = sorted(p.name for p in MCC.iterdir() if (p / "formulas" / "oracle.json").is_file())


@pytest.mark.parametrize("category", ("LTLCardinality", "LTLFireability"))
@pytest.mark.parametrize("model", MODELS)
def test_both_products_give_the_same_verdicts(model, category):
    net = load_net(MCC / model / "model.pnml")
    kripke = Kripke(reachability_graph(net))
    properties = load_mcc_properties(MCC / model / "formulas" / f"{category}.xml")
    expected = json.loads((MCC / model / "formulas" / "oracle.json").read_text())[category]
    for prop in properties:
        fast, lasso = check_ltl(kripke, prop.formula, "on-the-fly")
        whole, _ = check_ltl(kripke, prop.formula, "whole")
        lazy, lazy_lasso = check_ltl_on_net(net, net.initial_marking, prop.formula, max_states=10 ** 6)
        assert fast == whole == lazy, prop.id
        if lazy_lasso is not None:
            start = fire_sequence(net, net.initial_marking, lazy_lasso["witness"])
            assert fire_sequence(net, start, lazy_lasso["cycle"]) == start, prop.id
        assert ("TRUE" if fast else "FALSE") == str(expected[prop.id]), prop.id
        if lasso is not None:
            start = fire_sequence(net, net.initial_marking, lasso["witness"])
            assert fire_sequence(net, start, lasso["cycle"]) == start, prop.id


def test_an_unknown_product_search_is_refused():
    from petriflow.classic import dining_philosophers
    from petriflow.properties.language import Constant

    with pytest.raises(ValueError, match="unknown product search 'lazy'"):
        check_ltl(Kripke(reachability_graph(dining_philosophers(2))), Constant(True), "lazy")


def test_the_search_stops_at_the_first_accepting_cycle():
    """A chain 0 -> 1 -> ... -> 99 -> 0 with an automaton accepting everywhere: the lasso
    closes when the depth-first search first returns to the start, having seen every
    state; an accepting self-loop on state 0 is found after one state."""
    n = 100
    offsets, targets = np.arange(n + 1), (np.arange(n) + 1) % n
    everywhere = np.ones((1, n), dtype=bool)
    one_state = np.array([0, 1]), np.array([0]), np.array([True])
    prefix, cycle, explored = accepting_lasso(offsets, targets, everywhere, *one_state, 0)
    assert (prefix, cycle, explored) == ([], list(range(n)), n)
    offsets, targets = np.concatenate([[0], np.arange(n) + 2]), np.concatenate([[0], targets])
    prefix, cycle, explored = accepting_lasso(offsets, targets, everywhere, *one_state, 0)
    assert (prefix, cycle, explored) == ([], [0], 1)


def test_the_search_from_the_net_stops_at_its_budget_or_at_a_shallow_counterexample():
    """An unbounded net has no reachability graph; a counterexample near M0 (a lasso of
    ``u`` and ``v``, beside ``t`` that pumps tokens into ``b``) is found anyway, and a
    property that holds on every run runs into the budget."""
    from petriflow.analysis.exploration import StateSpaceLimit
    from petriflow.properties.yaml_props import parse_property

    net = _pump_beside_a_cycle()
    violated = parse_property({"id": "v", "ltl": "F G a == 1"}).formula
    verdict, lasso = check_ltl_on_net(net, net.initial_marking, violated, max_states=50)
    assert verdict is False and "u" in lasso["witness"] + lasso["cycle"]
    start = fire_sequence(net, net.initial_marking, lasso["witness"])
    assert fire_sequence(net, start, lasso["cycle"]) == start
    with pytest.raises(StateSpaceLimit):
        check_ltl_on_net(net, net.initial_marking, parse_property({"id": "s", "ltl": "G F a == 1"}).formula,
                         max_states=50)


def test_check_properties_decides_ltl_on_an_unbounded_net_from_the_net():
    from petriflow.properties.check import check_properties
    from petriflow.properties.yaml_props import parse_property

    net = _pump_beside_a_cycle()
    results = check_properties(net, [parse_property({"id": "v", "ltl": "F G a == 1"}),
                                     parse_property({"id": "s", "ltl": "G F a == 1"})],
                               max_states=1000)
    assert results[0]["verdict"] is False and "generated on the fly" in results[0]["method"]
    start = fire_sequence(net, net.initial_marking, results[0]["witness"])
    assert fire_sequence(net, start, results[0]["cycle"]) == start
    assert results[1]["verdict"] is None and results[1]["reason"].startswith("unbounded net")


def _pump_beside_a_cycle():
    """``u`` and ``v`` move a token between ``a`` and ``c``; ``t`` pumps tokens into ``b``."""
    from petriflow.net import Net

    net = Net()
    for place in ("a", "b", "c"):
        net.add_place(place)
    for transition in ("u", "v", "t"):
        net.add_transition(transition)
    for source, target in (("a", "u"), ("u", "c"), ("c", "v"), ("v", "a"), ("a", "t"), ("t", "a"),
                           ("t", "b")):
        net.add_arc(source, target)
    net.set_initial_marking({"a": 1})
    return net
