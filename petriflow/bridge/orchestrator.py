"""A run with remote agents: connect, wait for the agents, check, watch.

:func:`open_bridge` is what ``petriflow run`` does for a configuration with a
``bridge:``: it connects a :class:`~petriflow.bridge.dispatcher.Dispatcher`, waits for
the configured agents to announce themselves (``wait`` seconds; ``--wait-agents``),
checks every remote transition against what its agent announced
(:func:`~petriflow.bridge.remote.check_announced`, ``file:line``), and disconnects when
the run is over. :class:`AgentWatch` then runs after each instant of the run: an agent
silent for ``heartbeat_timeout`` is lost (:meth:`Scheduler.agent_lost
<petriflow.runtime.scheduler.Scheduler.agent_lost>`: its running firings end
``failed``, its transitions stop firing), and back when it announces itself again.
"""

from __future__ import annotations

from contextlib import contextmanager
from typing import Any, Iterator

from petriflow.bridge.dispatcher import Dispatcher
from petriflow.bridge.remote import check_announced
from petriflow.bridge.spec import BridgeSpec
from petriflow.net import Net
from petriflow.runtime.binding import Binding

__all__ = ["open_bridge", "AgentWatch"]


@contextmanager
def open_bridge(binding: Binding, spec: BridgeSpec, *, wait: float | None = None, path: str | None = None,
                run: str | None = None) -> Iterator[Dispatcher]:
    """The run's bridge, connected and checked (see the module).

    Raises:
        NetFormatError: an agent did not announce itself in time, or does not serve a
            remote transition's action with its parameters (the net's ``file:line``).
    """
    dispatcher = Dispatcher(spec, run=run)
    try:
        dispatcher.wait_for(spec.wait if wait is None else wait)
        check_announced(binding, dispatcher, path)
        yield dispatcher
    finally:
        dispatcher.close()


class AgentWatch:
    """After each instant: agents lost or back become the run's (see the module).

    Args:
        dispatcher: the run's bridge.
        net: the net (which subnets each remote agent runs).
        spec: the ``bridge:`` section.
    """

    def __init__(self, dispatcher: Dispatcher, net: Net, spec: BridgeSpec) -> None:
        self.dispatcher = dispatcher
        self.runs: dict[str, list[str]] = {}
        for subnet, remote in spec.agents.items():
            found = net.subnets.get(subnet) or next((s for s in net.subnets.values() if s.agent == subnet), None)
            if found is not None:
                self.runs.setdefault(remote, []).append(found.agent or found.id)

    def __call__(self, scheduler: Any) -> None:
        lost, back = self.dispatcher.watch()
        for remote in lost:
            why = f"no message from {remote!r} for {self.dispatcher.spec.heartbeat_timeout:g} s"
            for agent in self.runs.get(remote, []):
                scheduler.agent_lost(agent, why)
        for remote in back:
            for agent in self.runs.get(remote, []):
                scheduler.agent_back(agent)
