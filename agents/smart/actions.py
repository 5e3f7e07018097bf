"""The SMART actions that tie vision, planning, gaits and messages into the nets.

* ``smart.capture``: ``vision.capture`` after dressing the world once (white floor,
  marker hats from its ``meta.smart``; :mod:`petriflow.agents.smart.arena`). Bound
  to the start transition ``T0`` so the first frame already shows the hats.
* ``smart.dispatch``: the decision maker's AND-split ``T5`` of the helping task
  (seed 003 §5.2.1). From the scene it locates the helper and the fallen robot,
  asks the fallen robot how it lies (its own attitude: which side faces up) and
  picks the helper's final point behind its back; it sends the two orders as SMART
  command frames (:mod:`petriflow.agents.smart.messages`): ``STOP`` to the fallen
  robot ("wait for help") and ``HELP`` with the final point to the helper, and hands
  the planner a map in which the fallen robot is an obstacle.
* ``smart.send``: encode fixed commands (``T9``: ``HOLD`` to the helper).
* ``smart.follow``: walk a legged robot along a planned path by its gait; after every
  move (gait cycle) the path tracking of §4.2 runs on the camera's latest pose
  (``planning.track``'s rule: on track, reinsertion at the farthest reachable path
  point, or stop and re-plan), and the decision maker's collision orders (hold,
  re-plan) are obeyed; optionally it ends bracing a fallen robot (``gait.brace``).
  The latest scene and the standing orders are token data in places of the net,
  which the walk reads through its ports ``scene`` and ``orders``.
* ``smart.avoid``: collision detection and avoidance in the decision loop (§4.2):
  after every image, robots closer than two standard steps stop; the higher-priority
  one re-plans, the other holds until the first has passed. The orders are the
  token of a place the decision maker takes and gives back updated (port ``orders``).
* ``smart.push``: a disturbance: an external force on a robot for a while.

Every frame sent is in the action's result (``frames``: hex bytes and the decoded
command) and in the trace as a ``custom`` event named ``smart.frame``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, ClassVar

from petriflow.agents.legged.actions import Walk
from petriflow.agents.smart import messages
from petriflow.agents.smart.arena import SMART
from petriflow.agents.smart.decision import LABELS, assess, draw_obstacle, robot_id
from petriflow.vision.capture import Capture as _VisionCapture

from petriflow.capabilities import Bodies, Cameras, Physics, Poses
from petriflow.errors import NetFormatError
from petriflow.runtime.action import Action, ActionContext, ActionFailure, Param, Port, Status
from petriflow.runtime.stopwatch import timed

__all__ = [
    "Avoid",
    "Capture",
    "Dispatch",
    "Follow",
    "Push",
    "Send",
    "frame_record",
    "simplify",
]

_STR_OR_NONE = (str, type(None))
_FLOAT_OR_NONE = (float, type(None))
_CELLS = {"resolution": 0.01, "origin": (-1.25, -0.95)}


def _field(item: Any, name: str, default: Any = None) -> Any:
    value = item.get(name) if isinstance(item, Mapping) else getattr(item, name, None)
    return default if value is None else value


def frame_record(command: messages.Command) -> dict[str, Any]:
    """A command as it travels (its bytes in hex) and as it reads, for results and traces.

    Examples:
        >>> frame_record(messages.Command(messages.ActionId.HELP, 4, (160, 99)))
        {'hex': '05 04 2c a0 2c 63 25', 'action': 'HELP', 'robot': 4, 'params': [160, 99]}
    """
    return {"hex": messages.encode(command).hex(" "), "action": command.action.name, "robot": command.robot,
            "params": list(command.params)}


def _send(ctx: ActionContext, commands: list[messages.Command]) -> list[dict[str, Any]]:
    records = [frame_record(c) for c in commands]
    stream = b"".join(messages.encode(c) for c in commands)
    if messages.decode(stream) != commands:  # pragma: no cover - the codec is tested
        raise ActionFailure("SMART frames do not decode back to their commands")
    for record in records:
        ctx.emit("smart.frame", sent=round(ctx.now, 6), **record)
    return records


def _cells(x: float, y: float, params: Mapping[str, Any]) -> tuple[int, int]:
    try:
        return messages.to_cells(x, y, params["resolution"], tuple(params["origin"]))
    except messages.MessageError as exc:
        raise ActionFailure(str(exc)) from None


class Capture(_VisionCapture):
    """``vision.capture`` of the dressed arena (white floor, marker hats): the
    ``smart.arena`` resource, which the run makes once before the first firing."""

    resources = {"arena": "smart.arena"}


def _is_scene(data: Any) -> bool:
    return data is not None and _field(data, "label_map") is not None and _field(data, "robots") is not None


def _scene_of(ctx: ActionContext) -> Any:
    for place in sorted(ctx.inputs):
        for data in ctx.inputs[place]:
            if _is_scene(data):
                return data
    return None


class Dispatch(Action):
    """The decision maker starts the helping task (``T5``): the helper's final point,
    the planner's map, and the SMART frames ``STOP`` (fallen robot) and ``HELP`` (helper)."""

    params: ClassVar[dict[str, Param]] = {
        "helper": Param(str, "yellow", "the helper's colour", choices=tuple(LABELS)),
        "fallen": Param(str, "red", "the fallen robot's colour", choices=tuple(LABELS)),
        "gap": Param(float, 0.17, "brace distance from the fallen robot's centre (m), as gait.brace",
                     low=0),
        "approach": Param(float, 0.15, "the final point lies this much farther out (m), as gait.brace",
                          low=0),
        "height": Param(float, 0.13, "height of the fallen robot's visible side (m), for its position"),
        "obstacle": Param(float, 0.15, "radius (m) of the fallen robot drawn as an obstacle in the helper's map",
                          low=0),
        "side": Param(float, 0.26, "side L of a marker patch (m)", low=1e-9),
        "resolution": Param(float, _CELLS["resolution"], "size of a command's coordinate cell (m)",
                            low=1e-9),
        "origin": Param(list, list(_CELLS["origin"]), "world [x, y] of command cell (0, 0)"),
    }
    needs_world = False
    uses = (Cameras, Bodies, Physics)
    settings = SMART

    def setup(self, world: Any) -> None:
        self.world = world

    def start(self, ctx: ActionContext) -> None:
        ctx.result = self._decide(ctx)

    def _decide(self, ctx: ActionContext) -> dict[str, Any]:
        params = self.params
        scene = _scene_of(ctx)
        if scene is None:
            raise ActionFailure("smart.dispatch: no scene in the input tokens")
        world = ctx.world if ctx.world is not None else self.world
        camera = _field(scene, "camera")
        if camera is None and len(world.cameras) == 1:
            camera = next(iter(world.cameras.values()))
        size = _field(scene, "size")
        if camera is not None and size is not None and (camera.width, camera.height) != tuple(size):
            import dataclasses

            camera = dataclasses.replace(camera, width=int(size[0]), height=int(size[1]))
        helper = assess(scene, params["helper"], side=params["side"])
        fallen = assess(scene, params["fallen"], side=params["side"], height=params["height"], camera=camera)
        if helper.state != "upright" or helper.position is None:
            raise ActionFailure(f"smart.dispatch: the helper ({params['helper']}) is {helper.state}")
        if fallen.state != "down" or fallen.position is None:
            raise ActionFailure(f"smart.dispatch: the robot to help ({params['fallen']}) is {fallen.state}")
        # the fallen robot's own attitude report: which way its top plate faces
        from petriflow.agents.legged.righting import brace_point, lying_on
        from petriflow.agents.smart.arena import colour_robots

        body = colour_robots(world, ctx.settings).get(params["fallen"])
        if body is None:
            raise ActionFailure(f"smart.dispatch: no robot wears {params['fallen']!r} (world meta.smart.markers)")
        from petriflow.agents.legged.control import LeggedRobot

        _, rotation = LeggedRobot(world, body).frame()
        side = lying_on(rotation)
        if side not in ("left", "right"):
            raise ActionFailure(f"smart.dispatch: robot {body!r} lies on its {side}: no side to brace")
        where = (fallen.position[0], fallen.position[1], 0.0)
        brace = brace_point(where, rotation, params["gap"])
        final = brace_point(where, rotation, params["gap"] + params["approach"])
        scale = float(_field(scene, "metres_per_pixel"))
        label_map = draw_obstacle(_field(scene, "label_map"), fallen.pixel, params["obstacle"] / scale)
        cells = _cells(final[0], final[1], params)
        frames = _send(ctx, [
            messages.Command(messages.ActionId.STOP, robot_id(params["fallen"])),
            messages.Command(messages.ActionId.HELP, robot_id(params["helper"]), cells),
        ])
        return {
            "label_map": label_map,
            "metres_per_pixel": scale,
            "origin": list(_field(scene, "origin")),
            "poses": dict(_field(scene, "poses") or {}),
            "goal": {params["helper"]: [round(final[0], 4), round(final[1], 4)]},
            "fallen": {"colour": params["fallen"], "robot": body, "side": side,
                       "x": round(fallen.position[0], 4), "y": round(fallen.position[1], 4),
                       "brace": [round(v, 4) for v in brace]},
            "helper": {"colour": params["helper"], "x": round(helper.position[0], 4),
                       "y": round(helper.position[1], 4)},
            "frames": frames,
        }

    def poll(self, ctx: ActionContext) -> Status:
        return Status.OK


