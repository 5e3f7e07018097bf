"""The office the robot team maps: the 32 m x 22 m floor of seed 004's Fig. 6, and larger
generated ones, as pybullet world descriptions with their ground truth.

An :class:`Office` is plain geometry in metres: its ``size`` ``(L, W)`` and the
``origin`` of its south-west corner; ``walls`` and ``furniture`` as boxes
``(cx, cy, w, d)`` (centre, x and y extents); ``rooms`` as axis-aligned rectangles
(:class:`Room`; the corridor is a room named ``"corridor"``); the ``zones`` the
interface agent auctions, ``Z1 .. Zn`` in rank order; the robots' ``starts``
``(x, y, yaw)``.

* :func:`paper_office` rebuilds Fig. 6 (the ground floor of the DPR of CDTA) as well as
  the paper lets one: four rooms north of a corridor, three south of it, one door from
  each into the corridor, some desks and cabinets; the zones and starts of Table 2
  exactly (Z1-Z4 the north rooms east to west, Z5-Z7 the south rooms east to west, Z8
  in the corridor; the five robots start in the south-east room facing north).
* :func:`generated_office` builds one straight corridor with ``n`` rooms on either side,
  seeded doors and furniture, one corridor zone per pair of facing rooms.
* :meth:`Office.world` is the world description (``meta.office`` holds the office, so
  :func:`from_meta` gets it back from a world); :meth:`Office.truth` the cells a laser
  could hit (eq. 10's ground truth); :meth:`Office.free_grid` where a robot may stand;
  :meth:`Office.waypoints` the points a robot visits to map a zone; :func:`draw` a top
  view.

Examples:
    >>> office = paper_office()
    >>> office.size, len(office.zones), office.room_of(*office.zones[7])
    ((32.0, 22.0), 8, 'corridor')
    >>> [office.room_of(*zone) for zone in office.zones[:7]]
    ['room1', 'room2', 'room3', 'room4', 'room5', 'room6', 'room7']
    >>> from_meta(office.meta()) == office
    True
    >>> big = generated_office(3, 4)
    >>> big.size, len(big.rooms), len(big.zones), len(big.starts)
    ((24.0, 18.0), 7, 9, 4)
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from petriflow.agents.bidding.errors import BiddingError
from petriflow.agents.bidding.grid import Grid, dilate
from petriflow.agents.bidding.needs import OFFICE_SETTINGS
from petriflow.worldfile import COLOURS

__all__ = [
    "WALL_THICKNESS",
    "WALL_HEIGHT",
    "FURNITURE_HEIGHT",
    "DOOR_WIDTH",
    "ROBOT_URDF",
    "ROBOT_COLOURS",
    "Box",
    "Room",
    "Office",
    "paper_office",
    "generated_office",
    "from_meta",
    "Plan",
    "plan_resource",
    "robot_colour",
    "draw_boxes",
    "draw",
]

#: Walls are 0.1 m thick and, like the furniture, 0.5 m high (above the laser's plane).
WALL_THICKNESS, WALL_HEIGHT, FURNITURE_HEIGHT = 0.1, 0.5, 0.5
#: The width of every door (m).
DOOR_WIDTH = 1.6
#: The robot every start gets by default: the package's differential drive (radius 0.15 m).
ROBOT_URDF = "petriflow.agents:robots/diffdrive.urdf"
#: The robots' colours by index (robot1 red, robot2 green, ...), cycling past six.
ROBOT_COLOURS = ("red", "green", "blue", "orange", "magenta", "cyan")
_RGBA = {**COLOURS, "magenta": (0.85, 0.1, 0.85, 1.0), "cyan": (0.05, 0.75, 0.85, 1.0)}
_FURNITURE_RGBA = [0.6, 0.47, 0.33, 1.0]
_ROBOT_Z = 0.05

#: A box ``(cx, cy, w, d)``: centre and x, y extents (m).
Box = tuple[float, float, float, float]


def robot_colour(index: int) -> tuple[float, float, float, float]:
    """RGBA of robot ``index`` (from 0): red, green, blue, orange, magenta, cyan, again.

    Examples:
        >>> robot_colour(0), robot_colour(6) == robot_colour(0)
        ((0.9, 0.1, 0.1, 1.0), True)
    """
    return _RGBA[ROBOT_COLOURS[index % len(ROBOT_COLOURS)]]


@dataclass(frozen=True)
class Room:
    """An axis-aligned room between wall centre lines (m)."""

    name: str
    xmin: float
    ymin: float
    xmax: float
    ymax: float

    @property
    def centre(self) -> tuple[float, float]:
        return ((self.xmin + self.xmax) / 2, (self.ymin + self.ymax) / 2)

    def contains(self, x: float, y: float) -> bool:
        return self.xmin <= x <= self.xmax and self.ymin <= y <= self.ymax


def _floats(values: Any, size: int, what: str) -> tuple[float, ...]:
    try:
        out = tuple(float(v) for v in values)
    except (TypeError, ValueError):
        raise BiddingError(f"{what} must be {size} numbers, got {values!r}") from None
    if len(out) != size or not all(math.isfinite(v) for v in out):
        raise BiddingError(f"{what} must be {size} finite numbers, got {values!r}")
    return out


def _box_distance(boxes: np.ndarray, x: Any, y: Any) -> np.ndarray:
    """Distance from points (arrays x, y) to each box (rows of ``boxes``): shape
    ``boxes x points``; 0 inside."""
    if boxes.size == 0:
        return np.full((0,) + np.shape(x), np.inf)
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    cx, cy, w, d = (boxes[:, i].reshape((-1,) + (1,) * x.ndim) for i in range(4))
    dx = np.maximum(np.abs(x - cx) - w / 2, 0.0)
    dy = np.maximum(np.abs(y - cy) - d / 2, 0.0)
    return np.hypot(dx, dy)


@dataclass(frozen=True)
class Office:
    """An office floor: walls, furniture, rooms, the zones to map and the robots' starts."""

    size: tuple[float, float]
    origin: tuple[float, float]
    walls: tuple[Box, ...]
    furniture: tuple[Box, ...]
    rooms: tuple[Room, ...]
    zones: tuple[tuple[float, float], ...]
    starts: tuple[tuple[float, float, float], ...]

    def __post_init__(self) -> None:
        size = _floats(self.size, 2, "size")
        if min(size) <= 0:
            raise BiddingError(f"an office's size must be > 0 m, got {self.size!r}")
        boxes = {}
        for what in ("walls", "furniture"):
            boxes[what] = tuple(_floats(box, 4, f"a {what} box (cx, cy, w, d)")
                                for box in getattr(self, what))
            if any(box[2] <= 0 or box[3] <= 0 for box in boxes[what]):
                raise BiddingError(f"{what} boxes need extents > 0")
        rooms = []
        for room in self.rooms:
            room = room if isinstance(room, Room) else Room(*room)
            xmin, ymin, xmax, ymax = _floats((room.xmin, room.ymin, room.xmax, room.ymax), 4, "a room")
            if not (isinstance(room.name, str) and room.name and xmax > xmin and ymax > ymin):
                raise BiddingError(f"a room is a name and xmin < xmax, ymin < ymax, got {room!r}")
            rooms.append(Room(room.name, xmin, ymin, xmax, ymax))
        if len({room.name for room in rooms}) != len(rooms):
            raise BiddingError("room names must be unique")
        object.__setattr__(self, "size", size)
        object.__setattr__(self, "origin", _floats(self.origin, 2, "origin"))
        object.__setattr__(self, "walls", boxes["walls"])
        object.__setattr__(self, "furniture", boxes["furniture"])
        object.__setattr__(self, "rooms", tuple(rooms))
        object.__setattr__(self, "zones", tuple(_floats(z, 2, "a zone (x, y)") for z in self.zones))
        object.__setattr__(self, "starts", tuple(_floats(s, 3, "a start (x, y, yaw)") for s in self.starts))

    # Geometry -----------------------------------------------------------------------
    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of the floor."""
        return (self.origin[0], self.origin[1], self.origin[0] + self.size[0], self.origin[1] + self.size[1])

    def boxes(self) -> np.ndarray:
        """Walls then furniture as a ``(k, 4)`` array of ``(cx, cy, w, d)``."""
        return np.asarray(self.walls + self.furniture, dtype=float).reshape(-1, 4)

    def frame(self, resolution: float = 0.1) -> Grid:
        """The grid over the floor, corner at ``origin`` (what the maps of this office use)."""
        xmin, ymin, xmax, ymax = self.bounds
        return Grid.spanning(xmin, ymin, xmax, ymax, resolution)

    def room_of(self, x: float, y: float) -> str | None:
        """The name of the (first) room holding ``(x, y)``, or ``None``."""
        for room in self.rooms:
            if room.contains(x, y):
                return room.name
        return None

    def clearance(self, x: float, y: float) -> float:
        """Distance (m) from ``(x, y)`` to the nearest wall or piece of furniture."""
        distances = _box_distance(self.boxes(), x, y)
        return float(distances.min()) if distances.size else math.inf

    def region(self, zone_index: int) -> Room:
        """The part of its room a zone covers: the whole room, or, when several zones
        share a room (corridor segments), the slice of it nearest this zone along the
        room's longer side."""
        zone = self._zone(zone_index)
        name = self.room_of(*zone)
        if name is None:
            raise BiddingError(f"zone Z{zone_index + 1} {zone} lies in no room")
        room = next(r for r in self.rooms if r.name == name)
        axis = 0 if room.xmax - room.xmin >= room.ymax - room.ymin else 1
        shared = sorted(z[axis] for z in self.zones if self.room_of(*z) == name)
        low, high = (room.xmin, room.xmax) if axis == 0 else (room.ymin, room.ymax)
        here = shared.index(zone[axis])
        if here > 0:
            low = (shared[here - 1] + shared[here]) / 2
        if here < len(shared) - 1:
            high = (shared[here] + shared[here + 1]) / 2
        if axis == 0:
            return Room(name, low, room.ymin, high, room.ymax)
        return Room(name, room.xmin, low, room.xmax, high)

    def waypoints(self, zone_index: int, clearance: float = 0.4) -> list[tuple[float, float]]:
        """The points a robot visits to map zone ``zone_index`` (from 0: Z1 is 0): the
        zone itself, then the centres of the four quarters of its :meth:`region` (south-
        west, south-east, north-east, north-west), those within ``clearance`` m of a wall
        or piece of furniture left out."""
        zone = self._zone(zone_index)
        region = self.region(zone_index)
        (cx, cy), qx, qy = region.centre, (region.xmax - region.xmin) / 4, (region.ymax - region.ymin) / 4
        points = [zone]
        for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            point = (cx + sx * qx, cy + sy * qy)
            if self.clearance(*point) >= clearance and math.dist(point, zone) > 1e-6:
                points.append(point)
        return points

    def _zone(self, zone_index: int) -> tuple[float, float]:
        if isinstance(zone_index, bool) or not isinstance(zone_index, (int, np.integer)) \
                or not 0 <= zone_index < len(self.zones):
            raise BiddingError(f"zone index must be from 0 to {len(self.zones) - 1}, got {zone_index!r}")
        return self.zones[zone_index]

    # Grids --------------------------------------------------------------------------
    def truth(self, resolution: float = 0.1) -> Grid:
        """The ground truth of eq. 10: a grid whose ``occupied`` cells are the outline of
        the walls and furniture, what a laser can hit: the cells some box covers that
        touch (8-neighbourhood) a cell no box covers; beyond the floor counts as covered.
        (Furniture stands flush against the walls, so no sliver of floor lies behind it.)"""
        frame = self.frame(resolution)
        occupied = frame.empty()
        (x0, y0), res = frame.origin, frame.resolution
        for cx, cy, w, d in self.boxes():
            c0 = max(0, math.floor((cx - w / 2 - x0) / res + 1e-9))
            c1 = min(frame.shape[1], math.ceil((cx + w / 2 - x0) / res - 1e-9))
            r0 = max(0, math.floor((cy - d / 2 - y0) / res + 1e-9))
            r1 = min(frame.shape[0], math.ceil((cy + d / 2 - y0) / res - 1e-9))
            if c1 > c0 and r1 > r0:
                occupied[r0:r1, c0:c1] = True
        frame.occupied = occupied & dilate(~occupied, 1)  # the outline: no cell inside the boxes
        return frame

    def free_grid(self, resolution: float = 0.1, inflate: float = 0.3) -> tuple[np.ndarray, Grid]:
        """``(free, frame)``: True where a disc robot of radius ``inflate`` centred on the
        cell's centre touches no wall or furniture (for path planning)."""
        if not (math.isfinite(inflate) and inflate >= 0):
            raise BiddingError(f"inflate must be >= 0 m, got {inflate!r}")
        frame = self.frame(resolution)
        free = np.ones(frame.shape, dtype=bool)
        (x0, y0), res = frame.origin, frame.resolution
        for box in self.boxes():
            cx, cy, w, d = box
            c0 = max(0, math.floor((cx - w / 2 - inflate - x0) / res) - 1)
            c1 = min(frame.shape[1], math.ceil((cx + w / 2 + inflate - x0) / res) + 1)
            r0 = max(0, math.floor((cy - d / 2 - inflate - y0) / res) - 1)
            r1 = min(frame.shape[0], math.ceil((cy + d / 2 + inflate - y0) / res) + 1)
            if c1 <= c0 or r1 <= r0:
                continue
            xs, ys = frame.centre(np.arange(r0, r1)[:, None], np.arange(c0, c1)[None, :])
            free[r0:r1, c0:c1] &= _box_distance(box[None, :], xs, ys)[0] > inflate
        return free, frame

    # Worlds -------------------------------------------------------------------------
    def meta(self) -> dict[str, Any]:
        """The office as plain JSON-able data (``meta.office`` of its world)."""
        return {
            "size": list(self.size), "origin": list(self.origin),
            "walls": [list(box) for box in self.walls], "furniture": [list(box) for box in self.furniture],
            "rooms": [{"name": r.name, "xmin": r.xmin, "ymin": r.ymin, "xmax": r.xmax, "ymax": r.ymax}
                      for r in self.rooms],
            "zones": [list(zone) for zone in self.zones], "starts": [list(start) for start in self.starts],
        }

    def world(self, robots: int, *, dt: float = 0.1, urdf: str = ROBOT_URDF) -> dict[str, Any]:
        """A world description: a floor without gravity, the walls and furniture (0.5 m
        high), robots ``robot1 .. robot<robots>`` at the first starts, the office in
        ``meta.office``."""
        if isinstance(robots, bool) or not isinstance(robots, int) or not 0 <= robots <= len(self.starts):
            raise BiddingError(f"this office has {len(self.starts)} robot starts, asked for {robots!r}"
                               " robots")
        boxes = [{"id": f"wall{i + 1}", "size": [w, d, WALL_HEIGHT], "position": [cx, cy, WALL_HEIGHT / 2],
                  "colour": "grey"} for i, (cx, cy, w, d) in enumerate(self.walls)]
        boxes += [{"id": f"furniture{i + 1}", "size": [w, d, FURNITURE_HEIGHT],
                   "position": [cx, cy, FURNITURE_HEIGHT / 2], "colour": list(_FURNITURE_RGBA)}
                  for i, (cx, cy, w, d) in enumerate(self.furniture)]
        bodies = [{"id": f"robot{k + 1}", "agent": f"robot{k + 1}", "urdf": urdf, "position": [x, y],
                   "yaw": yaw, "z": _ROBOT_Z, "colour": list(robot_colour(k))}
                  for k, (x, y, yaw) in enumerate(self.starts[:robots])]
        return {"dt": dt, "gravity": 0.0, "plane": True, "boxes": boxes, "robots": bodies,
                "meta": {"office": self.meta()}}


