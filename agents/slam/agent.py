"""The agents' states (kept by the run, ``ctx.state``) and the radio beacons they hear.

* :class:`Robot` (``slam.robot``): an RA: its body, its history (Algorithm 1), where it
  stands and where it goes, the frames it has to send, whether it needs a WA.
* :class:`Wireless` (``slam.wireless``): a WA: its SSID, its array, its Algorithm 2
  role (client or access point) and the time it last connected, when it last heard
  of each RA, its alerts.
* :class:`Central` (``slam.central``): the centralised system's central unit: the map
  and each RA's place in it (the RAs only drive and report).
* :class:`Base` (``slam.base``): the external unit that receives alerts and the end
  of the mission, and sends a reserve RA in.

**Beacons** (:class:`Air`, the ``slam.air`` resource): what a Wi-Fi scan returns of each
radio that is on: its SSID, its role and how many nodes it holds (per block of ids),
which is what Algorithm 2 compares before connecting, and, for a WA, when it last heard
of each RA (metadata of the same kind, so that the network knows within seconds whether
anyone still hears an RA). The data itself travels as
frames, tokens of the shared ``air`` place.

Frames (:func:`frame`) are the payload of the runtime's
:class:`~petriflow.runtime.channel_models.Message` through the ``air`` place: plain
mappings (the token data a trace records) with ``from``, ``to``, ``kind`` (a
:class:`FrameKind`), ``size`` (bytes), ``counts`` (the sender's nodes per block),
``payload`` (rows, pending paths, links: the history's rows, not a message), ``seen``
(the latest time the sender knows each RA was heard).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from petriflow.agents.slam.history import History
from petriflow.outcome import Name
from petriflow.runtime.agents import AgentState

__all__ = ["make_air", "Air", "Base", "Beacon", "Central", "FrameKind", "FrameSender", "RadioKind", "Robot", "Role",
           "Wireless", "frame", "merge_seen", "payload_size"]


class RadioKind(Name):
    """Whose radio a beacon is."""

    RA = "ra"
    """A robot agent's."""
    WA = "wa"
    """A wireless agent's (a node an RA put down)."""


class Role(Name):
    """A radio's Algorithm 2 role."""

    CLIENT = "client"
    """Looking for an access point to exchange with."""
    AP = "ap"
    """An access point: others connect to it."""


class FrameKind(Name):
    """What a frame is (its ``kind``; a ``str`` enum, so a trace writes the text)."""

    DATA = "data"
    """History rows the receiver lacks (Algorithm 2's sender)."""
    PULL = "pull"
    """A request for the rows the sender lacks (the node holds more)."""
    GREET = "greet"
    """Nothing but the time stamps (equal holders)."""
    REPORT = "report"
    """An RA's sensor event, to the central unit."""
    DECISION = "decision"
    """The central unit's direction for an RA."""
    ALERT = "alert"
    """A WA's alert to the base: an RA not heard for too long."""
    FINISHED = "finished"
    """The end of the map, to the base."""


@dataclass
class Beacon:
    """What a scan hears of a radio: ``kind`` (:class:`RadioKind`), ``ssid``, ``role``
    (:class:`Role`), ``counts`` (nodes per block of ids) and, for a WA, ``seen``
    (when it last heard of each RA)."""

    kind: RadioKind
    ssid: str
    role: Role
    counts: dict[int, int]
    seen: dict[str, float] | None = None
    position: tuple[float, float] | None = None  # where a radio that does not move stands (world)


