"""One agent of seed 000's framework: what it knows, what it has to send, its robot.

A :class:`CommAgent` is the agent's state (:class:`~petriflow.runtime.agents.AgentState`,
registered as ``comm.agent``; the subnets declare ``state: comm.agent``): the run keeps
it, ``comm.characterise`` makes it (``ctx.state = ...``), and every later transition of
the agent sees and updates it through ``ctx.state``: the history
(:class:`~petriflow.agents.comm.framework.History`), the topological map, the messages
waiting for each peer, and, for a robot, its body, odometry and exploration. Tokens
carry no state.

**What changed, for the guards.** ``comm.has_message`` reads the key ``outbox/{peer}``:
whether a message waits for that peer and the peer is heard (in range, running). The
state touches that key whenever one peer's queue or hearing changes (:meth:`queue`,
:meth:`take`, :meth:`hear`), so after a step only the send guards of the peers whose
queue or hearing changed are asked again, not every peer's.

Map data is the history's data: an item is a vertex ``(id, x, y)`` whose id is the
maze cell the robot's odometry puts it in (one byte). A source's data is final when
its robot has explored all it will: the header then says so (the top bit of the
code byte; the paper's codes 0-3 need two bits), so other agents know when they hold
all of it.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

from petriflow.agents.comm.framework import Code, History, Packet, plan
from petriflow.runtime.agents import AgentState
from petriflow.runtime.outbox import Outbox

__all__ = ["CommAgent", "Peer", "vertex_id"]


def vertex_id(item: Any) -> int:
    """What a map item stands for: its vertex (the maze cell's id), whoever mapped it.
    The history's per-recipient record uses it (``History(identity=vertex_id)``): a
    vertex a peer holds is not sent to it again, under any source."""
    return item[0]


@dataclass
class Peer:
    """Another agent this one can talk to: its address and the channel place to it."""

    name: str
    address: int
    box: str


@dataclass(eq=False)
class CommAgent(AgentState):
    """The state of one agent (see the module)."""

    name: str
    kind: str                      # robot, monitor or central
    address: int = 0
    peers: dict[str, Peer] = field(default_factory=dict)
    team: set = field(default_factory=set)                   # addresses of every robot of the mission
    history: History | None = None
    robot: Any = None              # KinematicRobot
    explorer: Any = None           # Explorer
    cell: float = 0.5
    origin: tuple[float, float] = (0.0, 0.0)
    cols: int = 1
    cells: int = 1
    explored: bool = False
    explored_at: float | None = None
    final: dict[int, int] = field(default_factory=dict)      # source -> items it has in all
    outbox: Outbox = field(init=False, repr=False)          # peer -> packets waiting
    asked: set = field(default_factory=set)                  # (peer, source) queries answered by no reply yet
    in_range: set = field(default_factory=set)
    last_seen: dict[int, tuple[float, float]] = field(default_factory=dict)  # source -> last vertex position
    route: list = field(default_factory=list)
    met_at: dict = field(default_factory=dict)   # peer -> this robot's cell when it last heard that peer
    finished: bool = False
    reexplored: bool = False
    broken: bool = False                         # a mechanical failure: it cannot move
    stopped: set = field(default_factory=set)    # peers whose header says they cannot move
    parked: bool = False                         # waiting at its meeting place
    parked_for: tuple = ()                       # the robots it parked there to meet
    gave_up: set = field(default_factory=set)   # robots given up on (silent too long)
    last_news: float = 0.0                       # simulated time new map data last arrived
    heard: dict = field(default_factory=dict)    # peer -> simulated time of its last message
    lost: dict = field(default_factory=dict)     # peer -> its messages the radio lost on the way here,
                                                 # oldest first, until TCP gets them through (see resend)
    acted_at: float = 0.0                        # simulated time the agent last planned or took a message in:
                                                 # guards, which see no clock, judge silence as of then
    patience: float = 240.0                      # seconds of silence after which a peer counts as gone
    since: float = 0.0                           # simulated time the agent started its task
    sent_bytes: int = 0
    payload_bytes: int = 0

    def __post_init__(self) -> None:
        AgentState.__init__(self)
        self.outbox = Outbox(self)

    def to_token(self) -> dict[str, Any]:
        """What a trace records of this state: who it is and how far it got (cheap,
        and the same in every process)."""
        return {"agent": self.name, "kind": self.kind, "address": self.address,
                "items": len(self.history.data) if self.history is not None else 0,
                "sent_bytes": self.sent_bytes, "finished": self.finished}

    # Map -------------------------------------------------------------------------------
    @property
    def vertices(self) -> dict[int, tuple[float, float]]:
        """The topological map: vertex id -> (x, y)."""
        if self.history is None:
            return {}
        return {item[0]: (item[1], item[2]) for _, item, _ in self.history.data}

    def by_address(self, address: int) -> Peer | None:
        for peer in self.peers.values():
            if peer.address == address:
                return peer
        return None

    def complete_sources(self, ignore: set[int] = frozenset()) -> bool:
        """Whether this agent holds the whole map: its own exploration ended (a robot),
        and every other team robot's data is known final and held in full (``ignore``:
        sources given up on)."""
        if self.history is None:
            return False
        for source in self.team:
            if source in ignore:
                continue
            if source == self.address:
                if not self.explored:
                    return False
                continue
            if source not in self.final or self.history.count(source) < self.final[source]:
                return False
        return True

    def missing(self) -> list[int]:
        """Team robots (not this one) whose data is not known final and complete here."""
        return sorted(s for s in self.team if s != self.address and
                      (s not in self.final or self.history.count(s) < self.final[s]))

    def untold(self, now: float) -> list[str]:
        """Peers this agent has not yet told that a source it holds in full is final: it
        must meet them once more before it may stop. A peer not heard from for
        ``patience`` s before ``now`` (gone, as far as anyone can tell) is not waited for;
        one that still talks (a robot broken down, its radio on) is."""
        out = []
        for name, peer in self.peers.items():
            if now - self.heard.get(name, self.since) > self.patience or name in self.stopped:
                continue  # gone, or cannot come: it hears what passes by, nobody goes to tell it
            for source, total in self.final.items():
                if source == peer.address or self.history.count(source) < total:
                    continue
                if ("final", name, source) not in self.asked:
                    out.append(name)
                    break
        return out

    def met(self, peer: str) -> None:
        """Remember where this robot stands while it talks with ``peer`` (the cell its
        pose is in, when it has been there; else the last cell it sensed): a place to
        meet that peer again."""
        if self.explorer is None or self.robot is None:
            return
        x, y, _ = self.robot.pose
        cell = (int((y - self.origin[1]) // self.cell), int((x - self.origin[0]) // self.cell))
        self.met_at[peer] = cell if cell in self.explorer.visited else self.explorer.cell

    # Messages --------------------------------------------------------------------------
    @property
    def id_bytes(self) -> int:
        """Bytes of a vertex id: one (the paper's) up to 256 cells, else two."""
        return 1 if self.cells <= 256 else 2

    def queue(self, message: Packet) -> None:
        message = replace(message, id_bytes=self.id_bytes, stopped=self.broken)
        peer = self.by_address(message.receiver)
        if peer is not None:
            self.outbox.put(peer.name, message)

    def hear(self, names: set[str]) -> None:
        """The peers heard now (above the threshold and running); the send guards of
        those whose hearing changed are asked again."""
        changed = names ^ self.in_range
        self.in_range = names
        if changed:
            self.touch(*(f"outbox/{name}" for name in sorted(changed)))

    def plan_for(self, peer: Peer) -> None:
        """Algorithm 1 towards ``peer`` (in range): queue what it should get, unless a
        conversation about that source is under way; and, for every final source,
        a query with its count and the final flag when the peer may lack it."""
        waiting = {(m.source, m.code) for m in self.outbox.get(peer.name, ())}
        for message in plan(self.history, peer.address):
            message = replace(message, final=message.source in self.final)
            if message.code == Code.QUERY:
                if (peer.name, message.source) in self.asked or (message.source, 0) in waiting:
                    continue
                self.asked.add((peer.name, message.source))
            else:
                if (message.source, Code.IMMEDIATE) in waiting:
                    continue
                self.history.sent(peer.address, message.source, list(message.vertices))
            self.queue(message)
        for source, total in self.final.items():
            key = ("final", peer.name, source)
            if source == peer.address or key in self.asked:
                continue
            if self.history.count(source) >= total:
                self.asked.add(key)
                # the final push: what the peer may still lack goes with the note, so no
                # request has to be answered after this agent has finished
                unsent = self.history.unsent(peer.address, source)
                if unsent:
                    self.history.sent(peer.address, source, unsent)
                count = self.history.count_for(peer.address, source)
                self.queue(Packet(Code.QUERY, source, count, self.address, peer.address, final=True))
                if unsent:
                    self.queue(Packet(Code.BEGIN, source, count, self.address, peer.address, unsent, final=True))

    def keep_lost(self, peer: str, message: Packet) -> None:
        """A message from ``peer`` the radio lost on the way here (the run's loss notice,
        ``on_loss: notify``). The paper's transport is TCP (§3.2.3, "to ensure packet
        transmission without information loss"): a lost segment is sent again until it
        arrives, in order. Its receiving end keeps it here until the link carries frames
        again (:meth:`resend`)."""
        self.lost.setdefault(peer, []).append(message)

    def resend(self, peer: str) -> list[Packet]:
        """The messages from ``peer`` lost on the way, oldest first, now that the link
        carries frames again (this agent hears ``peer``, or a later message of it got
        through): TCP's retransmission arrives before anything sent after it."""
        return self.lost.pop(peer, [])

    def take(self, peer: str) -> Packet | None:
        message = self.outbox.take(peer)
        if message is None:
            return None
        self.sent_bytes += message.size
        self.payload_bytes += message.payload
        return message

    def has_for(self, peer: str) -> bool:
        return self.outbox.waiting(peer) > 0 and peer in self.in_range

    def receive(self, message: Packet, now: float) -> list[int]:
        """Handle one message that arrived at simulated time ``now``; returns the ids of
        vertices new to this agent."""
        sender = self.by_address(message.sender)
        if sender is not None:
            self.heard[sender.name] = now
            if message.stopped:
                self.stopped.add(sender.name)
        new: list[int] = []
        final = message.final
        if message.code == Code.QUERY:
            if final:
                self.final[message.source] = max(self.final.get(message.source, 0), message.count)
            have = self.history.count(message.source)
            wanted = max(0, message.count - have)
            if wanted and sender is not None:
                self.queue(Packet(Code.REQUEST, message.source, wanted, self.address, message.sender))
        elif message.code == Code.REQUEST:
            if sender is not None:
                self.asked.discard((sender.name, message.source))
                # the items never sent to the requester, oldest first
                chosen = self.history.unsent(message.sender, message.source)[:message.count]
                self.history.sent(message.sender, message.source, chosen)
                if chosen:
                    self.queue(Packet(Code.BEGIN, message.source,
                                      self.history.count_for(message.sender, message.source),
                                      self.address, message.sender, chosen, final=message.source in self.final))
        else:
            if final:
                self.final[message.source] = max(self.final.get(message.source, 0), message.count)
            fresh = self.history.receive(message.sender, message.source, list(message.vertices))
            new = [v[0] for v in fresh]
            if message.vertices:
                self.last_seen[message.source] = tuple(message.vertices[-1][1:3])
        return new