def from_meta(meta: dict[str, Any]) -> Office:
    """The office of a world's ``meta.office`` (:meth:`Office.meta`)."""
    try:
        return Office(
            size=tuple(meta["size"]), origin=tuple(meta["origin"]),
            walls=tuple(tuple(box) for box in meta["walls"]),
            furniture=tuple(tuple(box) for box in meta["furniture"]),
            rooms=tuple(Room(r["name"], r["xmin"], r["ymin"], r["xmax"], r["ymax"]) for r in meta["rooms"]),
            zones=tuple(tuple(zone) for zone in meta["zones"]),
            starts=tuple(tuple(start) for start in meta["starts"]),
        )
    except (KeyError, TypeError) as exc:
        raise BiddingError(f"meta.office is not an office description: {exc!r}") from None


class Plan:
    """A run's office plan and the navigators planned on it: the ``bidding.office``
    resource (one per run, made from the run's world by :func:`plan_resource`), so the
    free-space grids the robots plan on are built once per run and obstacle margin, not
    once per robot; and where the robots stood at the current time step (:meth:`near`),
    read once per step for the whole team.

    Attributes:
        office: the :class:`Office` of the world's ``meta.office``.
    """

    #: Side (m) of the cells :meth:`near` buckets the robots' positions in.
    CELL = 2.0

    def __init__(self, office: Office) -> None:
        self.office = office
        self._navigators: dict[float, Any] = {}
        self._seen_at: float | None = None
        self._cells: dict[tuple[int, int], list[str]] = {}
        self._running_at: float | None = None
        self._running: frozenset[str] = frozenset()

    def running(self, live: Any, now: float) -> frozenset[str]:
        """The run's agents running at the time step ``now`` (``live``: the run's
        ``core.liveness``), asked once per step for the whole team, not once per robot
        asking: faults happen at the start of a step, before its firings."""
        if self._running_at != now:
            self._running_at = now
            self._running = frozenset(live.running())
        return self._running

    def near(self, world: Any, now: float, x: float, y: float, radius: float) -> set[str]:
        """The agents whose robots stood within ``radius`` m of ``(x, y)`` (a box test:
        a superset of the disc) at the time step ``now``, as the world's positions were
        read at the first question of that step (every robot's, once per step, not once
        per robot asking). Robots move between two questions of one step by at most one
        step of their own, so a ``radius`` with that margin misses nobody."""
        if self._seen_at != now:
            self._seen_at = now
            self._cells = cells = {}
            for agent in world.agents:
                where = world.position(agent)
                if where is not None:
                    cells.setdefault((math.floor(where[0] / self.CELL), math.floor(where[1] / self.CELL)),
                                     []).append(agent)
        reach = math.ceil(radius / self.CELL)
        cx, cy = math.floor(x / self.CELL), math.floor(y / self.CELL)
        found: set[str] = set()
        for i in range(cx - reach, cx + reach + 1):
            for j in range(cy - reach, cy + reach + 1):
                found.update(self._cells.get((i, j), ()))
        return found

    def navigator(self, inflate: float) -> Any:
        """The :class:`~petriflow.agents.mobile.navigate.Navigator` on the free space with
        obstacles grown by ``inflate`` m (made on first use)."""
        navigator = self._navigators.get(inflate)
        if navigator is None:
            from petriflow.agents.mobile.navigate import Navigator

            free, frame = self.office.free_grid(0.1, inflate)
            navigator = self._navigators[inflate] = Navigator(free, frame.origin, frame.resolution)
        return navigator


