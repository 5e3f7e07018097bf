"""Export: DOT text, Graphviz pictures, file formats and the ``export`` command."""

from __future__ import annotations

import re
import shutil
import struct
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

import petriflow.export as export
from petriflow.dot import OUTCOME_COLOURS, quote
from petriflow.cli import main
from petriflow.errors import DependencyNotInstalled, PetriflowError, UnknownElementError
from petriflow.export import HIGHLIGHT_COLOUR, export_net, render, to_dot
from petriflow.io import load_net
from petriflow.net import Net

INSPECTION = Path(__file__).resolve().parents[1] / "nets" / "examples" / "inspection.yaml"
SVG = "{http://www.w3.org/2000/svg}"
TOKEN = "\u25cf"

needs_dot = pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz 'dot' not installed")

# A DOT statement for one node, `"id" [attrs];`, or one arc, `"a" -> "b" [attrs];`.
_QUOTED = r'"((?:[^"\\]|\\.)*)"'
_NODE = re.compile(rf"^\s*{_QUOTED} \[(.*)\];$")
_ARC = re.compile(rf"^\s*{_QUOTED} -> {_QUOTED}(?: \[(.*)\])?;$")


def node_statements(source: str) -> dict[str, str]:
    """``{node id: attribute text}`` of a DOT source with plain ids."""
    return {m.group(1): m.group(2) for line in source.splitlines() if (m := _NODE.match(line))}


def arc_statements(source: str) -> dict[tuple[str, str], str]:
    """``{(source, target): attribute text}`` of a DOT source with plain ids."""
    return {
        (m.group(1), m.group(2)): m.group(3) or ""
        for line in source.splitlines()
        if (m := _ARC.match(line))
    }


def svg_nodes(data: bytes) -> list[str]:
    """Titles (node names) of the ``<g class="node">`` groups of an SVG picture."""
    root = ET.fromstring(data)
    return [g.findtext(f"{SVG}title") for g in root.iter(f"{SVG}g") if g.get("class") == "node"]


@pytest.fixture
def inspection() -> Net:
    return load_net(INSPECTION)


def weighted_net() -> Net:
    net = Net("weighted", "Weighted demo")
    net.add_subnet("arm", label="Arm controller", agent="robot_arm")
    net.add_place("stock", tokens=3, subnet="arm")
    net.add_place("boxes")
    net.add_transition("pack", action="arm.pack", subnet="arm")
    net.add_transition("skip", silent=True)
    net.add_arc("stock", "pack", weight=3)
    net.add_arc("pack", "boxes")
    net.add_arc("boxes", "skip")
    net.add_arc("skip", "stock", weight=2)
    return net


# DOT text -------------------------------------------------------------------------------


def test_dot_draws_every_node_with_actions_and_left_to_right(inspection):
    """Every place and transition appears once; bound actions are on the boxes."""
    source = to_dot(inspection)
    nodes = node_statements(source)
    assert set(nodes) == set(inspection.places) | set(inspection.transitions)
    assert "rankdir=LR" in source
    for tid, action in inspection.actions().items():
        assert action in nodes[tid]
    for pid in inspection.places:
        assert "shape=box" not in nodes[pid]
    assert "<B>dispatch</B>" in nodes["dispatch"]
    assert "start" in nodes["i"]  # a place shows its label, not its id
    assert len(arc_statements(source)) == len(inspection.arcs)


def test_dot_has_one_labelled_cluster_per_subnet(inspection):
    """Each agent subnet is a cluster holding its own nodes, labelled with label and agent."""
    source = to_dot(inspection)
    for subnet in inspection.subnets.values():
        start = source.index(f'subgraph "cluster_{subnet.id}" {{')
        body = source[start:source.index("\n  }", start)]
        assert f"<B>{subnet.label}</B>" in body
        assert f"agent: {subnet.agent or subnet.id}" in body
        places, transitions = inspection.nodes_of(subnet.id)
        assert set(node_statements(body)) == set(places) | set(transitions)
    assert source.count('subgraph "cluster_') - source.count('subgraph "cluster_operator_') == len(inspection.subnets)


