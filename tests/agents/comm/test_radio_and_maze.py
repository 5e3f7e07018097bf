"""The radio model (process 2), mazes, exploration and the kinematic drive."""

from __future__ import annotations

import math
import random

import pytest

from petriflow.agents.comm.radio import RadioChannel, pick_threshold, threshold_sweep
from petriflow.agents.mobile.explore import Explorer
from petriflow.agents.mobile.kinematic import Encoders, icc_step
from petriflow.agents.mobile.maze import Maze, from_meta, generate
from petriflow.runtime.channels import Message


def test_radio_is_calibrated_to_the_paper():
    radio = RadioChannel()
    assert radio.rssi(2.0) == pytest.approx(-63.4375)
    assert radio.range() == pytest.approx(2.0)
    assert radio.range(walls=1) < 2.0
    assert radio.rssi(3.0, walls=2) < radio.rssi(3.0, walls=1) < radio.rssi(3.0)
    rows = threshold_sweep(radio, range(1, 11), walls=1, trials=300, seed=3)
    shares = [share for _, share, _ in rows]
    assert shares == sorted(shares, reverse=True)       # loss grows with distance
    assert pick_threshold(rows)[0] == 7 and shares[7] == 0.0   # the paper: losses from 8 m behind a wall


def test_radio_delivers_in_range_loses_beyond_and_is_seeded():
    radio = RadioChannel()
    near = Message("box", "a", "b", {}, 0.0, 100, 1.0)
    far = Message("box", "a", "b", {}, 0.0, 100, 40.0)
    assert radio.deliver(near, random.Random(1)) == pytest.approx(radio.latency + 800 / radio.bitrate)
    assert radio.deliver(far, random.Random(1)) is None
    edge = 10 ** ((radio.tx_power_dbm - radio.sensitivity_dbm - 0.5) / 20)  # inside the fade margin
    rng_a, rng_b = random.Random(5), random.Random(5)
    fates = [radio.deliver(Message("b", "a", "b", {}, 0.0, 8, edge), rng_a) is None for _ in range(200)]
    assert fates == [radio.deliver(Message("b", "a", "b", {}, 0.0, 8, edge), rng_b) is None for _ in range(200)]
    assert 0 < sum(fates) < 200  # in the fade margin some frames are lost, some arrive


def test_generated_mazes_are_connected_and_round_trip_through_meta():
    maze = generate(6, 6, seed=4, cell=5 / 6, loops=0.0)
    assert maze.is_connected() and len(maze.vertices()) == 24
    assert maze.cell_graph().number_of_edges() == 35  # a perfect maze: a tree over 36 cells
    assert from_meta(maze.meta()).vertices() == maze.vertices()
    assert generate(6, 6, seed=4, cell=5 / 6, loops=0.0).meta() == maze.meta()
    assert generate(6, 6, seed=4, cell=5 / 6, loops=0.2).cell_graph().number_of_edges() > 35
    with pytest.raises(ValueError):
        from_meta({"rows": 2, "cols": 2, "cell": 1, "east": ["1"], "north": []})


def test_a_straight_corridor_cell_is_not_a_vertex():
    maze = Maze(1, 3)
    maze.open_wall((0, 0), (0, 1))
    maze.open_wall((0, 1), (0, 2))
    assert maze.vertices() == [(0, 0), (0, 2)]
    assert maze.graph().edges[(0, 0), (0, 2)]["length"] == pytest.approx(1.0)


def test_exploration_visits_every_reachable_cell_once_over():
    maze = generate(5, 5, seed=2)
    explorer = Explorer((0, 0))
    here, moves = (0, 0), 0
    while True:
        explorer.sense(here, maze.open_directions(here))
        nxt = explorer.next_cell()
        if nxt is None:
            break
        assert nxt in maze.neighbours(here)        # one cell at a time, through open sides
        here, moves = nxt, moves + 1
    assert explorer.visited == set(maze.cells())
    assert moves <= 2 * len(maze.cells())


def test_the_drive_follows_the_icc_and_the_encoders_count_pulses():
    x, y, yaw = icc_step((0.0, 0.0, 0.0), 0.1, 0.2, 0.2, 1.0)
    assert yaw == pytest.approx(0.5)
    radius = 0.15 / 0.5
    assert (x, y) == pytest.approx((radius * math.sin(0.5), radius * (1 - math.cos(0.5))))
    encoders = Encoders(0.025, 200, 0.2)
    assert encoders.advance(0.01, 0.0) == (12, 0)  # 0.01 m / 0.785 mm = 12.7 pulses
    encoders.advance(0.001, 0.0)
    assert encoders.left_pulses == math.floor(0.011 / encoders.dpp) == 14  # fractions carry over


def test_a_link_out_of_free_space_range_is_refused_without_a_ray_test():
    """usable() answers as link_rssi() does; a pair beyond the threshold's free-space
    range (gains included) is refused before its walls are counted."""
    from petriflow.world import World

    world = World({"plane": True, "gravity": 0.0,
                   "boxes": [{"id": "w1", "size": [0.04, 2, 0.3], "position": [1, 0, 0.15]}],
                   "robots": [{"id": "a", "urdf": "petriflow.agents:robots/diffdrive.urdf", "position": [0.5, 0]},
                              {"id": "b", "urdf": "petriflow.agents:robots/diffdrive.urdf", "position": [1.5, 0]},
                              {"id": "c", "urdf": "petriflow.agents:robots/diffdrive.urdf", "position": [4.5, 0]}]})
    try:
        radio = RadioChannel()
        radio.bind(world)
        counted = []
        between = radio._walls.between
        radio._walls.between = lambda x, y: counted.append((x, y)) or between(x, y)
        for a, b in (("a", "b"), ("a", "c"), ("b", "c")):
            assert radio.usable(a, b) == (radio.link_rssi(a, b) > radio.threshold_dbm)
        counted.clear()
        assert not radio.usable("a", "c") and counted == []      # 4 m apart: beyond 2 m, no ray test
        assert radio.usable("a", "b") and counted == [("a", "b")]  # 1 m through one wall: counted, heard
        radio.gains_db = {"c": 20}                                 # a 20 dB antenna: 20 m in free space
        assert radio.usable("a", "c") == (radio.link_rssi("a", "c") > radio.threshold_dbm) is True
    finally:
        world.close()
