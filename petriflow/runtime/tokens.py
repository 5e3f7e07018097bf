"""Tokens with data, and the set of transitions that may fire, kept up to date.

:class:`TokenStore` is a run's marking: per place, the data of its tokens in arrival
order, beside the count vector that :class:`~petriflow.engine.CompiledNet`'s firing
rule reads. Starting a firing and ending it apply the compiled net's rows (its
``pre`` and ``post`` arcs, what :meth:`~petriflow.engine.CompiledNet.consume` and
:meth:`~petriflow.engine.CompiledNet.produce` apply) to the counts and the data
together: the runtime and the token game share one firing rule.

:class:`Agenda` holds the transitions enabled right now, by priority, in net order,
and picks one: the highest priority wins and a tie is broken by one draw of the run's
generator. Adding, removing and picking cost a binary search over the enabled
transitions, so a firing's cost does not grow with the size of the net.

Examples:
    >>> agenda = Agenda([0, 0, 1, 0])
    >>> for t in (0, 1, 3): agenda.add(t)
    >>> agenda.pick(lambda: 0.99), len(agenda)
    (3, 3)
    >>> agenda.add(2); agenda.pick(lambda: 0.0)
    2
    >>> agenda.take(lambda: 0.99), agenda.pick(lambda: 0.99), len(agenda)
    (2, 3, 3)
    >>> agenda.change(up=[2], down=[0, 3]); agenda.members(), len(agenda)
    ([1, 2], 2)
"""

from __future__ import annotations

from bisect import bisect_left, insort
from collections import deque
from typing import Any, Callable, Iterable, Mapping, Sequence

from petriflow.engine import CompiledNet
from petriflow.marking import Marking

__all__ = ["TokenStore", "Agenda"]

_NOTHING: Mapping[str, int] = {}  # what a firing without a cancellation region withdraws (read only)



class Agenda:
    """The enabled transitions (by their index in the net's order), grouped by priority.

    Each priority level keeps its enabled transitions in a sorted array: adding and
    removing one is a binary search plus a block move inside the array (a C
    ``memmove`` of a few bytes per enabled transition: nothing next to a firing's
    other work, even with thousands enabled at once), picking is an index.

    Args:
        priorities: per transition index, its priority.

    Attributes:
        on: per transition index, whether it is in the agenda (read it, never write it).
        count: how many transitions are in it (``len``, without a call; read only).
    """

    def __init__(self, priorities: Sequence[int]) -> None:
        levels = sorted(set(priorities), reverse=True)
        self._levels: list[list[int]] = [[] for _ in levels]
        level_of = {p: i for i, p in enumerate(levels)}
        self._level = [self._levels[level_of[p]] for p in priorities]
        self.on = [False] * len(priorities)
        self.count = 0

    def __len__(self) -> int:
        return self.count

    def __contains__(self, t: int) -> bool:
        return self.on[t]

    def add(self, t: int) -> None:
        """Mark transition ``t`` enabled (no-op if it is)."""
        if not self.on[t]:
            self.change((t,), ())

    def discard(self, t: int) -> None:
        """Mark transition ``t`` not enabled (no-op if it is not)."""
        if self.on[t]:
            self.change((), (t,))

    def change(self, up: Iterable[int], down: Iterable[int]) -> None:
        """Mark the transitions ``up`` enabled and those ``down`` not (each must be off,
        respectively on, now): :meth:`add` and :meth:`discard` for many at once."""
        on, level_of, count = self.on, self._level, self.count
        for t in down:
            on[t] = False
            count -= 1
            level = level_of[t]
            if level[-1] == t:
                level.pop()
            else:
                del level[bisect_left(level, t)]
        for t in up:
            on[t] = True
            count += 1
            level = level_of[t]
            if not level or level[-1] < t:
                level.append(t)
            else:
                insort(level, t)
        self.count = count

    def _choice(self, draw: Callable[[], float]) -> tuple[list[int], int]:
        for level in self._levels:
            if level:
                return level, 0 if len(level) == 1 else int(draw() * len(level))
        raise LookupError("no transition is enabled")

    def pick(self, draw: Callable[[], float]) -> int:
        """The transition to fire: of the highest priority enabled, the only one, or
        the ``int(draw() * n)``-th of the ``n`` in net order (one draw, only on a tie)."""
        level, i = self._choice(draw)
        return level[i]

    def take(self, draw: Callable[[], float]) -> int:
        """:meth:`pick` and :meth:`discard` the transition picked (what a firing does)."""
        level, i = self._choice(draw)
        t = level.pop(i)
        self.on[t] = False
        self.count -= 1
        return t

    def members(self) -> list[int]:
        """The enabled transitions, in net order."""
        return [t for t, on in enumerate(self.on) if on]


