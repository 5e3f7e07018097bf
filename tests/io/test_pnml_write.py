"""PNML writing: ISO documents other tools read, lossless round trips."""

from __future__ import annotations

import json
import os
import warnings

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from petriflow.errors import NetFormatError
from petriflow.io import load_net
from petriflow.io.pnml import (
    PTNET_TYPE,
    PnmlWarning,
    dumps_pnml,
    load_pnml,
    loads_pnml,
    save_pnml,
)
from petriflow.io.yaml import dumps_net, load_yaml, loads_net
from petriflow.net import Net, Operator
from tests.conftest import oracle_cases
from tests.io.pnml_support import (
    DATA,
    ISO,
    REPO,
    error_of,
    iso,
    load_warned,
    read,
    read_warned,
)

# Writing -------------------------------------------------------------------------------


def full_net() -> Net:
    """A net using every feature petriflow keeps in PNML."""
    return loads_net("""
petriflow: 1
net: relay
label: Relay with hand-over
subnets:
  - {id: arm, label: Arm agent, agent: robot_1, places: [held]}
  - {id: cam}
places: [{id: i, tokens: 2, label: start}, o, {id: radio, channel: wifi}, lost]
transitions:
  - {id: grab, action: arm.grab, params: {force: 2.5, tags: [a, b], nested: {k: null}}, guard: gripper_ok,
     priority: 3, timeout: 4.5, in: {i: 2}, out: [held, radio],
     outcomes: {failed: [lost], timeout: {lost: 2}}}
  - {id: route, split: xor, in: [held], out: [o, i]}
  - {id: skip, silent: true, label: tau, in: [i], out: [o], cancels: [held, grab]}
final: {o: 1}
""")


def test_written_file_is_iso_pnml_with_what_other_tools_read():
    """Namespace, ptnet type, one page, names, markings, weights, ProM silent, final marking."""
    from xml.etree.ElementTree import fromstring

    text = dumps_pnml(full_net())
    root = fromstring(text)
    ns = f"{{{ISO}}}"
    net = root.find(f"{ns}net")
    assert root.tag == f"{ns}pnml" and net.get("type") == PTNET_TYPE and net.get("id") == "relay"
    assert len(net.findall(f"{ns}page")) == 1
    assert net.find(f"{ns}name/{ns}text").text == "Relay with hand-over"
    page = net.find(f"{ns}page")
    weights = {(a.get("source"), a.get("target")): a.find(f"{ns}inscription/{ns}text")
               for a in page.findall(f"{ns}arc")}
    assert weights[("i", "grab")].text == "2" and weights[("grab", "held")] is None
    skip = page.find(f"{ns}transition[@id='skip']")
    assert skip.find(f"{ns}toolspecific[@tool='ProM']").get("activity") == "$invisible$"
    final = net.find(f"{ns}finalmarkings/{ns}marking/{ns}place")
    assert final.get("idref") == "o" and final.find(f"{ns}text").text == "1"
    assert page.find(f"{ns}place[@id='i']/{ns}initialMarking/{ns}text").text == "2"
    assert text == dumps_pnml(full_net())  # deterministic


def test_full_net_round_trips_without_loss():
    net = full_net()
    back = read(dumps_pnml(net))
    assert back.structure() == net.structure()
    assert (back.id, back.label) == (net.id, net.label)
    assert back.transition("grab").params == {"force": 2.5, "tags": ["a", "b"], "nested": {"k": None}}
    assert back.place("radio").channel == "wifi" and back.transition("grab").timeout == 4.5
    assert back.transition("skip").cancels == ("held", "grab")
    assert back.postset("grab", "timeout") == {"lost": 2} and back.postset("grab") == {"held": 1, "radio": 1}


def test_outcome_arcs_stay_out_of_the_plain_pnml_arcs():
    """Other tools see the ok runs only: failure routes live in petriflow's data."""
    text = dumps_pnml(full_net())
    assert 'target="lost"' not in text
    assert '<outcome kind="failed" place="lost" weight="1" />' in text


