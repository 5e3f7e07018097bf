"""Sending: the next message from an agent's outbox into a receiver's mailbox.

``bidding.send`` puts the next message waiting for one peer into that peer's mailbox
(a channel place) as a token; ``bidding.cast`` puts a whole broadcast into all its
receivers' mailboxes in one firing. Each is recorded as a ``bidding.sent`` event.
"""

from __future__ import annotations

from petriflow.agents.bidding.correspondent import Correspondent
from petriflow.agents.bidding.protocol import token
from petriflow.runtime.channel_models import Message
from petriflow.runtime.action import ActionContext, ActionFailure, InstantAction, Param

__all__ = ["Send", "Cast", "post"]


class Send(InstantAction):
    """Any agent: the next message waiting for ``peer`` into its mailbox. (Only the
    outbox changes: the guards reading ``outbox/<peer>`` and ``pending`` are asked again,
    not the agent's step guards.)"""

    agent_state = Correspondent
    params = {"peer": Param(str, doc="the receiving agent"),
              "box": Param(str, doc="its mailbox (channel place)", places="")}

    def run(self, ctx: ActionContext) -> None:
        message = ctx.state.take(self.params["peer"])
        if message is None:
            raise ActionFailure(f"bidding.send: nothing waits for {self.params['peer']!r}")
        post(ctx, self.params["box"], message)


def post(ctx: ActionContext, box: str, message: Message) -> None:
    """Put ``message`` into the mailbox ``box`` as a token and record it as sent."""
    data = token(message)
    ctx.put(box, data)
    ctx.emit("bidding.sent", message=message.kind.value, to=message.receiver, bytes=data["size"],
             broadcast=message.data.cast)


class Cast(InstantAction):
    """Any agent: a broadcast to exactly the agents of ``boxes`` into all their
    mailboxes in one firing, once every copy of it is first in its receiver's queue
    (``bidding.has_cast``). Each copy is put and recorded as :class:`Send` does."""

    agent_state = Correspondent
    params = {"boxes": Param(dict, doc="receiving agent -> its mailbox (channel place)", places="*")}

    def run(self, ctx: ActionContext) -> None:
        boxes = self.params["boxes"]
        messages = ctx.state.take_cast(frozenset(boxes))
        if not messages:
            raise ActionFailure(f"bidding.cast: no broadcast to {', '.join(sorted(boxes))} is ready")
        for message in messages:
            post(ctx, boxes[message.receiver], message)

