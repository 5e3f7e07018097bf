"""Seed 000's communication framework as plain functions and data: processes 1, 3, 4, 5.

Process 1, characterisation: the travel per encoder pulse ``dpp = 2 pi r / ppr``
(eq. 2) and the odometry grid ``pg`` whose upper corner is ``D / max(dpp)`` (eq. 3).
Process 2 (transmission analysis) is in :mod:`petriflow.agents.comm.radio`.

Process 3, initialisation: the address of agent ``i`` of ``N`` initial agents out of
``A`` available addresses (eq. 4) and its DHCP pool (eq. 5). The pools the paper
prints (§4.1-4.2: N = 2 gives .3-.127 and .129-.254) end one below the next agent's
address, not at ``round((A+2)(i+1)/N) + 1`` as eq. 5 is printed; the pools here follow
the paper's numbers (each pool ends where the next address begins, the last at
``A + 1``).

Process 4, history: :class:`History` is one agent's data array ``Ad`` (source id, data)
and history array ``Ah`` (from = the data's source, to = the agent it went to, sent,
pending), updated by the three rules of §3.2.4 when data goes to a peer: (1) the source
is in no row, (2) it is, but not towards that peer, (3) the row towards the peer has
pending data. New data of a source (made, or received) adds to the pending count of
the rows that already sent that source elsewhere.

Process 5, the packet header: code 0 asks how many packets are pending, 1 requests a
number of packets, 2 begins a transmission, 3 transfers a packet at once
(:class:`Code`; :data:`CODES` names them). :func:`plan` is Algorithm 1: towards one
peer in range, a source with a row of pending data goes by request (codes 0, 1, 2),
one never sent to that peer goes at once (code 3). A :class:`Packet` is a header of three bytes (code, source id,
count) and, for codes 2 and 3, five bytes per map vertex (a 1-byte id and two 16-bit
floats, §4.1): the payload a :class:`~petriflow.runtime.channel_models.Message` carries.

Examples:
    >>> round(dpp(0.025, 200) * 1000, 4), grid_position((0.25, 4.75), 0.0007853)
    (0.7854, (318, 6048))
    >>> addresses(3), dhcp_pools(3)
    ([2, 85, 170], [(3, 84), (86, 169), (171, 254)])
"""

from __future__ import annotations

import enum
import math
import struct
from dataclasses import dataclass, field
from collections.abc import Callable
from typing import Any

from petriflow.outcome import Name

__all__ = [
    "CODES",
    "Code",
    "HEADER_BYTES",
    "VERTEX_BYTES",
    "History",
    "Packet",
    "Rule",
    "addresses",
    "decode_vertex",
    "dhcp_pools",
    "dpp",
    "encode_vertex",
    "grid_position",
    "grid_size",
    "plan",
]


class Code(enum.IntEnum):
    """A packet header's code (§3.2.5): the kind of a :class:`Packet`. An ``int`` enum: the
    header byte holds the number, and the trace writes it."""

    QUERY = 0
    """How many items of the source are pending (a count: the items the sender holds)."""
    REQUEST = 1
    """Send this many items of the source."""
    BEGIN = 2
    """Items that answer a request."""
    IMMEDIATE = 3
    """Items of a source never sent to this peer, sent at once."""


#: The header codes of §3.2.5, as the paper names them.
CODES = {Code.QUERY: "query pending", Code.REQUEST: "request packets", Code.BEGIN: "begin transmission",
         Code.IMMEDIATE: "immediate transfer"}
#: Bytes of a header: code, source id, count.
HEADER_BYTES = 3
#: Bytes of one map vertex: a 1-byte id and two 16-bit floats (x, y).
VERTEX_BYTES = 5


# Process 1 ---------------------------------------------------------------------------
def dpp(radius: float, ppr: int) -> float:
    """Travel per encoder pulse (m), eq. 2."""
    if not radius > 0 or ppr < 1:
        raise ValueError(f"a wheel needs a radius > 0 and at least one pulse per turn, got {radius}, {ppr}")
    return 2.0 * math.pi * radius / ppr