@pytest.mark.parametrize("yaml_file", ["nets/examples/inspection.yaml",
                                       "nets/philosophers/philosophers-5.yaml",
                                       "nets/passage/passage.yaml"])
def test_yaml_to_pnml_to_yaml_is_lossless(yaml_file):
    """YAML -> PNML -> YAML gives the same YAML text."""
    path = REPO / yaml_file
    if not path.is_file():
        pytest.skip(f"{yaml_file} not in this checkout")
    net = load_yaml(path)
    back = read(dumps_pnml(net))
    assert back.structure() == net.structure()
    assert dumps_net(back) == dumps_net(net)


def test_positions_meta_and_odd_labels_round_trip():
    """Positions go to graphics, other meta to JSON; labels XML text cannot hold survive too."""
    net = Net("odd")
    net.add_place("p", label="  padded\r\n", meta={"position": [1.5, -2], "colour": "red"})
    net.add_place("q", label="", meta={"position": (3, 4)})
    net.add_transition("t", label="bell\x07", meta={"note": {"a": [1, 2]}})
    net.add_transition("u", label="plain")
    back = read(dumps_pnml(net))
    assert back.structure() == net.structure()
    assert back.place("p").meta == {"position": [1.5, -2], "colour": "red"}
    assert back.place("q").meta == {"position": [3, 4]}
    assert back.transition("t").meta == {"note": {"a": [1, 2]}}


def test_meta_that_is_not_json_is_warned_and_skipped():
    net = Net("m")
    net.add_place("p", meta={"ok": 1, "bad": {1, 2}})
    with pytest.warns(PnmlWarning, match="place 'p': meta 'bad' is not JSON data"):
        text = dumps_pnml(net)
    assert read(text).place("p").meta == {"ok": 1}


def test_unwritable_content_is_a_clear_error():
    """Params that JSON would change and ids XML cannot hold are refused, not mangled."""
    net = Net("w")
    net.add_transition("t", params={1: "int key"})
    with pytest.raises(NetFormatError, match="'t': params are not plain JSON"):
        dumps_pnml(net)
    bad = Net("w")
    bad.add_place("p\x00")
    with pytest.raises(NetFormatError, match="characters XML cannot represent"):
        dumps_pnml(bad)


def test_operator_kinds_other_than_and_xor_are_refused_when_writing(tmp_path):
    net = Net("o")
    net.add_transition("t", operator=Operator("g", split="or"))
    with pytest.raises(NetFormatError, match="split must be one of and, xor") as info:
        save_pnml(net, tmp_path / "o.pnml")
    assert info.value.path == str(tmp_path / "o.pnml") and info.value.element == "t"
    assert not (tmp_path / "o.pnml").exists()


def test_save_and_load_through_files(tmp_path):
    """save_pnml writes atomically; load_net picks the PNML reader by the ending."""
    path = tmp_path / "relay.pnml"
    save_pnml(full_net(), path)
    assert load_pnml(path).structure() == full_net().structure()
    assert load_net(path).structure() == full_net().structure()
    assert [p.name for p in tmp_path.iterdir()] == ["relay.pnml"]


def test_arc_ids_are_kept_and_made_unique():
    net = Net("ids")
    net.add_place("p"); net.add_transition("t"); net.add_place("a1")
    net.add_arc("p", "t", id="a1")  # clashes with the place a1
    net.add_arc("t", "p", id="keep me")
    back = read(dumps_pnml(net))
    assert back.arc("t", "p").id == "keep me"
    assert back.arc("p", "t").id not in ("a1", "keep me", None)


# Hypothesis: random nets survive the round trip ---------------------------------------

IDS = st.text(alphabet="abcdefghijklmnopqrstuvwxyz0123456789_-.", min_size=1, max_size=8)
LABELS = st.none() | st.text(st.characters(exclude_categories=("Cs",)), max_size=12)
NAMES = st.none() | st.text(alphabet="abcdefghij._", min_size=1, max_size=10)
JSON = st.recursive(
    st.none() | st.booleans() | st.integers(-10**6, 10**6) | st.floats(allow_nan=False, allow_infinity=False)
    | st.text(max_size=6),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=5), inner, max_size=3),
    max_leaves=8,
)
ATTRIBUTE_TEXT = st.none() | st.text(st.characters(exclude_categories=("Cs", "Cc", "Cn")), min_size=1, max_size=8)


