"""PNML: the dialects other tools write, loud errors and warnings, lossless round trips."""

from __future__ import annotations

import json
import os
import textwrap
import warnings
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from petriflow.errors import NetFormatError
from petriflow.io import load_net
from petriflow.io.pnml import (
    PNML_NAMESPACE,
    PT_NET_TYPES,
    PTNET_TYPE,
    WOPED_OPERATOR_TYPES,
    PnmlWarning,
    dumps_pnml,
    load_pnml,
    loads_pnml,
    save_pnml,
)
from petriflow.io.yaml import dumps_net, load_yaml, loads_net
from petriflow.net import Net, Operator

from tests.conftest import ORACLE, oracle_cases

REPO = Path(__file__).resolve().parents[2]
DATA = Path(__file__).resolve().parent / "data"
ISO = PNML_NAMESPACE


def tidy(text: str) -> str:
    """Inline test documents lose their indentation; written documents stay byte-exact."""
    return text if text.startswith("<") else textwrap.dedent(text).strip()


def read(text: str, path: str = "net.pnml") -> Net:
    """Read PNML text, failing the test on any warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PnmlWarning)
        return loads_pnml(tidy(text), path=path)


def read_warned(text: str, path: str = "net.pnml") -> tuple[Net, list[str]]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        net = loads_pnml(tidy(text), path=path)
    return net, [str(w.message) for w in caught if issubclass(w.category, PnmlWarning)]


def load_warned(path: Path) -> tuple[Net, list[str]]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        net = load_pnml(path)
    return net, [str(w.message) for w in caught if issubclass(w.category, PnmlWarning)]


def error_of(text: str) -> NetFormatError:
    with pytest.raises(NetFormatError) as info:
        loads_pnml(tidy(text), path="bad.pnml")
    return info.value


def iso(body: str, net_type: str = PTNET_TYPE) -> str:
    """An ISO document holding one net with one page around ``body``."""
    return (f'<pnml xmlns="{ISO}"><net id="n" type="{net_type}"><page id="pg">'
            f'{textwrap.dedent(body)}</page></net></pnml>')


def arcs_of(net: Net) -> set[tuple[str, str, int]]:
    return {(a.source, a.target, a.weight) for a in net.arcs}


# Oracle files from the field ---------------------------------------------------------


@pytest.mark.parametrize("folder", oracle_cases())
def test_oracle_file_loads_with_the_expected_counts(folder):
    """Every file other tools wrote loads with the known counts, or is rejected if illegal."""
    answer = json.loads((folder / "answer.json").read_text(encoding="utf-8"))
    path = folder / answer["file"]
    if folder.name.startswith("epnk-illegal"):
        with pytest.raises(NetFormatError):
            load_warned(path)
        return
    net, _ = load_warned(path)
    expected = answer.get("expected_parse") or answer.get("structure")
    if expected is None:  # workflow nets: their answers are about behaviour
        assert net.places and net.transitions and net.arcs
        return
    assert len(net.places) == expected["places"]
    assert len(net.transitions) == expected["transitions"]
    assert len(net.arcs) == expected["arcs"]
    assert sum(1 for a in net.arcs if a.weight > 1) == expected["weighted_arcs"]
    assert net.initial_marking.total == expected["initial_tokens"]
    if "initial_marking" in expected:
        assert net.initial_marking == expected["initial_marking"]


@pytest.mark.parametrize("folder", oracle_cases(legal_only=True))
def test_oracle_file_survives_a_petriflow_round_trip(folder):
    """What petriflow read from a foreign file, it writes and reads back unchanged."""
    answer = json.loads((folder / "answer.json").read_text(encoding="utf-8"))
    net, _ = load_warned(folder / answer["file"])
    back = read(dumps_pnml(net))
    assert back.structure() == net.structure()
    assert back.label == net.label and back.id == net.id
    assert {p: n.meta for p, n in back.places.items()} == {p: n.meta for p, n in net.places.items()}
    assert {t: n.meta for t, n in back.transitions.items()} == {
        t: n.meta for t, n in net.transitions.items()}


def test_illegal_epnk_file_is_rejected_naming_a_net():
    """ePNK's CyclicReferences example (two nets, reference cycles) is refused."""
    path = ORACLE / "dialects" / "epnk-illegal-CyclicReferences" / "CyclicReferences.pnml"
    with pytest.raises(NetFormatError) as info:
        load_pnml(path)
    assert info.value.line is not None and "4711" in str(info.value)


