"""Which transitions may fire now, kept up to date by what changed.

A transition may fire when its input places hold enough tokens (the compiled net's
rule), its guard holds for the tokens it would take, its agent is running, and its
action is not already running (a transition runs one firing at a time).

:class:`EnabledSet` keeps the transitions that may fire in an
:class:`~petriflow.runtime.tokens.Agenda`. Whatever changes something a transition's
enabling reads marks it *dirty* (:meth:`EnabledSet.mark`): a fault the transitions of
its agent, a transition starting or ending its action itself. Tokens are marked by
place (:meth:`EnabledSet.mark_place`): a firing marks the places it took from or put
into, a delivery its channel place. At the next :meth:`~EnabledSet.refresh` a marked
place makes its consumers dirty only where their answer may have changed: a consumer
that reads only the place's count, when the count crossed its arc weight since the
last refresh (a place an instant firing takes a token from and gives one back, an
agent's control place, re-checks nobody); a guard over the tokens it would take, at
any change. A consumer whose state guard's kept answer is no sleeps: no change of its
places wakes it, only a change of its guard's keys (:meth:`EnabledSet.forget`). Only
dirty transitions are checked again, so a firing's cost does not
grow with the size of the net, nor with the number of transitions sharing a place
whose tokens did not change.

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> from petriflow.runtime.binding import bind
    >>> from petriflow.runtime.index import RunIndex
    >>> from petriflow.runtime.tokens import TokenStore
    >>> net = loads_net('''
    ... petriflow: 1
    ... places: [{id: a, tokens: 1}, b]
    ... transitions: [{id: go, in: [a], out: [b]}, {id: back, in: [b], out: [a]}]
    ... ''')
    >>> index = RunIndex(net, bind(net))
    >>> enabled = EnabledSet(index, TokenStore(index.compiled, net.initial_marking), set(), {})
    >>> [index.ids[t] for t in enabled.members()]
    ['go']
"""

from __future__ import annotations

from typing import Any, Callable, Collection, Container, Iterable, Mapping

from petriflow.errors import PetriflowError
from petriflow.runtime.index import RunIndex
from petriflow.runtime.tokens import Agenda, TokenStore

__all__ = ["EnabledSet", "GuardError"]


class GuardError(PetriflowError):
    """A guard raised instead of answering."""


def reason_of(exc: BaseException, hook: str | None = None) -> str:
    """An exception as a one-line reason (``hook() failed: ...`` when it came from a hook)."""
    text = str(exc) or type(exc).__name__
    text = text if isinstance(exc, PetriflowError) else f"{type(exc).__name__}: {text}"
    return f"{hook}() failed: {text}" if hook else text


