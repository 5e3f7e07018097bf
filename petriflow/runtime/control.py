"""Steering a run while it goes: the control queue the scheduler reads between firings.

A person (the live page, ``petriflow ctl``) or a script asks for an
:class:`Intervention` (pause, resume, step, a breakpoint, tokens put in or taken out,
a running firing's outcome forced, the real-time factor); :meth:`Control.submit` puts
it on a queue, from any thread. The run applies what is queued only at its
**checkpoints**: before each firing (:meth:`Control.admit`, in the firing loop every
firing goes through) and between instants (:meth:`Control.between`). Nothing reaches
around the kernel: an intervention changes the run the way a firing does, through its
token store and enabled set, and each applied one is a ``control`` event in the trace
and journal, saying who asked, what, and when (simulated time, the wall-clock time it
was asked, the checkpoint's number).

While paused the run waits at a checkpoint: in simulation the clock stops (nothing
moves until the run goes on); with remote agents (actions whose work goes on outside
the process) pausing stops the dispatching of new firings, since every firing passes
:meth:`Control.admit` first, while the actions already running go on: the run's time
goes on with them (its :attr:`Control.idle`, the scheduler's ``pass_paused``), their
ends (and an agent lost, its firings ``failed``) are recorded when they happen, during
the pause, and what they enable fires when the run goes on.

**Breakpoints** (:class:`Breakpoint`, :func:`parse_breakpoint`) pause the run:

* ``transition NAME``: NAME is about to fire (paused before it fires);
* ``place NAME >= N`` (or ``>``, ``==``, ``<=``, ``<``): the place's count reaches N;
  it pauses when the condition becomes true, and again only after it was false;
* ``lost``: a message is lost in a channel;
* ``failed``: an action ends ``failed`` or ``timeout``.

A breakpoint that triggers is a ``control`` event (``action: hit``) and pauses the run
before any later firing. Without anyone to resume it (no live page) a hit is recorded
and the run goes on.

**Replay.** A run's interventions are the only thing in it that the net, world, seed
and configuration do not determine; so a resumed run (``--resume``) gives the journal's
``control`` events back to a :class:`Control` as its ``script``: each is applied again
at its checkpoint, in its place among the events, with its data as recorded, and the
re-executed run makes the same events (the journal checks it). A trace replays the
token changes from the events' ``added`` and ``removed`` counts
(:func:`petriflow.runtime.replay.markings`).

Examples:
    >>> parse_breakpoint("place done >= 2")
    Breakpoint(kind='place', name='done', compare='>=', count=2)
    >>> parse_breakpoint("transition grab").text
    'transition grab'
    >>> parse_breakpoint("failed")
    Breakpoint(kind='failed', name=None, compare=None, count=None)
"""

from __future__ import annotations

import re
import threading
import time as wallclock
from collections import deque
from dataclasses import dataclass, field
from typing import Any, Iterable, Protocol

from petriflow.errors import PetriflowError
from petriflow.outcome import Name, Outcome
from petriflow.runtime.trace import Event, EventKind

__all__ = ["Command", "Intervention", "Breakpoint", "parse_breakpoint", "Control", "Steerable", "ControlError",
           "Reply", "BREAKPOINT_SYNTAX", "PAUSED_STEP"]

_CONTROL = EventKind.CONTROL.value

#: Seconds a paused run whose time goes on (remote agents) lets pass at a time: its
#: :attr:`Control.idle` advances the run that far; a paced clock waits for the wall
#: clock as it goes, and for an unpaced one the control waits out what is left of the
#: step (cut short by an intervention), so a pause neither spins the CPU nor races
#: ahead of the agents.
PAUSED_STEP = 0.05

#: The breakpoint language, as the errors and the docs say it.
BREAKPOINT_SYNTAX = "transition NAME | place NAME >= N (or >, ==, <=, <) | lost | failed"


class ControlError(PetriflowError):
    """An intervention that cannot be applied (unknown name, too few tokens, no such firing)."""


