"""Seed 001's actions and guards, bound to the nets' transitions by name.

RA (subnet state ``slam.robot``):

* ``slam.boot``: makes the RA's state: its body (true wheels with systematic errors,
  the wheels it believes: UMBmark-calibrated or nominal), its empty history; reads the
  beacons around it and asks the nearest WA holding more nodes for them (Algorithm 1
  begins with ``goto evaluate``).
* ``slam.explore``: one leg of Algorithm 1: decide where to go (a random pending path
  of the vertex it stands on, the route to the nearest vertex with pending paths, the
  path the reading rule gave; centralised: what the central unit decided), drive to
  the next sensor event, update the history (a new vertex or an existing one's pending
  paths); then evaluate: no WA in range means a WA must be installed; the nearest WA
  (highest RSSI) gets the RA's array if it holds fewer nodes, or is asked for its own if
  it holds more. The first one only looks all round (the first vertex). A motor failure
  (``fail_at``) ends it ``failed``, its radio off.
* ``slam.install``: stop, drop the next WA, wait for it to boot and give up finding an
  access point (5 s, §3.2), connect and program it: SSID = the RA's name and the
  installation number, the array, its estimated position. The WA's start token carries
  the programming.
* ``slam.finish``: nothing is pending: the map is done; tell the base.

WA (``slam.wireless``): ``slam.scan`` (every ``period`` s: note the RAs heard; as a
client, connect to the nearest access point and exchange by Algorithm 2, then become an
access point; a client that finds none within ``window`` s becomes an access point, and
an access point nobody joined for ``window`` to 3 ``window`` s (seeded) a client again; take
in the newer "last heard of" times of the WAs it hears; raise an alert when an RA has not
been heard of for ``alert_after`` s although the map has pending paths and other WAs are
in reach to compare with), ``slam.switch_off``.

Everyone with a radio: ``slam.send`` (the next frame of its outbox into the air) and
``slam.receive`` (a frame addressed to it; guard ``slam.addressed`` on the frame).

Central unit (``slam.central``): ``slam.central_boot``, ``slam.serve`` (its loop: alerts,
its failure), frames handled in ``slam.receive`` (an RA's report: Algorithm 1 on the
central map, the decision back). Base (``slam.base``): ``slam.receive`` (alerts, the end),
``slam.dispatch`` (a reserve RA goes in for a missing one).
"""

from __future__ import annotations

import math
from typing import Any

from petriflow.agents.slam.agent import Air, Base, Central, Robot, Wireless, frame, merge_seen
from petriflow.agents.slam.corridors import SLAM, to_map
from petriflow.agents.slam.history import choose, exchange_role, read_node, update
from petriflow.capabilities import Bodies, Physics, Poses
from petriflow.runtime.action import Action, ActionContext, ActionFailure, InstantAction, Param, Status

__all__ = ["GUARDS", "AIR", "SLAM", "Boot", "Explore", "Install", "Finish", "Scan", "SwitchOff", "Send", "Receive",
           "CentralBoot", "Serve", "Dispatch"]

#: The resource type of the beacons.
AIR = "slam.air"
PLACE = "the shared air place (frames travel through it)"


def _radio(ctx: ActionContext, air_place: str) -> Any:
    return ctx.link(air_place)[0]


def _publish(ctx: ActionContext, state: Robot | Wireless) -> None:
    air: Air = ctx.resource("air")
    if isinstance(state, Robot) and state.broken:
        air.silence(state.name)
        return
    beacon = state.beacon()
    if air.beacons.get(state.name) != beacon:
        air.publish(state.name, beacon)


