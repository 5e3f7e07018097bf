"""ZigBee's network layer: broadcasts relayed by routers, end devices polling their parent.

By default (``network: true``) the XBee radios form a ZigBee network as Digi documents
it for its XBee ZigBee modules (:class:`ZigbeeNetworkMedium`, a layer that holds the
MAC, :class:`~petriflow.agents.bus.zigbee.CsmaCa`, and calls its public methods): a
payload-addressed frame is a network broadcast; the coordinator (the first module) and
every router that transmits a broadcast record it in a broadcast transaction table
(:class:`BroadcastTable`) of ``btt_entries`` = 8 entries kept ``btt_lifetime`` = 8 s
each (a node whose table is full drops a new broadcast: its module loses it, and it
relays nothing, :attr:`~petriflow.agents.bus.records.Loss.BTT_FULL`); each router
relays a new broadcast after a random jitter of up to ``max_jitter`` = 63 ms and
retransmits it, at most ``broadcast_retries`` = 2 times, when ``passive_ack_timeout`` =
0.5 s after a transmission it has not heard every neighbouring router relay it
(passive acknowledgement). With ``roles: end_devices`` the modules other than the
coordinator are its end devices: they send to it (acknowledged, ``mac_retries``) and get
broadcasts only when they poll it (``poll_period`` = 100 ms); the parent buffers one
broadcast for all of them, a newer one replacing it
(:attr:`~petriflow.agents.bus.records.Loss.PARENT_BUFFER`). The parameters are
:class:`~petriflow.agents.bus.parameters.ZigbeeBus`.

With ``addressing: unicast`` each device's own address is used instead: a frame goes as
one acknowledged unicast to each of its addressees (to an end device through its parent,
which buffers it until the child polls), retried ``mac_retries`` times when no
acknowledgement comes; nobody relays it and no broadcast transaction table records it.
A frame for no module (an address nobody holds) is a unicast nobody acknowledges: it is
sent ``mac_retries`` + 1 times. A sniffer overhears every intact unicast in its range.

Examples:
    Three routers in range: the originator's frame and one relay from each other node;
    each hears every other relay, so nobody retransmits.

    >>> from petriflow.agents.bus.parameters import ZigbeeBus
    >>> from petriflow.agents.bus.simulator import BusSimulator
    >>> sim = BusSimulator(ZigbeeBus(), modules=[0, 1, 2], seed=2)
    >>> sim.send(0.0, Frame(0, (1,), bytes(8)))
    >>> network = sim.run()
    >>> len(network.transmissions), network.losses, [f"{network.role(n)}" for n in range(3)]
    (3, [], ['coordinator', 'router', 'router'])
    >>> network.btt_size(1), network.table(1).entries
    (1, 8)
"""

from __future__ import annotations

import math
import random
from collections import deque
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from petriflow.agents.bus.buffer import MEDIUM, BusMedium
from petriflow.agents.bus.records import Frame, Loss, Lost, Transmission
from petriflow.agents.bus.zigbee import CsmaCa
from petriflow.outcome import Name
from petriflow.runtime.media import ProcessClock, Timer

if TYPE_CHECKING:
    from petriflow.agents.bus.parameters import ZigbeeBus

__all__ = ["BroadcastTable", "Role", "ZigbeeNetworkMedium"]


class Role(Name):
    """A node's role in the ZigBee network."""

    COORDINATOR = "coordinator"
    """The first module: it starts the network (and is the end devices' parent)."""
    ROUTER = "router"
    """It relays broadcasts (every module with ``roles: routers``, and a sniffer)."""
    END_DEVICE = "end_device"
    """It sends to its parent and gets broadcasts by polling it (``roles: end_devices``)."""


