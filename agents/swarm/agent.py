"""One swarm robot's state: its map of the maze, seed 000's history, what it will say.

A :class:`Scout` (registered ``swarm.scout``; the subnets declare ``state: swarm.scout``)
is made by ``swarm.wake`` and kept by the run. Its map is ``sides``: for every cell it
knows, the cell's open sides as a bit mask (:data:`SIDES`), from its own four rays or
from a neighbour's data. The data it shares is seed 000's history
(:class:`SwarmHistory`, the data and history arrays of
:class:`petriflow.agents.comm.framework.History`, with the same three rules): an item is
a cell ``(id, x, y, sides)``, its source the robot that sensed it.

Messages are seed 000's packets (:class:`~petriflow.agents.comm.framework.Message`,
codes 0-3, :func:`~petriflow.agents.comm.framework.plan` for Algorithm 1) and travel as
plain tuples ``(code, source, count, final, items)``. Sizes (:func:`packet_bytes`): a
header of a code byte, a two-byte source and a two-byte count (a swarm has more than
255 robots), and per item a two-byte cell id, x and y as half floats (seed 000's
vertex) and one byte of open sides.

Examples:
    >>> scout = Scout("robot1", 1, cols=4, rows=4, cell=1.0)
    >>> scout.cell_of(2.5, 1.5), scout.centre(6)
    (6, (2.5, 1.5))
    >>> scout.sense(6, OPEN["north"] | OPEN["east"]), scout.frontier_route(6, 5)
    (True, [10])
    >>> packet_bytes((3, 1, 1, False, [(6, 2.5, 1.5, 5)]))
    12
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import Any

from petriflow.agents.comm.framework import History, Message, plan
from petriflow.runtime.agents import AgentState

__all__ = ["Scout", "SwarmHistory", "OPEN", "SIDES", "packet_bytes"]

#: Open-side bits of a cell (north is +y).
OPEN = {"north": 1, "south": 2, "east": 4, "west": 8}
#: (side, row offset, column offset) in bit order.
SIDES = (("north", 1, 0), ("south", -1, 0), ("east", 0, 1), ("west", 0, -1))
#: Bytes of a packet header (code, two-byte source, two-byte count) and of one item.
HEADER_BYTES, ITEM_BYTES = 5, 7


def packet_bytes(packet: tuple) -> int:
    """Bytes of one packet on the air (header and items)."""
    return HEADER_BYTES + ITEM_BYTES * len(packet[4])


@dataclass
class SwarmHistory(History):
    """Seed 000's history (the same rules and arrays), with its rows also indexed by
    source, so new data of a source updates only that source's rows instead of
    scanning all of them (a swarm robot's history holds many sources)."""

    _source_rows: dict[int, list[list[int]]] = field(default_factory=dict, repr=False)
    #: Items kept so far: what the rules send a peer changes only when this grows.
    version: int = 0

    def _keep(self, source: int, item: Any, via: int) -> None:
        super()._keep(source, item, via)
        self.version += 1

    def _add_row(self, row: list[int]) -> None:
        super()._add_row(row)
        self._source_rows.setdefault(row[0], []).append(row)

    def _more(self, source: int, count: int, sender: int) -> None:
        for row in self._source_rows.get(source, ()):
            if row[1] not in (self.me, sender):
                row[3] += count


@dataclass(eq=False)
class Scout(AgentState):
    """The state of one swarm robot (see the module)."""

    name: str
    address: int
    cols: int = 1
    rows: int = 1
    cell: float = 1.0
    origin: tuple[float, float] = (0.0, 0.0)
    history: SwarmHistory | None = None
    sides: dict[int, int] = field(default_factory=dict)       # cell id -> open-side bits
    sensed: set = field(default_factory=set)                   # cells this robot sensed itself
    here: int = 0
    home: int = 0
    route: list = field(default_factory=list)
    explored: bool = False
    outbox: dict[str, list] = field(default_factory=dict)     # peer -> packets for the next frame
    asked: set = field(default_factory=set)                    # (peer, source) queries not answered yet
    names: dict[int, str] = field(default_factory=dict)        # address -> agent name, as heard
    planned: dict[str, int] = field(default_factory=dict)      # peer -> history version last planned for it
    horizon: int = 0                                           # cells around it whose data it keeps (0: all)
    sent_bytes: int = 0
    frames: int = 0

    def __post_init__(self) -> None:
        AgentState.__init__(self)
        if self.history is None:
            self.history = SwarmHistory(self.address)

    def to_token(self) -> dict[str, Any]:
        return {"agent": self.name, "cells": len(self.sides), "sensed": len(self.sensed),
                "sent_bytes": self.sent_bytes, "explored": self.explored}

    # The maze --------------------------------------------------------------------------
    def cell_of(self, x: float, y: float) -> int:
        col = min(max(int((x - self.origin[0]) // self.cell), 0), self.cols - 1)
        row = min(max(int((y - self.origin[1]) // self.cell), 0), self.rows - 1)
        return row * self.cols + col

    def centre(self, cell: int) -> tuple[float, float]:
        row, col = divmod(cell, self.cols)
        return (self.origin[0] + (col + 0.5) * self.cell, self.origin[1] + (row + 0.5) * self.cell)

    def _open_neighbours(self, cell: int):
        bits = self.sides.get(cell, 0)
        row, col = divmod(cell, self.cols)
        for bit, (_, dr, dc) in enumerate(SIDES):
            if bits >> bit & 1:
                r, c = row + dr, col + dc
                if 0 <= r < self.rows and 0 <= c < self.cols:
                    yield r * self.cols + c

    def sense(self, cell: int, bits: int) -> bool:
        """This robot sensed ``cell`` (open sides ``bits``): into the map and, as its
        own data, into the history; False if it knew the cell already."""
        self.sensed.add(cell)
        known = cell in self.sides
        self.sides[cell] = bits
        if known:
            return False
        x, y = self.centre(cell)
        self.history.add_own((cell, round(x, 2), round(y, 2), bits))
        return True

    def frontier_route(self, start: int, reach: int, around: int | None = None, within: int = 0) -> list[int]:
        """Cells from ``start`` (excluded) to the nearest cell nobody has mapped that
        an open side of a known cell leads into, through known cells, at most
        ``reach`` cells away (breadth first: the same answer every time), and, with
        ``around``, at most ``within`` rows and columns from that cell; ``[]`` when
        there is none."""
        if around is not None:
            row0, col0 = divmod(around, self.cols)
        parent = {start: start}
        queue = deque([(start, 0)])
        while queue:
            cell, depth = queue.popleft()
            if depth >= reach:
                continue
            for nxt in self._open_neighbours(cell):
                if nxt in parent:
                    continue
                parent[nxt] = cell
                if nxt not in self.sides:
                    if around is not None and (abs(nxt // self.cols - row0) > within or
                                               abs(nxt % self.cols - col0) > within):
                        continue
                    path = [nxt]
                    while path[-1] != start and parent[path[-1]] != start:
                        path.append(parent[path[-1]])
                    return path[::-1]
                queue.append((nxt, depth + 1))
        return []

    def route_to(self, start: int, goal: int) -> list[int]:
        """Cells from ``start`` (excluded) to ``goal`` through known cells (breadth first)."""
        if start == goal:
            return []
        parent = {start: start}
        queue = deque([start])
        while queue:
            cell = queue.popleft()
            for nxt in self._open_neighbours(cell):
                if nxt in parent or nxt not in self.sides:
                    continue
                parent[nxt] = cell
                if nxt == goal:
                    path = [goal]
                    while parent[path[-1]] != start:
                        path.append(parent[path[-1]])
                    return path[::-1]
                queue.append(nxt)
        return []

    # Messages (seed 000's processes 4 and 5) -----------------------------------------
    def plan_for(self, peer: str, address: int) -> None:
        """Algorithm 1 towards a neighbour heard now: what it should get goes into the
        next frame (a query per source with pending data, unless one is unanswered;
        every item of a source never sent to it)."""
        self.names[address] = peer
        if self.planned.get(peer) == self.history.version:
            return  # nothing kept since the last plan for this peer: the rules send it nothing new
        self.planned[peer] = self.history.version
        for message in plan(self.history, address):
            if message.code == 0:
                if (peer, message.source) in self.asked:
                    continue
                self.asked.add((peer, message.source))
            else:
                self.history.sent(address, message.source, list(message.vertices))
            self._queue(peer, message)

    def _queue(self, peer: str, message: Message) -> None:
        box = self.outbox.setdefault(peer, [])
        box.append((message.code, message.source, message.count, message.final, list(message.vertices)))
        if len(box) == 1 and sum(1 for b in self.outbox.values() if b) == 1:
            self.touch("outbox")  # the outbox was empty: the guards' answer changes

    def frame(self) -> dict[str, Any]:
        """The next frame: every queued packet, by receiver; the outbox empties."""
        to = {peer: packets for peer, packets in sorted(self.outbox.items()) if packets}
        self.outbox = {}
        self.touch("outbox")
        size = sum(packet_bytes(p) for packets in to.values() for p in packets)
        self.sent_bytes += size
        self.frames += 1
        return {"to": to, "size": size, "from": self.address}

    def receive(self, sender: str, address: int, packet: tuple) -> int:
        """One packet from a neighbour; returns the number of cells new to this robot."""
        code, source, count, final, items = packet
        self.names[address] = sender
        history = self.history
        if code == 0:
            wanted = count - history.count(source)
            if wanted > 0:
                self._queue(sender, Message(1, source, wanted, self.address, address))
            return 0
        if code == 1:
            self.asked.discard((sender, source))
            chosen = history.unsent(address, source)[:count]
            if chosen:
                history.sent(address, source, chosen)
                self._queue(sender, Message(2, source, history.count(source), self.address, address, list(chosen)))
            return 0
        items = [tuple(i) for i in items]
        if self.horizon:  # a robot keeps (and passes on) the map around it only
            row, col = divmod(self.here, self.cols)
            reach = self.horizon
            items = [i for i in items if abs(i[0] // self.cols - row) <= reach and abs(i[0] % self.cols - col) <= reach]
            if not items:
                return 0
        new = 0
        for item in history.receive(address, source, items):
            cell, bits = item[0], item[3]
            if cell not in self.sides:
                new += 1
            self.sides.setdefault(cell, bits)
        return new
