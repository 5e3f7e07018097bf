"""Build nets in Python: agents, mailboxes, broadcasts and the WF begin/end envelope.

A :class:`NetBuilder` grows a :class:`~petriflow.net.Net` through the model's own API
(``add_subnet``, ``add_place``, ``add_transition``, ``add_arc``) with the patterns the
multi-robot nets repeat:

* an **agent** is a subnet; its places and transitions get the id
  ``f"{agent}_{local}"`` (the one naming rule), and where an agent's method takes a
  place or transition, a local name of that agent is looked up first, then a full id;
* a **mailbox** is a channel place in its owner's subnet plus a *slot* place holding
  its free capacity: a sender (:meth:`NetBuilder.send`) takes a slot token and puts a
  message, a receiver (:meth:`NetBuilder.receive`) takes the message and gives the slot
  back, so the channel holds at most ``capacity`` messages and the net stays bounded;
* a **broadcast** (:meth:`NetBuilder.broadcast`) is one transition sending into
  several mailboxes at once;
* the **envelope** (:meth:`NetBuilder.envelope`) makes a workflow net of it: ``begin``
  takes the source token ``i`` and hands out every registered start place and every
  resource (each mailbox's slot tokens), ``end`` takes every registered done place and
  every resource back and puts the token in ``o``, the final marking.

:meth:`NetBuilder.build` returns a new, checked :class:`~petriflow.net.Net` each time
it is called (the builder can go on growing); it writes to and reads back from
:mod:`petriflow.io.yaml` and :mod:`petriflow.io.pnml` unchanged.

Examples:
    Two robots play ping-pong: robot1 sends into robot2's mailbox, robot2 answers into
    robot1's.

    >>> b = NetBuilder("pingpong", label="two robots, one message each way")
    >>> r1, r2 = b.agent("robot1"), b.agent("robot2")
    >>> box1 = b.mailbox(r1, channel="radio")   # robot1_box, and its slot robot1_box_slot
    >>> box2 = b.mailbox(r2, channel="radio")
    >>> r1.place("start"), r1.place("wait"), r1.place("done")
    ('robot1_start', 'robot1_wait', 'robot1_done')
    >>> ping = r1.transition("ping", action="demo.say", inputs=["start"], outputs=["wait"])
    >>> b.send(ping, box2)
    >>> b.receive(r1.transition("hear", inputs=["wait"], outputs=["done"]), box1)
    >>> _ = r2.place("start"), r2.place("heard"), r2.place("done")
    >>> b.receive(r2.transition("hear", inputs=["start"], outputs=["heard"]), box2)
    >>> b.send(r2.transition("pong", inputs=["heard"], outputs=["done"]), box1)
    >>> for robot in (r1, r2):
    ...     robot.start("start"); robot.done("done")
    >>> b.envelope()
    >>> net = b.build()
    >>> net, net.initial_marking, net.final_marking
    (<Net 'pingpong': 12 places, 6 transitions, 26 arcs>, Marking({'i': 1}), Marking({'o': 1}))
    >>> net.postset("begin")
    {'robot1_box_slot': 1, 'robot2_box_slot': 1, 'robot1_start': 1, 'robot2_start': 1}

    The analysis agrees it is a sound workflow net:

    >>> from petriflow.analysis.report import check_net
    >>> result = check_net(net)
    >>> result["workflow_net"], result["sound"], result["k_bound"]["robot2_box"]
    (True, True, 1)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Iterable, Mapping, Sequence, Union

from petriflow.errors import NetStructureError, UnknownElementError, did_you_mean
from petriflow.marking import Marking
from petriflow.net import OUTCOMES, Net

__all__ = ["NetBuilder", "AgentBuilder", "Mailbox", "Places", "is_capacity"]


def is_capacity(value: Any) -> bool:
    """Whether ``value`` is a mailbox capacity :meth:`NetBuilder.mailbox` takes: a whole
    number >= 1 (not a bool), or ``"senders"``."""
    return value == "senders" or (isinstance(value, int) and not isinstance(value, bool) and value >= 1)

#: Places an arc list names: one id, a list of ids (weight 1 each) or ``{id: weight}``.
Places = Union[str, Sequence[str], Mapping[str, int]]


@dataclass(frozen=True)
class Mailbox:
    """A bounded channel into an agent (see :meth:`NetBuilder.mailbox`): the net's part,
    two places. The messages themselves are :class:`~petriflow.runtime.channel_models.Message`
    values carrying a scenario's payload; what an agent keeps waiting to send is its own
    state (an outbox), not a mailbox.

    Attributes:
        id: the channel place (its tokens are the messages in flight).
        slot: the place holding the mailbox's free capacity.
        owner: the agent that owns the channel place (its receiver), or ``None``.
        channel: the channel name of the channel place (``Place.channel``).
        capacity: the most messages the mailbox holds at once, or ``"senders"``: one
            per agent that sends into it, counted when the net is built.
    """

    id: str
    slot: str
    owner: str | None
    channel: str | None
    capacity: int | str


class NetBuilder:
    """Grows a net; :meth:`build` returns it as a checked :class:`~petriflow.net.Net`.

    Args:
        net_id: the net's id.
        label: the net's readable title.

    Methods that name places or transitions take full ids (an agent's methods also take
    its local names, see :class:`AgentBuilder`); every element must exist when it is
    named, and errors are :mod:`petriflow.errors` errors, raised before the net is
    changed.
    """

    def __init__(self, net_id: str = "net", label: str | None = None) -> None:
        _check_text(label, "the net's label")
        self._net = Net(net_id, label)
        self._agents: dict[str, AgentBuilder] = {}
        self._mailboxes: dict[str, Mailbox] = {}
        self._begin_out: dict[str, int] = {}  # what begin hands out: {place: weight}
        self._end_in: dict[str, int] = {}  # what end collects
        self._envelope: tuple[str, str, str, str] | None = None  # (source, begin, end, sink)

    # Elements -----------------------------------------------------------------------
    @property
    def agents(self) -> dict[str, AgentBuilder]:
        """``{name: AgentBuilder}`` in the order the agents were added."""
        return dict(self._agents)

    @property
    def mailboxes(self) -> dict[str, Mailbox]:
        """``{channel place id: Mailbox}`` in the order the mailboxes were added."""
        return dict(self._mailboxes)

    def agent(self, name: str, *, label: str | None = None, runner: str | None = None,
              state: str | None = None) -> AgentBuilder:
        """Add an agent: a subnet ``name`` whose elements are named ``f"{name}_{local}"``.

        Args:
            name: the subnet's id.
            label: its readable title.
            runner: the agent that runs it (``Subnet.agent``); default ``name``.
            state: the registered type of the agent's state (``Subnet.state``), if any.
        """
        _check_local(name, "an agent's name")
        _check_text(label, f"agent {name!r}: label")
        _check_text(runner, f"agent {name!r}: runner")
        _check_text(state, f"agent {name!r}: state")
        self._net.add_subnet(name, label, name if runner is None else runner, state)
        self._agents[name] = AgentBuilder(self, name)
        return self._agents[name]

    def place(self, id: str, *, tokens: int = 0, label: str | None = None, channel: str | None = None,
              agent: AgentBuilder | str | None = None) -> str:
        """Add a place and return its id: outside every agent, or in ``agent``'s subnet
        under the full id ``id`` (an id outside the naming rule, such as a net file's)."""
        return self._place(id, self._agent_name(agent), tokens, label, channel)

    def transition(
        self,
        id: str,
        *,
        action: str | None = None,
        params: Mapping[str, Any] | None = None,
        guard: str | None = None,
        priority: int = 0,
        label: str | None = None,
        silent: bool = False,
        timeout: float | None = None,
        inputs: Places = (),
        outputs: Places = (),
        outcomes: Mapping[str, Places] | None = None,
        cancels: Iterable[str] = (),
        agent: AgentBuilder | str | None = None,
    ) -> str:
        """Add a transition with its arcs and return its id: outside every agent, or in
        ``agent``'s subnet under the full id ``id`` (an id outside the naming rule).

        Args:
            id: the transition's id.
            action, params, guard, priority, label, silent, timeout: the fields of
                :class:`~petriflow.net.Transition`; ``params`` must be plain data (text
                keys; text, numbers, booleans, ``None``, lists, mappings), as net files hold.
            inputs: the places it takes from: a list (weight 1 each) or ``{place: weight}``.
            outputs: the places it puts into when its action ends ``ok``.
            outcomes: output places per other outcome (``failed``, ``timeout``,
                ``cancelled``), each given like ``outputs``.
            cancels: the cancellation region: places and transitions (they must exist).
            agent: the agent (or its name) whose subnet holds it; its places may then be
                named locally too.
        """
        return self._transition(id, self._agent_name(agent), action=action, params=params, guard=guard,
                                priority=priority, label=label, silent=silent, timeout=timeout, inputs=inputs,
                                outputs=outputs, outcomes=outcomes, cancels=cancels)

    def arc(self, source: str, target: str, weight: int = 1, *, outcome: str | None = None) -> None:
        """Add one arc between existing nodes (:meth:`Net.add_arc <petriflow.net.Net.add_arc>`)."""
        self._net.add_arc(source, target, weight, outcome=outcome)

    # Messages -----------------------------------------------------------------------
    def mailbox(
        self,
        owner: AgentBuilder | str | None,
        name: str = "box",
        *,
        channel: str | None,
        capacity: int = 1,
        id: str | None = None,
        label: str | None = None,
        slot: str | None = None,
        slot_label: str | None = None,
        slot_agent: AgentBuilder | str | None = None,
    ) -> Mailbox:
        """Add a mailbox of ``owner``: a channel place and a slot place with ``capacity`` tokens.

        The slot is a resource of the envelope (:meth:`resource`): ``begin`` puts
        ``capacity`` tokens in it and ``end`` takes them back, so the run ends with every
        message received.

        Args:
            owner: the agent (or its name) whose subnet holds the channel place; ``None``:
                outside every agent.
            name: the channel place's local name: its id is ``f"{owner}_{name}"`` (``name``
                when there is no owner).
            channel: the channel the place stands for (``Place.channel``: the run's channel
                model delivers its messages); ``None``: a plain place, messages arrive at once.
            capacity: the most messages in the mailbox at once (a whole number >= 1), or
                ``"senders"``: one slot per agent (or transition outside every agent)
                that sends into it, counted by :meth:`build`, so no sender waits for a
                receiver while it has one message in flight to it.
            id: the channel place's full id, instead of the naming rule.
            label: the channel place's label.
            slot: the slot place's id; default ``f"{id}_slot"``.
            slot_label: the slot place's label.
            slot_agent: the agent whose subnet holds the slot place (default ``owner``;
                a point-to-point mailbox may give it to its one sender, whose permission
                to send it is).

        Examples:
            >>> b = NetBuilder()
            >>> inbox = b.mailbox(b.agent("base"), channel="lan", capacity=3)
            >>> inbox
            Mailbox(id='base_box', slot='base_box_slot', owner='base', channel='lan', capacity=3)
        """
        owner_name = self._agent_name(owner)
        slot_owner = owner_name if slot_agent is None else self._agent_name(slot_agent)
        if id is None:
            _check_local(name, "a mailbox's name")
            id = name if owner_name is None else f"{owner_name}_{name}"
        if slot is None:
            slot = f"{id}_slot"
        if not is_capacity(capacity):
            raise NetStructureError(f"mailbox {id!r}: capacity must be a whole number >= 1 or 'senders',"
                                    f" got {capacity!r}")
        if channel is not None and (not isinstance(channel, str) or not channel):
            raise NetStructureError(f"mailbox {id!r}: channel must be a channel name or None,"
                                    f" got {channel!r}")
        for node in (id, slot):
            if node in self._net.places or node in self._net.transitions:
                raise NetStructureError(f"mailbox {id!r}: duplicate id {node!r}")
        if id == slot:
            raise NetStructureError(f"mailbox {id!r}: the slot place needs an id of its own")
        _check_text(label, f"mailbox {id!r}: label")
        _check_text(slot_label, f"mailbox {id!r}: slot label")
        self._net.add_place(id, label=label, subnet=owner_name, channel=channel)
        self._net.add_place(slot, label=slot_label, subnet=slot_owner)
        self.resource(slot, 1 if capacity == "senders" else capacity)  # "senders": counted by build
        box = Mailbox(id, slot, owner_name, channel, capacity)
        self._mailboxes[id] = box
        return box

    def send(self, transition: str, mailbox: Mailbox | str) -> None:
        """Make ``transition`` send one message into ``mailbox`` each time it fires: it
        takes a slot token (so it waits while the mailbox is full) and puts a token in
        the channel place."""
        self.broadcast(transition, [mailbox])

    def broadcast(self, transition: str, mailboxes: Iterable[Mailbox | str]) -> None:
        """Make ``transition`` send one message into each of ``mailboxes`` at once: it
        takes one slot token of each (it waits until every one has room)."""
        tid = self._resolve(transition, "transition")
        boxes = [self._mailbox(m) for m in mailboxes]
        if not boxes:
            raise NetStructureError(f"{tid!r}: a broadcast needs at least one mailbox")
        seen: set[str] = set()
        for box in boxes:
            if box.id in seen:
                raise NetStructureError(f"{tid!r}: mailbox {box.id!r} is named twice")
            seen.add(box.id)
            if self._net.arc(box.slot, tid) is not None or self._net.arc(tid, box.id) is not None:
                raise NetStructureError(f"{tid!r} already sends to mailbox {box.id!r}")
        for box in boxes:
            self._net.add_arc(box.slot, tid)
            self._net.add_arc(tid, box.id)

    def receive(self, transition: str, mailbox: Mailbox | str) -> None:
        """Make ``transition`` take one message from ``mailbox`` each time it fires and
        give its slot token back."""
        tid = self._resolve(transition, "transition")
        box = self._mailbox(mailbox)
        if self._net.arc(box.id, tid) is not None or self._net.arc(tid, box.slot) is not None:
            raise NetStructureError(f"{tid!r} already receives from mailbox {box.id!r}")
        self._net.add_arc(box.id, tid)
        self._net.add_arc(tid, box.slot)

    # The envelope -------------------------------------------------------------------
    def start(self, *places: str) -> None:
        """Register places the envelope's ``begin`` puts one token in (agents' start places)."""
        self._register([self._resolve(p, "place") for p in places], 1, begin=True)

    def done(self, *places: str) -> None:
        """Register places the envelope's ``end`` takes one token from: where an agent
        ends, and places it leaves marked when it does (a listening state)."""
        self._register([self._resolve(p, "place") for p in places], 1, end=True)

    def resource(self, place: str, tokens: int = 1) -> None:
        """Register a resource: ``begin`` puts ``tokens`` tokens in ``place`` and ``end``
        takes them back (every mailbox's slot is one)."""
        self._register([self._resolve(place, "place")], tokens, begin=True, end=True)

    def envelope(
        self,
        *,
        begin: str = "begin",
        end: str = "end",
        source: str = "i",
        sink: str = "o",
        begin_label: str | None = None,
        end_label: str | None = None,
    ) -> None:
        """Add the workflow envelope: the source place ``source`` (one token), the sink
        place ``sink`` and the transitions ``begin`` and ``end``, outside every agent.

        :meth:`build` connects them: ``source -> begin``, ``begin ->`` every start place
        and resource, every done place and resource ``-> end``, ``end -> sink``, with the
        final marking ``{sink: 1}``; places registered before or after this call count.
        """
        if self._envelope is not None:
            raise NetStructureError(f"the net has an envelope already ({self._envelope[1]!r}, "
                                    f"{self._envelope[2]!r})")
        ids = (source, begin, end, sink)
        for node in ids:
            _check_local(node, "an envelope id")
            if node in self._net.places or node in self._net.transitions or ids.count(node) > 1:
                raise NetStructureError(f"envelope: duplicate id {node!r}")
        _check_text(begin_label, f"{begin!r}: label")
        _check_text(end_label, f"{end!r}: label")
        self._net.add_place(source, tokens=1)
        self._net.add_place(sink)
        self._net.add_transition(begin, label=begin_label)
        self._net.add_transition(end, label=end_label)
        self._envelope = ids

    def build(self) -> Net:
        """The net as it stands: a new :class:`~petriflow.net.Net`, checked
        (:meth:`~petriflow.net.Net.check_references`).

        With an envelope, its arcs and final marking are added. Without one, the start
        places and resources are marked in the initial marking instead (as if ``begin``
        had fired) and done places are left as they are.
        """
        net = self._net.copy()
        begin_out, end_in = dict(self._begin_out), dict(self._end_in)
        for box in self._mailboxes.values():
            if box.capacity == "senders":
                senders = {net.transitions[t].subnet or t for t in net.place_preset(box.id)}
                begin_out[box.slot] = end_in[box.slot] = max(1, len(senders))
        if self._envelope is None:
            if begin_out:
                net.set_initial_marking(net.initial_marking + Marking(begin_out))
        else:
            source, begin, end, sink = self._envelope
            net.add_arc(source, begin)
            for place, weight in begin_out.items():
                net.add_arc(begin, place, weight)
            for place, weight in end_in.items():
                net.add_arc(place, end, weight)
            net.add_arc(end, sink)
            net.set_final_marking({sink: 1})
        net.check_references()
        return net

    # Internals ----------------------------------------------------------------------
    def _register(self, places: list[str], weight: int, *, begin: bool = False, end: bool = False) -> None:
        if isinstance(weight, bool) or not isinstance(weight, int) or weight < 1:
            raise NetStructureError(f"{places[0]!r}: tokens must be a whole number >= 1, got {weight!r}")
        for place in places:
            if begin and place in self._begin_out:
                raise NetStructureError(f"{place!r} is already handed out by the envelope's begin")
            if end and place in self._end_in:
                raise NetStructureError(f"{place!r} is already collected by the envelope's end")
        for place in places:
            if begin:
                self._begin_out[place] = weight
            if end:
                self._end_in[place] = weight

    def _agent_name(self, agent: AgentBuilder | str | None) -> str | None:
        if agent is None:
            return None
        name = agent.name if isinstance(agent, AgentBuilder) else agent
        if name not in self._agents or (isinstance(agent, AgentBuilder) and agent.builder is not self):
            raise UnknownElementError("agent", name, self._agents)
        return name

    def _mailbox(self, mailbox: Mailbox | str) -> Mailbox:
        key = mailbox.id if isinstance(mailbox, Mailbox) else mailbox
        if key not in self._mailboxes or (isinstance(mailbox, Mailbox) and self._mailboxes[key] != mailbox):
            raise UnknownElementError("mailbox", key, self._mailboxes)
        return self._mailboxes[key]

    def _resolve(self, ref: str, kind: str, agent: str | None = None) -> str:
        """The full id ``ref`` stands for: ``f"{agent}_{ref}"`` if that exists, else ``ref``."""
        net = self._net
        if kind == "place":
            known: Mapping[str, Any] = net.places
        elif kind == "transition":
            known = net.transitions
        else:
            known = {**net.places, **net.transitions}
        if not isinstance(ref, str) or not ref:
            where = f"agent {agent!r}: " if agent else ""
            raise NetStructureError(f"{where}a {kind} must be named by a non-empty string, got {ref!r}")
        if agent is not None and f"{agent}_{ref}" in known:
            return f"{agent}_{ref}"
        if ref in known:
            return ref
        if agent is None:
            raise UnknownElementError(kind, ref, known)
        prefix = f"{agent}_"
        local = [n[len(prefix):] for n in known if n.startswith(prefix)]
        error = UnknownElementError(kind, ref, [*local, *known])
        error.message = (f"agent {agent!r}: unknown {kind} {ref!r}: neither {prefix + ref!r} nor {ref!r}"
                         f" exists{did_you_mean(ref, [*local, *known])}")
        error.args = (error.message,)
        raise error

    def _branches(self, places: Places, what: str, owner: str, agent: str | None) -> dict[str, int]:
        if isinstance(places, str):
            places = [places]
        pairs = list(places.items()) if isinstance(places, Mapping) else [(p, 1) for p in places]
        branches: dict[str, int] = {}
        for ref, weight in pairs:
            place = self._resolve(ref, "place", agent)
            if isinstance(weight, bool) or not isinstance(weight, int) or weight < 1:
                raise NetStructureError(f"{owner!r}: {what}: weight of {place!r} must be a whole number >= 1,"
                                        f" got {weight!r}")
            if place in branches:
                raise NetStructureError(f"{owner!r}: {what} names place {place!r} twice")
            branches[place] = weight
        return branches

    def _place(self, id: str, subnet: str | None, tokens: int, label: str | None, channel: str | None) -> str:
        _check_text(label, f"{id!r}: label")
        if channel is not None and (not isinstance(channel, str) or not channel):
            raise NetStructureError(f"{id!r}: channel must be a channel name or None, got {channel!r}")
        if isinstance(tokens, bool) or not isinstance(tokens, int) or tokens < 0:
            raise NetStructureError(f"{id!r}: tokens must be a whole number >= 0, got {tokens!r}")
        self._net.add_place(id, tokens=tokens, label=label, subnet=subnet, channel=channel)
        return id

    def _transition(self, id: str, agent: str | None, *, action, params, guard, priority, label, silent,
                    timeout, inputs, outputs, outcomes, cancels) -> str:
        if not isinstance(id, str) or not id:
            raise NetStructureError(f"a transition id must be a non-empty string, got {id!r}")
        if id in self._net.places or id in self._net.transitions:
            raise NetStructureError(f"duplicate id {id!r}")
        for value, what in ((action, "action"), (guard, "guard"), (label, "label")):
            _check_text(value, f"{id!r}: {what}")
        if isinstance(priority, bool) or not isinstance(priority, int):
            raise NetStructureError(f"{id!r}: priority must be a whole number, got {priority!r}")
        if not isinstance(silent, bool):
            raise NetStructureError(f"{id!r}: silent must be True or False, got {silent!r}")
        if params is not None and not isinstance(params, Mapping):
            raise NetStructureError(f"{id!r}: params must be a mapping, got {type(params).__name__}")
        params = dict(params or {})
        _check_plain(params, f"{id!r}: params")
        ins = self._branches(inputs, "inputs", id, agent)
        outs = self._branches(outputs, "outputs", id, agent)
        routed: dict[str, dict[str, int]] = {}
        for outcome, places in (outcomes or {}).items():
            if outcome not in OUTCOMES:
                hint = did_you_mean(outcome, OUTCOMES)
                raise NetStructureError(f"{id!r}: unknown outcome {outcome!r}{hint}"
                                        f" (one of {', '.join(OUTCOMES)}; 'ok' is the outputs)")
            routed[outcome] = self._branches(places, f"outcomes[{outcome!r}]", id, agent)
        region = tuple(self._resolve(node, "place or transition", agent)
                       for node in ([cancels] if isinstance(cancels, str) else cancels))
        if timeout is not None and not isinstance(timeout, bool) and isinstance(timeout, int):
            timeout = float(timeout)  # as net files read it
        self._net.add_transition(id, label=label, action=action, params=params, guard=guard, subnet=agent,
                                 silent=silent, priority=priority, timeout=timeout, cancels=region)
        for place, weight in ins.items():
            self._net.add_arc(place, id, weight)
        for place, weight in outs.items():
            self._net.add_arc(id, place, weight)
        for outcome, branches in routed.items():
            for place, weight in branches.items():
                self._net.add_arc(id, place, weight, outcome=outcome)
        return id


class AgentBuilder:
    """One agent's subnet, made by :meth:`NetBuilder.agent`.

    Its places and transitions get the id ``f"{name}_{local}"``. Where its methods take
    a place or transition, a local name of this agent is looked up first (``"start"``
    is ``f"{name}_start"`` when that exists), then a full id (``"i"``, another agent's
    ``"robot2_done"``).

    Attributes:
        name: the agent's name, which is its subnet's id.
        builder: the :class:`NetBuilder` it belongs to.
    """

    def __init__(self, builder: NetBuilder, name: str) -> None:
        self.builder = builder
        self.name = name

    def __repr__(self) -> str:
        return f"<AgentBuilder {self.name!r}>"

    def id(self, local: str) -> str:
        """The full id of this agent's element ``local`` (it need not exist yet)."""
        _check_local(local, f"agent {self.name!r}: a local name")
        return f"{self.name}_{local}"

    def place(self, local: str, tokens: int = 0, label: str | None = None, channel: str | None = None) -> str:
        """Add a place ``f"{name}_{local}"`` to the agent and return its id."""
        return self.builder._place(self.id(local), self.name, tokens, label, channel)

    def transition(
        self,
        local: str,
        *,
        action: str | None = None,
        params: Mapping[str, Any] | None = None,
        guard: str | None = None,
        priority: int = 0,
        label: str | None = None,
        silent: bool = False,
        timeout: float | None = None,
        inputs: Places = (),
        outputs: Places = (),
        outcomes: Mapping[str, Places] | None = None,
        cancels: Iterable[str] = (),
    ) -> str:
        """Add a transition ``f"{name}_{local}"`` with its arcs and return its id; the
        arguments are :meth:`NetBuilder.transition`'s, places named locally or by full id."""
        return self.builder._transition(self.id(local), self.name, action=action, params=params, guard=guard,
                                        priority=priority, label=label, silent=silent, timeout=timeout,
                                        inputs=inputs, outputs=outputs, outcomes=outcomes, cancels=cancels)

    def start(self, *places: str) -> None:
        """Register this agent's start places: the envelope's ``begin`` marks them."""
        self.builder.start(*(self.builder._resolve(p, "place", self.name) for p in places))

    def done(self, *places: str) -> None:
        """Register this agent's done places: the envelope's ``end`` takes their tokens."""
        self.builder.done(*(self.builder._resolve(p, "place", self.name) for p in places))


def _check_local(name: Any, what: str) -> None:
    if not isinstance(name, str) or not name:
        raise NetStructureError(f"{what} must be a non-empty string, got {name!r}")


def _check_text(value: Any, what: str) -> None:
    if value is not None and not isinstance(value, str):
        raise NetStructureError(f"{what} must be text or None, got {value!r}")


def _check_plain(value: Any, what: str) -> None:
    """Refuse what a net file cannot hold exactly: only text keys; text, whole and
    finite numbers, booleans, ``None``, lists and mappings."""
    stack: list[tuple[Any, str]] = [(value, "")]
    while stack:
        item, where = stack.pop()
        if isinstance(item, dict):
            for key, inner in item.items():
                if not isinstance(key, str):
                    raise NetStructureError(f"{what}: key {key!r}{where and f' in {where}'} must be text")
                stack.append((inner, f"{where}.{key}" if where else repr(key)))
        elif isinstance(item, list):
            stack.extend((inner, f"{where}[{i}]") for i, inner in enumerate(item))
        elif isinstance(item, float) and not math.isfinite(item):
            raise NetStructureError(f"{what}: {where or 'the value'} must be a finite number, got {item!r}")
        elif not (item is None or isinstance(item, (str, int, float, bool))):
            raise NetStructureError(f"{what}: {where or 'the value'} must be text, a number, a boolean, None,"
                                    f" a list or a mapping, got {type(item).__name__} (a net file could not"
                                    f" hold it)")
