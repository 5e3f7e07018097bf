"""The event core: a tick clock and a heap of typed events, in SimPy's mould.

Simulated time is an integer count of ticks of ``dt`` seconds, so equal inputs give
equal runs bit for bit. Everything that will happen later is a :class:`Scheduled`
event, ordered by ``(tick, phase, key)``:

* phase :data:`POLL`: a running firing asks to be polled (the firing itself is the
  event): at the time it asked for, at its transition's timeout (:class:`Deadline`),
  or at the next tick while it steps with the world or cleans up after a
  cancellation. Polls of one tick run in firing order (``key`` is the firing number).
* phase :data:`APPLY`: something from outside the net's firings: a message delivered
  by a channel, a fault, a link restored. They apply in the order they were
  scheduled.
* timed events (:meth:`Kernel.schedule_at`): a process of the run (a contended
  medium, see :mod:`petriflow.runtime.media`) that keeps time finer than a tick. An
  event at ``seconds`` runs at the first tick at or after it, *before* that tick's
  polls (it happened before the instant the actions see), ordered among the timed
  events of the tick by ``(seconds, rank, order)``; one scheduled for the current tick
  while the tick is processed runs in the same instant.

Components (channels, faults, the scheduler's firings) schedule events; an event
knows what to do when its time comes (:meth:`Scheduled.apply`); the kernel only
orders them. Nothing here is per agent or per transition: scheduling an event is an
append, and a tick costs one heap operation however many events share it.

Examples:
    >>> clock = Kernel(dt=0.5)
    >>> clock.ticks_at(1.2), clock.now
    (3, 0.0)
    >>> class Note(Scheduled):
    ...     phase = APPLY
    ...     def __init__(self, text): self.text = text
    ...     def apply(self, tick): print(self.text, clock.now)
    >>> clock.schedule(2, Note("second")); clock.schedule(1, Note("first"))
    >>> clock.peek()
    1
    >>> clock.tick = 1; clock.run_due()
    first 0.5
"""

from __future__ import annotations

import bisect
import heapq
import math

__all__ = ["Kernel", "Scheduled", "Deadline", "POLL", "APPLY", "TIMED"]

#: Phase of events that poll running firings (first at a tick, in firing order).
POLL = 0
#: Phase of events that change the marking or the agents from outside (after the polls).
APPLY = 1
#: Phase of events with an exact time of their own (before the polls of their tick).
TIMED = -1


class Scheduled:
    """Something that happens at a tick. Subclasses set :attr:`phase` and implement
    :meth:`apply`; :meth:`live` lets an event that no longer matters be skipped."""

    __slots__ = ()
    phase: int = APPLY

    def live(self, tick: int) -> bool:
        """Whether the event, scheduled at ``tick``, still matters (default: always)."""
        return True

    def apply(self, tick: int) -> None:
        """Do what the event stands for, at its ``tick``."""
        raise NotImplementedError


class Deadline(Scheduled):
    """A running firing's timeout: it is polled at that tick, whatever else it asked for.

    Attributes:
        firing: the firing's record (a :class:`Scheduled` with ``running``, ``number``
            and ``apply``).
        number: the firing's number (a record serves one firing after another).
    """

    __slots__ = ("firing", "number")
    phase = POLL

    def __init__(self, firing: Scheduled, number: int) -> None:
        self.firing = firing
        self.number = number

    def live(self, tick: int) -> bool:
        return self.firing.running and self.firing.number == self.number

    def apply(self, tick: int) -> None:
        self.firing.apply(tick)