class Air:
    """The beacons of every radio that is on (see the module); one per run."""

    def __init__(self) -> None:
        self.beacons: dict[str, Beacon] = {}
        self._order: list[str] = []
        self._moving_order: list[str] = []
        self._near: dict[str, list[tuple[str, float]]] = {}  # static radio -> static radios in reach
        self._moving: dict[str, tuple[float, tuple[float, float] | None]] = {}  # name -> (time, position)

    def publish(self, name: str, beacon: Beacon) -> None:
        old = self.beacons.get(name)
        self.beacons[name] = beacon
        if old is None or old.position != beacon.position:
            self._reorder()

    def silence(self, name: str) -> None:
        if self.beacons.pop(name, None) is not None:
            self._reorder()

    def _reorder(self) -> None:
        self._order = sorted(self.beacons)
        self._moving_order = [n for n in self._order if self.beacons[n].position is None]
        self._near = {}

    def _where(self, name: str, radio: Any, now: float | None) -> tuple[float, float] | None:
        beacon = self.beacons.get(name)
        if beacon is not None and beacon.position is not None:
            return beacon.position
        if now is None:
            return radio.position(name)
        cached = self._moving.get(name)
        if cached is None or cached[0] != now:
            cached = self._moving[name] = (now, radio.position(name))
        return cached[1]

    def heard(self, name: str, radio: Any, kinds: tuple[RadioKind, ...] = (RadioKind.WA,),
              now: float | None = None) -> list[tuple[float, str, Beacon]]:
        """``(RSSI, radio, beacon)`` of the radios of ``kinds`` that ``name`` hears (a
        frame has some chance to pass), strongest first. ``now``: positions of moving
        radios are looked up once per instant."""
        here = self._where(name, radio, now)
        if here is None:
            return []
        reach = radio.reach()
        mine = self.beacons.get(name)
        static = mine is not None and mine.position is not None
        if static and name not in self._near:
            near = []
            for other in self._order:
                beacon = self.beacons[other]
                if other != name and beacon.position is not None:
                    d = math.dist(here, beacon.position)
                    if d < reach:
                        near.append((other, d))
            self._near[name] = near
        candidates: list[tuple[str, float | None]]
        if static:
            candidates = self._near[name] + [(o, None) for o in self._moving_order]
        else:
            candidates = [(o, None) for o in self._order if o != name]
        out = []
        for other, distance in candidates:
            beacon = self.beacons[other]
            if beacon.kind not in kinds:
                continue
            if distance is None:
                there = self._where(other, radio, now)
                if there is None:
                    continue
                distance = math.dist(here, there)
                if distance >= reach:
                    continue
            rssi = radio.rssi(distance)
            if radio.loss(rssi) < 1.0:
                out.append((rssi, other, beacon))
        out.sort(key=lambda item: (-item[0], item[1]))
        return out


def make_air(context: Any) -> Air:
    """The ``slam.air`` resource's factory: no radio is on at the start."""
    return Air()


def payload_size(payload: dict[str, Any] | None) -> int:
    """Bytes of a payload: 8 per row (id, two 16-bit coordinates, last id, 2 for the
    pending paths), 2 per pending entry and per link."""
    if not payload:
        return 0
    rows = len(payload.get("rows", []))
    pending = sum(len(p) for p in payload.get("pending", {}).values())
    links = sum(len(v) for v in payload.get("links", {}).values())
    return 8 * rows + 2 * pending + 2 * links


def frame(sender: str, receiver: str, kind: FrameKind, **fields: Any) -> dict[str, Any]:
    """A frame (see the module): 12 bytes of header, then its payload."""
    data = {"from": sender, "to": receiver, "kind": FrameKind(kind), **fields}
    data["size"] = 12 + payload_size(fields.get("payload")) + 4 * len(fields.get("seen", {}) or {})
    return data


def merge_seen(mine: dict[str, float], theirs: dict[str, float] | None) -> bool:
    """Keep the latest time each RA was heard; whether anything got newer."""
    changed = False
    for ra, time in (theirs or {}).items():
        if time > mine.get(ra, -math.inf):
            mine[ra] = float(time)
            changed = True
    return changed


