"""Process 2 of seed 000: the radio link between agents, and the analysis that picks
its usable range.

:class:`RadioChannel` is a channel model (``channels: {radio: {model: comm.radio}}``)
for Wi-Fi adapters such as the paper's TL-WN823N. The received signal strength is a
log-distance path loss with a loss per wall crossed::

    RSSI(d, walls) = tx_power_dbm - 10 * exponent * log10(d / 1 m) - walls * wall_db

Walls are counted with a pybullet ray test between the two agents' antennas (the
channel is bound to the run's world). The calibration follows the paper: the
framework uses a link while RSSI > ``threshold_dbm`` = -63.4375 dBm, which in free
space is 2 m (so ``tx_power_dbm`` = -57.41 dBm at 1 m with exponent 2); the adapter
itself still delivers, behind one concrete wall, up to 8 m (Fig. 5), which puts its
``sensitivity_dbm`` at -75.47 - ``concrete_db``; below the sensitivity a frame is
lost, and within ``fade_db`` above it a frame is lost with a probability rising
linearly to 1 at the sensitivity (seeded). Maze walls are thin partitions:
``wall_db`` = 3 dB each (the concrete wall of Fig. 5 is 10 dB). Delay: ``latency``
plus the frame's bits at ``bitrate``.

:func:`threshold_sweep` is the Fig. 5 experiment on this model: the delivered share
and the mean RSSI at each distance behind a wall; :func:`pick_threshold` returns the
last distance with no loss and the RSSI there.

Examples:
    >>> radio = RadioChannel()
    >>> round(radio.rssi(2.0), 4), round(radio.range(), 3)
    (-63.4375, 2.0)
    >>> rows = threshold_sweep(radio, range(1, 11), walls=1, trials=200, seed=1)
    >>> pick_threshold(rows)[0]
    7
"""

from __future__ import annotations

import math
import random
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

from petriflow.capabilities import Positions, provides
from petriflow.runtime.channels import ChannelModel, Message
from petriflow.runtime.radio import LogDistance, WallCounter

__all__ = ["CALIBRATED_TX_DBM", "RadioChannel", "pick_threshold", "threshold_sweep"]

#: tx power (dBm at 1 m) that puts -63.4375 dBm at 2 m with exponent 2.
CALIBRATED_TX_DBM = -63.4375 + 20.0 * math.log10(2.0)


@dataclass
class RadioChannel(ChannelModel):
    """A Wi-Fi link with log-distance path loss and walls (see the module)."""

    tx_power_dbm: float = field(default=round(CALIBRATED_TX_DBM, 4), metadata={"range": (-200.0, 100.0)})
    exponent: float = field(default=2.0, metadata={"range": (0.5, 8.0)})
    wall_db: float = field(default=3.0, metadata={"range": (0.0, 100.0)})
    concrete_db: float = field(default=10.0, metadata={"range": (0.0, 100.0)})
    threshold_dbm: float = field(default=-63.4375, metadata={"range": (-200.0, 100.0)})
    fade_db: float = field(default=1.0, metadata={"range": (0.0, 50.0)})
    latency: float = field(default=0.002, metadata={"range": (0.0, 60.0)})
    bitrate: float = field(default=150e6, metadata={"range": (1.0, 1e12)})
    antenna_z: float = field(default=0.15, metadata={"range": (0.0, 10.0)})
    gains_db: dict = field(default_factory=dict)  # agent -> antenna gain (dB), where a maker documents one
    #: agents whose links are used wherever the adapter delivers every frame (Fig. 5:
    #: ``lossless_dbm``) instead of above the framework's threshold: a central unit,
    #: which every robot must reach and which has no peers to choose between
    adapter_limit: list = field(default_factory=list)
    #: What a lost frame leaves: a loss notice in its channel place (the run
    #: configuration's ``on_loss``; the runtime's default is ``drop``). The paper's
    #: transport is TCP, whose ends learn of a lost segment and send it again; a frame
    #: dropped without a trace would also keep its mailbox's slot token for ever, and
    #: the mission's net could never end (``comm.receive`` takes the notice).
    on_loss = "notify"

    def __post_init__(self) -> None:
        self.world: Any = None
        self._walls: Any = None
        self._placed: Positions | None = None  # the bound world, when it places the agents
        self.path = LogDistance(self.tx_power_dbm, 0.0, self.exponent, min_distance=0.05)

    @property
    def sensitivity_dbm(self) -> float:
        """Where frames stop arriving: the RSSI at 8 m behind one concrete wall (Fig. 5)."""
        return self.rssi(8.0) - self.concrete_db

    @property
    def lossless_dbm(self) -> float:
        """The weakest RSSI at which no frame is lost: the sensitivity plus the fading
        margin (7 m behind the concrete wall of Fig. 5)."""
        return self.sensitivity_dbm + self.fade_db

    def limit_dbm(self, a: str, b: str) -> float:
        """The RSSI a link between ``a`` and ``b`` must exceed to be used: the framework's
        threshold, or the adapter's lossless limit for a link of an ``adapter_limit`` agent."""
        if self.adapter_limit and (a in self.adapter_limit or b in self.adapter_limit):
            return self.lossless_dbm
        return self.threshold_dbm

    def bind(self, world: Any) -> None:
        """The run's world: positions and walls between agents come from it (walls do
        not move, so each pair of places, to the centimetre, is ray-tested once)."""
        self.world = world
        self._walls = WallCounter(world, z=self.antenna_z)
        self._placed = world if provides(world, Positions) else None

    def rssi(self, distance: float, walls: int = 0) -> float:
        """Received signal strength (dBm) at ``distance`` m through ``walls`` walls."""
        return self.path.rssi(distance, walls * self.wall_db)

    def range(self, walls: int = 0) -> float:
        """Distance (m) at which the RSSI reaches the framework's threshold."""
        return self.path.range(self.threshold_dbm, walls * self.wall_db)

    def between(self, a: str, b: str) -> tuple[float, int] | None:
        """``(distance, walls)`` between two agents of the bound world, or ``None``."""
        return None if self._walls is None else self._walls.between(a, b)

    def link_rssi(self, a: str, b: str) -> float | None:
        """The RSSI between two agents now, their antennas' gains included (``None``
        without a world or positions)."""
        found = self.between(a, b)
        if found is None:
            return None
        return self.rssi(*found) + float(self.gains_db.get(a, 0.0)) + float(self.gains_db.get(b, 0.0))

    def usable(self, a: str, b: str, positions: dict[str, Any] | None = None) -> bool:
        """Whether the framework would use the link (RSSI above the threshold, or above
        the adapter's lossless limit for an ``adapter_limit`` agent's link).

        Walls only take power away, so a pair whose RSSI in free space (antenna gains
        included) is already at or below the threshold is out of range without
        counting its walls: the ray tests are made only for pairs near enough to be
        heard, and the answer is the one :meth:`link_rssi` gives. ``positions``: the
        agents' ``(x, y)`` now, when the caller has read them already (one read per
        agent for a whole plan instead of two per pair).
        """
        world = self._placed
        if self._walls is not None and world is not None:
            if positions is not None and a in positions and b in positions:
                pa, pb = positions[a], positions[b]
            else:
                pa, pb = world.position(a), world.position(b)
            if pa is not None and pb is not None:
                free = self.path.rssi(math.dist(pa, pb)) + float(self.gains_db.get(a, 0.0)) \
                    + float(self.gains_db.get(b, 0.0))
                if free <= self.limit_dbm(a, b):
                    return False
        level = self.link_rssi(a, b)
        return level is None or level > self.limit_dbm(a, b)

    def loss_probability(self, level: float) -> float:
        """Chance a frame at RSSI ``level`` is lost."""
        floor = self.sensitivity_dbm
        if level <= floor:
            return 1.0
        if self.fade_db <= 0 or level >= floor + self.fade_db:
            return 0.0
        return 1.0 - (level - floor) / self.fade_db

    def deliver(self, message: Message, rng: Any) -> float | None:
        level = None
        if message.sender and message.receiver:
            level = self.link_rssi(message.sender, message.receiver)
        if level is None and message.distance is not None:
            level = self.rssi(message.distance)
        if level is not None:
            chance = self.loss_probability(level)
            if chance >= 1.0 or (chance > 0 and rng.random() < chance):
                return None
        return self.latency + 8.0 * message.size / self.bitrate


