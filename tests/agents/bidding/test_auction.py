"""Eq. 6, the tie rule, the sequential auction and the message kinds (seed 004)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from petriflow.agents.bidding.auction import autonomous, best, random_deployment, tour
from petriflow.agents.bidding.cost import Weights, bid_costs, cost_matrix, load_term
from petriflow.agents.bidding.errors import BiddingError
from petriflow.agents.bidding.correspondent import Correspondent
from petriflow.agents.bidding.protocol import KINDS, Payload

STARTS = [(6, -9), (7, -9), (8, -9), (9, -9), (10, -9)]
ZONES = [(10.5, 8.1), (2, 8.1), (-5, 8.1), (-12.5, 8.1), (13, -8.1), (0.5, -5.5), (-8.1, -5.5), (0, 2)]


def test_eq6_term_by_term():
    # robot holding n = 2 zones, 10 s from the zone, sensor accuracy 0.4
    a, b, c = 0.5, 0.3, 0.2
    cost = bid_costs([[10.0]], [2], [0.4], area=100.0, weights=Weights(a, b, c))[0, 0]
    expected = a * (2 * 10.0 + 10.0) + b * math.log(100.0) ** 2 * 2 + c * (1 - 0.4)
    assert cost == pytest.approx(expected)
    assert load_term([0])[0] == 0.0


def test_cost_matrix_uses_distance_over_speed():
    costs = cost_matrix([(0, 0)], [(3, 4)], speed=2.5)
    assert costs[0, 0] == pytest.approx(5 / 2.5 / 3)


def test_tie_goes_to_the_smallest_rank():
    assert best([1.0, 1.0, 0.5 + 0.5]) == 0
    assert best([2.0, 1.0, 1.0], ranks=[0, 7, 3]) == 3
    # two robots at the same distance from the zone: the first wins the auction
    won = autonomous([(0, 0), (2, 0)], [(1, 5)])
    assert won.winner == [0]


def test_best_rejects_nonsense():
    with pytest.raises(BiddingError):
        best([])
    with pytest.raises(BiddingError):
        best([1.0, float("nan")])


@pytest.mark.parametrize("robots, shares", [(1, [8]), (2, [4, 4]), (3, [3, 3, 2]), (4, [2, 2, 2, 2]),
                                            (5, [2, 2, 2, 1, 1])])
def test_paper_team_sizes_get_the_papers_zone_counts(robots, shares):
    # Tables 3-6 (autonomous): the load term spreads the eight zones this way
    won = autonomous(STARTS[:robots], ZONES)
    assert sorted((len(won.zones_of(r)) for r in range(robots)), reverse=True) == shares
    assert sorted(won.zones) == list(range(8)) and won.allocated == [len(won.zones_of(r)) for r in range(robots)]


def test_each_zone_goes_to_the_lowest_bid_given_the_counts_so_far():
    won = autonomous(STARTS[:3], ZONES)
    counts = np.zeros(3)
    for zone, winner in zip(won.zones, won.winner):
        bids = cost_matrix(STARTS[:3], [ZONES[zone]], counts)[:, 0]
        assert winner == int(np.argmin(bids))
        counts[winner] += 1


def test_reauction_among_survivors_keeps_their_counts():
    first = autonomous(STARTS[:3], ZONES)
    lost = first.zones_of(0)
    again = autonomous(STARTS[:3], ZONES, offer=lost, allocated=[0] + first.allocated[1:], alive=[False, True, True])
    assert 0 not in again.winner and sorted(again.zones) == sorted(lost)
    assert sum(again.allocated) == 8
    with pytest.raises(BiddingError, match="no robot is alive"):
        autonomous(STARTS[:2], ZONES, alive=[False, False])


def test_large_auction_allocates_every_zone_evenly():
    rng = np.random.default_rng(0)
    won = autonomous(rng.uniform(0, 100, (100, 2)), rng.uniform(0, 100, (1000, 2)), area=100 * 100)
    counts = np.bincount(won.winner, minlength=100)
    assert counts.sum() == 1000 and counts.max() - counts.min() <= 1  # the load term spreads the zones


def test_random_deployment_is_seeded_and_complete():
    a, b = random_deployment(3, 8, 5), random_deployment(3, 8, 5)
    assert a == b and sorted(z for zs in a for z in zs) == list(range(8))
    assert random_deployment(3, 8, 6) != a


def test_tour_visits_nearest_first():
    # the paper's robot 1 (6, -9) with its autonomous zones Z6, Z8, Z2, Z1 in Table 3
    zones = [ZONES[0], ZONES[1], ZONES[5], ZONES[7]]
    assert [[0, 1, 5, 7][k] + 1 for k in tour(STARTS[0], zones)] == [6, 8, 2, 1]


def test_messages_have_the_ten_kinds_and_sizes():
    assert len(KINDS) == 10
    with pytest.raises(BiddingError, match="unknown message kind"):
        Payload("HELLO")
    mapped = Payload("MAPPED", body={"points": np.zeros((10, 2), np.float32), "rank": 0})
    assert mapped.size == 4 + 80 + 8
    box = Correspondent()
    box.queue("robot2", Payload("PROPOSE", zone=0, body={"cost": 1.0}))
    box.queue("robot3", Payload("PROPOSE", zone=0, body={"cost": 1.0}))
    assert box.pending() and box.take("robot3").receiver == "robot3" and box.take("robot3") is None
    assert box.drop("robot2") == 1 and not box.pending() and box.sent == {"PROPOSE": 1}


def test_random_deployment_uses_the_whole_team():
    for seed in range(50):
        lists = random_deployment(5, 8, seed)
        assert all(lists) and sorted(z for zs in lists for z in zs) == list(range(8))
    assert sum(map(bool, random_deployment(5, 3, 1))) == 3