class Kernel:
    """A tick clock and the :class:`Scheduled` events ahead, in buckets by tick.

    Ticks are integers, so the events of one tick share a bucket (a list of polls and
    a list of applies) and only the distinct ticks are kept in a heap: scheduling is
    an append (plus a heap push for a tick not yet seen), and a thousand agents
    waking at the same tick cost one heap entry. The polls of a tick are sorted by
    their key (the firing number) when the tick comes.

    Args:
        dt: seconds per tick.

    Attributes:
        tick: the current tick (the scheduler advances it).
        pending: the :data:`APPLY` events not yet applied (deliveries, faults): a run
            is not over while one is.
        phase: what :meth:`run_due` applies now: :data:`TIMED` events, :data:`POLL`
            events or :data:`APPLY` events; ``None`` between (the firings of an instant).
        polling: the key of the poll being applied (``None`` outside the polls).
    """

    def __init__(self, dt: float) -> None:
        if not (isinstance(dt, (int, float)) and math.isfinite(dt) and dt > 0):
            raise ValueError(f"dt must be a finite number of seconds > 0, got {dt!r}")
        self.dt = float(dt)
        self.tick = 0
        self.pending = 0
        self.phase: int | None = None
        self.polling: int | None = None
        self._ticks: list[int] = []
        self._buckets: dict[int, tuple[list[tuple[int, int, Scheduled]], list[Scheduled],
                                       list[tuple[float, int, int, Scheduled]]]] = {}
        self._order = 0

    @property
    def now(self) -> float:
        """Current simulated time in seconds."""
        return self.tick * self.dt

    def ticks_at(self, seconds: float) -> int:
        """The first tick at or after ``seconds`` (never before tick 0)."""
        return max(0, math.ceil(seconds / self.dt - 1e-9))

    def schedule(self, tick: int, event: Scheduled, key: int | None = None) -> None:
        """Schedule ``event`` at ``tick`` (not before the current tick).

        ``key`` orders the polls of one tick (default: scheduling order); applies keep
        the order they were scheduled in.
        """
        tick = max(tick, self.tick)
        if event.phase == POLL:
            self.schedule_poll(tick, event, self._order + 1 if key is None else key)
            return
        bucket = self._bucket(tick)
        self._order += 1
        self.pending += 1
        bucket[1].append(event)

    def schedule_poll(self, tick: int, event: Scheduled, key: int) -> None:
        """Schedule a :data:`POLL` ``event`` at ``tick`` (not before the current tick),
        ordered among the polls of that tick by ``key``: :meth:`schedule` for the
        commonest event of a run, without its checks. One scheduled for the current
        tick while its polls are applied, with a key after the poll being applied,
        takes its place among the polls still to come."""
        bucket = self._buckets.get(tick)
        if bucket is None:
            bucket = self._bucket(tick)
        self._order += 1
        polling = self.polling
        if polling is not None and tick == self.tick and key > polling:
            bisect.insort(bucket[0], (key, self._order, event))
        else:
            bucket[0].append((key, self._order, event))

    def poll_tick(self, key: int, polled: int) -> int:
        """The first tick at which a poll of ``key``, made at every tick (the last one at
        ``polled``), comes after now: this tick while its poll here is still to come
        (timed events are being applied, or polls of earlier keys), else the next.

        Examples:
            >>> kernel = Kernel(dt=1.0); kernel.tick = 5
            >>> kernel.poll_tick(3, polled=4), kernel.poll_tick(3, polled=5)
            (6, 6)
            >>> kernel.phase = TIMED; kernel.poll_tick(3, polled=4)
            5
        """
        tick = self.tick
        if polled < tick and (self.phase == TIMED or (self.polling is not None and self.polling < key)):
            return tick
        return tick + 1

    def _bucket(self, tick: int) -> tuple[list, list, list]:
        bucket = self._buckets.get(tick)
        if bucket is None:
            bucket = self._buckets[tick] = ([], [], [])
            heapq.heappush(self._ticks, tick)
        return bucket

    def schedule_at(self, seconds: float, event: Scheduled, rank: int = 0) -> None:
        """Schedule a timed ``event`` at the exact time ``seconds`` (see the module).

        It counts as pending until it runs; whoever makes it not live (cancels it)
        must count it off (``pending -= 1``), as
        :class:`~petriflow.runtime.media.ProcessClock` does. ``rank`` orders timed events
        of equal time (lower first).

        Raises:
            ValueError: ``seconds`` is not a finite time.
        """
        if not math.isfinite(seconds):
            raise ValueError(f"cannot schedule at {seconds!r}")
        bucket = self._bucket(max(self.ticks_at(seconds), self.tick))
        self._order += 1
        self.pending += 1
        heapq.heappush(bucket[2], (float(seconds), rank, self._order, event))

    def peek(self) -> int | None:
        """The tick of the next live event, or ``None`` when nothing is scheduled."""
        ticks, buckets = self._ticks, self._buckets
        while ticks:
            tick = ticks[0]
            polls, applies, timed = buckets[tick]
            while timed and not timed[0][3].live(tick):  # cancelled (its canceller counted it off)
                heapq.heappop(timed)
            if applies or timed:
                return tick
            while polls and not polls[-1][2].live(tick):
                polls.pop()
            if polls:
                return tick
            del buckets[tick]
            heapq.heappop(ticks)
        return None

    def due(self) -> bool:
        """Whether events are scheduled at the current tick (and not yet taken)."""
        bucket = self._buckets.get(self.tick)
        return bucket is not None and bool(bucket[0] or bucket[1] or bucket[2])

    def run_due(self) -> None:
        """Apply the live events due at the current tick, in order (timed events by
        time, polls by key, then applies). Timed events, polls and applies scheduled
        for the current tick while they run are applied too."""
        tick = self.tick
        bucket = self._buckets.get(tick)
        if bucket is None:
            return
        polls, applies, timed = bucket
        try:
            if timed:
                self.phase = TIMED
                while timed:
                    event = heapq.heappop(timed)[3]
                    if event.live(tick):  # a cancelled one was counted off by its canceller
                        self.pending -= 1
                        event.apply(tick)
            if polls:
                self.phase = POLL
                polls.sort()
                for key, _, event in polls:  # a poll inserted after this one is still reached
                    self.polling = key
                    if event.live(tick):
                        event.apply(tick)
                self.polling = None
                polls.clear()
            self.phase = APPLY
            index = 0
            while index < len(applies):
                event = applies[index]
                index += 1
                self.pending -= 1
                if event.live(tick):
                    event.apply(tick)
            applies.clear()
        finally:
            self.phase = self.polling = None

    def __len__(self) -> int:
        """Events scheduled (live or not)."""
        return sum(len(polls) + len(applies) + len(timed) for polls, applies, timed in self._buckets.values())
