"""Properties decided on small nets: verdicts, evidence, semantics at deadlocks, budgets, CLI."""

from __future__ import annotations

import json

import pytest

from petriflow.cli import main
from petriflow.engine import fire_sequence
from petriflow.errors import NetFormatError
from petriflow.io import load_net
from petriflow.io.yaml import dumps_net, loads_net
from petriflow.properties.check import check_properties
from petriflow.properties.yaml_props import parse_formula, parse_property

PASSAGE = """
petriflow: 1
net: passage
places:
  - {id: red_wait, tokens: 1}
  - {id: blue_wait, tokens: 1}
  - {id: free, tokens: 1}
  - red_in
  - blue_in
transitions:
  - {id: red_enter, in: [red_wait, free], out: [red_in]}
  - {id: red_leave, in: [red_in], out: [red_wait, free]}
  - {id: blue_enter, in: [blue_wait, free], out: [blue_in]}
  - {id: blue_leave, in: [blue_in], out: [blue_wait, free]}
properties:
  - {id: exclusive, never: "red_in + blue_in >= 2"}
  - {id: red_can_enter, ctl: "AG EF red_in == 1"}
  - {id: one_inside, bound: [red_in, blue_in]}
"""


def decide(net, *entries, **options):
    return {r["id"]: r for r in check_properties(net, [parse_property(e) for e in entries], **options)}


def test_mutual_exclusion_holds_and_fails_when_an_arc_is_removed():
    """The passage guards one robot at a time; without blue_enter's arc from free it does not,
    and the counterexample is a firing sequence into the forbidden marking."""
    net = loads_net(PASSAGE)
    results = {r["id"]: r for r in check_properties(net, net.properties)}
    assert [results[k]["verdict"] for k in ("exclusive", "red_can_enter", "one_inside")] == [True, True, 1]
    broken = loads_net(PASSAGE.replace("{id: blue_enter, in: [blue_wait, free]",
                                       "{id: blue_enter, in: [blue_wait]"))
    result = check_properties(broken, broken.properties)[0]
    assert result["verdict"] is False
    end = fire_sequence(broken, broken.initial_marking, result["witness"])
    assert end["red_in"] + end["blue_in"] == 2


def test_a_deadlock_has_no_next_marking_but_repeats_for_g_and_f():
    """EX p false and AX p true in a deadlock; EG p and LTL F G p hold in a p deadlock."""
    net = loads_net("""
petriflow: 1
places: [{id: a, tokens: 1}, b]
transitions: [{id: go, in: [a], out: [b]}]
""")
    got = decide(net, {"id": "ex", "ctl": "EX EX b == 1"}, {"id": "ax", "ctl": "AX AX a == 1"},
                 {"id": "eg", "ctl": "EF EG b == 1"}, {"id": "fg", "ltl": "F G b == 1"},
                 {"id": "stuck", "ltl": "F deadlock"})
    assert {k: r["verdict"] for k, r in got.items()} == {
        "ex": False, "ax": True, "eg": True, "fg": True, "stuck": True}


def test_an_ltl_counterexample_is_a_lasso_that_replays():
    """G F red_in fails: blue may pass forever; the cycle returns to the marking it starts in."""
    net = loads_net(PASSAGE)
    result = decide(net, {"id": "fair", "ltl": "G F red_in == 1"})["fair"]
    assert result["verdict"] is False
    start = fire_sequence(net, net.initial_marking, result["witness"])
    assert result["cycle"] and fire_sequence(net, start, result["cycle"]) == start
    assert "red_enter" not in result["cycle"]


def test_responds_and_exists_path_ltl():
    """Every blue entry is followed by a leave; some run lets red in infinitely often."""
    net = loads_net(PASSAGE)
    got = decide(net, {"id": "leaves", "responds": {"to": "blue_in >= 1", "with": "blue_in == 0"}},
                 {"id": "some", "ctl": "EF AG red_in == 1"})
    assert got["leaves"]["verdict"] is True           # inside, leaving is all blue can do
    assert got["some"]["verdict"] is False