def test_cli_info_works_on_every_oracle_file(capsys):
    """``petriflow info`` answers 0 on every legal oracle file and 2 on the illegal one."""
    from petriflow.cli import main

    for answer_file in sorted(ORACLE.glob("*/*/answer.json")):
        net_file = answer_file.parent / json.loads(answer_file.read_text(encoding="utf-8"))["file"]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            code = main(["info", str(net_file)])
        assert code == (2 if "illegal" in answer_file.parent.name else 0), net_file
    capsys.readouterr()


# The dialects, one hand-written file each ----------------------------------------------


def test_iso_nested_pages_are_flattened_keeping_every_node():
    """Nodes on nested pages all land in the net; references resolve to their final node."""
    net, warned = load_warned(DATA / "iso_nested_pages.pnml")
    assert (net.id, net.label) == ("assembly", "Assembly line")
    assert list(net.places) == ["parts", "tray", "done"]
    assert list(net.transitions) == ["pick", "mount"]
    assert arcs_of(net) == {("parts", "pick", 2), ("pick", "tray", 1), ("tray", "mount", 1),
                            ("mount", "done", 1)}
    assert net.initial_marking == {"parts": 4}
    assert net.place("parts").label == "parts bin" and net.place("done").label is None
    assert net.place("parts").meta["position"] == [10, 40.5]
    assert net.transition("pick").meta["position"] == [60, 40.5]
    assert len(warned) == 1 and "'top', 'station', 'inner' flattened" in warned[0]


def test_pm4py_dialect_reads_final_marking_silent_transitions_and_reports_data():
    """PM4Py's core-model files: final marking, $invisible$, data Petri net extras warned."""
    net, warned = load_warned(DATA / "pm4py_dialect.pnml")
    assert list(net.places) == ["source", "paid", "sink"]  # <finalmarkings> places are not places
    assert net.final_marking == {"sink": 1}
    assert net.transition("skip").silent and not net.transition("pay").silent
    assert net.transition("pay").label == "Pay order"
    assert arcs_of(net) >= {("pay", "paid", 2), ("paid", "ship", 2)}
    assert net.transition("pay").guard is None
    assert net.transition("pay").meta["data_guard"] == "(amount > 0)"
    assert len(warned) == 3
    assert any("variables (amount, balance)" in w for w in warned)
    assert any("transition 'pay': data Petri net guard" in w for w in warned)
    assert any("<readVariable>" in w for w in warned)
    assert all(w.startswith(str(DATA / "pm4py_dialect.pnml") + ": ") for w in warned)


def test_woped_operators_are_rebuilt_on_every_part():
    """Each WoPeD operator part carries Operator(group, split, join) from its type code."""
    net, warned = load_warned(DATA / "woped_operators.pnml")
    ops = {t.id: t.operator for t in net.transitions.values()}
    assert ops["t1_op_1"] == ops["t1_op_2"] == Operator("t1", split="xor")
    assert ops["t2_op_1"] == Operator("t2", split="and")
    assert {ops[f"t3_op_{i}"] for i in range(1, 5)} == {Operator("t3", split="xor", join="xor")}
    assert ops["t4_op_1"] == Operator("t4", join="and")
    assert ops["sub1"] is None
    assert "P_CENTER_t3" in net.places  # the XOR/XOR operator's centre place is plain structure
    assert net.transition("t1_op_2").label == "t1" and net.place("p1").label == "start"
    assert (len(net.places), len(net.transitions), len(net.arcs)) == (9, 9, 20)
    assert net.initial_marking == {"p1": 1}


