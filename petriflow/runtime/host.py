"""What a run's components (channels, faults) may ask of the run: a typed interface.

Components are made by the scheduler and given the run as a :class:`RunHost`; they
schedule their events on its kernel, record events, put delivered tokens into places
and say when an agent stopped or started. They never reach into the scheduler's
other parts, so a component can be read, and tested, against this interface alone.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

from petriflow.net import Net
from petriflow.runtime.kernel import Kernel

if TYPE_CHECKING:
    from petriflow.runtime.faults import Faults
    from petriflow.runtime.recorder import Recorder

__all__ = ["RunHost"]


class RunHost(Protocol):
    """The run, as its components see it."""

    net: Net
    kernel: Kernel
    world: Any
    faults: "Faults"  # which agents run and which links work (channels read it)
    #: The run's events: a component asks ``recorder.wants(kind)`` before it works out
    #: data only an event would carry (``emit`` itself takes only the event's number when
    #: nobody listens).
    recorder: "Recorder"

    def emit(self, kind: str, transition: str | None = None, agent: str | None = None, **data: Any) -> None:
        """Record an event (observers receive it)."""

    def deliver(self, place: str, data: Any) -> None:
        """A token arrives in ``place`` from outside a firing."""

    def agent_stopped(self, agent: str) -> None:
        """``agent`` stopped: its running actions are cancelled, its transitions do not fire."""

    def agent_started(self, agent: str) -> None:
        """``agent`` started: its transitions may fire."""