class Send(Action):
    """Send fixed SMART commands: ``commands: [[ACTION, robot colour or id, p1, p2], ...]``."""

    params: ClassVar[dict[str, Param]] = {
        "commands": Param(list, doc="[[ACTION, robot colour or id, params...], ...] (ACTION: MOVE_TO, STOP, "
                                    "TURN, STAND_UP, HELP, HOLD)"),
    }
    needs_world = False

    @classmethod
    def check_params(cls, given: dict[str, Any], where: str) -> dict[str, Any]:
        checked = super().check_params(given, where)
        for entry in checked["commands"]:
            try:
                cls._command(entry)
            except (KeyError, ValueError, TypeError, messages.MessageError) as exc:
                raise NetFormatError(f"bad SMART command {entry!r}: {exc}", element=where) from None
        return checked

    @staticmethod
    def _command(entry: Any) -> messages.Command:
        action, robot, *rest = entry
        robot = robot_id(robot) if isinstance(robot, str) else int(robot)
        command = messages.Command(messages.ActionId[str(action).upper()], robot, tuple(int(v) for v in rest))
        messages.encode(command)
        return command

    def start(self, ctx: ActionContext) -> None:
        ctx.result = {"frames": _send(ctx, [self._command(e) for e in self.params["commands"]])}

    def poll(self, ctx: ActionContext) -> Status:
        return Status.OK