def test_woped_subprocess_stays_one_transition_and_its_ids_do_not_clash():
    """The subprocess page's net (which repeats parent ids) is not read; one warning says so."""
    net, warned = load_warned(DATA / "woped_operators.pnml")
    sub = net.transition("sub1")
    assert net.preset("sub1") == {"p2": 1} and net.postset("sub1") == {"p4": 1}
    assert sub.meta["subprocess"] == {"places": 3, "transitions": 2, "arcs": 4}
    assert not {"sub1_t1", "sub1_p1"} & set(net)
    assert net.place("p2").meta["position"] == [140, 40]  # parent's p2, not the page's
    assert len(warned) == 1
    message = warned[0]
    assert message.startswith(f"{DATA / 'woped_operators.pnml'}: transition 'sub1': subprocess page")
    assert "not inlined" in message and "\n" not in message


def test_jarp_values_read_like_iso_text():
    """JARP / Petri Net Plans use <value> where ISO has <text>."""
    net = read((DATA / "jarp_ptnet.pnml").read_text(encoding="utf-8"), path="jarp_ptnet.pnml")
    assert net.initial_marking == {"p1": 1}
    assert [t.label for t in net.transitions.values()] == ["goto.start", "goto.end"]
    assert arcs_of(net) == {("p1", "t1", 1), ("t1", "p2", 3), ("p2", "t2", 3), ("t2", "p1", 1)}
    assert net.place("p1").meta["position"] == [30, 50]


def test_pipe_class_counts_and_spaced_arc_ids_read_and_gspn_warned_once():
    """PIPE: 'Default,2' counts, arc ids with spaces, one warning for all GSPN timing."""
    net, warned = load_warned(DATA / "pipe_gspn.xml")
    assert net.initial_marking == {"P0": 2}
    assert net.arc("P0", "T0").id == "P0 to T0"
    assert arcs_of(net) == {("P0", "T0", 1), ("T0", "P1", 1), ("P1", "T1", 1), ("T1", "P0", 1)}
    assert net.place("P0").label == "Buffer"
    assert len(warned) == 1 and "transitions 'T0', 'T1': GSPN timing" in warned[0]


def test_snakes_numbers_padded_with_whitespace_and_no_type():
    """SNAKES: no net type, no page, '\\n 2 \\n' counts, arc ids with ':'."""
    net = read((DATA / "snakes_pt.pnml").read_text(encoding="utf-8"), path="snakes_pt.pnml")
    assert net.id == "Two-phase P/T net"
    assert net.initial_marking == {"ready": 2}
    assert net.arc("ready", "begin").id == "ready:begin"
    assert len(net.arcs) == 4


def test_course_material_markings_nested_in_token_and_no_net_id():
    """<initialMarking><token><value> and a <net> with no id (the id comes from the file)."""
    net = read("""
        <pnml><net>
          <place id="s"><initialMarking><token><value>3</value></token></initialMarking></place>
          <transition id="t"/><arc id="a" source="s" target="t"/>
        </net></pnml>""", path="folder/Beispiel.pnml")
    assert net.id == "Beispiel" and net.initial_marking == {"s": 3}


def test_bytes_in_a_declared_encoding_are_decoded():
    """A latin-1 file (ProM writes ISO-8859-1) keeps its accented names."""
    text = ('<?xml version="1.0" encoding="ISO-8859-1"?><pnml><net id="n">'
            '<place id="p"><name><text>Übergabe</text></name></place></net></pnml>')
    assert loads_pnml(text.encode("latin-1")).place("p").label == "Übergabe"


def test_reference_chains_and_reference_transitions_resolve():
    """Arcs through referencePlace chains and referenceTransitions reach the real nodes."""
    net = read(iso("""
        <place id="p"/><transition id="t"/>
        <referencePlace id="r1" ref="r2"/><referencePlace id="r2" ref="p"/>
        <referenceTransition id="rt" ref="t"/>
        <arc id="a1" source="r1" target="rt"/>"""))
    assert arcs_of(net) == {("p", "t", 1)}
    assert list(net.places) == ["p"] and list(net.transitions) == ["t"]