def plan_resource(context: Any) -> Plan | None:
    """The ``bidding.office`` resource of a run: the :class:`Plan` of its world file's
    ``meta.office`` (:data:`OFFICE_SETTINGS`, read and checked when the world loaded:
    ``context.settings["office"]``); ``None``: no world, or a world without an office
    (the actions then need their zones given).

    Raises:
        BiddingError: ``meta.office`` is not an office description (geometry the
            settings' types do not catch: a box of three numbers, a size <= 0).
    """
    values = context.settings.get(OFFICE_SETTINGS.name)
    if values is None or values.get("size") is None:
        return None
    return Plan(from_meta(values))


# Building offices ---------------------------------------------------------------------
def _run(low: float, high: float, doors: tuple[float, ...]) -> list[tuple[float, float]]:
    """Wall pieces from ``low`` to ``high`` (extended by half a thickness at both ends to
    close the corners) with a door gap of ``DOOR_WIDTH`` centred at each door."""
    pieces, start = [], low - WALL_THICKNESS / 2
    for door in sorted(doors):
        end = door - DOOR_WIDTH / 2
        if end > start:
            pieces.append((start, end))
        start = door + DOOR_WIDTH / 2
    pieces.append((start, high + WALL_THICKNESS / 2))
    return [(a, b) for a, b in pieces if b - a > 1e-9]