def threshold_sweep(model: RadioChannel, distances: Iterable[float], *, walls: int = 1, trials: int = 100,
                    seed: int = 0, concrete: bool = True) -> list[tuple[float, float, float]]:
    """Fig. 5 on the model: ``(distance, delivered share, RSSI)`` at each distance
    behind ``walls`` walls (concrete ones by default, as in the paper's test)."""
    rng = random.Random(seed)
    rows = []
    for distance in distances:
        loss = (model.concrete_db if concrete else model.wall_db) * walls
        level = model.path.rssi(distance, loss)
        chance = model.loss_probability(level)
        delivered = sum(1 for _ in range(trials) if not (chance >= 1.0 or rng.random() < chance))
        rows.append((distance, delivered / trials, round(level, 4)))
    return rows


def pick_threshold(rows: list[tuple[float, float, float]]) -> tuple[float, float]:
    """The last distance of a sweep with every frame delivered, and its RSSI."""
    best = None
    for distance, share, level in rows:
        if share < 1.0:
            break
        best = (distance, level)
    if best is None:
        raise ValueError("no distance of the sweep delivered every frame")
    return best


def plot_analysis(model: RadioChannel, path: str, *, distances: Iterable[float] = range(1, 11), trials: int = 500,
                  seed: int = 0) -> tuple[float, float]:
    """Fig. 5 on the model: delivered share and RSSI against distance behind one
    concrete wall, with the picked threshold marked; returns it ``(m, dBm)``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = threshold_sweep(model, list(distances), walls=1, trials=trials, seed=seed)
    picked = pick_threshold(rows)
    figure, (share, level) = plt.subplots(1, 2, figsize=(9, 3.6))
    share.plot([r[0] for r in rows], [r[1] for r in rows], marker="o")
    share.axvline(picked[0], color="tab:red", linestyle="--", label=f"last lossless: {picked[0]:g} m")
    share.set_xlabel("distance behind a concrete wall (m)")
    share.set_ylabel("frames delivered")
    share.legend(fontsize=8)
    level.plot([r[0] for r in rows], [r[2] for r in rows], marker="o", color="tab:orange")
    level.axhline(model.sensitivity_dbm, color="tab:red", linestyle="--", label="adapter sensitivity")
    level.axhline(model.threshold_dbm, color="tab:green", linestyle=":", label="framework threshold (2 m, free space)")
    level.set_xlabel("distance behind a concrete wall (m)")
    level.set_ylabel("RSSI (dBm)")
    level.legend(fontsize=8)
    figure.suptitle("process 2: transmission analysis of the comm.radio model (seed 000 Fig. 5)")
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
    return picked


if __name__ == "__main__":  # python -m petriflow.agents.comm.radio OUT.png
    import sys

    print(plot_analysis(RadioChannel(), sys.argv[1] if len(sys.argv) > 1 else "fig5.png"))