def test_over_budget_is_undecided_unless_a_state_found_decides():
    """A state found before the limit decides EF p; nothing else is guessed."""
    net = loads_net("""
petriflow: 1
places: [{id: p, tokens: 1}, q]
transitions: [{id: t, in: [p], out: [p, q]}]
""")
    got = decide(net, {"id": "two", "reachable": "q >= 2"}, {"id": "many", "always": "q <= 1000"},
                 {"id": "live", "ctl": "AG EF q >= 1"}, max_states=50)
    assert got["two"]["verdict"] is True and got["two"]["witness"] == ["t", "t"]
    assert got["many"]["verdict"] is None and "unbounded" in got["many"]["reason"]
    assert got["live"]["verdict"] is None


def test_formula_errors_name_the_file_and_line(tmp_path):
    """A bad formula or an unknown place is one error naming the file, line and property."""
    bad = tmp_path / "bad.yaml"
    bad.write_text(PASSAGE.replace('never: "red_in + blue_in >= 2"', 'never: "red_in + >= 2"'))
    with pytest.raises(NetFormatError, match=r"bad\.yaml:\d+: property 'exclusive'"):
        load_net(bad)
    typo = tmp_path / "typo.yaml"
    typo.write_text(PASSAGE.replace('"red_in + blue_in >= 2"', '"red_inn + blue_in >= 2"'))
    with pytest.raises(NetFormatError, match=r"typo\.yaml:16: .*unknown place 'red_inn'.*red_in"):
        load_net(typo)


def test_properties_round_trip_through_yaml():
    """Saving a net keeps its properties: read back, they are the same formulas."""
    net = loads_net(PASSAGE)
    again = loads_net(dumps_net(net))
    assert [p.formula for p in again.properties] == [p.formula for p in net.properties]
    assert [p.bound for p in again.properties] == [p.bound for p in net.properties]


def test_the_text_syntax_reads_ctl_and_ltl():
    """Operators bind as documented: A[p U q], implication, negation, linear sums."""
    assert str(parse_formula("A[a >= 1 U b >= 1]")) == "A[a >= 1 U b >= 1]"
    assert str(parse_formula("E[!(a == 0) U 2*b - c < 3]")) == "E[!(a == 0) U 2*b - c < 3]"
    assert str(parse_formula("a >= 1 -> b >= 1")) == "(!(a >= 1) || b >= 1)"