@st.composite
def random_nets(draw) -> Net:
    ids = draw(st.lists(IDS, min_size=2, max_size=10, unique=True))
    cut = draw(st.integers(1, len(ids) - 1))
    places, transitions = ids[:cut], ids[cut:]
    net = Net(draw(IDS), label=draw(LABELS))
    subnets = draw(st.lists(IDS, max_size=2, unique=True))
    for sid in subnets:
        net.add_subnet(sid, draw(ATTRIBUTE_TEXT), draw(ATTRIBUTE_TEXT))
    subnet = st.none() | st.sampled_from(subnets) if subnets else st.none()
    for pid in places:
        net.add_place(pid, tokens=draw(st.integers(0, 4)), label=draw(LABELS), subnet=draw(subnet),
                      channel=draw(NAMES))
    for tid in transitions:
        operator = draw(st.none() | st.builds(Operator, IDS, st.sampled_from([None, "and", "xor"]),
                                              st.sampled_from([None, "and", "xor"])))
        net.add_transition(
            tid, label=draw(LABELS), action=draw(NAMES), guard=draw(NAMES), subnet=draw(subnet),
            params=draw(st.dictionaries(st.text(max_size=5), JSON, max_size=3)),
            silent=draw(st.booleans()), priority=draw(st.integers(-5, 5)), operator=operator,
            timeout=draw(st.none() | st.floats(min_value=1e-3, max_value=1e6)),
            cancels=draw(st.lists(st.sampled_from(ids), max_size=3, unique=True)),
        )
    pairs = [(p, t) for p in places for t in transitions] + [(t, p) for t in transitions for p in places]
    for source, target in draw(st.lists(st.sampled_from(pairs), max_size=12, unique=True)):
        net.add_arc(source, target, draw(st.integers(1, 5)))
    routes = [(t, p, o) for t in transitions for p in places for o in ("failed", "timeout", "cancelled")]
    for source, target, outcome in draw(st.lists(st.sampled_from(routes), max_size=4, unique=True)):
        net.add_arc(source, target, draw(st.integers(1, 3)), outcome=outcome)
    if draw(st.booleans()):
        net.set_final_marking({p: draw(st.integers(0, 3)) for p in draw(st.lists(st.sampled_from(places),
                                                                                   unique=True))})
    return net


@settings(max_examples=40, deadline=None)
@given(random_nets())
def test_random_nets_round_trip_through_pnml(net):
    assert read(dumps_pnml(net)).structure() == net.structure()


# Interoperability with PM4Py (AGPL: imported in tests only) -----------------------------


@pytest.fixture(scope="module")
def pm4py():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with open(os.devnull, "w") as quiet:  # pm4py prints a banner on import
            import contextlib

            with contextlib.redirect_stdout(quiet):
                return pytest.importorskip("pm4py")


def test_pm4py_reads_what_petriflow_writes(pm4py, tmp_path):
    net = full_net()
    path = tmp_path / "relay.pnml"
    save_pnml(net, path)
    pm_net, im, fm = pm4py.read_pnml(str(path))
    assert {p.name for p in pm_net.places} == set(net.places)
    labels = {t.name: t.label for t in pm_net.transitions}
    assert labels == {t.id: None if t.silent else (t.label or t.id) for t in net.transitions.values()}
    ok_arcs = {(a.source, a.target, a.weight) for a in net.arcs if a.outcome is None}
    assert {(a.source.name, a.target.name, a.weight) for a in pm_net.arcs} == ok_arcs
    assert {p.name: n for p, n in im.items()} == net.initial_marking.to_dict()
    assert {p.name: n for p, n in fm.items()} == net.final_marking.to_dict()


