"""What a run reports when it ends, besides its result: the scenario's metrics and a picture.

The run configuration names the metrics (``metrics:``, a sweep file's syntax, see
:mod:`petriflow.runtime.metrics`); ``petriflow run --metrics NAMES`` picks others. They
are computed on the finished run with the world still open, exactly as a sweep trial
computes them, so ``run`` and ``sweep`` report the same numbers for the same seed.
``--picture out.png`` samples the robots' positions as the run goes
(:class:`~petriflow.runtime.trajectories.Trajectories`) and draws them over the world's
top view at the end (:func:`petriflow.picture.draw_run`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from petriflow.errors import NetFormatError
from petriflow.runtime.metrics import MetricRef, RunRecord, measure
from petriflow.runtime.registry import Registry, UnknownActionError, default_registry
from petriflow.runtime.trajectories import Trajectories

__all__ = ["RunExtras", "extras_for"]


@dataclass
class RunExtras:
    """The metrics to compute and the picture to draw at the end of a run.

    Attributes:
        metrics: ``(ref, MetricSpec)`` pairs, resolved in the run's registry.
        picture: the picture's file, or ``None``.
    """

    metrics: list[tuple[MetricRef, Any]] = field(default_factory=list)
    picture: Path | None = None
    track: Trajectories | None = None
    #: A :class:`~petriflow.properties.monitor.PropertyMonitor` watching the run, or None.
    monitor: Any = None

    def needs_events(self) -> bool:
        """Whether a metric reads the run's events (then the run keeps them)."""
        return any(spec.events for _, spec in self.metrics)

    def event_kinds(self) -> list[str] | None:
        """The kinds of events the metrics read (``None``: every kind)."""
        from petriflow.runtime.metrics import event_kinds

        return event_kinds(spec for _, spec in self.metrics)

    def watch(self, scheduler: Any) -> None:
        """Start sampling the robots' positions, if a picture is wanted and there is a world."""
        if self.picture is not None and scheduler.world is not None:
            self.track = Trajectories()
            scheduler.on_instant(self.track)
        if self.monitor is not None:
            self.monitor.attach(scheduler)

    def finish(self, scheduler: Any, outcome: Any, config: Any) -> None:
        """Compute the metrics into ``outcome.metrics`` and draw the picture (its file
        goes into ``outcome.written``); the monitored properties into ``outcome.properties``."""
        if self.monitor is not None:
            outcome.properties = self.monitor.results()
        if self.metrics:
            record = RunRecord(outcome.result, outcome.events, scheduler.world, config, {}, outcome.seed,
                               outcome.wall, scheduler, outcome.cpu)
            outcome.metrics = measure(self.metrics, record)
        if self.picture is not None and self.track is not None:
            from petriflow.picture import draw_run

            self.track.sample(scheduler.world, scheduler.now)
            from petriflow.io.files import PartialFile

            try:
                partial = PartialFile(self.picture, opened=False)
                try:
                    draw_run(scheduler.world, self.track.paths, partial.temporary,
                             title=f"{outcome.net.id}: {outcome.result.reason} at t = {outcome.result.time:g} s")
                except BaseException:
                    partial.finish(keep=False)
                    raise
                partial.finish()
            except OSError as exc:
                raise NetFormatError(f"cannot write the picture: {getattr(exc, 'strerror', None) or exc}",
                                     path=str(self.picture)) from None
            outcome.written.append(str(self.picture))


def extras_for(config: Any, *, metrics: list[str] | None = None, picture: str | Path | None = None,
               registry: Registry | None = None) -> RunExtras:
    """The extras of a run: the configuration's metrics (or ``metrics``, names of
    registered metrics; ``[]`` for none), resolved in ``registry``.

    Raises:
        NetFormatError: a metric is not registered (naming the configuration's file).
    """
    registry = registry or default_registry
    refs = config.metrics if metrics is None else [MetricRef(name, name) for name in metrics]
    resolved = []
    for ref in refs:
        try:
            resolved.append((ref, registry.metric_spec(ref.metric)))
        except UnknownActionError as exc:
            where = config.path if metrics is None else None
            raise NetFormatError(f"metrics: {ref.name}: {exc}", path=where,
                                 line=config.lines.get("metrics") if metrics is None else None) from None
    if picture is not None:
        picture = Path(picture)
        if picture.suffix.lower() not in (".png", ".svg", ".pdf"):
            raise NetFormatError("a picture is a .png, .svg or .pdf file", path=str(picture))
    return RunExtras(resolved, picture)
