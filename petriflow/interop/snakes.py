"""Convert place/transition nets to and from SNAKES (:mod:`snakes.nets`).

SNAKES is a coloured Petri-net library; a P/T net is the special case in which every
token is SNAKES' black token ``dot``. The conversion maps:

* a place to a ``snakes.nets.Place`` of the same name, typed ``tBlackToken``, holding
  ``k`` copies of ``dot`` for ``k`` tokens of the initial marking (SNAKES keeps the
  current marking inside its places, so the initial marking becomes the net's marking);
* a transition to a ``snakes.nets.Transition`` of the same name with the guard ``True``;
* an arc of weight 1 to the annotation ``Value(dot)`` and an arc of weight ``k > 1`` to
  ``MultiArc([Value(dot)] * k)``, the form SNAKES' own PNML reader gives P/T arcs.

SNAKES nodes have a name and nothing else a petriflow net uses, so ids become names and
everything else (every field of a place or transition besides its id: labels, actions,
parameters, guard names, subnets, channels, priorities, timeouts, operators, ``meta``...;
the net's label, subnets and final marking; arc ids) rides along as a plain
``petriflow`` attribute on the SNAKES net and its nodes. So do output arcs reserved for
an action outcome (``Arc.outcome``): they are not part of P/T firing, so they are not
SNAKES arcs. :func:`from_snakes` reads the attribute back for the nodes still there,
which makes an in-process round trip lossless; SNAKES itself ignores it, and its
``copy()`` and PNML export drop it.

So the SNAKES net plays petriflow's token game exactly for plain P/T nets. A net with
outcome arcs or cancellation regions (``Transition.cancels``) is more than P/T: petriflow's
:class:`~petriflow.engine.CompiledNet` adds ``t@failed``-style outcome rows and reset
semantics, which the SNAKES net does not have.

One SNAKES behaviour to know when comparing semantics: in SNAKES 0.9.33,
``Transition.modes()`` returns ``[]`` for a transition without input arcs, although such
a transition is enabled in P/T semantics (and ``Transition.enabled(Substitution())``
says ``True``). Test such transitions with ``enabled(Substitution())``.

SNAKES is imported inside the functions, so ``import petriflow`` does not pay for it.

Examples:
    >>> from petriflow.net import Net
    >>> net = Net("pair")
    >>> _ = net.add_place("a", tokens=2); _ = net.add_place("b")
    >>> _ = net.add_transition("t", label="pack")
    >>> _ = net.add_arc("a", "t", weight=2); _ = net.add_arc("t", "b")
    >>> snet = to_snakes(net)
    >>> snet.transition("t").input()[0][1]
    MultiArc((Value(dot), Value(dot)))
    >>> t = snet.transition("t")
    >>> t.fire(t.modes()[0])
    >>> marking_from_snakes(snet.get_marking())
    Marking({'b': 1})
    >>> back = from_snakes(snet)
    >>> back.transitions["t"].label, back.initial_marking
    ('pack', Marking({'b': 1}))
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, Any, Mapping

from petriflow.errors import MarkingError, NetFormatError, NetStructureError
from petriflow.marking import Marking
from petriflow.net import Net

if TYPE_CHECKING:  # pragma: no cover - typing only
    import snakes.nets

__all__ = ["to_snakes", "from_snakes", "snakes_marking", "marking_from_snakes", "ATTRIBUTE"]

#: Name of the attribute that carries petriflow-only data on SNAKES nets and nodes.
ATTRIBUTE = "petriflow"


def _arc_label(weight: int) -> Any:
    from snakes.nets import MultiArc, Value, dot

    return Value(dot) if weight == 1 else MultiArc([Value(dot)] * weight)


def to_snakes(net: Net) -> "snakes.nets.PetriNet":
    """Build the SNAKES P/T net of ``net``, marked with its initial marking.

    Args:
        net: the net to convert (it is not changed).

    Returns:
        A new ``snakes.nets.PetriNet`` named after ``net.id``, with black-token places,
        ``Value(dot)`` / ``MultiArc`` arcs and the initial marking in its places.

    Examples:
        >>> from petriflow.classic import dining_philosophers
        >>> snet = to_snakes(dining_philosophers(3))
        >>> len(snet.place()), len(snet.transition())
        (9, 6)
        >>> sorted(t.name for t in snet.transition() if t.modes())
        ['take_0', 'take_1', 'take_2']
    """
    from snakes.nets import PetriNet, Place, Transition, dot, tBlackToken

    snet = PetriNet(net.id)
    marking = net.initial_marking
    for place in net.places.values():
        node = Place(place.id, [dot] * marking[place.id], tBlackToken)
        setattr(node, ATTRIBUTE, _fields(place))
        snet.add_place(node)
    for transition in net.transitions.values():
        node = Transition(transition.id)
        setattr(node, ATTRIBUTE, _fields(transition))
        snet.add_transition(node)
    arc_ids: dict[tuple[str, str], str] = {}
    outcome_arcs = []
    for arc in net.arcs:
        if getattr(arc, "outcome", None) is not None:
            outcome_arcs.append(arc)  # produces only when an action fails: not P/T firing
            continue
        label = _arc_label(arc.weight)
        if arc.source in net.places:
            snet.add_input(arc.source, arc.target, label)
        else:
            snet.add_output(arc.target, arc.source, label)
        if arc.id is not None:
            arc_ids[(arc.source, arc.target)] = arc.id
    setattr(snet, ATTRIBUTE, {
        "label": net.label,
        "meta": dict(net.meta),
        "subnets": list(net.subnets.values()),
        "final_marking": net.final_marking,
        "arc_ids": arc_ids,
        "outcome_arcs": outcome_arcs,
    })
    return snet


def _fields(node: Any) -> dict[str, Any]:
    """The dataclass fields of a petriflow place or transition, except its id."""
    return {f.name: getattr(node, f.name) for f in dataclasses.fields(node) if f.name != "id"}


def _black_count(tokens: Any, what: str, error: type[Exception]) -> int:
    """The number of tokens in a SNAKES multiset, all of which must be ``dot``."""
    from snakes.nets import BlackToken

    if not hasattr(tokens, "domain"):  # any iterable of tokens, not a SNAKES MultiSet
        from snakes.nets import MultiSet

        tokens = MultiSet(tokens)
    count = 0
    for token in tokens.domain():  # distinct values; tokens(value) is the multiplicity
        if not isinstance(token, BlackToken):
            message = f"{what} holds the token {token!r}; only black tokens (dot) convert"
            raise error(message)
        count += tokens(token)
    return count


def _arc_weight(label: Any, place: str, transition: str, direction: str) -> int:
    """The P/T weight of a SNAKES arc annotation, or :class:`NetFormatError`."""
    from snakes.nets import BlackToken, MultiArc, Tuple, Value, Variable

    if isinstance(label, Value) and isinstance(label.value, BlackToken):
        return 1
    if (
        isinstance(label, MultiArc)
        and not isinstance(label, Tuple)
        and all(isinstance(c, Value) and isinstance(c.value, BlackToken) for c in label)
    ):
        return len(label)
    arc = f"{place} -> {transition}" if direction == "input" else f"{transition} -> {place}"
    names = sorted(label.vars()) if hasattr(label, "vars") else []
    if isinstance(label, Variable) or names:
        detail = "carries variable " + ", ".join(repr(n) for n in names)
    else:
        detail = f"is annotated {label!r}"
    raise NetFormatError(
        f"{direction} arc {arc} {detail}; only P/T arcs (Value(dot) or a MultiArc of "
        "Value(dot)) convert",
        element=transition,
    )


def from_snakes(snakes_net: "snakes.nets.PetriNet", *, id: str | None = None) -> Net:
    """Read a SNAKES P/T net back as a :class:`~petriflow.net.Net`.

    The net's current marking (the tokens in its places) becomes the initial marking.
    Data left by :func:`to_snakes` in the ``petriflow`` attributes is restored for the
    nodes that are still there.

    Args:
        snakes_net: a ``snakes.nets.PetriNet`` whose tokens are all ``dot``.
        id: the new net's id (default: the SNAKES net's name).

    Returns:
        A new net; the SNAKES net is not changed.

    Raises:
        NetFormatError: the SNAKES net uses a coloured construct: a token other than
            ``dot``, a typed place that refuses ``dot``, an arc with a variable,
            expression, tuple, test, inhibitor or flush annotation, or a guard other
            than ``True``. The error names the place or transition.

    Examples:
        >>> from snakes.nets import PetriNet, Place, Transition, Value, Variable, dot
        >>> snet = PetriNet("tiny")
        >>> snet.add_place(Place("p", [dot])); snet.add_transition(Transition("t"))
        >>> snet.add_input("p", "t", Value(dot))
        >>> from_snakes(snet).preset("t")
        {'p': 1}
        >>> snet.add_place(Place("q", [1, 2])); snet.add_input("q", "t", Variable("x"))
        >>> from_snakes(snet)
        Traceback (most recent call last):
            ...
        petriflow.errors.NetFormatError: 'q': place holds the token 1; only black tokens (dot) convert
    """
    from snakes.nets import Expression, tAll, tBlackToken

    extra = getattr(snakes_net, ATTRIBUTE, None) or {}
    net = Net(str(snakes_net.name) if id is None else id, extra.get("label"))
    net.meta = dict(extra.get("meta") or {})
    for subnet in extra.get("subnets") or ():
        net.add_subnet(subnet.id, subnet.label, subnet.agent)

    def name_of(node: Any, kind: str) -> str:
        name = node.name
        if not isinstance(name, str) or not name:
            raise NetFormatError(f"{kind} name must be a non-empty string, got {name!r}",
                                 element=str(name))
        return name

    tokens: dict[str, int] = {}
    for node in snakes_net.place():
        name = name_of(node, "place")
        check = getattr(node, "_check", tAll)
        if check != tAll and check != tBlackToken:
            raise NetFormatError(
                f"place is typed {check!r}; only untyped or tBlackToken places convert",
                element=name,
            )
        try:
            tokens[name] = _black_count(node.tokens, "place", ValueError)
        except ValueError as exc:
            raise NetFormatError(str(exc), element=name) from None
        data = dict(getattr(node, ATTRIBUTE, None) or {})
        if data.get("subnet") not in net.subnets:
            data.pop("subnet", None)
        try:
            net.add_place(name, **data)
        except (TypeError, NetStructureError) as exc:
            raise NetFormatError(f"place: {exc}", element=name) from None
    true = Expression("True")
    for node in snakes_net.transition():
        name = name_of(node, "transition")
        if node.guard != true:
            raise NetFormatError(
                f"transition has the guard {str(node.guard)!r}; only P/T transitions "
                "(guard True) convert",
                element=name,
            )
        data = dict(getattr(node, ATTRIBUTE, None) or {})
        if data.get("subnet") not in net.subnets:
            data.pop("subnet", None)
        try:
            net.add_transition(name, **data)
        except (TypeError, NetStructureError) as exc:
            raise NetFormatError(f"transition: {exc}", element=name) from None
    arc_ids = extra.get("arc_ids") or {}
    for node in snakes_net.transition():
        for place, label in node.input():
            weight = _arc_weight(label, place.name, node.name, "input")
            net.add_arc(place.name, node.name, weight, arc_ids.get((place.name, node.name)))
        for place, label in node.output():
            weight = _arc_weight(label, place.name, node.name, "output")
            net.add_arc(node.name, place.name, weight, arc_ids.get((node.name, place.name)))
    for arc in extra.get("outcome_arcs") or ():
        if arc.source in net.transitions and arc.target in net.places:
            net.add_arc(arc.source, arc.target, arc.weight, arc.id, outcome=arc.outcome)
    net.set_initial_marking({p: k for p, k in tokens.items() if k})
    final = extra.get("final_marking")
    if final is not None and all(p in net.places for p in final):
        net.set_final_marking(final)
    return net


def snakes_marking(marking: Mapping[str, int]) -> "snakes.nets.Marking":
    """The SNAKES marking of a P/T marking: ``k`` tokens become ``k`` copies of ``dot``.

    Examples:
        >>> print(snakes_marking(Marking(p=2, q=1)))
        {p={dot, dot}, q}
    """
    from snakes.nets import Marking as SnakesMarking
    from snakes.nets import MultiSet, dot

    return SnakesMarking({p: MultiSet([dot] * k) for p, k in marking.items() if k})


def marking_from_snakes(marking: Mapping[str, Any]) -> Marking:
    """The P/T marking of a SNAKES marking (``{place: MultiSet of dot}``).

    Raises:
        MarkingError: a place holds a token other than ``dot``.

    Examples:
        >>> marking_from_snakes(snakes_marking({"p": 3}))
        Marking({'p': 3})
    """
    counts = {}
    for place, tokens in marking.items():
        counts[str(place)] = _black_count(tokens, f"place {place!r}", MarkingError)
    return Marking(counts)
