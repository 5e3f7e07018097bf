"""Injected faults as a run component: agents killed or joining late, links dropped.

The run configuration lists faults (:class:`~petriflow.runtime.config.Fault`);
:class:`Faults` schedules each one as an event on the run's kernel and keeps the state
they change: which agents run and which links are down. When a fault's time comes it
records a ``fault`` event and tells the scheduler what changed (an agent stopped or
started), so the scheduler never branches on fault kinds.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Callable, Iterable

from petriflow.runtime.config import Fault, FaultKind
from petriflow.runtime.kernel import APPLY, Scheduled

if TYPE_CHECKING:
    from petriflow.runtime.host import RunHost

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
        run: the run (:class:`~petriflow.runtime.host.RunHost`: its ``kernel``,
            ``emit``, ``agent_stopped`` and ``agent_started``).
        faults: the faults to inject.
        agents: the run's agents (all running at the start, except late joiners).
    """

    def __init__(self, run: "RunHost", faults: Iterable[Fault], agents: Iterable[str]) -> None:
        self.run = run
        self.agents = list(agents)
        #: The agents not running now (killed, or not yet joined): every other agent runs.
        self.stopped: set[str] = set()
        self.down: set[frozenset[str]] = set()
        kernel = run.kernel
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
        run = self.run
        if fault.kind == FaultKind.KILL:
            self.stopped.add(fault.agent)
            run.emit("fault", None, fault.agent, fault=FaultKind.KILL.value)
            run.agent_stopped(fault.agent)
        elif fault.kind == FaultKind.JOIN:
            self.stopped.discard(fault.agent)
            run.emit("fault", None, fault.agent, fault=FaultKind.JOIN.value)
            run.agent_started(fault.agent)
        elif fault.kind == FaultKind.DROP_LINK:
            self.down.add(frozenset(fault.link))
            run.emit("fault", None, None, fault=FaultKind.DROP_LINK.value, link=list(fault.link))
            if fault.until is not None:
                run.kernel.schedule(run.kernel.ticks_at(fault.until), FaultEvent(self.restore, fault))

    def restore(self, fault: Fault) -> None:
        """The link ``fault`` dropped works again."""
        self.down.discard(frozenset(fault.link))
        self.run.emit("fault", None, None, fault=FaultKind.RESTORE_LINK.value, link=list(fault.link))
