"""Communication between agents: the run's channel places.

A place with ``channel: NAME`` stands for messages between agents. When a transition
puts a token there, the run's channel model for ``NAME``
(:mod:`petriflow.runtime.channel_models`, or a :class:`~petriflow.runtime.media.Medium`)
decides whether the message arrives and after how long; the token appears in the place
only on delivery. :class:`Channels` is the run's component that does this: it asks the
model, records the message's fate, and schedules a :class:`Delivery` event on the
run's kernel.

The sender is the agent of the transition that produced the token; the receiver is
the agent of the transitions that consume from the place (when they all belong to
one agent), else the agent of the place's own subnet.

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> from petriflow.runtime.kernel import Kernel
    >>> from petriflow.runtime.recorder import Recorder
    >>> pair = "{id: a, places: [{id: out, channel: radio}], transitions: [{id: send, out: [out]}]}"
    >>> net = loads_net(f"{{petriflow: 1, subnets: [{pair}, {{id: b, transitions: [{{id: take, in: [out]}}]}}]}}")
    >>> class Everyone:
    ...     def alive(self, agent): return True
    ...     def link_down(self, sender, receiver): return False
    >>> kernel, arrived = Kernel(dt=0.1), []
    >>> channels = Channels(net, {"radio": IdealChannel(latency=0.25)}, seed=0, kernel=kernel,
    ...                     recorder=Recorder(kernel), links=Everyone(), world=None,
    ...                     deliver=lambda place, data: arrived.append((place, data, kernel.now)))
    >>> channels.send("out", "hello", "a")
    >>> kernel.tick = kernel.peek(); kernel.run_due(); arrived
    [('out', 'hello', 0.30000000000000004)]
"""

from __future__ import annotations

import math
import random
from typing import Any, Callable, Protocol

from petriflow.capabilities import Distances, missing
from petriflow.errors import PetriflowError
from petriflow.net import Net
from petriflow.runtime.channel_models import (
    CHANNEL_MODELS,
    BusChannel,
    ChannelModel,
    Fate,
    IdealChannel,
    Message,
    RangeChannel,
    build_channel,
    payload_size,
)
from petriflow.runtime.kernel import APPLY, Kernel, Scheduled
from petriflow.runtime.media import Medium, MediumPort, ProcessClock
from petriflow.runtime.recorder import Recorder

__all__ = [
    "Message",
    "Fate",
    "ChannelModel",
    "IdealChannel",
    "RangeChannel",
    "BusChannel",
    "CHANNEL_MODELS",
    "build_channel",
    "Channels",
    "Delivery",
    "LinkState",
    "receivers",
]


def receivers(net: Net) -> dict[str, str | None]:
    """``{channel place: receiving agent}``: the agent of the transitions that take from
    the place when they all belong to one, else the agent of the place's subnet.

    Examples:
        >>> from petriflow.io.yaml import loads_net
        >>> net = loads_net('''
        ... petriflow: 1
        ... subnets:
        ...   - {id: a, places: [{id: out, channel: radio}], transitions: [{id: send, out: [out]}]}
        ...   - {id: b, transitions: [{id: take, in: [out]}]}
        ... ''')
        >>> receivers(net)
        {'out': 'b'}
    """
    agent_of = {s.id: s.agent or s.id for s in net.subnets.values()}
    found: dict[str, str | None] = {}
    for place in net.places.values():
        if place.channel is None:
            continue
        takers = {agent_of[net.transitions[t].subnet] if net.transitions[t].subnet else None
                  for t in net.place_postset(place.id)}
        takers.discard(None)
        if len(takers) == 1:
            found[place.id] = takers.pop()
        else:
            found[place.id] = agent_of.get(place.subnet) if place.subnet else None
    return found


#: What :meth:`Channels.send` uses for "a medium process decides" (not a delay).
_PROCESS = object()


class Delivery(Scheduled):
    """A message arrives in its channel place (scheduled by :meth:`Channels.send`)."""

    __slots__ = ("channels", "place", "data", "sender", "notice", "message")
    phase = APPLY

    def __init__(self, channels: "Channels", place: str, data: Any, sender: str | None,
                 notice: bool = False, message: Message | None = None) -> None:
        self.channels = channels
        self.place = place
        self.data = data
        self.sender = sender
        self.notice = notice
        self.message = message

    def apply(self, tick: int) -> None:
        self.channels.arrive(self)


class LinkState(Protocol):
    """Which agents run and which links work (the run's
    :class:`~petriflow.runtime.faults.Faults`), as :class:`Channels` asks."""

    def alive(self, agent: str | None) -> bool:
        """Whether ``agent`` runs now."""

    def link_down(self, sender: str | None, receiver: str | None) -> bool:
        """Whether messages between the two agents are being lost."""