def simplify(points: list, tolerance: float) -> list[int]:
    """Indices of the points Ramer–Douglas–Peucker keeps: the polyline through them
    stays within ``tolerance`` of every point.

    Examples:
        >>> simplify([(0, 0), (1, 0.001), (2, 0), (2, 1), (2, 2)], 0.01)
        [0, 2, 4]
    """
    import numpy as np

    pts = np.asarray(points, dtype=float)
    keep = {0, len(pts) - 1}
    stack = [(0, len(pts) - 1)]
    while stack:
        a, b = stack.pop()
        if b <= a + 1:
            continue
        ab = pts[b] - pts[a]
        norm = float(np.hypot(*ab))
        rel = pts[a + 1:b] - pts[a]
        if norm > 0:
            dist = np.abs(ab[0] * rel[:, 1] - ab[1] * rel[:, 0]) / norm
        else:
            dist = np.hypot(rel[:, 0], rel[:, 1])
        i = int(np.argmax(dist))
        if dist[i] > tolerance:
            k = a + 1 + i
            keep.add(k)
            stack += [(a, k), (k, b)]
    return sorted(keep)


class Follow(Walk):
    """Walk a legged robot along a planned path by its gait, checking the track after
    every move (seed 003 §4.2) on the camera's pose, obeying the decision maker's
    collision orders, and optionally ending braced behind a fallen robot.

    The path is ``path`` or the input token's ``path`` (``planning.astar``'s result);
    it is walked through the corners Ramer–Douglas–Peucker keeps within
    ``simplify`` metres. After each gait cycle, when the camera has a new pose of the
    robot (``colour``), ``dc`` decides: on track; reinsertion (the robot heads for the
    farthest path point within ``reach``, then on along the path); or, farther than
    ``radius``, the action fails with ``decision: replan`` so the net can plan again.

    Two ports name places the walk reads while it runs: ``scene``, the place holding
    the camera's latest scene (for the tracking), and ``orders``, the place holding
    the decision maker's standing orders (``smart.avoid``): a ``hold`` order for its
    colour keeps the robot standing until released; a ``replan`` order (each has an
    ``id``; the walk obeys one once) fails the action the same way.
    """

    params: ClassVar[dict[str, Param]] = {
        "robot": Param(_STR_OR_NONE, None, "body or agent to walk (default: the agent)"),
        "colour": Param(_STR_OR_NONE, None, "its marker colour for the camera (default: from the world's meta)"),
        "path": Param(list, [], "waypoints [[x, y], ...] (default: the input token's path)"),
        "brace": Param(_STR_OR_NONE, None, "end braced behind this fallen robot (body or agent), as gait.brace"),
        "gap": Param(float, 0.17, "brace distance from the fallen robot's centre (m)", low=0),
        "approach": Param(float, 0.15, "extra distance of the brace approach point (m)", low=0),
        "step": Param(_FLOAT_OR_NONE, None, "dmin: one standard move (m; default: the gait's stride)"),
        "radius": Param(float, 0.15, "r: robot radius (m); farther than this from the path, re-plan",
                        low=1e-9),
        "reach": Param(_FLOAT_OR_NONE, None, "longest single move (m), the reinsertion search radius; default 2 x step"),
        "simplify": Param(float, 0.02, "corner tolerance of the walked polyline (m)", low=0),
        "localise": Param(str, "vision", "pose for path tracking: vision (the last scene) or world (ground truth)",
                          choices=("vision", "world", "off")),
        "stride": Param(_FLOAT_OR_NONE, None, "body travel per gait cycle (m; default: the gait's)"),
        "speed": Param(_FLOAT_OR_NONE, None, "walking speed at full stride (m/s; default: the gait's)"),
        "tolerance": Param(float, 0.03, "arrival distance (m)", low=0),
        "resolution": Param(float, _CELLS["resolution"], "size of a command's coordinate cell (m)",
                            low=1e-9),
        "origin": Param(list, list(_CELLS["origin"]), "world [x, y] of command cell (0, 0)"),
        "scene": Port("place holding the camera's latest scene (read for vision tracking)"),
        "orders": Port("place holding the decision maker's standing orders (read: hold, re-plan)"),
    }
    settings = SMART

    def setup(self, world: Any) -> None:
        super().setup(world)
        self.obeyed: set[Any] = set()  # ids of the re-plan orders obeyed, across this transition's firings

    @classmethod
    def check_params(cls, given: dict[str, Any], where: str) -> dict[str, Any]:
        checked = Action.check_params.__func__(cls, given, where)
        for name in ("stride", "speed", "step", "reach"):
            if checked.get(name) is not None and checked[name] <= 0:
                raise NetFormatError(f"parameter {name!r} must be > 0", element=where)
        return checked

    # Route ---------------------------------------------------------------------------
    def _route(self, ctx: ActionContext) -> list[tuple]:
        import numpy as np
        from petriflow.agents.planning.tracking import densify

        path = self.params["path"] or None
        if path is None:
            for place in sorted(ctx.inputs):
                for data in ctx.inputs[place]:
                    if data is not None and _field(data, "path") is not None:
                        path = _field(data, "path")
                        break
                if path is not None:
                    break
        if not path:
            raise ActionFailure("smart.follow: no path (params.path or an input token's path)")
        points = np.asarray(path, dtype=float)
        if points.ndim != 2 or points.shape[1] != 2:
            raise ActionFailure(f"smart.follow: a path is [[x, y], ...], got shape {points.shape}")
        self.path = densify(points, 0.02)
        kept = simplify(points.tolist(), self.params["simplify"])
        x, y, _ = self.robot.pose()
        if len(kept) > 1 and math.hypot(points[0][0] - x, points[0][1] - y) < 0.05:
            kept = kept[1:]  # the path starts where the robot stands
        # dense index of each waypoint, so a reinsertion knows which waypoints remain
        dense = [int(np.argmin(np.hypot(*(self.path - points[i]).T))) for i in kept]
        self.waypoints = [("goto", float(points[i][0]), float(points[i][1]), False) for i in kept]
        self._dense = dense
        self.tail: list[tuple] = []
        if self.params["brace"] is not None:
            self.tail = self._brace_items()
        colour = self.params["colour"]
        if colour is None:
            from petriflow.agents.smart.arena import robot_colours

            colour = robot_colours(self.world, ctx.settings).get(self.robot.name)
        self.colour = colour
        gait_step = self.gait.stride
        self.step = self.params["step"] or gait_step
        self.reach = self.params["reach"] or 2 * self.step
        self.checks: list[dict[str, Any]] = []
        self._last_scene = None
        self._holding: dict[str, Any] | None = None
        self.held_for = 0.0
        self.reinsertions = 0
        if self.colour in LABELS:
            self.frames = _send(ctx, [messages.Command(messages.ActionId.MOVE_TO, robot_id(self.colour),
                                                       _cells(item[1], item[2], self.params))
                                      for item in self.waypoints])
        else:
            self.frames = []
        outline = 0.005  # the planned path for the record, within 5 mm, at most 64 points
        shown = simplify(points.tolist(), outline)
        while len(shown) > 64:
            outline *= 2
            shown = simplify(points.tolist(), outline)
        ctx.emit("smart.path", robot=self.robot.name, colour=colour,
                 path=[[round(float(points[i][0]), 4), round(float(points[i][1]), 4)] for i in shown],
                 waypoints=[[round(item[1], 4), round(item[2], 4)] for item in self.waypoints],
                 step=round(self.step, 4), reach=round(self.reach, 4), radius=self.params["radius"])
        return list(self.waypoints) + list(self.tail)

    def _brace_items(self) -> list[tuple]:
        from petriflow.agents.legged.actions import brace_route

        items, self.brace = brace_route(self._robot(self.params["brace"]), self.params["gap"],
                                        self.params["approach"])
        return items

    def _angle_tolerance(self) -> float:
        return 0.08 if self.params["brace"] is not None else 0.05

    def _on_path(self) -> bool:
        """Whether a path waypoint is still ahead (the brace's items are not path)."""
        return bool(self.route) and any(self.route[0] is item for item in self._remaining_waypoints())

    def _remaining_waypoints(self) -> list[tuple]:
        return [item for item in self.route if not any(item is t for t in self.tail)]

    # Checks after every move -----------------------------------------------------------
    def _pose_seen(self, ctx: ActionContext) -> tuple[float, float] | None:
        mode = self.params["localise"]
        if mode == "off":
            return None
        if mode == "world":
            x, y, _ = self.robot.pose()
            return (x, y)
        scene = ctx.latest("scene")
        # a scene, or its token form (read by a robot on a remote agent: docs/bridge.md)
        token = isinstance(scene, Mapping) and isinstance(scene.get("robots"), Mapping)
        if not (_is_scene(scene) or token) or scene is self._last_scene or self.colour is None:
            return None
        if token and scene == self._last_scene:
            return None
        self._last_scene = scene
        pose = (_field(scene, "robots") or {}).get(self.colour)
        if isinstance(pose, Mapping):
            x, y = pose.get("x"), pose.get("y")
            return None if x is None or y is None else (float(x), float(y))
        position = getattr(pose, "position", None)
        return None if position is None else (float(position[0]), float(position[1]))

    def _track(self, ctx: ActionContext) -> None:
        from petriflow.agents.planning.tracking import check_track

        position = self._pose_seen(ctx)
        if position is None:
            return
        with ctx.stopwatch.measure("planning"):
            decision = check_track(self.path, position, step=self.step, radius=self.params["radius"],
                                   reach=self.reach)
        record = {"t": round(ctx.now, 4), "decision": decision.kind.value, "dc": round(decision.distance, 4),
                  "position": [round(v, 4) for v in position]}
        if decision.point is not None:
            record["point"] = [round(v, 4) for v in decision.point]
            record["index"] = decision.index
        self.checks.append(record)
        if decision.kind.value == "on_track":
            return
        ctx.emit("smart.track", robot=self.robot.name, **record)
        if decision.kind.value == "replan":
            ctx.result = {"decision": "replan", "robot": self.robot.name, "colour": self.colour,
                          "dc": record["dc"], "position": record["position"], "checks": self.checks}
            raise ActionFailure(f"robot {self.robot.name!r} is {decision.distance:.3f} m off its path "
                                f"(more than r = {self.params['radius']} m): stop and re-plan")
        # reinsertion: head for the chosen path point, then on along the path
        self.reinsertions += 1
        index = decision.index if decision.index is not None else decision.nearest
        ahead = [item for item, d in zip(self.waypoints, self._dense) if d > index]
        point = ("goto", decision.point[0], decision.point[1], False)
        self.route = [point] + ahead + list(self.tail)
        self.goal = list(self.route)
        self.best, self.stalled = math.inf, 0

    def _orders(self, ctx: ActionContext) -> dict[str, Any] | None:
        orders = ctx.latest("orders")
        return orders.get(self.colour) if isinstance(orders, Mapping) else None

    @timed("control")
    def poll(self, ctx: ActionContext) -> Status:
        if self._holding is not None:
            order = self._orders(ctx)
            if order is not None and order.get("order") == "hold":
                self.held_for += self.dt
                return Status.RUNNING
            ctx.emit("smart.release", robot=self.robot.name, held=round(self.held_for, 4))
            self._holding = None
        boundary = self.posture is None and (self.plan is None or self.plan_time >= self.plan.duration - 1e-9)
        if boundary and self._on_path():
            order = self._orders(ctx)
            if order is not None and order.get("order") == "replan" and order.get("id") not in self.obeyed:
                self.obeyed.add(order.get("id"))
                ctx.result = {"decision": "replan", "robot": self.robot.name, "colour": self.colour,
                              "others": order.get("others", []), "checks": self.checks}
                raise ActionFailure(f"robot {self.robot.name!r}: collision ahead with "
                                    f"{', '.join(order.get('others', [])) or 'another robot'}: re-plan")
            if order is not None and order.get("order") == "hold":
                self._holding = order
                ctx.emit("smart.hold", robot=self.robot.name, others=list(order.get("others", [])))
                return Status.RUNNING
            self._track(ctx)
        status = super().poll(ctx)
        if status is Status.OK:
            ctx.result = dict(ctx.result, checks=self.checks, reinsertions=self.reinsertions,
                              held=round(self.held_for, 4), frames=self.frames,
                              waypoints=[[round(i[1], 4), round(i[2], 4)] for i in self.waypoints])
            if self.params["brace"] is not None:
                ctx.result["brace"] = [round(v, 4) for v in self.brace]
        return status


