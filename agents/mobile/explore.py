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
        self.visited: set[Cell] = set()
        self.known: set[Cell] = set()
        self.open: dict[Cell, list[str]] = {}

    @property
    def cell(self) -> Cell:
        return self.stack[-1] if self.stack else (0, 0)

    def sense(self, cell: Cell, open_sides: Iterable[str]) -> None:
        """The robot is in ``cell`` and sees these sides open."""
        sides = [s for s in open_sides if s in _OFFSET]
        self.visited.add(cell)
        self.open[cell] = sides

    def learn(self, cells: Iterable[Cell]) -> None:
        """Cells other agents have explored: not to be entered again."""
        self.known.update(tuple(c) for c in cells)

    def is_vertex(self, cell: Cell) -> bool:
        """Whether a sensed cell is a vertex of the topological map (not straight corridor)."""
        sides = set(self.open.get(cell, []))
        return sides not in STRAIGHT

    def next_cell(self) -> Cell | None:
        """Where to go next: a new cell, one cell back, or ``None`` when done."""
        while self.stack:
            here = self.stack[-1]
            for side in self.open.get(here, []):
                dr, dc = _OFFSET[side]
                there = (here[0] + dr, here[1] + dc)
                if there not in self.visited and there not in self.known and there not in self.stack:
                    self.stack.append(there)
                    return there
            self.stack.pop()
            if self.stack:
                return self.stack[-1]
        return None

    @property
    def done(self) -> bool:
        return not self.stack
