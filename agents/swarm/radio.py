"""The swarm's radio as a medium (channel model ``swarm.radio``): broadcast frames to
the robots that hear the sender, found by a spatial index.

Every robot has one channel place, its radio (``air``). A frame a robot puts there is a
broadcast: it holds packets for some of the neighbours the robot heard. The medium
finds who hears the sender *now* with the core's :class:`~petriflow.runtime.radio.RadioIndex`
(a k-d tree of the robots' positions, built once per tick however many robots ask;
walls counted by batched rays only for the candidates in range; the log-distance
RSSI through them against the threshold), puts each addressed neighbour's packets in
that neighbour's **receive buffer** (its radio's; at most ``buffer`` packets: the
oldest goes when it is full, recorded as lost), and, when the frame's airtime is over,
gives the frame back into the sender's radio place as the transmission's end (with
the number of robots that heard it): so the net sees one token go out and come back,
and a robot reads what its radio received through the medium's view
(``ctx.medium(place).take()``), as an ESP8266 program reads its Wi-Fi buffer.

Parameters (the README gives each one's source): the ESP8266 link of seed 001
(-64 dBm threshold at 5 m with exponent 2, so -50.02 dBm at 1 m; 1,024-byte packets of
1.88 ms) and seed 000's 3 dB per wall.

Examples:
    >>> radio = SwarmRadio()
    >>> round(radio.index().radius, 2), radio.airtime(1500)
    (5.0, 0.00376)
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field
from typing import Any

from petriflow.capabilities import PoseArrays, provides
from petriflow.runtime.channels import Message
from petriflow.runtime.media import Medium, MediumPort
from petriflow.runtime.radio import LogDistance, RadioIndex

__all__ = ["SwarmRadio", "RadioView"]

#: The power at 1 m that puts the ESP8266's -64 dBm threshold at 5 m (exponent 2).
TX_AT_1M = round(-64.0 + 20.0 * math.log10(5.0), 4)


class RadioView:
    """What one robot's actions see of the radio: who it hears now, and its buffer."""

    def __init__(self, radio: "SwarmRadio", agent: str) -> None:
        self.radio = radio
        self.agent = agent

    def address(self) -> int:
        """This robot's radio address (1, 2, ...: the robot's place among the world's)."""
        return self.radio.rows[self.agent] + 1

    def neighbours(self) -> list[tuple[str, int]]:
        """The robots that hear this one now (and that it hears): ``(name, address)``,
        sorted by name."""
        rows = self.radio.rows
        return [(name, rows[name] + 1) for name in self.radio.neighbours(self.agent)]

    def take(self) -> list[tuple[str, int, tuple]]:
        """Everything the radio received since the last call: ``(sender, sender's
        address, packet)`` in arrival order; the buffer empties."""
        buffer = self.radio.buffers.get(self.agent)
        if not buffer:
            return []
        out = list(buffer)
        buffer.clear()
        return out


@dataclass
class SwarmRadio(Medium):
    """The swarm's broadcast radio (see the module)."""

    tx_power_dbm: float = field(default=TX_AT_1M, metadata={"range": (-200.0, 100.0)})
    exponent: float = field(default=2.0, metadata={"range": (0.5, 8.0)})
    threshold_dbm: float = field(default=-64.0, metadata={"range": (-200.0, 100.0)})
    wall_db: float = field(default=3.0, metadata={"range": (0.0, 100.0)})
    packet_ms: float = field(default=1.88, metadata={"range": (0.0, 10_000.0)})
    packet_bytes: int = field(default=1024, metadata={"range": (1, 1_000_000)})
    buffer: int = field(default=256, metadata={"range": (1, 1_000_000)})
    antenna_z: float = field(default=0.1, metadata={"range": (0.0, 100.0)})
    wall_cell: float = field(default=0.0, metadata={"range": (0.0, 1000.0)})

    def index(self, world: Any = None) -> RadioIndex:
        return RadioIndex(LogDistance(self.tx_power_dbm, 0.0, self.exponent, min_distance=0.01),
                          self.threshold_dbm, self.wall_db, world, z=self.antenna_z,
                          wall_cell=self.wall_cell or None)

    def airtime(self, size: int) -> float:
        """Seconds a frame of ``size`` bytes takes on the air."""
        return round(max(1, math.ceil(size / self.packet_bytes)) * self.packet_ms / 1000.0, 9)

    def attach(self, port: MediumPort) -> None:
        self.port = port
        world = port.world
        self.world = world
        self.radios = self.index(world)
        self.buffers: dict[str, deque] = {}
        self.lost = 0
        self._tick: Any = None
        self._tree: Any = None
        self._points: Any = None
        # the robots the world moves kinematically, by agent (row of the world's poses)
        self.rows: dict[str, int] = {}
        self.agents: list[str] = []
        if provides(world, PoseArrays) and world.mode == "kinematic":
            for agent in world.agents:
                if world.is_kinematic(agent):
                    self.rows[agent] = world.row(agent)
            self.agents = [""] * (max(self.rows.values()) + 1 if self.rows else 0)
            for agent, row in self.rows.items():
                self.agents[row] = agent

    def view(self, agent: str | None) -> RadioView:
        return RadioView(self, agent or "")

    def _now(self) -> None:
        """The positions and their index for this instant (once per tick)."""
        tick = self.port.clock.now
        if tick != self._tick:
            self._tick = tick
            self._points = self.world.poses[:, :2].copy()
            self._tree = self.radios.tree(self._points)
            self._heard: dict[str, list[str]] = {}

    def neighbours(self, agent: str) -> list[str]:
        row = self.rows.get(agent)
        if row is None:
            return []
        self._now()
        heard = self._heard.get(agent)
        if heard is None:  # nothing moves within an instant: one answer per robot and instant
            live = self.world.active
            heard = self._heard[agent] = sorted(self.agents[j] for j in self.radios.heard_by(self._points, row, self._tree)
                                                if live[j])
        return heard

    def send(self, message: Message) -> None:
        data = message.data if isinstance(message.data, dict) else {}
        sender = message.sender or ""
        heard = set(self.neighbours(sender)) if data.get("to") else set()
        got = 0
        for receiver, packets in (data.get("to") or {}).items():
            if receiver not in heard:
                continue
            buffer = self.buffers.setdefault(receiver, deque())
            for packet in packets:
                if len(buffer) >= self.buffer:
                    buffer.popleft()
                    self.lost += 1
                buffer.append((sender, data.get("from", 0), packet))
            got += 1
        done = Message(message.place, message.sender, message.receiver,
                       {"size": message.size, "heard": got, "addressed": len(data.get("to") or {})},
                       message.time, message.size, message.distance)
        self.port.clock.after(self.airtime(message.size), self.port.deliver, done)
