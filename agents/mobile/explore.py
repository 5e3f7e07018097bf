"""Depth-first exploration of a maze of cells by a robot that senses the walls around it.

The robot stands in a cell, learns which sides are open (its distance sensors), and
:meth:`Explorer.next_cell` says where to go: the first open neighbour that is neither
visited nor known from other agents, else back one cell along the way it came
(backtracking), else ``None``: everything reachable is explored. Cells learnt from
others (:meth:`Explorer.learn`) are not entered again, so robots that share what they
found split the maze between them.

Examples:
    >>> explorer = Explorer((0, 0))
    >>> explorer.sense((0, 0), ["north", "east"])
    >>> explorer.next_cell()
    (1, 0)
    >>> explorer.sense((1, 0), ["south"])
    >>> explorer.next_cell()        # dead end: back
    (0, 0)
    >>> explorer.learn([(0, 1)])    # another robot has been east
    >>> explorer.next_cell() is None
    True
"""

from __future__ import annotations

from collections.abc import Iterable

__all__ = ["STRAIGHT", "Explorer"]

Cell = tuple[int, int]
_OFFSET = {"north": (1, 0), "south": (-1, 0), "east": (0, 1), "west": (0, -1)}
#: Open sides of a cell in the middle of a straight corridor (not a map vertex).
STRAIGHT = ({"north", "south"}, {"east", "west"})


class Explorer:
    """A robot's depth-first exploration state (see the module)."""

    def __init__(self, start: Cell) -> None:
        self.stack: list[Cell] = [start]
        self.here: Cell = start
        self.visited: set[Cell] = set()
        self.known: set[Cell] = set()
        self.open: dict[Cell, list[str]] = {}

    @property
    def cell(self) -> Cell:
        """Where the robot is (the last cell it sensed, or its start)."""
        return self.here

    def sense(self, cell: Cell, open_sides: Iterable[str]) -> None:
        """The robot is in ``cell`` and sees these sides open."""
        sides = [s for s in open_sides if s in _OFFSET]
        self.visited.add(cell)
        self.open[cell] = sides
        self.here = cell

    def learn(self, cells: Iterable[Cell]) -> None:
        """Cells other agents have explored: not to be entered again."""
        self.known.update(tuple(c) for c in cells)

    def is_vertex(self, cell: Cell) -> bool:
        """Whether a sensed cell is a vertex of the topological map (not straight corridor)."""
        sides = set(self.open.get(cell, []))
        return sides not in STRAIGHT

    def _new(self, cell: Cell) -> list[Cell]:
        out = []
        for side in self.open.get(cell, []):
            dr, dc = _OFFSET[side]
            there = (cell[0] + dr, cell[1] + dc)
            if there not in self.visited and there not in self.known:
                out.append(there)
        return out

    def next_cell(self) -> Cell | None:
        """Where to go next: a new cell, one cell back, or ``None`` when done. When the
        way back is used up (after a detour, or cells forgotten), the robot goes to the
        nearest visited cell that still opens onto an unexplored one."""
        while self.stack:
            here = self.stack[-1]
            for there in self._new(here):
                if there not in self.stack:
                    self.stack.append(there)
                    return there
            self.stack.pop()
            if self.stack:
                return self.stack[-1]
        path = self._to_frontier()
        if path is None:
            return None
        self.stack = path
        return path[1] if len(path) > 1 else self.next_cell()

    def _to_frontier(self) -> list[Cell] | None:
        """Visited cells from here to the nearest one with an unexplored open side."""
        from collections import deque

        start = self.here
        if start not in self.visited:
            return None
        parent: dict[Cell, Cell | None] = {start: None}
        queue = deque([start])
        while queue:
            cell = queue.popleft()
            if self._new(cell):
                path = [cell]
                while parent[path[-1]] is not None:
                    path.append(parent[path[-1]])
                return path[::-1]
            for side in self.open.get(cell, []):
                dr, dc = _OFFSET[side]
                there = (cell[0] + dr, cell[1] + dc)
                if there in self.visited and there not in parent:
                    parent[there] = cell
                    queue.append(there)
        return None