class EnabledSet:
    """The transitions that may fire now (see the module).

    Args:
        index: the run's net index.
        tokens: the run's tokens.
        stopped: the agents not running now, kept up to date by its owner (every other
            agent runs; while it is empty no transition's agent is looked up).
        running: the transitions whose action is running (the action runner's firings,
            by transition index).
        states: ``{agent: state}``, what state guards read.
    """

    def __init__(self, index: RunIndex, tokens: TokenStore, stopped: Collection[str], running: Container[int],
                 states: Mapping[str, Any] | None = None) -> None:
        self.index = index
        self.tokens = tokens
        self.stopped = stopped
        self.running = running
        self.states: Mapping[str, Any] = {} if states is None else states
        self.agenda = Agenda(index.priority)
        self.dirty: set[int] = set()
        #: Places whose tokens changed since the last refresh.
        self.changed: set[int] = set()
        self._seen: list[int] = []  # per place, its count when its consumers were last checked
        self.resync()
        pre, reset = index.compiled.pre, index.compiled.reset
        weights: list[dict[int, int]] = [{} for _ in index.consumers]  # place -> {consumer: arc weight}
        for t, r in enumerate(index.row):
            for p, w in pre[r]:
                weights[p][t] = w
        token_guard = [index.guard[t] is not None and index.reads[t] is None for t in range(len(index.ids))]
        #: per place: its consumers that read its tokens' data (a guard over them), and
        #: the largest arc weight of the others (below it, a count change can matter);
        #: -1 for a place with one consumer, woken at every change (a firing does not
        #: mark a place only it consumes from: it checks itself again when it ends)
        self._reading = [tuple(t for t in ws if token_guard[t]) for ws in weights]
        self._need = [-1 if len(ws) == 1 else max((w for t, w in ws.items() if not token_guard[t]), default=0)
                      for ws in weights]
        #: per place, its consumers a change of its count may enable or disable: all of
        #: them but those whose state guard's kept answer is "no" (they wait for their
        #: guard's keys to change, :meth:`forget`, whatever the tokens do)
        self._awake = [set(c) for c in index.consumers]
        self._inputs = [tuple(p for p, _ in pre[r]) for r in index.row]
        #: per transition, the places a firing marks when it takes its tokens (its preset
        #: and cancellation region), less a place only it consumes from
        self.taking = [tuple(p for p in dict.fromkeys((*(p for p, _ in pre[r]), *reset[r])) if weights[p].keys() != {t})
                       for t, r in enumerate(index.row)]
        self.answer: list[bool | None] = [None] * len(index.ids)  # kept answers of state guards
        #: How many times a guard was called (what "cost by what changed" saves).
        self.evaluations = 0

    def forget(self, t: int) -> None:
        """The kept guard answer of ``t`` is out of date: ask again at the next check."""
        if self.answer[t] is False:  # its places wake it again
            awake = self._awake
            for p in self._inputs[t]:
                awake[p].add(t)
        self.answer[t] = None
        self.dirty.add(t)

    def mark(self, transitions: Iterable[int]) -> None:
        """Check these transitions again at the next :meth:`refresh`."""
        self.dirty.update(transitions)

    def mark_place(self, place: int) -> None:
        """The tokens of place index ``place`` changed: at the next refresh, check again
        the consumers whose answer that may change (see the module)."""
        self.changed.add(place)

    def resync(self) -> None:
        """Every place's tokens were replaced: check every transition again."""
        self._seen = list(self.tokens.counts)
        self.changed.clear()
        self.dirty.update(range(len(self.index.ids)))

    def _places(self) -> None:
        """Make dirty the consumers of the changed places whose answer may have changed."""
        dirty, counts, seen, need, reading = self.dirty, self.tokens.counts, self._seen, self._need, self._reading
        awake = self._awake
        for p in self.changed:
            now, before, n = counts[p], seen[p], need[p]
            seen[p] = now
            if n < 0 or (now != before and (now < n or before < n)):
                dirty.update(awake[p])
            elif reading[p]:
                dirty.update(reading[p])
        self.changed.clear()

    def can_fire(self, t: int) -> bool:
        """Whether transition index ``t`` may fire now (checked afresh).

        Raises:
            GuardError: its guard raised (naming the transition and the guard).
        """
        if t in self.running:
            return False
        index = self.index
        agent = index.agent[t]
        if agent is not None and agent in self.stopped:
            return False
        row = index.row[t]
        if not index.compiled.is_enabled(self.tokens.counts, row):
            return False
        guard = index.guard[t]
        if guard is None:
            return True
        try:
            if index.reads[t] is None:  # a guard over the tokens the firing would take
                self.evaluations += 1
                return bool(guard(self.tokens.offered(row), index.params[t]))
            answer = self.answer[t]
            if answer is None:  # a guard over its agent's state, asked again only when its keys changed
                self.evaluations += 1
                answer = self.answer[t] = bool(guard(self.states.get(agent), index.params[t]))
                if not answer:  # no token change can enable it until its keys change
                    for p in self._inputs[t]:
                        self._awake[p].discard(t)
            return answer
        except Exception as exc:
            raise GuardError(f"transition {index.ids[t]!r}: guard {index.guard_name[t]!r} raised"
                             f" {reason_of(exc)}") from exc

    def refresh(self) -> None:
        """Check the dirty transitions again (:meth:`can_fire`, with its common cases,
        a running transition, a state guard whose answer is kept, or one short of
        tokens, decided inline)."""
        if self.changed:
            self._places()
        dirty = self.dirty
        if dirty:
            can_fire, running, answer, on = self.can_fire, self.running, self.answer, self.agenda.on
            counts, row, pre, guard = self.tokens.counts, self.index.row, self.index.compiled.pre, self.index.guard
            agent, stopped = self.index.agent, self.stopped
            everyone = not stopped  # every agent runs: no transition's agent to look up
            up: list[int] = []
            down: list[int] = []
            for t in dirty:
                kept = answer[t]
                if kept is False or t in running:  # a state guard's kept "no", or running
                    ok = False
                else:
                    for p, w in pre[row[t]]:
                        if counts[p] < w:
                            ok = False
                            break
                    else:
                        if guard[t] is None or kept:  # no guard, or a state guard's kept "yes": the agent decides
                            ok = everyone or agent[t] not in stopped
                        else:
                            ok = can_fire(t)
                if ok != on[t]:
                    (up if ok else down).append(t)
            dirty.clear()
            if up or down:
                self.agenda.change(up, down)

    def pick(self, draw: Callable[[], float]) -> int | None:
        """The transition to fire next (see :meth:`Agenda.pick`), or ``None`` when none may."""
        if self.dirty or self.changed:
            self.refresh()
        if not self.agenda:
            return None
        return self.agenda.pick(draw)

    def members(self) -> list[int]:
        """The transitions that may fire now, in the net's order."""
        self.refresh()
        return self.agenda.members()