class BroadcastTable:
    """A node's broadcast transaction table: the broadcasts it has taken, each kept
    ``lifetime`` seconds, at most ``entries`` at once.

    Examples:
        >>> table = BroadcastTable(entries=2, lifetime=8.0)
        >>> table.record("a", now=0.0), table.record("b", now=1.0), table.record("c", now=2.0)
        (True, True, False)
        >>> table.size(now=8.0), table.record("c", now=8.0)   # "a" expired at 8 s
        (1, True)
    """

    def __init__(self, entries: int, lifetime: float) -> None:
        self.entries = entries
        self.lifetime = lifetime
        self._expiries: deque[tuple[float, Any]] = deque()  # (when it expires, broadcast key), oldest first

    def size(self, now: float) -> int:
        """Entries in the table at ``now``."""
        self._purge(now)
        return len(self._expiries)

    def record(self, key: Any, now: float) -> bool:
        """Make the entry of a new broadcast at ``now``; ``False`` if the table is full."""
        self._purge(now)
        if len(self._expiries) >= self.entries:
            return False
        self._expiries.append((now + self.lifetime, key))
        return True

    def clear(self) -> None:
        """Forget every entry (the radio restarted)."""
        self._expiries.clear()

    def _purge(self, now: float) -> None:
        while self._expiries and self._expiries[0][0] <= now:
            self._expiries.popleft()


class _Hop(Name):
    """What a node's radio sends a broadcast for."""

    UP = "up"
    """An end device's frame to its parent (acknowledged, retried)."""
    BROADCAST = "broadcast"
    """A network broadcast (the sender then listens for passive acknowledgements)."""
    UNICAST = "unicast"
    """A frame to one node (``addressing: unicast``; acknowledged, retried)."""


class _Broadcast:
    """One frame on the ZigBee network, a network broadcast or (``targets`` not ``None``)
    unicasts to its addressees: which nodes have it, why the others have not (yet), and
    how much of its relaying is still under way."""

    __slots__ = ("frame", "origin", "key", "pending", "reached", "why", "heard", "tries", "intact", "done",
                 "targets")

    def __init__(self, frame: Frame, origin: int, key: Any, targets: frozenset[int] | None = None) -> None:
        self.frame = frame
        self.targets = targets
        self.origin = origin
        self.key = key
        self.pending = 0  # transmissions, jitter waits, passive-ack waits and polls to come
        self.reached: set[int] = {origin}
        self.why: dict[int | None, Loss] = {}
        self.heard: dict[int, set[int]] = {}  # node -> the routers it heard transmit this broadcast
        self.tries: dict[Any, int] = {}  # node (or (node, next hop) for a unicast) -> transmissions
        self.intact = False
        self.done = False