class Boot(InstantAction):
    """Make the RA's state (body, calibrated wheels, history); ask a WA for its map.

    It declares what it needs of its run: the world's poses, bodies and physics (its
    body drives the pybullet robot) and the world file's ``meta.slam`` (:data:`SLAM`),
    read and checked when the world is loaded.
    """

    agent_state = Robot
    resources = {"air": AIR}
    uses = (Poses, Bodies, Physics)
    settings = SLAM
    params = {
        "slot": Param(int, 0, "the RA's slot: its vertex ids are slot * 1000 + n", low=0),
        "mode": Param(str, "decentralised", "decentralised or centralised", choices=("decentralised", "centralised")),
        "was": Param(int, 16, "WAs it carries", low=0),
        "air": Param(str, "air", PLACE, places=""),
        "speed": Param(float, 0.325, "cruise speed (m/s)", low=1e-6),
        "turn_rate": Param(float, 1.5, "turn rate on the spot (rad/s)", low=1e-6),
        "wheel_radius": Param(float, 0.025, "nominal wheel radius (m)", low=1e-6),
        "track": Param(float, 0.2, "nominal wheelbase (m)", low=1e-6),
        "ppr": Param(int, 200, "encoder pulses per wheel turn", low=1),
        "ed": Param(float, 1.003, "UMBmark Ed: right over left wheel diameter (the true wheels)", low=0.5, high=2),
        "eb": Param(float, 1.015, "UMBmark Eb: true over nominal wheelbase", low=0.5, high=2),
        "umbmark": Param(bool, True, "calibrate the wheels by UMBmark before the mission"),
        "passes": Param(int, 2, "UMBmark passes", low=1),
        "compass_deg": Param(float, 1.0, "compass resolution (degrees)", low=0),
        "sensor_range": Param(float, 4.0, "distance sensors' range (m)", low=0.1),
        "match": Param(float, 1.0, "two positions nearer than this (m) are one vertex", low=0.01),
    }

    @classmethod
    def requirements(cls, params: dict[str, Any]) -> frozenset[str]:
        return frozenset({"world"})

    def run(self, ctx: ActionContext) -> None:
        from petriflow.agents.slam.odometry import Compass, Wheels, calibrate
        from petriflow.agents.slam.robot import Body, LegSettings

        p = self.params
        if ctx.world is None:
            raise ActionFailure("slam.boot: an RA needs a world")
        name = ctx.agent or ctx.transition
        layout = ctx.settings
        nominal = Wheels.nominal(p["wheel_radius"], p["track"])
        true = nominal.with_errors(p["ed"], p["eb"])
        believed, passes = (calibrate(true, nominal, p["ppr"], passes=p["passes"]) if p["umbmark"]
                            else (nominal, []))
        if not p["umbmark"]:
            from petriflow.agents.slam.odometry import umbmark

            passes = [umbmark(true, nominal, p["ppr"])]
        x, y = ctx.world.position(name)
        origin = (x, y) if layout["origin"] is None else tuple(layout["origin"])
        start = to_map((x, y), origin)
        radios = sorted(n for n in ctx.world.bodies if n.startswith(("wa_", "node")))
        body = Body(ctx.world, name, true=true, believed=believed, ppr=p["ppr"], start=start,
                    compass=Compass(p["compass_deg"]), sensor_range=p["sensor_range"], ignore=radios)
        half = layout["half_width"]
        state = Robot(name, slot=p["slot"], mode=p["mode"], radius=p["match"])
        state.body = body
        state.origin = origin
        state.hopper = p["was"]
        state.settings = LegSettings(speed=p["speed"], turn_rate=p["turn_rate"], stop=half, centre=half,
                                     open=2 * half, graze=half / 2)
        ctx.state = state
        state.touch("plan", "install", "outbox")
        ctx.emit("slam.umbmark", passes=[r.report() for r in passes], umbmark=p["umbmark"],
                 believed=[round(believed.left, 7), round(believed.right, 7), round(believed.track, 7)])
        if p["mode"] == "decentralised":
            _evaluate(ctx, state, p["air"], boot=True)
        _publish(ctx, state)