class Command(Name):
    """What an :class:`Intervention` asks for."""

    PAUSE = "pause"
    """Stop at the next checkpoint and wait."""
    RESUME = "resume"
    """Go on (also ends a step)."""
    STEP = "step"
    """While paused: let ``count`` firings happen, then pause again."""
    BREAK = "break"
    """Add the breakpoint ``spec``."""
    CLEAR = "clear"
    """Remove the breakpoint ``spec`` (all of them without one)."""
    INJECT = "inject"
    """Put ``count`` black tokens into ``place``."""
    REMOVE = "remove"
    """Take ``count`` tokens (the oldest) out of ``place``."""
    FORCE = "force"
    """End the running ``firing`` (its number, or its transition's name) with ``outcome``."""
    SPEED = "speed"
    """Pace the run at ``factor`` times real time (0: as fast as it goes)."""
    HIT = "hit"
    """(Recorded, never asked for) a breakpoint triggered."""


_COMPARE = {">=": lambda a, b: a >= b, ">": lambda a, b: a > b, "==": lambda a, b: a == b,
            "<=": lambda a, b: a <= b, "<": lambda a, b: a < b}


@dataclass(frozen=True)
class Breakpoint:
    """One breakpoint (see the module for the language).

    Attributes:
        kind: ``transition``, ``place``, ``lost`` or ``failed``.
        name: the transition or place it watches.
        compare: for a place, the comparison (``>=`` ...).
        count: for a place, the count compared with.
    """

    kind: str
    name: str | None = None
    compare: str | None = None
    count: int | None = None

    @property
    def text(self) -> str:
        """The breakpoint written in its language (what :func:`parse_breakpoint` reads)."""
        if self.kind == "transition":
            return f"transition {self.name}"
        if self.kind == "place":
            return f"place {self.name} {self.compare} {self.count}"
        return self.kind


_PLACE = re.compile(r"^place\s+(\S+)\s*(>=|<=|==|>|<)\s*(\d+)$")


def parse_breakpoint(text: Any) -> Breakpoint:
    """A :class:`Breakpoint` from its text.

    Raises:
        ControlError: the text is not a breakpoint (the error gives the syntax).

    Examples:
        >>> parse_breakpoint("place  q>3").text
        'place q > 3'
        >>> parse_breakpoint("when done")
        Traceback (most recent call last):
        ...
        petriflow.runtime.control.ControlError: not a breakpoint: 'when done' (transition NAME | place NAME >= N (or >, ==, <=, <) | lost | failed)
    """
    spec = " ".join(str(text).split()) if isinstance(text, str) else None
    if spec in ("lost", "failed"):
        return Breakpoint(spec)
    if spec is not None:
        words = spec.split(" ")
        if len(words) == 2 and words[0] == "transition":
            return Breakpoint("transition", words[1])
        match = _PLACE.match(spec)
        if match and len(match.group(3)) <= 9:
            return Breakpoint("place", match.group(1), match.group(2), int(match.group(3)))
    raise ControlError(f"not a breakpoint: {text!r} ({BREAKPOINT_SYNTAX})")


class Steerable(Protocol):
    """What a :class:`Control` changes in its run (the scheduler provides it)."""

    def inject(self, place: str, count: int) -> dict[str, int]:
        """Put ``count`` black tokens into ``place``; returns ``{place: count}``."""

    def remove(self, place: str, count: int) -> dict[str, int]:
        """Take ``count`` tokens out of ``place``; returns ``{place: count}``."""

    def find_firing(self, firing: str) -> tuple[str, int]:
        """``(transition, firing number)`` of a running firing (its number, or its
        transition's id)."""

    def force(self, firing: str, outcome: Outcome, reason: str) -> tuple[str, int]:
        """End a running firing with ``outcome``; returns ``(transition, firing number)``."""

    def set_speed(self, factor: float) -> None:
        """Pace the run at ``factor`` times real time (0: unpaced)."""

    def count(self, place: str) -> int:
        """Tokens in ``place`` now."""

    def can_fire(self, t: int) -> bool:
        """Whether transition index ``t`` may still fire now."""

    def recorder_count(self) -> int:
        """The number the next event will have."""

    def rebase_clock(self) -> None:
        """The run stood still (paused): pace it from now on as from this moment."""

    def transition_of(self, t: int) -> str:
        """Transition index ``t``'s id."""

    def emit(self, kind: str, transition: str | None = None, agent: str | None = None, **data: Any) -> None:
        """Record an event."""

    def on_event(self, handler: Any, kinds: Iterable[str] | None = None) -> None:
        """Watch the run's events."""

    @property
    def now(self) -> float:
        """Simulated time."""

    @property
    def paced(self) -> bool:
        """Whether the run's clock waits for the wall clock itself (real-time pacing)."""