def test_weights_above_one_are_edge_labels():
    """Weights > 1 label their arc beside it (xlabel, not on the line); weight-1 arcs carry no label."""
    arcs = arc_statements(to_dot(weighted_net()))
    assert 'xlabel="3"' in arcs[("stock", "pack")]
    assert 'xlabel="2"' in arcs[("skip", "stock")]
    assert not re.search(r"(?<![x])label=", arcs[("stock", "pack")])
    assert "label" not in arcs[("pack", "boxes")]


def test_tokens_are_drawn_from_the_marking():
    """The initial marking is drawn by default; a marking argument replaces it."""
    net = weighted_net()
    default = node_statements(to_dot(net))
    assert default["stock"].count(TOKEN) == 3 and TOKEN not in default["boxes"]
    for count in (1, 2, 4):
        assert node_statements(to_dot(net, {"boxes": count}))["boxes"].count(TOKEN) == count
    nodes = node_statements(to_dot(net, {"boxes": 7, "stock": 250}))
    assert "<B>7</B>" in nodes["boxes"] and "<B>250</B>" in nodes["stock"]
    assert TOKEN not in nodes["stock"]
    with pytest.raises(UnknownElementError, match="nowhere"):
        to_dot(net, {"nowhere": 1})


def test_silent_transitions_are_thin_black_bars_without_label():
    attrs = node_statements(to_dot(weighted_net()))["skip"]
    assert 'label=""' in attrs and 'fillcolor="black"' in attrs and "width=0.1" in attrs


def test_title_defaults_to_the_net_label_and_can_be_dropped():
    net = weighted_net()
    assert "<B>Weighted demo</B>" in to_dot(net)
    assert "<B>Packing</B>" in to_dot(net, title="Packing")
    assert "Weighted demo" not in to_dot(net, title="")


def test_highlight_colours_exactly_the_given_nodes(inspection):
    """Highlighted nodes, and only they, get the colour; arcs between them turn bold."""
    chosen = ["i", "capture", "image_ready", "red_walk"]
    source = to_dot(inspection, highlight=chosen)
    coloured = {node for node, attrs in node_statements(source).items() if HIGHLIGHT_COLOUR in attrs}
    assert coloured == set(chosen)
    bold = {arc for arc, attrs in arc_statements(source).items() if HIGHLIGHT_COLOUR in attrs}
    assert bold == {("i", "capture"), ("capture", "image_ready")}
    assert HIGHLIGHT_COLOUR not in to_dot(inspection)


def test_highlighted_firing_sequence_is_a_connected_path(inspection):
    """Transitions only: arcs through the place joining consecutive ones are bold too."""
    sequence = ["capture", "segment", "dispatch", "blue_walk"]
    source = to_dot(inspection, highlight=sequence)
    coloured = {node for node, attrs in node_statements(source).items() if HIGHLIGHT_COLOUR in attrs}
    assert coloured == set(sequence)
    bold = {arc for arc, attrs in arc_statements(source).items() if HIGHLIGHT_COLOUR in attrs}
    assert bold == {
        ("capture", "image_ready"), ("image_ready", "segment"),
        ("segment", "scene_known"), ("scene_known", "dispatch"),
        ("dispatch", "plan_blue"), ("plan_blue", "blue_walk"),
    }


def test_highlight_of_an_unknown_node_is_an_error(inspection):
    with pytest.raises(UnknownElementError, match="captur"):
        to_dot(inspection, highlight=["captur"])


ODD_IDS = [
    "two words", 'say "hi"', "x:y/z", "ünïcödé ☃ 机器人", "tab\there", "line\nbreak",
    "a -> b", "{x}; [y]=z,", "<b>&lt;", '"', "end\\", "\\", "\\\\", 'q\\"r', "mid\\dle",
]


def odd_net() -> Net:
    """A chain alternating places and transitions named by awkward ids."""
    net = Net('odd "net"\\', label='A <label> & "quotes"')
    net.add_subnet('sub "1"/ü', label="Sub <1> & \\", agent='agent "a"')
    previous = None
    for number, node in enumerate(ODD_IDS):
        subnet = 'sub "1"/ü' if number % 3 == 0 else None
        if number % 2 == 0:
            net.add_place(node, tokens=number, subnet=subnet, label=node if number % 4 else None)
        else:
            net.add_transition(node, action=node, guard=node, subnet=subnet, silent=number == 5)
        if previous is not None:
            net.add_arc(previous, node, weight=number)
        previous = node
    return net