def _evaluate(ctx: ActionContext, state: Robot, air_place: str, boot: bool = False) -> None:
    """Algorithm 1's ``evaluate``: the WAs heard; install one if none is in range; the
    nearest gets the RA's array if it holds fewer nodes, or gives its own if more."""
    air: Air = ctx.resource("air")
    radio = _radio(ctx, air_place)
    heard = air.heard(state.name, radio, ("wa",), now=ctx.now)
    in_range = any(rssi >= radio.threshold_dbm for rssi, _, _ in heard)
    if not boot and not in_range and state.installed < getattr(state, "hopper", 0) and not state.needs_wa:
        state.needs_wa = True
        state.touch("install")
    if not heard:
        return
    rssi, nearest, beacon = heard[0]
    role = exchange_role(state.history.counts(), beacon.counts)
    seen = {state.name: ctx.now}
    if role == "send":
        state.queue(frame(state.name, nearest, "data", counts=state.history.counts(),
                          payload=state.history.payload(beacon.counts), seen=seen))
    elif role == "pull":
        state.queue(frame(state.name, nearest, "pull", counts=state.history.counts(), seen=seen))
        state.awaiting = nearest
        state.touch("plan")


class Explore(Action):
    """One leg of Algorithm 1 (see the module)."""

    agent_state = Robot
    resources = {"air": AIR}
    needs_world = True
    params = {
        "air": Param(str, "air", PLACE, places=""),
        "fail_at": Param((float, int, type(None)), None, "a motor failure and a radio failure at this time (s)"),
    }

    def start(self, ctx: ActionContext) -> None:
        from petriflow.agents.slam.robot import Leg, Look

        self.state = state = ctx.state
        self.at = ctx.now
        self.leg = None
        self.done = False
        self.start_here = False
        self._check(ctx)
        if state.here is None:  # the first vertex: look all round
            self.leg = Look(state.body, state.body.compass.cardinal(state.body.pose[2]), state.settings)
            self.came_from = None
            self.start_here = True
            return
        direction = None
        if state.mode == "centralised":
            decision, state.decision = state.decision, None
            state.touch("plan")
            if decision is None or decision.get("direction") is None:
                self._finished(ctx)
                return
            direction = int(decision["direction"])
        else:
            choice = choose(state.history, state.here, ctx.rng, state.goal)
            if choice.direction is not None:
                direction = choice.direction
                if state.goal is not None and state.history.canonical(state.goal[0]) == state.here:
                    state.goal = None
            elif choice.route:
                direction = choice.route[0][0]
            else:
                self._finished(ctx)
                return
        self.came_from = state.here
        self.heading = direction
        self.leg = Leg(state.body, direction, state.settings)

    def _finished(self, ctx: ActionContext) -> None:
        state = self.state
        state.finished = True
        state.touch("plan")
        self.done = True

    def _check(self, ctx: ActionContext) -> None:
        at = self.params["fail_at"]
        state = self.state
        if at is not None and ctx.now >= at - 1e-9:
            if not state.broken:
                state.broken = True
                state.touch("plan")
                ctx.resource("air").silence(state.name)
                ctx.emit("slam.failed", at=round(ctx.now, 3), vertices=len(state.history),
                         position=list(state.body.true_map_position(state.origin)))
            raise ActionFailure(f"{state.name}: motor failure (and its radio) at {at:g} s")

    def poll(self, ctx: ActionContext) -> Status:
        if self.done:
            return Status.OK
        self._check(ctx)
        dt = ctx.now - self.at
        if dt <= 1e-12:
            return Status.RUNNING
        self.at = ctx.now
        event = self.leg.step(dt)
        if event is None:
            return Status.RUNNING
        self._arrive(ctx, event, self.came_from, start=self.start_here)
        return Status.OK

    def _arrive(self, ctx: ActionContext, event: Any, came_from: int | None, start: bool = False) -> None:
        state = self.state
        body = state.body
        state.legs += 1
        true = body.true_map_position(state.origin)
        if state.mode == "centralised":
            state.here = 0 if start else (state.here or 0)
            state.touch("plan")
            state.queue(frame(state.name, "central", "report", seen={state.name: ctx.now},
                              event={"position": list(event.position), "heading": event.heading,
                                     "openings": list(event.openings), "start": start}))
            ctx.emit("slam.leg", why=event.why, position=list(event.position), true=[round(v, 4) for v in true],
                     distance_m=round(body.travelled, 3))
            self.done = True
            return
        before = len(state.history)
        vertex = update(state.history, event.position, heading=event.heading, openings=event.openings,
                        came_from=came_from)
        state.here = vertex
        state.touch("plan")
        new = len(state.history) > before
        ctx.emit("slam.leg", why=event.why, vertex=vertex, new=new, position=list(event.position),
                 true=[round(v, 4) for v in true], distance_m=round(body.travelled, 3))
        _evaluate(ctx, state, self.params["air"])
        _publish(ctx, state)
        self.done = True

    def cancel(self, ctx: ActionContext) -> bool:
        return True


