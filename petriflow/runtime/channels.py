"""Communication between agents: channel places and pluggable delivery models.

A place with ``channel: NAME`` stands for messages between agents. When a transition
puts a token there, the run's channel model for ``NAME`` decides whether the message
arrives and after how long; the token appears in the place only on delivery. Models
are plain classes with one method, so scenarios can bring their own:

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
from dataclasses import dataclass
from typing import Any, Callable

from petriflow.errors import NetFormatError, did_you_mean

__all__ = [
    "Message",
    "ChannelModel",
    "IdealChannel",
    "RangeChannel",
    "BusChannel",
    "CHANNEL_MODELS",
    "build_channel",
]


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
    """Decides the fate of each message: a delay in seconds, or ``None`` for lost."""

    def deliver(self, message: Message, rng: Any) -> float | None:
        raise NotImplementedError


@dataclass
class IdealChannel(ChannelModel):
    """Lossless channel with a fixed latency (seconds)."""

    latency: float = 0.0

    def deliver(self, message: Message, rng: Any) -> float | None:
        return self.latency


@dataclass
class RangeChannel(ChannelModel):
    """Radio link with log-distance path loss.

    RSSI(d) = tx_power_dbm - 10 * exponent * log10(d / 1 m). A message is lost when
    the RSSI at the sender-receiver distance is below ``threshold_dbm``, and otherwise
    with probability ``loss``. Without a known distance the link counts as in range.
    """

    tx_power_dbm: float = -30.0
    exponent: float = 2.0
    threshold_dbm: float = -63.4375
    loss: float = 0.0
    latency: float = 0.005
    bitrate: float = 1e6

    def rssi(self, distance: float) -> float:
        """Received signal strength at ``distance`` metres (dBm)."""
        return self.tx_power_dbm - 10.0 * self.exponent * math.log10(max(distance, 0.01))

    def range(self) -> float:
        """Distance in metres at which the RSSI reaches the threshold."""
        return round(10 ** ((self.tx_power_dbm - self.threshold_dbm) / (10.0 * self.exponent)), 6)

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

    baud: float = 115200.0
    overhead_bits: int = 20
    arbitration: bool = True
    loss: float = 0.0

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


def build_channel(name: str, spec: dict[str, Any], where: str = "channels") -> ChannelModel:
    """Make a channel model from its run-configuration entry.

    Raises:
        NetFormatError: unknown model or parameter, naming the channel.
    """
    spec = dict(spec)
    model = spec.pop("model", "ideal")
    if model not in CHANNEL_MODELS:
        raise NetFormatError(
            f"unknown channel model {model!r}{did_you_mean(str(model), CHANNEL_MODELS)}"
            f" (one of {', '.join(CHANNEL_MODELS)})",
            element=f"{where}.{name}",
        )
    try:
        return CHANNEL_MODELS[model](**spec)
    except TypeError as exc:
        raise NetFormatError(f"bad parameters for channel model {model!r}: {exc}",
                             element=f"{where}.{name}") from None
