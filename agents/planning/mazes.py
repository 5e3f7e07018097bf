"""Test maps like the paper's Fig. 12: spiral, labyrinth and zig-zag occupancy grids.

Seed 003 §5.1 checks its planner on "a spiral map, labyrinth map and zig-zag map type"
at the planning resolution (320 × 240 cells) and finds every path in under 30 ms. These
generators draw such maps, deterministically (the labyrinth from a seed), for the
benchmark and the tests. Each returns a :class:`Maze`: the grid (``True`` occupied,
indexed ``[row, col]``), a start and a goal far apart along the corridor, and a name.

* :func:`spiral`: nested rectangular walls, each with one gap, the gaps alternating
  between opposite corners, so the corridor winds from the outside to the centre.
* :func:`labyrinth`: a perfect maze (one path between any two cells) carved by a
  seeded depth-first search over a lattice of rooms.
* :func:`zigzag`: parallel walls from alternate sides, so the corridor runs back and
  forth across the map.

Walls are ``wall`` cells thick and corridors ``corridor`` cells wide; walls at least
two cells thick keep a diagonal move from slipping through a wall corner even when
corners may be cut.

Examples:
    >>> maze = spiral()
    >>> maze.grid.shape, maze.grid.dtype, maze.start, maze.goal
    ((240, 320), dtype('bool'), (3, 3), (120, 160))
    >>> bool(maze.grid[maze.start]), bool(maze.grid[maze.goal])
    (False, False)
    >>> [m.name for m in all_mazes()]
    ['spiral', 'labyrinth', 'zigzag']
"""

from __future__ import annotations

import random
from dataclasses import dataclass

import numpy as np

__all__ = ["Maze", "spiral", "labyrinth", "zigzag", "all_mazes"]


@dataclass(frozen=True)
class Maze:
    """An occupancy grid with a start and a goal cell.

    Attributes:
        name: what kind of map it is.
        grid: boolean array, ``True`` where occupied.
        start: ``(row, col)`` start cell (free).
        goal: ``(row, col)`` goal cell (free).
    """

    name: str
    grid: np.ndarray
    start: tuple[int, int]
    goal: tuple[int, int]


def _framed(rows: int, cols: int, wall: int) -> np.ndarray:
    grid = np.zeros((rows, cols), bool)
    grid[:wall, :] = grid[-wall:, :] = grid[:, :wall] = grid[:, -wall:] = True
    return grid