class Install(Action):
    """Drop, boot and program the next WA (see the module)."""

    agent_state = Robot
    needs_world = False
    resources = {"air": AIR}
    uses = (Physics, Bodies)  # the WA's box is put down where the RA stands
    params = {
        "index": Param(int, 1, "the installation number", low=1),
        "wa": Param(str, doc="the WA (its agent, and its box in the world)"),
        "on": Param(str, doc="the WA's loop place: its start token carries the programming", places=""),
        "air": Param(str, "air", PLACE, places=""),
        "drop_s": Param(float, 10.0, "seconds to stop and put the WA down (an assumption)", low=0),
        "window_s": Param(float, 5.0, "the new WA's client window before it becomes an access point (§3.2)",
                          low=0),
        "connect_s": Param(float, 3.0, "seconds for the RA to join the WA's access point (an assumption)", low=0),
    }

    def start(self, ctx: ActionContext) -> None:
        state = ctx.state
        p = self.params
        self.payload = state.history.payload({})
        size = frame(state.name, p["wa"], "data", payload=self.payload)["size"]
        self.wake_at = ctx.now + p["drop_s"] + p["window_s"] + p["connect_s"] + _radio(ctx, p["air"]).latency(size)

    def poll(self, ctx: ActionContext) -> Status:
        if ctx.now < self.wake_at - 1e-9:
            return Status.RUNNING
        state = ctx.state
        p = self.params
        world = ctx.world
        x, y, _ = state.body.pose
        world.p.resetBasePositionAndOrientation(world.body(p["wa"]), (x, y, 0.03), (0, 0, 0, 1),
                                                physicsClientId=world.client)
        number = state.name[2:] if state.name.startswith("ra") else state.name
        ssid = f"WA_R{number}_{p['index']}"
        position = [round(v, 4) for v in state.body.odometry]
        ctx.put(p["on"], {"ssid": ssid, "owner": state.name, "position": position,
                          "payload": self.payload, "seen": {state.name: ctx.now}})
        state.installed += 1
        state.needs_wa = False
        state.touch("install")
        ctx.emit("slam.installed", wa=p["wa"], ssid=ssid, position=position,
                 true=[round(v, 4) for v in state.body.true_map_position(state.origin)], vertices=len(state.history))
        return Status.OK


class Finish(InstantAction):
    """The map is done (nothing pending): record it, tell the base."""

    agent_state = Robot
    params = {"box": Param(str, doc="the base's mailbox", places="")}

    def run(self, ctx: ActionContext) -> None:
        state = ctx.state
        ctx.put(self.params["box"], frame(state.name, "base", "finished"))
        body = state.body
        report = {"vertices": len(state.history), "legs": state.legs, "distance_m": round(body.travelled, 3)}
        if state.mode == "decentralised":
            ctx.emit("slam.map", **_map_of(state.history))
        true = body.true_map_position(state.origin)
        report["odometry_error_m"] = round(math.dist(body.odometry, true), 4)
        report["dead_reckoning_error_m"] = round(body.dead_reckoning_error(), 4)
        ctx.emit("slam.finished", **report)


