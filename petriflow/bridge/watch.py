"""Watching a bridged run's agents after each instant: lost, back, and waiting for them.

:class:`AgentWatch` runs after each instant of a run with remote agents: an agent
silent for ``heartbeat_timeout`` is lost (:meth:`Scheduler.agent_lost
<petriflow.runtime.scheduler.Scheduler.agent_lost>`: its running firings end
``failed``, its transitions stop firing), and back when it announces itself again
(:meth:`~petriflow.runtime.scheduler.Scheduler.agent_back`, a late joiner). The
agents' ``feedback`` on running goals becomes ``feedback`` events
(:func:`record_feedback`), each datum at most :data:`FEEDBACK_BYTES` of JSON.
"""

from __future__ import annotations

import hashlib
import json
from typing import Any

from petriflow.bridge.dispatcher import Dispatcher
from petriflow.bridge.spec import BridgeSpec
from petriflow.net import Net
from petriflow.runtime.kernel import POLL, Scheduled
from petriflow.runtime.trace import EventKind, summarize

__all__ = ["AgentWatch", "Listen", "record_feedback", "feedback_data", "FEEDBACK_BYTES"]

#: The most JSON one feedback event keeps of the agent's data; larger data is recorded
#: as its size and digest (a message may be 1 MiB: :data:`~petriflow.bridge.protocol.MAX_MESSAGE`).
FEEDBACK_BYTES = 4096
_FEEDBACK = EventKind.FEEDBACK.value


def feedback_data(data: Any) -> Any:
    """An agent's feedback data as a trace keeps it: summarized as token data is, and
    replaced by its size and digest when its JSON is over :data:`FEEDBACK_BYTES`.

    Examples:
        >>> feedback_data({"progress": 0.5})
        {'progress': 0.5}
        >>> feedback_data("x" * 5000)
        '<feedback 5002 bytes sha1=...>'
    """
    kept = summarize(data)
    text = json.dumps(kept, sort_keys=True, separators=(",", ":"), allow_nan=False)
    if len(text) <= FEEDBACK_BYTES:
        return kept
    return f"<feedback {len(text)} bytes sha1={hashlib.sha1(text.encode()).hexdigest()[:12]}>"


def record_feedback(scheduler: Any, dispatcher: Any) -> None:
    """Record the feedback the agents sent since the last instant, one ``feedback`` event
    each, in goal order (the transition's agent as the event's; the remote agent, the
    goal and the firing in its data: ``remote_agent``, ``goal``, ``firing``; ``skipped``: older ones of a flood left out)."""
    taken = dispatcher.take_feedback()
    if not taken:
        return
    index, listened = scheduler.index, scheduler.recorder.wants(_FEEDBACK)
    for goal, items, skipped in taken:
        position = index.position.get(goal.transition)
        agent = None if position is None else index.agent[position]
        firing = int(goal.id.split("/")[1])  # run/firing/attempt (the run made the id)
        for k, data in enumerate(items):
            extra = {"skipped": skipped} if skipped and not k else {}
            scheduler.emit(_FEEDBACK, goal.transition, agent, firing=firing, goal=goal.id, remote_agent=goal.agent,
                           data=feedback_data(data) if listened else None, **extra)


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
        record_feedback(scheduler, self.dispatcher)
        lost, back = self.dispatcher.watch()
        for remote in lost:
            self.lost_at[remote] = scheduler.now
            why = f"{remote!r}: {self.dispatcher.why_lost(remote)}"
            for agent in self.runs.get(remote, []):
                scheduler.agent_lost(agent, why)
        for remote in back:
            self.lost_at.pop(remote, None)
            for agent in self.runs.get(remote, []):
                scheduler.agent_back(agent)  # one a kill fault stopped stays stopped (Faults.rejoin)
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