class FrameSender(AgentState):
    """The part of a state with a radio: its frames waiting to go into the air, oldest
    first, in one queue whatever their receivers (the air carries one frame at a
    time, in the order they were queued). A change touches the key ``outbox``."""

    def __init__(self) -> None:
        super().__init__()
        self.outbox: list[dict[str, Any]] = []

    def queue(self, data: dict[str, Any]) -> None:
        self.outbox.append(data)
        self.touch("outbox")

    def take(self) -> dict[str, Any] | None:
        if not self.outbox:
            return None
        data = self.outbox.pop(0)
        self.touch("outbox")
        return data


class Robot(FrameSender):
    """An RA's state (see the module)."""

    def __init__(self, name: str, *, slot: int = 0, mode: str = "decentralised", radius: float = 1.0) -> None:
        super().__init__()
        self.name = name
        self.slot = slot
        self.mode = mode
        self.history = History(block=slot, radius=radius)
        self.body: Any = None
        self.settings: Any = None
        self.origin: tuple[float, float] = (0.0, 0.0)  # world point of the map's origin
        self.hopper = 0  # WAs it carries
        self.here: int | None = None
        self.route: list[tuple[int, int]] = []
        self.goal: tuple[int, int] | None = None
        self.decision: dict[str, Any] | None = None
        self.awaiting: str | None = None  # a peer whose answer it waits for before moving
        self.last_read: str | None = None
        self.needs_wa = False
        self.installed = 0
        self.finished = False
        self.broken = False
        self.legs = 0

    # What guards read -------------------------------------------------------------------
    def can_move(self) -> bool:
        if self.finished or self.broken or self.awaiting is not None:
            return False
        return self.mode == "decentralised" or self.here is None or self.decision is not None

    def beacon(self) -> Beacon:
        return Beacon(RadioKind.RA, self.name, Role.CLIENT, self.history.counts())

    def to_token(self) -> dict[str, Any]:
        return {"ra": self.name, "vertices": len(self.history), "installed": self.installed}


class Wireless(FrameSender):
    """A WA's state (see the module)."""

    def __init__(self, name: str, ssid: str, owner: str, position: tuple[float, float], *, radius: float = 1.0,
                 role: Role = Role.CLIENT) -> None:
        super().__init__()
        self.name = name
        self.ssid = ssid
        self.owner = owner
        self.position = position
        self.history = History(block=-1, radius=radius)
        self.spot: tuple[float, float] | None = None  # where it stands in the world (it does not move)
        self.role = role
        self.window_end = 0.0
        self.connected_at = -math.inf  # the last time it exchanged with another WA
        self.seen: dict[str, float] = {}
        self.alerted: set[tuple[str, float]] = set()
        self.alerts: list[dict[str, Any]] = []
        self.exchanges = 0

    def beacon(self) -> Beacon:
        return Beacon(RadioKind.WA, self.ssid, self.role, self.history.counts(), dict(self.seen), self.spot)

    def to_token(self) -> dict[str, Any]:
        return {"wa": self.ssid, "role": self.role, "vertices": len(self.history)}


class Central(FrameSender):
    """The central unit's state (see the module)."""

    def __init__(self, name: str = "central", *, radius: float = 1.0) -> None:
        super().__init__()
        self.name = name
        self.history = History(block=0, radius=radius)
        self.here: dict[str, int | None] = {}
        self.heard: dict[str, float] = {}
        self.alerted: set[tuple[str, float]] = set()
        self.alerts: list[dict[str, Any]] = []
        self.done = False
        self.broken = False

    def to_token(self) -> dict[str, Any]:
        return {"central": self.name, "vertices": len(self.history)}


class Base(AgentState):
    """The external unit's state (see the module)."""

    def __init__(self) -> None:
        super().__init__()
        self.missing: list[str] = []  # RAs alerts say are gone, not yet replaced
        self.replaced: set[str] = set()
        self.over = False
        self.finished_by: list[str] = []

    def to_token(self) -> dict[str, Any]:
        return {"base": "base", "over": self.over, "missing": list(self.missing)}
