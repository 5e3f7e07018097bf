"""Folded pictures of team nets: one box per agent, the mailboxes between them."""

from __future__ import annotations

import shutil
import struct
import subprocess
import sys

import pytest

from petriflow.export import export_net
from petriflow.fold import FAN, folded_dot, should_fold
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


def test_a_mailbox_many_agents_send_into_says_so_instead_of_drawing_every_arc():
    net = team(FAN + 2)
    source = folded_dot(net)
    assert f"from {FAN + 1} agents" in source
    assert '"agent:r1" -> "box_r2"' not in source and '"box_r2" -> "agent:r2"' in source


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
def test_the_20_robot_bidding_net_folded_fits_2000_px_and_names_every_agent(tmp_path):
    out = tmp_path / "b20.png"
    done = subprocess.run([sys.executable, "-m", "petriflow.cli", "export", str(NETS / "bidding" /
                           "bidding-autonomous-20.yaml"), "-o", str(out), "--fold"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    width, height = struct.unpack(">II", out.read_bytes()[16:24])
    assert max(width, height) < 2000
    svg = tmp_path / "b20.svg"
    export_net(load_net(NETS / "bidding" / "bidding-autonomous-20.yaml"), svg, fold=True)
    text = svg.read_text()
    for agent in ["operator", "hmia", *(f"robot{k}" for k in range(1, 21))]:
        assert f">{agent}</text>" in text


def test_full_and_fold_exclude_each_other(tmp_path):
    done = subprocess.run([sys.executable, "-m", "petriflow.cli", "export", str(NETS / "passage" / "passage.yaml"),
                           "-o", str(tmp_path / "p.dot"), "--fold", "--full"], capture_output=True, text=True)
    assert done.returncode == 2 and "not allowed with" in done.stderr
