"""Fuzzing the net readers (YAML and PNML) and the commands that read nets: a mutated
file loads, or is refused with a one-line error; never another exception."""

from __future__ import annotations

import re

from hypothesis import event, given
from hypothesis import strategies as st

from petriflow.errors import PetriflowError
from petriflow.io.pnml import dumps_pnml, loads_pnml
from petriflow.io.yaml import dumps_net, loads_net
from tests.conftest import NETS, ORACLE, SEQUENCE_YAML
from tests.fuzz.contract import HOSTILE_VALUES, assert_contract, mutate_yaml

YAML_BASES = [
    SEQUENCE_YAML,
    (NETS / "examples" / "inspection.yaml").read_text(),
    """petriflow: 1
net: rich
run: {until: 3, seed: 2, faults: [{kill: r2, at: 1}], channels: {radio: {model: ideal, latency: 0.1}}}
subnets:
  - {id: r1, places: [{id: a, tokens: 2}, done], transitions: [
      {id: go, action: core.fail, params: {seconds: 0.5, probability: 0.5}, timeout: 2, in: [a], out: [done, box],
       outcomes: {failed: [a], timeout: [a]}}]}
  - {id: r2, places: [{id: box, channel: radio}, got], transitions: [{id: take, in: [box], out: [got], priority: 1}]}
places: [{id: alarm, tokens: 1, meta: {note: x}}]
transitions:
  - {id: stop, action: core.wait, params: {seconds: 2.5}, in: [alarm], cancels: [go, a], label: Stop}
final: {done: 2}
""",
]
PNML_BASES = [dumps_pnml(loads_net(text)) for text in YAML_BASES] + [
    (ORACLE / "dialects" / name).read_text(encoding="utf-8") for name in (
        "woped-Ballgame/Ballgame.pnml", "pipe-Dining_philosophers/Dining_philosophers.xml",
        "snakes-simple-pt/simple-pt.pnml", "epnk-samplePTnet/samplePTnet.pnml")
]


@st.composite
def mutated_yaml(draw: st.DrawFn) -> bytes:
    return mutate_yaml(draw, draw(st.sampled_from(YAML_BASES)),
                       ["tokens: -1", "weight: 0", "timeout: .nan", "cancels: [zz]", "zz: 1"])


@st.composite
def mutated_pnml(draw: st.DrawFn) -> bytes:
    text = draw(st.sampled_from(PNML_BASES))
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.sampled_from(["text", "text", "attribute", "drop", "nest", "truncate", "doctype"]))
        if kind == "text":
            hits = list(re.finditer(r"(?<=<text>)[^<]*(?=</text>)", text))
            if hits:
                hit = draw(st.sampled_from(hits))
                value = draw(st.sampled_from(HOSTILE_VALUES + ["-5", "1,2", "Default,1", "x" * 10, "1" * 40]))
                text = text[:hit.start()] + value.replace("<", "") + text[hit.end():]
        elif kind == "attribute":
            hits = list(re.finditer(r'\b(?:source|target|id|ref)="([^"]*)"', text))
            if hits:
                hit = draw(st.sampled_from(hits))
                text = text[:hit.start(1)] + draw(st.sampled_from(["", "nowhere", "p1", "t1", "i", "o", "a b"])) \
                    + text[hit.end(1):]
        elif kind == "drop":
            hits = list(re.finditer(r"<(place|transition|arc|page|initialMarking|inscription)\b[^>]*/>", text))
            if hits:
                hit = draw(st.sampled_from(hits))
                text = text[:hit.start()] + text[hit.end():]
        elif kind == "nest":
            depth = draw(st.integers(1, 120))
            text = text.replace("<page ", "<page id=\"deep\">" * depth + "<page ", 1).replace(
                "</page>", "</page>" + "</page>" * depth, 1)
        elif kind == "doctype":
            text = text.replace("<pnml", '<!DOCTYPE pnml [<!ENTITY a "aaaaaaaa">]><pnml', 1)
        else:
            text = text[:draw(st.integers(0, len(text)))]
    return text.encode("utf-8")


def _loads_and_round_trips_or_refuses(read, data, path: str) -> str:
    """Read ``data``: a net that loads survives load -> dump -> load in both formats
    (YAML and PNML give the same net); a refusal is one line naming the file. Returns
    which happened."""
    try:
        net = read(data)
    except PetriflowError as exc:
        message = str(exc)
        assert "\n" not in message.strip() and message.startswith(path), message
        return "refused"
    import warnings

    assert loads_net(dumps_net(net)).structure() == net.structure()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a net's own PNML holds nothing petriflow cannot represent
        try:
            written = dumps_pnml(net)
        except PetriflowError as exc:  # text XML cannot hold (a control character in a label)
            assert "characters XML cannot represent" in str(exc), str(exc)
            return "loaded"
        again = loads_pnml(written)
    assert again.structure() == net.structure()
    assert loads_net(dumps_net(again)).structure() == net.structure()
    return "loaded"


@given(mutated_yaml())
def test_yaml_reader_round_trips_or_refuses(data):
    outcome = _loads_and_round_trips_or_refuses(
        lambda d: loads_net(d.decode("utf-8", "replace"), path="fuzz.yaml"), data, "fuzz.yaml")
    event(outcome)


@given(mutated_pnml())
def test_pnml_reader_round_trips_or_refuses(data):
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        outcome = _loads_and_round_trips_or_refuses(lambda d: loads_pnml(d, path="fuzz.pnml"), data, "fuzz.pnml")
    event(outcome)


def test_the_fuzzers_reach_both_outcomes():
    """The mutations are neither all harmless nor all fatal: each reader both loads and
    refuses some of them (otherwise the round-trip assertions would test nothing)."""
    from hypothesis import find

    for strategy, read, path in ((mutated_yaml(), lambda d: loads_net(d.decode("utf-8", "replace"),
                                                                         path="fuzz.yaml"), "fuzz.yaml"),
                                 (mutated_pnml(), lambda d: loads_pnml(d, path="fuzz.pnml"), "fuzz.pnml")):
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for wanted in ("loaded", "refused"):
                find(strategy, lambda d, w=wanted: _loads_and_round_trips_or_refuses(read, d, path) == w)


@given(mutated_yaml())
def test_commands_on_mutated_yaml_keep_the_contract(tmp_path_factory, data):
    folder = tmp_path_factory.mktemp("fuzz")
    net = folder / "net.yaml"
    net.write_bytes(data)
    for argv in (["info", net], ["check", net, "--max-states", "2000"],
                 ["run", net, "--until", "3", "--max-firings", "200", "--trace", folder / "t.jsonl"],
                 ["export", net, "-o", folder / "n.pnml"], ["simulate", net, "--steps", "20"]):
        assert_contract(*argv)


@given(mutated_pnml())
def test_commands_on_mutated_pnml_keep_the_contract(tmp_path_factory, data):
    folder = tmp_path_factory.mktemp("fuzz")
    net = folder / "net.pnml"
    net.write_bytes(data)
    for argv in (["info", net], ["check", net, "--max-states", "2000"], ["export", net, "-o", folder / "n.yaml"]):
        assert_contract(*argv)
