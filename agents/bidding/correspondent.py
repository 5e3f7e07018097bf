"""A bidding agent as a correspondent: what it has to send, its broadcasts, its counts.

An agent's mailbox (where messages arrive) is the run's: a channel place, from which
``bidding.receive`` takes one token at a time. What an agent has still to *send* waits
in its state's :class:`~petriflow.runtime.outbox.Outbox` (the runtime's: one queue per
receiver, oldest first), as the one message type
(:class:`~petriflow.runtime.channel_models.Message`) carrying a bidding
:class:`~petriflow.agents.bidding.protocol.Payload`; ``bidding.send`` and
``bidding.cast`` put them into the receivers' mailboxes. A :class:`Correspondent` (the
base of every bidding agent's state) adds what the bidding protocol needs besides: a
broadcast is one message with a copy per receiver, which may leave in one firing when
every copy is first in its queue, and the messages waiting are counted (``pending``).

Examples:
    >>> from petriflow.agents.bidding.protocol import Kind, Payload
    >>> hmia = Correspondent("hmia")
    >>> hmia.queue("robot1", Payload(Kind.CFP, zone=2))
    >>> hmia.has_for("robot1"), hmia.has_for("robot2")
    (True, False)
    >>> message = hmia.take("robot1")
    >>> message.sender, message.receiver, message.kind, message.size
    ('hmia', 'robot1', <Kind.CFP: 'CFP'>, 4)
"""

from __future__ import annotations

from typing import Any

from petriflow.agents.bidding.protocol import Kind, Payload
from petriflow.runtime.agents import AgentState
from petriflow.runtime.channel_models import Message
from petriflow.runtime.outbox import Outbox

__all__ = ["Correspondent"]


