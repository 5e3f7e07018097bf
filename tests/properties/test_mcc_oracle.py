"""Every verdict of the Model Checking Contest's consensus on its 8 public models, right.

For each model, ``formulas/`` holds the seven property files as the contest publishes
them and ``oracle.json`` the consensus verdicts (ORACLE2021): 896 in all. Each must be
decided, and decided as the contest did; every firing sequence given as evidence must
be fireable from the initial marking, and a reachability witness must end in a marking
that decides the property. Every verdict is checked twice: as ``check`` decides by
default, and with the stubborn-set reduction forced on (``reduction="stubborn"``: every
``EF p``/``AG p`` by the up-set search, every LTL formula without ``X`` by the reduced
product, graph or no graph; slow).
"""

from __future__ import annotations

import json

import pytest

from petriflow.engine import fire_sequence
from petriflow.analysis.reachability import reachability_graph
from petriflow.io import load_net
from petriflow.properties.check import check_properties
from petriflow.properties.kripke import Kripke
from petriflow.properties.language import ExistsPath
from petriflow.properties.mcc_xml import load_mcc_properties
from tests.conftest import ORACLE

MCC = ORACLE / "mcc"
MODELS = sorted(p.name for p in MCC.iterdir() if (p / "formulas" / "oracle.json").is_file())
CATEGORIES = ("ReachabilityCardinality", "ReachabilityFireability", "UpperBounds", "CTLCardinality",
              "CTLFireability", "LTLCardinality", "LTLFireability")


def test_the_yardstick_is_complete():
    """8 models, 7 categories, 16 formulas each: 896 verdicts."""
    total = sum(len(answers) for m in MODELS
                for answers in json.loads((MCC / m / "formulas" / "oracle.json").read_text()).values())
    assert (len(MODELS), total) == (8, 896)


@pytest.mark.parametrize("reduction", ["auto", pytest.param("stubborn", marks=pytest.mark.slow)])
@pytest.mark.parametrize("category", CATEGORIES)
@pytest.mark.parametrize("model", MODELS)
def test_every_contest_verdict_is_right(model, category, reduction):
    """All 16 properties decided, each as the contest's consensus says, with evidence that replays."""
    net = load_net(MCC / model / "model.pnml")
    expected = json.loads((MCC / model / "formulas" / "oracle.json").read_text())[category]
    properties = load_mcc_properties(MCC / model / "formulas" / f"{category}.xml")
    results = check_properties(net, properties, reduction=reduction)
    got = {r["id"]: ("TRUE" if r["verdict"] is True else "FALSE" if r["verdict"] is False
                     else None if r["verdict"] is None else str(r["verdict"])) for r in results}
    assert got == {k: str(v) for k, v in expected.items()}
    for prop, result in zip(properties, results):
        for key in ("witness", "cycle"):
            if result.get(key):
                start = net.initial_marking if key == "witness" else fire_sequence(
                    net, net.initial_marking, result["witness"])
                end = fire_sequence(net, start, result[key])      # raises if not fireable
                if key == "cycle":
                    assert end == start, "a lasso's cycle returns to where it began"
        if result["kind"] == "reachability" and result["witness"]:
            # EF p true: the witness ends where p holds; AG p false: where p fails
            end = fire_sequence(net, net.initial_marking, result["witness"])
            kripke = Kripke(reachability_graph(net))
            holds = kripke.holds(prop.formula.operand.operand)[kripke.space.index(end)]
            assert bool(holds) == isinstance(prop.formula, ExistsPath)
