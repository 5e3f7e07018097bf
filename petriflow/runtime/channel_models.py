"""Channel models: what becomes of a message put into a channel place.

A place with ``channel: NAME`` stands for messages between agents; the run configuration
gives each channel a model (``channels: {radio: {model: range, ...}}``), which decides,
for each :class:`Message`, whether it arrives and after how long. Models are plain
classes with one method, so scenarios can bring their own:

* :class:`IdealChannel`: every message arrives after a fixed latency;
* :class:`RangeChannel`: radio with a log-distance path-loss model; a message is
  lost when the receiver's RSSI is below a threshold (or by a loss probability);
* :class:`BusChannel`: a shared bus (RS-485, CAN, ZigBee) carrying one frame at a
  time: transmission takes ``bits / baud`` seconds and frames queue behind each other
  (or collide and are lost, on a bus without arbitration).

A model that must see messages sent after it decided (a contended medium) is a
:class:`~petriflow.runtime.media.Medium` instead. The run's component that asks the
models and schedules the deliveries is :class:`~petriflow.runtime.channels.Channels`.

Examples:
    >>> model = RangeChannel(tx_power_dbm=-30.0, exponent=2.0, threshold_dbm=-63.4375)
    >>> round(model.rssi(2.0), 2)
    -36.02
    >>> round(model.range(), 1)  # metres at which the RSSI falls to the threshold
    47.0
    >>> build_channel("radio", {"model": "ideal", "latency": 0.5}).latency
    0.5
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, is_dataclass
from typing import Any, Callable

from petriflow.errors import NetFormatError, did_you_mean
from petriflow.outcome import Name

__all__ = ["Message", "payload_size", "Fate", "ChannelModel", "IdealChannel", "RangeChannel", "BusChannel",
           "CHANNEL_MODELS", "build_channel"]


class Fate(Name):
    """What became of a message (the ``fate`` of a ``message`` event)."""

    SENT = "sent"
    DELIVERED = "delivered"
    LOST = "lost"
    NOTICED = "noticed"  # a loss notice reached the place (``on_loss: notify``)


@dataclass
class Message:
    """A message between agents: the one message type of petriflow.

    The run makes one for every token put into a channel place (the channel model and
    the ``message`` trace event see it); a scenario's agents use the same type for
    what they queue, send and receive outside places (an outbox, a medium's frames).

    **A scenario adds a payload type, not a message class.** What a message says is its
    ``data``: a frozen dataclass of the scenario's (a header, a bid, a map update), with

    * ``size`` (an attribute or property, bytes on a wire): what :func:`payload_size`
      counts and the channel models time and lose (else 16 bytes);
    * ``kind`` (a member of a :class:`~petriflow.outcome.Name` enum of the scenario's
      message kinds): what :attr:`kind` reads, so handlers dispatch on the enum and a
      trace writes its text.

    Examples:
        >>> from dataclasses import dataclass
        >>> from petriflow.outcome import Name
        >>> class Kind(Name):
        ...     HELLO = "HELLO"
        >>> @dataclass(frozen=True)
        ... class Hello:
        ...     kind = Kind.HELLO
        ...     size = 4
        >>> message = Message(None, "a", "b", Hello())
        >>> message.kind, message.kind == "HELLO", message.size
        (<Kind.HELLO: 'HELLO'>, True, 4)

    Attributes:
        place: the channel place it travels through (``None``: not a place's token).
        sender: agent that sent it (for a place, the agent of the transition that
            produced the token), or ``None``.
        receiver: agent it is for (for a place, the agent that consumes from it), or ``None``.
        data: the payload (a token's data, for a place).
        time: simulated send time.
        size: payload size in bytes (default: :func:`payload_size` of ``data``).
        distance: sender-receiver distance in metres, when the world knows both.
    """

    place: str | None
    sender: str | None
    receiver: str | None
    data: Any
    time: float = 0.0
    size: int = -1
    distance: float | None = None

    def __post_init__(self) -> None:
        if self.size < 0:
            self.size = payload_size(self.data)

    @property
    def kind(self) -> Any:
        """The payload's kind: its ``kind`` attribute or key, else ``None``."""
        if isinstance(self.data, dict):
            return self.data.get("kind")
        return getattr(self.data, "kind", None)


def payload_size(data: Any) -> int:
    """Bytes a message of payload ``data`` counts: its ``size`` (attribute or key, a
    whole number > 0), else 16.

    Examples:
        >>> payload_size({"size": 9}), payload_size(b"xy"), payload_size([1, 2]), payload_size(None)
        (9, 16, 16, 16)
    """
    if isinstance(data, dict):
        size = data.get("size")
        return size if isinstance(size, int) and not isinstance(size, bool) and size > 0 else 16
    if isinstance(data, list):
        return 16
    size = getattr(data, "size", 0)
    return int(size) if isinstance(size, (int, float)) and not isinstance(size, bool) and size > 0 else 16


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