def _wall_x(y: float, x0: float, x1: float, doors: tuple[float, ...] = ()) -> list[Box]:
    """A wall along x at ``y``, from ``x0`` to ``x1``, with doors at the x's given."""
    return [((a + b) / 2, y, b - a, WALL_THICKNESS) for a, b in _run(x0, x1, doors)]


def _wall_y(x: float, y0: float, y1: float, doors: tuple[float, ...] = ()) -> list[Box]:
    """A wall along y at ``x``, from ``y0`` to ``y1``, with doors at the y's given."""
    return [(x, (a + b) / 2, WALL_THICKNESS, b - a) for a, b in _run(y0, y1, doors)]


def _outline(xmin: float, ymin: float, xmax: float, ymax: float) -> list[Box]:
    return _wall_x(ymin, xmin, xmax) + _wall_x(ymax, xmin, xmax) + _wall_y(xmin, ymin, ymax) \
        + _wall_y(xmax, ymin, ymax)


#: Fig. 6's corridor (y from -0.5 to 4.5) and its door positions (x) on each side.
_PAPER_CORRIDOR = (-0.5, 4.5)
_PAPER_NORTH_DOORS = (9.0, 1.0, -4.0, -11.0)     # rooms 1-4
_PAPER_SOUTH_DOORS = (8.0, 2.0, -7.0)            # rooms 5-7
_PAPER_FURNITURE: tuple[Box, ...] = (   # desks 2 x 0.8 m, cabinets 0.6 x 1.6 m, tables; flush with the walls
    # room1 (north-east)
    (13.5, 10.55, 2.0, 0.8), (7.0, 10.55, 1.6, 0.8), (15.65, 6.0, 0.6, 1.6),
    # room2
    (4.6, 10.55, 2.0, 0.8), (-1.15, 8.5, 0.6, 1.6), (4.5, 6.5, 1.2, 1.2),
    # room3
    (-7.5, 10.55, 2.0, 0.8), (-3.0, 10.55, 2.0, 0.8), (-8.4, 6.0, 0.6, 1.6),
    # room4 (north-west)
    (-14.5, 10.55, 2.0, 0.8), (-15.65, 7.0, 0.6, 1.6), (-10.0, 8.5, 1.2, 1.2),
    # room5 (south-east, the robots' room)
    (14.5, -0.95, 2.0, 0.8), (15.65, -4.5, 0.6, 1.6), (11.0, -5.0, 1.6, 1.0), (12.5, -10.55, 2.0, 0.8),
    # room6
    (-1.5, -10.55, 2.0, 0.8), (2.5, -10.55, 2.0, 0.8), (-3.15, -3.0, 0.6, 1.6), (3.5, -7.5, 1.0, 1.6),
    # room7 (south-west)
    (-13.0, -10.55, 2.0, 0.8), (-10.0, -10.55, 2.0, 0.8), (-15.65, -5.0, 0.6, 1.6), (-5.5, -7.5, 1.6, 1.0),
    (-12.5, -0.95, 2.0, 0.8),
)


