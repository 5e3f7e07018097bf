"""Mazes of square cells: generated from a seed, built as a world, and their ground truth.

A :class:`Maze` is ``rows x cols`` cells of side ``cell`` metres, cell ``(0, 0)`` at the
south-west corner (``origin``), with a wall or an opening between every two
neighbouring cells and walls all round. :func:`generate` carves a perfect maze
(randomised depth-first search, every cell reachable by exactly one path) and then
opens ``loops`` of the remaining inner walls, so there are cycles as in a real
building. :meth:`Maze.world` is its pybullet world description (thin wall boxes, the
robots), with the maze itself in ``meta.maze`` so metrics can compute the ground
truth from the world alone (:func:`from_meta`). That section of a world file is
declared (:data:`MAZE`, read and checked with the file's lines when the world loads,
by a run whose actions declare it; its metrics read it from ``record.settings``), as
is a tiled world's ``meta.tiles`` (:data:`TILES`).

The **topological map** of a maze has a vertex at every cell that is not the middle
of a straight corridor: a dead end, a corner, a junction (:meth:`Maze.vertices`); its
edges are the corridors between them (:meth:`Maze.graph`).

Examples:
    >>> maze = generate(4, 4, seed=1)
    >>> len(maze.cells()), maze.is_connected()
    (16, True)
    >>> from_meta(maze.meta()).walls() == maze.walls()
    True
    >>> from_meta(MAZE.read(maze.meta())).walls() == maze.walls()
    True
    >>> vertex_count = len(maze.vertices()); 2 <= vertex_count <= 16
    True
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field
from typing import Any

import networkx as nx

from petriflow.runtime.settings import Section, Setting

__all__ = ["DIRECTIONS", "MAZE", "TILES", "Cell", "Maze", "from_meta", "generate"]

_WALLS = Setting(str, doc="'1' (a wall) or '0' (an opening) per neighbouring pair of cells")

#: A maze world's ``meta.maze`` (:meth:`Maze.meta` writes it); ``rows: 0``: no maze.
MAZE = Section("maze", {
    "rows": Setting(int, 0, "rows of cells (0: the world has no maze)", low=0),
    "cols": Setting(int, 0, "cells per row", low=0),
    "cell": Setting(float, 1.0, "side of a cell (m)", low=1e-9),
    "origin": Setting(list, [0.0, 0.0], "world x, y of the south-west corner", items=Setting(float)),
    "east": Setting(list, [], "per row, the walls east of its cells but the last", items=_WALLS),
    "north": Setting(list, [], "per row but the last, the walls north of its cells", items=_WALLS),
}, doc="the maze of a maze world: its ground truth")

#: A world tiled with copies of one maze (``meta.tiles``): how many, and the rows
#: from one copy to the next.
TILES = Section("tiles", {
    "count": Setting(int, 1, "copies of the maze (their cell ids differ)", low=1),
    "pitch_rows": Setting(int, 0, "rows of cells from one copy to the next", low=0),
}, doc="copies of a maze in one world")

Cell = tuple[int, int]
#: Neighbour offsets (row, col) by direction name; north is +y.
DIRECTIONS = {"north": (1, 0), "south": (-1, 0), "east": (0, 1), "west": (0, -1)}


@dataclass
class Maze:
    """A maze of ``rows x cols`` cells of side ``cell`` m, south-west corner at ``origin``.

    ``east[r][c]`` is a wall between ``(r, c)`` and ``(r, c + 1)``; ``north[r][c]``
    between ``(r, c)`` and ``(r + 1, c)``. The outer boundary is always walled.
    """

    rows: int
    cols: int
    cell: float = 0.5
    origin: tuple[float, float] = (0.0, 0.0)
    east: list[list[bool]] = field(default_factory=list)
    north: list[list[bool]] = field(default_factory=list)

    def __post_init__(self) -> None:
        if self.rows < 1 or self.cols < 1 or not self.cell > 0:
            raise ValueError(f"a maze needs at least one cell of positive size, got {self.rows} x {self.cols}"
                             f" of {self.cell} m")
        if not self.east:
            self.east = [[True] * (self.cols - 1) for _ in range(self.rows)]
        if not self.north:
            self.north = [[True] * self.cols for _ in range(self.rows - 1)]

    # Structure ----------------------------------------------------------------------
    def cells(self) -> list[Cell]:
        return [(r, c) for r in range(self.rows) for c in range(self.cols)]

    def inside(self, cell: Cell) -> bool:
        return 0 <= cell[0] < self.rows and 0 <= cell[1] < self.cols

    def is_open(self, cell: Cell, direction: str) -> bool:
        """Whether the robot can move from ``cell`` one cell in ``direction``."""
        dr, dc = DIRECTIONS[direction]
        r, c = cell
        other = (r + dr, c + dc)
        if not self.inside(other):
            return False
        if dr:
            return not self.north[min(r, other[0])][c]
        return not self.east[r][min(c, other[1])]

    def open_directions(self, cell: Cell) -> list[str]:
        return [d for d in DIRECTIONS if self.is_open(cell, d)]

    def neighbours(self, cell: Cell) -> list[Cell]:
        return [(cell[0] + DIRECTIONS[d][0], cell[1] + DIRECTIONS[d][1]) for d in self.open_directions(cell)]

    def open_wall(self, a: Cell, b: Cell) -> None:
        """Remove the wall between neighbouring cells ``a`` and ``b``."""
        (ra, ca), (rb, cb) = a, b
        if abs(ra - rb) + abs(ca - cb) != 1 or not (self.inside(a) and self.inside(b)):
            raise ValueError(f"cells {a} and {b} are not neighbours inside the maze")
        if ra != rb:
            self.north[min(ra, rb)][ca] = False
        else:
            self.east[ra][min(ca, cb)] = False

    def walls(self) -> int:
        """Inner walls left."""
        return sum(map(sum, self.east)) + sum(map(sum, self.north))

    def is_connected(self) -> bool:
        return nx.is_connected(self.cell_graph())

    def cell_graph(self) -> nx.Graph:
        """Every cell, an edge between open neighbours."""
        graph = nx.Graph()
        graph.add_nodes_from(self.cells())
        for cell in self.cells():
            for other in self.neighbours(cell):
                graph.add_edge(cell, other)
        return graph

    def is_vertex(self, cell: Cell) -> bool:
        """A dead end, corner or junction: not the middle of a straight corridor."""
        directions = self.open_directions(cell)
        return not (len(directions) == 2 and set(directions) in ({"north", "south"}, {"east", "west"}))

    def vertices(self) -> list[Cell]:
        """The topological map's vertices (cells), row by row."""
        return [cell for cell in self.cells() if self.is_vertex(cell)]

    def graph(self) -> nx.Graph:
        """The topological map: vertices, and an edge per corridor between two of them
        (weighted by its length in metres)."""
        graph = nx.Graph()
        vertices = set(self.vertices())
        graph.add_nodes_from(vertices)
        for start in vertices:
            for direction in self.open_directions(start):
                dr, dc = DIRECTIONS[direction]
                cell, steps = (start[0] + dr, start[1] + dc), 1
                while cell not in vertices:  # a straight corridor cell: go on the same way
                    cell, steps = (cell[0] + dr, cell[1] + dc), steps + 1
                graph.add_edge(start, cell, length=steps * self.cell)
        return graph

    # Geometry -----------------------------------------------------------------------
    def centre(self, cell: Cell) -> tuple[float, float]:
        """World (x, y) of a cell's centre."""
        return (self.origin[0] + (cell[1] + 0.5) * self.cell, self.origin[1] + (cell[0] + 0.5) * self.cell)

    def cell_at(self, x: float, y: float) -> Cell:
        """The cell containing the world point (clamped to the maze)."""
        c = int((x - self.origin[0]) // self.cell)
        r = int((y - self.origin[1]) // self.cell)
        return (min(max(r, 0), self.rows - 1), min(max(c, 0), self.cols - 1))

    @property
    def size(self) -> tuple[float, float]:
        return (self.cols * self.cell, self.rows * self.cell)

    # Worlds -------------------------------------------------------------------------
    def meta(self) -> dict[str, Any]:
        """The maze as plain data (``meta.maze`` of its world)."""
        return {"rows": self.rows, "cols": self.cols, "cell": self.cell, "origin": list(self.origin),
                "east": ["".join("1" if w else "0" for w in row) for row in self.east],
                "north": ["".join("1" if w else "0" for w in row) for row in self.north]}

    def boxes(self, thickness: float = 0.04, height: float = 0.3, colour: str = "grey") -> list[dict[str, Any]]:
        """Wall boxes: the boundary and every inner wall, runs of walls merged into one box."""
        x0, y0 = self.origin
        width, depth = self.size
        boxes = [
            {"id": "wall_s", "size": [width + thickness, thickness, height], "position": [x0 + width / 2, y0, height / 2]},
            {"id": "wall_n", "size": [width + thickness, thickness, height],
             "position": [x0 + width / 2, y0 + depth, height / 2]},
            {"id": "wall_w", "size": [thickness, depth + thickness, height], "position": [x0, y0 + depth / 2, height / 2]},
            {"id": "wall_e", "size": [thickness, depth + thickness, height],
             "position": [x0 + width, y0 + depth / 2, height / 2]},
        ]
        # vertical walls (east sides), merged along each column line
        for c in range(self.cols - 1):
            x = x0 + (c + 1) * self.cell
            r = 0
            while r < self.rows:
                if not self.east[r][c]:
                    r += 1
                    continue
                start = r
                while r < self.rows and self.east[r][c]:
                    r += 1
                length = (r - start) * self.cell
                boxes.append({"id": f"wall_v{c}_{start}", "size": [thickness, length + thickness, height],
                              "position": [x, y0 + start * self.cell + length / 2, height / 2]})
        for r in range(self.rows - 1):
            y = y0 + (r + 1) * self.cell
            c = 0
            while c < self.cols:
                if not self.north[r][c]:
                    c += 1
                    continue
                start = c
                while c < self.cols and self.north[r][c]:
                    c += 1
                length = (c - start) * self.cell
                boxes.append({"id": f"wall_h{r}_{start}", "size": [length + thickness, thickness, height],
                              "position": [x0 + start * self.cell + length / 2, y, height / 2]})
        for box in boxes:
            box["colour"] = colour
            box["position"] = [round(v, 6) for v in box["position"]]
            box["size"] = [round(v, 6) for v in box["size"]]
        return boxes

    def world(self, robots: list[dict[str, Any]], *, dt: float = 0.05, height: float = 0.3,
              thickness: float = 0.04) -> dict[str, Any]:
        """A world description: a floor, the walls, ``robots`` as given, the maze in ``meta.maze``."""
        return {"dt": dt, "gravity": -9.81, "plane": True, "boxes": self.boxes(thickness, height),
                "robots": robots, "meta": {"maze": self.meta()}}


def generate(rows: int, cols: int, seed: int, *, cell: float = 0.5, loops: float = 0.1,
             origin: tuple[float, float] = (0.0, 0.0)) -> Maze:
    """A maze carved by randomised depth-first search from cell (0, 0), then with a
    fraction ``loops`` of the remaining inner walls opened (cycles)."""
    if not 0 <= loops <= 1:
        raise ValueError(f"loops is a fraction from 0 to 1, got {loops}")
    maze = Maze(rows, cols, cell, origin)
    rng = random.Random(seed)
    seen = {(0, 0)}
    stack = [(0, 0)]
    while stack:
        r, c = stack[-1]
        options = [(r + dr, c + dc) for dr, dc in DIRECTIONS.values()
                   if maze.inside((r + dr, c + dc)) and (r + dr, c + dc) not in seen]
        if not options:
            stack.pop()
            continue
        nxt = rng.choice(options)
        maze.open_wall((r, c), nxt)
        seen.add(nxt)
        stack.append(nxt)
    inner = [((r, c), (r, c + 1)) for r in range(rows) for c in range(cols - 1) if maze.east[r][c]]
    inner += [((r, c), (r + 1, c)) for r in range(rows - 1) for c in range(cols) if maze.north[r][c]]
    for a, b in rng.sample(inner, round(loops * len(inner))):
        maze.open_wall(a, b)
    return maze


def from_meta(data: dict[str, Any]) -> Maze:
    """The maze of a world's ``meta.maze`` (:meth:`Maze.meta`)."""
    try:
        rows, cols = int(data["rows"]), int(data["cols"])
        east = [[ch == "1" for ch in row] for row in data["east"]]
        north = [[ch == "1" for ch in row] for row in data["north"]]
        maze = Maze(rows, cols, float(data["cell"]), tuple(data.get("origin", (0.0, 0.0))), east, north)
    except (KeyError, TypeError, ValueError) as exc:
        raise ValueError(f"meta.maze is not a maze description: {exc}") from None
    if len(east) != rows or any(len(row) != cols - 1 for row in east) or len(north) != rows - 1 \
            or any(len(row) != cols for row in north):
        raise ValueError(f"meta.maze: wall lists do not match {rows} x {cols} cells")
    return maze
