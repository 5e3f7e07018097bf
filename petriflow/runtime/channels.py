"""Communication between agents: channel places and pluggable delivery models.

A place with ``channel: NAME`` stands for messages between agents. When a transition
puts a token there, the run's channel model for ``NAME`` decides whether the message
arrives and after how long; the token appears in the place only on delivery.
:class:`Channels` is the run's component that does this: it asks the model, records
the message's fate, and schedules a :class:`Delivery` event on the run's kernel.

The sender is the agent of the transition that produced the token; the receiver is
the agent of the transitions that consume from the place (when they all belong to
one agent), else the agent of the place's own subnet.

Models are plain classes with one method, so scenarios can bring their own:

* :class:`IdealChannel`: every message arrives after a fixed latency;
* :class:`RangeChannel`: radio with a log-distance path-loss model; a message is
  lost when the receiver's RSSI is below a threshold (or by a loss probability);
* :class:`BusChannel`: a shared bus (RS-485, CAN, ZigBee) carrying one frame at a
  time: transmission takes ``bits / baud`` seconds and frames queue behind each other
  (or collide and are lost, on a bus without arbitration).

Examples:
    >>> model = RangeChannel(tx_power_dbm=-30.0, exponent=2.0, threshold_dbm=-63.4375)
    >>> round(model.rssi(2.0), 2)
    -36.02
    >>> round(model.range(), 1)  # metres at which the RSSI falls to the threshold
    47.0
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field, fields, is_dataclass
from typing import Any, Callable

from petriflow.errors import NetFormatError, PetriflowError, did_you_mean
from petriflow.net import Net
from petriflow.outcome import Name
from petriflow.runtime.kernel import APPLY, Scheduled

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
    "receivers",
]


class Fate(Name):
    """What became of a message (the ``fate`` of a ``message`` event)."""

    SENT = "sent"
    DELIVERED = "delivered"
    LOST = "lost"
    NOTICED = "noticed"  # a loss notice reached the place (``on_loss: notify``)


@dataclass
class Message:
    """A token travelling through a channel place.

    Attributes:
        place: the channel place.
        sender: agent of the transition that produced the token (or ``None``).
        receiver: agent that consumes from the place (or ``None``).
        data: the token's data.
        time: simulated send time.
        size: payload size in bytes (from the token data's ``size`` if any).
        distance: sender-receiver distance in metres, when the world knows both.
    """

    place: str
    sender: str | None
    receiver: str | None
    data: Any
    time: float
    size: int = 16
    distance: float | None = None


class ChannelModel:
    """Decides the fate of each message: a delay in seconds, or ``None`` for lost.

    A model may say why it lost a message in ``loss_reason`` (read right after
    :meth:`deliver` returned ``None``; default "channel model").

    ``on_loss`` (set from the run configuration, every model has it) says what a lost
    message leaves behind: ``drop`` (nothing, the default) or ``notify`` (a loss notice,
    a token ``{"lost": True, "why": ..., "data": <the message's data>}`` in the channel
    place at once, as a receiver that sees a garbled frame or a sender's timeout would
    learn of it; a net whose channel places are bounded by slot tokens stays live).
    """

    on_loss = "drop"
    #: Whether :meth:`deliver` reads ``message.distance`` (the sender-receiver distance,
    #: from the world's poses); a model that does not spares the run those lookups.
    needs_distance = True

    def deliver(self, message: Message, rng: Any) -> float | None:
        raise NotImplementedError


@dataclass
class IdealChannel(ChannelModel):
    """Lossless channel with a fixed latency (seconds)."""

    latency: float = field(default=0.0, metadata={"range": (0.0, 3600.0)})
    needs_distance = False

    def deliver(self, message: Message, rng: Any) -> float | None:
        return self.latency


@dataclass
class RangeChannel(ChannelModel):
    """Radio link with log-distance path loss.

    RSSI(d) = tx_power_dbm - 10 * exponent * log10(d / 1 m). A message is lost when
    the RSSI at the sender-receiver distance is below ``threshold_dbm``, and otherwise
    with probability ``loss``. Without a known distance the link counts as in range.
    """

    tx_power_dbm: float = field(default=-30.0, metadata={"range": (-300.0, 300.0)})
    exponent: float = field(default=2.0, metadata={"range": (0.1, 10.0)})
    threshold_dbm: float = field(default=-63.4375, metadata={"range": (-300.0, 300.0)})
    loss: float = field(default=0.0, metadata={"range": (0.0, 1.0)})
    latency: float = field(default=0.005, metadata={"range": (0.0, 3600.0)})
    bitrate: float = field(default=1e6, metadata={"range": (1e-3, 1e15)})

    def _path(self) -> Any:
        from petriflow.runtime.radio import LogDistance

        return LogDistance(self.tx_power_dbm, 0.0, self.exponent, min_distance=0.01)

    def rssi(self, distance: float) -> float:
        """Received signal strength at ``distance`` metres (dBm)."""
        return self._path().rssi(distance)

    def range(self) -> float:
        """Distance in metres at which the RSSI reaches the threshold."""
        return self._path().range(self.threshold_dbm)

    def deliver(self, message: Message, rng: Any) -> float | None:
        if message.distance is not None and self.rssi(message.distance) < self.threshold_dbm:
            return None
        if self.loss and rng.random() < self.loss:
            return None
        return self.latency + 8.0 * message.size / self.bitrate


@dataclass
class BusChannel(ChannelModel):
    """A shared bus that carries one frame at a time.

    Args:
        baud: bits per second.
        overhead_bits: framing bits added to each payload.
        arbitration: with arbitration (CAN) frames wait for the bus; without it
            (a plain RS-485 line, a radio), a frame sent while another is on the bus
            collides and is lost (the frame already on the bus gets through).
        loss: extra loss probability per frame (a lossy radio such as ZigBee).
    """

    baud: float = field(default=115200.0, metadata={"range": (1e-3, 1e15)})
    overhead_bits: int = field(default=20, metadata={"range": (0, 1_000_000)})
    arbitration: bool = True
    loss: float = field(default=0.0, metadata={"range": (0.0, 1.0)})
    needs_distance = False

    def __post_init__(self) -> None:
        self._busy_until = -math.inf

    def deliver(self, message: Message, rng: Any) -> float | None:
        duration = (8 * message.size + self.overhead_bits) / self.baud
        if message.time < self._busy_until:
            if not self.arbitration:
                return None  # the late frame is garbled; the frame on the bus gets through
            start = self._busy_until
        else:
            start = message.time
        self._busy_until = start + duration
        if self.loss and rng.random() < self.loss:
            return None
        return start + duration - message.time


#: Built-in channel models by name (``channels: {radio: {model: range, ...}}``).
CHANNEL_MODELS: dict[str, Callable[..., ChannelModel]] = {
    "ideal": IdealChannel,
    "range": RangeChannel,
    "bus": BusChannel,
}


def build_channel(name: str, spec: dict[str, Any], where: str = "channels", registry: Any = None) -> ChannelModel:
    """Make a channel model from its run-configuration entry.

    Raises:
        NetFormatError: unknown model or parameter, naming the channel.
    """
    spec = dict(spec)
    model = spec.pop("model", "ideal")
    given = "on_loss" in spec  # written in the configuration: it overrides the model's own default
    on_loss = spec.pop("on_loss", "drop")
    if on_loss not in ("drop", "notify"):
        raise NetFormatError(f"on_loss is drop or notify, not {on_loss!r}", element=f"{where}.{name}")
    from petriflow.runtime.registry import default_registry

    registry = registry or default_registry
    cls = CHANNEL_MODELS.get(model) if isinstance(model, str) else None
    if cls is None and isinstance(model, str):
        cls = registry.channel_model(model)
    if cls is None:
        known = [*CHANNEL_MODELS, *registry.channel_names()]
        raise NetFormatError(
            f"unknown channel model {model!r}{did_you_mean(str(model), known)}"
            f" (one of {', '.join(known)})",
            element=f"{where}.{name}",
        )
    if is_dataclass(cls):
        _check_parameters(cls, model, spec, f"{where}.{name}")
    try:
        built = cls(**spec)
    except (TypeError, ValueError) as exc:
        raise NetFormatError(f"bad parameters for channel model {model!r}: {exc}",
                             element=f"{where}.{name}") from None
    if given:
        built.on_loss = on_loss
    return built


def _check_parameters(cls: type, model: str, spec: dict[str, Any], element: str) -> None:
    """Parameters of a dataclass model: known names, the declared type (a bool is not a
    number), finite numbers within a field's ``metadata["range"]``."""
    declared = {f.name: f for f in fields(cls) if f.init}
    for key, value in spec.items():
        if key not in declared:
            raise NetFormatError(f"channel model {model!r} has no parameter {key!r}{did_you_mean(str(key), declared)}"
                                 f" (it takes {', '.join(declared) or 'none'})", element=element)
        kind = declared[key].type if isinstance(declared[key].type, str) else declared[key].type.__name__
        if kind == "bool":
            if not isinstance(value, bool):
                raise NetFormatError(f"{key} must be true or false, got {value!r}", element=element)
            continue
        if kind not in ("float", "int"):
            continue
        whole = kind == "int"
        if isinstance(value, bool) or not isinstance(value, int if whole else (int, float)) \
                or not math.isfinite(value):
            raise NetFormatError(f"{key} must be a {'whole' if whole else 'finite'} number, got {value!r}",
                                 element=element)
        low, high = declared[key].metadata.get("range", (-math.inf, math.inf))
        if not low <= value <= high:
            raise NetFormatError(f"{key} must be from {low:g} to {high:g}, got {value!r}", element=element)


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


def _size(data: Any) -> int:
    """Bytes a message counts: the data's ``size`` (attribute or key), else 16."""
    if isinstance(data, dict):
        size = data.get("size")
        return size if isinstance(size, int) and not isinstance(size, bool) and size > 0 else 16
    if isinstance(data, list):
        return 16
    size = getattr(data, "size", 0)
    return int(size) if isinstance(size, (int, float)) and size > 0 else 16


class Channels:
    """A run's channel places: every token put into one is a message that a model
    delivers after a delay, or loses.

    Args:
        run: the run (:class:`~petriflow.runtime.host.RunHost`: its ``net``,
            ``kernel``, ``world``, ``faults``, ``emit`` and ``deliver``).
        models: ``{channel name: ChannelModel}``; a channel with none is ideal.
        seed: the run seed (losses are drawn from a generator of their own).
    """

    def __init__(self, run: Any, models: dict[str, ChannelModel], seed: Any) -> None:
        self.run = run
        self.models = dict(models)
        self.rng = random.Random(f"{seed}:channels")
        self.receiver = receivers(run.net)
        self.channel = {p.id: p.channel for p in run.net.places.values() if p.channel is not None}
        from petriflow.runtime.media import Medium, MediumPort, ProcessClock

        for name, model in self.models.items():
            bind = getattr(model, "bind", None)
            if callable(bind):  # a model that measures the world (walls between agents...)
                bind(getattr(run, "world", None))
            if isinstance(model, Medium):  # a process on the run's kernel
                model.attach(MediumPort(ProcessClock(run.kernel), self._delivered, self._lost,
                                        random.Random(f"{seed}:medium:{name}"), getattr(run, "world", None)))

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
        run = self.run
        channel = self.channel[place]
        receiver = self.receiver[place]
        model, _ = self.model_for(place)
        distance = None  # asked of the world only for a model that reads it or a listener of the event
        world = run.world
        wanted = getattr(model, "needs_distance", True) or run.recorder.wants("message")
        if wanted and sender and receiver and hasattr(world, "distance"):
            distance = world.distance(sender, receiver)
        now = run.kernel.now
        message = Message(place, sender, receiver, data, now, _size(data), distance)
        faults = run.faults
        if faults.link_down(sender, receiver):
            delay, why = None, "link down"
        elif receiver is not None and not faults.alive(receiver):
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
            run.emit("message", None, sender, fate=Fate.LOST.value, why=why, **info)
            self._notice(model, place, data, sender, receiver, why, now)
            return
        if delay is _PROCESS:  # a medium decides the fate when it happens
            run.emit("message", None, sender, fate=Fate.SENT.value, **info)
            model.send(message)
            return
        kernel = run.kernel
        arrival = kernel.ticks_at(now + delay)
        run.emit("message", None, sender, fate=Fate.SENT.value, arrival=round(arrival * kernel.dt, 9), **info)
        kernel.schedule(arrival, Delivery(self, place, data, sender, message=message))

    def _notice(self, model: ChannelModel, place: str, data: Any, sender: str | None, receiver: str | None,
                why: str, now: float) -> None:
        """With ``on_loss: notify``, a loss notice for a lost message, at once."""
        if getattr(model, "on_loss", "drop") == "notify" and (receiver is None or self.run.faults.alive(receiver)):
            notice = {"lost": True, "why": why, "data": data}
            self.run.kernel.schedule(self.run.kernel.ticks_at(now), Delivery(self, place, notice, sender, notice=True))

    def _delivered(self, message: Message) -> None:
        """A medium delivers ``message`` now: its token appears in its channel place."""
        self.run.deliver(message.place, message.data)
        self.run.emit("message", None, message.sender, fate=Fate.DELIVERED.value, place=message.place,
                      channel=self.channel[message.place])

    def _lost(self, message: Message, why: str) -> None:
        """A medium lost ``message`` now (``why``: the reason it gives). The event says
        ``in_flight``: the message was recorded ``sent`` when it was put in, so it counts
        once as sent."""
        model, receiver = self.model_for(message.place)
        self.run.emit("message", None, message.sender, fate=Fate.LOST.value, why=str(why), place=message.place,
                      channel=self.channel[message.place], receiver=receiver, size=message.size,
                      in_flight=True)
        self._notice(model, message.place, message.data, message.sender, receiver, str(why), self.run.kernel.now)

    def view(self, place: str, agent: str | None) -> Any:
        """What the medium carrying ``place`` lets ``agent`` ask about it (see
        :meth:`petriflow.runtime.media.Medium.view`).

        Raises:
            PetriflowError: ``place`` is not a channel place, or its model is not a
                medium that offers a view.
        """
        model, _ = self.model_for(place)
        view = getattr(model, "view", None)
        if view is None:
            raise PetriflowError(f"channel place {place!r}: its {type(model).__name__} model offers nothing to ask")
        return view(agent)

    def arrive(self, delivery: Delivery) -> None:
        """A message reaches its place: the token appears there."""
        self.run.deliver(delivery.place, delivery.data)
        fate = Fate.NOTICED if delivery.notice else Fate.DELIVERED
        self.run.emit("message", None, delivery.sender, fate=fate.value, place=delivery.place,
                      channel=self.channel[delivery.place])
