"""The RA's body in pybullet: a differential drive, five distance sensors, a compass.

**Body.** A kinematic differential drive (as Stage does, and as seed 000's robots): the
wheel speeds the controller commands, turned by the RA's *true* wheels
(:class:`~petriflow.agents.slam.odometry.Wheels` with systematic errors), move the body
by the kinematic model of eq. (1); pybullet holds the walls and answers the sensors' ray
casts. The encoders count whole pulses; the RA turns them into distances with the wheels
it *believes* (nominal, or UMBmark-corrected).

**Odometry** (§3.1): "the digital compass locates the RA's bearings to increment its
position in the X or Y axes": each step's travelled distance (the mean of the two
wheels' encoder distances) is added along the axis of the compass's cardinal
identifier (west +x, north +y: the map frame). :attr:`Body.dead_reckoning` is the
encoder-only estimate (x, y and heading from the wheels), kept to show what UMBmark's
correction changes.

**Sensors** (Fig. 2, not in our text): five rays 45 degrees apart across the front, 4 m
long (an ultrasonic ranger's reach, an assumption), numbered 0 (left, +90 degrees),
1 (right, -90), 2 (front left, +45), 3 (ahead), 4 (front right, -45): 2, 3 and 4 see
obstacles ahead, 0 and 1 lateral openings.

**A leg** (:class:`Leg`): turn on the spot to a cardinal bearing (compass), then drive
holding it until a sensor event: an obstacle ahead (sensor 3 at ``stop`` m, half a
corridor's width, so the RA stops where the corridor's centre lines meet; 2 or 4 nearer
than ``graze``), or a lateral opening (sensor 0 or 1 reading more than ``open`` m after
reading less: the RA goes on half a corridor's width to its centre). At the event it
reads which sides are open: the front and the two laterals, as cardinal identifiers.
At the start (:class:`Look`) it also turns round once and reads ahead again, so the first
vertex knows what is behind the RA too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from petriflow.agents.mobile.kinematic import icc_step
from petriflow.agents.slam.history import STEP, left_of, right_of
from petriflow.agents.slam.odometry import Compass, Encoders, Wheels

__all__ = ["SENSORS", "Body", "Event", "Leg", "LegSettings", "Look", "sense_event"]

#: Sensor number -> angle (rad) in the robot frame (anticlockwise from ahead).
SENSORS = {0: math.pi / 2, 1: -math.pi / 2, 2: math.pi / 4, 3: 0.0, 4: -math.pi / 4}


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


class Body:
    """One RA's body in a world (see the module).

    Args:
        world: the :class:`petriflow.world.World`.
        agent: the agent (its robot's name in the world).
        true: the wheels as they are.
        believed: the wheels the RA computes with.
        ppr: encoder pulses per wheel turn.
        start: the RA's start in the map frame (its odometry's first value).
        compass: the compass.
        ignore: body names the sensors see through (the other robots, the WAs).
    """

    def __init__(self, world: Any, agent: str, *, true: Wheels, believed: Wheels, ppr: int,
                 start: tuple[float, float] = (0.0, 0.0), compass: Compass | None = None,
                 sensor_range: float = 4.0, sensor_z: float = 0.1, ignore: list[str] | None = None) -> None:
        self.world = world
        self.agent = agent
        self.p = world.p
        self.body = world.body(agent)
        position, orientation = self.p.getBasePositionAndOrientation(self.body, physicsClientId=world.client)
        self.z = position[2]
        self.pose = (position[0], position[1], self.p.getEulerFromQuaternion(orientation)[2])
        self.true = true
        self.believed = believed
        self.encoders = Encoders(ppr)
        self.compass = compass or Compass()
        self.odometry = (float(start[0]), float(start[1]))
        self.start = self.odometry
        self.home = self.pose
        self.dead_reckoning = self.pose
        self.travelled = 0.0
        self.sensor_range = sensor_range
        self.sensor_z = sensor_z
        names = set(ignore or []) | set(world.agents)
        self.ignore = sorted({world.body(n) for n in names if _has_body(world, n)})
        # the body is placed where the kinematics say: it must not be pushed by contacts
        # (two RAs wait at the start; the floor)
        for link in range(-1, self.p.getNumJoints(self.body, physicsClientId=world.client)):
            self.p.setCollisionFilterGroupMask(self.body, link, 0, 0, physicsClientId=world.client)

    # Motion ---------------------------------------------------------------------------
    def drive(self, v: float, w: float, dt: float) -> float:
        """Command body speed ``v`` (m/s) and turn rate ``w`` (rad/s) for ``dt`` s, as
        the RA believes its wheels; returns the distance the odometry counted."""
        wl, wr = self.believed.speeds(v, w)
        left, right = wl * dt, wr * dt
        self.pose = icc_step(self.pose, left * self.true.left, right * self.true.right, self.true.track, 1.0)
        self.travelled += abs(left * self.true.left + right * self.true.right) / 2
        dl, dr = self.encoders.travel(self.encoders.advance(left, right), self.believed)
        distance = (dl + dr) / 2
        ux, uy = STEP[self.compass.cardinal(self.pose[2])]
        self.odometry = (self.odometry[0] + distance * ux, self.odometry[1] + distance * uy)
        self.dead_reckoning = icc_step(self.dead_reckoning, dl, dr, self.believed.track, 1.0)
        x, y, yaw = self.pose
        self.p.resetBasePositionAndOrientation(self.body, (x, y, self.z), self.p.getQuaternionFromEuler((0, 0, yaw)),
                                               physicsClientId=self.world.client)
        return distance

    def bearing(self) -> float:
        """The compass bearing (degrees clockwise from west)."""
        return self.compass.bearing(self.pose[2])

    def heading_error(self, cardinal: int) -> float:
        """Radians to turn (anticlockwise positive) to face ``cardinal``, by the compass."""
        error_deg = (90.0 * cardinal - self.bearing() + 180.0) % 360.0 - 180.0
        return -math.radians(error_deg)

    def sense(self) -> dict[int, float]:
        """The five distance sensors' readings (m)."""
        from petriflow.agents.mobile.sensors import cast

        x, y, yaw = self.pose
        ranges = cast(self.world, (x, y), yaw, [SENSORS[i] for i in range(5)], self.sensor_range, z=self.sensor_z,
                      ignore=self.ignore, near=0.16)
        return dict(enumerate(ranges))

    # What the map is scored by ---------------------------------------------------------
    def true_map_position(self, origin: tuple[float, float]) -> tuple[float, float]:
        """Where the RA really is, in the map frame (x west)."""
        return (origin[0] - self.pose[0], self.pose[1] - origin[1])

    def dead_reckoning_error(self) -> float:
        """Metres between the encoder-only estimate and the true position."""
        return math.hypot(self.dead_reckoning[0] - self.pose[0], self.dead_reckoning[1] - self.pose[1])