def test_nodes_beside_a_subprocess_net_on_the_same_page_are_kept():
    """A page holding a <net> is a subprocess, yet nodes placed next to that net still count."""
    net, warned = read_warned("""
        <pnml><net id="w"><transition id="s"/>
          <page id="s"><place id="beside"/><net><place id="inner"/></net></page>
        </net></pnml>""")
    assert list(net.places) == ["beside"]
    assert net.transition("s").meta["subprocess"] == {"places": 1, "transitions": 0, "arcs": 0}
    assert len(warned) == 1 and "transition 's': subprocess page not inlined" in warned[0]


def test_absurdly_deep_pages_are_an_error_not_a_crash():
    depth = 5000
    text = f'<pnml><net id="n">{"<page>" * depth}<place id="p"/>{"</page>" * depth}</net></pnml>'
    with pytest.raises(NetFormatError, match="nested more than"):
        loads_pnml(text)


def test_woped_or_split_is_kept_as_plain_transitions_with_a_warning():
    """WoPeD's OR-split (103) has no AND/XOR form: parts stay plain, and we say so."""
    net, warned = read_warned("""
        <pnml><net id="w" type="http://www.informatik.hu-berlin.de/top/pntd/ptNetb">
          <place id="p"/>
          <transition id="t_op_1"><toolspecific tool="WoPeD" version="1.0">
            <operator type="103" id="t"/></toolspecific></transition>
        </net></pnml>""")
    assert net.transition("t_op_1").operator is None
    assert len(warned) == 1 and "OR-split" in warned[0]


def test_woped_operator_codes_match_woped_constants():
    """101..109 as in WoPeD's OperatorTransitionModel (103, the OR-split, excluded)."""
    assert WOPED_OPERATOR_TYPES[101] == ("and", None)
    assert WOPED_OPERATOR_TYPES[102] == (None, "and")
    assert WOPED_OPERATOR_TYPES[104] == ("xor", None)
    assert WOPED_OPERATOR_TYPES[105] == (None, "xor")
    assert WOPED_OPERATOR_TYPES[106] == ("xor", "xor")
    assert 103 not in WOPED_OPERATOR_TYPES


def test_unknown_toolspecific_and_elements_are_warned_not_dropped_silently():
    """Anything unread is named in a warning (one per kind, listing the elements)."""
    net, warned = read_warned(iso("""
        <place id="p"><toolspecific tool="Mystery" version="1"><x/></toolspecific>
          <colour>red</colour></place>
        <place id="q"><colour>blue</colour></place>"""), path="m.pnml")
    assert len(warned) == 2
    assert "m.pnml: place 'p': toolspecific data of tool 'Mystery'" in warned[0]
    assert "m.pnml: places 'p', 'q': <colour> is not part of a P/T net" in warned[1]


def test_parallel_arcs_are_merged_with_a_warning():
    """Two arcs between the same nodes act like one arc of the summed weight."""
    net, warned = read_warned(iso("""
        <place id="p"/><transition id="t"/>
        <arc id="a1" source="p" target="t"/>
        <arc id="a2" source="p" target="t"><inscription><text>2</text></inscription></arc>"""))
    assert arcs_of(net) == {("p", "t", 3)}
    assert len(warned) == 1 and "arc 'a2'" in warned[0] and "merged" in warned[0]


def test_several_final_markings_keep_the_first_with_a_warning():
    net, warned = read_warned("""
        <pnml><net id="n"><page id="g"><place id="a"/><place id="b"/></page>
          <finalmarkings><marking><place idref="a"><text>1</text></place></marking>
          <marking><place idref="b"><text>1</text></place></marking></finalmarkings>
        </net></pnml>""")
    assert net.final_marking == {"a": 1}
    assert len(warned) == 1 and "2 final markings" in warned[0]


