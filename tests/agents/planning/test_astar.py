"""A* (seed 003 §4.1): exact costs against Dijkstra, the paper variant's bound, errors,
tie-breaking and determinism."""

from __future__ import annotations

import math
import os
import subprocess
import sys

import numpy as np
import pytest

from petriflow.agents.planning.astar import COMPILED, VARIANTS, Plan, astar
from petriflow.agents.planning.errors import PlanningError
from petriflow.agents.planning.mazes import all_mazes

SQRT2 = math.sqrt(2.0)


def random_cases(seed: int, count: int = 12):
    """Seeded random maps (5..24 cells a side, 5..45 % obstacles) with free start and goal."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        rows, cols = (int(v) for v in rng.integers(5, 25, size=2))
        grid = rng.random((rows, cols)) < rng.uniform(0.05, 0.45)
        free = np.argwhere(~grid)
        if len(free) < 2:
            continue
        start, goal = (tuple(int(v) for v in free[i]) for i in rng.choice(len(free), 2, replace=False))
        yield grid, start, goal


def assert_valid_path(grid: np.ndarray, plan: Plan, start, goal, cut_corners: bool = False) -> None:
    cells = plan.cells
    assert cells[0].tolist() == list(start) and cells[-1].tolist() == list(goal)
    assert not grid[cells[:, 0], cells[:, 1]].any(), "path crosses an obstacle"
    steps = np.diff(cells, axis=0)
    assert (np.abs(steps).max(axis=1) == 1).all(), "path is not 8-connected"
    if not cut_corners:
        for (r, c), (dr, dc) in zip(cells[:-1], steps):
            if dr and dc:
                assert not grid[r + dr, c] and not grid[r, c + dc], "diagonal move cuts a corner"
    assert len({tuple(c) for c in cells.tolist()}) == len(cells), "path visits a cell twice"


@pytest.mark.parametrize("seed", range(25))
@pytest.mark.parametrize("cut_corners", [False, True])
def test_optimal_cost_equals_dijkstra(seed, cut_corners, oracle):
    """The optimal variant's path cost equals Dijkstra's distance on random maps."""
    for grid, start, goal in random_cases(seed):
        distance = oracle(grid, start, cut_corners=cut_corners)[goal]
        plan = astar(grid, start, goal, cut_corners=cut_corners)
        if math.isinf(distance):
            assert not plan.found and plan.cells.shape == (0, 2) and math.isinf(plan.cost)
            continue
        assert plan.found
        assert_valid_path(grid, plan, start, goal, cut_corners)
        assert plan.cost == pytest.approx(distance, abs=1e-9)


@pytest.mark.parametrize("seed", range(25))
def test_paper_variant_path_within_sqrt2_of_fewest_steps(seed, oracle):
    """The paper variant finds a path whenever one exists, valid, with between the
    fewest steps and √2 times as many (weighted A* with ε = √2)."""
    for grid, start, goal in random_cases(seed + 1000):
        fewest = oracle(grid, start, diagonal_cost=1.0)[goal]
        plan = astar(grid, start, goal, variant="paper")
        assert plan.found == (not math.isinf(fewest))
        if plan.found:
            assert_valid_path(grid, plan, start, goal)
            assert fewest <= plan.steps <= SQRT2 * fewest + 1e-9
            assert plan.cost == plan.steps


def test_paper_variant_can_take_more_steps_than_needed(oracle):
    """Euclidean h overestimates on diagonals, so some paper paths are not the fewest
    steps; seen on the benchmark's random maps (this is why it is not the default)."""
    longer = 0
    for seed in range(60):
        for grid, start, goal in random_cases(seed + 5000):
            plan = astar(grid, start, goal, variant="paper")
            if plan.found and plan.steps > oracle(grid, start, diagonal_cost=1.0)[goal]:
                longer += 1
    assert longer > 0


@pytest.mark.parametrize("maze", all_mazes(60, 80), ids=lambda m: m.name)
def test_mazes_solved_optimally(maze, oracle):
    """Each benchmark map type (small size) has a path, and A* finds the shortest."""
    plan = astar(maze.grid, maze.start, maze.goal)
    assert plan.found
    assert_valid_path(maze.grid, plan, maze.start, maze.goal)
    assert plan.cost == pytest.approx(oracle(maze.grid, maze.start)[maze.goal])


def test_unreachable_goal_is_a_no_path_result():
    """A walled-off goal gives found=False, an empty path and infinite cost, not an error."""
    grid = np.zeros((6, 6), bool)
    grid[2, :] = True
    for variant in VARIANTS:
        plan = astar(grid, (0, 0), (5, 5), variant=variant)
        assert not plan.found and plan.cells.shape == (0, 2)
        assert math.isinf(plan.cost) and math.isinf(plan.length)
        assert plan.expanded == 12  # every reachable cell was tried