def _map_of(history: Any) -> dict[str, Any]:
    """The map as text (a trace shortens long lists to a digest): ``vertices`` is
    ``id,x,y`` rows separated by ``;``, ``edges`` ``a-b`` pairs."""
    return {"vertices": ";".join(f"{v.id},{v.x:.3f},{v.y:.3f}" for v in history.vertices()),
            "edges": ";".join(f"{a}-{b}" for a, b in sorted(history.edges())),
            "count": len(history.vertices())}


class Scan(Action):
    """A WA's Algorithm 2 cycle (see the module)."""

    agent_state = Wireless
    needs_world = False
    resources = {"air": AIR}
    params = {
        "on": Param(str, doc="the WA's loop place (its first token carries the programming)", places=""),
        "air": Param(str, "air", PLACE, places=""),
        "period": Param(float, 1.0, "seconds between scans", low=1e-3),
        "window": Param(float, 5.0, "a client connecting to no one this long becomes an access point (§3.2)",
                        low=0),
        "alert_after": Param(float, 60.0, "seconds without news of an RA before an alert", low=0),
        "match": Param(float, 1.0, "two positions nearer than this (m) are one vertex", low=0.01),
    }

    def start(self, ctx: ActionContext) -> None:
        state = ctx.state
        p = self.params
        if state is None:
            programming = ctx.inputs[p["on"]][0]
            if not isinstance(programming, dict) or "ssid" not in programming:
                raise ActionFailure(f"{ctx.agent}: no programming in its start token")
            state = Wireless(ctx.agent, programming["ssid"], programming["owner"], tuple(programming["position"]),
                             radius=p["match"])
            state.history.merge(programming["payload"])
            merge_seen(state.seen, programming.get("seen"))
            state.window_end = ctx.now + p["window"]
            if ctx.world is not None:
                state.spot = ctx.world.position(ctx.agent)
            ctx.state = state
            state.touch("outbox", "alert")
            _publish(ctx, state)
            ctx.emit("slam.wa_on", ssid=state.ssid, vertices=len(state.history))
        self.wake_at = ctx.now + p["period"]

    def poll(self, ctx: ActionContext) -> Status:
        if ctx.now < self.wake_at - 1e-9:
            return Status.RUNNING
        state: Wireless = ctx.state
        p = self.params
        air: Air = ctx.resource("air")
        radio = _radio(ctx, p["air"])
        neighbours = []
        for heard in air.heard(state.name, radio, ("ra", "wa"), now=ctx.now):
            if heard[2].kind == "ra":
                state.seen[heard[1]] = ctx.now
            else:
                neighbours.append(heard)
                merge_seen(state.seen, heard[2].seen)
        if state.role == "client":
            aps = [h for h in neighbours if h[2].role == "ap"]
            role = exchange_role(state.history.counts(), aps[0][2].counts) if aps else "greet"
            if role != "greet":  # the nearest access point holds other nodes: exchange (Algorithm 2)
                _, peer, beacon = aps[0]
                mine = state.history.counts()
                extra = {"payload": state.history.payload(beacon.counts)} if role == "send" else {}
                state.queue(frame(state.name, peer, "data" if role == "send" else "pull", counts=mine,
                                  seen=dict(state.seen), **extra))
                state.connected_at = ctx.now
                state.exchanges += 1
                state.role = "ap"
            elif ctx.now >= state.window_end - 1e-9:
                state.role = "ap"
            if state.role == "ap":
                state.window_end = ctx.now + p["window"] * (1.0 + 2.0 * ctx.rng.random())
        elif ctx.now >= state.window_end - 1e-9:
            # an access point nobody joined for a while looks for one again (not in the
            # paper: with only its client-to-AP rule, every WA ends an access point)
            state.role = "client"
            state.window_end = ctx.now + p["window"]
        _publish(ctx, state)
        for ra, heard in sorted(state.seen.items()):
            if (ctx.now - heard > p["alert_after"] and neighbours and state.history.has_pending()
                    and (ra, heard) not in state.alerted):
                state.alerted.add((ra, heard))
                state.alerts.append(frame(state.name, "base", "alert", ra=ra, last_heard=heard))
                state.touch("alert")
        return Status.OK


