"""The firing engine: enabled transitions, firing, sequences and the random token game.

Two paths share one semantics (a transition is enabled when every input place holds at
least the arc weight; firing subtracts the preset and adds the postset):

* :func:`enabled` and :func:`fire` work on :class:`~petriflow.marking.Marking` values
  and read like the definition, for users and tests;
* :class:`CompiledNet` turns a net into integer-indexed tuples (and numpy matrices for
  analysis) once, and :class:`Simulation` plays the token game on a mutable list of
  counts, re-checking after each firing only the transitions whose preset it touched.

Examples:
    >>> from petriflow.net import Net
    >>> net = Net()
    >>> _ = net.add_place("a", tokens=1); _ = net.add_place("b")
    >>> _ = net.add_transition("t"); _ = net.add_arc("a", "t"); _ = net.add_arc("t", "b")
    >>> enabled(net, net.initial_marking)
    ['t']
    >>> fire(net, net.initial_marking, "t")
    Marking({'b': 1})
    >>> sim = Simulation(net, seed=1)
    >>> sim.run(until=5)
    ['t']
    >>> sim.marking, sim.is_dead
    (Marking({'b': 1}), True)
"""

from __future__ import annotations

import functools
import random
from typing import Callable, Iterable, Mapping, Sequence

import numpy as np

from petriflow.errors import NotEnabledError, PetriflowError
from petriflow.marking import Marking
from petriflow.net import Net

__all__ = [
    "Deadlock",
    "enabled",
    "is_enabled",
    "consume",
    "produce",
    "fire",
    "fire_sequence",
    "CompiledNet",
    "Simulation",
    "variant_id",
]


class Deadlock(PetriflowError):
    """No transition is enabled (raised by :meth:`Simulation.step`)."""


def is_enabled(net: Net, marking: Mapping[str, int], transition: str) -> bool:
    """Whether ``transition`` may fire in ``marking``."""
    return all(marking.get(p, 0) >= w for p, w in net.preset(transition).items())


def enabled(net: Net, marking: Mapping[str, int]) -> list[str]:
    """Ids of the transitions enabled in ``marking``, in the net's order."""
    return [t for t in net.transitions if is_enabled(net, marking, t)]


def consume(net: Net, marking: Mapping[str, int], transition: str) -> Marking:
    """The marking once ``transition`` has started: its preset consumed and its
    cancellation region's places emptied. Its outputs come later, with
    :func:`produce`, when its action ends (at once for a plain P/T firing).

    Raises:
        UnknownElementError: no such transition (with a did-you-mean hint).
        NotEnabledError: the transition is not enabled; names each short place.
    """
    pre = net.preset(transition)
    missing = {p: (marking.get(p, 0), w) for p, w in pre.items() if marking.get(p, 0) < w}
    if missing:
        raise NotEnabledError(transition, missing)
    counts = dict(marking)
    for place, weight in pre.items():
        counts[place] -= weight
    for node in net.transitions[transition].cancels:
        if node in net.places:
            counts[node] = 0
    return Marking(counts)


def produce(net: Net, marking: Mapping[str, int], transition: str, outcome: str | None = None) -> Marking:
    """The marking once ``transition``'s action has ended with ``outcome`` (default
    ``ok``): the output arcs of the outcome's route (:meth:`Net.route`) produce.

    Raises:
        UnknownElementError: no such transition.
        PetriflowError: the net routes ``outcome`` nowhere (a failure with no
            ``failed`` arcs): no marking follows.
    """
    route = net.route(transition, outcome)
    if route is None:
        raise PetriflowError(f"transition {transition!r} routes no {outcome!r} outcome")
    counts = dict(marking)
    for place, weight in net.postset(transition, route).items():
        counts[place] = counts.get(place, 0) + weight
    return Marking(counts)


