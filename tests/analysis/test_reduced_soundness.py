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

from petriflow.analysis.reachability import StateSpaceLimit
from petriflow.analysis.reduced_soundness import reduced_soundness
from petriflow.analysis.report import check_net, exit_code
from petriflow.analysis.soundness import check_soundness
from petriflow.engine import CompiledNet
from petriflow.marking import Marking
from petriflow.net import Net
from petriflow.netbuild import NetBuilder

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


def _team_net(k: int, steps, *, local, start: str, done: str, lock: bool = True,
              mail: bool = False, sends: bool = False) -> Net:
    """``k`` agents ``a1..ak`` (one template: ``steps`` are ``(name, inputs, outputs)``
    over the ``local`` places and the shared ``lock``) in the WF envelope of
    :class:`~petriflow.netbuild.NetBuilder`: ``begin`` marks each agent's ``start`` (and
    the lock, a resource, with ``lock``), ``end`` takes each ``done`` back. With ``mail``
    each agent has a mailbox (``box``) and a ``receive``; with ``sends`` a busy agent can
    send into every other agent's mailbox."""
    b = NetBuilder("team")
    if lock or any("lock" in ins + outs for _, ins, outs in steps):
        b.place("lock")
    if lock:
        b.resource("lock")
    agents = [b.agent(f"a{a}", state="agent") for a in range(1, k + 1)]
    boxes = {}
    for agent in agents:
        for place in local:
            agent.place(place)
        if mail:
            boxes[agent.name] = b.mailbox(agent, channel=None)
        agent.start(start)
        agent.done(done)
    for agent in agents:
        for name, ins, outs in steps:
            agent.transition(name, inputs=ins, outputs=outs)
        if mail:
            for other in agents:
                if sends and other is not agent:
                    b.send(agent.transition(f"send_{other.name}", inputs=["busy"], outputs=["busy"]),
                           boxes[other.name])
            b.receive(agent.transition("receive"), boxes[agent.name])
    b.envelope()
    return b.build()


@st.composite
def team_workflows(draw) -> Net:
    """A WF-net of 2-3 agents from one random template: a chain ``start -> busy -> wait
    -> done`` and 1-3 random steps over those places, a shared lock (a resource, or
    only passed between steps) and, sometimes, a mailbox per agent that every other
    busy agent sends into; ``begin`` starts the agents, ``end`` takes every ``done``,
    the lock and the free mailbox slots back."""
    k = draw(st.integers(2, 3))
    mail = draw(st.booleans())
    steps = [("go", ["start"], ["busy"]), ("pause", ["busy"], ["wait"]), ("finish", ["wait"], ["done"])]
    for s in range(draw(st.integers(1, 3))):
        ins = draw(st.lists(st.sampled_from(LOCAL + ["lock"] + (["box"] if mail else [])), min_size=1,
                            max_size=2, unique=True))
        outs = draw(st.lists(st.sampled_from(LOCAL + ["lock"]), min_size=0, max_size=2, unique=True))
        steps.append((f"s{s}", ins, outs))
    return _team_net(k, steps, local=LOCAL, start="start", done="done", lock=draw(st.booleans()),
                     mail=mail, sends=mail)


def _agrees(net: Net) -> bool:
    """Compare with the explicit verdict; returns whether the reduction decided."""
    try:
        full = check_soundness(net, max_states=20_000)
    except StateSpaceLimit:
        return False
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
    steps = [("take", ["idle", "lock"], ["busy"]), ("give", ["busy"], ["done", "lock"])]
    local = ["idle", "busy", "done"]
    if loop:
        # the way out of the cycle needs the lock the stray agent still holds
        steps += [("stray", ["busy"], ["spin"]), ("go_round", ["spin"], ["spun"]),
                  ("come_back", ["spun"], ["spin"]), ("leave", ["spun", "lock"], ["done", "lock"])]
        local += ["spin", "spun"]
    return _team_net(k, steps, local=local, start="idle", done="done")


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
    chain = [(f"t{s}", [f"s{s}"], [f"s{s + 1}"]) for s in range(steps)]
    chain[0] = ("t0", ["s0", "lock"], ["s1"])        # the first step holds a shared lock:
    chain[1] = ("t1", ["s1"], ["s2", "lock"])        # not free-choice (no Rank Theorem)
    return _team_net(k, chain, local=[f"s{s}" for s in range(steps + 1)], start="s0",
                     done=f"s{steps}")


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