def grid_size(area: tuple[float, float], dpps: list[float]) -> tuple[int, int]:
    """The odometry grid's upper corner ``pg(sup)`` for an area ``(Dx, Dy)`` (m), eq. 3."""
    step = max(dpps)
    return (math.floor(area[0] / step), math.floor(area[1] / step))


def grid_position(point: tuple[float, float], step: float) -> tuple[int, int]:
    """The grid point ``pg`` of a position (m) on a grid of ``step`` m."""
    return (math.floor(point[0] / step + 1e-9), math.floor(point[1] / step + 1e-9))


# Process 3 ---------------------------------------------------------------------------
def addresses(agents: int, available: int = 253) -> list[int]:
    """The last byte of each initial agent's address, eq. 4 (``A`` = ``available``)."""
    if agents < 1:
        raise ValueError(f"the network needs at least one initial agent, got {agents}")
    if agents > available // 2:
        raise ValueError(f"{agents} agents leave no DHCP pool in {available} addresses")
    span = (available + 2) / agents
    return [2 if i == 0 else _round(span * i) for i in range(agents)]


def dhcp_pools(agents: int, available: int = 253) -> list[tuple[int, int]]:
    """Each initial agent's DHCP pool ``(first, last)`` (eq. 5, as the paper's pools)."""
    starts = addresses(agents, available)
    ends = [s - 1 for s in starts[1:]] + [available + 1]
    return [(start + 1, end) for start, end in zip(starts, ends)]


def _round(value: float) -> int:
    return math.floor(value + 0.5)


# Process 4 ---------------------------------------------------------------------------
class Rule(Name):
    """Why :meth:`History.outgoing` sends a source to a peer."""

    NEW = "new"
    """Rules 1 and 2: never sent that source to this peer: all of it."""
    PENDING = "pending"
    """Rule 3: the items made or received since it was last sent."""