def fire(net: Net, marking: Mapping[str, int], transition: str, outcome: str | None = None) -> Marking:
    """The marking reached by firing ``transition`` in ``marking``.

    One firing is :func:`consume` then :func:`produce`: the preset is consumed, the
    places of the transition's cancellation region are emptied, then the outputs for
    ``outcome`` (default ``ok``) are produced. The runtime does the same two steps
    with simulated time between them.

    Raises:
        UnknownElementError: no such transition (with a did-you-mean hint).
        NotEnabledError: the transition is not enabled; names each short place.
    """
    return produce(net, consume(net, marking, transition), transition, outcome)


def fire_sequence(net: Net, marking: Mapping[str, int], transitions: Iterable[str]) -> Marking:
    """Fire ``transitions`` one after the other; raises at the first one not enabled."""
    current = net.check_marking(marking)
    for transition in transitions:
        current = fire(net, current, transition)
    return current


def variant_id(transition: str, outcome: str | None) -> str:
    """Id of the outcome variant of a transition: ``t`` for ok, ``t@failed`` otherwise.

    Examples:
        >>> variant_id("walk", "timeout"), variant_id("walk", None)
        ('walk@timeout', 'walk')
    """
    return transition if outcome in (None, "ok") else f"{transition}@{outcome}"