@dataclass
class Reply:
    """What became of an intervention: set once, by the run's thread."""

    done: threading.Event = field(default_factory=threading.Event)
    ok: bool = False
    message: str = ""

    def set(self, ok: bool, message: str) -> None:
        self.ok, self.message = ok, message
        self.done.set()


@dataclass
class Intervention:
    """One thing asked of a run.

    Attributes:
        command: what is asked.
        args: its arguments (``count``, ``place``, ``spec``, ``firing``, ``outcome``, ``factor``).
        by: who asked (a name the asker gives: ``page``, a user name).
        wall: when it was asked, wall-clock UTC, ISO 8601.
        reply: set when the run applied it or refused it.
    """

    command: Command
    args: dict[str, Any] = field(default_factory=dict)
    by: str = "python"
    wall: str = ""
    reply: Reply = field(default_factory=Reply)

    @classmethod
    def of(cls, command: str, args: dict[str, Any] | None = None, by: str = "python") -> "Intervention":
        """An intervention asked now, its arguments checked for type (names are checked
        by the run).

        Raises:
            ControlError: an unknown command or a malformed argument.
        """
        try:
            kind = Command(command)
        except ValueError:
            names = ", ".join(c.value for c in Command if c is not Command.HIT)
            raise ControlError(f"unknown command {command!r} (one of {names})") from None
        if kind is Command.HIT:
            raise ControlError("'hit' is recorded by the run, never asked for")
        args = dict(args or {})
        checked: dict[str, Any] = {}
        if kind in (Command.STEP, Command.INJECT, Command.REMOVE):
            count = args.get("count", 1)
            if isinstance(count, str) and count.isdigit():
                count = int(count)
            if type(count) is not int or not 1 <= count <= 1_000_000:
                raise ControlError(f"{kind.value}: the count must be a whole number from 1 to 1000000, got {count!r}")
            checked["count"] = count
        if kind in (Command.INJECT, Command.REMOVE):
            checked["place"] = _name(args.get("place"), "place")
        if kind is Command.BREAK:
            checked["spec"] = parse_breakpoint(args.get("spec")).text
        if kind is Command.CLEAR and args.get("spec") is not None:
            checked["spec"] = parse_breakpoint(args.get("spec")).text
        if kind is Command.FORCE:
            checked["firing"] = _name(args.get("firing"), "firing")
            outcome = "cancelled" if args.get("outcome") == "cancel" else args.get("outcome")
            if outcome not in ("ok", "failed", "cancelled"):
                raise ControlError(f"force: the outcome is ok, failed or cancel, got {args.get('outcome')!r}")
            checked["outcome"] = outcome
        if kind is Command.SPEED:
            factor = args.get("factor")
            try:
                factor = float(factor)
            except (TypeError, ValueError):
                factor = -1.0
            if not 0 <= factor <= 1000:
                raise ControlError(f"speed: the factor is a number from 0 (as fast as it goes) to 1000, got"
                                   f" {args.get('factor')!r}")
            checked["factor"] = factor
        who = by if isinstance(by, str) and 0 < len(by) <= 64 and by.isprintable() else "unknown"
        stamp = wallclock.strftime("%Y-%m-%dT%H:%M:%SZ", wallclock.gmtime())
        return cls(kind, checked, who, stamp)


def _name(value: Any, what: str) -> str:
    if isinstance(value, int) and not isinstance(value, bool) and what == "firing":
        return str(value)
    if not isinstance(value, str) or not value or len(value) > 200 or not value.isprintable():
        raise ControlError(f"a {what} name is needed, got {value!r}")
    return value