class TokenStore:
    """A run's marking: per place, the data of its tokens (oldest first).

    Args:
        compiled: the net's compiled firing rule.
        initial: token counts to start with (tokens without data).
        final: the final marking, if the net has one (tracked in ``O(1)`` per change).

    A place whose tokens all carry no data (black tokens, most places of most nets)
    keeps only its count: its data is ``None`` until a token with data arrives, and
    becomes ``None`` again when the place empties. A run over plain control flow then
    allocates nothing per place and touches only the count vector.

    Attributes:
        counts: per place index, the token count (what the firing rule reads).
        data: per place index, a deque of the tokens' data, or ``None`` when every
            token there is black (its count says how many).
    """

    def __init__(self, compiled: CompiledNet, initial: Mapping[str, int],
                 final: Mapping[str, int] | None = None) -> None:
        self.compiled = compiled
        self.places = compiled.places
        self.index = compiled.place_index
        self.counts = [0] * len(self.places)
        self.data: list[deque | None] = [None] * len(self.places)
        self._final = None if final is None else compiled.vector(final)
        self.mismatch = 0
        self.replace({p: [None] * n for p, n in initial.items()})

    def replace(self, tokens: Mapping[str, Iterable[Any]]) -> None:
        """Set every place's tokens (places not named hold none)."""
        for i in range(len(self.places)):
            self.data[i] = None
            self.counts[i] = 0
        for place, items in tokens.items():
            i = self.index[place]
            items = list(items)
            self.data[i] = deque(items) if any(item is not None for item in items) else None
            self.counts[i] = len(items)
        final = self._final
        self.mismatch = 0 if final is None else sum(c != f for c, f in zip(self.counts, final))

    @property
    def at_final(self) -> bool:
        """Whether the token counts equal the final marking (``False`` without one)."""
        return self._final is not None and self.mismatch == 0

    def _track(self, i: int, before: int) -> None:
        final = self._final
        if final is not None:
            self.mismatch += (self.counts[i] != final[i]) - (before != final[i])

    def consume(self, row: int) -> tuple[dict[str, list[Any]], Mapping[str, int]]:
        """Start firing ``row`` (its preset enabled): take its input tokens and empty its
        cancellation region's places, by the compiled firing rule.

        Returns:
            ``({place: [data, ...]} taken, {place: count} withdrawn by the region)``.
        """
        taken, withdrawn = self.take(row)
        return (self.black(row) if taken is None else taken), withdrawn

    def black(self, row: int) -> dict[str, list[Any]]:
        """``{place: [None, ...]}``: the tokens firing ``row`` takes, all black."""
        places = self.places
        return {places[p]: [None] * w for p, w in self.compiled.pre[row]}

    def take(self, row: int) -> tuple[dict[str, list[Any]] | None, Mapping[str, int]]:
        """:meth:`consume`, with ``None`` for the tokens taken when none of them carries
        data (:meth:`black` makes them if they are needed): most firings of most nets
        then allocate nothing."""
        compiled, counts, data, final = self.compiled, self.counts, self.data, self._final
        if compiled.reset[row]:
            return self._consume_with_reset(row)
        pre = compiled.pre[row]
        taken = None
        for p, _ in pre:
            if data[p] is not None:
                taken = self._take_data(pre)
                break
        for p, w in pre:  # the compiled rule's consume
            count = counts[p]
            counts[p] = count - w
            if final is not None:
                wanted = final[p]
                self.mismatch += (count - w != wanted) - (count != wanted)
        return taken, _NOTHING

    def _take_data(self, pre: Sequence[tuple[int, int]]) -> dict[str, list[Any]]:
        """``{place: [data, ...]}`` of the tokens of ``pre``, taken from the places' queues
        (the counts are the caller's)."""
        data, places = self.data, self.places
        taken = {}
        for p, w in pre:
            queue = data[p]
            if queue is None:  # black tokens only
                taken[places[p]] = [None] * w
            else:
                taken[places[p]] = [queue.popleft()] if w == 1 else [queue.popleft() for _ in range(w)]
                if not queue:
                    data[p] = None
        return taken

    def _consume_with_reset(self, row: int) -> tuple[dict[str, list[Any]], dict[str, int]]:
        compiled, counts, data, places = self.compiled, self.counts, self.data, self.places
        touched = {p for p, _ in compiled.pre[row]} | set(compiled.reset[row])
        before = {p: counts[p] for p in touched}
        taken = {}
        for p, w in compiled.pre[row]:
            queue = data[p]
            taken[places[p]] = [None] * w if queue is None else [queue.popleft() for _ in range(w)]
            if queue is not None and not queue:
                data[p] = None
        withdrawn = {}
        for p in compiled.reset[row]:
            count = counts[p] - sum(w for q, w in compiled.pre[row] if q == p)
            if count:
                withdrawn[places[p]] = count
            data[p] = None
        compiled.consume(counts, row)
        for p, count in before.items():
            self._track(p, count)
        return taken, withdrawn

    def produce(self, row: int, result: Any, outputs: Mapping[str, Any] | None,
                skip: Sequence[bool]) -> dict[str, int]:
        """End firing ``row``: add its output tokens by the compiled firing rule, with
        ``result`` as their data (``outputs[place]`` for the places it names), except
        in the places where ``skip[index]`` holds (channel places: their tokens arrive
        later, through :meth:`add`).

        Returns:
            ``{place: count}`` produced here (:meth:`put` when nobody asks).
        """
        self.put(row, result, outputs, skip)
        return self.produced(row, skip)

    def produced(self, row: int, skip: Sequence[bool]) -> dict[str, int]:
        """``{place: count}`` firing ``row`` produces here (not where ``skip[index]``)."""
        places = self.places
        return {places[p]: w for p, w in self.compiled.post[row] if not skip[p]}

    def put(self, row: int, result: Any, outputs: Mapping[str, Any] | None, skip: Sequence[bool]) -> None:
        """:meth:`produce`, without counting what it produced."""
        counts, data, places, final = self.counts, self.data, self.places, self._final
        for p, w in self.compiled.post[row]:  # the compiled rule's produce, less what travels through channels
            if skip[p]:
                continue
            item = outputs.get(places[p], result) if outputs else result
            queue = data[p]
            count = counts[p]
            if queue is None:
                if item is not None:  # the first token with data: keep the black ones before it
                    data[p] = deque([None] * count + [item] * w)
            elif w == 1:
                queue.append(item)
            else:
                queue.extend([item] * w)
            counts[p] = count + w
            if final is not None:
                wanted = final[p]
                self.mismatch += (count + w != wanted) - (count != wanted)

    def add(self, i: int, item: Any) -> None:
        """One token with data ``item`` arrives in place index ``i`` (a delivery)."""
        before = self.counts[i]
        self.counts[i] += 1
        queue = self.data[i]
        if queue is not None:
            queue.append(item)
        elif item is not None:
            self.data[i] = deque([None] * before + [item])
        self._track(i, before)

    def remove(self, i: int, count: int) -> None:
        """Take ``count`` tokens (the oldest) out of place index ``i`` (it holds them)."""
        before = self.counts[i]
        self.counts[i] = before - count
        queue = self.data[i]
        if queue is not None:
            for _ in range(count):
                queue.popleft()
            if not queue:
                self.data[i] = None
        self._track(i, before)

    def offered(self, row: int) -> dict[str, list[Any]]:
        """``{place: [data, ...]}`` of the tokens firing ``row`` would take now."""
        data, places = self.data, self.places
        return {places[p]: [None] * w if data[p] is None else [data[p][k] for k in range(w)]
                for p, w in self.compiled.pre[row]}

    def read(self, place: str) -> list[Any]:
        """The data of the tokens in ``place`` (oldest first), not taken."""
        return self._items(self.index[place])

    def _items(self, i: int) -> list[Any]:
        queue = self.data[i]
        return [None] * self.counts[i] if queue is None else list(queue)

    def marking(self) -> Marking:
        """Token counts now."""
        return Marking({self.places[i]: c for i, c in enumerate(self.counts) if c})

    def tokens(self) -> dict[str, list[Any]]:
        """``{place: [data, ...]}`` of the marked places."""
        return {self.places[i]: self._items(i) for i, c in enumerate(self.counts) if c}