def paper_office() -> Office:
    """The 32 m x 22 m office of Fig. 6 with the zones and starts of Table 2.

    Rooms (x from -16 to 16, y from -11 to 11): ``room1`` .. ``room4`` north of the
    corridor (y 4.5 to 11; partitions at x = 6, -1.5, -8.75), ``room5`` .. ``room7`` south
    of it (y -11 to -0.5; partitions at x = 4.5, -3.5), ``roomk`` holding zone ``Zk``;
    the ``corridor`` (y -0.5 to 4.5) holds Z8. Each room has one 1.6 m door into the
    corridor.
    """
    x0, x1, y0, y1 = -16.0, 16.0, -11.0, 11.0
    south, north = _PAPER_CORRIDOR
    walls = _outline(x0, y0, x1, y1)
    walls += _wall_x(north, x0, x1, _PAPER_NORTH_DOORS) + _wall_x(south, x0, x1, _PAPER_SOUTH_DOORS)
    walls += [box for x in (6.0, -1.5, -8.75) for box in _wall_y(x, north, y1)]
    walls += [box for x in (4.5, -3.5) for box in _wall_y(x, y0, south)]
    rooms = (
        Room("room1", 6.0, north, x1, y1), Room("room2", -1.5, north, 6.0, y1),
        Room("room3", -8.75, north, -1.5, y1), Room("room4", x0, north, -8.75, y1),
        Room("room5", 4.5, y0, x1, south), Room("room6", -3.5, y0, 4.5, south),
        Room("room7", x0, y0, -3.5, south), Room("corridor", x0, south, x1, north),
    )
    zones = ((10.5, 8.1), (2.0, 8.1), (-5.0, 8.1), (-12.5, 8.1),      # Table 2: g1 .. g8
             (13.0, -8.1), (0.5, -5.5), (-8.1, -5.5), (0.0, 2.0))
    starts = tuple((x, -9.0, math.pi / 2) for x in (6.0, 7.0, 8.0, 9.0, 10.0))
    return Office((x1 - x0, y1 - y0), (x0, y0), tuple(walls), _PAPER_FURNITURE, rooms, zones, starts)