def test_awkward_ids_get_distinct_dot_names():
    """Quoting is one-to-one, also for backslashes that Graphviz reads specially."""
    names = [quote(node) for node in ODD_IDS]
    assert len(set(names)) == len(names)
    assert quote('say "hi"') == '"say \\"hi\\""'
    assert quote("end\\") == '"end\\\\"'


@needs_dot
def test_dot_parses_awkward_ids_and_keeps_them(tmp_path):
    """dot reads the source; every node comes out once, named by its id."""
    net = odd_net()
    done = subprocess.run(["dot", "-Tsvg"], input=to_dot(net, highlight=ODD_IDS).encode(),
                          capture_output=True, timeout=60)
    assert done.returncode == 0, done.stderr.decode()
    names = svg_nodes(done.stdout)
    assert len(names) == len(set(names)) == len(ODD_IDS)
    # Backslashes before a quote or the end are doubled, and dot's SVG writer decodes
    # "&lt;" in a name; every other id comes back exactly.
    exact = [node for node in ODD_IDS if "\\" not in node and "&" not in node]
    assert set(exact) <= set(names)
    texts = "".join(t.text or "" for t in ET.fromstring(done.stdout).iter(f"{SVG}text"))
    assert "ünïcödé ☃ 机器人" in texts and "<b>&lt;" in texts and 'agent "a"' in texts


# Files ------------------------------------------------------------------------------------


@needs_dot
def test_svg_has_a_node_per_place_and_transition(tmp_path, inspection):
    out = tmp_path / "net.svg"
    export_net(inspection, out, "svg")
    names = svg_nodes(out.read_bytes())
    assert sorted(names) == sorted(list(inspection.places) + list(inspection.transitions))


@needs_dot
def test_png_is_a_png(tmp_path, inspection):
    out = tmp_path / "net.png"
    export_net(inspection, out, "png", marking={"plan_red": 2}, highlight=["red_walk"])
    assert out.read_bytes().startswith(b"\x89PNG\r\n\x1a\n")


def test_dot_format_writes_the_dot_source(tmp_path, inspection):
    out = tmp_path / "net.dot"
    export_net(inspection, out, "dot", marking={"o": 5}, highlight=["o"], rankdir="LR")
    assert out.read_text(encoding="utf-8") == to_dot(inspection, {"o": 5}, highlight=["o"])


def test_yaml_format_round_trips_and_takes_the_marking(tmp_path, inspection):
    out = tmp_path / "net.yaml"
    export_net(inspection, out, "yaml")
    assert load_net(out).structure() == inspection.structure()
    export_net(inspection, out, "yaml", marking={"plan_red": 1})
    assert load_net(out).initial_marking == {"plan_red": 1}
    assert inspection.initial_marking == {"i": 1}  # the net itself is left alone


def test_pnml_format_goes_through_the_pnml_writer(tmp_path, inspection):
    pytest.importorskip("petriflow.io.pnml")
    out = tmp_path / "net.pnml"
    export_net(inspection, out, "pnml")
    assert out.read_bytes().lstrip().startswith(b"<")
    assert set(load_net(out).places) == set(inspection.places)


def test_unknown_format_and_missing_directory_are_errors(tmp_path, inspection):
    with pytest.raises(PetriflowError, match="unknown export format 'gif'"):
        export_net(inspection, tmp_path / "net.gif", "gif")
    with pytest.raises(PetriflowError, match="cannot draw format 'pdf'"):
        render("digraph {}", tmp_path / "net.pdf", "pdf")
    missing = tmp_path / "no" / "such" / "net.dot"
    with pytest.raises(PetriflowError, match="does not exist") as info:
        export_net(inspection, missing, "dot")
    assert str(missing) in str(info.value)


def test_missing_dot_leaves_the_old_file(tmp_path, inspection, monkeypatch):
    out = tmp_path / "net.svg"
    out.write_text("old picture")
    monkeypatch.setattr(export, "DOT_EXECUTABLE", "dot-that-is-not-installed")
    with pytest.raises(DependencyNotInstalled, match="scripts/setup.sh"):
        export_net(inspection, out, "svg")
    assert out.read_text() == "old picture"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["net.svg"]