# Errors: malformed, unsafe, not P/T, broken nets ---------------------------------------

BROKEN = {
    "truncated": ('<pnml><net id="n">\n<place id="p">\n', "malformed XML", 3),
    "not-pnml": ("<petrinet/>", "not <pnml>", 1),
    "no-net": ("<pnml/>", "no <net>", 1),
    "two-nets": ('<pnml>\n<net id="first"/>\n<net id="second"/>\n</pnml>', "'first', 'second'", 3),
    "symmetric": ('<pnml>\n<net id="c" '
                  'type="http://www.pnml.org/version-2009/grammar/symmetricnet"/></pnml>',
                  "symmetric (coloured) net", 2),
    "hlpn": ('<pnml><net id="h" type="http://www.pnml.org/version-2009/grammar/hlpn"/></pnml>',
             "high-level", 1),
    "empty-type": ('<pnml><net id="e" type="http://www.pnml.org/version-2009/grammar/empty"/></pnml>',
                   "not a place/transition net type", 1),
    "unknown-type": ('<pnml><net id="u" type="Timed Net"/></pnml>', "'Timed Net'", 1),
    "duplicate-id": (iso('\n<place id="x"/>\n<transition id="x"/>'), "duplicate id", 3),
    "duplicate-arc-id": (iso('<place id="p"/><transition id="t"/>\n<arc id="a" source="p" target="t"/>'
                             '\n<arc id="a" source="t" target="p"/>'), "duplicate id", 3),
    "missing-node": (iso('<place id="p"/><transition id="go"/>\n<arc id="a" source="p" target="gox"/>'),
                     "did you mean 'go'", 2),
    "place-to-place": (iso('<place id="p"/><place id="q"/>\n<arc id="a" source="p" target="q"/>'),
                       "joins two places", 2),
    "negative-marking": (iso('<place id="p">\n<initialMarking><text>-1</text></initialMarking></place>'),
                         ">= 0, got -1", 2),
    "fraction-marking": (iso('<place id="p"><initialMarking>\n<text>1.5</text></initialMarking></place>'),
                         "whole number", 2),
    "word-weight": (iso('<place id="p"/><transition id="t"/><arc id="a" source="p" target="t">'
                        '\n<inscription><text>two</text></inscription></arc>'), "whole number", 2),
    "zero-weight": (iso('<place id="p"/><transition id="t"/><arc id="a" source="p" target="t">'
                        '<inscription>\n<text>0</text></inscription></arc>'), ">= 1, got 0", 2),
    "reference-self": (iso('<place id="p"/>\n<referencePlace id="r" ref="r"/>'), "cycle r -> r", 2),
    "reference-cycle": (iso('<place id="p"/>\n<referencePlace id="r3" ref="r7"/>\n'
                            '<referencePlace id="r7" ref="r3"/>'), "cycle r3 -> r7 -> r3", 3),
    "reference-dangling": (iso('<place id="p"/>\n<referencePlace id="r" ref="nowhere"/>'),
                           "unknown node 'nowhere'", 2),
    "reference-wrong-kind": (iso('<transition id="t"/>\n<referencePlace id="r" ref="t"/>'),
                             "refers to the transition 't'", 2),
    "inhibitor": (iso('<place id="p"/><transition id="t"/>\n<arc id="a" source="p" target="t">'
                      '<arctype><text>inhibitor</text></arctype></arc>'), "inhibitor arcs", 2),
    "coloured-counts": ('<pnml><net id="n" type="P/T net"><place id="P">\n<initialMarking>'
                        '<value>Default,1,Red,2</value></initialMarking></place></net></pnml>',
                        "several classes", 2),
    "final-unknown-place": ('<pnml><net id="n"><place id="p"/><finalmarkings><marking>\n'
                            '<place idref="q"><text>1</text></place></marking></finalmarkings></net></pnml>',
                            "unknown place 'q'", 2),
    "no-id": (iso('\n<place/>'), "without an id", 2),
    "cancel-unknown": (iso('<transition id="t"><toolspecific tool="petriflow" version="1">'
                           '<cancel node="ghost"/></toolspecific></transition>'),
                       "cancellation region names unknown node 'ghost'", 1),
    "bad-timeout": (iso('<transition id="t"><toolspecific tool="petriflow" version="1">\n'
                        '<timeout>-3</timeout></toolspecific></transition>'), "timeout must be", 2),
    "bad-outcome": (iso('<place id="p"/><transition id="t"><toolspecific tool="petriflow" version="1">\n'
                        '<outcome kind="crashed" place="p"/></toolspecific></transition>'),
                    "outcome must be one of failed", 2),
    "bad-params": (iso('<transition id="t">\n<toolspecific tool="petriflow" version="1">'
                       '<params>{oops</params></toolspecific></transition>'), "not valid JSON", 2),
    "unknown-subnet": (iso('\n<place id="p"><toolspecific tool="petriflow" version="1">'
                           '<subnet>ghost</subnet></toolspecific></place>'), "unknown subnet", 2),
}


