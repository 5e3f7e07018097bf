"""Watching a bridged run's agents after each instant: lost, back, and waiting for them.

:class:`AgentWatch` runs after each instant of a run with remote agents: an agent
silent for ``heartbeat_timeout`` is lost (:meth:`Scheduler.agent_lost
<petriflow.runtime.scheduler.Scheduler.agent_lost>`: its running firings end
``failed``, its transitions stop firing), and back when it announces itself again
(:meth:`~petriflow.runtime.scheduler.Scheduler.agent_back`, a late joiner).
"""

from __future__ import annotations

from typing import Any

from petriflow.bridge.dispatcher import Dispatcher
from petriflow.bridge.spec import BridgeSpec
from petriflow.net import Net
from petriflow.runtime.kernel import POLL, Scheduled

__all__ = ["AgentWatch", "Listen"]


class Listen(Scheduled):
    """An instant for nothing but to look whether a lost agent is back: while an agent
    is lost, the run waits for it (``rejoin`` seconds) rather than ending ``dead``."""

    __slots__ = ()
    phase = POLL

    def apply(self, tick: int) -> None:
        pass


class AgentWatch:
    """After each instant: agents lost or back become the run's (see the module). While
    an agent is lost, and for at most ``rejoin`` seconds since, the run looks again
    every heartbeat (a :class:`Listen`), so that a run with nothing else to do waits
    for it to come back instead of ending ``dead``.

    Args:
        dispatcher: the run's bridge.
        net: the net (which subnets each remote agent runs).
        spec: the ``bridge:`` section.
    """

    def __init__(self, dispatcher: Dispatcher, net: Net, spec: BridgeSpec) -> None:
        self.dispatcher = dispatcher
        self.spec = spec
        self.lost_at: dict[str, float] = {}  # lost remote agent -> the run's time it was lost
        self.listening = -1  # the tick of the Listen scheduled last
        self.runs: dict[str, list[str]] = {}
        for subnet, remote in spec.agents.items():
            found = net.subnets.get(subnet) or next((s for s in net.subnets.values() if s.agent == subnet), None)
            if found is not None:
                self.runs.setdefault(remote, []).append(found.agent or found.id)

    def __call__(self, scheduler: Any) -> None:
        lost, back = self.dispatcher.watch()
        for remote in lost:
            self.lost_at[remote] = scheduler.now
            why = f"no message from {remote!r} for {self.dispatcher.spec.heartbeat_timeout:g} s"
            for agent in self.runs.get(remote, []):
                scheduler.agent_lost(agent, why)
        for remote in back:
            self.lost_at.pop(remote, None)
            for agent in self.runs.get(remote, []):
                scheduler.agent_back(agent)
        self.listen(scheduler)

    def listen(self, scheduler: Any) -> None:
        """While an agent is lost (``rejoin`` seconds at most), an instant every heartbeat."""
        kernel = scheduler.kernel
        if not self.lost_at or self.listening > kernel.tick:
            return
        if min(self.lost_at.values()) + self.spec.rejoin < scheduler.now:
            return
        self.listening = kernel.tick + max(1, kernel.ticks_at(self.spec.heartbeat))
        kernel.schedule(self.listening, Listen())
