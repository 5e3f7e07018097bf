"""Reductions (symmetry, stubborn sets, the Rank Theorem) against the full state space.

Every property a reduction claims must equal what the explicit exploration finds: on
the oracle corpus (``--method auto`` against ``--method explicit``), on the team nets,
and on random nets (hypothesis).
"""

from __future__ import annotations

import warnings

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from petriflow.analysis.report import check_net, exit_code
from petriflow.analysis.structural import structural_soundness
from petriflow.analysis.stubborn import reaches_marking, stubborn_deadlocks
from petriflow.analysis.symmetry import find_symmetries, symmetric_graph
from petriflow.engine import enabled
from petriflow.marking import Marking
from petriflow.net import Net

from tests.analysis.nets import philosophers_one_fork
from tests.analysis.strategies import bounded_nets, reference_exploration
from tests.conftest import oracle_cases

VERDICTS = ("workflow_net", "sound", "bounded", "safe", "deadlock_free", "dead_transitions",
            "states", "edges", "max_tokens_place", "max_tokens_marking", "k_bound", "reversible",
            "unbounded_places", "stuck_markings")


def agree(reduced: dict, full: dict, keys=VERDICTS) -> None:
    """Every key the reduced result decides equals the full one."""
    for key in keys:
        if reduced.get(key) is not None:
            assert reduced[key] == full.get(key), key
    if reduced.get("live") is not None:
        assert reduced["live"] == full["live"]
    assert exit_code(reduced) == exit_code(full)


def replay(net: Net, start: Marking, sequence: list[str]) -> Marking:
    """Fire ``sequence`` (row ids; ``t@outcome`` variants) from ``start``."""
    from petriflow.engine import CompiledNet

    compiled = CompiledNet(net)
    vector = compiled.vector(start)
    for name in sequence:
        t = compiled.transition_index[name]
        assert all(vector[p] >= w for p, w in compiled.pre[t]), name
        compiled.consume(vector, t)
        compiled.produce(vector, t)
    return compiled.marking(vector)


@pytest.mark.parametrize("case", oracle_cases(legal_only=True))
def test_oracle_auto_agrees_with_explicit(case):
    """--method auto gives the explicit verdicts on every net of the oracle corpus."""
    import json

    from petriflow.io import load_net

    answer = json.loads((case / "answer.json").read_text())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        net = load_net(case / answer["file"])
    auto = check_net(net, method="auto")
    full = check_net(net, method="explicit")
    agree(auto, full)
    assert set(auto["methods"]) >= {"sound", "deadlock_free", "states"}


@pytest.mark.parametrize("robots,deployment", [(2, "autonomous"), (3, "autonomous"), (3, "random")])
def test_team_net_symmetry_matches_explicit(robots, deployment):
    from petriflow.io import load_net

    net = load_net(f"nets/bidding/bidding-{deployment}-{robots}.yaml")
    auto = check_net(net, method="symmetry")
    full = check_net(net, method="explicit")
    assert auto["methods"]["sound"] == "symmetry"
    assert auto["symmetry"]["groups"] == [[f"robot{k + 1}" for k in range(robots)]]
    assert auto["symmetry"]["canonical_states"] < full["states"]
    agree(auto, full)
    assert auto["live"] == full["live"]        # decided here: some terminal component lacks a transition


def test_symmetric_witnesses_are_concrete():
    """A deadlock in a symmetric net: its witness fires from the initial marking and
    reaches the reported marking, with the agents' own transition names."""
    net = _agents_net(3, [("go", ["idle", "lock"], ["busy"]), ("stuck", ["busy"], ["jam"])],
                      shared={"lock": 1})
    result = check_net(net, method="symmetry")
    assert result["methods"]["deadlock_free"] == "symmetry"
    deadlock = next(v for v in result["violations"] if v["kind"] == "deadlock")
    assert replay(net, net.initial_marking, deadlock["transitions"]) == Marking(deadlock["marking"])
    assert result["stuck_markings"] == check_net(net, method="explicit")["stuck_markings"] == 3


