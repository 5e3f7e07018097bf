"""Folded pictures of team nets: one box per agent, the mailboxes between them."""

from __future__ import annotations

import re
import shutil
import struct
import subprocess
import sys

import pytest

from petriflow.export import export_net
from petriflow.fold import CROWD, FAN, FAN_ARCS, folded_dot, should_fold
from petriflow.io import load_net
from petriflow.netbuild import NetBuilder
from tests.conftest import NETS

needs_dot = pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz 'dot' not installed")


def team(robots: int):
    """A team built with the API: each robot a work loop, a mailbox every other robot sends into."""
    b = NetBuilder(f"team-{robots}")
    names = [f"r{k}" for k in range(1, robots + 1)]
    agents = {n: b.agent(n, label=f"robot {n}") for n in names}
    boxes = {n: b.mailbox(n, channel="radio", id=f"box_{n}") for n in names}
    for n, a in agents.items():
        a.place("idle")
        a.place("done")
        a.place("listen")
        for peer in names:
            if peer != n:
                b.send(a.transition(f"send_{peer}", inputs=["idle"], outputs=["idle"]), boxes[peer])
        b.receive(a.transition("receive", inputs=["listen"], outputs=["listen"]), boxes[n])
        a.transition("finish", inputs=["idle"], outputs=["done"])
        a.start("idle")
        a.done("done", "listen")
    b.envelope()
    return b.build()


def test_each_agent_is_one_box_and_its_mailbox_a_circle_beside_it():
    net = team(3)
    source = folded_dot(net)
    for name in ("r1", "r2", "r3"):
        assert f'"agent:{name}"' in source and f'"box_{name}" -> "agent:{name}"' in source
        assert f'"{name}_idle"' not in source   # an agent's own places are inside its box
    assert '"agent:r1" -> "box_r2"' in source   # below FAN senders, each sender's arc is drawn


def arcs_of(source: str) -> list[tuple[str, str, str]]:
    """``(source, target, attributes)`` of every arc in folded DOT text."""
    return re.findall(r'^\s*"([^"]+)" -> "([^"]+)"\s*(\[.*?\])?;$', source, flags=re.M)


def test_a_mailbox_many_agents_send_into_says_so_and_keeps_its_senders_arcs():
    net = team(FAN + 2)
    source = folded_dot(net)
    assert f"from {FAN + 1} agents" in source
    assert '"agent:r1" -> "box_r2"' in source and '"box_r2" -> "agent:r2"' in source


def test_beyond_the_fan_budget_fans_go_through_one_crowd_node_and_nothing_loses_its_arcs():
    robots = 13   # 13 mailboxes with 12 senders each: more fan arcs than FAN_ARCS
    assert robots * (robots - 1) > FAN_ARCS
    source = folded_dot(team(robots))
    arcs = arcs_of(source)
    assert len(arcs) < robots * (robots - 1)
    assert f'"{CROWD}"' in source and f"{robots} agents" in source
    for k in range(1, robots + 1):
        assert any(t == f"box_r{k}" for _, t, _ in arcs), f"box_r{k} has no incoming arc"
        assert any(f"agent:r{k}" in (s, t) for s, t, _ in arcs), f"r{k} is not joined to anything"
    crowd_in = [attrs for s, t, attrs in arcs if s == CROWD and t.startswith("box_")]
    assert crowd_in and all('xlabel="12"' in attrs for attrs in crowd_in)


@pytest.mark.parametrize("name, node", [("bidding/bidding-autonomous-20.yaml", None),
                                        ("slam/slam-decentralised.yaml", None)])
def test_shipped_team_nets_folded_keep_every_node_joined(name, node):
    """Every node of the folded drawing of a shipped team net has an arc: no agent box
    floats alone, no transition (bidding's mission over) lacks its incoming arc."""
    net = load_net(NETS / name)
    source = folded_dot(net)
    arcs = arcs_of(source)
    nodes = re.findall(r'^\s*"([^"]+)" \[', source, flags=re.M)
    ends = {n for s, t, _ in arcs for n in (s, t)}
    assert nodes and set(nodes) <= ends, sorted(set(nodes) - ends)[:5]
    targets = {t for _, t, _ in arcs} | {s for s, _, attrs in arcs if "dir=both" in (attrs or "")}
    for t in net.transitions.values():
        if t.subnet is None and net.preset(t.id):
            assert t.id in targets, f"{t.id} lost its incoming arc"


def test_a_failure_route_between_folded_nodes_is_drawn_as_one():
    net = team(2)
    net.add_place("broken")
    net.add_arc("r1_finish", "broken", outcome="failed")
    attrs = {(s, t): a for s, t, a in arcs_of(folded_dot(net))}
    assert "dashed" in attrs["agent:r1", "broken"] and 'xlabel="failed"' in attrs["agent:r1", "broken"]


def test_big_team_nets_fold_by_default_and_small_ones_do_not():
    assert should_fold(load_net(NETS / "bidding" / "bidding-autonomous-20.yaml"))
    assert not should_fold(load_net(NETS / "bidding" / "bidding-autonomous-2.yaml"))
    assert not should_fold(load_net(NETS / "passage" / "passage.yaml"))


def test_export_folds_big_nets_unless_full_is_asked(tmp_path):
    net = load_net(NETS / "bidding" / "bidding-autonomous-20.yaml")
    export_net(net, tmp_path / "auto.dot")
    export_net(net, tmp_path / "full.dot", fold=False)
    auto, full = (tmp_path / "auto.dot").read_text(), (tmp_path / "full.dot").read_text()
    assert "folded: one box per agent" in auto and "folded" not in full
    assert len(auto) * 5 < len(full)


@needs_dot
def test_the_20_robot_bidding_net_folded_fits_4000_px_and_names_every_agent(tmp_path):
    """With the flow between agents kept (every robot joined to the bundle of arcs), the
    22 boxes stack in one rank: taller than the old drawing with no arcs, still bounded."""
    out = tmp_path / "b20.png"
    done = subprocess.run([sys.executable, "-m", "petriflow.cli", "export", str(NETS / "bidding" /
                           "bidding-autonomous-20.yaml"), "-o", str(out), "--fold"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    width, height = struct.unpack(">II", out.read_bytes()[16:24])
    assert max(width, height) < 4000
    svg = tmp_path / "b20.svg"
    export_net(load_net(NETS / "bidding" / "bidding-autonomous-20.yaml"), svg, fold=True)
    text = svg.read_text()
    for agent in ["operator", "hmia", *(f"robot{k}" for k in range(1, 21))]:
        assert f">{agent}</text>" in text


def test_full_and_fold_exclude_each_other(tmp_path):
    done = subprocess.run([sys.executable, "-m", "petriflow.cli", "export", str(NETS / "passage" / "passage.yaml"),
                           "-o", str(tmp_path / "p.dot"), "--fold", "--full"], capture_output=True, text=True)
    assert done.returncode == 2 and "not allowed with" in done.stderr
