"""Contended media as processes on the run's kernel.

A simple channel model answers, when a message is sent, after how long it arrives
(:class:`~petriflow.runtime.channel_models.ChannelModel`). A shared medium cannot: whether a
frame gets through depends on frames sent after it (a collision, an overwritten
receive buffer, a lost arbitration). A :class:`Medium` is a channel model that runs as
a process instead, in SimPy's resource shape: the run hands it each message when it
is sent (:meth:`Medium.send`) and it schedules its own events on the run's kernel
through a :class:`ProcessClock` (transmission start and end, arbitration, collision,
back-off, buffer reads), each at its exact time. When a message's fate happens, the
medium says so through its :class:`MediumPort`: :meth:`~MediumPort.deliver` puts the
token in its channel place then, :meth:`~MediumPort.lose` records the loss then (and
leaves a loss notice with ``on_loss: notify``). Nothing is decided ahead of time and
nothing is taken back.

Actions ask a medium about itself only through the small interface it declares for
one agent (:meth:`Medium.view`, reached with ``ctx.medium(place)``): is the medium
quiet, how often this agent reads its receive buffer. They never reconfigure it or test
its type.

A medium's timed events keep the run alive while they are pending, so a medium must
not schedule events forever: it schedules a buffer read when a frame waits, not every
read period.

Examples:
    A toy medium that carries one message at a time, 1 ms each, and loses a message
    sent while another is on it:

    >>> from petriflow.runtime.channel_models import Message
    >>> from petriflow.runtime.kernel import Kernel
    >>> class Wire(Medium):
    ...     def attach(self, port):
    ...         self.port, self.busy_until = port, -1.0
    ...     def send(self, message):
    ...         clock = self.port.clock
    ...         if clock.now < self.busy_until:
    ...             self.port.lose(message, "collision")
    ...             return
    ...         self.busy_until = clock.now + 0.001
    ...         clock.at(self.busy_until, self.port.deliver, message)
    >>> kernel = Kernel(dt=0.01)
    >>> seen = []
    >>> port = MediumPort(ProcessClock(kernel), lambda m: seen.append(("delivered", m.data, port.clock.now)),
    ...                   lambda m, why: seen.append((why, m.data, port.clock.now)))
    >>> wire = Wire(); wire.attach(port)
    >>> wire.send(Message("box", "a", "b", "first", 0.0)); wire.send(Message("box", "c", "b", "second", 0.0))
    >>> port.clock.run(until=0.05)
    >>> seen
    [('collision', 'second', 0.0), ('delivered', 'first', 0.001)]
"""

from __future__ import annotations

import math
from typing import Any, Callable

from petriflow.runtime.channel_models import ChannelModel, Message
from petriflow.runtime.kernel import TIMED, Kernel, Scheduled

__all__ = ["Medium", "MediumPort", "ProcessClock", "Timer"]


class Timer(Scheduled):
    """A callback scheduled at an exact time on a :class:`ProcessClock`; :meth:`cancel`
    stops it from running.

    Attributes:
        time: when it runs (simulated seconds).
        cancelled: whether :meth:`cancel` was called.
    """

    __slots__ = ("clock", "time", "callback", "args", "cancelled", "done")
    phase = TIMED

    def __init__(self, clock: "ProcessClock", time: float, callback: Callable[..., Any], args: tuple) -> None:
        self.clock = clock
        self.time = time
        self.callback = callback
        self.args = args
        self.cancelled = False
        self.done = False

    def cancel(self) -> None:
        """Do not run this callback (a no-op once it has run)."""
        if not self.cancelled and not self.done:
            self.cancelled = True
            self.clock.kernel.pending -= 1

    def live(self, tick: int) -> bool:
        return not self.cancelled

    def apply(self, tick: int) -> None:
        self.done = True
        clock = self.clock
        clock.handling = self.time
        try:
            self.callback(*self.args)
        finally:
            clock.handling = None

    def __repr__(self) -> str:
        name = getattr(self.callback, "__name__", repr(self.callback))
        return f"Timer({self.time!r}, {name}{', cancelled' if self.cancelled else ''})"