def test_broken_symmetry_is_not_used():
    """An agent whose copy differs (an extra arc) is not in the group."""
    net = _agents_net(3, [("go", ["idle", "lock"], ["busy"]), ("back", ["busy"], ["idle", "lock"])],
                      shared={"lock": 1})
    net.add_arc("a3_idle", "a3_back")       # an extra input on a3 only
    groups = find_symmetries(net)
    assert [g.agents for g in groups] == [["a1", "a2"]]
    agree(check_net(net, method="symmetry"), check_net(net, method="explicit"))


def _agents_net(k: int, steps, shared: dict[str, int], local_start: str = "idle",
                name: str = "agents") -> Net:
    """``k`` agents ``a1..ak`` from one template: ``steps`` are ``(name, inputs,
    outputs)`` over local place names and the ``shared`` places."""
    net = Net(name)
    local = sorted({p for _, ins, outs in steps for p in ins + outs if p not in shared} | {local_start})
    for place in shared:
        net.add_place(place)
    for a in range(1, k + 1):
        net.add_subnet(f"a{a}", state="agent")
        for place in local:
            net.add_place(f"a{a}_{place}", subnet=f"a{a}")
        for step, ins, outs in steps:
            t = f"a{a}_{step}"
            net.add_transition(t, subnet=f"a{a}")
            for p in ins:
                net.add_arc(p if p in shared else f"a{a}_{p}", t)
            for p in outs:
                net.add_arc(t, p if p in shared else f"a{a}_{p}")
    marking = dict(shared)
    marking.update({f"a{a}_{local_start}": 1 for a in range(1, k + 1)})
    net.set_initial_marking(Marking(marking))
    return net


LOCAL = ["idle", "busy", "done"]
SHARED = ["lock", "pool"]


@st.composite
def symmetric_nets(draw) -> Net:
    """2-3 agents from one random template over 3 local and 2 shared places."""
    steps = []
    for s in range(draw(st.integers(1, 4))):
        ins = draw(st.lists(st.sampled_from(LOCAL + SHARED), min_size=1, max_size=2, unique=True))
        outs = draw(st.lists(st.sampled_from(LOCAL + SHARED), min_size=0,
                             max_size=len(ins), unique=True))
        steps.append((f"s{s}", ins, outs))
    shared = {p: draw(st.integers(0, 2)) for p in SHARED}
    return _agents_net(draw(st.integers(2, 3)), steps, shared)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(symmetric_nets())