def test_petriflow_reads_what_pm4py_writes(pm4py, tmp_path):
    from pm4py.objects.petri_net.obj import Marking, PetriNet
    from pm4py.objects.petri_net.utils.petri_utils import add_arc_from_to

    pm_net = PetriNet("made_by_pm4py")
    start, middle, end = (PetriNet.Place(n) for n in ("start", "middle", "end"))
    work, tau = PetriNet.Transition("work", "Work"), PetriNet.Transition("tau_1", None)
    for node in (start, middle, end):
        pm_net.places.add(node)
    for node in (work, tau):
        pm_net.transitions.add(node)
    add_arc_from_to(start, work, pm_net, weight=2)
    add_arc_from_to(work, middle, pm_net)
    add_arc_from_to(middle, tau, pm_net)
    add_arc_from_to(tau, end, pm_net, weight=3)
    path = tmp_path / "pm.pnml"
    pm4py.write_pnml(pm_net, Marking({start: 2}), Marking({end: 3}), str(path))

    got = read(path.read_text(encoding="utf-8"), path=str(path))
    expected = Net("made_by_pm4py")
    for place in ("start", "middle", "end"):
        expected.add_place(place, label=place)
    expected.add_transition("work", label="Work")
    expected.add_transition("tau_1", label="tau_1", silent=True)
    for source, target, weight in (("start", "work", 2), ("work", "middle", 1), ("middle", "tau_1", 1),
                                   ("tau_1", "end", 3)):
        expected.add_arc(source, target, weight)
    expected.set_initial_marking({"start": 2})
    expected.set_final_marking({"end": 3})
    assert got.structure() == expected.structure()
    assert got.id == "made_by_pm4py"


# Multisets and pages (real files from other tools) --------------------------------------


def test_snakes_multiset_markings_are_read_as_counts():
    """SNAKES' native marking: black tokens count; nothing is read as an empty place."""
    net = read("""
        <pnml><net id="N">
          <place id="p"><type domain="universal"/><initialMarking><multiset>
            <item><value><token/></value><multiplicity>2</multiplicity></item>
          </multiset></initialMarking></place>
          <transition id="t"/>
          <arc id="a" source="p" target="t"><inscription><text>1</text></inscription></arc>
        </net></pnml>""")
    assert net.initial_marking == {"p": 2}


def test_coloured_multiset_values_are_counted_with_a_warning_naming_the_place():
    net, warned = read_warned("""
        <pnml><net id="N">
          <place id="q"><initialMarking><multiset>
            <item><value><object type="int">1</object></value><multiplicity>1</multiplicity></item>
            <item><value><object type="int">2</object></value><multiplicity>2</multiplicity></item>
          </multiset></initialMarking></place>
        </net></pnml>""")
    assert net.initial_marking == {"q": 3}
    assert warned == ["net.pnml: place 'q': coloured token values (1, 2 x2) are not representable; read as 3"
                      " plain tokens"]


def test_snakes_own_pnml_of_a_marked_net_reads_back_its_marking():
    snakes_nets = pytest.importorskip("snakes.nets")
    import snakes.pnml

    made = snakes_nets.PetriNet("N")
    made.add_place(snakes_nets.Place("p", [snakes_nets.dot] * 3))
    assert loads_pnml(snakes.pnml.dumps(made)).initial_marking == {"p": 3}


def test_an_arc_between_pages_is_refused_naming_the_arc():
    """ISO/IEC 15909-2 joins nodes of different pages only through reference nodes."""
    message = str(error_of(f"""
        <pnml xmlns="{ISO}"><net id="n" type="{PTNET_TYPE}">
          <page id="one"><place id="p"/></page>
          <page id="two"><transition id="t"/><arc id="crossing" source="p" target="t"/></page>
        </net></pnml>"""))
    assert "'crossing': arc on page 'two' joins 'p' on page 'one'" in message and "reference nodes" in message


def test_a_reference_node_on_the_arcs_page_joins_pages():
    net, warned = read_warned(f"""
        <pnml xmlns="{ISO}"><net id="n" type="{PTNET_TYPE}">
          <page id="one"><place id="p"><initialMarking><text>1</text></initialMarking></place></page>
          <page id="two"><referencePlace id="rp" ref="p"/><transition id="t"/>
            <arc id="a" source="rp" target="t"/></page>
        </net></pnml>""")
    assert net.preset("t") == {"p": 1}
    assert warned == ["net.pnml: net 'n': pages 'one', 'two' flattened into one page (every node kept)"]