class Control:
    """A run's control queue and breakpoints (see the module).

    Args:
        breakpoints: breakpoints declared before the run (its configuration's).
        paused: start paused (wait for someone to go on before the first firing).
        interactive: someone can resume a paused run (a live page is served); without
            one, a paused run does not wait.
        script: a resumed run's journaled ``control`` events, applied again.
    """

    def __init__(self, *, breakpoints: Iterable[str] = (), paused: bool = False, interactive: bool = False,
                 script: Iterable[Event] = ()) -> None:
        self.paused = paused
        self.interactive = interactive
        self.steps = 0  # firings still allowed while paused (a step)
        self.point = 0  # checkpoints passed at this instant (where an intervention applies)
        self._at = 0.0  # the instant they are counted at
        self.closed = False
        self._queue: deque[Intervention] = deque()
        self._wakeup = threading.Condition()
        self._script = deque(e for e in script if e.kind == _CONTROL and e.data.get("action") != "hit")
        self._run: Steerable | None = None
        self._signals: list[dict[str, Any]] = []  # lost messages and failures seen since the last checkpoint
        self._armed: dict[str, bool] = {}  # per place breakpoint: may trigger (its condition was false)
        self._transitions: set[str] = set()
        self._hit_at: tuple[float, int] | None = None  # the checkpoint a transition breakpoint last triggered at
        self._watching = False
        self._observing = False  # watching the run's end and message events (lost, failed)
        self.breakpoints: list[Breakpoint] = []
        for spec in breakpoints:
            self._add(parse_breakpoint(spec))
        #: Called with :meth:`state` when an intervention is applied or a breakpoint hits.
        self.listeners: list[Any] = []
        #: Called (in the run's thread) when the run stops to wait (paused): a live page
        #: samples the run's state then.
        self.waiting: list[Any] = []
        #: Called (in the run's thread) over and over while paused by a run whose time
        #: goes on during a pause (remote agents): it lets up to :data:`PAUSED_STEP`
        #: seconds of the run pass, takes in what happens meanwhile and fires nothing;
        #: ``True`` when something happened. When the run is not paced
        #: (:attr:`Steerable.paced`), the control waits out the rest of
        #: :data:`PAUSED_STEP` in wall-clock time after each call, or until an
        #: intervention comes (a paced clock has waited for the wall clock itself).
        self.idle: Any = None

    # Any thread -------------------------------------------------------------------
    def submit(self, intervention: Intervention) -> Reply:
        """Queue ``intervention`` for the run's next checkpoint; returns its reply."""
        with self._wakeup:
            if self.closed:
                intervention.reply.set(False, "the run has ended")
            else:
                self._queue.append(intervention)
                self._wakeup.notify_all()
        return intervention.reply

    def close(self) -> None:
        """The run ended: refuse what is queued and what comes later."""
        with self._wakeup:
            self.closed = True
            while self._queue:
                self._queue.popleft().reply.set(False, "the run has ended")
            self._wakeup.notify_all()

    @property
    def holding(self) -> bool:
        """Whether a pause holds the run now (no firing may start)."""
        return self.paused and not self.steps and self.interactive and not self._script and not self.closed

    def state(self) -> dict[str, Any]:
        """What a page shows of the controls: paused, steps left, breakpoints."""
        return {"paused": self.paused, "steps": self.steps, "breakpoints": [b.text for b in self.breakpoints]}

    # The run's thread ---------------------------------------------------------------
    def attach(self, run: Steerable) -> None:
        """Steer ``run`` (called once by the scheduler that takes this control)."""
        self._run = run
        self._reindex()

    def interrupt(self) -> bool:
        """The clock asks after each tick of an advance: ``True`` stops it there (paused,
        or something queued), so that a checkpoint comes at once, not at the next
        instant (which may be far off in a paced run)."""
        return bool(self.interactive and (self._queue or (self.paused and not self.steps)) and not self._script)

    def cut(self, now: int, tick: int, ticks_at: Any) -> int:
        """The tick to advance to from ``now``, ``tick`` unless a replayed intervention
        came between (the original run stopped there: :meth:`interrupt`)."""
        if self._script:
            at = ticks_at(self._script[0].time)
            if now < at < tick:
                return at
        return tick

    def new_instant(self, now: float) -> None:
        """Time moved on to ``now``: checkpoints are numbered per instant (so a resumed
        run finds the same ones)."""
        self._at, self.point = now, 0

    def admit(self, t: int) -> bool:
        """A checkpoint before transition index ``t`` fires: apply what is queued, pause
        for a breakpoint or while paused. ``False``: ``t`` can no longer fire (an
        intervention took its tokens); it is checked again with the others."""
        if not (self.paused or self._queue or self._script or self._watching):
            self.point += 1
            return True
        changed = self._checkpoint(t)
        if self.paused and self.steps:
            self.steps -= 1
        return not changed or self._run.can_fire(t)

    def between(self) -> bool:
        """A checkpoint between instants; ``True`` when an intervention changed the
        marking (the run then fires at this instant again before time moves on)."""
        if not (self.paused or self._queue or self._script or self._watching):
            self.point += 1
            return False
        return self._checkpoint(None)

    def _checkpoint(self, t: int | None) -> bool:
        self.point += 1
        changed = waited = False
        told = -1
        while True:
            before = len(self._script)
            changed |= self._drain()
            hits = self._triggers(t)
            if self._script and self._here(self._script[0]):
                if len(self._script) == before and not hits:
                    head = self._script[0]
                    raise ControlError(f"the journal's control event {head.seq} ({head.data.get('action')}) does"
                                       " not come where it did: this run is not the one journaled")
                continue  # replaying: what was applied after a hit at this point comes next
            if self.holding:
                seen = self._run.recorder_count()
                if seen != told:  # something happened since the watchers last looked
                    told = seen
                    for watcher in self.waiting:
                        watcher()
                if self.idle is not None:  # the run's time goes on: take in what comes
                    began = wallclock.monotonic()
                    changed |= self.idle()
                    if not self._run.paced:
                        self._rest(PAUSED_STEP - (wallclock.monotonic() - began))
                else:
                    self._rest(0.25)
                waited = True
                continue
            if waited:
                self._run.rebase_clock()
            return changed

    def _rest(self, seconds: float) -> None:
        """Wait up to ``seconds`` of wall-clock time, or until an intervention is queued
        or the run closes."""
        if seconds <= 0:
            return
        with self._wakeup:
            if not self._queue and not self.closed:
                self._wakeup.wait(seconds)

    def _here(self, event: Event) -> bool:
        """Whether a journaled control event was applied at this checkpoint."""
        return event.data.get("point") == self.point and event.time == round(self._run.now, 9)

    def _drain(self) -> bool:
        """Apply the queued interventions (the script's, replaying); ``True`` if the
        marking changed."""
        changed = False
        run = self._run
        while True:
            if self._script:
                event = self._script[0]
                if not self._here(event) or event.seq != run.recorder_count():
                    return changed
                self._script.popleft()
                data = dict(event.data)
                intervention = Intervention(Command(data.pop("action")), {}, data.get("by", ""), data.get("wall", ""))
                intervention.args = {k: v for k, v in data.items()
                                     if k in ("count", "place", "spec", "firing", "outcome", "factor")}
                if intervention.command is Command.FORCE:
                    intervention.args["firing"] = str(data.get("number", data.get("firing")))
            else:
                with self._wakeup:
                    if not self._queue:
                        return changed
                    intervention = self._queue.popleft()
            try:
                changed |= self._apply(intervention)
            except ControlError as exc:
                intervention.reply.set(False, str(exc))
            except BaseException:  # an unrouted forced failure ends the run (its reply is set)
                raise

    def _apply(self, intervention: Intervention) -> bool:
        """Apply one intervention: checked, recorded, then done (so its event comes
        before what it causes, as a firing's start comes before its end)."""
        run, args, command = self._run, intervention.args, intervention.command
        details: dict[str, Any] = dict(args)
        transition = None
        effect = None
        if command is Command.PAUSE:
            self.paused, self.steps = True, 0
        elif command is Command.RESUME:
            self.paused, self.steps = False, 0
        elif command is Command.STEP:
            self.paused, self.steps = True, args["count"]
        elif command is Command.BREAK:
            self._add(parse_breakpoint(args["spec"]))
        elif command is Command.CLEAR:
            spec = args.get("spec")
            if spec is not None and spec not in [b.text for b in self.breakpoints]:
                raise ControlError(f"no breakpoint {spec!r} (breakpoints: "
                                   f"{', '.join(b.text for b in self.breakpoints) or 'none'})")
            self.breakpoints = [b for b in self.breakpoints if spec is not None and b.text != spec]
            self._reindex()
        elif command is Command.INJECT:
            place, count = args["place"], args["count"]
            run.count(place)  # the place exists
            details["added"] = {place: count}
            effect = lambda: run.inject(place, count)  # noqa: E731
        elif command is Command.REMOVE:
            place, count = args["place"], args["count"]
            held = run.count(place)
            if held < count:
                raise ControlError(f"place {place!r} holds {held} token{'s' * (held != 1)}, not {count}")
            details["removed"] = {place: count}
            effect = lambda: run.remove(place, count)  # noqa: E731
        elif command is Command.FORCE:
            transition, number = run.find_firing(args["firing"])
            details["firing"], details["number"] = transition, number
            reason = f"forced {args['outcome']} by {intervention.by}"
            effect = lambda: run.force(str(number), Outcome(args["outcome"]), reason)  # noqa: E731
        elif command is Command.SPEED:
            run.set_speed(args["factor"])
        details.update(action=command.value, by=intervention.by, wall=intervention.wall, point=self.point)
        run.emit(_CONTROL, transition, None, **details)
        for listener in self.listeners:
            listener(self.state())
        intervention.reply.set(True, f"{command.value} applied at t={run.now:g} s")
        if effect is not None:
            effect()
        return effect is not None

    # Breakpoints ----------------------------------------------------------------------
    def _add(self, point: Breakpoint) -> None:
        if point.text not in [b.text for b in self.breakpoints]:
            self.breakpoints.append(point)
        self._reindex()

    def _reindex(self) -> None:
        self._transitions = {b.name for b in self.breakpoints if b.kind == "transition"}
        self._armed = {b.text: self._armed.get(b.text, True) for b in self.breakpoints if b.kind == "place"}
        self._watching = bool(self.breakpoints)
        kinds = {b.kind for b in self.breakpoints} & {"lost", "failed"}
        if kinds and not self._observing and self._run is not None:
            # only now: watching every end and message would make the run build them all
            self._observing = True
            self._run.on_event(self._observe, kinds=["message", "end"])

    def _observe(self, event: Event) -> None:
        """Watch for lost messages and failures (the ``lost`` and ``failed`` breakpoints)."""
        if not self._watching:
            return
        if event.kind == "message" and event.data.get("fate") == "lost":
            self._signals.append({"spec": "lost", "place": event.data.get("place"), "seq": event.seq})
        elif event.kind == "end" and event.data.get("outcome") in ("failed", "timeout"):
            self._signals.append({"spec": "failed", "failed": event.transition, "seq": event.seq})

    def _triggers(self, t: int | None) -> bool:
        """Record and pause for the breakpoints that trigger at this checkpoint (``True``
        if any did)."""
        if not self._watching:
            return False
        run = self._run
        kinds = {b.kind for b in self.breakpoints}
        hits: list[tuple[str | None, dict[str, Any]]] = []
        for signal in self._signals:
            if signal["spec"] in kinds:
                hits.append((None, signal))
        self._signals.clear()
        for b in self.breakpoints:
            if b.kind == "place":
                now = run.count(b.name)
                true = _COMPARE[b.compare](now, b.count)
                if true and self._armed.get(b.text, True):
                    hits.append((None, {"spec": b.text, "place": b.name, "tokens": now}))
                self._armed[b.text] = not true
        if t is not None and self._transitions:
            name = run.transition_of(t)
            here = (self._at, self.point)
            if name in self._transitions and self._hit_at != here:  # once per checkpoint
                hits.append((name, {"spec": f"transition {name}"}))
                self._hit_at = here
        for transition, details in hits:
            self.paused, self.steps = True, 0
            run.emit(_CONTROL, transition, None, action=Command.HIT.value, point=self.point, **details)
        if hits:
            for listener in self.listeners:
                listener(self.state())
        return bool(hits)