class ZigbeeNetworkMedium(BusMedium):
    """XBee radios as a ZigBee network (``network: true``, the default): a module's
    payload-addressed frame is a network broadcast (see the module). A sniffer
    (:meth:`~petriflow.agents.bus.buffer.BusMedium.sniff`) is a router. A broadcast's
    losses are decided when its last transmission, wait or poll is over.

    Attributes:
        radio: the MAC the network sends through (:class:`~petriflow.agents.bus.zigbee.CsmaCa`).
    """

    bus: ZigbeeBus

    def __init__(self, bus: ZigbeeBus, clock: ProcessClock, rng: random.Random, modules: Iterable[int] = (),
                 positions: dict[int, float] | None = None, **options: Any) -> None:
        # no on_collision: what a collision costs is decided when the broadcast's last frame ends
        self.radio = CsmaCa(bus, clock, rng, on_start=self._started, on_sent=self._sent,
                            on_failure=self._failed, on_free=self._free, positions=positions)
        self._tables: dict[int, BroadcastTable] = {}
        # what each radio has to send: (frame, hop, next hop of a unicast)
        self._outbox: dict[int, deque[tuple[_Broadcast, _Hop, int | None]]] = {}
        self._uart_free: dict[int, float] = {}
        self._buffered: dict[int, tuple[_Broadcast, set[int]]] = {}  # parent -> (broadcast, children to poll)
        self._polls: dict[int, Timer] = {}
        self._poll_phase: dict[int, float] = {}
        self._sequence = 0
        super().__init__(bus, clock, rng, modules, **options)

    def add_module(self, module: int) -> None:
        super().add_module(module)
        self.radio.add_node(module)
        self._tables.setdefault(module, BroadcastTable(self.bus.btt_entries, self.bus.btt_lifetime))
        self._outbox.setdefault(module, deque())

    # Roles ----------------------------------------------------------------------------
    def coordinator(self) -> int | None:
        """The coordinator: the first attached module that is not a sniffer."""
        return next((m for m in self.modules if m not in self.sniffers), None)

    def role(self, node: int) -> Role:
        """``node``'s role in the network."""
        if node == self.coordinator():
            return Role.COORDINATOR
        if node in self.sniffers or self.bus.roles == "routers":
            return Role.ROUTER
        return Role.END_DEVICE

    def parent(self, node: int) -> int | None:
        """An end device's parent (the coordinator); ``None`` for the others."""
        return self.coordinator() if self.role(node) is Role.END_DEVICE else None

    def table(self, node: int) -> BroadcastTable:
        """``node``'s broadcast transaction table."""
        return self._tables[node]

    def btt_size(self, node: int) -> int:
        """Entries in ``node``'s broadcast transaction table now."""
        return self._tables[node].size(self.clock.now)

    # The host's side ------------------------------------------------------------------
    def is_free(self, module: int) -> bool:
        return not self.radio.serving(module) and not self._queues[module] and not self._outbox[module]

    def busy(self) -> bool:
        return self.radio.busy()

    def _request(self, frame: Frame) -> bool:
        if not self._enqueue(frame, False):
            return False
        sender = frame.sender
        now = self.clock.now
        start = max(now, self._uart_free.get(sender, now))
        ready = start + self.bus.uart_time(len(frame.data) + self.bus.packetization_chars)
        self._uart_free[sender] = ready
        self.clock.at(ready, self._originate, sender, rank=MEDIUM)
        return True

    def _originate(self, node: int) -> None:
        """The radio has the frame from its host's UART: a new broadcast."""
        frame = self._queues[node].popleft()
        self._sequence += 1
        unicast = self.bus.addressing == "unicast"
        broadcast = _Broadcast(frame, node, (node, self._sequence),
                               frozenset(frame.receivers) - {node} if unicast else None)
        if unicast and self.role(node) is not Role.END_DEVICE:
            if not broadcast.targets:
                self._push(node, broadcast, _Hop.UNICAST, None)
            self._forward(node, broadcast)
            return
        if self.role(node) is Role.END_DEVICE:
            self._push(node, broadcast, _Hop.UP)
            return
        if not self._tables[node].record(broadcast.key, self.clock.now):
            self._lost(Lost(frame, None, Loss.BTT_FULL, self.clock.now))
            if not self._outbox[node] and not self.radio.serving(node):
                self._notify_idle([node])
            return
        self._push(node, broadcast, _Hop.BROADCAST)
        self._buffer_for_children(node, broadcast)

    # Relaying -----------------------------------------------------------------------------
    def _take(self, node: int, broadcast: _Broadcast) -> None:
        """A router or the coordinator received an intact copy now."""
        if node in broadcast.reached:
            return  # a duplicate: only a passive acknowledgement
        now = self.clock.now
        if broadcast.targets is not None:  # a unicast: its addressee, or the parent of some
            broadcast.reached.add(node)
            broadcast.why.pop(node, None)
            if node in broadcast.targets or node in self.sniffers:
                frame = broadcast.frame
                self.clock.at(now + self.bus.uart_time(len(frame.data)), self._arrive, frame, node, rank=MEDIUM)
            if node not in self.sniffers and self.parent(broadcast.origin) == node:
                self._forward(node, broadcast)  # from its end device: on to every addressee
            elif node not in self.sniffers:
                self._buffer_for_children(node, broadcast)  # its own end devices' copies
            return
        if not self._tables[node].record(broadcast.key, now):
            broadcast.why[node] = Loss.BTT_FULL
            for child in self.modules:  # its end devices get nothing from it either
                if self.parent(child) == node:
                    broadcast.why.setdefault(child, Loss.BTT_FULL)
            return
        broadcast.reached.add(node)
        broadcast.why.pop(node, None)
        frame = broadcast.frame
        self.clock.at(now + self.bus.uart_time(len(frame.data)), self._arrive, frame, node, rank=MEDIUM)
        broadcast.pending += 1
        jitter = self.rng.uniform(0.0, self.bus.max_jitter)
        self.clock.at(now + jitter, self._relay, node, broadcast, rank=MEDIUM)
        self._buffer_for_children(node, broadcast)

    def _relay(self, node: int, broadcast: _Broadcast) -> None:
        broadcast.pending -= 1
        self._push(node, broadcast, _Hop.BROADCAST)

    def _forward(self, node: int, broadcast: _Broadcast) -> None:
        """A unicast at ``node``: one to each addressee it has not reached whose next hop
        is another node (the addressee, or an end device's parent); ``node``'s own end
        devices get it when they poll."""
        hops = []
        for target in sorted(broadcast.targets or ()):
            hop = self.parent(target) if self.role(target) is Role.END_DEVICE else target
            if target not in broadcast.reached and hop not in (node, None) and hop not in hops \
                    and hop not in broadcast.reached:
                hops.append(hop)
        for hop in hops:
            self._push(node, broadcast, _Hop.UNICAST, hop)
        self._buffer_for_children(node, broadcast)

    # End devices --------------------------------------------------------------------------
    def _buffer_for_children(self, node: int, broadcast: _Broadcast) -> None:
        children = {m for m in self.modules if m != broadcast.origin and self.parent(m) == node
                    and (broadcast.targets is None or m in broadcast.targets)}
        if not children:
            return
        old = self._buffered.pop(node, None)
        self._buffered[node] = (broadcast, children)
        broadcast.pending += len(children)
        if old is not None:
            dropped, waiting = old
            for child in waiting:
                dropped.why[child] = Loss.PARENT_BUFFER
                dropped.pending -= 1
            self._check_done(dropped)
        for child in children:
            self._schedule_poll(child)

    def _schedule_poll(self, child: int) -> None:
        if child in self._polls:
            return
        period = self.bus.poll_period
        phase = self._poll_phase.setdefault(child, self.rng.uniform(0.0, period))
        now = self.clock.now
        when = phase + math.ceil((now - phase) / period - 1e-9) * period
        self._polls[child] = self.clock.at(max(when, now), self._poll, child, rank=MEDIUM)

    def _poll(self, child: int) -> None:
        """An end device polls its parent: it gets the buffered broadcast it has not had."""
        self._polls.pop(child, None)
        parent = self.parent(child)
        entry = self._buffered.get(parent) if parent is not None else None
        if entry is None or child not in entry[1]:
            return
        broadcast, waiting = entry
        waiting.discard(child)
        if not waiting:
            del self._buffered[parent]
        broadcast.pending -= 1
        broadcast.reached.add(child)
        broadcast.why.pop(child, None)
        broadcast.intact = True  # the child has it intact (a unicast may reach nobody else)
        frame = broadcast.frame
        out = self.radio.airtime(frame) + self.bus.uart_time(len(frame.data))
        self.clock.at(self.clock.now + out, self._arrive, frame, child, rank=MEDIUM)
        if broadcast.targets is not None:  # the parent's unicast to its child: a sniffer overhears it
            for sniffer in sorted(self.sniffers - broadcast.reached):
                self._take(sniffer, broadcast)
        self._check_done(broadcast)

    # Through the MAC --------------------------------------------------------------------------
    def _push(self, node: int, broadcast: _Broadcast, hop: _Hop, to: int | None = None) -> None:
        broadcast.pending += 1
        self._outbox[node].append((broadcast, hop, to))
        if not self.radio.serving(node):
            self._serve(node)

    def _serve(self, node: int) -> None:
        """The radio takes the head of the node's outbox (CSMA/CA starts now)."""
        self.radio.send(node, self._outbox[node][0][0].frame)

    def _sent(self, node: int, transmission: Transmission) -> None:
        broadcast, hop, to = self._outbox[node][0]
        if not transmission.garbled:
            broadcast.intact = True
        self._ended(transmission)
        self._after(node, broadcast, hop, transmission, to)
        self._outbox[node].popleft()

    def _failed(self, node: int) -> None:
        broadcast, hop, to = self._outbox[node][0]
        broadcast.why.setdefault(None, Loss.ACCESS_FAILURE)
        self._after(node, broadcast, hop, None, to)
        self._outbox[node].popleft()

    def _free(self, node: int) -> None:
        if self._outbox[node]:
            self._serve(node)
        elif not self._queues[node]:
            self._notify_idle([node])

    def _after(self, node: int, broadcast: _Broadcast, hop: _Hop, transmission: Transmission | None,
               to: int | None = None) -> None:
        """``node``'s transmission of ``broadcast`` is over (``None``: CSMA/CA gave up);
        ``to``: a unicast's next hop."""
        broadcast.tries[node] = broadcast.tries.get(node, 0) + 1
        if broadcast.targets is not None and transmission is not None and not transmission.garbled:
            for sniffer in self.sniffers:  # a sniffer overhears every unicast in its range
                if sniffer != node and self.radio.survives(node, sniffer, transmission):
                    self._take(sniffer, broadcast)
        if hop is _Hop.UNICAST:
            tries = broadcast.tries[(node, to)] = broadcast.tries.get((node, to), 0) + 1
            if to is not None and transmission is not None and not transmission.garbled \
                    and self.radio.survives(node, to, transmission):
                self._take(to, broadcast)
            else:
                if transmission is not None and to is not None:
                    broadcast.why[to] = Loss.COLLISION if transmission.garbled else Loss.RADIO
                if tries <= self.bus.mac_retries:
                    self._push(node, broadcast, _Hop.UNICAST, to)
        elif hop is _Hop.UP:
            parent = self.parent(node)
            if transmission is not None and not transmission.garbled and parent is not None \
                    and self.radio.survives(node, parent, transmission):
                self._take(parent, broadcast)
                if parent not in broadcast.reached:  # the parent's table was full: it went no further
                    broadcast.why[None] = Loss.BTT_FULL
            else:
                if transmission is not None:
                    broadcast.why[None] = Loss.COLLISION if transmission.garbled else Loss.RADIO
                if broadcast.tries[node] <= self.bus.mac_retries:
                    self._push(node, broadcast, _Hop.UP)
        elif transmission is not None:
            for other in self.modules:
                if other == node or self.role(other) is Role.END_DEVICE:
                    continue
                if transmission.garbled:
                    broadcast.why.setdefault(other, Loss.COLLISION)
                    continue
                if not self.radio.survives(node, other, transmission):
                    broadcast.why.setdefault(other, Loss.RADIO)
                    continue
                broadcast.heard.setdefault(other, set()).add(node)
                self._take(other, broadcast)
        if hop is _Hop.BROADCAST:
            broadcast.pending += 1
            self.clock.at(self.clock.now + self.bus.passive_ack_timeout, self._passive_ack, node, broadcast,
                          rank=MEDIUM)
        broadcast.pending -= 1
        self._check_done(broadcast)

    def _passive_ack(self, node: int, broadcast: _Broadcast) -> None:
        """The passive acknowledgement timeout: retransmit unless every neighbouring
        router (and the coordinator) was heard transmitting the broadcast."""
        broadcast.pending -= 1
        neighbours = [m for m in self.modules if m != node and self.role(m) is not Role.END_DEVICE]
        heard = broadcast.heard.get(node, set())
        retries_left = broadcast.tries.get(node, 0) <= self.bus.broadcast_retries
        if any(m not in heard for m in neighbours) and retries_left:
            self._push(node, broadcast, _Hop.BROADCAST)
        self._check_done(broadcast)

    def _check_done(self, broadcast: _Broadcast) -> None:
        """Nothing of the broadcast is under way: the nodes it did not reach lost it now."""
        if broadcast.pending > 0 or broadcast.done:
            return
        broadcast.done = True
        now = self.clock.now
        if not broadcast.intact:
            self._lost(Lost(broadcast.frame, None, broadcast.why.get(None, Loss.COLLISION), now))
            return
        default = broadcast.why.get(None, Loss.COLLISION)
        for node in self.modules:
            if node not in broadcast.reached and (broadcast.targets is None or node in broadcast.targets
                                                  or node in self.sniffers):
                self._lost(Lost(broadcast.frame, node, broadcast.why.get(node, default), now))