def spiral(rows: int = 240, cols: int = 320, corridor: int = 8, wall: int = 3) -> Maze:
    """A rectangular spiral: start in the outer corridor's corner, goal at the centre.

    Args:
        rows: grid height (cells).
        cols: grid width (cells).
        corridor: corridor width (cells).
        wall: wall thickness (cells).

    Examples:
        >>> small = spiral(17, 23, corridor=2, wall=1)
        >>> print("\\n".join("".join("#" if v else "." for v in row) for row in small.grid))
        #######################
        #.....................#
        #.....................#
        #..#..##############..#
        #..#...............#..#
        #..#...............#..#
        #..#..###########..#..#
        #..#..#.........#..#..#
        #..#..#.........#..#..#
        #..#..#.........#..#..#
        #..#..########..#..#..#
        #..#...............#..#
        #..#...............#..#
        #..#################..#
        #.....................#
        #.....................#
        #######################
        >>> small.start, small.goal
        ((1, 1), (8, 11))
    """
    grid = _framed(rows, cols, wall)
    pitch = corridor + wall
    ring = 1
    while True:
        top, left = ring * pitch, ring * pitch
        bottom, right = rows - ring * pitch, cols - ring * pitch
        if bottom - top < 2 * wall + corridor or right - left < 2 * wall + corridor:
            break
        grid[top:top + wall, left:right] = True
        grid[bottom - wall:bottom, left:right] = True
        grid[top:bottom, left:left + wall] = True
        grid[top:bottom, right - wall:right] = True
        # one gap per ring, at the top-left on odd rings and bottom-right on even ones,
        # so the corridor goes half-way round each ring before it can turn inward
        if ring % 2:
            grid[top:top + wall, left + wall:left + wall + corridor] = False
        else:
            grid[bottom - wall:bottom, right - wall - corridor:right - wall] = False
        ring += 1
    start = (wall, wall)
    goal = (rows // 2, cols // 2)
    grid[goal] = False
    return Maze("spiral", grid, start, goal)


def labyrinth(rows: int = 240, cols: int = 320, corridor: int = 6, wall: int = 2, seed: int = 3) -> Maze:
    """A perfect maze from a seeded depth-first search; start top-left, goal bottom-right.

    Args:
        rows: grid height (cells).
        cols: grid width (cells).
        corridor: room and passage width (cells).
        wall: wall thickness (cells).
        seed: seed of the carving order (the same seed gives the same maze).

    Examples:
        >>> bool((labyrinth(seed=1).grid == labyrinth(seed=1).grid).all())
        True
        >>> bool((labyrinth(seed=1).grid == labyrinth(seed=2).grid).all())
        False
    """
    pitch = corridor + wall
    room_rows = (rows - wall) // pitch
    room_cols = (cols - wall) // pitch
    grid = np.ones((rows, cols), bool)

    def room(r: int, c: int) -> tuple[int, int]:
        return wall + r * pitch, wall + c * pitch

    for r in range(room_rows):
        for c in range(room_cols):
            top, left = room(r, c)
            grid[top:top + corridor, left:left + corridor] = False
    rng = random.Random(seed)
    seen = {(0, 0)}
    stack = [(0, 0)]
    while stack:
        r, c = stack[-1]
        options = [(r + dr, c + dc) for dr, dc in ((-1, 0), (1, 0), (0, -1), (0, 1))
                   if 0 <= r + dr < room_rows and 0 <= c + dc < room_cols and (r + dr, c + dc) not in seen]
        if not options:
            stack.pop()
            continue
        nr, nc = options[int(rng.random() * len(options))]
        top, left = room(min(r, nr), min(c, nc))
        if nr != r:  # knock down the wall below the upper room
            grid[top + corridor:top + pitch, left:left + corridor] = False
        else:  # the wall right of the left room
            grid[top:top + corridor, left + corridor:left + pitch] = False
        seen.add((nr, nc))
        stack.append((nr, nc))
    start = room(0, 0)
    last = room(room_rows - 1, room_cols - 1)
    goal = (last[0] + corridor - 1, last[1] + corridor - 1)
    return Maze("labyrinth", grid, start, goal)


def zigzag(rows: int = 240, cols: int = 320, corridor: int = 12, wall: int = 4) -> Maze:
    """Vertical walls alternately from the top and from the bottom edge: the corridor
    zig-zags from the left edge to the right one.

    Args:
        rows: grid height (cells).
        cols: grid width (cells).
        corridor: corridor width and gap length (cells).
        wall: wall thickness (cells).

    Examples:
        >>> maze = zigzag(60, 80, corridor=6, wall=2)
        >>> maze.start, maze.goal
        ((30, 2), (30, 77))
    """
    grid = _framed(rows, cols, wall)
    pitch = corridor + wall
    left = wall + corridor
    from_top = True
    while left + wall + corridor <= cols - wall:
        if from_top:
            grid[:rows - wall - corridor, left:left + wall] = True
        else:
            grid[wall + corridor:, left:left + wall] = True
        from_top = not from_top
        left += pitch
    start = (rows // 2, wall)
    goal = (rows // 2, cols - wall - 1)
    return Maze("zigzag", grid, start, goal)


def all_mazes(rows: int = 240, cols: int = 320) -> list[Maze]:
    """The three benchmark maps at one size (default the paper's 320 × 240)."""
    return [spiral(rows, cols), labyrinth(rows, cols), zigzag(rows, cols)]