@pytest.mark.parametrize("name", ["windows_bom.pnml", "windows_utf16.pnml"])
def test_byte_order_marks_and_utf16_read_as_the_same_net(name, tmp_path):
    """XML allows a UTF-8 byte-order mark and UTF-16 (Windows tools write both): the
    net is the one its UTF-8 original holds, from the file, from bytes, and by the
    reader that sniffs the format (no .pnml ending)."""
    expected = load_pnml(DATA / "snakes_pt.pnml").structure()
    assert load_pnml(DATA / name).structure() == expected
    assert loads_pnml((DATA / name).read_bytes()).structure() == expected
    unnamed = tmp_path / "net.txt"
    unnamed.write_bytes((DATA / name).read_bytes())
    assert load_net(unnamed).structure() == expected


def test_utf16_without_a_mark_and_undecodable_bytes(tmp_path):
    text = (DATA / "snakes_pt.pnml").read_text().replace('encoding="utf-8"', 'encoding="UTF-16LE"')
    (tmp_path / "le.pnml").write_bytes(text.encode("utf-16-le"))
    assert load_net(tmp_path / "le.pnml").structure() == load_pnml(DATA / "snakes_pt.pnml").structure()
    (tmp_path / "bad.pnml").write_bytes(b"<?xml version='1.0'?><pnml>\xff\xfe\xfa</pnml>")
    with pytest.raises(NetFormatError, match=r"bad.pnml: cannot read: not utf-8 text"):
        load_net(tmp_path / "bad.pnml")


# NUPN (the Model Checking Contest's unit structure) ------------------------------------

NUPN = """
    <place id="a"><initialMarking><text>1</text></initialMarking></place><place id="b"/>
    <transition id="t"/>
    <arc id="x" source="a" target="t"/><arc id="y" source="t" target="b"/>
    <toolspecific tool="nupn" version="1.1">
      <size places="2" transitions="1" arcs="2"/>
      <structure units="3" root="u0" safe="true">
        <unit id="u0"><places/><subunits>u1 u2</subunits></unit>
        <unit id="u1"><places>a</places><subunits/></unit>
        <unit id="u2"><places>b</places><subunits/></unit>
      </structure>
    </toolspecific>"""


def test_nupn_units_are_kept_as_meta_data_without_a_warning():
    """NUPN is read into net.meta["nupn"], silently, and survives a PNML round trip."""
    net, warned = read_warned(iso(NUPN))
    assert warned == []
    assert net.meta["nupn"] == {"version": "1.1", "root": "u0", "safe": True, "units": {
        "u0": {"places": [], "subunits": ["u1", "u2"]},
        "u1": {"places": ["a"], "subunits": []},
        "u2": {"places": ["b"], "subunits": []}}}
    again, warned = read_warned(dumps_pnml(net))
    assert warned == [] and again.meta["nupn"] == net.meta["nupn"]


def test_nupn_naming_unknown_places_is_one_note():
    """Units naming places the net lacks: kept as read, one warning."""
    net, warned = read_warned(iso(NUPN.replace("<places>b</places>", "<places>b ghost</places>")))
    assert net.meta["nupn"]["units"]["u2"]["places"] == ["b", "ghost"]
    assert len(warned) == 1 and "NUPN units name a place that is not in the net (e.g. 'ghost')" in warned[0]


@pytest.mark.parametrize("case", [c for c in oracle_cases(legal_only=True) if c.id.startswith("mcc/")])
def test_mcc_files_with_nupn_read_without_warnings(case):
    """The MCC models of the corpus (three carry NUPN) load without a single warning."""
    answer = json.loads((case / "answer.json").read_text())
    net, warned = load_warned(case / answer["file"])
    assert warned == []
    if "nupn" in (case / answer["file"]).read_text():
        assert net.meta["nupn"]["units"]
