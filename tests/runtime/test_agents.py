"""Agents, their state, guards that cost by what changed, resources, places named in
parameters, and re-registering code: the kernel parts scenarios stand on."""

from __future__ import annotations

import pytest

from petriflow import Param
from petriflow.errors import NetFormatError, PetriflowError
from petriflow.io.yaml import loads_net
from petriflow.runtime.action import InstantAction
from petriflow.runtime.agents import AgentState
from petriflow.runtime.registry import Registry
from petriflow.runtime.scheduler import Scheduler


class Inbox(AgentState):
    """A counter agent: a queue of work per peer."""

    def __init__(self) -> None:
        super().__init__()
        self.waiting: dict[str, int] = {}
        self.done = 0

    def add(self, peer: str) -> None:
        self.waiting[peer] = self.waiting.get(peer, 0) + 1
        self.touch(f"waiting/{peer}")

    def take(self, peer: str) -> None:
        self.waiting[peer] -= 1
        self.touch(f"waiting/{peer}")


def registry_with_agents() -> Registry:
    registry = Registry(False)
    registry.register_state("test.inbox", Inbox)

    class Create(InstantAction):
        agent_state = Inbox
        params = {"peers": Param(list, [])}

        def run(self, ctx):
            state = Inbox()
            for peer in self.params["peers"]:
                state.waiting[peer] = 0
            ctx.state = state

    class Work(InstantAction):
        agent_state = Inbox
        params = {"peer": Param(str)}

        def run(self, ctx):
            ctx.state.take(self.params["peer"])
            ctx.state.done += 1

    class Produce(InstantAction):
        agent_state = Inbox
        params = {"peer": Param(str), "times": Param(int, 1)}

        def run(self, ctx):
            for _ in range(self.params["times"]):
                ctx.state.add(self.params["peer"])

    registry.register("test.create", Create)
    registry.register("test.work", Work)
    registry.register("test.produce", Produce)
    registry.predicate("test.has_work", reads=("waiting/{peer}",))(
        lambda state, params: state is not None and state.waiting.get(params["peer"], 0) > 0)
    return registry


def peers_net(n: int) -> str:
    """One agent with ``n`` peers: a work transition per peer, all on one ``loop``
    place, and a producer that fills peer p0's queue three times."""
    peers = [f"p{i}" for i in range(n)]
    work = "\n".join(f"      - {{id: work_{p}, action: test.work, params: {{peer: {p}}}, guard: test.has_work,"
                     f" in: [loop], out: [loop]}}" for p in peers)
    return f"""petriflow: 1
subnets:
  - id: a
    state: test.inbox
    places: [{{id: start, tokens: 1}}, loop, gate]
    transitions:
      - {{id: create, action: test.create, params: {{peers: {peers}}}, in: [start], out: [loop, gate]}}
      - {{id: produce, action: test.produce, params: {{peer: p0, times: 3}}, in: [gate], out: []}}
{work}
"""


@pytest.mark.parametrize("peers", [2, 40])
def test_a_state_guard_is_asked_again_only_when_its_keys_change(peers):
    """Each firing puts the ``loop`` token back, so every work transition's count check
    runs again; but only the guard whose queue changed is asked again: the number of
    guard calls does not grow with the number of peers."""
    registry = registry_with_agents()
    run = Scheduler(loads_net(peers_net(peers)), registry=registry)
    result = run.run()
    assert result.reason.value == "dead"
    state = run.firer.agents.state("a")
    assert state.done == 3 and state.waiting["p0"] == 0
    # one ask per guard at the start, then only p0's guard after each change of its queue
    assert run.enabled_set.evaluations == peers + 4


def test_a_guard_over_tokens_is_asked_at_every_check():
    """The old guard style (over the tokens offered) has no declared reads: it is asked
    whenever its transition is checked."""
    registry = registry_with_agents()
    asked = []
    registry.predicate("test.any")(lambda tokens, params: asked.append(1) or True)
    net = loads_net("""petriflow: 1
places: [{id: p, tokens: 1}, q]
transitions:
  - {id: t, guard: test.any, in: [p], out: [q]}
  - {id: u, guard: test.any, in: [q], out: [p]}
""")
    run = Scheduler(net, registry=registry)
    run.run(max_firings=10)
    assert len(asked) >= 10 and run.enabled_set.evaluations == len(asked)


def test_the_state_type_is_checked_when_the_net_binds():
    registry = registry_with_agents()

    class Other(AgentState):
        pass

    registry.register_state("test.other", Other)
    text = peers_net(1).replace("state: test.inbox", "state: test.other")
    with pytest.raises(NetFormatError, match="'create': action test.create reads a Inbox state, but subnet 'a'"
                                             " declares state 'test.other'"):
        Scheduler(loads_net(text, path="n.yaml"), registry=registry)
    text = peers_net(1).replace("    state: test.inbox\n", "")
    with pytest.raises(NetFormatError, match="declare it on the subnet"):
        Scheduler(loads_net(text, path="n.yaml"), registry=registry)
    text = peers_net(1).replace("state: test.inbox", "state: test.inbx")
    with pytest.raises(NetFormatError, match=r"unknown agent state 'test.inbx' \(did you mean 'test.inbox'\?\)"):
        Scheduler(loads_net(text, path="n.yaml"), registry=registry)


def test_the_state_survives_yaml_and_pnml():
    from petriflow.io.pnml import dumps_pnml, loads_pnml
    from petriflow.io.yaml import dumps_net

    net = loads_net(peers_net(2))
    assert net.subnets["a"].state == "test.inbox"
    assert loads_net(dumps_net(net)).structure() == net.structure()
    assert loads_pnml(dumps_pnml(net)).subnets["a"].state == "test.inbox"