def test_symmetry_agrees_with_explicit_on_random_nets(net):
    full = check_net(net, method="explicit", max_states=20_000)
    reduced = check_net(net, method="symmetry", max_states=20_000)
    if not full["complete"] or full.get("bounded") is not True:
        return
    agree(reduced, full)
    if reduced.get("symmetry"):
        space = symmetric_graph(net, groups=find_symmetries(net))
        states, edges = reference_exploration(net)
        assert (space.full_states, space.full_edges) == (len(states), edges)
        # every canonical marking is reachable, and its concrete witness reaches its orbit
        for state in range(0, space.num_states, max(1, space.num_states // 5)):
            path, reached = space.concrete(state)
            assert reached in states
            assert replay(net, net.initial_marking, path) == reached


@settings(max_examples=80, deadline=None)
@given(bounded_nets())
def test_stubborn_deadlocks_agree_with_full_space(net):
    states, _ = reference_exploration(net)
    dead = {m for m in states if not enabled(net, m)}
    found = stubborn_deadlocks(net)
    assert found.deadlock == bool(dead)
    assert set(found.deadlocks) <= dead
    if dead:
        assert replay(net, net.initial_marking, found.witness) == found.marking
        assert found.marking in dead
    assert found.states <= len(states)


@settings(max_examples=80, deadline=None)
@given(bounded_nets(), st.integers(0, 1000))
def test_stubborn_reachability_agrees_with_full_space(net, pick):
    states, _ = reference_exploration(net)
    ordered = sorted(states, key=lambda m: sorted(m.items()))
    target = ordered[pick % len(ordered)]
    found = reaches_marking(net, target)
    assert found.deadlock
    assert replay(net, net.initial_marking, found.witness) == target
    # a marking with one token more than the total is never reachable
    total = sum(net.initial_marking.values())
    place = next(iter(net.places))
    assert not reaches_marking(net, {place: total + 1}).deadlock


def test_philosophers_deadlock_by_stubborn_sets():
    net = philosophers_one_fork(30)
    result = check_net(net, method="stubborn")
    assert result["deadlock_free"] is False and result["methods"]["deadlock_free"] == "stubborn"
    witness = next(v for v in result["violations"] if v["kind"] == "deadlock")
    reached = replay(net, net.initial_marking, witness["transitions"])
    assert not enabled(net, reached)
    assert result["states_visited"]["stubborn"] < 1000         # the full space has ~3**30
    assert exit_code(result) == 1


def _workflow(steps) -> Net:
    net = Net("wf")
    places = sorted({p for _, ins, outs in steps for p in ins + outs})
    for p in places:
        net.add_place(p)
    for name, ins, outs in steps:
        net.add_transition(name)
        for p in ins:
            net.add_arc(p, name)
        for p in outs:
            net.add_arc(name, p)
    net.set_initial_marking(Marking({"i": 1}))
    return net


@st.composite
def free_choice_workflows(draw) -> Net:
    """Block-structured WF-nets (sequence, AND, XOR, loop), sometimes with one arc
    dropped or added to make them unsound."""
    counter = [0]

    def fresh(prefix):
        counter[0] += 1
        return f"{prefix}{counter[0]}"

    steps = []

    def block(a, b, depth):
        kind = draw(st.sampled_from(["seq", "and", "xor", "loop", "step"] if depth < 3 else ["step"]))
        if kind == "step":
            steps.append((fresh("t"), [a], [b]))
        elif kind == "seq":
            m = fresh("p")
            block(a, m, depth + 1)
            block(m, b, depth + 1)
        elif kind == "xor":
            block(a, b, depth + 1)
            block(a, b, depth + 1)
        elif kind == "and":
            x1, x2, y1, y2 = (fresh("p") for _ in range(4))
            steps.append((fresh("t"), [a], [x1, x2]))
            block(x1, y1, depth + 1)
            block(x2, y2, depth + 1)
            steps.append((fresh("t"), [y1, y2], [b]))
        else:
            m = fresh("p")
            steps.append((fresh("t"), [a], [m]))
            steps.append((fresh("t"), [m], [a]))
            steps.append((fresh("t"), [m], [b]))

    block("i", "o", 0)
    mutate = draw(st.integers(0, 3))
    if mutate == 1 and len(steps) > 1:
        k = draw(st.integers(0, len(steps) - 1))
        name, ins, outs = steps[k]
        if len(outs) > 1:
            steps[k] = (name, ins, outs[:-1])
    elif mutate == 2:
        k = draw(st.integers(0, len(steps) - 1))
        name, ins, outs = steps[k]
        extra = draw(st.sampled_from(sorted({p for _, i, o in steps for p in i + o} - {"i"})))
        steps[k] = (name, ins, sorted(set(outs) | {extra}))
    return _workflow(steps)


@settings(max_examples=120, deadline=None)
@given(free_choice_workflows())
def test_rank_theorem_agrees_with_explicit(net):
    verdict = structural_soundness(net)
    full = check_net(net, method="explicit", max_states=50_000)
    if verdict.sound is None or not full["complete"] or full["sound"] is None:
        return
    assert verdict.sound == full["sound"], verdict.reason
    assert check_net(net, method="structural", max_states=50_000)["structural"]["sound"] == full["sound"]


def test_structural_answers_when_the_state_space_is_over_the_limit():
    """A free-choice WF-net whose state space is larger than --max-states: the Rank
    Theorem still answers soundness, and says so."""
    steps = [("split", ["i"], [f"a{k}" for k in range(14)])]
    steps += [(f"work{k}", [f"a{k}"], [f"b{k}"]) for k in range(14)]
    steps += [("join", [f"b{k}" for k in range(14)], ["o"])]
    net = _workflow(steps)
    result = check_net(net, method="auto", max_states=1000)
    assert not result["complete"]
    assert result["sound"] is True and result["methods"]["sound"] == "structural"
    assert exit_code(result) == 0
    assert check_net(net, method="explicit", max_states=1000)["sound"] is None


def test_cli_method_and_json(capsys, tmp_path):
    """check --method picks the method; --json names the method of each property."""
    import json

    from petriflow.cli import main

    path = "nets/bidding/bidding-autonomous-3.yaml"
    code = main(["check", path, "--method", "explicit", "--json"])
    full = json.loads(capsys.readouterr().out)
    assert full["methods"]["sound"] == "explicit" and full["states_visited"] == {"explicit": full["states"]}
    assert main(["check", path, "--method", "symmetry", "--json"]) == code
    result = json.loads(capsys.readouterr().out)
    assert result["method"] == "symmetry" and result["methods"]["sound"] == "symmetry"
    assert result["states"] == full["states"]
    assert result["states_visited"]["symmetry"] == result["symmetry"]["canonical_states"] < full["states"]
    assert main(["check", path, "--method", "explicit"]) == code
    out = capsys.readouterr().out
    assert "sound: yes (state space)" in out and "method: explicit" in out
    assert f"markings stored: explicit {full['states']:,}" in out
    with pytest.raises(SystemExit) as stop:
        main(["check", path, "--method", "nope"])
    assert stop.value.code == 2


def test_declared_symmetric_agents_and_routes_and_cancellations():
    """Agents declared in meta.symmetric_agents (different templates by name), with a
    failure route and a cancellation region: the group is verified and used, and every
    property agrees with the full space; a declared group whose swap is no automorphism
    is refused."""
    net = Net("declared")
    net.add_place("lock")
    for a in ("left", "right"):
        net.add_subnet(a, state=f"{a}-arm")
        for place in ("idle", "busy", "err"):
            net.add_place(f"{a}_{place}", subnet=a)
        net.add_transition(f"{a}_go", subnet=a)
        net.add_arc(f"{a}_idle", f"{a}_go")
        net.add_arc("lock", f"{a}_go")
        net.add_arc(f"{a}_go", f"{a}_busy")
        net.add_arc(f"{a}_go", f"{a}_err", outcome="failed")
        net.add_transition(f"{a}_back", subnet=a)
        net.add_arc(f"{a}_busy", f"{a}_back")
        net.add_arc(f"{a}_back", f"{a}_idle")
        net.add_arc(f"{a}_back", "lock")
        net.add_transition(f"{a}_abort", subnet=a, cancels=(f"{a}_busy",))
        net.add_arc(f"{a}_err", f"{a}_abort")
        net.add_arc(f"{a}_abort", f"{a}_idle")
        net.add_arc(f"{a}_abort", "lock")
    net.set_initial_marking(Marking({"lock": 1, "left_idle": 1, "right_idle": 1}))
    assert find_symmetries(net) == []                  # different templates, none declared
    net.meta["symmetric_agents"] = [["left", "right"]]
    assert [g.agents for g in find_symmetries(net)] == [["left", "right"]]
    reduced = check_net(net, method="symmetry")
    full = check_net(net, method="explicit")
    assert reduced["methods"]["deadlock_free"] == "symmetry"
    agree(reduced, full)
    net.add_place("left_spare", subnet="left")          # the swap no longer maps places
    assert find_symmetries(net) == []


def test_symmetry_stopped_at_the_limit_keeps_its_facts():
    """A symmetry-reduced exploration stopped at --max-states: undecided where it must
    be, and the net's bounds still known (P-semiflows)."""
    from petriflow.io import load_net

    net = load_net("nets/bidding/bidding-autonomous-3.yaml")
    result = check_net(net, method="symmetry", max_states=100)
    assert result["complete"] is False and "canonical markings" in result["error"]
    assert result["states"] is None and result["methods"]["states"] is None
    assert result["sound"] is None and "sound" in result["undecided"] and exit_code(result) == 2
    assert result["bounded"] is True and result["partial"]["states_explored"] > 100
