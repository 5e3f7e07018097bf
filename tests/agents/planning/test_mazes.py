"""The benchmark maps (seed 003 Fig. 12): spiral, labyrinth and zig-zag at 320 × 240."""

from __future__ import annotations

import math

import numpy as np
import pytest

from petriflow.agents.planning.mazes import all_mazes, labyrinth, spiral, zigzag


@pytest.mark.parametrize("maze", all_mazes(), ids=lambda m: m.name)
def test_maze_is_320x240_with_a_long_corridor_between_start_and_goal(maze, oracle):
    """Each map is 240 rows × 320 columns, start and goal free and connected, and the
    shortest path is many times the straight-line distance (a real maze)."""
    assert maze.grid.shape == (240, 320) and maze.grid.dtype == bool
    assert not maze.grid[maze.start] and not maze.grid[maze.goal]
    distance = oracle(maze.grid, maze.start)[maze.goal]
    assert math.isfinite(distance)
    assert distance > 4 * math.dist(maze.start, maze.goal)


@pytest.mark.parametrize("make", [spiral, labyrinth, zigzag])
def test_mazes_are_deterministic(make):
    """The same arguments draw the same map."""
    a, b = make(), make()
    assert np.array_equal(a.grid, b.grid) and (a.start, a.goal) == (b.start, b.goal)


def test_labyrinth_seed_changes_the_maze():
    """Another seed carves another maze."""
    assert not np.array_equal(labyrinth(seed=1).grid, labyrinth(seed=2).grid)


@pytest.mark.parametrize("maze", all_mazes(), ids=lambda m: m.name)
def test_walls_do_not_leak_at_corners(maze, oracle):
    """Walls are at least two cells thick: allowing corner cuts changes no path's route
    between start and goal much (it only trims corners)."""
    strict = oracle(maze.grid, maze.start)[maze.goal]
    loose = oracle(maze.grid, maze.start, cut_corners=True)[maze.goal]
    assert loose <= strict and loose > 0.97 * strict
