"""The history arrays of seed 001 and its two algorithms, as pure functions.

**Cardinal identifiers** (§3.1, Fig. 1): the compass's four bearings, stored as the
integers 0 (west, 0 degrees), 1 (north, 90), 2 (east, 180) and 3 (south, 270): the
paper's pending paths are these integers (Table 3: "1" is north; at a frontal
obstacle heading north it adds "0" and "2", the two laterals). The map frame is the
paper's: the compass axis decides which coordinate a displacement increments, west
increasing ``x`` and north increasing ``y`` (Table 8 fixes the sign of ``x``: vertex 1's
pending path "0" leads to vertex 28 at larger ``x``; see ``nets/slam/README.md``).

**The RA's array** (Table 2) is a :class:`History`: rows ``(id, x, y, last id, pending
paths)``; the WA's array (Table 1) is the same without the pending column. Two fields
are added and said so in the README: each row's ``links`` (the corridors found from it,
by cardinal: the map's edges beyond the one ``last id`` holds) and, for teams of RAs,
vertex ids in blocks of 1000 per RA so that two RAs never number two vertices alike.

**Algorithm 1** (history update): :func:`update` at each sensor event (a frontal
obstacle or a lateral opening: a new vertex with its pending paths, or an existing one
whose pending paths are updated), :func:`choose` (a random pending path of the vertex
the RA stands on, else back-tracking to the nearest vertex with pending paths, else
the end: nothing pending).

**Algorithm 2** (exchange): :func:`exchange_role` (the holder of more nodes sends;
equal holders only greet), :meth:`History.missing_for` (the difference, per block of
ids: each block is a prefix), :meth:`History.merge`; :func:`read_node` is §3.2's rule
for an RA reading a node (a new id: take the first pending path of the array; the same
id: ignore; a new id with nothing pending: keep going away from the node).

Examples:
    The RA of Fig. 3 starts at (0, 0) facing north, drives 0.5 m, meets a wall ahead
    and finds both laterals open:

    >>> h = History(radius=0.3)
    >>> start = update(h, (0.0, 0.0), heading=1, openings=[1], came_from=None)
    >>> choose(h, start, random.Random(0))
    Choice(direction=1, route=[], target=0)
    >>> one = update(h, (0.0, 0.5), heading=1, openings=[0, 2], came_from=start)
    >>> h.table()[1]
    (1, 0.0, 0.5, 0, '0.2')
    >>> pick = choose(h, one, random.Random(5)); pick.direction, h.table()[1][4]
    (2, '0')
"""

from __future__ import annotations

import heapq
import math
import random
from dataclasses import dataclass, field
from typing import Any, Iterable

from petriflow.outcome import Name

__all__ = [
    "BLOCK",
    "CARDINALS",
    "DEGREES",
    "NAMES",
    "STEP",
    "Choice",
    "Exchange",
    "History",
    "Reading",
    "ReadingRule",
    "Vertex",
    "choose",
    "exchange_role",
    "left_of",
    "opposite",
    "pending_text",
    "read_node",
    "right_of",
    "update",
]

#: The four cardinal identifiers (Fig. 1).
CARDINALS = (0, 1, 2, 3)
#: Compass degrees of each identifier: 0 west, 90 north, 180 east, 270 south.
DEGREES = {0: 0, 1: 90, 2: 180, 3: 270}
NAMES = {0: "west", 1: "north", 2: "east", 3: "south"}
#: Unit step of each identifier in the map frame (west is +x, north is +y).
STEP = {0: (1.0, 0.0), 1: (0.0, 1.0), 2: (-1.0, 0.0), 3: (0.0, -1.0)}
#: Vertex ids per RA: RA slot s numbers its vertices s * BLOCK, s * BLOCK + 1, ...
BLOCK = 1000


def opposite(cardinal: int) -> int:
    """The identifier pointing the other way (``opposite(1) == 3``: north, south)."""
    return (cardinal + 2) % 4


def left_of(heading: int) -> int:
    """The lateral on the left of ``heading`` (facing north, west is on the left)."""
    return (heading - 1) % 4