class Avoid(Action):
    """Collision detection in the decision loop (§4.2): after every image, robots
    closer than ``steps`` standard steps stop; the higher-priority one re-plans with
    the other as a fixed obstacle, the other holds until it has passed.

    The standing orders ``{colour: {"order": "go" | "hold" | "replan", "others": [...],
    "t": time, "id": n}}`` are the token of the place the ``orders`` port names: the
    transition takes it and gives it back updated (that place is one of its inputs
    and outputs), and ``smart.follow`` reads it. A ``replan`` order stands until
    another order replaces it; each one has a new ``id`` so a walk obeys it once. A
    ``STOP`` frame goes to a robot told to hold. The scene is passed on to the other
    outputs."""

    params: ClassVar[dict[str, Param]] = {
        "priorities": Param(dict, doc="{colour: priority}, higher goes first"),
        "step": Param(float, 0.08, "standard step (m)", low=1e-9),
        "radius": Param(float, 0.13, "robot radius (m): distances are gaps between discs", low=0),
        "steps": Param(float, 2.0, "a conflict is a gap under this many standard steps", low=0),
        "orders": Port("place of the standing orders (an input and output of the transition)"),
    }
    needs_world = False

    def setup(self, world: Any) -> None:
        from petriflow.agents.planning.avoidance import CollisionAvoidance

        self.avoidance = CollisionAvoidance(dict(self.params["priorities"]), step=self.params["step"],
                                            radius=self.params["radius"], steps=self.params["steps"])
        self.issued = 0

    def start(self, ctx: ActionContext) -> None:
        place = self.params["orders"]
        standing = ctx.inputs.get(place, [None])[0] if place is not None else None
        orders = {colour: dict(order) for colour, order in standing.items()} if isinstance(standing, Mapping) else {}
        scene = _scene_of(ctx)
        ctx.result = scene
        if place is not None:
            ctx.put(place, orders)
        if scene is None:
            return
        robots = _field(scene, "robots") or {}
        positions = {colour: tuple(robots[colour].position) for colour in self.params["priorities"]
                     if colour in robots and getattr(robots[colour], "position", None) is not None}
        commands = []
        for colour, directive in self.avoidance.update(positions).items():
            previous = orders.get(colour, {}).get("order")
            order = directive.order.value
            if previous == "replan" and order == "go":
                continue  # a re-plan order stands until another order replaces it
            if order == "replan" or order != (previous or "go"):
                ctx.emit("smart.order", robot=colour, order=order, others=list(directive.others))
                if order == "hold":
                    commands.append(messages.Command(messages.ActionId.STOP, robot_id(colour)))
            entry = {"order": order, "others": list(directive.others), "t": round(ctx.now, 4)}
            if order == "replan":
                self.issued += 1
                entry["id"] = self.issued
            orders[colour] = entry
        if commands:
            _send(ctx, commands)

    def poll(self, ctx: ActionContext) -> Status:
        return Status.OK