@dataclass
class History:
    """One agent's data array ``Ad`` and history array ``Ah`` (see the module).

    The history model of the comm and swarm scenarios (the swarm's
    :class:`~petriflow.agents.swarm.agent.SwarmHistory` is this model, kept in arrays for
    a large team, with the same answers): what this agent knows, from whom, and what
    went to which peer. The SLAM scenario's
    :class:`~petriflow.agents.slam.history.History` is a different model (its docstring
    says how).

    ``data`` holds ``(source, item, via)``: ``via`` is the agent it came from (the
    agent itself for its own data), so nothing goes back where it came from.
    ``rows`` holds ``[from, to, sent, pending]`` in the order they were made. Both are
    indexed (by source, by row key) so a large team's history stays fast. ``held``
    holds, per peer, what it has as far as this agent knows (see the module):
    ``identity(item)`` with ``identity``, else ``(source, item)``.
    """

    me: int
    identity: Callable[[Any], Any] | None = None
    held: dict[int, set] = field(default_factory=dict)
    data: list[tuple[int, Any, int]] = field(default_factory=list)
    rows: list[list[int]] = field(default_factory=list)
    given: dict[tuple[int, int], list[Any]] = field(default_factory=dict)  # (peer, source) -> items sent
    _by_source: dict[int, list[tuple[Any, int]]] = field(default_factory=dict, repr=False)
    _held: set = field(default_factory=set, repr=False)
    _rows: dict[tuple[int, int], list[int]] = field(default_factory=dict, repr=False)
    _given_sets: dict[tuple[int, int], set] = field(default_factory=dict, repr=False)

    def _row(self, source: int, to: int) -> list[int] | None:
        return self._rows.get((source, to))

    def _add_row(self, row: list[int]) -> None:
        self.rows.append(row)
        self._rows[(row[0], row[1])] = row

    def _id(self, source: int, item: Any) -> Any:
        return self.identity(item) if self.identity is not None else (source, _key(item))

    def _note(self, peer: int, source: int, items: list[Any]) -> None:
        self.held.setdefault(peer, set()).update(self._id(source, item) for item in items)

    def lacks(self, peer: int, source: int, items: list[Any]) -> list[Any]:
        """Those of ``items`` (of ``source``) that ``peer`` does not hold, as far as this
        agent knows."""
        held = self.held.get(peer)
        if not held:
            return list(items)
        return [item for item in items if self._id(source, item) not in held]

    def _keep(self, source: int, item: Any, via: int) -> None:
        self.data.append((source, item, via))
        self._by_source.setdefault(source, []).append((item, via))
        self._held.add((source, _key(item)))

    def items(self, source: int, excluding_via: int | None = None) -> list[Any]:
        return [item for item, via in self._by_source.get(source, ()) if via != excluding_via]

    def count(self, source: int) -> int:
        """Items of ``source`` held."""
        return len(self._by_source.get(source, ()))

    def sources(self) -> list[int]:
        return list(self._by_source)

    def has(self, source: int, item: Any) -> bool:
        return (source, _key(item)) in self._held

    def _more(self, source: int, count: int, sender: int) -> None:
        for (row_source, to), row in self._rows.items():
            if row_source == source and to not in (self.me, sender):
                row[3] += count

    def add_own(self, item: Any) -> bool:
        """Data this agent made (a vertex it found); False if it had it already."""
        if self.has(self.me, item):
            return False
        self._keep(self.me, item, self.me)
        self._more(self.me, 1, self.me)
        return True

    def receive(self, sender: int, source: int, items: list[Any]) -> list[Any]:
        """Items of ``source`` arrived from ``sender``: keep the new ones; returns them."""
        new = []
        for item in items:
            if not self.has(source, item):
                self._keep(source, item, sender)
                new.append(item)
        self._note(sender, source, items)
        row = self._row(source, self.me)
        if row is None:
            self._add_row([source, self.me, len(items), 0])
        else:
            row[2] += len(items)
        if new:
            self._more(source, len(new), sender)
        return new

    def outgoing(self, peer: int) -> list[tuple[int, list[Any], Rule]]:
        """What the rules send ``peer``: ``(source, items, rule)`` per source, rule
        :attr:`Rule.NEW` (rules 1 and 2: never sent that source to this peer: all of it) or
        :attr:`Rule.PENDING` (rule 3: the items made or received since); in either case only
        the items the peer does not hold (:meth:`lacks`)."""
        out = []
        chosen: set = set()  # what goes to the peer in this plan already, under an earlier source
        for source in self.sources():
            if source == peer:
                continue
            row = self._row(source, peer)
            if row is not None and row[3] <= 0:
                continue
            items = self.items(source, excluding_via=peer)
            if row is not None:
                items = items[-row[3]:]
            items = [item for item in self.lacks(peer, source, items) if self._id(source, item) not in chosen]
            chosen.update(self._id(source, item) for item in items)
            if not items:
                if row is not None:
                    row[3] = 0  # the peer holds all of it already: nothing is pending
                continue
            out.append((source, items, Rule.NEW if row is None else Rule.PENDING))
        return out

    def sent(self, peer: int, source: int, items: list[Any]) -> None:
        """``items`` of ``source`` went to ``peer``: the row counts them, nothing pending."""
        row = self._row(source, peer)
        if row is None:
            self._add_row([source, peer, len(items), 0])
        else:
            row[2] += len(items)
            row[3] = 0
        self.given.setdefault((peer, source), []).extend(items)
        self._given_sets.setdefault((peer, source), set()).update(_key(i) for i in items)
        self._note(peer, source, items)

    def unsent(self, peer: int, source: int) -> list[Any]:
        """Items of ``source`` this agent holds, did not get from ``peer``, never sent it,
        and that the peer does not hold as far as this agent knows."""
        given = self._given_sets.get((peer, source), set())
        return self.lacks(peer, source, [item for item in self.items(source, excluding_via=peer)
                                         if _key(item) not in given])

    def count_for(self, peer: int, source: int) -> int:
        """How many items of ``source`` ``peer`` must hold, as that source's, to hold it all:
        the items of ``source`` held here, less those whose identity the peer holds from
        another source (with ``identity``: the vertex it mapped itself, or got under
        another robot's name). A header's count towards that peer."""
        items = self._by_source.get(source, ())
        held = self.held.get(peer)
        if self.identity is None or not held:
            return len(items)
        given = self._given_sets.get((peer, source), set())
        covered = sum(1 for item, via in items
                      if via != peer and _key(item) not in given and self.identity(item) in held)
        return len(items) - covered

    def sent_count(self, peer: int, source: int) -> int:
        """Items of ``source`` sent to ``peer`` so far (the row's ``sent``)."""
        row = self._row(source, peer)
        return 0 if row is None else row[2]

    def pending(self, peer: int, source: int) -> int:
        row = self._row(source, peer)
        return 0 if row is None else row[3]


