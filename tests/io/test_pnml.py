"""PNML reading: the dialects other tools write, loud errors and warnings."""

from __future__ import annotations

import json
import warnings

import pytest

from petriflow.errors import NetFormatError
from petriflow.io.pnml import (
    PT_NET_TYPES,
    PTNET_TYPE,
    WOPED_OPERATOR_TYPES,
    PnmlWarning,
    dumps_pnml,
    load_pnml,
    loads_pnml,
)
from petriflow.net import Operator
from tests.conftest import ORACLE, oracle_cases
from tests.io.pnml_support import (
    DATA,
    arcs_of,
    error_of,
    iso,
    load_warned,
    read,
    read_warned,
)

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
