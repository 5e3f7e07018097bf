"""Soundness on the stubborn-set graph up to symmetry against the full state space.

Whatever :func:`reduced_soundness` decides (the verdict and each of the three
conditions) must equal what the explicit exploration finds, on random team WF-nets
(interchangeable agents around shared places and mailboxes, sound or not), on random
block-structured WF-nets, and on the shipped team nets; every witness must replay.
"""

from __future__ import annotations

import json

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from petriflow.analysis.reduced_soundness import reduced_soundness
from petriflow.analysis.report import check_net, exit_code
from petriflow.analysis.soundness import check_soundness
from petriflow.engine import CompiledNet
from petriflow.marking import Marking
from petriflow.net import Net

from tests.analysis.test_reductions import free_choice_workflows, replay


def _can_finish(net: Net, start: Marking, final: Marking, limit: int = 50_000) -> bool:
    """Whether ``final`` is reachable from ``start`` (plain search)."""
    compiled = CompiledNet(net)
    goal = tuple(compiled.vector(final))
    first = tuple(compiled.vector(start))
    seen = {first}
    todo = [first]
    while todo:
        m = todo.pop()
        if m == goal:
            return True
        for t in compiled.enabled(list(m)):
            v = list(m)
            compiled.consume(v, t)
            compiled.produce(v, t)
            nxt = tuple(v)
            if nxt not in seen:
                seen.add(nxt)
                todo.append(nxt)
        assert len(seen) < limit
    return False


LOCAL = ["start", "busy", "wait", "done"]


@st.composite
def team_workflows(draw) -> Net:
    """A WF-net: ``begin`` starts 2-3 agents from one random template (local places,
    a shared lock and a mailbox per agent, sends to every other agent), ``end`` takes
    every agent's ``done``, the lock and the free mailbox slots back."""
    k = draw(st.integers(2, 3))
    steps = []
    for s in range(draw(st.integers(1, 4))):
        ins = draw(st.lists(st.sampled_from(LOCAL + ["lock", "box"]), min_size=1, max_size=2,
                            unique=True))
        outs = draw(st.lists(st.sampled_from(LOCAL + ["lock"]), min_size=0, max_size=2, unique=True))
        steps.append((f"s{s}", ins, outs))
    steps.append(("finish", [draw(st.sampled_from(LOCAL[:3]))], ["done"]))
    sends = draw(st.booleans())
    lock = draw(st.integers(0, 1))
    net = Net("team")
    for p in ("i", "o", "lock"):
        net.add_place(p)
    agents = [f"a{a}" for a in range(1, k + 1)]
    for a in agents:
        net.add_subnet(a, state="agent")
        for p in LOCAL + ["box", "slot"]:
            net.add_place(f"{a}_{p}", subnet=a)

    def arc(place, a):
        return place if place == "lock" else f"{a}_{place}"

    for a in agents:
        for name, ins, outs in steps:
            t = f"{a}_{name}"
            net.add_transition(t, subnet=a)
            for p in ins:
                net.add_arc(arc(p, a), t)
            for p in outs:
                net.add_arc(t, arc(p, a))
        if sends:
            for b in agents:
                if b != a:
                    t = f"{a}_send_{b}"
                    net.add_transition(t, subnet=a)
                    net.add_arc(f"{a}_busy", t)
                    net.add_arc(f"{b}_slot", t)
                    net.add_arc(t, f"{a}_busy")
                    net.add_arc(t, f"{b}_box")
        t = f"{a}_receive"
        net.add_transition(t, subnet=a)
        net.add_arc(f"{a}_box", t)
        net.add_arc(t, f"{a}_slot")
    net.add_transition("begin")
    net.add_arc("i", "begin")
    for a in agents:
        net.add_arc("begin", f"{a}_start")
        net.add_arc("begin", f"{a}_slot")
    if lock:
        net.add_arc("begin", "lock")
    net.add_transition("end")
    for a in agents:
        net.add_arc(f"{a}_done", "end")
        net.add_arc(f"{a}_slot", "end")
    if lock:
        net.add_arc("lock", "end")
    net.add_arc("end", "o")
    net.set_initial_marking(Marking({"i": 1}))
    return net


