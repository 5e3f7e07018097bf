"""The driving controller of a robot agent: ``bidding.explore``.

The RA drives to its zones nearest first (the operator's order in a random
deployment), steering on where its odometry says it is: turn on the spot to face the
next waypoint of its route, then drive straight at it; it holds while a robot of
smaller rank is close ahead, and plans a detour around it after a while. Its laser
scans every ``scan_period`` s; each scan's new world points go to the HMIA (MAPPED).
"""

from __future__ import annotations

import math

import numpy as np

from petriflow.agents.bidding.agent import RobotAgent
from petriflow.agents.bidding.auction import tour
from petriflow.agents.bidding.cost import SPEED_M_S
from petriflow.agents.bidding.needs import DRIVEN, LIVE, OFFICE, office_of
from petriflow.agents.bidding.protocol import Kind, Payload
from petriflow.agents.bidding.robot import watch_teammates
from petriflow.runtime.action import Action, ActionContext, ActionFailure, Param, Status

__all__ = ["Explore"]


class Explore(Action):
    """RA: drive to its zones nearest first (the operator's order in a random
    deployment), steering on where its odometry says it is, scanning the laser every
    ``scan_period`` s; each scan's new world points (eq. 7-8, from the believed pose)
    go to the HMIA (MAPPED), with the zones reached and the zones first in sight. Once
    its zones are done it stands and goes on mapping until END (``idle: scan``).

    Ends after ``step`` s, or as soon as a message waits to be sent, so the work loop
    sends it and answers calls for proposals while mapping.
    """

    params = {
        "speed": Param(float, SPEED_M_S, "cruise speed (m/s)", low=1e-9),
        "turn_rate": Param(float, 1.0, "turn rate (rad/s; Stage 3.2's position controller: 1)", low=1e-9),
        "step": Param(float, 1.0, "longest run of one firing (s)", low=1e-9),
        "scan_period": Param(float, 1.0, "seconds between laser scans", low=0),
        "range": Param(float, 8.0, "laser range (m)", low=1e-9),
        "fov": Param(float, 180.0, "laser field of view (degrees)", low=1e-9, high=360),
        "beams": Param(int, 360, "laser beams", low=1),
        "z": Param(float, 0.13, "laser height (m): at the robots' body height, so teammates are seen"),
        "filter_teammates": Param(bool, False, "drop laser returns on teammates (the paper's drawback, fixed)"),
        "cell": Param(float, 0.1, "a point is new when its cell (m) was not sent before", low=1e-9),
        "send": Param(str, "every", "MAPPED after every scan (every, the paper's: its message counts follow"
                      " the mapping time) or only after scans that saw new cells (new)", choices=("every", "new")),
        "spin": Param(bool, False, "turn a full circle at every waypoint (the paper describes none)"),
        "idle": Param(str, "scan", "once its zones are done: go on scanning and sending MAPPED until END"
                      " (scan; the RA's procedure \"continues until receiving END\", §3.2.2) or stop (stop)",
                      choices=("scan", "stop")),
        "visit": Param(str, "centre", "what mapping a zone means: drive to its position (centre, the paper's)"
                       " or through waypoints spread over its room (room)", choices=("centre", "room")),
        "clearance": Param(float, 0.8, "hold while a robot of smaller rank is this close ahead (m)",
                           low=0),
        "patience": Param(float, 3.0, "seconds held before planning a detour around the robot in the way",
                          low=0),
        "inflate": Param(float, 0.35, "obstacle margin for path planning (m)", low=0),
    }
    needs_world = True
    uses = DRIVEN
    agent_state = RobotAgent
    resources = {**OFFICE, **LIVE}

    def start(self, ctx: ActionContext) -> None:
        self.ra = ra = ctx.state
        self.left = self.params["step"]
        self.at = ctx.now
        ra.keep_mapping = self.params["idle"] == "scan"
        if ra.robot is None:
            raise ActionFailure("bidding.explore: the robot agent is not initialised")
        # how far a teammate may drive between two questions of one time step (one step of
        # its own at this speed), plus slack: the margin of the robots' positions per step
        self._margin = 0.5 + 2.0 * self.params["speed"] * float(ctx.world.dt)
        watch_teammates(ctx, ra)

    def poll(self, ctx: ActionContext) -> Status:
        ra = self.ra
        dt = ctx.now - self.at  # the first poll comes at the start: no time has passed yet
        self.at = ctx.now
        if dt <= 1e-12:
            return Status.RUNNING
        self.dt = dt
        self.left -= dt
        standing = False
        if not ra.route and ra.spin_left <= 0 and not self._next(ctx):
            if not ra.keep_mapping:
                ra.changed()
                return Status.OK
            standing = True  # every zone done: stand and go on mapping until END
        if standing:
            pass
        elif ra.spin_left > 0:
            w = self.params["turn_rate"]
            half = ra.robot.encoders.track / 2.0
            self._drive(-w * half, w * half, dt)
            ra.spin_left -= w * dt
        elif not self._held(ctx):
            target = ra.route[0]
            if self._towards(target, dt, tolerance=0.05):
                ra.route.pop(0)
                if not ra.route:
                    ra.passing = None
                    ra.spin_left = 2 * math.pi if self.params["spin"] else 0.0
        ra.waiting += dt
        if ra.waiting >= self.params["scan_period"] - 1e-9:
            ra.waiting = 0.0
            self._scan(ctx)
        if not ra.route and ra.spin_left <= 0 and not ra.waypoints and ra.plan:
            self._zone_done(ctx)
        if ra.pending() or self.left <= 1e-9:
            ra.changed()
            return Status.OK
        return Status.RUNNING

    def _drive(self, left: float, right: float, dt: float) -> None:
        """Turn the wheels: the body moves (the truth), the odometry integrates the
        same wheel speeds with its errors (the robot's belief)."""
        ra = self.ra
        ra.robot.drive(left, right, dt)
        if ra.odometry is not None:
            ra.odometry.wheels(left, right, ra.robot.encoders.track, dt)

    def _towards(self, goal: tuple[float, float], dt: float, tolerance: float) -> bool:
        """One ``dt`` towards ``goal`` steered on where the robot believes it is: turn on
        the spot to face it, then drive straight at it; ``True`` once (believed) within
        ``tolerance``."""
        ra = self.ra
        x, y, yaw = ra.pose()
        distance = math.hypot(goal[0] - x, goal[1] - y)
        if distance <= tolerance:
            return True
        error = math.atan2(goal[1] - y, goal[0] - x) - yaw
        error = math.atan2(math.sin(error), math.cos(error))
        half = ra.robot.encoders.track / 2.0
        if abs(error) > 0.02:
            w = math.copysign(min(self.params["turn_rate"], abs(error) / dt), error)
            self._drive(-w * half, w * half, dt)
            return False
        v = min(self.params["speed"], distance / dt)
        w = error / dt * 0.5
        self._drive(v - w * half, v + w * half, dt)
        x, y, _ = ra.pose()
        return math.hypot(goal[0] - x, goal[1] - y) <= tolerance

    def _next(self, ctx: ActionContext) -> bool:
        """Route to the next waypoint (of this zone, or of the nearest zone left)."""
        ra = self.ra
        if not ra.waypoints:
            left = ra.left()
            if not left:
                return False
            x, y, _ = ra.pose()
            listed = [z for z in ra.order if z in left]
            zone = listed[0] if listed else left[tour((x, y), [ra.zones[z] for z in left])[0]]
            ra.plan = [zone]
            building = office_of(ctx)
            if building is not None and self.params["visit"] == "room":
                points = [tuple(p) for p in building.waypoints(zone)]
            else:
                points = [ra.zones[zone]]
            ra.waypoints = [points[k] for k in tour((x, y), points)]
        goal = ra.waypoints.pop(0)
        plan = ctx.resource("office")
        if plan is None:
            ra.route = [goal]
            return True
        route = plan.navigator(self.params["inflate"]).route(ra.pose()[:2], goal)
        if route is None:
            ctx.emit("bidding.unreachable", goal=[round(goal[0], 3), round(goal[1], 3)])
            return bool(ra.waypoints) or self._finish_zone(ctx)
        ra.route = route
        return True

    def _finish_zone(self, ctx: ActionContext) -> bool:
        self._zone_done(ctx)
        return False

    def _zone_done(self, ctx: ActionContext) -> None:
        ra = self.ra
        zone = ra.plan.pop(0)
        ra.done.add(zone)
        ra.queue(ra.hmia, Payload(Kind.MAPPED, zone=zone, body={"points": None, "finished": [zone],
                                                                "rank": ra.rank}))
        (bx, by, _), (tx, ty, _) = ra.pose(), ra.robot.pose
        ctx.emit("bidding.zone_done", zone=zone + 1, distance_m=round(ra.robot.travelled, 3),
                 drift_m=round(math.hypot(bx - tx, by - ty), 4))

    def _held(self, ctx: ActionContext) -> bool:
        """Hold while a robot of smaller rank is close ahead (no two robots wait for
        each other: ranks order them); after ``patience`` s, drive around it."""
        ra = self.ra
        blocker = self._blocker(ctx)
        if blocker is None:
            ra.held = 0.0
            return False
        ra.held += self.dt
        if ra.held < self.params["patience"]:
            return True
        ra.held = 0.0
        plan = ctx.resource("office")
        if plan is None or not ra.route:
            return False
        where = ctx.world.position(blocker)
        navigator = plan.navigator(self.params["inflate"])
        detour = navigator.around([(where[0], where[1], self.params["clearance"])]).route(ra.pose()[:2],
                                                                                           ra.route[-1])
        ctx.emit("bidding.detour", around=blocker, found=detour is not None)
        if detour is not None:
            ra.route = detour
            ra.passing = blocker
        return False

    def _blocker(self, ctx: ActionContext) -> str | None:
        ra = self.ra
        world = ctx.world
        x, y, yaw = ra.robot.pose
        clearance = self.params["clearance"]
        plan = ctx.resource("office")
        # who can be that close: the team's positions read once per step (margin: a step
        # of every robot between two questions of one step), instead of every robot's here
        near = None if plan is None else plan.near(world, ctx.now, x, y, clearance + self._margin)
        # only the robots near (not the whole team: a step's cost must not grow with it),
        # in rank order (the nearest in rank of those in the way, whatever the set's order)
        candidates = ra.alive if near is None else (near & ra.alive)
        for other in sorted(candidates, key=lambda name: (ra.ranks.get(name, ra.rank), name)):
            if other == ra.name or other == ra.passing or ra.ranks.get(other, ra.rank) >= ra.rank:
                continue
            where = world.position(other)
            if where is None:
                continue
            dx, dy = where[0] - x, where[1] - y
            distance = math.hypot(dx, dy)
            if distance < clearance:
                bearing = math.atan2(dy, dx) - yaw
                if math.cos(bearing) > 0.3:
                    return other
        return None

    def _scan(self, ctx: ActionContext) -> None:
        from petriflow.agents.bidding.laser import scan, world_points

        ra = self.ra
        p = self.params
        # the beams leave from where the robot is; it places their returns (eq. 7-8) where
        # it believes it is
        ranges, angles, bodies = scan(ctx.world, ra.name, ra.robot.pose, max_range=p["range"], fov_deg=p["fov"],
                                      beams=p["beams"], z=p["z"], ignore_teammates=p["filter_teammates"],
                                      hits=True)
        pose = ra.pose()
        points = world_points(pose, ranges, angles, p["range"])
        # which returns came off a real obstacle, which off a teammate (the simulator's
        # knowledge, for eq. 10's scoring only)
        hit = np.isfinite(ranges) & (ranges >= 0) & (ranges < p["range"]) & np.isfinite(angles)
        real = ~np.isin(bodies[hit], self._team_bodies(ctx))
        ra.scans += 1
        seen = self._sighted(pose, ranges, angles)
        every = p["send"] == "every"
        if not len(points):
            if every or seen:
                ra.queue(ra.hmia, Payload(Kind.MAPPED, body={"points": None, "finished": [], "seen": seen,
                                                             "rank": ra.rank}))
            return
        cells = np.floor(points / p["cell"]).astype(np.int64)
        keys = cells[:, 0] * 1_000_003 + cells[:, 1]
        keys, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
        # a cell is real when a real return fell in it; a cell sent as a teammate is sent
        # again once a real return falls in it
        real_cell = np.bincount(inverse.reshape(-1), weights=real.astype(float), minlength=len(keys)) > 0
        new = [k for k in range(len(keys)) if int(keys[k]) not in ra.seen
               and (real_cell[k] or int(keys[k]) not in ra.seen_teammate)]
        if not new and not every and not seen:
            return
        for k in new:
            (ra.seen if real_cell[k] else ra.seen_teammate).add(int(keys[k]))
        fresh = points[first[new]].astype(np.float32)
        ra.queue(ra.hmia, Payload(Kind.MAPPED, body={"points": fresh, "finished": [], "seen": seen,
                                                     "rank": ra.rank, "real": real_cell[new]}))

    def _team_bodies(self, ctx: ActionContext) -> np.ndarray:
        """The pybullet bodies of the robot's teammates (what its laser may see that is
        not a real obstacle)."""
        bodies = getattr(self, "_bodies", None)
        if bodies is None:
            world = ctx.world
            bodies = self._bodies = np.asarray(
                [world.body(name) for name in self.ra.team if name != self.ra.name and name in world.agents],
                dtype=np.int64)
        return bodies

    def _sighted(self, pose: tuple[float, float, float], ranges: np.ndarray, angles: np.ndarray) -> list[int]:
        """The mission's zones this scan has in sight for the first time: within the
        laser's range and field of view, and the beam nearest their bearing reaches past
        them (nothing in between). Judged from where the robot believes it is."""
        ra = self.ra
        if not ra.sight or len(ra.sighted) == len(ra.sight) or not len(angles):
            return []
        x, y, yaw = pose
        spacing = float(angles[1] - angles[0]) if len(angles) > 1 else math.pi
        seen = []
        for zone, (zx, zy) in ra.sight.items():
            if zone in ra.sighted:
                continue
            distance = math.hypot(zx - x, zy - y)
            if distance >= self.params["range"]:
                continue
            bearing = math.atan2(zy - y, zx - x) - yaw
            bearing = math.atan2(math.sin(bearing), math.cos(bearing))
            k = int(round((bearing - float(angles[0])) / spacing))
            if not 0 <= k < len(angles) or abs(float(angles[k]) - bearing) > spacing:
                continue
            if ranges[k] >= distance:
                seen.append(zone)
        ra.sighted.update(seen)
        return seen

