"""One swarm robot's state: its map of the maze, seed 000's history, what it will say.

A :class:`Scout` (registered ``swarm.scout``; the subnets declare ``state: swarm.scout``)
is made by ``swarm.wake`` and kept by the run. Its map is ``sides``: for every cell it
knows, the cell's open sides as a bit mask (:data:`SIDES`), from its own four rays or
from a neighbour's data. The data it shares is seed 000's history
(:class:`SwarmHistory`, the data and history arrays of
:class:`petriflow.agents.comm.framework.History`, with the same three rules): an item is
a cell ``(id, x, y, sides)``, its source the robot that sensed it.

Messages are seed 000's packets (:class:`~petriflow.agents.comm.framework.Packet`,
codes 0-3, :func:`~petriflow.agents.comm.framework.plan` for Algorithm 1). On the air
they travel as plain tuples ``(code, source, count, final, items)``, several to a frame
(the runtime :class:`~petriflow.runtime.channel_models.Message` whose payload is
:meth:`Scout.frame`'s dict): the same packet without its addresses (a frame says who
sent it, and the receiver is the key it is filed under), kept a tuple because a swarm
files hundreds of thousands of them. Sizes (:func:`packet_bytes`): a
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

from array import array
from collections import deque
from dataclasses import dataclass, field
from itertools import chain
from typing import Any

from petriflow.agents.comm.framework import Code, History, Packet, Rule, plan
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
    """Seed 000's history: the same data and history arrays (``data``, ``rows``) and
    the same three rules, kept so that a robot with many sources and neighbours can
    afford them. Items are hashable (a cell is a tuple) and there is no ``identity``
    (an item is its source's), so:

    * what this agent and each peer hold are sets of ``(source, item)`` pairs made
      inline (``held``), with no call per item;
    * the history array's counts are one ``array("q")`` of four numbers a row (from,
      to, sent, pending), each row found by ``(from, to)`` and by source, so new data
      of a source updates only that source's rows; ``rows`` gives them as lists. A
      swarm's robots hold hundreds of thousands of rows: as lists, Python's cycle
      collector would walk every one of them at each of its full collections;
    * a source that :meth:`outgoing` found nothing of for a peer it has no row towards
      (all of it came from that peer, or the peer holds it) is looked at again only
      from the first item kept since: items are only appended and what a peer holds
      only grows, so the earlier ones still give nothing;
    * rule 3 takes the last ``pending`` items from the end, not from a copy of all;
    * what went to a peer is in what the peer holds (``held``), not also in lists per
      peer and source (``given`` stays empty): the rules read only the former.

    The answers are :class:`History`'s, item for item and in the same order (tested
    beside it with random operations)."""

    _source_rows: dict[int, list[int]] = field(default_factory=dict, repr=False)  # source -> rows' offsets
    #: Items kept so far: what the rules send a peer changes only when this grows.
    version: int = 0
    _clean: dict[tuple[int, int], int] = field(default_factory=dict, repr=False)  # (peer, source) -> items checked
    _counts: Any = field(default_factory=lambda: array("q"), repr=False)           # 4 a row: from, to, sent, pending

    def __post_init__(self) -> None:
        if self.identity is not None:
            raise ValueError("SwarmHistory keeps items as their source's: no identity")

    @property  # type: ignore[override]
    def rows(self) -> list[list[int]]:
        """The history array: ``[from, to, sent, pending]`` per row, in the order made
        (a copy)."""
        counts = self._counts
        return [counts[at:at + 4].tolist() for at in range(0, len(counts), 4)]

    @rows.setter
    def rows(self, rows: list[list[int]]) -> None:
        if rows:  # (the dataclass's __init__ sets an empty one)
            raise ValueError("a swarm history's rows are made by its rules, not given")
        self._counts = array("q")

    def _new_row(self, source: int, to: int, sent: int) -> None:
        counts = self._counts
        at = len(counts)
        counts.extend((source, to, sent, 0))
        self._rows[(source, to)] = at
        offsets = self._source_rows.get(source)
        if offsets is None:
            self._source_rows[source] = [at]
        else:
            offsets.append(at)

    def _add_row(self, row: list[int]) -> None:
        self._new_row(row[0], row[1], row[2])
        self._counts[-1] = row[3]

    def _row(self, source: int, to: int) -> list[int] | None:
        at = self._rows.get((source, to))
        return None if at is None else self._counts[at:at + 4].tolist()

    def sent_count(self, peer: int, source: int) -> int:
        at = self._rows.get((source, peer))
        return 0 if at is None else self._counts[at + 2]

    def pending(self, peer: int, source: int) -> int:
        at = self._rows.get((source, peer))
        return 0 if at is None else self._counts[at + 3]

    def _keep(self, source: int, item: Any, via: int) -> None:
        self.data.append((source, item, via))
        entries = self._by_source.get(source)
        if entries is None:
            entries = self._by_source[source] = []
        entries.append((item, via))
        self._held.add((source, item))
        self.version += 1

    def has(self, source: int, item: Any) -> bool:
        return (source, item) in self._held

    def _more(self, source: int, count: int, sender: int) -> None:
        me, counts = self.me, self._counts
        for at in self._source_rows.get(source, ()):
            to = counts[at + 1]
            if to != me and to != sender:
                counts[at + 3] += count

    def _note(self, peer: int, source: int, items: list[Any]) -> None:
        held = self.held.get(peer)
        if held is None:
            held = self.held[peer] = set()
        held.update([(source, item) for item in items])

    def lacks(self, peer: int, source: int, items: list[Any]) -> list[Any]:
        held = self.held.get(peer)
        if not held:
            return list(items)
        return [item for item in items if (source, item) not in held]

    def receive(self, sender: int, source: int, items: list[Any]) -> list[Any]:
        mine = self._held
        pairs = [(source, item) for item in items]
        new = []
        for pair in pairs:
            if pair not in mine:
                self._keep(source, pair[1], sender)
                new.append(pair[1])
        held = self.held.get(sender)
        if held is None:
            self.held[sender] = set(pairs)
        else:
            held.update(pairs)
        at = self._rows.get((source, self.me))
        if at is None:
            self._new_row(source, self.me, len(items))
        else:
            self._counts[at + 2] += len(items)
        if new:
            self._more(source, len(new), sender)
        return new

    def outgoing(self, peer: int) -> list[tuple[int, list[Any], Rule]]:
        out = []
        rows, clean, counts = self._rows, self._clean, self._counts
        held = self.held.get(peer) or ()
        for source, entries in self._by_source.items():
            if source == peer:
                continue
            at = rows.get((source, peer))
            if at is None:  # rules 1 and 2: all of it that the peer lacks
                start = clean.get((peer, source), 0)
                if start == len(entries):
                    continue
                items = [item for item, via in entries[start:] if via != peer and (source, item) not in held]
                if not items:
                    clean[(peer, source)] = len(entries)
                    continue
                out.append((source, items, Rule.NEW))
                continue
            pending = counts[at + 3]
            if pending <= 0:
                continue
            tail = []
            for item, via in reversed(entries):  # rule 3: the last ``pending`` items not from the peer
                if via != peer:
                    tail.append(item)
                    if len(tail) == pending:
                        break
            items = [item for item in reversed(tail) if (source, item) not in held]
            if not items:
                counts[at + 3] = 0  # the peer holds all of it already: nothing is pending
                continue
            out.append((source, items, Rule.PENDING))
        return out

    def sent(self, peer: int, source: int, items: list[Any]) -> None:
        at = self._rows.get((source, peer))
        if at is None:
            self._new_row(source, peer, len(items))
        else:
            counts = self._counts
            counts[at + 2] += len(items)
            counts[at + 3] = 0
        self._note(peer, source, items)

    def unsent(self, peer: int, source: int) -> list[Any]:
        # what went to the peer, the peer holds (sent notes it): its holdings decide
        held = self.held.get(peer) or ()
        return [item for item, via in self._by_source.get(source, ()) if via != peer and (source, item) not in held]

    def count_for(self, peer: int, source: int) -> int:
        return len(self._by_source.get(source, ()))


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
    _near_at: int = field(default=-1, repr=False)                # the cell _near_cells was made for
    _near_cells: frozenset = field(default=frozenset(), repr=False)

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
            if message.code == Code.QUERY:
                if (peer, message.source) in self.asked:
                    continue
                self.asked.add((peer, message.source))
            else:
                self.history.sent(address, message.source, message.vertices)
            self._queue(peer, message)

    def _queue(self, peer: str, message: Packet) -> None:
        box = self.outbox.setdefault(peer, [])
        box.append((int(message.code), message.source, message.count, message.final, tuple(message.vertices)))
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

    def _near(self) -> frozenset:
        """The maze's cells within ``horizon`` rows and columns of where the robot is
        (made again only when it has moved on)."""
        if self._near_at != self.here:
            cols, reach = self.cols, self.horizon
            row, col = divmod(self.here, cols)
            first, last = max(0, col - reach), min(cols, col + reach + 1)
            self._near_cells = frozenset(chain.from_iterable(
                range(r * cols + first, r * cols + last) for r in range(max(0, row - reach), min(self.rows, row + reach + 1))))
            self._near_at = self.here
        return self._near_cells

    def receive(self, sender: str, address: int, packet: tuple) -> int:
        """One packet from a neighbour; returns the number of cells new to this robot."""
        code, source, count, final, items = packet
        self.names[address] = sender
        history = self.history
        if code == Code.QUERY:
            wanted = count - history.count(source)
            if wanted > 0:
                self._queue(sender, Packet(Code.REQUEST, source, wanted, self.address, address))
            return 0
        if code == Code.REQUEST:
            self.asked.discard((sender, source))
            chosen = history.unsent(address, source)[:count]
            if chosen:
                history.sent(address, source, chosen)
                self._queue(sender, Packet(Code.BEGIN, source, history.count(source), self.address, address, chosen))
            return 0
        if self.horizon:  # a robot keeps (and passes on) the map around it only
            near = self._near()
            items = [tuple(i) for i in items if i[0] in near]
            if not items:
                return 0
        else:
            items = [tuple(i) for i in items]
        new = 0
        for item in history.receive(address, source, items):
            cell, bits = item[0], item[3]
            if cell not in self.sides:
                new += 1
            self.sides.setdefault(cell, bits)
        return new
