"""The ESP8266 link of the paper's Fig. 5, as a channel model (``slam.esp8266``).

What §4 measured: packets are lost when the RSSI falls below -64 dB (Fig. 5a), their
latency stays under 1.88 ms above -50 dB (Fig. 5b, 100 packets of 1024 bytes), and the
working range is 5 m (Fig. 5c); the simulation used an omnidirectional 5 m pattern with
no loss through obstacles. :class:`ESP8266` is the core's log-distance model
(:class:`petriflow.runtime.radio.LogDistance`) with exponent 2 (free space, as the
paper's simulation) and the power at 1 m that puts -64 dBm at 5 m: -50.02 dBm, which is
Fig. 5b's -50 dB at 1 m. Above ``threshold_dbm`` nothing is lost; below it a frame is
lost with a probability growing linearly to 1 over ``fade_db`` (Fig. 5a's curve is not
in our text: 10 dB is an assumption, 16 m in free space). A frame of ``n`` bytes takes
``ceil(n / 1024)`` packets of ``packet_ms``.

Frames travel in one shared place (the 2.4 GHz channel: one frame in the air at a
time); each frame says who sends it and to whom (``from``, ``to``), and the model finds
both in the world (RAs by their bodies, WAs by the boxes an RA put down). The central
unit of the centralised system has no body: a frame to it (or from it) goes through
the nearest of the pre-installed nodes (``meta.slam.nodes``) to the RA, then over the
nodes' backbone (``backbone_ms``), and is lost only on that first hop.

Examples:
    >>> radio = ESP8266()
    >>> round(radio.rssi(1.0), 2), round(radio.rssi(5.0), 2), round(radio.range(), 2), round(radio.reach(), 1)
    (-50.02, -64.0, 5.0, 15.8)
    >>> radio.loss(-63.0), radio.loss(-69.0), radio.loss(-80.0)
    (0.0, 0.5, 1.0)
    >>> round(radio.latency(300) * 1000, 2), round(radio.latency(3000) * 1000, 2)
    (1.88, 5.64)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from petriflow.agents.slam.corridors import SLAM

from petriflow.capabilities import Positions, provides
from petriflow.runtime.channels import ChannelModel, Message
from petriflow.runtime.radio import LogDistance, fade_loss, power_for_range
from petriflow.runtime.settings import world_section

__all__ = ["CENTRAL", "ESP8266", "Esp8266Link", "TX_AT_1M"]

#: The power at 1 m (dBm) that puts the loss threshold (-64 dBm) at 5 m with exponent 2.
TX_AT_1M = power_for_range(-64.0, 5.0, exponent=2.0)
#: The central unit's agent name (reached through the pre-installed nodes).
CENTRAL = "central"


@dataclass
class Esp8266Link:
    """The ESP8266's measured link (see the module): its power at 1 m, path-loss
    exponent and loss threshold, and its packets. The parameters every model of this
    radio shares: the SLAM channel (:class:`ESP8266`) and the swarm's broadcast medium
    (:class:`~petriflow.agents.swarm.radio.SwarmRadio`) add theirs."""

    tx_power_dbm: float = field(default=round(TX_AT_1M, 4), metadata={"range": (-200.0, 100.0)})
    exponent: float = field(default=2.0, metadata={"range": (0.5, 8.0)})
    threshold_dbm: float = field(default=-64.0, metadata={"range": (-200.0, 100.0)})
    packet_ms: float = field(default=1.88, metadata={"range": (0.0, 10_000.0)})
    packet_bytes: int = field(default=1024, metadata={"range": (1, 1_000_000)})

    def packets(self, size: int) -> int:
        """Packets a frame of ``size`` bytes takes (at least one)."""
        return max(1, math.ceil(size / self.packet_bytes))


@dataclass
class ESP8266(Esp8266Link, ChannelModel):
    """An ESP8266 Wi-Fi link (see the module)."""

    fade_db: float = field(default=10.0, metadata={"range": (0.0, 60.0)})
    backbone_ms: float = field(default=10.0, metadata={"range": (0.0, 10_000.0)})

    def __post_init__(self) -> None:
        self._path = LogDistance(self.tx_power_dbm, 0.0, self.exponent, min_distance=0.05)
        self._reach = self._path.range(self.threshold_dbm - self.fade_db)
        self.world: Any = None
        self.loss_reason = ""
        self._placed: Positions | None = None
        self._nodes: list[tuple[float, ...]] = []

    def bind(self, world: Any) -> None:
        """The run's world: where the agents are (when it places them), and the nodes of
        its ``meta.slam`` (:data:`~petriflow.agents.slam.corridors.SLAM`, checked)."""
        self.world = world
        self._placed = world if provides(world, Positions) else None
        self._nodes = [tuple(point) for point in world_section(world, SLAM)["nodes"]]

    # The link budget ----------------------------------------------------------------
    def rssi(self, distance: float) -> float:
        """Received power (dBm) at ``distance`` metres."""
        return self._path.rssi(distance)

    def range(self) -> float:
        """Metres up to which nothing is lost (-64 dBm: 5 m)."""
        return self._path.range(self.threshold_dbm)

    def reach(self) -> float:
        """Metres beyond which everything is lost."""
        return self._reach

    def loss(self, rssi: float) -> float:
        """Probability that a frame received at ``rssi`` is lost (the core's
        :func:`~petriflow.runtime.radio.fade_loss`, from the threshold down to the reach)."""
        return fade_loss(rssi, self.threshold_dbm - self.fade_db, self.fade_db)

    def latency(self, size: int) -> float:
        """Seconds a frame of ``size`` bytes takes."""
        return self.packets(size) * self.packet_ms / 1000.0

    # Positions ------------------------------------------------------------------------
    def position(self, name: str) -> tuple[float, float] | None:
        world = self._placed
        if world is None:
            return None
        try:
            return world.position(name)
        except Exception:  # not a body of this world
            return None

    def nodes(self) -> list[tuple[float, float]]:
        return list(self._nodes)

    def link(self, a: str, b: str) -> tuple[float, bool] | None:
        """``(RSSI, through the backbone)`` of a frame between agents ``a`` and ``b``, or
        ``None`` when the world does not place them."""
        if CENTRAL in (a, b):
            other = self.position(b if a == CENTRAL else a)
            nodes = self.nodes()
            if other is None or not nodes:
                return None
            return self.rssi(min(math.dist(other, n) for n in nodes)), True
        pa, pb = self.position(a), self.position(b)
        if pa is None or pb is None:
            return None
        return self.rssi(math.dist(pa, pb)), False

    def deliver(self, message: Message, rng: Any) -> float | None:
        data = message.data if isinstance(message.data, dict) else {}
        sender, receiver = data.get("from"), data.get("to")
        if not sender or not receiver:
            return self.latency(message.size)
        link = self.link(str(sender), str(receiver))
        if link is None:
            return self.latency(message.size)
        rssi, backbone = link
        p = self.loss(rssi)
        if p >= 1.0:
            self.loss_reason = f"out of reach ({rssi:.1f} dBm)"
            return None
        if p > 0 and rng.random() < p:
            self.loss_reason = f"faded ({rssi:.1f} dBm)"
            return None
        return self.latency(message.size) + (self.backbone_ms / 1000.0 if backbone else 0.0)