def _agrees(net: Net) -> bool:
    """Compare with the explicit verdict; returns whether the reduction decided."""
    full = check_soundness(net, max_states=20_000)
    if full.space is None or not full.bounded:
        return False
    found = reduced_soundness(net, max_states=20_000)
    if found.option_to_complete is not None:
        assert found.option_to_complete == full.option_to_complete
    if found.proper_completion is not None:
        assert found.proper_completion == full.proper_completion
    if found.no_dead_transitions is not None:
        assert found.no_dead_transitions == full.no_dead_transitions
    if found.sound is not None:
        assert found.sound == full.sound
    final = full.final_marking
    for violation in found.violations:
        reached = replay(net, Marking({"i": 1}), violation.transitions)
        assert reached.to_dict() == violation.marking
        assert not _can_finish(net, reached, final)
    return found.sound is not None


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(team_workflows())
def test_reduced_soundness_agrees_with_explicit_on_team_nets(net):
    _agrees(net)


@settings(max_examples=80, deadline=None)
@given(free_choice_workflows())
def test_reduced_soundness_agrees_with_explicit_on_workflows(net):
    _agrees(net)


def _team(k: int, loop: bool) -> Net:
    """``k`` agents take a shared lock in turn; with ``loop`` one of them may instead
    enter, lock in hand, a two-step cycle whose exit needs the lock: it never leaves
    (a livelock, not a deadlock)."""
    net = Net("lockers")
    for p in ("i", "o", "lock"):
        net.add_place(p)
    net.add_transition("begin")
    net.add_arc("i", "begin")
    net.add_arc("begin", "lock")
    net.add_transition("end")
    net.add_arc("lock", "end")
    net.add_arc("end", "o")
    for a in range(1, k + 1):
        net.add_subnet(f"a{a}", state="agent")
        for p in ("idle", "busy", "done") + (("spin", "spun") if loop else ()):
            net.add_place(f"a{a}_{p}", subnet=f"a{a}")
        net.add_arc("begin", f"a{a}_idle")
        net.add_arc(f"a{a}_done", "end")
        steps = [("take", ["idle", "lock"], ["busy"]), ("give", ["busy"], ["done", "lock"])]
        if loop:
            # the way out of the cycle needs the lock the stray agent still holds
            steps += [("stray", ["busy"], ["spin"]), ("go_round", ["spin"], ["spun"]),
                      ("come_back", ["spun"], ["spin"]), ("leave", ["spun", "lock"], ["done", "lock"])]
        for name, ins, outs in steps:
            t = f"a{a}_{name}"
            net.add_transition(t, subnet=f"a{a}")
            for p in ins:
                net.add_arc(p if p == "lock" else f"a{a}_{p}", t)
            for p in outs:
                net.add_arc(t, p if p == "lock" else f"a{a}_{p}")
    net.set_initial_marking(Marking({"i": 1}))
    return net


def test_a_team_of_twelve_is_sound_on_a_small_reduced_graph():
    found = reduced_soundness(_team(12, loop=False))
    assert found.sound is True and found.method == "stubborn+symmetry"
    assert len(found.groups[0]) == 12
    assert found.states < 100                     # the full space has over 3**12 markings


def test_a_livelock_is_found_without_a_deadlock():
    """An agent that strays into a cycle never lets the net finish: no dead marking
    other than the final one exists, yet the option to complete fails."""
    net = _team(5, loop=True)
    found = reduced_soundness(net)
    assert found.sound is False and found.option_to_complete is False
    violation = found.violations[0]
    assert violation.kind == "no_option_to_complete"
    reached = replay(net, Marking({"i": 1}), violation.transitions)
    assert not _can_finish(net, reached, Marking({"o": 1}))
    assert _agrees(_team(3, loop=True)) is True


def test_not_decided_without_a_covering_semiflow():
    """A busy agent may log as often as it likes: the log is covered by no P-semiflow,
    boundedness and proper completion are not proved, so soundness stays open (the
    reduction never guesses)."""
    net = _team(2, loop=False)
    net.add_place("log")
    for a in ("a1", "a2"):
        net.add_transition(f"{a}_note", subnet=a)
        net.add_arc(f"{a}_busy", f"{a}_note")
        net.add_arc(f"{a}_note", f"{a}_busy")
        net.add_arc(f"{a}_note", "log")
    net.add_arc("log", "end")
    found = reduced_soundness(net, max_states=5_000)
    assert found.sound is None and "P-semiflow" in found.reason
    assert check_soundness(net).sound is False     # unbounded


