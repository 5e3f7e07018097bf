"""Radio neighbours by a spatial index equal the all-pairs answer; walls counted in
batches equal walls counted one pair at a time."""

import math

import numpy as np
import pytest

from petriflow.runtime.radio import (
    LogDistance,
    RadioIndex,
    fade_loss,
    pairs_within,
    power_for_range,
    walls_along,
    walls_between,
)
from petriflow.world import World


@pytest.mark.parametrize("method", ["grid", "kdtree"])
@pytest.mark.parametrize("n, radius, seed", [(2, 1.0, 0), (50, 3.0, 1), (400, 2.5, 2), (1000, 1.2, 3), (300, 40.0, 4)])
def test_the_spatial_index_finds_exactly_the_pairs_all_pairs_finds(method, n, radius, seed):
    rng = np.random.default_rng(seed)
    points = rng.uniform(-20, 20, size=(n, 2))
    points[: n // 10] = np.round(points[: n // 10])   # some on the grid's cell edges
    expected = [(i, j) for i in range(n) for j in range(i + 1, n) if math.dist(points[i], points[j]) <= radius]
    assert pairs_within(points, radius, method="all").tolist() == [list(p) for p in expected]
    assert pairs_within(points, radius, method=method).tolist() == [list(p) for p in expected]


def test_no_points_or_one_point_have_no_pairs():
    assert pairs_within([], 1.0).shape == (0, 2)
    assert pairs_within([(0, 0)], 1.0).shape == (0, 2)
    with pytest.raises(ValueError, match="method"):
        pairs_within([(0, 0), (1, 1)], 2.0, method="guess")


def _walled_world():
    boxes = [{"id": f"wall{i}", "size": [0.05, 6, 0.5], "position": [i * 1.0, 0, 0.25]} for i in range(1, 8)]
    robots = [{"id": f"r{i}", "urdf": "petriflow.agents:robots/diffdrive.urdf", "position": [0.5 + i, 0.3 * i],
               "z": 0.05} for i in range(7)]
    return World({"dt": 0.1, "mode": "kinematic", "boxes": boxes, "robots": robots})


def test_walls_counted_in_batches_equal_walls_counted_pair_by_pair():
    world = _walled_world()
    try:
        names = [f"r{i}" for i in range(7)]
        points = [world.position(n) for n in names]
        bodies = [world.body(n) for n in names]
        starts, ends, expected = [], [], []
        for i in range(7):
            for j in range(7):
                if i != j:
                    starts.append(points[i]), ends.append(points[j])
                    expected.append(walls_between(world, points[i], points[j], ignore=bodies))
        assert walls_along(world, starts, ends) == expected
        assert max(expected) == 6
    finally:
        world.close()


def test_the_radio_index_keeps_the_pairs_whose_rssi_through_walls_clears_the_threshold():
    world = _walled_world()
    try:
        model = LogDistance(tx_power_dbm=-30.0, exponent=2.0, min_distance=0.01)
        index = RadioIndex(model, threshold_dbm=-52.0, wall_db=3.0, world=world)
        points = np.array([world.position(f"r{i}") for i in range(7)])
        links = index.links(points).tolist()
        bodies = [world.body(f"r{i}") for i in range(7)]
        expected = []
        for i in range(7):
            for j in range(i + 1, 7):
                d = math.dist(points[i], points[j])
                walls = walls_between(world, tuple(points[i]), tuple(points[j]), ignore=bodies)
                if model.rssi(d, 3.0 * walls) >= -52.0:
                    expected.append([i, j])
        assert links == expected and 0 < len(links) < 21
        tested = index.tested
        assert tested <= len(pairs_within(points, index.radius))   # only candidates are ray tested
        assert index.links(points).tolist() == expected and index.tested == tested   # walls cached
    finally:
        world.close()


@pytest.mark.parametrize("method", ["auto", "grid"])
def test_who_hears_one_radio_by_the_index_equals_the_all_pairs_links(method):
    rng = np.random.default_rng(7)
    points = rng.uniform(0, 30, size=(500, 2))
    model = LogDistance(tx_power_dbm=-50.0, exponent=2.0, min_distance=0.01)
    index = RadioIndex(model, threshold_dbm=-64.0, method=method)
    links = index.links(points).tolist()
    everyone = RadioIndex(model, threshold_dbm=-64.0, method="all").links(points).tolist()
    assert links == everyone and len(links) > 100
    tree = index.tree(points)
    for asker in range(0, 500, 7):
        expected = sorted({j for i, j in everyone if i == asker} | {i for i, j in everyone if j == asker})
        assert index.heard_by(points, asker, tree) == expected


@pytest.mark.parametrize("model", [LogDistance(-30.0, 0.0, 2.0, 0.01), LogDistance(0.0, 40.0, 3.1, 0.5)])
def test_the_vectorised_link_budget_is_the_scalar_one(model):
    """rssi_many gives rssi's value for each distance (reference loss and walls included)."""
    distances = np.array([0.0, 0.2, 1.0, 7.5, 120.0])
    walls = np.array([0.0, 3.0, 0.0, 6.0, 9.0])
    assert model.rssi_many(distances).tolist() == pytest.approx([model.rssi(d) for d in distances])
    assert model.rssi_many(distances, walls).tolist() == \
        pytest.approx([model.rssi(d, w) for d, w in zip(distances, walls)])


def test_power_for_range_is_the_inverse_of_range():
    power = power_for_range(-64.0, 5.0, exponent=2.5, reference_loss_db=40.0)
    assert LogDistance(power, 40.0, 2.5).range(-64.0) == pytest.approx(5.0)


def test_fade_loss_rises_from_none_to_all_over_the_margin():
    assert fade_loss(-60.0, floor_dbm=-70.0, fade_db=10.0) == 0.0
    assert fade_loss(-65.0, floor_dbm=-70.0, fade_db=10.0) == pytest.approx(0.5)
    assert fade_loss(-70.0, floor_dbm=-70.0, fade_db=10.0) == 1.0
    assert fade_loss(-69.9, floor_dbm=-70.0, fade_db=0.0) == 0.0