def test_cli_check_properties(tmp_path, capsys):
    """`check NET --properties` decides the net's own; `--properties FILE` a file's; exit 1 on false."""
    path = tmp_path / "passage.yaml"
    path.write_text(PASSAGE)
    assert main(["check", str(path), "--properties", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [p["id"] for p in data["properties"]] == ["exclusive", "red_can_enter", "one_inside"]
    extra = tmp_path / "more.yaml"
    extra.write_text("properties:\n  - {id: fair, ltl: 'G F red_in == 1'}\n")
    assert main(["check", str(path), "--properties", str(extra)]) == 1
    out = capsys.readouterr().out
    assert out.startswith("fair: false") and "then forever:" in out
    extra.write_text("properties:\n  - {id: fair, ltl: 'G F red_in == '}\n")
    assert main(["check", str(path), "--properties", str(extra)]) == 2
    assert "more.yaml:2:" in capsys.readouterr().err


def test_deadlock_reachability_beyond_the_budget_by_stubborn_sets():
    """Over --max-states, EF deadlock is still decided: stubborn sets keep every deadlock."""
    from petriflow.classic import dining_philosophers

    net = dining_philosophers(12)
    got = decide(net, {"id": "stuck", "reachable": "deadlock"}, {"id": "free", "never": "deadlock"},
                 {"id": "other", "reachable": "eat_0 == 1"}, max_states=20)
    assert (got["stuck"]["verdict"], got["free"]["verdict"]) == (False, True)
    assert got["stuck"]["method"].startswith("stubborn sets")
    assert got["other"]["verdict"] is True       # found before the limit


def test_an_empty_place_bound_is_zero():
    """The contest writes ``<place-bound/>`` with no place (Sudoku-PT-AN01): the empty sum, 0."""
    from petriflow.properties.mcc_xml import parse_mcc_properties

    text = ('<property-set xmlns="http://mcc.lip6.fr/"><property><id>N-UpperBounds-00</id>'
            '<formula><place-bound/></formula></property></property-set>')
    result = check_properties(loads_net(PASSAGE), parse_mcc_properties(text, "UpperBounds.xml"))[0]
    assert (result["verdict"], result["witness"]) == (0, [])


def test_ltl_formulas_under_boolean_connectives_are_decided_one_by_one():
    """`A G F p || A F q`: each quantified LTL (or CTL) operand decided, the verdicts combined."""
    net = loads_net(PASSAGE)
    got = decide(net, {"id": "either", "ltl": "A(G(F(red_in >= 1))) || A(F(blue_in == 1))"},
                 {"id": "both", "ltl": "E(G(F(red_in >= 1))) && A(G(red_in + blue_in <= 1))"},
                 {"id": "not", "ltl": "!E(F(G(blue_in == 1)))"},
                 {"id": "alone", "ltl": "G(F(red_in >= 1))"})
    assert got["alone"]["verdict"] is False        # blue may take the passage forever
    assert (got["either"]["kind"], got["either"]["verdict"]) == ("boolean", False)
    assert got["both"]["verdict"] is True
    assert got["not"]["verdict"] is True
    with pytest.raises(NetFormatError, match="quantifiers"):
        parse_property({"id": "nested", "ltl": "G(A(F(red_in >= 1)))"})


TEAM = """
petriflow: 1
subnets:
""" + "".join(f"""- {{id: a{k}, state: worker, places: [{{id: a{k}_idle, tokens: 1}}, a{k}_busy], transitions: [
    {{id: a{k}_go, in: [a{k}_idle, lock], out: [a{k}_busy]}},
    {{id: a{k}_back, in: [a{k}_busy], out: [a{k}_idle, lock]}}]}}
""" for k in (1, 2, 3)) + """places: [{id: lock, tokens: 1}]
"""


def test_a_symmetric_safety_property_beyond_the_budget_is_decided_on_the_quotient():
    """Three interchangeable workers, a budget of 2 markings (the full space has 4, the
    quotient 2): a predicate every permutation keeps is decided; one naming a worker only
    where the formula with its orbit in its place settles it."""
    net = loads_net(TEAM)
    got = decide(net, {"id": "mutex", "never": "a1_busy + a2_busy + a3_busy >= 2"},
                 {"id": "pairs", "always": "a1_busy + a2_busy <= 1 && a2_busy + a3_busy <= 1 && a1_busy + a3_busy <= 1"},
                 {"id": "first", "always": "a1_busy <= 1"}, {"id": "twice", "reachable": "a1_busy >= 2"},
                 {"id": "never_busy", "always": "a1_busy <= 0"}, max_states=2)
    assert got["mutex"]["verdict"] is True and "symmetry" in got["mutex"]["method"]
    assert got["pairs"]["verdict"] is True
    assert got["first"]["verdict"] is True and "stronger formula" in got["first"]["method"]
    assert got["twice"]["verdict"] is False and "weaker formula" in got["twice"]["method"]
    # false, but the quotient cannot tell: left to the other methods (a marking found)
    assert got["never_busy"]["verdict"] is False and "symmetry" not in got["never_busy"]["method"]


def test_a_symmetric_violation_on_the_quotient_has_a_concrete_witness():
    net = loads_net(TEAM.replace("{id: lock, tokens: 1}", "{id: lock, tokens: 2}"))
    got = decide(net, {"id": "mutex", "never": "a1_busy + a2_busy + a3_busy >= 2"}, max_states=4)
    assert got["mutex"]["verdict"] is False
    end = fire_sequence(net, net.initial_marking, got["mutex"]["witness"])
    assert sum(end.get(f"a{k}_busy", 0) for k in (1, 2, 3)) >= 2