class ProcessClock:
    """A process's view of the run's kernel: exact time and timed callbacks.

    ``now`` is the exact time of the timed event being handled, or the kernel's time
    (the current instant) outside one, when the run's actions call the medium.
    Callbacks run in order of time, then ``rank``, then scheduling order.

    Args:
        kernel: the run's kernel.

    Attributes:
        handling: the time of the timed event being handled, or ``None``.
    """

    def __init__(self, kernel: Kernel) -> None:
        self.kernel = kernel
        self.handling: float | None = None

    @property
    def now(self) -> float:
        """The current time in seconds."""
        return self.kernel.now if self.handling is None else self.handling

    def at(self, time: float, callback: Callable[..., Any], *args: Any, rank: int = 0) -> Timer:
        """Run ``callback(*args)`` at ``time`` (not before now).

        Raises:
            ValueError: ``time`` is in the past or not finite.
        """
        if not math.isfinite(time) or time < self.now - 1e-12:
            raise ValueError(f"cannot schedule at {time!r}: now is {self.now!r}")
        timer = Timer(self, max(float(time), self.now), callback, args)
        self.kernel.schedule_at(timer.time, timer, rank)
        return timer

    def after(self, delay: float, callback: Callable[..., Any], *args: Any, rank: int = 0) -> Timer:
        """Run ``callback(*args)`` ``delay`` seconds from now."""
        return self.at(self.now + delay, callback, *args, rank=rank)

    def run(self, until: float) -> None:
        """Drive the kernel on its own up to ``until`` (a medium outside a run: tests,
        figures); inside a run, the run drives it."""
        kernel = self.kernel
        limit = kernel.ticks_at(until)
        while True:
            tick = kernel.peek()
            if tick is None or tick > limit:
                break
            kernel.tick = tick
            kernel.run_due()
        kernel.tick = max(kernel.tick, limit)


class MediumPort:
    """What a run gives a :class:`Medium`: its clock, and where fates go.

    Attributes:
        clock: the run's :class:`ProcessClock`.
        deliver: ``deliver(message)``: the message's token appears in its channel place now.
        lose: ``lose(message, why)``: the message is lost now (``why``: a short reason).
        rng: the medium's random generator (seeded from the run's seed).
        world: the run's world (``None`` in a world-less run).
    """

    def __init__(self, clock: ProcessClock, deliver: Callable[[Message], None],
                 lose: Callable[[Message, str], None], rng: Any = None, world: Any = None) -> None:
        self.clock = clock
        self.deliver = deliver
        self.lose = lose
        self.rng = rng
        self.world = world


class Medium(ChannelModel):
    """A channel model that runs as a process (see the module).

    Subclasses implement :meth:`attach` (keep the port; schedule nothing yet),
    :meth:`send` (a message is handed over now) and, if actions may ask about the
    medium, :meth:`view`.
    """

    #: The run hands messages to :meth:`send` instead of asking :meth:`deliver`.
    process = True

    def attach(self, port: MediumPort) -> None:
        """The run starts: keep ``port`` (the clock, and where fates go)."""
        raise NotImplementedError

    def send(self, message: Message) -> None:
        """A message is handed over now (``port.clock.now``); decide its fate later."""
        raise NotImplementedError

    def view(self, agent: str | None) -> Any:
        """The interface ``agent``'s actions use to ask about the medium (default: none).

        Raises:
            PetriflowError: the medium offers none.
        """
        from petriflow.errors import PetriflowError

        raise PetriflowError(f"the {type(self).__name__} medium offers its agents nothing to ask")

    def deliver(self, message: Message, rng: Any) -> float | None:  # pragma: no cover - not used for media
        raise NotImplementedError("a Medium decides fates as a process, not at send time")