@pytest.mark.parametrize("robots", [2, 3])
def test_bidding_team_nets_agree(robots):
    from petriflow.agents.bidding.nets import build

    net = build(robots, "autonomous")
    found = reduced_soundness(net)
    assert found.sound is True and found.groups
    assert check_net(net, method="explicit")["sound"] is True


def test_check_stubborn_and_auto_report_the_reduced_answer(tmp_path, capsys):
    from petriflow.cli import main
    from petriflow.io.yaml import dumps_net

    path = tmp_path / "team.yaml"
    path.write_text(dumps_net(_team(9, loop=False)))
    assert main(["check", str(path), "--method", "stubborn", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["sound"] is True and result["methods"]["sound"] == "stubborn+symmetry"
    assert result["states_visited"]["stubborn+symmetry"] == result["reduced"]["states"]
    full = check_net(_team(9, loop=False), method="explicit")
    for key in ("bounded", "deadlock_free", "deadlock_markings", "dead_transitions", "live", "reversible",
                "stuck_markings"):
        assert result[key] == full[key], key
    assert result["methods"]["live"] == "stubborn+symmetry"
    # auto: the symmetric exploration stops at the limit, the reduced graph answers
    net = _parallel(9, 4)
    assert check_net(net, method="symmetry")["symmetry"]["canonical_states"] > 300
    auto = check_net(net, method="auto", max_states=100)
    assert auto["complete"] is False and auto["sound"] is True
    assert auto["methods"]["sound"] == "stubborn+symmetry" and auto["reduced"]["states"] <= 100
    assert exit_code(auto) == 0
    net.add_arc("a3_s2", "end")                  # a token the end never gets: unsound
    auto = check_net(net, method="auto", max_states=100)
    assert auto["sound"] is False and exit_code(auto) == 1


def _parallel(k: int, steps: int) -> Net:
    """``k`` agents that each take ``steps`` steps (2 or more), between a fork and a join."""
    net = Net("parallel")
    net.add_place("i")
    net.add_place("o")
    net.add_place("lock")
    net.add_transition("begin")
    net.add_transition("end")
    net.add_arc("i", "begin")
    net.add_arc("end", "o")
    for a in range(1, k + 1):
        net.add_subnet(f"a{a}", state="agent")
        for s in range(steps + 1):
            net.add_place(f"a{a}_s{s}", subnet=f"a{a}")
        for s in range(steps):
            net.add_transition(f"a{a}_t{s}", subnet=f"a{a}")
            net.add_arc(f"a{a}_s{s}", f"a{a}_t{s}")
            net.add_arc(f"a{a}_t{s}", f"a{a}_s{s + 1}")
        net.add_arc("begin", f"a{a}_s0")
        net.add_arc(f"a{a}_s{steps}", "end")
        net.add_arc("lock", f"a{a}_t0")         # the first step holds a shared lock:
        net.add_arc(f"a{a}_t1", "lock")         # not free-choice (no Rank Theorem)
    net.add_arc("begin", "lock")
    net.add_arc("lock", "end")
    net.set_initial_marking(Marking({"i": 1}))
    return net


@pytest.mark.parametrize("path", ["nets/bus/bus-algorithm2-3.yaml", "nets/comm/comm-centralised-3.yaml",
                                  "nets/slam/slam-decentralised.yaml", "nets/smart/smart.yaml",
                                  "nets/swarm/swarm-3.yaml"])
def test_shipped_nets_agree(path):
    """The scenarios' nets (agents, mailboxes, media, outcome routes): the reduced
    graph is smaller and says what the full state space says."""
    from petriflow.io import load_net

    net = load_net(path)
    found = reduced_soundness(net)
    full = check_soundness(net)
    assert found.sound is not None and found.sound == full.sound
    assert found.states <= len(full.space.markings)