def test_a_misspelt_place_inside_a_dict_parameter_fails_at_load():
    """comm.initialise names its peers' mailboxes inside a mapping: a typo there is an
    error naming the file, the line and the closest place, before anything runs."""
    from petriflow.runtime.binding import bind

    net = loads_net("""petriflow: 1
subnets:
  - id: r1
    places: [{id: s, tokens: 1}, done, box_r1_r2]
    transitions:
      - id: init
        action: comm.initialise
        params: {index: 0, agents: 2, peers: {r2: {address: 3, box: box_r1_r3}}}
        in: [s]
        out: [done]
""", path="n.yaml")
    with pytest.raises(NetFormatError, match=r"n.yaml:8: 'init': parameter 'peers' names unknown place"
                                             r" 'box_r1_r3' \(did you mean 'box_r1_r2'\?\)"):
        bind(net)


def test_resources_are_made_once_per_run_and_checked_at_bind():
    registry = registry_with_agents()
    made = []
    registry.register_resource("test.plan", lambda context: made.append(1) or {"cells": 4})

    class Use(InstantAction):
        resources = {"plan": "test.plan", "live": "core.liveness"}

        def run(self, ctx):
            return {"cells": ctx.resource("plan")["cells"], "alive": ctx.resource("live").running()}

    registry.register("test.use", Use)
    net = loads_net("""petriflow: 1
subnets:
  - {id: a, places: [{id: p, tokens: 2}, q], transitions: [{id: t, action: test.use, in: [p], out: [q]}]}
""")
    run = Scheduler(net, registry=registry)
    result = run.run()
    assert made == [1]
    assert result.tokens["q"] == [{"cells": 4, "alive": ["a"]}] * 2
    Use.resources = {"plan": "test.plna"}
    with pytest.raises(NetFormatError, match=r"uses resource 'plan': unknown resource 'test.plna'"):
        Scheduler(net, registry=registry)


def test_running_a_cell_twice_replaces_its_action_but_a_name_clash_is_refused():
    """A notebook cell that decorates an action, run again, replaces it; another
    function under the same name is refused (unless replace=True)."""
    from petriflow import action

    registry = Registry(False)
    cell = "@action('nb.charge', registry=registry)\ndef charge(ctx):\n    return {0}\n"
    for value in (1, 2):
        exec(cell.format(value), {"action": action, "registry": registry, "__name__": "__main__"})
    assert registry.resolve("nb.charge").function(None) == 2

    def charge(ctx):  # same name, other code
        return 3

    with pytest.raises(PetriflowError, match="'nb.charge' is already registered"):
        action("nb.charge", registry=registry)(charge)
    action("nb.charge", registry=registry, replace=True)(charge)
    assert registry.resolve("nb.charge").function(None) == 3


def busy_net(peers: int, slots: int) -> str:
    """One agent whose work transitions, one per peer, share ``loop`` and a pool of
    ``slots`` (given back one at a time, a second each); two pacers, every 0.7 s
    and every 1.3 s, add work to a peer picked at random, so guards turn from no to
    yes while the pool is empty, and the pool's count crosses zero again and again."""
    names = [f"p{i}" for i in range(peers)]
    lines = [f"      - {{id: work_{p}, action: test.work, params: {{peer: {p}}}, guard: test.has_work,"
             f" in: [loop, pool], out: [loop, back]}}" for p in names]
    for k, seconds in ((1, 0.7), (2, 1.3)):
        lines.append(f"      - {{id: pace{k}, action: core.wait, params: {{seconds: {seconds}}},"
                     f" in: [gate{k}], out: [fed{k}]}}")
        lines += [f"      - {{id: feed{k}_{p}, action: test.produce, params: {{peer: {p}}}, in: [fed{k}],"
                  f" out: [gate{k}]}}" for p in names]
    work = "\n".join(lines)
    return f"""petriflow: 1
subnets:
  - id: a
    state: test.inbox
    places: [{{id: start, tokens: 1}}, loop, gate1, gate2, fed1, fed2, back, {{id: pool, tokens: {slots}}}]
    transitions:
      - {{id: create, action: test.create, params: {{peers: {names}}}, in: [start],
         out: [loop, gate1, gate2]}}
      - {{id: give_back, action: core.wait, params: {{seconds: 1.0}}, in: [back], out: [pool]}}
{work}
"""


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("slots", [1, 2])
def test_a_guard_that_said_no_misses_no_change_of_its_keys(seed, slots):
    """A transition whose state guard said no is not checked again when only its
    tokens change; it still fires as soon as its keys change with its tokens there: at
    the end of every instant, no work transition is left with its tokens and a guard
    that holds."""
    from petriflow.engine import is_enabled

    registry = registry_with_agents()
    net = loads_net(busy_net(5, slots))
    run = Scheduler(net, registry=registry, seed=seed)
    missed: list = []

    def check(run):
        state = run.firer.agents.states.get("a")
        if state is None:
            return
        marking, running = run.marking(), set(run.running())
        missed.extend((run.now, t) for t in net.transitions if t.startswith("work_") and t not in running
                      and is_enabled(net, marking, t) and state.waiting[t[5:]] > 0)

    run.on_instant(check)
    run.run(until=40)
    state = run.firer.agents.state("a")
    assert not missed
    assert state.done + sum(state.waiting.values()) >= 80  # work came ~2.2 a second
    assert state.done >= 35  # give_back runs one firing at a time: a slot a second
