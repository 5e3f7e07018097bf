"""Injected faults as a run component: agents killed or joining late, links dropped.

The run configuration lists faults (:class:`~petriflow.runtime.config.Fault`);
:class:`Faults` schedules each one as an event on the run's kernel and keeps the state
they change: which agents run and which links are down. When a fault's time comes it
records a ``fault`` event and says what changed (an agent stopped or started) to
the callbacks it was made with, so the scheduler never branches on fault kinds.

Examples:
    >>> from petriflow.runtime.config import Fault
    >>> from petriflow.runtime.kernel import Kernel
    >>> from petriflow.runtime.recorder import Recorder
    >>> kernel, stopped = Kernel(dt=1.0), []
    >>> faults = Faults(kernel, Recorder(kernel), [Fault("kill", 2.0, "r1")], ["r1", "r2"],
    ...                 stopped=stopped.append, started=print)
    >>> kernel.tick = kernel.peek(); kernel.run_due()
    >>> stopped, faults.running
    (['r1'], {'r1': False, 'r2': True})
"""

from __future__ import annotations

from typing import Callable, Iterable

from petriflow.runtime.config import Fault, FaultKind
from petriflow.runtime.kernel import APPLY, Kernel, Scheduled
from petriflow.runtime.recorder import Recorder

__all__ = ["Faults", "FaultEvent"]


class FaultEvent(Scheduled):
    """A fault's time has come (``handler`` is :meth:`Faults.apply`), or a dropped
    link's ``until`` (:meth:`Faults.restore`)."""

    __slots__ = ("handler", "fault")
    phase = APPLY

    def __init__(self, handler: Callable[[Fault], None], fault: Fault) -> None:
        self.handler = handler
        self.fault = fault

    def apply(self, tick: int) -> None:
        self.handler(self.fault)


class Faults:
    """Which agents run and which links work, changed by scheduled faults.

    Args:
        kernel: the run's kernel (each fault is an event on it).
        recorder: the run's events (each fault is one).
        faults: the faults to inject.
        agents: the run's agents (all running at the start, except late joiners).
        stopped: called with an agent that stops (killed): the run cancels its actions.
        started: called with an agent that starts (a late joiner): its transitions may fire.
    """

    def __init__(self, kernel: Kernel, recorder: Recorder, faults: Iterable[Fault], agents: Iterable[str], *,
                 stopped: Callable[[str], None], started: Callable[[str], None]) -> None:
        self.kernel = kernel
        self.recorder = recorder
        self.on_stopped = stopped
        self.on_started = started
        self.agents = list(agents)
        #: The agents not running now (killed, or not yet joined): every other agent runs.
        self.stopped: set[str] = set()
        #: The agents stopped by :meth:`lose` alone: what :meth:`rejoin` starts again (an
        #: agent a ``kill`` stopped, or one not joined yet, stays stopped).
        self.lost: set[str] = set()
        self.down: set[frozenset[str]] = set()
        for fault in faults:
            kernel.schedule(kernel.ticks_at(fault.at), FaultEvent(self.apply, fault))
            if fault.kind == FaultKind.JOIN:
                self.stopped.add(fault.agent)

    @property
    def running(self) -> dict[str, bool]:
        """``{agent: running}`` for every agent of the run."""
        return {agent: agent not in self.stopped for agent in self.agents}

    def alive(self, agent: str | None) -> bool:
        """Whether ``agent`` runs now (``None``, no agent, always does)."""
        return agent not in self.stopped

    def link_down(self, sender: str | None, receiver: str | None) -> bool:
        """Whether messages between the two agents are being lost."""
        return bool(self.down) and frozenset(a for a in (sender, receiver) if a) in self.down

    def apply(self, fault: Fault) -> None:
        """Inject ``fault`` now."""
        emit = self.recorder.emit
        if fault.kind == FaultKind.KILL:
            self.stopped.add(fault.agent)
            self.lost.discard(fault.agent)
            emit("fault", None, fault.agent, fault=FaultKind.KILL.value)
            self.on_stopped(fault.agent)
        elif fault.kind == FaultKind.JOIN:
            self.stopped.discard(fault.agent)
            emit("fault", None, fault.agent, fault=FaultKind.JOIN.value)
            self.on_started(fault.agent)
        elif fault.kind == FaultKind.DROP_LINK:
            self.down.add(frozenset(fault.link))
            emit("fault", None, None, fault=FaultKind.DROP_LINK.value, link=list(fault.link))
            if fault.until is not None:
                self.kernel.schedule(self.kernel.ticks_at(fault.until), FaultEvent(self.restore, fault))

    def lose(self, agent: str, why: str = "") -> None:
        """``agent`` stopped answering (a remote agent silent too long): it no longer
        runs, as if killed, until :meth:`rejoin`; the caller ends its running actions."""
        if agent not in self.stopped:
            self.lost.add(agent)
            self.stopped.add(agent)
        self.recorder.emit("fault", None, agent, fault=FaultKind.LOST.value, **({"why": why} if why else {}))

    def rejoin(self, agent: str) -> None:
        """A lost ``agent`` is back: it runs again, as a late joiner does (one that was
        stopped before it was lost, killed or not joined yet, stays stopped)."""
        if agent not in self.lost:
            return
        self.lost.discard(agent)
        self.stopped.discard(agent)
        self.recorder.emit("fault", None, agent, fault=FaultKind.BACK.value)
        self.on_started(agent)

    def restore(self, fault: Fault) -> None:
        """The link ``fault`` dropped works again."""
        self.down.discard(frozenset(fault.link))
        self.recorder.emit("fault", None, None, fault=FaultKind.RESTORE_LINK.value, link=list(fault.link))
