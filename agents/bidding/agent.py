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

Each is a :class:`~petriflow.agents.bidding.correspondent.Correspondent`, an agent state the run
keeps (``ctx.state``; registered as ``bidding.operator``, ``bidding.interface`` and
``bidding.robot``): the actions (:mod:`~petriflow.agents.bidding.interface`,
:mod:`~petriflow.agents.bidding.robot`, ...) change them and the guards read them.
What a guard asks costs the same whatever the team's size: :meth:`Interface.next_step`
and :meth:`RobotAgent.next_step` read counters kept as messages arrive, not the team.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import Any

from petriflow.agents.bidding.correspondent import Correspondent
from petriflow.runtime.channel_models import Message

__all__ = ["Interface", "Operator", "RobotAgent", "Auction"]


class Operator(Correspondent):
    """The human operator: the mission it asks for."""

    def __init__(self, name: str, hmia: str, mission: dict[str, Any]) -> None:
        super().__init__(name)
        self.hmia = hmia
        self.mission = mission


class Interface(Correspondent):
    """The HMIA's state (see the module)."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
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
        self.until = "mapped"          # END when every zone is mapped (in sight or reached), or only reached
        self.seen: set[int] = set()   # zones a robot's laser has had in sight

    def mapped(self) -> set[int]:
        """The zones mapped so far: reached, or (``until == "mapped"``) in a laser's sight."""
        return self.finished | self.seen if self.until == "mapped" else self.finished

    def deployed(self) -> bool:
        """Every zone has an owner (nothing left to auction or inform)."""
        return self.requested and not self.to_offer and self.auction is None and len(self.owner) == len(self.zones)

    def done(self) -> bool:
        return self.map_sent is not None and len(self.mapped()) == len(self.zones)

    def next_step(self) -> str | None:
        """What the HMIA should do now (``team``, ``inform``, ``cfp``, ``map``, ``end``), or ``None``."""
        if self.end_sent is not None:
            return None
        if self.requested and not self.initialise_sent:
            return "team"
        if not self.initialise_sent:
            return None
        if not self.alive:
            return "end" if self.map_sent is not None or self.initialised else None
        if not (self.initialised >= self.alive):
            return None
        if self.mode == "random" and not self.informed:
            return "inform"
        if self.to_offer and self.auction is None:
            return "cfp"
        if self.map_sent is None and self.deployed():
            return "map"
        if self.done():
            return "end"
        return None

    def busy(self) -> bool:
        """Something to do or to send (else the HMIA waits for news)."""
        return self.queued > 0 or self.end_sent is not None or self.next_step() is not None

    def signature(self) -> tuple[str | None, bool]:
        return self.next_step(), self.end_sent is not None


@dataclass
class Auction:
    """One zone under auction, as a robot agent sees it.

    ``missing`` counts the living bidders (other than the robot itself) whose proposal
    has not come (``None``: to be counted again, after the team's liveness changed), so
    whether every proposal is in costs nothing per message.
    """

    zone: int
    position: tuple[float, float]
    bidders: list[str]
    own: float | None = None
    proposals: dict[str, float] = field(default_factory=dict)
    missing: int | None = None
    among: frozenset[str] = frozenset()

    def __post_init__(self) -> None:
        self.among = frozenset(self.bidders)

    def count(self, me: str, alive: set[str]) -> int:
        """The living bidders but ``me`` still to propose (counted once, then kept)."""
        if self.missing is None:
            self.missing = sum(1 for b in self.among if b != me and b in alive and b not in self.proposals)
        return self.missing

    def propose(self, sender: str, cost: float, me: str, alive: set[str]) -> None:
        if self.missing is not None and sender not in self.proposals and sender != me and sender in alive \
                and sender in self.among:
            self.missing -= 1
        self.proposals[sender] = cost


class RobotAgent(Correspondent):
    """An RA's state (see the module)."""

    def __init__(self, name: str, rank: int, hmia: str) -> None:
        super().__init__(name)
        self.rank = rank
        self.hmia = hmia
        self.robot: Any = None        # the KinematicRobot, once initialised
        self.odometry: Any = None     # its Stage odometry (localization odom), else None: the true pose
        self.sight: dict[int, tuple[float, float]] = {}  # the mission's zones (from MAP), to see
        self.sighted: set[int] = set()  # zones this robot's laser had in sight
        self.initialise: Message | None = None
        self.initialised = False
        self.auctions: deque[Auction] = deque()
        self.ranks: dict[str, int] = {}
        self.zones: dict[int, tuple[float, float]] = {}
        self.mine: list[int] = []     # zones won or given, in that order
        self.order: list[int] = []    # the operator's list (random deployment): visited in its order
        self.done: set[int] = set()
        self.mapping = False
        self.keep_mapping = True      # once its zones are done, go on scanning (MAPPED) until END
        self.ended = False
        self.alive: set[str] = set()
        self.team: list[str] = [name]
        self.plan: list[int] = []     # zones left, in visiting order
        self.route: list[tuple[float, float]] = []
        self.waypoints: list[tuple[float, float]] = []
        self.spin_left = 0.0
        self.held = 0.0               # seconds held behind a robot of smaller rank
        self.passing: str | None = None  # the robot a detour goes around
        self.seen: set[int] = set()           # cells sent as real returns
        self.seen_teammate: set[int] = set()  # cells sent as returns off teammates
        self.scans = 0
        self.waiting = 0.0
        self.ranks[name] = rank
        self._members_of: list[str] | None = None
        self._members: frozenset[str] = frozenset()

    def auction(self) -> Auction | None:
        return self.auctions[0] if self.auctions else None

    def pose(self) -> tuple[float, float, float]:
        """Where the robot believes it is (``localizeRobot()``): its odometry's estimate,
        or the true pose when it localises perfectly (Stage's ``gps``)."""
        return self.odometry.pose if self.odometry is not None else self.robot.pose

    def to_bid(self) -> bool:
        a = self.auction()
        return self.initialised and a is not None and a.own is None

    def bids_in(self) -> bool:
        a = self.auction()
        if a is None or a.own is None:
            return False
        return a.count(self.name, self.alive) == 0

    def members(self) -> frozenset[str]:
        """The team (made once per team list)."""
        team = self.team
        if self._members_of is not team:
            self._members_of = team
            self._members = frozenset(team)
        return self._members

    def set_alive(self, alive: set[str]) -> None:
        """The teammates running now (what the heartbeats say); counts of missing
        proposals are made again when this changed."""
        if alive != self.alive:
            self.alive = alive
            for auction in self.auctions:
                auction.missing = None
            self.changed()

    def left(self) -> list[int]:
        return [z for z in self.mine if z not in self.done]

    def next_step(self) -> str | None:
        """What the RA should do now (``ready``, ``decide``, ``bid``, ``explore``), or ``None``."""
        if self.ended:
            return None
        if self.initialise is not None and not self.initialised:
            return "ready"
        if self.bids_in():
            return "decide"
        if self.to_bid():
            return "bid"
        if self.mapping and (self.route or self.spin_left > 0 or self.left() or self.keep_mapping):
            return "explore"
        return None

    def busy(self) -> bool:
        """Something to do or to send (else the RA waits for news)."""
        return self.queued > 0 or self.ended or self.next_step() is not None

    def signature(self) -> tuple[str | None, bool]:
        return self.next_step(), self.ended