class Correspondent(AgentState):
    """An agent's messages waiting to be sent, per receiver (oldest first: its
    :attr:`outbox`), its broadcasts, and counts of those sent and received.

    Args:
        name: the agent.

    The base of an agent's state (:class:`~petriflow.runtime.agents.AgentState`, kept
    by the run, never a token). It says what changed, so guards are asked again only
    when what they read did:

    * ``outbox/<peer>``: a message for ``peer`` was queued, sent or dropped (the guard of
      the send transition to that peer, ``bidding.has_message``, reads it);
    * ``pending``: the outbox went from empty to not, or back (:meth:`pending`, which
      costs nothing whatever the team's size: the messages waiting are counted);
    * ``step``: the step the agent's state calls for, or whether its part is over,
      changed (:meth:`changed`, which the agents' actions call when they end, compares
      :meth:`signature` with what it was: a message that changes neither, a proposal
      among many, asks no guard again);
    * ``cast`` (once :meth:`track_casts` was called): a broadcast became ready to leave
      in one firing, or stopped being ready (:meth:`ready_cast`: every copy of it is
      first in its receiver's queue).
    """

    def __init__(self, name: str = "") -> None:
        super().__init__()
        self.name = name
        self.casts = 0
        self.outbox = Outbox(self)  # touches outbox/<peer> as a message is queued or taken
        self.queued = 0  # messages in the outbox, all peers together
        self.sent: dict[Kind, int] = {}
        self.received: dict[Kind, int] = {}
        self._signature: Any = None
        self._track = False  # see track_casts
        # per broadcast whose copies are all still queued: its receivers and how many of
        # the copies are first in their queue (all of them: it may leave in one firing)
        self._cast_to: dict[int, frozenset[str]] = {}
        self._heads: dict[int, int] = {}

    def to_token(self) -> dict[str, Any]:
        """What a trace records of an agent's state: who it is and its message counts."""
        return {"agent": self.name or type(self).__name__, "casts": self.casts,
                "sent": sum(self.sent.values()), "received": sum(self.received.values())}

    def queue(self, receiver: str, payload: Payload) -> None:
        """Queue ``payload`` for ``receiver`` (last), as a message from this agent."""
        outbox = self.outbox
        outbox.put(receiver, Message(None, self.name, receiver, payload))
        self.queued += 1
        if outbox.waiting(receiver) == 1:
            self._first(payload.cast)
        if self.queued == 1:
            self.touch("pending")

    def broadcast(self, kind: Kind, receivers: list[str], zone: int | None = None,
                  body: dict[str, Any] | None = None) -> None:
        """Queue one broadcast: a copy for each receiver, all with the same ``cast``."""
        self.casts += 1
        if self._track and len(set(receivers)) == len(receivers) > 0:
            self._cast_to[self.casts] = frozenset(receivers)
            self._heads[self.casts] = 0
        for receiver in receivers:
            self.queue(receiver, Payload(kind, zone, dict(body or {}), self.casts))

    def track_casts(self) -> None:
        """Follow each broadcast queued from now on, so that it may leave in one firing
        (:meth:`ready_cast`, :meth:`take_cast`; the ``cast`` key): for an agent whose
        net has a ``cast`` transition."""
        self._track = True

    def _first(self, cast: int | None) -> None:
        """A copy of broadcast ``cast`` became first in its queue (it leaves that place
        only with the whole broadcast, or alone: :meth:`_alone`)."""
        if cast is None or cast not in self._heads:
            return
        self._heads[cast] += 1
        if self._ready(cast):
            self.touch("cast")

    def _ready(self, cast: int) -> bool:
        """Every copy of broadcast ``cast`` is first in its queue."""
        return self._heads[cast] == len(self._cast_to[cast])

    def _alone(self, cast: int | None) -> None:
        """Broadcast ``cast`` no longer leaves in one firing (a copy of it left alone, or
        was dropped, or all left together): its copies go one by one."""
        if cast is None or cast not in self._cast_to:
            return
        ready = self._ready(cast)
        del self._cast_to[cast], self._heads[cast]
        if ready:
            self.touch("cast")

    def ready_cast(self, receivers: Any) -> int | None:
        """The broadcast to exactly ``receivers`` (a set of agent names) that can leave in
        one firing now (:meth:`take_cast`): every copy first in its receiver's queue; or
        ``None``."""
        for cast, to in self._cast_to.items():  # the broadcasts in flight: a few
            if to == receivers and self._ready(cast):
                return cast
        return None

    def take_cast(self, receivers: Any) -> list[Message]:
        """Take the copies of the broadcast :meth:`ready_cast` names, one per receiver in
        name order (``[]`` when none is ready)."""
        cast = self.ready_cast(receivers)
        if cast is None:
            return []
        peers = sorted(self._cast_to[cast])
        self._alone(cast)
        taken = [self._taken(peer) for peer in peers]
        if self.queued == 0:
            self.touch("pending")
        return taken

    def has_for(self, peer: str) -> bool:
        """Whether a message waits for ``peer``."""
        return self.outbox.waiting(peer) > 0

    def pending(self) -> bool:
        """Whether any message waits (for anyone)."""
        return self.queued > 0

    def take(self, peer: str) -> Message | None:
        """The oldest message for ``peer``, taken out (``None``: nothing waits)."""
        if not self.outbox.waiting(peer):
            return None
        message = self._taken(peer)
        self._alone(message.data.cast)
        if self.queued == 0:
            self.touch("pending")
        return message

    def _taken(self, peer: str) -> Message:
        """The oldest message for ``peer`` out of its queue, counted as sent."""
        outbox = self.outbox
        message = outbox.take(peer)
        if outbox.waiting(peer):
            self._first(outbox[peer][0].data.cast)
        self.queued -= 1
        self.sent[message.kind] = self.sent.get(message.kind, 0) + 1
        return message

    def drop(self, peer: str) -> int:
        """Forget what waits for ``peer`` (it stopped); how many were dropped."""
        dropped = 0
        while (message := self.outbox.take(peer)) is not None:
            self._alone(message.data.cast)
            dropped += 1
        self.queued -= dropped
        if dropped and self.queued == 0:
            self.touch("pending")
        return dropped

    def signature(self) -> Any:
        """What the agent's step guards answer by (subclasses: the next step, whether
        the agent's part is over)."""
        return None

    def changed(self) -> None:
        """The state may have changed: touch ``step`` if its :meth:`signature` did."""
        signature = self.signature()
        if signature != self._signature:
            self._signature = signature
            self.touch("step")

    def clear(self) -> None:
        """Forget every message waiting (a test's reset)."""
        for peer in list(self.outbox):
            self.drop(peer)