def right_of(heading: int) -> int:
    """The lateral on the right of ``heading`` (facing north, east is on the right)."""
    return (heading + 1) % 4


def pending_text(paths: Iterable[int]) -> str:
    """Pending paths as the paper stores them: identifiers separated by a period
    (``"0.2"``), ``"-"`` when there are none."""
    paths = list(paths)
    return ".".join(str(p) for p in paths) if paths else "-"


def direction_between(a: tuple[float, float], b: tuple[float, float]) -> int:
    """The cardinal identifier closest to the bearing from ``a`` to ``b`` (map frame)."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    if abs(dx) >= abs(dy):
        return 0 if dx > 0 else 2
    return 1 if dy > 0 else 3


@dataclass
class Vertex:
    """One row of the history (Table 2), plus the corridors found from it."""

    id: int
    x: float
    y: float
    last: int
    pending: list[int] = field(default_factory=list)
    links: dict[int, int] = field(default_factory=dict)

    def row(self) -> list[Any]:
        """The row as plain data: ``[id, x, y, last id, pending, links]``."""
        return [self.id, self.x, self.y, self.last, list(self.pending),
                {str(k): v for k, v in sorted(self.links.items())}]

    @classmethod
    def from_row(cls, row: list[Any]) -> "Vertex":
        return cls(int(row[0]), float(row[1]), float(row[2]), int(row[3]), [int(p) for p in row[4]],
                   {int(k): int(v) for k, v in dict(row[5]).items()} if len(row) > 5 else {})


class History:
    """A history array: the rows, by id, in the order they were learnt.

    Not the history model of :class:`petriflow.agents.comm.framework.History` (which
    the swarm shares): that one records, per source and per peer, what was sent to
    whom and what is pending (the exchange is driven by *whom* this agent told what).
    This one keeps no record of peers: it is the map itself (vertices with their
    pending paths and links), and what a peer lacks is read from the peer's own
    counts per block of ids, which its beacon and frames carry (Algorithm 2 compares
    holdings, then sends the difference). The two papers' exchanges differ in just
    this, so each scenario keeps its own.

    Args:
        block: the RA's block of ids (its own new vertices are numbered
            ``block * BLOCK``, ``+ 1``, ...); a WA's array has no block of its own.
        radius: two positions closer than this (metres) are the same vertex.
    """

    def __init__(self, block: int = 0, radius: float = 1.0) -> None:
        self.block = block
        self.radius = radius
        self.rows: dict[int, Vertex] = {}
        #: ``{id: id}`` of vertices another RA found too (same place): merged into the smaller id.
        self.alias: dict[int, int] = {}
        self._counts: dict[int, int] | None = None

    # What it holds ------------------------------------------------------------------
    def __len__(self) -> int:
        """``lengthData``: the rows held (Algorithm 2 compares these)."""
        return len(self.rows)

    def counts(self) -> dict[int, int]:
        """Rows held per block of ids (each block is a prefix of its RA's numbering)."""
        if self._counts is None:
            out: dict[int, int] = {}
            for vid in self.rows:
                out[vid // BLOCK] = out.get(vid // BLOCK, 0) + 1
            self._counts = dict(sorted(out.items()))
        return dict(self._counts)

    def canonical(self, vid: int) -> int:
        while vid in self.alias:
            vid = self.alias[vid]
        return vid

    def vertices(self) -> list[Vertex]:
        """The map's vertices (rows that are not another row's alias), by id."""
        return [v for vid, v in sorted(self.rows.items()) if vid not in self.alias]

    def edges(self) -> set[tuple[int, int]]:
        """The map's edges: each row's ``last id`` and its links, between canonical ids."""
        out: set[tuple[int, int]] = set()
        for vertex in self.rows.values():
            a = self.canonical(vertex.id)
            for b in [vertex.last, *vertex.links.values()]:
                b = self.canonical(b)
                if a != b and b in self.rows:
                    out.add((min(a, b), max(a, b)))
        return out

    def table(self) -> list[tuple[int, float, float, int, str]]:
        """The array as the paper prints it: ``(id, x, y, last id, pending)``."""
        return [(v.id, round(v.x, 2), round(v.y, 2), v.last, pending_text(v.pending)) for v in self.rows.values()]

    def find(self, position: tuple[float, float], radius: float | None = None) -> int | None:
        """The vertex within ``radius`` of ``position`` (the nearest), else ``None``."""
        radius = self.radius if radius is None else radius
        best, where = None, radius
        for vertex in self.vertices():
            d = math.hypot(vertex.x - position[0], vertex.y - position[1])
            if d <= where:
                best, where = vertex.id, d
        return best

    def has_pending(self) -> bool:
        return any(v.pending for v in self.vertices())

    def first_pending(self) -> tuple[int, int] | None:
        """The first pending path of the array: ``(vertex id, identifier)``."""
        for vertex in self.vertices():
            if vertex.pending:
                return vertex.id, vertex.pending[0]
        return None

    # Changing it --------------------------------------------------------------------
    def next_id(self) -> int:
        own = [vid for vid in self.rows if vid // BLOCK == self.block]
        return max(own) + 1 if own else self.block * BLOCK

    def add(self, position: tuple[float, float], last: int | None, pending: Iterable[int]) -> int:
        """A new row at ``position``; ``last`` is the vertex the RA came from (the first
        row's own id when it came from nowhere, as in Table 6)."""
        vid = self.next_id()
        self._counts = None
        self.rows[vid] = Vertex(vid, round(position[0], 3), round(position[1], 3),
                                vid if last is None else last, sorted(set(pending)))
        return vid

    def take(self, vid: int, direction: int) -> None:
        """The path ``direction`` of vertex ``vid`` is navigated: no longer pending."""
        vertex = self.rows[self.canonical(vid)]
        if direction in vertex.pending:
            vertex.pending.remove(direction)

    def link(self, a: int, direction: int, b: int) -> None:
        """A corridor from ``a`` heading ``direction`` arrives at ``b``."""
        a, b = self.canonical(a), self.canonical(b)
        if a == b:
            return
        self.rows[a].links[direction] = b
        self.rows[b].links[opposite(direction)] = a
        self.take(a, direction)
        self.take(b, opposite(direction))

    # Algorithm 2 --------------------------------------------------------------------
    def missing_for(self, counts: dict[int, int]) -> list[Vertex]:
        """The rows a holder of ``counts`` rows per block lacks (each block is a prefix)."""
        have: dict[int, int] = {}
        out = []
        for vid in self.rows:
            block = vid // BLOCK
            have[block] = have.get(block, 0) + 1
            if have[block] > counts.get(block, 0):
                out.append(self.rows[vid])
        return out

    def lacks(self, counts: dict[int, int]) -> bool:
        """Whether a holder of ``counts`` has rows this array lacks."""
        mine = self.counts()
        return any(n > mine.get(block, 0) for block, n in counts.items())

    def payload(self, counts: dict[int, int]) -> dict[str, Any]:
        """What is sent to a holder of ``counts``: the rows it lacks, and every row's
        pending paths and links (so the receiver's array becomes this one, as
        Algorithm 1's ``NearNode.data <- data`` says)."""
        return {"rows": [v.row() for v in self.missing_for(counts)],
                "pending": {str(v.id): list(v.pending) for v in self.rows.values()},
                "links": {str(v.id): {str(k): w for k, w in sorted(v.links.items())} for v in self.rows.values()}}

    def merge(self, payload: dict[str, Any]) -> list[int]:
        """Take a payload in: new rows are added (a row at the place of a known vertex
        from another block becomes its alias), pending paths of known rows are
        intersected (a path anyone took is taken), links are joined. Returns the new ids."""
        new = []
        for row in payload.get("rows", []):
            vertex = Vertex.from_row(row)
            if vertex.id in self.rows:
                continue
            twin = self.find((vertex.x, vertex.y))
            self.rows[vertex.id] = vertex
            self._counts = None
            if twin is not None and twin // BLOCK != vertex.id // BLOCK:
                keep, drop = min(twin, vertex.id), max(twin, vertex.id)
                self.alias[drop] = keep
                self._fold(drop, keep)
            new.append(vertex.id)
        for key, paths in payload.get("pending", {}).items():
            vid = int(key)
            if vid in self.rows:
                vertex = self.rows[vid]
                vertex.pending = [p for p in vertex.pending if p in paths]
        for key, links in payload.get("links", {}).items():
            vid = int(key)
            if vid in self.rows:
                for direction, other in links.items():
                    if int(other) in self.rows:
                        self.link(vid, int(direction), int(other))
        for drop, keep in list(self.alias.items()):
            self._fold(drop, keep)
        return new

    def _fold(self, drop: int, keep: int) -> None:
        """A vertex known under two ids: its pending paths are those both still have."""
        a, b = self.rows[drop], self.rows[self.canonical(keep)]
        b.pending = [p for p in b.pending if p in a.pending]
        for direction, other in a.links.items():
            b.links.setdefault(direction, other)
            b.pending = [p for p in b.pending if p != direction]

    # The map as a graph ---------------------------------------------------------------
    def neighbours(self, vid: int) -> list[tuple[int, int, float]]:
        """``(direction, neighbour, length)`` of the corridors found from ``vid``."""
        vertex = self.rows[self.canonical(vid)]
        out = []
        links = dict(vertex.links)
        for alias, keep in self.alias.items():
            if self.canonical(keep) == vertex.id:
                for direction, other in self.rows[alias].links.items():
                    links.setdefault(direction, other)
        for direction, other in sorted(links.items()):
            other = self.canonical(other)
            if other in self.rows and other != vertex.id:
                w = self.rows[other]
                out.append((direction, other, abs(w.x - vertex.x) + abs(w.y - vertex.y)))
        return out

    def route(self, start: int, goal_test) -> tuple[int, list[tuple[int, int]]] | None:
        """Shortest route over the known corridors from ``start`` to the nearest vertex
        ``goal_test`` accepts: ``(that vertex, [(direction, next vertex), ...])``."""
        start = self.canonical(start)
        queue = [(0.0, start)]
        best = {start: 0.0}
        back: dict[int, tuple[int, int]] = {}
        while queue:
            cost, vid = heapq.heappop(queue)
            if cost > best.get(vid, math.inf) + 1e-12:
                continue
            if goal_test(vid):
                legs = []
                node = vid
                while node != start:
                    prev, direction = back[node]
                    legs.append((direction, node))
                    node = prev
                return vid, legs[::-1]
            for direction, other, length in self.neighbours(vid):
                total = cost + length
                if total < best.get(other, math.inf) - 1e-12:
                    best[other] = total
                    back[other] = (vid, direction)
                    heapq.heappush(queue, (total, other))
        return None


@dataclass(frozen=True)
class Choice:
    """Where the RA goes next: ``direction`` to leave by (``None``: the map is done),
    the ``route`` of legs ``(direction, vertex)`` before it, the vertex it leaves from."""

    direction: int | None
    route: list[tuple[int, int]]
    target: int | None


def update(history: History, position: tuple[float, float], *, heading: int, openings: Iterable[int],
           came_from: int | None) -> int:
    """Algorithm 1 at a sensor event: the RA is at ``position`` (odometry), heading
    ``heading``, sees ``openings`` (identifiers of the open sides among front and
    laterals), and came along a corridor from vertex ``came_from``. Returns the vertex.

    A position already in the array (within the history's radius) only updates its
    pending paths (the way the RA came is navigated); otherwise a row is added with the
    open sides as pending paths, the way back excluded.
    """
    back = opposite(heading)
    existing = history.find(position)
    if existing is not None:
        if came_from is not None:
            history.link(came_from, heading, existing)
        return existing
    paths = [o for o in openings if o != back or came_from is None]
    vid = history.add(position, came_from, paths)
    if came_from is not None:
        history.link(came_from, heading, vid)
    return vid


def choose(history: History, here: int, rng: random.Random, goal: tuple[int, int] | None = None) -> Choice:
    """Algorithm 1's move: a random pending path of ``here`` (taken out of the pending
    paths); else the route to the nearest vertex with pending paths (back-tracking),
    whose first pending path will be taken there; else the end (``direction None``).

    ``goal`` (a vertex and a path, from :func:`read_node`) is where to go instead.
    """
    here = history.canonical(here)
    if goal is not None and history.canonical(goal[0]) == here:
        history.take(here, goal[1])
        return Choice(goal[1], [], here)
    if goal is None:
        pending = history.rows[here].pending
        if pending:
            direction = rng.choice(sorted(pending))
            history.take(here, direction)
            return Choice(direction, [], here)
    found = None
    if goal is not None:
        target = history.canonical(goal[0])
        found = history.route(here, lambda vid: vid == target)
    if found is None:
        pending = history.rows[here].pending
        if goal is not None and pending:  # the goal cannot be reached: Algorithm 1 as usual
            direction = rng.choice(sorted(pending))
            history.take(here, direction)
            return Choice(direction, [], here)
        found = history.route(here, lambda vid: bool(history.rows[vid].pending))
    if found is None:
        return Choice(None, [], None)
    target, legs = found
    if not legs:
        return Choice(None, [], None)
    return Choice(None, legs, target)


class Exchange(Name):
    """Algorithm 2's decision for a client that found a node (:func:`exchange_role`)."""

    SEND = "send"
    """It holds more nodes: it sends the difference."""
    PULL = "pull"
    """The node holds more: the node sends."""
    GREET = "greet"
    """Equal: nothing but the time stamps."""


def exchange_role(mine: dict[int, int], theirs: dict[int, int]) -> Exchange:
    """Algorithm 2's decision for a client that found a node (:class:`Exchange`).

    Examples:
        >>> exchange_role({0: 6}, {0: 4}), exchange_role({0: 4}, {0: 6}), exchange_role({0: 4}, {0: 4})
        (<Exchange.SEND: 'send'>, <Exchange.PULL: 'pull'>, <Exchange.GREET: 'greet'>)
    """
    total_mine, total_theirs = sum(mine.values()), sum(theirs.values())
    if total_mine > total_theirs:
        return Exchange.SEND
    if total_mine < total_theirs:
        return Exchange.PULL
    if any(n > theirs.get(b, 0) for b, n in mine.items()):
        return Exchange.SEND
    if any(n > mine.get(b, 0) for b, n in theirs.items()):
        return Exchange.PULL
    return Exchange.GREET


class ReadingRule(Name):
    """Which of §3.2's rules an RA reading a node applies (:class:`Reading`)."""

    FOLLOW = "follow"
    """Take the first pending path of the array."""
    IGNORE = "ignore"
    """The node read last: nothing to do."""
    AWAY = "away"
    """Nothing pending: go on away from the node, remembering its id."""


@dataclass(frozen=True)
class Reading:
    """§3.2's rule for an RA reading a node: ``kind`` (:class:`ReadingRule`) and, to
    follow, ``path`` (the first pending path of the array)."""

    kind: ReadingRule
    path: tuple[int, int] | None = None


def read_node(history: History, node: str, last_read: str | None) -> Reading:
    """The reading rule (see :class:`Reading`); the caller records ``node`` as read.

    Examples:
        >>> h = History(); _ = h.add((0, 0), None, []); _ = h.add((0, 6), 0, [0])
        >>> follow, ignore = read_node(h, "WA_R1_1", None), read_node(h, "WA_R1_1", "WA_R1_1")
        >>> follow.kind.value, follow.path, ignore.kind.value, ignore.path
        ('follow', (1, 0), 'ignore', None)
    """
    if node == last_read:
        return Reading(ReadingRule.IGNORE)
    first = history.first_pending()
    if first is None:
        return Reading(ReadingRule.AWAY)
    return Reading(ReadingRule.FOLLOW, first)