def _key(item: Any) -> Any:
    """A hashable stand-in for an item (lists become tuples)."""
    return tuple(item) if isinstance(item, list) else item


# Process 5 ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Packet:
    """One packet, the payload of a :class:`~petriflow.runtime.channel_models.Message`:
    header ``code`` (:class:`Code`), ``source`` id, ``count`` (codes 0, 2, 3: the items
    of that source the sender holds; code 1: the items requested); vertices for codes 2
    and 3; ``final``: the source's data is complete (the code byte's top bit);
    ``stopped``: the sender cannot move any more (a mechanical failure; the next bit).
    ``sender`` and ``receiver`` are network addresses (the IP header's), not the agent
    names the runtime's message carries."""

    code: Code
    source: int
    count: int
    sender: int
    receiver: int
    vertices: tuple[tuple[int, float, float], ...] = ()
    final: bool = False
    id_bytes: int = 1
    stopped: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "code", Code(self.code))
        object.__setattr__(self, "vertices", tuple(self.vertices))

    @property
    def kind(self) -> Code:
        """The packet's kind: its code."""
        return self.code

    @property
    def size(self) -> int:
        """Bytes on the air (header and vertices)."""
        return HEADER_BYTES + self.payload

    @property
    def payload(self) -> int:
        """Bytes of map data (what the paper's tables count): 5 per vertex, 6 when a
        maze has more than 256 cells and a vertex id takes two bytes."""
        return (VERTEX_BYTES - 1 + self.id_bytes) * len(self.vertices)

    def encode(self) -> bytes:
        head = bytes([self.code | (0x80 if self.final else 0) | (0x40 if self.stopped else 0), self.source & 0xFF,
                      min(self.count, 255)])
        return head + b"".join(encode_vertex(*v, id_bytes=self.id_bytes) for v in self.vertices)


def encode_vertex(vertex_id: int, x: float, y: float, *, id_bytes: int = 1) -> bytes:
    """A vertex as an id of ``id_bytes`` bytes (the paper's one byte), then x and y as
    IEEE 754 half floats.

    Examples:
        >>> decode_vertex(encode_vertex(7, 1.25, 4.75))
        (7, 1.25, 4.75)
        >>> decode_vertex(encode_vertex(300, 0.5, 0.5, id_bytes=2), id_bytes=2)
        (300, 0.5, 0.5)
    """
    if not 0 <= vertex_id < 256 ** id_bytes:
        raise ValueError(f"a vertex id of {id_bytes} byte(s) is 0..{256 ** id_bytes - 1}, got {vertex_id}")
    return vertex_id.to_bytes(id_bytes, "little") + struct.pack("<ee", x, y)


def decode_vertex(data: bytes, *, id_bytes: int = 1) -> tuple[int, float, float]:
    x, y = struct.unpack("<ee", data[id_bytes:id_bytes + 4])
    return (int.from_bytes(data[:id_bytes], "little"), x, y)


def plan(history: History, peer: int) -> list[Packet]:
    """Algorithm 1 towards one peer in range: a message per source to send, code 0
    (query, then the peer requests and code 2 follows) for a source with pending data
    in a row towards the peer, code 3 (immediate) for a source never sent to it."""
    messages = []
    for source, items, rule in history.outgoing(peer):
        total = history.count_for(peer, source)
        if rule is Rule.PENDING:
            messages.append(Packet(Code.QUERY, source, total, history.me, peer))
        else:
            messages.append(Packet(Code.IMMEDIATE, source, total, history.me, peer, tuple(items)))
    return messages