def _has_body(world: Any, name: str) -> bool:
    return name in world.agents or name in world.bodies


@dataclass(frozen=True)
class LegSettings:
    """How the RA drives a leg (see the module); distances in metres."""

    speed: float = 0.325
    turn_rate: float = 1.5
    stop: float = 0.6
    graze: float = 0.3
    open: float = 1.2
    centre: float = 0.6
    gain: float = 2.0
    longest: float = 200.0


@dataclass
class Event:
    """Where a leg ended: the odometry there, the heading, the open sides (cardinal
    identifiers), why it stopped (``front``, ``lateral``, ``start``, ``lost``)."""

    position: tuple[float, float]
    heading: int
    openings: list[int]
    why: str
    true_position: tuple[float, float] = (0.0, 0.0)


@dataclass
class Leg:
    """One leg: turn to ``heading``, drive to the next sensor event (see the module).
    ``step(dt)`` each world step; it returns the :class:`Event` when the leg ends."""

    body: Body
    heading: int
    settings: LegSettings = field(default_factory=LegSettings)
    phase: str = "turn"
    along: float = 0.0
    onset: dict[int, float | None] = field(default_factory=lambda: {0: None, 1: None})
    armed: dict[int, bool] = field(default_factory=lambda: {0: False, 1: False})

    def step(self, dt: float) -> Event | None:
        s = self.settings
        body = self.body
        if self.phase == "turn":
            error = body.heading_error(self.heading)
            if abs(error) <= math.radians(max(body.compass.resolution_deg, 0.5)):
                self.phase = "drive"
                return None
            w = math.copysign(min(s.turn_rate, abs(error) / dt), error)
            body.drive(0.0, w, dt)
            return None
        readings = body.sense()
        if readings[3] <= s.stop + 1e-3 or min(readings[2], readings[4]) <= s.graze:
            return self._event(readings, "front")
        for side in (0, 1):
            if readings[side] > s.open:
                if self.armed[side] and self.onset[side] is None:
                    self.onset[side] = self.along
            else:
                self.armed[side] = True
                self.onset[side] = None
        onsets = [o for o in self.onset.values() if o is not None]
        if onsets and self.along - min(onsets) >= s.centre - 1e-3:
            return self._event(readings, "lateral")
        if self.along >= s.longest:
            return self._event(readings, "lost")
        v = min(s.speed, max(readings[3] - s.stop, 0.0) / dt)
        if onsets:
            v = min(v, max(s.centre - (self.along - min(onsets)), 0.0) / dt)
        v = max(v, 0.002)
        w = max(-s.turn_rate, min(s.turn_rate, s.gain * body.heading_error(self.heading)))
        self.along += body.drive(v, w, dt)
        return None

    def _event(self, readings: dict[int, float], why: str) -> Event:
        return sense_event(self.body, self.heading, readings, why, self.settings)


@dataclass
class Look:
    """At the start: read the sensors, turn on the spot to face the other way and read the
    one ahead again, so the first vertex knows all four sides (the sensors only look
    ahead and sideways). ``step(dt)`` returns the :class:`Event` (facing back) when done."""

    body: Body
    heading: int
    settings: LegSettings = field(default_factory=LegSettings)
    first: Event | None = None
    turn: Leg | None = None

    def step(self, dt: float) -> Event | None:
        from petriflow.agents.slam.history import opposite

        if self.first is None:
            self.first = sense_event(self.body, self.heading, None, "start", self.settings)
            self.turn = Leg(self.body, opposite(self.heading), self.settings)
        if self.turn.phase == "turn":
            self.turn.step(dt)
            if self.turn.phase == "turn":
                return None
        behind = sense_event(self.body, opposite(self.heading), None, "start", self.settings)
        openings = sorted(set(self.first.openings) | ({opposite(self.heading)} & set(behind.openings)))
        return Event(behind.position, self.heading, openings, "start")


def sense_event(body: Body, heading: int, readings: dict[int, float] | None, why: str,
                settings: LegSettings) -> Event:
    """The open sides where the RA stands (front and laterals, as identifiers)."""
    readings = body.sense() if readings is None else readings
    openings = []
    if readings[3] > settings.open:
        openings.append(heading)
    if readings[0] > settings.open:
        openings.append(left_of(heading))
    if readings[1] > settings.open:
        openings.append(right_of(heading))
    return Event((round(body.odometry[0], 4), round(body.odometry[1], 4)), heading, sorted(openings), why)