class CompiledNet:
    """A net turned into integer-indexed arrays, built once and then only read.

    A transition whose action outcomes are routed (output arcs reserved for
    ``failed``, ``timeout`` or ``cancelled``) becomes one row per outcome: ``t`` for
    ok and ``t@failed`` etc., each consuming the same preset and producing its own
    outputs, so the token game and analysis explore failure routes too. A
    cancellation region empties its places after the preset is consumed and before
    the outputs are produced (reset arcs).

    Attributes:
        places: place ids; index ``i`` of a count vector is ``places[i]``.
        transitions: row ids (transition ids and outcome variants), indexed likewise.
        origin: per row, ``(transition id, outcome or None)``.
        pre: per row, a tuple of ``(place index, weight)`` it consumes.
        post: per row, a tuple of ``(place index, weight)`` it produces.
        reset: per row, the place indices its cancellation region empties.
        has_resets: whether any row empties places (not a plain P/T net then).
        affected: per row ``t``, the rows whose enabledness can change when ``t``
            fires (those consuming from a place whose count ``t`` may change).
        pre_matrix, post_matrix, incidence: ``|rows| x |P|`` int64 numpy matrices
            (resets are not in them).
    """

    def __init__(self, net: Net) -> None:
        self.net = net
        self.places: list[str] = list(net.places)
        self.place_index = {p: i for i, p in enumerate(self.places)}
        index = self.place_index
        self.transitions: list[str] = []
        self.origin: list[tuple[str, str | None]] = []
        self.pre: list[tuple[tuple[int, int], ...]] = []
        self.post: list[tuple[tuple[int, int], ...]] = []
        self.reset: list[tuple[int, ...]] = []
        # Bound methods: this loop runs once per transition of every net analysed.
        add_id, add_origin = self.transitions.append, self.origin.append
        add_pre, add_post, add_reset = self.pre.append, self.post.append, self.reset.append
        for t, transition, preset, outputs in net.firing_rules():
            pre = tuple([(index[p], w) for p, w in preset.items()])
            cancels = transition.cancels
            reset = tuple([index[n] for n in cancels if n in index]) if cancels else ()
            for outcome, postset in outputs:
                add_id(t if outcome is None else variant_id(t, outcome))
                add_origin((t, outcome))
                add_pre(pre)
                add_post(tuple([(index[p], w) for p, w in postset.items()]))
                add_reset(reset)
        self.has_resets = any(self.reset)
        self.transition_index = {t: i for i, t in enumerate(self.transitions)}

    def row(self, transition: str, outcome: str | None = None) -> int | None:
        """The row whose outputs produce when ``transition``'s action ends with
        ``outcome`` (the net's :meth:`~petriflow.net.Net.route`), or ``None`` when the
        net routes that outcome nowhere. A ``cancelled`` outcome with no ``cancelled``
        arcs has no row either: it produces nothing."""
        route = self.net.route(transition, outcome)
        if route is None:
            return None
        return self.transition_index.get(variant_id(transition, route))

    def consume(self, vector: list[int], t: int) -> None:
        """Start row ``t`` in ``vector`` (in place): consume its preset, empty its
        cancellation region. The caller has checked :meth:`is_enabled`."""
        for p, w in self.pre[t]:
            vector[p] -= w
        for p in self.reset[t]:
            vector[p] = 0

    def produce(self, vector: list[int], t: int) -> None:
        """End row ``t`` in ``vector`` (in place): add its outputs."""
        for p, w in self.post[t]:
            vector[p] += w

    # The matrices are built on first use: the token game and the bitmask exploration
    # of small nets read only the tuples above.
    @functools.cached_property
    def pre_matrix(self) -> np.ndarray:
        """``|rows| x |P|`` int64 matrix of the weights each row consumes."""
        return _matrix((len(self.transitions), len(self.places)), self.pre)

    @functools.cached_property
    def post_matrix(self) -> np.ndarray:
        """``|rows| x |P|`` int64 matrix of the weights each row produces."""
        return _matrix((len(self.transitions), len(self.places)), self.post)

    @functools.cached_property
    def incidence(self) -> np.ndarray:
        """``post_matrix - pre_matrix`` (resets are not in it)."""
        return self.post_matrix - self.pre_matrix

    @functools.cached_property
    def consumers(self) -> list[tuple[int, ...]]:
        """Per place, the rows that consume from it."""
        consumers: list[list[int]] = [[] for _ in self.places]
        for t, pre in enumerate(self.pre):
            for p, _ in pre:
                consumers[p].append(t)
        return [tuple(c) for c in consumers]

    @functools.cached_property
    def affected(self) -> list[tuple[int, ...]]:
        """Per row ``t``, the rows whose enabledness can change when ``t`` fires."""
        affected = []
        for t in range(len(self.transitions)):
            change: dict[int, int] = {p: 1 for p in self.reset[t]}
            for p, w in self.pre[t]:
                change[p] = change.get(p, 0) - w
            for p, w in self.post[t]:
                change[p] = change.get(p, 0) + w
            touched = sorted({u for p, d in change.items() if d for u in self.consumers[p]})
            affected.append(tuple(touched))
        return affected

    def vector(self, marking: Mapping[str, int]) -> list[int]:
        """The marking as a list of counts in place-index order."""
        vec = [0] * len(self.places)
        for place, count in marking.items():
            vec[self.place_index[place]] = count
        return vec

    def marking(self, vector: Sequence[int]) -> Marking:
        """The :class:`Marking` of a count vector."""
        return Marking({self.places[i]: int(c) for i, c in enumerate(vector) if c})

    def is_enabled(self, vector: Sequence[int], t: int) -> bool:
        """Whether transition index ``t`` is enabled in ``vector``."""
        for p, w in self.pre[t]:
            if vector[p] < w:
                return False
        return True

    def enabled(self, vector: Sequence[int]) -> list[int]:
        """Indices of the transitions enabled in ``vector``."""
        return [t for t in range(len(self.transitions)) if self.is_enabled(vector, t)]


def _matrix(shape: tuple[int, int], arcs: list[tuple[tuple[int, int], ...]]) -> np.ndarray:
    """The ``rows x places`` int64 matrix of per-row ``(place, weight)`` arcs."""
    matrix = np.zeros(shape, dtype=np.int64)
    width = shape[1]
    flat, weights = [], []
    for t, row in enumerate(arcs):
        for p, w in row:
            flat.append(t * width + p)
            weights.append(w)
    if flat:
        matrix.put(flat, weights)
    return matrix


FireHandler = Callable[[str, Marking], None]