@pytest.mark.parametrize("name", BROKEN)
def test_broken_file_is_rejected_with_line_and_reason(name):
    """Every broken input is a NetFormatError naming the file, the line and the problem."""
    text, reason, line = BROKEN[name]
    with pytest.raises(NetFormatError) as info:
        with warnings.catch_warnings():
            warnings.simplefilter("error", PnmlWarning)
            loads_pnml(text, path="bad.pnml")
    error = info.value
    assert reason in str(error)
    assert error.path == "bad.pnml" and error.line == line, str(error)
    assert str(error).startswith(f"bad.pnml:{line}: ")


def test_errors_name_the_element():
    """The element id is part of the error (duplicate ids, net type, dangling arcs)."""
    assert error_of(BROKEN["duplicate-id"][0]).element == "x"
    assert error_of(BROKEN["symmetric"][0]).element == "c"
    assert error_of(BROKEN["missing-node"][0]).element == "a"
    assert error_of(BROKEN["reference-cycle"][0]).element in ("r3", "r7")


def test_dtd_and_entity_bombs_are_refused():
    """No DOCTYPE: entity expansion bombs never expand."""
    bomb = ('<?xml version="1.0"?>\n<!DOCTYPE pnml [\n<!ENTITY a "aaaaaaaaaa">\n'
            '<!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">\n<!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;">\n]>\n'
            '<pnml><net id="n"><place id="p"><name><text>&c;</text></name></place></net></pnml>')
    error = error_of(bomb)
    assert "DOCTYPE" in str(error) and error.line == 2


def test_external_entities_are_never_fetched(tmp_path):
    """An XXE pointing at a local file (or the network) is refused, not resolved."""
    secret = tmp_path / "secret.txt"
    secret.write_text("top secret", encoding="utf-8")
    for system in (secret.as_uri(), "http://example.invalid/x.dtd"):
        xxe = (f'<?xml version="1.0"?><!DOCTYPE pnml [<!ENTITY x SYSTEM "{system}">]>'
               '<pnml><net id="n"><place id="p"><name><text>&x;</text></name></place></net></pnml>')
        error = error_of(xxe)
        assert "top secret" not in str(error) and "DOCTYPE" in str(error)


def test_undefined_entity_is_malformed_xml():
    error = error_of('<pnml>\n<net id="n"><place id="&nope;"/></net></pnml>')
    assert "malformed XML" in str(error) and error.line == 2


def test_missing_unreadable_and_directory_paths_are_net_format_errors(tmp_path):
    for path in (tmp_path / "absent.pnml", tmp_path):
        with pytest.raises(NetFormatError) as info:
            load_pnml(path)
        assert info.value.path == str(path)
    with pytest.raises(NetFormatError):
        loads_pnml(12)  # type: ignore[arg-type]


def test_accepted_net_types_are_listed():
    assert PTNET_TYPE in PT_NET_TYPES and "P/T net" in PT_NET_TYPES and "PTNet" in PT_NET_TYPES


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