_DESK, _CABINET = (2.0, 0.8), (0.6, 1.6)
_ZONE_CLEAR = 1.0    # generated furniture stands at least this far from the zone (m)
_APART = 0.6         # and from other furniture
_DOOR_CLEAR = 2.0    # and leaves this depth in front of the door free
_MAX_EXTENT = 990.0  # a world's box is at most 1 km long


def _check_count(value: Any, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise BiddingError(f"{what} must be a whole number >= 1, got {value!r}")
    return int(value)


def _furnish(rng: random.Random, room: Room, door_x: float, corridor_side: str) -> list[Box]:
    """1 to 3 desks (against the wall opposite the door) and cabinets (against the side
    walls), clear of the room's centre, of the door and of each other."""
    inner = WALL_THICKNESS / 2   # flush with the walls
    xmin, xmax, ymin, ymax = room.xmin + inner, room.xmax - inner, room.ymin + inner, room.ymax - inner
    door_y = room.ymin if corridor_side == "south" else room.ymax
    y_a, y_b = sorted((door_y, door_y + (_DOOR_CLEAR if corridor_side == "south" else -_DOOR_CLEAR)))
    keep_out = (door_x - DOOR_WIDTH / 2 - 0.5, y_a, door_x + DOOR_WIDTH / 2 + 0.5, y_b)
    placed: list[Box] = []
    for _ in range(rng.randint(1, 3)):
        for _attempt in range(20):
            if rng.random() < 0.5:
                w, d = _DESK
                y = ymax - d / 2 if corridor_side == "south" else ymin + d / 2
                x = rng.uniform(xmin + w / 2, xmax - w / 2) if xmax - xmin > w else math.nan
            else:
                w, d = _CABINET
                x = xmin + w / 2 if rng.random() < 0.5 else xmax - w / 2
                y = rng.uniform(ymin + d / 2, ymax - d / 2) if ymax - ymin > d else math.nan
            box = (round(x, 2), round(y, 2), w, d)
            if math.isnan(x + y) or not _fits(box, placed, room.centre, keep_out):
                continue
            placed.append(box)
            break
    return placed


def _fits(box: Box, placed: list[Box], zone: tuple[float, float], keep_out: tuple[float, ...]) -> bool:
    boxes = np.asarray([box])
    if _box_distance(boxes, *zone)[0] < _ZONE_CLEAR:
        return False
    cx, cy, w, d = box
    kx0, ky0, kx1, ky1 = keep_out
    if cx + w / 2 > kx0 and cx - w / 2 < kx1 and cy + d / 2 > ky0 and cy - d / 2 < ky1:
        return False
    for ox, oy, ow, od in placed:
        if abs(cx - ox) - (w + ow) / 2 < _APART and abs(cy - oy) - (d + od) / 2 < _APART:
            return False
    return True


def generated_office(rooms_per_side: int, robots: int, *, room: tuple[float, float] = (8.0, 7.0),
                     corridor: float = 4.0, seed: int = 0) -> Office:
    """A straight corridor along x with ``rooms_per_side`` rooms of ``room = (width,
    depth)`` m on each side, each with a seeded door into the corridor and 1 to 3 seeded
    desks and cabinets.

    Zones, in rank order: the north rooms' centres east to west, the south rooms' east
    to west (rooms ``room1 ..`` in that order), then the centres of the corridor's
    segments in front of each pair of facing rooms, east to west. The ``robots`` starts
    lie on the corridor's centre line 1 m apart around its middle, facing east.

    Raises:
        BiddingError: a count below 1, a room smaller than 3 m x 3 m, a corridor
            narrower than 2 m, an office longer than 990 m, or robots that do not fit
            in the corridor (1 m from its ends).
    """
    sides = _check_count(rooms_per_side, "rooms per side")
    team = _check_count(robots, "robots")
    width, depth = _floats(room, 2, "room (width, depth)")
    corridor = _floats((corridor,), 1, "corridor")[0]
    if width < 3.0 or depth < 3.0:
        raise BiddingError(f"rooms must be at least 3 m x 3 m, got {width:g} x {depth:g}")
    if corridor < 2.0:
        raise BiddingError(f"the corridor must be at least 2 m wide, got {corridor:g}")
    length, breadth = sides * width, 2 * depth + corridor
    if max(length, breadth) > _MAX_EXTENT:
        raise BiddingError(f"a {length:g} m x {breadth:g} m office is larger than {_MAX_EXTENT:g} m a side")
    if team - 1 > length - 2.0:
        raise BiddingError(f"{team} robots 1 m apart do not fit in a {length:g} m corridor")
    x0, y0 = -length / 2, -breadth / 2
    south, north = -corridor / 2, corridor / 2
    rng = random.Random(seed)
    rooms: list[Room] = []
    doors: dict[str, list[float]] = {"north": [], "south": []}
    furniture: list[Box] = []
    for side, ylow, yhigh in (("north", north, -y0), ("south", y0, south)):
        for i in reversed(range(sides)):
            here = Room(f"room{len(rooms) + 1}", x0 + i * width, ylow, x0 + (i + 1) * width, yhigh)
            margin = 0.5 + DOOR_WIDTH / 2
            door = round(rng.uniform(here.xmin + margin, here.xmax - margin), 2)
            doors[side].append(door)
            furniture += _furnish(rng, here, door, "south" if side == "north" else "north")
            rooms.append(here)
    walls = _outline(x0, y0, -x0, -y0)
    walls += _wall_x(north, x0, -x0, tuple(doors["north"])) + _wall_x(south, x0, -x0, tuple(doors["south"]))
    for i in range(1, sides):
        walls += _wall_y(x0 + i * width, north, -y0) + _wall_y(x0 + i * width, y0, south)
    hall = Room("corridor", x0, south, -x0, north)
    zones = [r.centre for r in rooms] + [(x0 + (i + 0.5) * width, 0.0) for i in reversed(range(sides))]
    starts = tuple((k - (team - 1) / 2, 0.0, 0.0) for k in range(team))
    return Office((length, breadth), (x0, y0), tuple(walls), tuple(furniture), tuple(rooms) + (hall,),
                  tuple(zones), starts)


# Drawing --------------------------------------------------------------------------------
def draw_boxes(axis: Any, office: Office, *, alpha: float = 1.0) -> None:
    """Draw the office's walls (dark) and furniture (grey) on a matplotlib axis."""
    import matplotlib.pyplot as plt

    for boxes, face, edge in ((office.furniture, "0.7", "0.45"), (office.walls, "0.15", "0.15")):
        for cx, cy, w, d in boxes:
            axis.add_patch(plt.Rectangle((cx - w / 2, cy - d / 2), w, d, facecolor=face, edgecolor=edge,
                                         linewidth=0.6, alpha=alpha, zorder=1))


def draw(office: Office, path: str | Path, *, title: str | None = None, robots: int = 0) -> None:
    """A top view of the office as a PNG: walls, furniture, room names, the zones
    ``Z1 .. Zn`` and the first ``robots`` starts in the robots' colours."""
    if isinstance(robots, bool) or not isinstance(robots, int) or not 0 <= robots <= len(office.starts):
        raise BiddingError(f"this office has {len(office.starts)} robot starts, asked to draw {robots!r}")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    xmin, ymin, xmax, ymax = office.bounds
    width = 11.0
    figure, axis = plt.subplots(figsize=(width, max(3.0, width * (ymax - ymin) / (xmax - xmin) + 0.8)))
    draw_boxes(axis, office)
    for room in office.rooms:
        axis.text(room.xmin + 0.3, room.ymax - 0.3, room.name, fontsize=8, color="0.2", ha="left", va="top",
                  zorder=2, bbox={"boxstyle": "round,pad=0.2", "facecolor": "white", "edgecolor": "none",
                                  "alpha": 0.8})
    if office.zones:
        xs, ys = zip(*office.zones)
        axis.scatter(xs, ys, s=110, marker="*", color="tab:purple", edgecolors="k", linewidths=0.5, zorder=3,
                     label="zones")
        for j, (x, y) in enumerate(office.zones):
            axis.annotate(f"Z{j + 1}", (x, y), textcoords="offset points", xytext=(6, 5), fontsize=9,
                          fontweight="bold", color="tab:purple", zorder=3)
    for k, (x, y, yaw) in enumerate(office.starts[:robots]):
        colour = robot_colour(k)
        axis.plot([x, x + 0.45 * math.cos(yaw)], [y, y + 0.45 * math.sin(yaw)], color="k", linewidth=1,
                  zorder=4)
        axis.scatter([x], [y], s=45, color=colour, edgecolors="k", linewidths=0.6, zorder=5,
                     label=f"robot{k + 1}" if robots <= 8 else None)
    axis.set_xlim(xmin - 0.5, xmax + 0.5)
    axis.set_ylim(ymin - 0.5, ymax + 0.5)
    axis.set_aspect("equal")
    axis.set_xlabel("x (m)")
    axis.set_ylabel("y (m)")
    axis.set_title(title or f"office {xmax - xmin:g} m x {ymax - ymin:g} m: {len(office.rooms)} rooms "
                            f"(corridor included), {len(office.zones)} zones")
    axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
