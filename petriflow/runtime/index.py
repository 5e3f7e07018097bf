"""What a run needs to know about its net, by transition index, computed once.

A run refers to transitions by their position in the net's order (an index) and to
places by the compiled net's index, so the hot paths read lists, never dictionaries of
strings. :class:`RunIndex` holds those lists: the compiled row of each transition and
of each of its outcome variants, its agent, its bound guard, parameters and action
class, its cancellation region and timeout, and per place the transitions that
consume from it.

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> from petriflow.runtime.binding import bind
    >>> net = loads_net('''
    ... petriflow: 1
    ... subnets: [{id: r, places: [{id: a, tokens: 1}], transitions: [{id: go, in: [a], out: [b]}]}]
    ... places: [b]
    ... ''')
    >>> index = RunIndex(net, bind(net))
    >>> index.ids, index.agent, index.of_agent
    (['go'], ['r'], {'r': [0]})
"""

from __future__ import annotations

from petriflow.engine import CompiledNet
from petriflow.net import Net
from petriflow.outcome import Outcome
from petriflow.runtime.binding import Binding

__all__ = ["RunIndex", "agents_of"]


def agents_of(net: Net) -> list[str]:
    """Agent names of the net's subnets, in declaration order (a subnet's ``agent``, else its id)."""
    seen: dict[str, None] = {}
    for subnet in net.subnets.values():
        seen.setdefault(subnet.agent or subnet.id)
    return list(seen)


class RunIndex:
    """A net and its binding as integer-indexed lists (see the module).

    Attributes:
        compiled: the compiled net (the firing rule on count vectors).
        ids: transition ids in the net's order; a transition's index is its position.
        position: ``{transition id: index}``.
        agent: per transition, its agent (``None`` outside any agent's subnet).
        of_agent: ``{agent: [transition indices]}``.
        row: per transition, its compiled row (the plain firing).
        route: per transition, ``{outcome: compiled row or None}``.
        ok_row: per transition, its ``ok`` outcome's row (``route[t][Outcome.OK]``).
        consumers: per place index, the transitions that consume from it.
        channel: per place index, whether it is a channel place.
        cancels: per transition, the transitions of its cancellation region.
        timeout: per transition, its timeout in seconds (or ``None``).
        guard, params, action_class: per transition, from the binding.
        reads: per transition, the agent-state keys its guard reads (``None``: a guard
            over tokens, or none).
        priority: per transition, its priority.
        state_type: ``{agent: the class of its state}`` for agents whose subnet declares one.
    """

    def __init__(self, net: Net, binding: Binding) -> None:
        compiled = self.compiled = CompiledNet(net)
        ids = self.ids = list(net.transitions)
        self.position = {t: i for i, t in enumerate(ids)}
        agent_of_subnet = {s.id: s.agent or s.id for s in net.subnets.values()}
        transitions = list(net.transitions.values())
        self.agent = [agent_of_subnet[t.subnet] if t.subnet else None for t in transitions]
        self.of_agent: dict[str, list[int]] = {}
        for t, agent in enumerate(self.agent):
            if agent is not None:
                self.of_agent.setdefault(agent, []).append(t)
        self.row = [compiled.transition_index[t] for t in ids]
        self.route = [{o: compiled.row(t, o) for o in Outcome} for t in ids]
        self.ok_row = [route[Outcome.OK] for route in self.route]
        consumers: list[list[int]] = [[] for _ in compiled.places]
        for t, row in enumerate(self.row):
            for p, _ in compiled.pre[row]:
                consumers[p].append(t)
        self.consumers = [tuple(c) for c in consumers]
        self.channel = [net.places[p].channel is not None for p in compiled.places]
        self.cancels = [tuple(self.position[n] for n in t.cancels if n in self.position) for t in transitions]
        self.timeout = [t.timeout for t in transitions]
        self.priority = [t.priority for t in transitions]
        bound = [binding.transitions[t] for t in ids]
        self.guard = [b.guard for b in bound]
        self.guard_name = [t.guard for t in transitions]
        self.params = [b.params for b in bound]
        self.action_class = [b.action for b in bound]
        self.reads = [b.reads for b in bound]
        self.agents = agents_of(net)
        self.state_type = {s.agent or s.id: binding.registry.state_type(s.state)
                           for s in net.subnets.values() if s.state is not None}