class SwitchOff(InstantAction):
    """The mission is over: the WA's radio goes off."""

    resources = {"air": AIR}

    def run(self, ctx: ActionContext) -> None:
        ctx.resource("air").silence(ctx.agent)


class Send(InstantAction):
    """The next frame of the agent's outbox (or its alert) into the air (or the base's box)."""

    agent_state = (Robot, Wireless, Central)
    params = {"air": Param(str, doc="the place the frame goes into", places=""),
              "alert": Param(bool, False, "send the next alert (to the base) instead")}

    def run(self, ctx: ActionContext) -> None:
        state = ctx.state
        if self.params["alert"]:
            data = state.alerts.pop(0) if state.alerts else None
            state.touch("alert")
        else:
            data = state.take()
        if data is None:
            raise ActionFailure(f"{ctx.agent}: nothing to send")
        ctx.put(self.params["air"], data)
        ctx.emit("slam.sent", to=data["to"], frame=data["kind"], bytes=data["size"])


class Receive(InstantAction):
    """A frame addressed to this agent (or the notice that its own frame was lost)."""

    agent_state = (Robot, Wireless, Central, Base)
    resources = {"air": AIR}
    params = {"air": Param(str, doc="the place frames arrive in", places=""),
              "me": Param(str, doc="the agent the frames are addressed to"),
              "window": Param(float, 5.0, "a WA's client window (§3.2)", low=0),
              "radio": Param((str, type(None)), None, "the air place, to judge the radio (a base has none)",
                             places="")}

    def run(self, ctx: ActionContext) -> None:
        data = ctx.inputs[self.params["air"]][0]
        state = ctx.state
        if isinstance(ctx.state, Base) or (state is None and self.params["radio"] is None):
            _base(ctx, data)
            return
        if state is None:
            return
        if isinstance(data, dict) and data.get("lost"):
            _lost(ctx, state, data.get("data") or {})
            return
        if isinstance(state, Robot):
            _robot_hears(ctx, state, data)
        elif isinstance(state, Wireless):
            _wa_hears(ctx, state, data, self.params["window"])
        elif isinstance(state, Central):
            _central_hears(ctx, state, data)


def _lost(ctx: ActionContext, state: Any, original: dict[str, Any]) -> None:
    """One of the agent's frames was lost: an RA waiting for an answer stops waiting
    (a report to the central unit is sent again)."""
    ctx.emit("slam.lost", to=original.get("to"), frame=original.get("kind"))
    if isinstance(state, Robot):
        if original.get("kind") == "pull" and state.awaiting == original.get("to"):
            state.awaiting = None
            state.touch("plan")
        elif original.get("kind") == "report":
            state.queue(original)


def _robot_hears(ctx: ActionContext, state: Robot, data: dict[str, Any]) -> None:
    kind = data.get("kind")
    if kind == "data":
        new = state.history.merge(data.get("payload") or {})
        if new:
            ctx.emit("slam.loaded", source=data["from"], ids=new,
                     table=";".join(",".join(str(v) for v in row) for row in state.history.table()))
        if state.awaiting == data["from"]:
            state.awaiting = None
            air: Air = ctx.resource("air")
            beacon = air.beacons.get(data["from"])
            ssid = beacon.ssid if beacon else data["from"]
            reading = read_node(state.history, ssid, state.last_read)
            if reading.kind != "ignore":
                state.last_read = ssid
            if reading.kind == "follow" and new:
                state.goal = reading.path
                state.history.take(*reading.path)
                ctx.emit("slam.reading", node=ssid, rule=reading.kind, path=list(reading.path))
        state.touch("plan")
        _publish(ctx, state)
    elif kind == "decision":
        state.decision = data.get("decision") or {}
        state.touch("plan")