class Simulation:
    """The random token game, SimPy style: :meth:`step`, :meth:`run`, :meth:`peek`.

    Conflicts are resolved uniformly at random with a seeded generator, so the same
    net, marking and seed give the same firing sequence.

    Args:
        net: the net to play.
        marking: the start marking (default: the net's initial marking).
        seed: seed of the random choice between enabled transitions.
        compiled: a :class:`CompiledNet` of ``net`` to reuse.
    """

    def __init__(
        self,
        net: Net,
        marking: Mapping[str, int] | None = None,
        *,
        seed: int | None = None,
        compiled: CompiledNet | None = None,
    ) -> None:
        self.compiled = compiled or CompiledNet(net)
        self.net = net
        start = net.initial_marking if marking is None else net.check_marking(marking)
        self._counts = self.compiled.vector(start)
        self._rng = random.Random(seed)
        self._handlers: list[FireHandler] = []
        self.fired = 0
        n = len(self.compiled.transitions)
        self._is_on = [False] * n
        self._on: list[int] = []
        self._slot = [0] * n
        for t in range(n):
            if self.compiled.is_enabled(self._counts, t):
                self._switch_on(t)

    def _switch_on(self, t: int) -> None:
        self._is_on[t] = True
        self._slot[t] = len(self._on)
        self._on.append(t)

    def _switch_off(self, t: int) -> None:
        self._is_on[t] = False
        slot, last = self._slot[t], self._on.pop()
        if last != t:
            self._on[slot] = last
            self._slot[last] = slot

    def on_fire(self, handler: FireHandler) -> None:
        """Call ``handler(transition id, marking after)`` after every firing."""
        self._handlers.append(handler)

    @property
    def marking(self) -> Marking:
        """The current marking."""
        return self.compiled.marking(self._counts)

    @property
    def is_dead(self) -> bool:
        """Whether no transition is enabled."""
        return not self._on

    def peek(self) -> list[str]:
        """Ids of the enabled transitions, in the net's order."""
        names = self.compiled.transitions
        return [names[t] for t in sorted(self._on)]

    def _fire_index(self, t: int) -> None:
        compiled, counts = self.compiled, self._counts
        compiled.consume(counts, t)
        compiled.produce(counts, t)
        pre, is_on = compiled.pre, self._is_on
        for u in compiled.affected[t]:
            ok = True
            for p, w in pre[u]:
                if counts[p] < w:
                    ok = False
                    break
            if ok != is_on[u]:
                if ok:
                    self._switch_on(u)
                else:
                    self._switch_off(u)
        self.fired += 1
        if self._handlers:
            name, marking = compiled.transitions[t], self.marking
            for handler in self._handlers:
                handler(name, marking)

    def fire(self, transition: str) -> None:
        """Fire a named transition or outcome variant (``t@failed``); raises
        :class:`NotEnabledError` if it is not enabled."""
        if transition not in self.compiled.transition_index:
            self.net.transition(transition)  # raises with a did-you-mean hint
        t = self.compiled.transition_index[transition]
        transition = self.compiled.origin[t][0]
        if not self._is_on[t]:
            fire(self.net, self.marking, transition)  # raises with the short places named
        self._fire_index(t)

    def step(self) -> str:
        """Fire one enabled transition chosen at random and return its id.

        Raises:
            Deadlock: no transition is enabled.
        """
        if not self._on:
            raise Deadlock(f"no transition is enabled in {self.marking!r}")
        t = self._on[int(self._rng.random() * len(self._on))]
        self._fire_index(t)
        return self.compiled.transitions[t]

    def run(self, until: int | Callable[[Marking], bool]) -> list[str]:
        """Fire until ``until`` firings were made (an int) or ``until(marking)`` holds,
        or until no transition is enabled. Returns the ids fired, in order."""
        fired: list[str] = []
        if callable(until):
            while self._on and not until(self.marking):
                fired.append(self.step())
            return fired
        names, on, rng = self.compiled.transitions, self._on, self._rng
        for _ in range(int(until)):
            if not on:
                break
            t = on[int(rng.random() * len(on))]
            self._fire_index(t)
            fired.append(names[t])
        return fired
