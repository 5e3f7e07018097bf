"""The messages of seed 004's agents (§3.3) and the mailboxes that hold them.

Ten kinds: the operator's ``REQUEST`` and ``INFORM`` to the interface agent (HMIA);
``INITIALIZE`` (HMIA to each robot agent, RA) and ``INITIALIZED`` back; ``CFP`` (HMIA
offers a zone to every RA), ``PROPOSE`` (an RA's cost, to every other bidder) and
``ALLOCATED`` (the winner tells the HMIA); ``INFORM`` (random deployment: the
operator's zone list for an RA); ``MAP`` (start mapping), ``MAPPED`` (an RA's world
points) and ``END``. Every message is one token through a channel place, so the run's
trace counts them (``core.messages``) and the ``bidding.messages`` metric counts them
per kind.

A message's size is what it would take on a wire: a 4-byte header (kind, sender,
receiver, zone) plus its body (a cost or a position is 8 bytes, a world point two
32-bit floats).

Examples:
    >>> box = Mailbox()
    >>> box.queue(Message("CFP", "hmia", "robot1", zone=2))
    >>> box.has_for("robot1"), box.has_for("robot2")
    (True, False)
    >>> box.take("robot1").size
    4
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from petriflow.agents.bidding.errors import BiddingError

__all__ = ["KINDS", "Mailbox", "Message"]

KINDS = ("REQUEST", "INFORM", "INITIALIZE", "INITIALIZED", "CFP", "PROPOSE", "ALLOCATED", "MAP", "MAPPED", "END")


@dataclass
class Message:
    """One protocol message.

    Attributes:
        kind: one of :data:`KINDS`.
        sender, receiver: agent names.
        zone: the zone it is about (CFP, PROPOSE, ALLOCATED), else ``None``.
        body: anything else (a cost, a position, a zone list, world points).
        cast: the broadcast this is one copy of (``None``: a message to one agent).
            A broadcast (CFP, PROPOSE, MAP, END: "to all the RAs") is one message on
            the network, delivered to every mailbox.
    """

    kind: str
    sender: str
    receiver: str
    zone: int | None = None
    body: dict[str, Any] = field(default_factory=dict)
    cast: int | None = None

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise BiddingError(f"unknown message kind {self.kind!r} (one of {', '.join(KINDS)})")

    @property
    def size(self) -> int:
        """Bytes on a wire: header plus body."""
        size = 4
        for value in self.body.values():
            if isinstance(value, np.ndarray):
                size += 4 * value.size
            elif isinstance(value, (list, tuple)):
                size += 8 * len(value)
            elif value is not None:
                size += 8
        return size

    def token(self) -> dict[str, Any]:
        """The token data carrying it through a channel place."""
        return {"kind": self.kind, "size": self.size, "message": self}


class Mailbox:
    """Messages waiting to be sent, per receiver (oldest first), and those received."""

    def __init__(self) -> None:
        self.casts = 0
        self.outbox: dict[str, deque[Message]] = {}
        self.sent: dict[str, int] = {}
        self.received: dict[str, int] = {}

    def to_token(self) -> dict[str, Any]:
        """What a trace records of an agent's state: who it is and its message counts."""
        return {"agent": getattr(self, "name", type(self).__name__), "casts": self.casts,
                "sent": sum(self.sent.values()), "received": sum(self.received.values())}

    def queue(self, message: Message) -> None:
        self.outbox.setdefault(message.receiver, deque()).append(message)

    def broadcast(self, kind: str, sender: str, receivers: list[str], zone: int | None = None,
                  body: dict[str, Any] | None = None) -> None:
        """Queue one broadcast: a copy for each receiver, all with the same ``cast``."""
        self.casts += 1
        for receiver in receivers:
            self.queue(Message(kind, sender, receiver, zone, dict(body or {}), self.casts))

    def has_for(self, peer: str) -> bool:
        box = self.outbox.get(peer)
        return bool(box)

    def pending(self) -> bool:
        return any(self.outbox.values())

    def take(self, peer: str) -> Message | None:
        box = self.outbox.get(peer)
        if not box:
            return None
        message = box.popleft()
        self.sent[message.kind] = self.sent.get(message.kind, 0) + 1
        return message

    def drop(self, peer: str) -> int:
        """Forget what waits for ``peer`` (it stopped); how many were dropped."""
        box = self.outbox.pop(peer, None)
        return len(box) if box else 0