class Channels:
    """A run's channel places: every token put into one is a message that a model
    delivers after a delay, or loses.

    Args:
        net: the net (its channel places, their receivers).
        models: ``{channel name: ChannelModel}``; a channel with none is ideal.
        seed: the run seed (losses are drawn from a generator of their own).
        kernel: the run's kernel (deliveries are scheduled on it).
        recorder: the run's events (each message's fate is one).
        links: which agents run and which links work.
        world: the run's world (distances between agents; ``None``: none).
        deliver: ``deliver(place, data)`` puts a delivered token into its place.
    """

    def __init__(self, net: Net, models: dict[str, ChannelModel], seed: Any, *, kernel: Kernel,
                 recorder: Recorder, links: LinkState, world: Any, deliver: Callable[[str, Any], None]) -> None:
        self.kernel = kernel
        self.recorder = recorder
        self.links = links
        self.world = world
        self.deliver = deliver
        self.models = dict(models)
        self.rng = random.Random(f"{seed}:channels")
        self.receiver = receivers(net)
        self.channel = {p.id: p.channel for p in net.places.values() if p.channel is not None}
        # a world that tells distances between agents (the core's World does): asked only
        # for a model that reads them, or a listener of message events
        self._distance = world.distance if world is not None and not missing(world, Distances) else None
        for name, model in self.models.items():
            bind = getattr(model, "bind", None)
            if callable(bind):  # a model that measures the world (walls between agents...)
                bind(world)
            if isinstance(model, Medium):  # a process on the run's kernel
                model.attach(MediumPort(ProcessClock(kernel), self._delivered, self._lost,
                                        random.Random(f"{seed}:medium:{name}"), world))

    def model_for(self, place: str) -> tuple[ChannelModel, str | None]:
        """The model carrying the channel place ``place`` and the agent receiving from it.

        Raises:
            PetriflowError: ``place`` is not a channel place.
        """
        channel = self.channel.get(place)
        if channel is None:
            raise PetriflowError(f"{place!r} is not a channel place")
        model = self.models.get(channel)
        if model is None:
            model = self.models[channel] = IdealChannel()
        return model, self.receiver[place]

    def send(self, place: str, data: Any, sender: str | None) -> None:
        """Put a message into ``place``: record it and schedule its delivery, or its loss."""
        channel = self.channel[place]
        receiver = self.receiver[place]
        model, _ = self.model_for(place)
        recorder, kernel = self.recorder, self.kernel
        distance = None  # asked of the world only for a model that reads it or a listener of the event
        wanted = getattr(model, "needs_distance", True) or recorder.wants("message", place=place, fate=Fate.SENT.value) \
            or recorder.wants("message", place=place, fate=Fate.LOST.value)
        if wanted and sender and receiver and self._distance is not None:
            distance = self._distance(sender, receiver)
        now = kernel.now
        message = Message(place, sender, receiver, data, now, payload_size(data), distance)
        links = self.links
        if links.link_down(sender, receiver):
            delay, why = None, "link down"
        elif receiver is not None and not links.alive(receiver):
            delay, why = None, "receiver not running"
        elif getattr(model, "process", False):
            delay, why = _PROCESS, ""
        else:
            delay = model.deliver(message, self.rng)
            why = str(getattr(model, "loss_reason", None) or "channel model") if delay is None else "channel model"
            if delay is not None and delay is not _PROCESS and (isinstance(delay, bool) or not isinstance(delay, (int, float))
                                      or not 0 <= delay < math.inf):
                raise PetriflowError(f"channel {channel!r}: model {type(model).__name__} gave a delay of {delay!r}"
                                     " (a finite number of seconds >= 0, or None for lost)")
        info: dict[str, Any] = {"place": place, "channel": channel, "receiver": receiver, "size": message.size}
        if distance is not None:
            info["distance"] = round(distance, 6)
        if delay is None:
            recorder.emit("message", None, sender, fate=Fate.LOST.value, why=why, **info)
            self._notice(model, place, data, sender, receiver, why, now)
            return
        if delay is _PROCESS:  # a medium decides the fate when it happens
            recorder.emit("message", None, sender, fate=Fate.SENT.value, **info)
            model.send(message)
            return
        arrival = kernel.ticks_at(now + delay)
        recorder.emit("message", None, sender, fate=Fate.SENT.value, arrival=round(arrival * kernel.dt, 9), **info)
        kernel.schedule(arrival, Delivery(self, place, data, sender, message=message))

    def _notice(self, model: ChannelModel, place: str, data: Any, sender: str | None, receiver: str | None,
                why: str, now: float) -> None:
        """With ``on_loss: notify``, a loss notice for a lost message, at once."""
        if getattr(model, "on_loss", "drop") == "notify" and (receiver is None or self.links.alive(receiver)):
            notice = {"lost": True, "why": why, "data": data}
            self.kernel.schedule(self.kernel.ticks_at(now), Delivery(self, place, notice, sender, notice=True))

    def _delivered(self, message: Message) -> None:
        """A medium delivers ``message`` now: its token appears in its channel place."""
        self.deliver(message.place, message.data)
        self.recorder.emit("message", None, message.sender, fate=Fate.DELIVERED.value, place=message.place,
                           channel=self.channel[message.place])

    def _lost(self, message: Message, why: str) -> None:
        """A medium lost ``message`` now (``why``: the reason it gives). The event says
        ``in_flight``: the message was recorded ``sent`` when it was put in, so it counts
        once as sent."""
        model, receiver = self.model_for(message.place)
        self.recorder.emit("message", None, message.sender, fate=Fate.LOST.value, why=str(why), place=message.place,
                           channel=self.channel[message.place], receiver=receiver, size=message.size,
                           in_flight=True)
        self._notice(model, message.place, message.data, message.sender, receiver, str(why), self.kernel.now)

    def view(self, place: str, agent: str | None) -> Any:
        """What the medium carrying ``place`` lets ``agent`` ask about it (see
        :meth:`petriflow.runtime.media.Medium.view`).

        Raises:
            PetriflowError: ``place`` is not a channel place, or its model is not a
                medium that offers a view.
        """
        model, _ = self.model_for(place)
        if not isinstance(model, Medium):
            raise PetriflowError(f"channel place {place!r}: its {type(model).__name__} model offers nothing to ask")
        return model.view(agent)

    def arrive(self, delivery: Delivery) -> None:
        """A message reaches its place: the token appears there."""
        self.deliver(delivery.place, delivery.data)
        fate = Fate.NOTICED if delivery.notice else Fate.DELIVERED
        self.recorder.emit("message", None, delivery.sender, fate=fate.value, place=delivery.place,
                           channel=self.channel[delivery.place])
