"""An agent's outbox: what it has waiting to send, per receiver, oldest first.

An agent that decides what to say in one step and says it in others (a send
transition per peer, guarded by "something waits for that peer") keeps its queued
messages in an :class:`Outbox`, a part of its :class:`~petriflow.runtime.agents.AgentState`.
The outbox tells the state's guards what changed: putting or taking a message for
``peer`` touches the key ``outbox/<peer>`` (:data:`KEY`), so only the send guard of that
peer (registered with ``reads=("outbox/{peer}",)``) is asked again.

What waits is whatever the scenario sends: a payload (a frozen dataclass, see
:class:`~petriflow.runtime.channel_models.Message`) or a whole message. Not to be
confused with :class:`petriflow.netbuild.Mailbox`, the two places of a net that bound
a channel into an agent: an outbox is the sender's state, a mailbox is the net's.

Examples:
    >>> from petriflow.runtime.agents import AgentState
    >>> state, touched = AgentState(), []
    >>> state.attach(touched.append)
    >>> box = Outbox(state)
    >>> box.put("robot2", "hello"); box.put("robot2", "again")
    >>> box.waiting("robot2"), box.take("robot2"), touched
    (2, 'hello', [('outbox/robot2',), ('outbox/robot2',), ('outbox/robot2',)])
    >>> dict(box), box.take("robot3")
    ({'robot2': deque(['again'])}, None)
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterator, Mapping
from typing import Any

from petriflow.runtime.agents import AgentState

__all__ = ["KEY", "Outbox"]

#: The state key a change of one receiver's queue touches (``KEY.format(peer="robot2")``).
KEY = "outbox/{peer}"


class Outbox(Mapping[str, deque]):
    """Queued messages by receiver (see the module); reads as ``{receiver: deque}``.

    Args:
        owner: the agent state whose keys :meth:`put` and :meth:`take` touch (``None``:
            nobody is told).
    """

    def __init__(self, owner: AgentState | None = None) -> None:
        self._owner = owner
        self._queues: dict[str, deque] = {}

    def put(self, receiver: str, item: Any) -> None:
        """Queue ``item`` for ``receiver`` (last)."""
        queue = self._queues.get(receiver)
        if queue is None:
            queue = self._queues[receiver] = deque()
        queue.append(item)
        self._touch(receiver)

    def take(self, receiver: str) -> Any:
        """The oldest item for ``receiver``, taken out; ``None`` when nothing waits."""
        queue = self._queues.get(receiver)
        if not queue:
            return None
        item = queue.popleft()
        self._touch(receiver)
        return item

    def waiting(self, receiver: str) -> int:
        """How many items wait for ``receiver``."""
        queue = self._queues.get(receiver)
        return len(queue) if queue else 0

    def clear(self) -> None:
        """Drop everything queued (every receiver that had something is touched)."""
        had = [receiver for receiver, queue in self._queues.items() if queue]
        self._queues.clear()
        for receiver in had:
            self._touch(receiver)

    def _touch(self, receiver: str) -> None:
        if self._owner is not None:
            self._owner.touch(KEY.format(peer=receiver))

    def __getitem__(self, receiver: str) -> deque:
        return self._queues[receiver]

    def __iter__(self) -> Iterator[str]:
        return iter(self._queues)

    def __len__(self) -> int:
        return len(self._queues)

    def __repr__(self) -> str:
        return f"Outbox({self._queues!r})"
