"""Stubborn sets for properties give the full search's verdicts, with evidence that replays.

Small random nets (seeded) and handmade ones: every ``EF p`` decided by the up-set
search (:func:`~petriflow.properties.partial_order.reach_stubborn`) and every LTL
formula without ``X`` decided by the reduced product
(:func:`~petriflow.properties.ltl.check_ltl_on_net` with ``stubborn=True``) agree with
the reachability graph; the contest's formulas with the reduction forced on are in
tests/properties/test_mcc_oracle.py.
"""

from __future__ import annotations

import random

import pytest

from petriflow.analysis.exploration import StateSpaceLimit, UnboundedNetError
from petriflow.analysis.reachability import reachability_graph
from petriflow.engine import fire_sequence
from petriflow.io.yaml import loads_net
from petriflow.properties.check import check_properties
from petriflow.properties.kripke import Kripke
from petriflow.properties.language import (
    And, Compare, Deadlock, Finally, Fireable, Globally, Linear, Next, Not, Or, Property, Until
)
from petriflow.properties.ltl import check_ltl, check_ltl_on_net
from petriflow.properties.partial_order import reach_stubborn


def _random_net(rng: random.Random):
    places = [f"p{i}" for i in range(rng.randint(3, 6))]
    lines = ["petriflow: 1", "places:"]
    for p in places:
        lines.append(f"  - {{id: {p}, tokens: {rng.choice([0, 0, 1, 1, 2])}}}")
    lines.append("transitions:")
    for t in range(rng.randint(3, 7)):
        ins = rng.sample(places, rng.randint(1, 2))
        outs = rng.sample(places, rng.randint(0, 2))
        lines.append(f"  - {{id: t{t}, in: [{', '.join(ins)}], out: [{', '.join(outs)}]}}")
    return loads_net("\n".join(lines) + "\n"), places


def _random_predicate(rng: random.Random, places, transitions, depth: int = 2):
    roll = rng.random()
    if depth == 0 or roll < 0.5:
        kind = rng.random()
        if kind < 0.6:
            terms = Linear.of_places(rng.sample(places, rng.randint(1, 2)))
            return Compare(rng.choice(["<=", ">=", "==", "!=", "<", ">"]), terms,
                           Linear.constant(rng.randint(0, 2)))
        if kind < 0.9:
            return Fireable(tuple(rng.sample(transitions, rng.randint(1, 2))))
        return Deadlock()
    if roll < 0.65:
        return Not(_random_predicate(rng, places, transitions, depth - 1))
    connective = And if roll < 0.85 else Or
    return connective(tuple(_random_predicate(rng, places, transitions, depth - 1) for _ in range(2)))


def _random_ltl(rng: random.Random, places, transitions):
    p = _random_predicate(rng, places, transitions, 1)
    q = _random_predicate(rng, places, transitions, 1)
    return rng.choice([Globally(p), Finally(p), Globally(Finally(p)), Finally(Globally(p)),
                       Until(p, q), Globally(Or((Not(p), Finally(q)))), Not(Until(p, q))])


def _nets(count: int, seed: int):
    rng = random.Random(seed)
    made = 0
    while made < count:
        net, places = _random_net(rng)
        try:
            space = reachability_graph(net, max_states=2000)
        except (StateSpaceLimit, UnboundedNetError):
            continue
        made += 1
        yield rng, net, places, Kripke(space)


@pytest.mark.parametrize("seed", range(4))
def test_the_up_set_search_finds_what_the_graph_holds(seed):
    for rng, net, places, kripke in _nets(25, seed):
        for _ in range(6):
            goal = _random_predicate(rng, places, list(net.transitions))
            found = reach_stubborn(net, net.initial_marking, goal, max_states=10_000)
            assert found.found == bool(kripke.holds(goal).any()), (net.id, str(goal))
            if found.found:
                end = fire_sequence(net, net.initial_marking, found.witness)
                assert kripke.holds(goal)[kripke.space.index(end)], str(goal)


@pytest.mark.parametrize("seed", range(4))
def test_the_reduced_ltl_product_gives_the_full_verdicts(seed):
    for rng, net, places, kripke in _nets(20, seed):
        for _ in range(5):
            formula = _random_ltl(rng, places, list(net.transitions))
            full, _ = check_ltl(kripke, formula)
            stats: dict = {}
            reduced, lasso = check_ltl_on_net(net, net.initial_marking, formula, max_states=10_000,
                                              stubborn=True, stats=stats)
            assert reduced == full, str(formula)
            assert stats["reduced"] is True
            if lasso is not None:
                start = fire_sequence(net, net.initial_marking, lasso["witness"])
                assert fire_sequence(net, start, lasso["cycle"]) == start


# Two independent parts: a cycle a <-> a2 that never matters, and b -> b2 that does.
# A reduction that kept choosing the cycle (invisible, always enabled) would never fire
# ``tb``: the stack proviso expands the marking that closes the cycle.
IGNORING = """
petriflow: 1
places: [{id: a, tokens: 1}, a2, {id: b, tokens: 1}, b2]
transitions:
  - {id: go, in: [a], out: [a2]}
  - {id: back, in: [a2], out: [a]}
  - {id: tb, in: [b], out: [b2]}
"""