@needs_dot
def test_failing_dot_reports_its_error_and_leaves_the_old_file(tmp_path):
    out = tmp_path / "net.png"
    out.write_bytes(b"old picture")
    with pytest.raises(PetriflowError, match=r"Graphviz 'dot' failed: .*syntax error") as info:
        render("digraph { a -> }", out, "png")
    assert "\n" not in str(info.value)
    assert out.read_bytes() == b"old picture"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["net.png"]


def test_slow_dot_times_out_and_leaves_the_old_file(tmp_path, monkeypatch):
    out = tmp_path / "net.svg"
    out.write_text("old picture")

    def too_slow(command, **kwargs):
        raise subprocess.TimeoutExpired(command, kwargs.get("timeout"))

    monkeypatch.setattr(export.shutil, "which", lambda name: name)
    monkeypatch.setattr(export.subprocess, "run", too_slow)
    with pytest.raises(PetriflowError, match="took longer"):
        render("digraph {}", out, "svg")
    assert out.read_text() == "old picture"


# Command line -------------------------------------------------------------------------------


@needs_dot
def test_cli_exports_svg(tmp_path, capsys):
    out = tmp_path / "inspection.svg"
    code = main(["export", str(INSPECTION), "-f", "svg", "-o", str(out), "--marking", '{"red_done": 2}'])
    assert code == 0, capsys.readouterr().err
    assert len(svg_nodes(out.read_bytes())) == 17