class Push(Action):
    """Push a robot: an external force (world frame, N) on its base for ``duration`` s."""

    params: ClassVar[dict[str, Param]] = {
        "robot": Param(_STR_OR_NONE, None, "body or agent to push (default: the agent)"),
        "force": Param(list, doc="[fx, fy, fz] (N, world frame)"),
        "duration": Param(float, 0.2, "how long the force acts (s)", low=0),
    }
    needs_world = True
    requires = frozenset({"world", "robot"})
    uses = (Physics, Bodies, Poses)

    def setup(self, world: Any) -> None:
        if world is None:
            raise ActionFailure("smart.push needs a pybullet world")
        self.world = world

    def start(self, ctx: ActionContext) -> None:
        name = self.params["robot"] or ctx.agent
        if name is None:
            raise ActionFailure("smart.push: no robot")
        self.name = name
        self.body = self.world.body(name)
        self.before = self.world.pose(name)
        self.force = [float(v) for v in self.params["force"]]
        self._apply()

    def _apply(self) -> None:
        p = self.world.p
        com = p.getBasePositionAndOrientation(self.body, physicsClientId=self.world.client)[0]
        p.applyExternalForce(self.body, -1, self.force, com, p.WORLD_FRAME, physicsClientId=self.world.client)

    def poll(self, ctx: ActionContext) -> Status:
        if ctx.elapsed < self.params["duration"] - 1e-9:
            self._apply()
            return Status.RUNNING
        after = self.world.pose(self.name)
        ctx.result = {"robot": self.name, "force": self.force, "duration": self.params["duration"],
                      "from": [round(v, 4) for v in self.before[:2]], "to": [round(v, 4) for v in after[:2]],
                      "moved": round(math.hypot(after[0] - self.before[0], after[1] - self.before[1]), 4)}
        return Status.OK

