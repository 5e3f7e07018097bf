"""The messages of the bidding mission (§3.3): their kinds and their payload.

Ten kinds (:class:`Kind`): the operator's ``REQUEST`` and ``INFORM`` to the interface
agent (HMIA); ``INITIALIZE`` (HMIA to each robot agent, RA) and ``INITIALIZED`` back;
``CFP`` (HMIA offers a zone to every RA), ``PROPOSE`` (an RA's cost, to every other
bidder) and ``ALLOCATED`` (the winner tells the HMIA); ``INFORM`` (random deployment:
the operator's zone list for an RA); ``MAP`` (start mapping), ``MAPPED`` (an RA's world
points) and ``END``.

A bidding message is the runtime's one message type
(:class:`petriflow.runtime.channel_models.Message`: sender, receiver, data) carrying a
:class:`Payload` (what it says: its kind, the zone, the body) as its ``data``. An agent
queues it in its outbox (:mod:`~petriflow.agents.bidding.correspondent`) and sends it
as the data of one token through the receiver's mailbox, a channel place
(:meth:`token`), so the run's trace counts them (``core.messages``) and the
``bidding.messages`` metric counts them per kind.

A payload's size is what it would take on a wire: a 4-byte header (kind, sender,
receiver, zone) plus its body (a number is 8 bytes, a list or tuple 8 per item, a
world point two 32-bit floats).

Examples:
    >>> from petriflow.runtime.channel_models import Message
    >>> cfp = Payload(Kind.CFP, zone=2, body={"position": (1.0, 2.0)})
    >>> cfp.kind is Kind.CFP, cfp.size
    (True, 20)
    >>> message = Message(None, "hmia", "robot1", cfp)
    >>> message.kind, message.size, token(message)["kind"]
    (<Kind.CFP: 'CFP'>, 20, 'CFP')
    >>> Payload("HELLO")
    Traceback (most recent call last):
    ...
    petriflow.agents.bidding.errors.BiddingError: unknown message kind 'HELLO' (one of REQUEST, INFORM, INITIALIZE, INITIALIZED, CFP, PROPOSE, ALLOCATED, MAP, MAPPED, END)
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from petriflow.agents.bidding.errors import BiddingError
from petriflow.outcome import Name
from petriflow.runtime.channel_models import Message

__all__ = ["Kind", "KINDS", "Payload", "token"]


class Kind(Name):
    """What a bidding message says (its text is what traces and metrics record)."""

    REQUEST = "REQUEST"
    INFORM = "INFORM"
    INITIALIZE = "INITIALIZE"
    INITIALIZED = "INITIALIZED"
    CFP = "CFP"
    PROPOSE = "PROPOSE"
    ALLOCATED = "ALLOCATED"
    MAP = "MAP"
    MAPPED = "MAPPED"
    END = "END"


#: The ten kinds, in protocol order.
KINDS = tuple(Kind)

#: Body keys the simulator adds for scoring only (which returns were off teammates, for
#: eq. 10): nothing a robot knows, nothing on a wire (not in :attr:`Payload.size`).
SCORING = ("real",)


@dataclass(frozen=True, eq=False)
class Payload:
    """What one bidding message says (never changed once made): the ``data`` of a
    :class:`~petriflow.runtime.channel_models.Message`, which names its sender and
    receiver.

    Attributes:
        kind: a :class:`Kind` (its text is accepted).
        zone: the zone it is about (CFP, PROPOSE, ALLOCATED), else ``None``.
        body: anything else (a cost, a position, a zone list, world points).
        cast: the broadcast this is one copy of (``None``: a message to one agent).
            A broadcast (CFP, PROPOSE, MAP, END: "to all the RAs") is one message on
            the network, delivered to every mailbox.
    """

    kind: Kind
    zone: int | None = None
    body: dict[str, Any] = field(default_factory=dict)
    cast: int | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.kind, Kind):
            try:
                object.__setattr__(self, "kind", Kind(self.kind))
            except ValueError:
                raise BiddingError(f"unknown message kind {self.kind!r} (one of {', '.join(KINDS)})") from None

    @property
    def size(self) -> int:
        """Bytes on a wire: header plus body."""
        size = 4
        for key, value in self.body.items():
            if key in SCORING:
                continue
            if isinstance(value, np.ndarray):
                size += 4 * value.size
            elif isinstance(value, (list, tuple)):
                size += 8 * len(value)
            elif value is not None:
                size += 8
        return size


def token(message: Message) -> dict[str, Any]:
    """The token data carrying ``message`` (a bidding payload's) through a mailbox."""
    return {"kind": message.kind.value, "size": message.size, "message": message}