def test_cli_missing_output_directory_is_one_line_and_exit_2(tmp_path, capsys):
    out = tmp_path / "missing" / "inspection.svg"
    assert main(["export", str(INSPECTION), "-f", "svg", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(out) in err and "Traceback" not in err
    assert not out.parent.exists()


def test_cli_exports_dot_without_graphviz(tmp_path, monkeypatch):
    monkeypatch.setattr(export, "DOT_EXECUTABLE", "dot-that-is-not-installed")
    out = tmp_path / "inspection.dot"
    assert main(["export", str(INSPECTION), "-f", "dot", "-o", str(out)]) == 0
    assert 'subgraph "cluster_camera"' in out.read_text(encoding="utf-8")


def test_nodes_show_their_id_beside_their_label():
    """What check, replay and errors name (ids) is in the picture next to the label."""
    from petriflow.io import load_net
    from tests.conftest import NETS

    source = to_dot(load_net(NETS / "smart" / "smart.yaml"))
    assert "<B>T5 \u00b7 start cooperative task</B>" in source
    assert "P2 \u00b7 camera standby" in source


def test_operators_carry_markers_and_xor_parts_are_framed_together(inspection):
    """An AND side is marked in its box; the parts of an XOR side sit in one dashed frame."""
    from petriflow.net import Net
    from petriflow.workflow import add_operator

    net = Net("ops")
    for place in ("a", "b", "c", "d"):
        net.add_place(place)
    add_operator(net, "fork", inputs={"a": 1}, outputs={"b": 1, "c": 1}, split="and")
    add_operator(net, "pick", inputs={"b": 1}, outputs={"c": 1, "d": 1}, split="xor")
    source = to_dot(net)
    assert "AND-split \u25b7" in node_statements(source)["fork"]
    frame = source[source.index('subgraph "cluster_operator_pick"'):]
    frame = frame[:frame.index("}")]
    assert '"pick_op_1"' in frame and '"pick_op_2"' in frame and "branch 2 of 2" in source


def test_running_transitions_are_drawn_with_the_tokens_they_hold(inspection):
    source = to_dot(inspection, running={"capture": {"i": 1}})
    from petriflow.export import RUNNING_COLOUR

    assert RUNNING_COLOUR in node_statements(source)["capture"] and "running, holds i" in source


def test_a_caption_says_what_the_picture_shows(inspection):
    assert "the path to the deadlock" in to_dot(inspection, caption="red: the path to the deadlock")


def test_the_format_comes_from_the_ending_and_a_contradiction_is_refused(tmp_path, inspection):
    export_net(inspection, tmp_path / "net.dot")
    assert (tmp_path / "net.dot").read_text().startswith("digraph")
    with pytest.raises(PetriflowError, match="ends in .svg but the format asked for is png"):
        export_net(inspection, tmp_path / "net.svg", "png")
    assert not (tmp_path / "net.svg").exists()


def test_a_wide_net_is_laid_out_top_to_bottom(tmp_path):
    """rankdir auto: a long chain, too wide left to right, is drawn top to bottom."""
    pytest.importorskip("shutil").which("dot") or pytest.skip("Graphviz 'dot' is not installed")
    from petriflow.net import Net

    chain = Net("chain")
    chain.add_place("p0", tokens=1)
    for k in range(12):
        chain.add_place(f"p{k + 1}")
        chain.add_transition(f"t{k}")
        chain.add_arc(f"p{k}", f"t{k}")
        chain.add_arc(f"t{k}", f"p{k + 1}")
    export_net(chain, tmp_path / "chain.dot")
    assert "rankdir=TB" in (tmp_path / "chain.dot").read_text()
    export_net(chain, tmp_path / "lr.dot", rankdir="LR")
    assert "rankdir=LR" in (tmp_path / "lr.dot").read_text()


def charging() -> Net:
    net = Net("charging")
    for place in ("empty", "full", "faulty"):
        net.add_place(place, tokens=int(place == "empty"))
    net.add_transition("charge", action="demo.charge")
    net.add_arc("empty", "charge")
    net.add_arc("charge", "full")
    net.add_arc("charge", "faulty", outcome="failed")
    return net


def test_an_outcome_arc_is_dashed_coloured_and_named_and_an_ok_arc_is_plain():
    arcs = arc_statements(to_dot(charging()))
    failed = arcs[("charge", "faulty")]
    assert "style=dashed" in failed and 'xlabel="failed"' in failed
    assert OUTCOME_COLOURS["failed"] in failed
    plain = arcs.get(("charge", "full"), "")
    assert "dashed" not in plain and "label" not in plain


@pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz missing")
def test_the_svg_shows_the_outcome_beside_its_dashed_arc(tmp_path):
    out = tmp_path / "charging.svg"
    export_net(charging(), out)
    root = ET.fromstring(out.read_bytes())
    ns = {"s": "http://www.w3.org/2000/svg"}
    edges = {e.find("s:title", ns).text: e for e in root.iter("{http://www.w3.org/2000/svg}g")
             if e.get("class") == "edge"}
    failed = edges["charge&#45;&gt;faulty"] if "charge&#45;&gt;faulty" in edges else edges["charge->faulty"]
    assert failed.find("s:path", ns).get("stroke-dasharray")
    assert [t.text for t in failed.iter("{http://www.w3.org/2000/svg}text")] == ["failed"]
    plain = edges["charge->full"]
    assert plain.find("s:path", ns).get("stroke-dasharray") is None


def chain(places: int) -> Net:
    """A long line of places and transitions: wide drawn in full."""
    net = Net("chain")
    for k in range(places):
        net.add_place(f"p{k}", tokens=int(k == 0))
    for k in range(places - 1):
        net.add_transition(f"t{k}")
        net.add_arc(f"p{k}", f"t{k}")
        net.add_arc(f"t{k}", f"p{k + 1}")
    return net


@pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz missing")
def test_a_big_net_drawn_in_full_is_scaled_to_the_bound_and_says_so(tmp_path, capsys):
    from petriflow.fold import FOLD_ABOVE

    net = chain(FOLD_ABOVE)   # 2 * FOLD_ABOVE - 1 nodes in one row: far wider than FULL_SIZE
    out = tmp_path / "chain.png"
    note = export_net(net, out, fold=False, rankdir="LR")
    assert note and f"{2 * FOLD_ABOVE - 1} nodes" in note and "scaled down" in note
    width, height = struct.unpack(">II", out.read_bytes()[16:24])
    assert max(width, height) <= export.FULL_SIZE[0] * export.PNG_DPI + 1
    yaml_file = tmp_path / "chain.yaml"
    export_net(net, yaml_file)
    again = tmp_path / "again.png"
    assert main(["export", str(yaml_file), "-o", str(again), "--full", "--rankdir", "LR"]) == 0
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "too many to read drawn in full" in err


@pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz missing")
def test_a_small_net_is_drawn_without_a_note(tmp_path):
    assert export_net(charging(), tmp_path / "c.png") is None
