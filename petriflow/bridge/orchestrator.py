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

import uuid
from contextlib import ExitStack, contextmanager
from typing import Any, Iterator

from petriflow.bridge.dispatcher import Dispatcher
from petriflow.bridge.remote import check_announced
from petriflow.bridge.spec import BridgeSpec
from petriflow.bridge.watch import AgentWatch, Listen
from petriflow.runtime.binding import Binding

__all__ = ["open_bridge", "AgentWatch", "Listen", "connect_run", "new_run_name"]


def new_run_name() -> str:
    """A new run's name in its goal ids (journaled, so a resume re-attaches by it)."""
    return uuid.uuid4().hex[:12]


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


def connect_run(stack: ExitStack, checked: Any, *, run: str | None, wait: float | None,
                journal: Any = None) -> tuple[Any, Any, Any]:
    """A checked bridged run's ``(remote service, clock, watcher after each instant)``,
    its connection closed with ``stack``; with a ``journal`` that holds events (a resume),
    the remote firings and agent faults it journaled are replayed up to its end and the
    firings still running are re-attached (:mod:`petriflow.bridge.resume`)."""
    from petriflow.runtime.clock import RealtimeClock

    spec = checked.config.bridge
    dispatcher = stack.enter_context(open_bridge(checked.binding, spec, wait=wait, run=run,
                                                 path=None if checked.path is None else str(checked.path)))
    watch = AgentWatch(dispatcher, checked.net, spec)
    if journal is None or not journal.journaled:
        return dispatcher, RealtimeClock(), watch
    from petriflow.bridge.remote import RemoteAction
    from petriflow.bridge.resume import Replay, ReplayingRemote, ReplayWatch, ResumeClock

    remote_ids = {tid for tid, bound in checked.binding.transitions.items()
                  if isinstance(bound.action, type) and issubclass(bound.action, RemoteAction)}
    replay = Replay(journal.events(), remote_ids)
    remote = ReplayingRemote(dispatcher, replay)
    return remote, ResumeClock(replay.until), ReplayWatch(remote, watch, watch.runs)
