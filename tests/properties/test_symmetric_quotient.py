"""CTL and LTL on the symmetry quotient give the full state space's verdicts.

On small shipped nets with interchangeable agents, every property of the net and
generated formulas (symmetric atoms: the agents' places summed, shared places,
``enabled`` of whole transition orbits, ``deadlock``; and atoms of one agent, which the
quotient only bounds) are decided on the quotient and on the full reachability graph:
a verdict of the quotient is the full graph's, every formula with symmetric atoms only
is decided, and its witnesses and cycles fire from the initial marking.
"""

from __future__ import annotations

import random

import pytest

from petriflow.analysis.check_result import explored_marking
from petriflow.analysis.symmetry import find_symmetries, transition_orbits
from petriflow.engine import CompiledNet, enabled, fire_sequence
from petriflow.io import load_net
from petriflow.properties import language as lang
from petriflow.properties.check import check_properties
from petriflow.properties.language import Compare, Constant, Deadlock, Fireable, Linear, Not, Property
from petriflow.properties.symmetric import decide_on_quotient, symmetric
from petriflow.properties.yaml_props import parse_formula
from petriflow.workflow import workflow_structure
from tests.conftest import NETS

SMALL = ["passage/passage.yaml", "swarm/swarm-3.yaml", "bidding/bidding-autonomous-2.yaml",
         "bus/bus-algorithm1-3.yaml", "comm/comm-centralised-2.yaml"]


def atom_pool(net):
    """``(symmetric atoms, atoms of one agent)`` of the net."""
    compiled = CompiledNet(net)
    groups = find_symmetries(net)
    in_block = {int(p) for g in groups for p in g.blocks.reshape(-1)}
    same, one = [Deadlock(), Constant(True)], []
    for group in groups:
        for column in range(group.blocks.shape[1]):
            places = [compiled.places[p] for p in group.blocks[:, column]]
            for bound in range(group.size + 1):
                same.append(Compare(">=", Linear.of_places(places), Linear.constant(bound)))
            one.append(Compare(">=", Linear.of_places(places[:1]), Linear.constant(1)))
            one.append(Compare("==", Linear.of_places(places[-1:]), Linear.constant(0)))
    for p, place in enumerate(compiled.places):
        if p not in in_block:
            same.append(Compare(">=", Linear.of_places([place]), Linear.constant(1)))
    orbit = transition_orbits(compiled, groups)
    origins = [o for o, _ in compiled.origin]
    for root in sorted(set(orbit.tolist())):
        names = tuple(dict.fromkeys(origins[r] for r in range(len(origins)) if orbit[r] == root))
        same.append(Fireable(names))
        if len(names) > 1:
            one.append(Fireable(names[:1]))
    return same, one


def random_formula(rng, pool, depth, ctl=True):
    """A CTL formula (each temporal operator under ``A``/``E``), or an LTL path formula."""
    if depth == 0 or rng.random() < 0.2:
        return rng.choice(pool)
    kind = rng.randrange(10)
    operands = [random_formula(rng, pool, depth - 1, ctl) for _ in range(2)]
    if kind < 3:
        return [Not(operands[0]), lang.And(tuple(operands)), lang.Or(tuple(operands))][kind]
    path = lang.Until(*operands) if kind == 3 else \
        rng.choice([lang.Next, lang.Finally, lang.Globally])(operands[0])
    return rng.choice([lang.AllPaths, lang.ExistsPath])(path) if ctl else path


def formulas(net, seed):
    rng = random.Random(seed)
    same, one = atom_pool(net)
    found = [p.formula for p in net.properties if p.formula is not None]
    found += [random_formula(rng, same, 3) for _ in range(40)]
    found += [random_formula(rng, same + one, 3) for _ in range(40)]
    found += [lang.AllPaths(random_formula(rng, same, 3, ctl=False)) for _ in range(6)]
    found += [lang.ExistsPath(random_formula(rng, same + one, 3, ctl=False)) for _ in range(6)]
    return found


def replays(net, start, result):
    """The witness fires from the start; a cycle comes back to the marking it starts in."""
    reached = fire_sequence(net, start, result.get("witness") or [])
    if "cycle" in result:
        if result["cycle"]:
            assert fire_sequence(net, reached, result["cycle"]) == reached
        else:
            assert not enabled(net, reached)


@pytest.mark.parametrize("relative", SMALL)
def test_the_quotient_gives_the_full_graphs_verdicts(relative):
    """Every verdict on the quotient is the full graph's; symmetric formulas are all decided."""
    net = load_net(NETS / relative)
    start = explored_marking(net, workflow_structure(net))
    groups = find_symmetries(net)
    assert groups
    cases = [f for f in formulas(net, seed=len(relative))
             if Property(id="x", formula=f).kind in ("reachability", "ctl", "ltl")]
    full = check_properties(net, [Property(id=str(k), formula=f) for k, f in enumerate(cases)])
    store: dict = {}
    decided_by_bounds = 0
    for formula, expected in zip(cases, full):
        kind = Property(id="x", formula=formula).kind
        got = decide_on_quotient(net, formula, kind, start, max_states=100_000, store=store)
        exact = all(symmetric(atom, groups, net) for atom in lang.atoms(formula))
        if exact:
            assert got is not None, formula
        if got is None:
            continue
        decided_by_bounds += not exact
        assert got["verdict"] == expected["verdict"], (formula, got, expected)
        assert "symmetry quotient" in got["method"]
        replays(net, start, got)
    assert store["space"].num_states < full[0].get("states", float("inf"))
    assert decided_by_bounds > 0


