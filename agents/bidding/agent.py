"""The three kinds of agent of seed 004 as the state their tokens carry.

* :class:`Operator`: sends the mission (``REQUEST``, then ``INFORM`` with the
  deployment, the team, the zones and, for a random deployment, the zone lists).
* :class:`Interface` (the HMIA, Fig. 3): creates the team (``INITIALIZE``), deploys it
  (``INFORM`` lists, or one ``CFP`` per zone in rank order), starts the mapping
  (``MAP``), draws every ``MAPPED`` into the global map, re-offers the zones of a robot
  that stopped, and ends the mission (``END``) once every zone is mapped.
* :class:`RobotAgent` (the RA, Fig. 4): initialises its laser, bids (eq. 6) and decides
  (lowest cost, ties to the smallest rank) on every CFP, then maps its zones nearest
  first, sending what its laser sees.

Each is a :class:`~petriflow.agents.bidding.protocol.Mailbox`; the actions of
:mod:`~petriflow.agents.bidding.actions` change them and the guards read them.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import Any

from petriflow.agents.bidding.protocol import Mailbox, Message

__all__ = ["Interface", "Operator", "RobotAgent", "Auction"]


class Operator(Mailbox):
    """The human operator: the mission it asks for."""

    def __init__(self, name: str, hmia: str, mission: dict[str, Any]) -> None:
        super().__init__()
        self.name = name
        self.hmia = hmia
        self.mission = mission


class Interface(Mailbox):
    """The HMIA's state (see the module)."""

    def __init__(self, name: str) -> None:
        super().__init__()
        self.name = name
        self.mission: dict[str, Any] | None = None
        self.requested = False
        self.robots: list[str] = []
        self.zones: list[tuple[float, float]] = []
        self.mode = "autonomous"
        self.lists: list[list[int]] | None = None
        self.initialised: set[str] = set()
        self.initialise_sent = False
        self.informed = False
        self.to_offer: deque[int] = deque()
        self.auction: int | None = None
        self.auction_at = 0.0
        self.request: Message | None = None
        self.owner: dict[int, str] = {}
        self.finished: set[int] = set()
        self.alive: set[str] = set()
        self.map_sent: float | None = None
        self.end_sent: float | None = None
        self.global_map: Any = None
        self.truth: Any = None
        self.points = 0
        self.now = 0.0

    def deployed(self) -> bool:
        """Every zone has an owner (nothing left to auction or inform)."""
        return self.requested and not self.to_offer and self.auction is None and len(self.owner) == len(self.zones)

    def done(self) -> bool:
        return self.map_sent is not None and len(self.finished) == len(self.zones)


@dataclass
class Auction:
    """One zone under auction, as a robot agent sees it."""

    zone: int
    position: tuple[float, float]
    bidders: list[str]
    own: float | None = None
    proposals: dict[str, float] = field(default_factory=dict)


class RobotAgent(Mailbox):
    """An RA's state (see the module)."""

    def __init__(self, name: str, rank: int, hmia: str) -> None:
        super().__init__()
        self.name = name
        self.rank = rank
        self.hmia = hmia
        self.robot: Any = None        # the KinematicRobot, once initialised
        self.initialise: Message | None = None
        self.initialised = False
        self.auctions: deque[Auction] = deque()
        self.ranks: dict[str, int] = {}
        self.zones: dict[int, tuple[float, float]] = {}
        self.mine: list[int] = []     # zones won or given, in that order
        self.order: list[int] = []    # the operator's list (random deployment): visited in its order
        self.done: set[int] = set()
        self.mapping = False
        self.ended = False
        self.alive: set[str] = set()
        self.team: list[str] = [name]
        self.plan: list[int] = []     # zones left, in visiting order
        self.route: list[tuple[float, float]] = []
        self.waypoints: list[tuple[float, float]] = []
        self.spin_left = 0.0
        self.held = 0.0               # seconds held behind a robot of smaller rank
        self.passing: str | None = None  # the robot a detour goes around
        self.seen: set[tuple[int, int]] = set()
        self.scans = 0
        self.now = 0.0
        self.waiting = 0.0
        self.ranks[name] = rank

    def auction(self) -> Auction | None:
        return self.auctions[0] if self.auctions else None

    def to_bid(self) -> bool:
        a = self.auction()
        return self.initialised and a is not None and a.own is None

    def bids_in(self) -> bool:
        a = self.auction()
        if a is None or a.own is None:
            return False
        return all(b in a.proposals or b == self.name or b not in self.alive for b in a.bidders)

    def left(self) -> list[int]:
        return [z for z in self.mine if z not in self.done]
