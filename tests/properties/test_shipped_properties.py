"""The scenarios' nets state what their missions guarantee, and `check` proves it.

Every shipped net with a ``properties:`` list (generated nets get theirs from their
builder) has every property decided and true; the 20-robot bidding net's state space is beyond
the default budget, and its three properties are proved on the symmetry quotient.
A net with one arc removed makes one of them fail, with a counterexample that fires
from the initial marking.
"""

from __future__ import annotations

import pytest
import yaml

from petriflow.engine import fire_sequence
from petriflow.io import load_net
from petriflow.io.yaml import loads_net, net_to_dict
from petriflow.properties.check import check_properties
from tests.conftest import NETS

SHIPPED = sorted(p for p in NETS.glob("*/*.yaml") if "\nproperties:" in p.read_text())
BEYOND_BUDGET = {"bidding-autonomous-20.yaml"}
SCENARIOS = {"passage", "bidding", "bus", "comm", "slam", "swarm", "smart"}


@pytest.mark.slow
def test_the_20_robot_properties_are_proved_on_the_symmetry_quotient():
    """6.6e16 markings: every property decided true on the quotient (the nested CTL
    ones too: mission_can_end directly, messages_delivered by a stronger formula)."""
    net = load_net(NETS / "bidding" / "bidding-autonomous-20.yaml")
    got = {r["id"]: r for r in check_properties(net, net.properties)}
    assert {k: r["verdict"] for k, r in got.items()} == {p.id: True for p in net.properties}
    assert all("symmetry quotient" in r["method"] for r in got.values())
    assert "stronger formula" in got["messages_delivered"]["method"]


def test_every_scenario_states_at_least_two_properties():
    """Each scenario folder has a net with two or more properties."""
    counts = {p.parent.name: len(load_net(p).properties) for p in SHIPPED}
    assert SCENARIOS <= set(counts) and all(counts[s] >= 2 for s in SCENARIOS)


@pytest.mark.parametrize("path", [p for p in SHIPPED if p.name not in BEYOND_BUDGET],
                         ids=lambda p: p.name)
def test_shipped_properties_hold(path):
    """Every property of the shipped net is decided and holds."""
    net = load_net(path)
    results = check_properties(net, net.properties)
    assert {r["id"]: r["verdict"] for r in results} == {p.id: True for p in net.properties}


def without_arc(net, place, transition):
    """The net read back from its YAML form with the arc ``place -> transition`` left out."""
    data = net_to_dict(net)
    found = []

    def visit(item):
        if isinstance(item, dict):
            if item.get("id") == transition and place in item.get("in", []):
                item["in"] = [p for p in item["in"] if p != place]
                found.append(item)
            for value in item.values():
                visit(value)
        elif isinstance(item, list):
            for value in item:
                visit(value)

    visit(data)
    assert len(found) == 1, f"no arc {place} -> {transition}"
    return loads_net(yaml.safe_dump(data, sort_keys=False))


# (net, the arc removed: (source, target)) -> the property that must fail
MUTATIONS = [
    ("passage/passage.yaml", ("mutex", "blue_enter"), "passage_exclusive"),
    ("bus/bus-algorithm2-3.yaml", ("slot_m1_m2", "m1_send"), "one_frame_per_mailbox"),
    ("smart/smart.yaml", ("P13", "T5"), "one_rescue"),
]


@pytest.mark.parametrize("relative, arc, failing", MUTATIONS, ids=[m[0] for m in MUTATIONS])
def test_an_arc_removed_breaks_a_property_with_a_counterexample(relative, arc, failing):
    """Without the arc, the named property is false and its counterexample replays."""
    net = without_arc(load_net(NETS / relative), *arc)
    result = {r["id"]: r for r in check_properties(net, net.properties)}[failing]
    assert result["verdict"] is False
    fire_sequence(net, net.initial_marking, result["witness"])     # raises if not fireable


def test_export_violation_draws_a_failing_property(tmp_path, capsys):
    """`export --violation` draws the counterexample of the net's own failing property."""
    from petriflow.cli import main

    mutated = tmp_path / "passage.yaml"
    text = (NETS / "passage" / "passage.yaml").read_text()
    mutated.write_text(text.replace("in: [blue_waiting, mutex]", "in: [blue_waiting]").replace("run: run.yaml\n", ""))
    assert main(["export", str(mutated), "-o", str(tmp_path / "out.dot"), "--violation"]) == 0
    assert capsys.readouterr().out.startswith("property passage_exclusive fails")
    assert "blue_enter" in (tmp_path / "out.dot").read_text()
