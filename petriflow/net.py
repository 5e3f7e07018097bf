"""The net model: places, transitions, weighted arcs, subnets.

A :class:`Net` is structure only. Its initial and final markings are :class:`Marking`
values kept beside the structure; firing never changes a net. Analysis and firing are
free functions in :mod:`petriflow.engine` and :mod:`petriflow.analysis`.

Examples:
    >>> net = Net("pingpong")
    >>> net.add_place("ready", tokens=1)
    Place(id='ready', label=None, subnet=None, meta={}, channel=None)
    >>> _ = net.add_place("done")
    >>> _ = net.add_transition("go", action="robot.move", params={"speed": 0.2})
    >>> net.add_arc("ready", "go"); net.add_arc("go", "done", weight=2)
    Arc(source='ready', target='go', weight=1, id=None, outcome=None)
    Arc(source='go', target='done', weight=2, id=None, outcome=None)
    >>> net.preset("go"), net.postset("go")
    ({'ready': 1}, {'done': 2})
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Iterator, Mapping

from petriflow.errors import NetStructureError, UnknownElementError, did_you_mean
from petriflow.marking import Marking
from petriflow.outcome import ROUTED_OUTCOMES, Outcome

__all__ = ["Place", "Transition", "Arc", "Subnet", "Operator", "Net", "OPERATOR_KINDS", "OUTCOMES"]

#: The routing kinds of a WF-net operator's split or join side.
OPERATOR_KINDS = ("and", "xor")

#: Outcomes of an action that output arcs can be reserved for (plain arcs mean ``ok``),
#: as the plain strings files hold (:class:`~petriflow.outcome.Outcome` values).
OUTCOMES = tuple(o.value for o in ROUTED_OUTCOMES)


@dataclass(frozen=True)
class Place:
    """A place. Tokens live in markings, not here.

    Attributes:
        id: unique id within the net.
        label: human-readable name (defaults to the id when drawn).
        subnet: id of the agent subnet the place belongs to, if any.
        meta: free-form data other tools wrote (graphics position, ...), kept for
            round-trips; petriflow's semantics never read it.
        channel: name of the communication channel this place stands for, if it
            carries messages between agents; at run time a channel model decides
            whether and when a token put here arrives.
    """

    id: str
    label: str | None = None
    subnet: str | None = None
    meta: dict[str, Any] = field(default_factory=dict, compare=False)
    channel: str | None = None


@dataclass(frozen=True)
class Operator:
    """Membership of a transition in a WF-net operator (WoPeD-style AND/XOR split/join).

    An operator ``t`` with an XOR side is expanded into plain P/T transitions
    ``t_op_1``, ``t_op_2``, ... that all carry ``Operator(group="t", ...)``, so a writer
    can fold them back into one operator.

    Attributes:
        group: id of the operator as the user wrote it.
        split: ``"and"``, ``"xor"`` or ``None`` (a single output branch).
        join: ``"and"``, ``"xor"`` or ``None`` (a single input branch).
    """

    group: str
    split: str | None = None
    join: str | None = None


@dataclass(frozen=True)
class Transition:
    """A transition, optionally bound to an agent action.

    Attributes:
        id: unique id within the net.
        label: activity label (what an event log calls it); defaults to the id.
        action: registered action name this transition runs, e.g. ``"vision.capture"``.
        params: the action's parameters (plain data).
        guard: registered predicate name that must hold for the transition to fire
            at run time (no code from files is ever evaluated).
        subnet: id of the agent subnet the transition belongs to, if any.
        silent: an invisible (tau) transition: routing only, no event in logs.
        priority: higher fires first when several are enabled at run time.
        operator: the WF operator this transition was expanded from, if any.
        meta: free-form data for round-trips (graphics...), never read by semantics.
        timeout: simulated seconds after which a running action ends with the
            ``timeout`` outcome (``None``: no limit).
        cancels: the cancellation region: ids of places emptied and of transitions
            whose running actions are cancelled when this transition fires.
    """

    id: str
    label: str | None = None
    action: str | None = None
    params: dict[str, Any] = field(default_factory=dict, hash=False)
    guard: str | None = None
    subnet: str | None = None
    silent: bool = False
    priority: int = 0
    operator: Operator | None = None
    meta: dict[str, Any] = field(default_factory=dict, compare=False)
    timeout: float | None = None
    cancels: tuple[str, ...] = ()


@dataclass(frozen=True)
class Arc:
    """A weighted arc from a place to a transition or from a transition to a place.

    Attributes:
        outcome: on an output arc, the action outcome it is reserved for (one of
            :data:`OUTCOMES`); ``None`` means the arc produces when the action ends ``ok``.
    """

    source: str
    target: str
    weight: int = 1
    id: str | None = field(default=None, compare=False)
    outcome: str | None = None


@dataclass(frozen=True)
class Subnet:
    """A named group of places and transitions, typically one agent's part of the net.

    Attributes:
        id: unique id among subnets.
        label: readable title (drawn on the cluster).
        agent: the agent that runs this subnet (defaults to the id).
        state: the registered type of the agent's state (``bidding.robot``), or
            ``None``: the actions bound in the subnet that read an agent state must
            expect this type (checked when the net is bound).
    """

    id: str
    label: str | None = None
    agent: str | None = None
    state: str | None = None


class Net:
    """A place/transition net with weighted arcs, agent subnets and markings.

    Args:
        id: the net's id (file name stem by default when loaded).
        label: readable title.

    Attributes:
        places: ``{id: Place}`` in insertion order.
        transitions: ``{id: Transition}`` in insertion order.
        subnets: ``{id: Subnet}``.
        initial_marking: the marking the net starts in.
        final_marking: the marking a run should end in (WF-nets: one token in ``o``),
            or ``None`` when the file gives none.
        meta: free-form data kept for round-trips.
    """

    def __init__(self, id: str = "net", label: str | None = None) -> None:
        self.id = id
        self.label = label
        self.places: dict[str, Place] = {}
        self.transitions: dict[str, Transition] = {}
        self.subnets: dict[str, Subnet] = {}
        self._arcs: dict[tuple[str, str, str | None], Arc] = {}
        self._pre: dict[str, dict[str, int]] = {}
        self._post: dict[str, dict[str, int]] = {}
        self._post_outcome: dict[str, dict[str, dict[str, int]]] = {}
        self._initial_counts: dict[str, int] = {}
        self._initial: Marking | None = Marking()
        self.final_marking: Marking | None = None
        self.meta: dict[str, Any] = {}
        #: The run configuration the net names (``run:`` in YAML): a file name relative
        #: to the net's file, or the configuration itself as a mapping; ``None``: none.
        self.run: str | dict[str, Any] | None = None
        #: What the net must guarantee (``properties:`` in YAML): a list of
        #: :class:`~petriflow.properties.language.Property`, checked by
        #: ``petriflow check --properties`` and watched by ``petriflow run --monitor``.
        self.properties: list[Any] = []
        #: The file the net was read from, if any (errors name it).
        self.path: str | None = None
        #: Where the reader found each element: ``{id: line}``, and ``"id/key"`` (e.g.
        #: ``"walk/action"``, ``"walk/params/speed"``) for a transition's keys.
        self.lines: dict[str, int] = {}

    # Building -----------------------------------------------------------------------
    def _check_new_id(self, node_id: str) -> None:
        if not isinstance(node_id, str) or not node_id:
            raise NetStructureError(f"node id must be a non-empty string, got {node_id!r}")
        if node_id in self.places or node_id in self.transitions:
            raise NetStructureError(f"duplicate id {node_id!r}")

    def _check_subnet(self, node_id: str, subnet: str | None) -> None:
        if subnet is not None and subnet not in self.subnets:
            raise NetStructureError(
                f"{node_id!r}: unknown subnet {subnet!r}{did_you_mean(subnet, self.subnets)}"
            )

    def add_subnet(self, id: str, label: str | None = None, agent: str | None = None,
                   state: str | None = None) -> Subnet:
        """Add an agent subnet; nodes join it through their ``subnet`` attribute."""
        if not isinstance(id, str) or not id.strip():
            raise NetStructureError(f"subnet id must be non-empty text, got {id!r}")
        if id in self.subnets:
            raise NetStructureError(f"duplicate subnet id {id!r}")
        for what, value in (("agent", agent), ("state", state)):
            if value is not None and (not isinstance(value, str) or not value.strip()):
                raise NetStructureError(f"subnet {id!r}: {what} must be non-empty text, got {value!r}")
        subnet = Subnet(id, label, agent, state)
        self.subnets[id] = subnet
        return subnet

    def add_place(
        self,
        id: str,
        *,
        tokens: int = 0,
        label: str | None = None,
        subnet: str | None = None,
        meta: dict[str, Any] | None = None,
        channel: str | None = None,
    ) -> Place:
        """Add a place holding ``tokens`` tokens in the initial marking."""
        self._check_new_id(id)
        self._check_subnet(id, subnet)
        place = Place(id, label, subnet, dict(meta or {}), channel)
        self.places[id] = place
        if tokens:
            Marking({id: tokens})  # validates the count
            self._initial_counts[id] = tokens
            self._initial = None  # rebuilt on demand: adding n marked places stays O(n)
        return place

    def add_transition(self, id: str, **attributes: Any) -> Transition:
        """Add a transition; ``attributes`` are the fields of :class:`Transition`."""
        self._check_new_id(id)
        self._check_subnet(id, attributes.get("subnet"))
        timeout = attributes.get("timeout")
        if timeout is not None and (isinstance(timeout, bool) or not isinstance(timeout, (int, float))
                                    or not timeout > 0):
            raise NetStructureError(f"{id!r}: timeout must be a number of seconds > 0, got {timeout!r}")
        if "cancels" in attributes:
            attributes["cancels"] = tuple(attributes["cancels"] or ())
        transition = Transition(id, **attributes)
        self.transitions[id] = transition
        self._pre[id] = {}
        self._post[id] = {}
        self._post_outcome[id] = {}
        return transition

    def add_arc(self, source: str, target: str, weight: int = 1, id: str | None = None,
                outcome: str | None = None) -> Arc:
        """Connect a place and a transition (either way) with a positive integer weight.

        ``outcome`` reserves an output arc for an action outcome (see :data:`OUTCOMES`).
        """
        if isinstance(weight, bool) or not isinstance(weight, int) or weight < 1:
            raise NetStructureError(
                f"arc {source!r} -> {target!r}: weight must be a whole number >= 1, got {weight!r}"
            )
        if outcome == "ok":
            outcome = None
        if outcome is not None and outcome not in OUTCOMES:
            raise NetStructureError(
                f"arc {source!r} -> {target!r}: outcome must be one of ok, {', '.join(OUTCOMES)};"
                f" got {outcome!r}"
            )
        key = (source, target, outcome)
        if key in self._arcs:
            raise NetStructureError(f"duplicate arc {source!r} -> {target!r}")
        if source in self.places and target in self.transitions:
            if outcome is not None:
                raise NetStructureError(
                    f"arc {source!r} -> {target!r}: only output arcs can be reserved for an outcome"
                )
            self._pre[target][source] = weight
        elif source in self.transitions and target in self.places:
            if outcome is None:
                self._post[source][target] = weight
            else:
                self._post_outcome[source].setdefault(outcome, {})[target] = weight
        else:
            raise NetStructureError(self._arc_problem(source, target))
        arc = Arc(source, target, weight, id, outcome)
        self._arcs[key] = arc
        return arc

    def _arc_problem(self, source: str, target: str) -> str:
        nodes = list(self.places) + list(self.transitions)
        for end in (source, target):
            if end not in self.places and end not in self.transitions:
                return f"arc {source!r} -> {target!r}: unknown node {end!r}{did_you_mean(end, nodes)}"
        kind = "places" if source in self.places else "transitions"
        return f"arc {source!r} -> {target!r} joins two {kind}; arcs join a place and a transition"

    @property
    def initial_marking(self) -> Marking:
        """The marking the net starts in."""
        if self._initial is None:
            self._initial = Marking(self._initial_counts)
        return self._initial

    @initial_marking.setter
    def initial_marking(self, marking: Mapping[str, int]) -> None:
        self._initial = marking if isinstance(marking, Marking) else Marking(marking)
        self._initial_counts = dict(self._initial)

    def set_initial_marking(self, marking: Mapping[str, int]) -> None:
        """Replace the initial marking (every place it names must exist)."""
        self.initial_marking = self.check_marking(marking)

    def set_final_marking(self, marking: Mapping[str, int] | None) -> None:
        """Replace the final marking (``None``: the net declares none)."""
        self.final_marking = None if marking is None else self.check_marking(marking)

    def check_marking(self, marking: Mapping[str, int]) -> Marking:
        """Return ``marking`` as a :class:`Marking`, checking every place exists."""
        for place in marking:
            if place not in self.places:
                raise UnknownElementError("place", place, self.places)
        return marking if isinstance(marking, Marking) else Marking(marking)

    # Queries ------------------------------------------------------------------------
    @property
    def arcs(self) -> list[Arc]:
        """Every arc, in insertion order."""
        return list(self._arcs.values())

    def arc(self, source: str, target: str, outcome: str | None = None) -> Arc | None:
        """The arc from ``source`` to ``target`` (for ``outcome``), or ``None``."""
        return self._arcs.get((source, target, None if outcome == "ok" else outcome))

    def transition(self, id: str) -> Transition:
        """The transition ``id``; raises :class:`UnknownElementError` with a hint."""
        try:
            return self.transitions[id]
        except KeyError:
            raise UnknownElementError("transition", id, self.transitions) from None

    def place(self, id: str) -> Place:
        """The place ``id``; raises :class:`UnknownElementError` with a hint."""
        try:
            return self.places[id]
        except KeyError:
            raise UnknownElementError("place", id, self.places) from None

    def preset(self, transition: str) -> dict[str, int]:
        """``{place: weight}`` consumed by ``transition``."""
        self.transition(transition)
        return dict(self._pre[transition])

    def postset(self, transition: str, outcome: str | None = None) -> dict[str, int]:
        """``{place: weight}`` produced by ``transition`` when its action ends with
        ``outcome`` (default ``ok``: the plain output arcs)."""
        self.transition(transition)
        if outcome is None or outcome == "ok":
            return dict(self._post[transition])
        return dict(self._post_outcome[transition].get(outcome, {}))

    def outcomes(self, transition: str) -> list[str]:
        """The non-``ok`` outcomes ``transition`` has output arcs for, in :data:`OUTCOMES` order."""
        self.transition(transition)
        return [o for o in OUTCOMES if o in self._post_outcome[transition]]

    def route(self, transition: str, outcome: str | None) -> str | None:
        """The outcome whose output arcs produce when ``transition``'s action ends with
        ``outcome``, or ``None`` when the net routes that outcome nowhere.

        ``ok`` always has a route (its plain arcs, possibly none); a ``timeout`` with no
        ``timeout`` arcs takes the ``failed`` arcs; a ``failed`` or ``timeout`` outcome
        with neither has no route (a run stops on it); a ``cancelled`` outcome with no
        ``cancelled`` arcs produces nothing (``"cancelled"`` with an empty postset).

        Examples:
            >>> net = Net()
            >>> _ = net.add_place("a"); _ = net.add_place("retry"); _ = net.add_transition("t")
            >>> _ = net.add_arc("t", "retry", outcome="failed")
            >>> net.route("t", "timeout"), net.route("t", "ok"), net.route("t", "cancelled")
            ('failed', 'ok', 'cancelled')
        """
        routed = self._post_outcome[self.transition(transition).id]
        outcome = Outcome(outcome or Outcome.OK)
        if outcome is Outcome.OK or outcome is Outcome.CANCELLED or outcome.value in routed:
            return outcome.value
        if outcome is Outcome.TIMEOUT and Outcome.FAILED.value in routed:
            return Outcome.FAILED.value
        return None

    def firing_rules(self):
        """Per transition, in order: ``(id, transition, preset, outputs)`` where
        ``outputs`` is ``[(None, postset), (outcome, postset), ...]`` in
        :data:`OUTCOMES` order. The dicts are the net's own (no copies, for compilers
        that read every transition): do not modify them."""
        for id, transition in self.transitions.items():
            routed = self._post_outcome[id]
            outputs = [(None, self._post[id])]
            if routed:
                outputs += [(o, routed[o]) for o in OUTCOMES if o in routed]
            yield id, transition, self._pre[id], outputs

    def place_preset(self, place: str) -> dict[str, int]:
        """``{transition: weight}`` of the transitions that put tokens into ``place``
        (on any outcome; the largest weight when several outcomes do)."""
        self.place(place)
        found: dict[str, int] = {}
        for arc in self._arcs.values():
            if arc.target == place:
                found[arc.source] = max(found.get(arc.source, 0), arc.weight)
        return found

    def check_references(self) -> None:
        """Check ids that may name nodes added later (cancellation regions).

        Raises:
            NetStructureError: a cancellation region names an unknown node.
        """
        nodes = list(self.places) + list(self.transitions)
        for transition in self.transitions.values():
            for node in transition.cancels:
                if node not in self.places and node not in self.transitions:
                    raise NetStructureError(
                        f"{transition.id!r}: cancellation region names unknown node {node!r}"
                        f"{did_you_mean(node, nodes)}"
                    )

    def place_postset(self, place: str) -> dict[str, int]:
        """``{transition: weight}`` of the transitions that take tokens from ``place``."""
        self.place(place)
        return {t: pre[place] for t, pre in self._pre.items() if place in pre}

    def nodes_of(self, subnet: str) -> tuple[list[str], list[str]]:
        """``(place ids, transition ids)`` of one subnet."""
        places = [p.id for p in self.places.values() if p.subnet == subnet]
        transitions = [t.id for t in self.transitions.values() if t.subnet == subnet]
        return places, transitions

    def actions(self) -> dict[str, str]:
        """``{transition id: action name}`` for every bound transition."""
        return {t.id: t.action for t in self.transitions.values() if t.action}

    def __iter__(self) -> Iterator[str]:
        yield from self.places
        yield from self.transitions

    def __repr__(self) -> str:
        return (
            f"<Net {self.id!r}: {len(self.places)} places, {len(self.transitions)} transitions,"
            f" {len(self._arcs)} arcs>"
        )

    def structure(self) -> tuple:
        """A comparable summary of the net's semantics (nodes, arcs, markings, bindings).

        Two nets with equal ``structure()`` fire alike and bind the same actions; ids
        of arcs and graphics are left out.
        """
        return (
            tuple(sorted((p.id, p.label, p.subnet, p.channel) for p in self.places.values())),
            tuple(
                sorted(
                    (t.id, t.label, t.action, repr(sorted(t.params.items())), t.guard, t.subnet,
                     t.silent, t.priority, t.operator, t.timeout, t.cancels)
                    for t in self.transitions.values()
                )
            ),
            tuple(sorted((a.source, a.target, a.weight, a.outcome or "") for a in self._arcs.values())),
            tuple(sorted((s.id, s.label, s.agent, s.state or "") for s in self.subnets.values())),
            tuple(self.initial_marking.items()),
            None if self.final_marking is None else tuple(self.final_marking.items()),
            repr(self.run),
        )

    def copy(self) -> "Net":
        """An independent copy (elements are immutable, so they are shared)."""
        other = Net(self.id, self.label)
        other.places = dict(self.places)
        other.transitions = dict(self.transitions)
        other.subnets = dict(self.subnets)
        other._arcs = dict(self._arcs)
        other._pre = {t: dict(p) for t, p in self._pre.items()}
        other._post = {t: dict(p) for t, p in self._post.items()}
        other._post_outcome = {
            t: {o: dict(p) for o, p in by.items()} for t, by in self._post_outcome.items()
        }
        other.initial_marking = self.initial_marking
        other.final_marking = self.final_marking
        other.meta = dict(self.meta)
        other.run = self.run
        other.properties = list(self.properties)
        other.path = self.path
        other.lines = dict(self.lines)
        return other
