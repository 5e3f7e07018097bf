"""What a run gave: one result type, from the scheduler's loop to ``petriflow.run``.

A run ends for one :class:`~petriflow.outcome.StopReason` (``final``, ``dead``,
``until``...) and leaves a marking, its tokens' data and a count of events. A run
started from files or from Python (:func:`petriflow.runtime.session.run`,
``petriflow run``) adds what it wrote, how long it took on the wall clock, the events
it was asked to keep and the metrics its configuration names. All of it is one
:class:`RunResult`: the scheduler fills the first part
(:meth:`~petriflow.runtime.scheduler.Scheduler.run`), the session the rest.

An action's own ending is an :class:`~petriflow.outcome.Outcome` (``ok``,
``failed``, ``timeout``, ``cancelled``): a different thing, which picks output arcs.

Examples:
    >>> from petriflow.marking import Marking
    >>> result = RunResult(StopReason.FINAL, 2.0, 1, Marking({"o": 1}), 4)
    >>> result.reason, result.time, result.marking
    (<StopReason.FINAL: 'final'>, 2.0, Marking({'o': 1}))
    >>> result.realtime_factor   # no wall-clock time measured
    inf
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from petriflow.marking import Marking
from petriflow.outcome import StopReason

if TYPE_CHECKING:
    from petriflow.net import Net
    from petriflow.runtime.trace import Event

__all__ = ["RunResult", "StopReason"]


@dataclass
class RunResult:
    """What a run gave.

    Attributes:
        reason: why it ended (:class:`~petriflow.outcome.StopReason`): ``final`` (the
            net's final marking was reached with nothing running or pending),
            ``dead`` (nothing can fire, run or arrive any more), ``until`` (the time
            limit), ``firings`` (the firing limit), ``failed`` (an action failed with
            no failure route; see ``error``), ``stalled`` (actions stepped tick by tick
            for the configuration's ``stall`` seconds with no firing starting or
            ending; see ``error``) or ``fired``
            (:meth:`~petriflow.runtime.scheduler.Scheduler.fire_one`).
        time: simulated seconds at the end.
        firings: transitions fired.
        marking: token counts at the end.
        event_count: number of events recorded (kept or not).
        error: the unrouted failure or the stall, if any.
        tokens: ``{place: [data, ...]}`` at the end.
        net: the net run.
        events: the events, when the run was asked to keep them (else empty).
        wall: wall-clock seconds the run took (0 when not measured).
        written: the files written.
        seed: the run's random seed (conflicts, action randomness, channel losses).
        metrics: the metrics the run configuration (or ``metrics=``) asked for, by name.
        cpu: CPU seconds of the run itself (``time.process_time``), ``None`` when not
            measured.
        properties: with ``monitor=True``, the net's properties as the run kept them
            (:meth:`~petriflow.properties.monitor.PropertyMonitor.results`).
    """

    reason: StopReason
    time: float
    firings: int
    marking: Marking
    event_count: int = 0
    error: str | None = None
    tokens: dict[str, list[Any]] = field(default_factory=dict)
    net: Net | None = None
    events: list[Event] = field(default_factory=list)
    wall: float = 0.0
    written: list[str] = field(default_factory=list)
    seed: int | None = None
    metrics: dict[str, Any] = field(default_factory=dict)
    cpu: float | None = None
    properties: list[dict[str, Any]] = field(default_factory=list)

    @property
    def realtime_factor(self) -> float:
        """Simulated seconds per wall-clock second (``inf`` when no wall time was measured)."""
        return self.time / self.wall if self.wall > 0 else float("inf")

    @property
    def result(self) -> "RunResult":
        """The result itself: code written when a run's outcome held its result
        (``outcome.result.reason``) reads on unchanged."""
        return self