def test_start_equal_to_goal_is_a_one_cell_path():
    """Start == goal: a path of one cell, no moves, cost 0."""
    plan = astar(np.zeros((3, 3), bool), (1, 2), (1, 2))
    assert plan.found and plan.cells.tolist() == [[1, 2]] and plan.steps == 0 and plan.cost == 0.0


@pytest.mark.parametrize("start, goal, message", [
    ((1, 1), (0, 0), "start (1, 1) is inside an obstacle"),
    ((0, 0), (1, 1), "goal (1, 1) is inside an obstacle"),
    ((-1, 0), (0, 0), "outside"),
    ((0, 0), (0, 3), "outside"),
    (("a", 0), (0, 0), "must be a (row, col) cell"),
])
def test_bad_start_or_goal_raises(start, goal, message):
    """A start or goal inside an obstacle or off the grid is a PlanningError."""
    grid = np.zeros((3, 3), bool)
    grid[1, 1] = True
    with pytest.raises(PlanningError, match=message.replace("(", r"\(").replace(")", r"\)")):
        astar(grid, start, goal)


def test_bad_variant_or_grid_raises():
    """An unknown variant or a grid that is not 2-D is a PlanningError."""
    with pytest.raises(PlanningError, match="unknown A\\* variant 'fast'"):
        astar(np.zeros((3, 3)), (0, 0), (1, 1), variant="fast")
    with pytest.raises(PlanningError, match="2-D"):
        astar(np.zeros(9), (0, 0), (1, 1))


def test_ties_broken_toward_the_target():
    """Among equal f the cell nearer the target goes first: on an open grid with many
    shortest paths, A* expands only the cells of the one it returns (diagonals first)."""
    grid = np.zeros((8, 10), bool)
    plan = astar(grid, (0, 0), (3, 6))
    assert plan.cells.tolist() == [[0, 0], [1, 1], [2, 2], [3, 3], [3, 4], [3, 5], [3, 6]]
    assert plan.expanded == len(plan.cells)
    paper = astar(grid, (0, 0), (3, 6), variant="paper")
    assert paper.steps == 6 and paper.expanded == len(paper.cells)


def test_exact_ties_go_to_the_lower_cell_index():
    """Mirror-image paths (equal f and h): the one through the lower row-major index wins."""
    grid = np.zeros((3, 3), bool)
    grid[1, 1] = True
    assert astar(grid, (0, 1), (2, 1)).cells.tolist() == [[0, 1], [0, 0], [1, 0], [2, 0], [2, 1]]
    assert astar(grid, (0, 1), (2, 1), cut_corners=True).cells.tolist() == [[0, 1], [1, 0], [2, 1]]


def test_corner_cutting_is_off_by_default():
    """Without cut_corners a diagonal move between two obstacles is refused."""
    grid = np.array([[0, 1], [1, 0]], bool)
    assert not astar(grid, (0, 0), (1, 1)).found
    assert astar(grid, (0, 0), (1, 1), cut_corners=True).cells.tolist() == [[0, 0], [1, 1]]


def test_repeated_searches_are_identical():
    """The same query gives the same path and counts, call after call, across grid sizes."""
    mazes = all_mazes(60, 80)
    first = [astar(m.grid, m.start, m.goal, variant=v) for m in mazes for v in VARIANTS]
    astar(np.zeros((5, 5), bool), (0, 0), (4, 4))  # another size in between
    again = [astar(m.grid, m.start, m.goal, variant=v) for m in mazes for v in VARIANTS]
    for a, b in zip(first, again):
        assert np.array_equal(a.cells, b.cells) and (a.expanded, a.visited) == (b.expanded, b.visited)


def test_grid_of_any_numeric_type_is_accepted():
    """Nonzero means occupied, whatever the dtype (bool, uint8 labels, floats)."""
    grid = np.zeros((4, 4), np.uint8)
    grid[1:3, 1] = 7
    reference = astar(grid.astype(bool), (2, 0), (2, 3))
    for kind in (np.uint8, np.int32, np.float64):
        assert np.array_equal(astar(grid.astype(kind), (2, 0), (2, 3)).cells, reference.cells)


_PLAIN_PYTHON = """
import json, numpy as np

from petriflow.agents.planning.astar import astar
from petriflow.agents.planning.mazes import all_mazes
out = [astar(m.grid, m.start, m.goal, variant=v).cells.tolist() for m in all_mazes(24, 32)
       for v in ("optimal", "paper")]
print(json.dumps(out))
"""


@pytest.mark.skipif(not COMPILED, reason="numba is not installed: the plain-Python path is the only one")
def test_plain_python_fallback_gives_the_same_paths():
    """Without the JIT (NUMBA_DISABLE_JIT=1, as without numba) the same code finds the same paths."""
    import json

    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    done = subprocess.run([sys.executable, "-W", "ignore", "-c", _PLAIN_PYTHON], env=env, check=True,
                          capture_output=True, text=True)
    plain = json.loads(done.stdout)
    compiled = [astar(m.grid, m.start, m.goal, variant=v).cells.tolist() for m in all_mazes(24, 32)
                for v in VARIANTS]
    assert plain == compiled