def _wa_hears(ctx: ActionContext, state: Wireless, data: dict[str, Any], window: float) -> None:
    kind = data.get("kind")
    sender = data.get("from")
    merge_seen(state.seen, data.get("seen"))
    mine_before = state.history.counts()
    if kind == "data":
        new = state.history.merge(data.get("payload") or {})
        if new:
            ctx.emit("slam.wa_learnt", ssid=state.ssid, source=sender, ids=new)
    theirs = data.get("counts") or {}
    theirs = {int(k): int(v) for k, v in theirs.items()}
    if kind == "pull" or (kind == "data" and state.history.missing_for(theirs)
                          and any(n > theirs.get(b, 0) for b, n in mine_before.items())):
        state.queue(frame(state.name, sender, "data", counts=state.history.counts(),
                          payload=state.history.payload(theirs), seen=dict(state.seen)))
    if str(sender).startswith("wa_"):
        state.connected_at = ctx.now
        state.exchanges += 1
    state.role = "client"
    state.window_end = ctx.now + window
    _publish(ctx, state)


def _central_hears(ctx: ActionContext, state: Central, data: dict[str, Any]) -> None:
    if data.get("kind") != "report" or state.broken:
        return
    ra = data["from"]
    state.heard[ra] = ctx.now
    event = data["event"]
    came_from = None if event.get("start") else state.here.get(ra)
    before = len(state.history)
    vertex = update(state.history, tuple(event["position"]), heading=int(event["heading"]),
                    openings=event["openings"], came_from=came_from)
    state.here[ra] = vertex
    choice = choose(state.history, vertex, ctx.rng)
    direction = choice.direction if choice.direction is not None else (choice.route[0][0] if choice.route else None)
    if direction is None:
        state.done = True
        state.touch("plan")
        ctx.emit("slam.map", **_map_of(state.history))
    state.queue(frame(state.name, ra, "decision", decision={"direction": direction}))
    if len(state.history) > before:
        ctx.emit("slam.central_vertex", ra=ra, vertex=vertex)


def _base(ctx: ActionContext, data: dict[str, Any]) -> None:
    state = ctx.state
    if state is None:
        state = Base()
        ctx.state = state
    kind = data.get("kind") if isinstance(data, dict) else None
    if kind == "finished":
        state.over = True
        state.finished_by.append(data["from"])
        state.touch("over", "missing")
    elif kind == "alert":
        ra = data.get("ra")
        ctx.emit("slam.alert", ra=ra, by=data.get("from"), last_heard=data.get("last_heard"))
        if not state.over and ra not in state.replaced and ra not in state.missing:
            state.missing.append(ra)
            state.touch("missing")
    state.touch("over", "missing")


class CentralBoot(InstantAction):
    """Make the central unit's state; count the pre-installed nodes it works through."""

    agent_state = Central
    settings = SLAM
    params = {"match": Param(float, 1.0, "two positions nearer than this (m) are one vertex", low=0.01)}

    def run(self, ctx: ActionContext) -> None:
        state = Central(ctx.agent or "central", radius=self.params["match"])
        ctx.state = state
        state.touch("outbox", "alert", "plan")
        nodes = ctx.settings["nodes"]
        ctx.emit("slam.nodes", count=len(nodes))


class Serve(Action):
    """The central unit's loop: every ``period`` s, alert when an RA has been silent for
    ``alert_after`` s with the map unfinished; a failure at ``fail_at``."""

    agent_state = Central
    needs_world = False
    params = {"period": Param(float, 1.0, "seconds between checks", low=1e-3),
              "alert_after": Param(float, 60.0, "seconds of silence before an alert", low=0),
              "fail_at": Param((float, int, type(None)), None, "the central unit's communication error (s)")}

    def start(self, ctx: ActionContext) -> None:
        self.wake_at = ctx.now + self.params["period"]

    def poll(self, ctx: ActionContext) -> Status:
        if ctx.now < self.wake_at - 1e-9:
            return Status.RUNNING
        state: Central = ctx.state
        at = self.params["fail_at"]
        if at is not None and ctx.now >= at - 1e-9:
            state.broken = True
            ctx.emit("slam.failed", at=round(ctx.now, 3), vertices=len(state.history))
            raise ActionFailure(f"central unit: communication error at {at:g} s")
        for ra, heard in sorted(state.heard.items()):
            if (ctx.now - heard > self.params["alert_after"] and not state.done and (ra, heard) not in state.alerted):
                state.alerted.add((ra, heard))
                state.alerts.append(frame(state.name, "base", "alert", ra=ra, last_heard=heard))
                state.touch("alert")
        return Status.OK