@pytest.mark.slow
@pytest.mark.parametrize("relative", ["bidding/bidding-autonomous-3.yaml", "bidding/bidding-autonomous-4.yaml",
                                      "comm/comm-centralised-3.yaml"])
def test_the_quotient_gives_the_full_graphs_verdicts_on_larger_teams(relative):
    """As above, with three and four agents."""
    test_the_quotient_gives_the_full_graphs_verdicts(relative)


def test_a_formula_the_bounds_do_not_settle_is_left_to_the_other_methods():
    """An atom of one agent whose orbit bounds prove nothing: the quotient says nothing,
    and over budget the verdict stays undecided, while a symmetric one is decided."""
    net = load_net(NETS / "bidding/bidding-autonomous-2.yaml")
    start = explored_marking(net, workflow_structure(net))
    place = next(p for p in net.places if p.startswith("box_robot1"))
    lonely = parse_formula(f"EF({place} >= 1 && EX({place} == 0))")
    assert decide_on_quotient(net, lonely, "ctl", start, max_states=10_000, store={}) is None
    both = parse_formula(f"AG(EF(o == 1)) && EF({place} + {place.replace('robot1', 'robot2')} >= 1)")
    results = {r["id"]: r for r in check_properties(net, [
        Property(id="lonely", formula=lonely), Property(id="both", formula=both)], max_states=400)}
    assert results["lonely"]["verdict"] is None and results["lonely"]["reason"].startswith("state space over")
    assert results["both"]["verdict"] is True and "symmetry quotient" in results["both"]["method"]


def test_a_cycle_on_the_quotient_becomes_a_concrete_lasso():
    """EG on a net whose quotient cycle permutes the agents: the concrete cycle closes."""
    net = load_net(NETS / "swarm/swarm-3.yaml")
    start = explored_marking(net, workflow_structure(net))
    result = decide_on_quotient(net, parse_formula("EG(!deadlock)"), "ctl", start,
                                max_states=10_000, store={})
    full = check_properties(net, [Property(id="eg", formula=parse_formula("EG(!deadlock)"))])[0]
    assert result["verdict"] == full["verdict"]
    if result["verdict"]:
        assert result["cycle"]
    replays(net, start, result)


TEAM = "petriflow: 1\nplaces: [{id: lock, tokens: 1}]\nsubnets:\n" + "".join(
    f"- {{id: a{k}, state: worker, places: [{{id: a{k}_idle, tokens: 1}}, a{k}_busy], transitions: ["
    f"{{id: a{k}_go, in: [a{k}_idle, lock], out: [a{k}_busy]}}, "
    f"{{id: a{k}_back, in: [a{k}_busy], out: [a{k}_idle, lock]}}]}}\n" for k in (1, 2, 3))


@pytest.mark.parametrize("text", [
    "AG(a1_busy == 0)",
    ("AG((a1_busy <= 0 || EX(a1_busy == 0 && lock == 0)) && (a2_busy <= 0 || EX(a2_busy == 0 && lock == 0))"
     " && (a3_busy <= 0 || EX(a3_busy == 0 && lock == 0)))"),
])
def test_what_the_bounds_leave_is_decided_on_the_quotient_by_the_other_agents(text):
    """Three workers, one lock: false, and neither bound says so; the quotient that
    keeps the named worker apart (one conjunct per orbit under AG) does, with the firing."""
    from petriflow.io.yaml import loads_net

    net = loads_net(TEAM)
    formula = parse_formula(text)
    got = decide_on_quotient(net, formula, "ctl", net.initial_marking, max_states=100, store={})
    full = check_properties(net, [Property(id="x", formula=formula)])[0]
    assert full["verdict"] is False and got["verdict"] is False
    assert "leaves unnamed" in got["method"] and "a1 kept apart" in got["method"]
    assert got["witness"] == ["a1_go"]
    assert ("one per orbit" in got["method"]) == ("&&" in text)


def test_a_quotient_cycle_that_swaps_the_agents_is_replayed_until_it_closes():
    """Two workers pass one job back and forth: on the quotient one step is a cycle; the
    concrete lasso needs two passes of it, and fires back to where it starts."""
    from petriflow.io.yaml import loads_net

    net = loads_net("petriflow: 1\nplaces: [{id: lock, tokens: 1}]\nsubnets:\n" + "".join(
        f"- {{id: a{k}, state: worker, places: [{{id: a{k}_idle, tokens: 1}}, a{k}_busy], transitions: ["
        f"{{id: a{k}_go, in: [a{k}_idle, lock], out: [a{k}_busy]}}, "
        f"{{id: a{k}_pass_a{j}, in: [a{k}_busy, a{j}_idle], out: [a{k}_idle, a{j}_busy]}}]}}\n"
        for k, j in ((1, 2), (2, 1))))
    got = decide_on_quotient(net, parse_formula("E(F(G(lock == 0)))"), "ltl", net.initial_marking,
                             max_states=100, store={})
    assert got["verdict"] is True and len(got["cycle"]) == 2
    assert set(got["cycle"]) == {"a1_pass_a2", "a2_pass_a1"}
    replays(net, net.initial_marking, got)
