"""Zone allocation: the autonomous (bidding) and random deployments of seed 004.

Autonomous deployment (§3.2.2): the interface agent offers the zones one call for
proposals (CFP) at a time, in rank order. Every robot prices the zone by eq. 6
(:mod:`~petriflow.agents.bidding.cost`) counting the zones it already won, the lowest
cost wins and a tie goes to the robot of smallest rank. :func:`autonomous` is that
auction run in one place (each robot agent runs the same rule on the costs it
receives, so all of them reach this result); it also re-auctions the zones of a robot
that broke down among the survivors (``alive``, ``allocated``).

Random deployment (§3.2.1): the operator gives each robot its zone list.
:func:`random_deployment` draws one (each zone to a robot chosen uniformly, visited in
a shuffled order), as the operator's arbitrary lists of Tables 3-6 are.

A robot visits its zones nearest first from where it stands (:func:`tour`): the order
of the paper's autonomous lists (Table 3: robot 1 at (6, -9) maps Z6, Z8, Z2, Z1).

Examples:
    The paper's two robots and eight zones (Table 2), robots at 0.5 m/s:

    >>> from petriflow.agents.bidding.office import paper_office
    >>> office = paper_office()
    >>> won = autonomous([s[:2] for s in office.starts[:2]], office.zones)
    >>> [z + 1 for z in won.zones_of(0)], [z + 1 for z in won.zones_of(1)]
    ([2, 3, 6, 7], [1, 4, 5, 8])
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from petriflow.agents.bidding.cost import AREA_M2, SPEED_M_S, Weights, load_term, travel_times
from petriflow.agents.bidding.errors import BiddingError

__all__ = ["Allocation", "autonomous", "best", "random_deployment", "tour"]

#: Two costs closer than this (relative) are a tie, decided by rank.
TIE = 1e-9


def best(costs: Sequence[float], ranks: Sequence[int] | None = None) -> int:
    """The winner among proposals: the lowest cost, a tie going to the smallest rank.

    ``costs[k]`` is the proposal of the robot of rank ``ranks[k]`` (default ``k``);
    returns that rank.

    Examples:
        >>> best([3.0, 1.0, 1.0])
        1
        >>> best([2.0, 2.0], ranks=[4, 2])
        2
    """
    if len(costs) == 0:
        raise BiddingError("no proposals to choose from")
    ranks = list(range(len(costs))) if ranks is None else list(ranks)
    if len(ranks) != len(costs):
        raise BiddingError(f"{len(costs)} costs but {len(ranks)} ranks")
    values = [float(c) for c in costs]
    if any(math.isnan(c) for c in values):
        raise BiddingError("a proposal's cost is not a number")
    low = min(values)
    tied = [r for c, r in zip(values, ranks) if c == low or (math.isfinite(low) and c - low <= TIE * max(1.0, abs(low)))]
    return min(tied)


@dataclass
class Allocation:
    """The result of an auction.

    Attributes:
        winner: the winning robot's index for each auctioned zone (in offer order).
        zones: the auctioned zones' indices (in offer order).
        costs: the winning bid of each.
        allocated: zones each robot holds afterwards (the counts it started with included).
    """

    winner: list[int]
    zones: list[int]
    costs: list[float]
    allocated: list[int]

    def zones_of(self, robot: int) -> list[int]:
        """Indices of the zones ``robot`` won, in offer order."""
        return [z for z, w in zip(self.zones, self.winner) if w == robot]

    def lists(self, robots: int) -> list[list[int]]:
        return [self.zones_of(r) for r in range(robots)]


def autonomous(positions: Any, zones: Any, *, offer: Sequence[int] | None = None, allocated: Any = None,
               alive: Sequence[bool] | None = None, accuracy: Any = 1.0, speed: float = SPEED_M_S,
               area: float = AREA_M2, weights: Weights = Weights(), log_base: float = math.e) -> Allocation:
    """Offer ``zones`` one at a time (``offer``: their indices, default all in rank
    order) to the robots at ``positions``; each goes to the lowest eq. 6 bid.

    Args:
        positions: ``(m, 2)`` robot positions (where each bids from; they do not move
            during the auction).
        zones: ``(n, 2)`` zone positions.
        offer: which zones to offer, in order (a re-auction offers a broken robot's).
        allocated: zones each robot holds already (``n_i`` before the first offer).
        alive: robots that bid; the others are out of the auction.
        accuracy, speed, area, weights, log_base: eq. 6's ``E_i`` and constants.
    """
    travel = travel_times(positions, zones, speed)
    robots = travel.shape[0]
    offer = list(range(travel.shape[1])) if offer is None else [int(z) for z in offer]
    for z in offer:
        if not 0 <= z < travel.shape[1]:
            raise BiddingError(f"zone index {z} is not one of the {travel.shape[1]} zones")
    counts = np.zeros(robots) if allocated is None else np.array(allocated, dtype=float)
    if counts.shape != (robots,):
        raise BiddingError(f"allocated has {counts.size} counts for {robots} robots")
    bidding = np.ones(robots, bool) if alive is None else np.array(alive, dtype=bool)
    if bidding.shape != (robots,):
        raise BiddingError(f"alive has {bidding.size} flags for {robots} robots")
    if offer and not bidding.any():
        raise BiddingError("no robot is alive to bid")
    sensor = np.broadcast_to(np.asarray(accuracy, dtype=float), (robots,))
    if np.any((sensor < 0) | (sensor > 1)):
        raise BiddingError("sensor accuracy E_i must be from 0 to 1")
    # eq. 6 as bid_costs computes it, with the load term looked up by the count held
    start = counts.astype(np.int64)
    if np.any(start != counts):
        raise BiddingError("allocated zone counts must be whole numbers")
    table = weights.beta * load_term(np.arange(int(start.max(initial=0)) + len(offer) + 1), area, log_base)
    sensor_term = weights.gamma * (1.0 - sensor)
    held = start.copy()
    winners, costs = [], []
    for z in offer:
        bids = weights.alpha * (held + 1.0) * travel[:, z] + (table[held] + sensor_term)
        bids[~bidding] = np.inf
        low = bids.min()
        if math.isfinite(low):
            tied = np.flatnonzero(bids - low <= TIE * max(1.0, abs(low)))
        else:  # every living bid overflowed: the smallest living rank
            tied = np.flatnonzero(bidding)
        w = int(tied[0])
        winners.append(w)
        costs.append(float(bids[w]))
        held[w] += 1
    return Allocation(winners, offer, costs, [int(c) for c in held])


def random_deployment(robots: int, zones: int, rng: random.Random | int = 0) -> list[list[int]]:
    """An operator's random zone lists: every robot gets one zone (while zones last;
    the operator deploys the whole team, as in Tables 3-6), the other zones go to
    robots drawn uniformly, and each list is in a shuffled order.

    Examples:
        >>> lists = random_deployment(3, 8, rng=1)
        >>> sorted(z for zs in lists for z in zs)
        [0, 1, 2, 3, 4, 5, 6, 7]
    """
    if robots < 1 or zones < 0:
        raise BiddingError(f"a deployment needs >= 1 robot and >= 0 zones, got {robots} and {zones}")
    rng = rng if isinstance(rng, random.Random) else random.Random(rng)
    lists: list[list[int]] = [[] for _ in range(robots)]
    order = list(range(zones))
    rng.shuffle(order)
    for k, z in enumerate(order):
        lists[k if k < robots else rng.randrange(robots)].append(z)
    for zs in lists:
        rng.shuffle(zs)
    return lists


def tour(start: Sequence[float], points: Sequence[Sequence[float]]) -> list[int]:
    """Indices of ``points`` in nearest-first order from ``start`` (ties: lower index).

    Examples:
        >>> tour((0, 0), [(5, 0), (1, 0), (2, 0)])
        [1, 2, 0]
    """
    left = list(range(len(points)))
    here = (float(start[0]), float(start[1]))
    order = []
    while left:
        k = min(left, key=lambda i: (math.dist(here, points[i][:2]), i))
        order.append(k)
        left.remove(k)
        here = (float(points[k][0]), float(points[k][1]))
    return order