class Dispatch(InstantAction):
    """The base sends a reserve RA in for the first RA alerts say is missing."""

    agent_state = Base
    params = {"reserve": Param(str, doc="the reserve RA that goes in")}

    def run(self, ctx: ActionContext) -> None:
        state: Base = ctx.state
        missing = state.missing.pop(0)
        state.replaced.add(missing)
        state.touch("missing")
        ctx.emit("slam.dispatched", reserve=self.params["reserve"], replaces=missing)


# Guards -------------------------------------------------------------------------------
def can_move(state: Any, params: dict[str, Any]) -> bool:
    """(reads ``plan``) The RA may drive its next leg: not waiting for an answer, not
    done, not broken (centralised: the central unit's decision is in)."""
    return isinstance(state, Robot) and state.can_move()


def needs_wa(state: Any, params: dict[str, Any]) -> bool:
    """(reads ``install``) No WA in range where the RA stands: install one."""
    return isinstance(state, Robot) and state.needs_wa and not state.broken


def has_frame(state: Any, params: dict[str, Any]) -> bool:
    """(reads ``outbox``) A frame waits in the agent's outbox."""
    return state is not None and bool(getattr(state, "outbox", None)) and not getattr(state, "broken", False)


def map_done(state: Any, params: dict[str, Any]) -> bool:
    """(reads ``plan``) Nothing pending: the RA's map is done."""
    return isinstance(state, Robot) and state.finished and not state.outbox


def alert_due(state: Any, params: dict[str, Any]) -> bool:
    """(reads ``alert``) An alert waits to go to the base."""
    return state is not None and bool(getattr(state, "alerts", None))


def missing(state: Any, params: dict[str, Any]) -> bool:
    """(reads ``missing``) The base knows of an RA that is gone and not yet replaced."""
    return isinstance(state, Base) and bool(state.missing) and not state.over


def over(state: Any, params: dict[str, Any]) -> bool:
    """(reads ``over``) The base knows the map is done."""
    return isinstance(state, Base) and state.over


def central_done(state: Any, params: dict[str, Any]) -> bool:
    """(reads ``plan``) The central unit's map is done and its decisions are sent."""
    return isinstance(state, Central) and state.done and not state.outbox


def addressed(tokens: dict[str, list[Any]], params: dict[str, Any]) -> bool:
    """A token guard: the frame in the air is for this agent (``params['me']``), or is the
    notice that this agent's own frame was lost."""
    frames = tokens.get(params.get("air"), [])
    if not frames or not isinstance(frames[0], dict):
        return False
    data = frames[0]
    if data.get("lost"):
        return isinstance(data.get("data"), dict) and data["data"].get("from") == params.get("me")
    return data.get("to") == params.get("me")


#: ``{name: (guard, the state keys it reads or None for a guard over tokens)}``.
GUARDS = {
    "slam.can_move": (can_move, ("plan",)),
    "slam.needs_wa": (needs_wa, ("install",)),
    "slam.has_frame": (has_frame, ("outbox",)),
    "slam.map_done": (map_done, ("plan", "outbox")),
    "slam.alert_due": (alert_due, ("alert",)),
    "slam.missing": (missing, ("missing",)),
    "slam.over": (over, ("over",)),
    "slam.central_done": (central_done, ("plan", "outbox")),
    "slam.addressed": (addressed, None),
}