def test_the_stack_proviso_keeps_a_postponed_transition():
    net = loads_net(IGNORING)
    b2 = Compare("==", Linear.of_places(["b2"]), Linear.constant(0))
    stats: dict = {}
    verdict, lasso = check_ltl_on_net(net, net.initial_marking, Globally(b2), max_states=100,
                                      stubborn=True, stats=stats)
    assert (verdict, stats["reduced"]) == (False, True)
    assert "tb" in lasso["witness"] + lasso["cycle"]
    # the cycle alone is invisible: fewer markings than the 4 of the full search suffice
    # to see that b2 stays empty while only ``go``/``back`` fire, and ``F b2 == 1`` fails
    verdict, _ = check_ltl_on_net(net, net.initial_marking, Finally(Not(b2)), max_states=100,
                                  stubborn=True)
    assert verdict is False


def test_the_up_set_goes_straight_to_the_goal():
    """Reaching ``b2 == 1`` needs ``tb``: the up-set holds only it, so the invisible cycle
    is never explored (2 markings of the 4), and the witness is ``tb`` alone; ``a2 >= 1
    && b2 == 1`` needs both parts (3 markings)."""
    net = loads_net(IGNORING)
    b2 = Compare("==", Linear.of_places(["b2"]), Linear.constant(1))
    found = reach_stubborn(net, net.initial_marking, b2, max_states=10)
    assert (found.found, found.witness, found.states) == (True, ["tb"], 2)
    both = And((Compare(">=", Linear.of_places(["a2"]), Linear.constant(1)), b2))
    found = reach_stubborn(net, net.initial_marking, both, max_states=10)
    assert found.found and sorted(found.witness) == ["go", "tb"] and found.states == 3


def test_formulas_with_next_keep_the_full_search():
    net = loads_net(IGNORING)
    stats: dict = {}
    formula = Next(Compare(">=", Linear.of_places(["a2"]), Linear.constant(1)))
    check_ltl_on_net(net, net.initial_marking, formula, max_states=100, stubborn=True, stats=stats)
    assert stats["reduced"] is False


def test_independent_workers_are_reduced_to_one_interleaving():
    """n independent workers: the full graph has 2**n markings; the up-set search for all
    of them done stores at most one marking per worker and step (every worker raises the
    count, so each marking on the way keeps all of them), and ``AG`` of a predicate on
    one worker visits only that worker's move."""
    n = 10
    places = ", ".join(f"{{id: w{i}, tokens: 1}}, d{i}" for i in range(n))
    moves = ", ".join(f"{{id: t{i}, in: [w{i}], out: [d{i}]}}" for i in range(n))
    net = loads_net(f"petriflow: 1\nplaces: [{places}]\ntransitions: [{moves}]\n")
    done = Compare("==", Linear.of_places([f"d{i}" for i in range(n)]), Linear.constant(n))
    found = reach_stubborn(net, net.initial_marking, done, max_states=100)
    assert (found.found, len(found.witness)) == (True, n) and found.states <= n * (n + 1) // 2 + 1
    one = Compare("<=", Linear.of_places(["d0"]), Linear.constant(0))
    assert reach_stubborn(net, net.initial_marking, Not(one), max_states=100).states == 2
    results = check_properties(net, [Property("never", Globally(Compare("<=", Linear.of_places(["d3"]),
                                                                          Linear.constant(0))))],
                               reduction="stubborn")
    assert results[0]["verdict"] is False and "stubborn sets" in results[0]["method"]


def test_an_unknown_reduction_is_refused():
    net = loads_net(IGNORING)
    with pytest.raises(ValueError, match="unknown reduction 'partial'"):
        check_properties(net, [], reduction="partial")


def test_reset_arcs_are_explored_in_full():
    # t empties b as it fires (a cancellation region): no stubborn set is taken
    net = loads_net("petriflow: 1\nplaces: [{id: a, tokens: 1}, {id: b, tokens: 2}, c]\n"
                    "transitions: [{id: t, in: [a], out: [c], cancels: [b]}]\n")
    found = reach_stubborn(net, net.initial_marking,
                           Compare("==", Linear.of_places(["b"]), Linear.constant(0)), max_states=10)
    assert (found.found, found.reduced, found.witness, found.states) == (True, False, ["t"], 2)


def test_cli_method_chooses_the_reduction(tmp_path, capsys):
    """`check --properties --method stubborn` decides by stubborn sets and names them in
    `method`; `--method explicit` on the reachability graph; the verdicts agree."""
    import json

    from petriflow.cli import main

    path = tmp_path / "split.yaml"
    path.write_text(IGNORING + "properties:\n  - {id: b_done, reachable: 'b2 == 1'}\n"
                    "  - {id: b_stays, ltl: 'G b2 == 0'}\n")
    methods = {}
    for method in ("stubborn", "explicit"):
        assert main(["check", str(path), "--properties", "--json", "--method", method]) == 1
        data = json.loads(capsys.readouterr().out)["properties"]
        assert [p["verdict"] for p in data] == [True, False]
        methods[method] = [p["method"] for p in data]
    assert all("stubborn sets" in m for m in methods["stubborn"])
    assert not any("stubborn" in m for m in methods["explicit"])
