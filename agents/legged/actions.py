"""Gait actions for the SMART legged robots: walk, turn, brace a fallen robot, stand up.

Every action commands joint positions every scheduler tick and lets pybullet move the
robot by its legs; none sets a body's pose. The legs follow the gait of the robot's
design (:func:`petriflow.agents.legged.gait.gait_for`: Robot4L crawls, Robot3L
slides), planned one cycle at a time from the measured pose, so the robot corrects its
heading and distance as it goes.

* ``gait.walk``: to a point ``(x, y)`` (turning on the spot first when it is far off
  the heading), or ``distance`` metres along the current heading (negative: backwards);
  optional final ``heading``.
* ``gait.turn``: on the spot by ``angle`` rad (counter-clockwise positive).
* ``gait.brace`` (the helper, seed 003 §5.2): walk to the back of a fallen robot lying
  on its side (:func:`petriflow.agents.legged.righting.brace_point`), face it and stop
  there, holding the fallen robot so it cannot roll onto its back.
* ``gait.stand_up`` (the fallen Robot4L): roll from its side onto its feet and stand
  (:func:`petriflow.agents.legged.righting.righting_motion`), leaning on its ``helper``
  when one is named (it must be braced behind it). A robot on its back cannot.

In the paper's cooperation net (Fig. 17) the helper's "trajectory and final point" and
"helper arrived" are ``gait.brace``; "crawled robot stands up" is ``gait.stand_up``;
the helper then "holds its final position": its motors keep their last targets.

Examples:
    >>> Walk.check_params({"x": 1, "y": 0}, where="t")["x"]
    1.0
    >>> sorted(Turn.params)
    ['angle', 'robot', 'speed', 'stride', 'tolerance']
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

from petriflow.agents.legged.control import LeggedRobot, NotLeggedError
from petriflow.agents.legged.gait import GaitError, gait_for
from petriflow.agents.legged.righting import BACK_TILT, brace_point, lying_on, righting_motion

from petriflow.capabilities import Bodies, Physics
from petriflow.errors import NetFormatError
from petriflow.runtime.action import Action, ActionContext, ActionFailure, Param, Status
from petriflow.runtime.stopwatch import timed

__all__ = ["Brace", "StandUp", "Turn", "Walk"]

_FLOAT_OR_NONE = (float, type(None))
_STR_OR_NONE = (str, type(None))
#: Tilt (rad) over which a walking robot counts as fallen.
_FALLEN = math.radians(40)


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


def _clamp(value: float, limit: float) -> float:
    return max(-limit, min(limit, value))


class _JointMove:
    """Linear joint-space interpolation from the current joints to a target."""

    def __init__(self, robot: LeggedRobot, target: dict, duration: float) -> None:
        self.robot = robot
        self.start = robot.joints()
        self.target = target
        self.duration = max(duration, 1e-9)
        self.t = 0.0

    def tick(self, dt: float) -> bool:
        self.t += dt
        s = min(1.0, self.t / self.duration)
        self.robot.command({leg: tuple(a + s * (b - a) for a, b in zip(self.start[leg], self.target[leg]))
                            for leg in self.target})
        return self.t >= self.duration - 1e-9


class _LeggedAction(Action):
    """Shared lifecycle: find the robot, tick the current motion, hold on cancel."""

    needs_world = True
    requires = frozenset({"world", "robot"})
    uses = (Physics, Bodies)

    def setup(self, world: Any) -> None:
        if world is None:
            raise ActionFailure(f"{type(self).__name__} needs a pybullet world (run with --world)")
        self.world = world
        self.robots: dict[str, LeggedRobot] = {}

    def _robot(self, name: str | None) -> LeggedRobot:
        if name is None:
            raise ActionFailure("no robot: give params.robot or put the transition in an agent subnet")
        if name not in self.robots:
            try:
                self.robots[name] = LeggedRobot(self.world, name)
            except NotLeggedError as exc:
                raise ActionFailure(str(exc)) from None
            except NetFormatError as exc:
                raise ActionFailure(exc.message) from None
        return self.robots[name]

    def cancel(self, ctx: ActionContext) -> bool:
        robot = getattr(self, "robot", None)
        if robot is not None:
            robot.hold()
        return True


class Walk(_LeggedAction):
    """Walk a legged robot to a point, or a distance along its heading, by its gait.

    Give ``x`` and ``y`` (world, m) or ``distance`` (m along the heading, negative
    backwards). Ends ``ok`` within ``tolerance`` of the point, the feet back in the
    standing posture; ``failed`` if the robot falls or stops making progress.
    """

    params: ClassVar[dict[str, Param]] = {
        "robot": Param(_STR_OR_NONE, None, "body or agent to walk (default: the agent)"),
        "x": Param(_FLOAT_OR_NONE, None, "goal x (m, world)"),
        "y": Param(_FLOAT_OR_NONE, None, "goal y (m, world)"),
        "distance": Param(_FLOAT_OR_NONE, None, "or: metres along the current heading (negative: backwards)"),
        "heading": Param(_FLOAT_OR_NONE, None, "final heading (rad, world), if any"),
        "stride": Param(_FLOAT_OR_NONE, None, "body travel per gait cycle (m; default: the gait's)"),
        "speed": Param(_FLOAT_OR_NONE, None, "walking speed at full stride (m/s; default: the gait's)"),
        "tolerance": Param(float, 0.03, "arrival distance (m)", low=0),
    }

    #: Heading error (rad) over which the robot turns on the spot before walking.
    TURN_FIRST = 0.35
    #: Heading correction per cycle while walking (rad).
    STEER = 0.15
    #: Cycles without 1 cm of progress before the walk fails.
    PATIENCE = 6

    @classmethod
    def check_params(cls, given: dict[str, Any], where: str) -> dict[str, Any]:
        checked = super().check_params(given, where)
        has_point = checked.get("x") is not None or checked.get("y") is not None
        if "distance" in cls.params and has_point == (checked.get("distance") is not None):
            raise NetFormatError("give either 'distance' or both 'x' and 'y'", element=where)
        if has_point and (checked.get("x") is None or checked.get("y") is None):
            raise NetFormatError("give both 'x' and 'y'", element=where)
        for name in ("stride", "speed"):
            if checked.get(name) is not None and checked[name] <= 0:
                raise NetFormatError(f"parameter {name!r} must be > 0", element=where)
        return checked

    # Lifecycle --------------------------------------------------------------------------
    def start(self, ctx: ActionContext) -> None:
        self.robot = self._robot(self.params["robot"] or ctx.agent)
        if not self.robot.upright():
            raise ActionFailure(f"robot {self.robot.name!r} is not upright (tilt"
                                f" {math.degrees(self.robot.tilt()):.0f}°): stand it up first")
        self.gait = self._gait()
        self.dt = float(self.world.dt)
        self.route = self._route(ctx)
        self.goal = list(self.route)
        self.corrections = 0
        self.origin = self.robot.pose()
        self._unwrapped = self.origin[2]
        self._last_yaw = self.origin[2]
        self.plan = None
        self.plan_time = 0.0
        self.state = self.gait.standing()
        self.near = self.robot.nominal()
        self.settled = False
        self.best = math.inf
        self.stalled = 0
        self.cycles = 0
        # bring the legs to the standing posture first if they are elsewhere
        current = self.robot.joints()
        far = max(abs(a - b) for leg in current for a, b in zip(current[leg], self.near[leg]))
        self.posture = _JointMove(self.robot, self.near, 1.0) if far > 0.02 else None

    def _gait(self):
        options: dict[str, Any] = {}
        design = self.robot.design
        base = gait_for(design)
        if self.params.get("stride") is not None:
            options["stride"] = self.params["stride"]
        if self.params.get("speed") is not None:
            stride = options.get("stride", base.stride)
            scale = (stride / self.params["speed"]) / base.cycle_time
            if scale < 0.5:
                raise ActionFailure(f"{design.name} walks at most {2 * stride / base.cycle_time:.3g} m/s"
                                    f" with a {stride} m stride, asked {self.params['speed']}")
            options["transfer_time"] = base.transfer_time * scale
            options["body_time"] = base.body_time * scale
        try:
            gait = gait_for(design, **options)
            gait.cycle(gait.standing(), (gait.stride, 0.0, 0.0))
        except GaitError as exc:
            raise ActionFailure(f"stride {options.get('stride')} m: {exc}") from None
        return gait

    def _route(self, ctx: ActionContext) -> list[tuple]:
        x, y, yaw = self.robot.pose()
        route: list[tuple] = []
        if self.params.get("distance") is not None:
            d = self.params["distance"]
            route.append(("goto", x + d * math.cos(yaw), y + d * math.sin(yaw), d < 0))
        else:
            route.append(("goto", self.params["x"], self.params["y"], False))
        if self.params.get("heading") is not None:
            route.append(("face", self.params["heading"]))
        return route

    @timed("control")
    def poll(self, ctx: ActionContext) -> Status:
        robot = self.robot
        self._track_yaw()
        if robot.tilt() > _FALLEN:
            raise ActionFailure(f"robot {robot.name!r} fell over (tilt {math.degrees(robot.tilt()):.0f}°)")
        if self.posture is not None:
            if self.posture.tick(self.dt):
                self.posture = None
            return Status.RUNNING
        if self.plan is None or self.plan_time >= self.plan.duration - 1e-9:
            if self.plan is not None and self.settled and not self._corrected():
                x, y, yaw = robot.pose()
                ctx.result = {"x": round(x, 4), "y": round(y, 4), "yaw": round(yaw, 4),
                              "travelled": round(math.hypot(x - self.origin[0], y - self.origin[1]), 4),
                              "cycles": self.cycles}
                return Status.OK
            motion = self._next_motion()
            self.plan, self.state, motion = self._cycle(motion)
            self.plan_time = 0.0
            self.cycles += 1
            self.settled = not any(motion)
        self.plan_time += self.dt
        sample = self.plan.sample(self.plan_time)
        try:
            self.near = self.plan.joints(sample, self.near)
        except GaitError as exc:  # pragma: no cover - plans are checked when made
            raise ActionFailure(str(exc)) from None
        robot.command(self.near)
        return Status.RUNNING

    #: Extra rounds (correction cycles and a new settle) when the settled robot is off.
    MAX_CORRECTIONS = 3

    def _corrected(self) -> bool:
        """After the settling cycle: if the robot ended outside the tolerances (the
        feet's last steps move it a little), put the final goal back on the route and
        return True (up to :attr:`MAX_CORRECTIONS` times)."""
        if self.corrections >= self.MAX_CORRECTIONS or self._within():
            return False
        self.corrections += 1
        gotos = [i for i, item in enumerate(self.goal) if item[0] == "goto"]
        self.route = list(self.goal[gotos[-1]:]) if gotos else list(self.goal)
        self.best, self.stalled = math.inf, 0
        return True

    def _within(self) -> bool:
        """Whether the settled robot meets its final goal: the last point within 1.5
        tolerances, and the final heading or turn within its tolerance."""
        x, y, _ = self.robot.pose()
        gotos = [item for item in self.goal if item[0] == "goto"]
        if gotos and math.hypot(gotos[-1][1] - x, gotos[-1][2] - y) > 1.5 * self.params["tolerance"]:
            return False
        last = self.goal[-1]
        if last[0] == "face" and abs(self._face_error(last[1], self._unwrapped)) > self._angle_tolerance():
            return False
        return not (last[0] == "turn" and abs(last[1] - self._unwrapped) > self.params["tolerance"])

    def _cycle(self, motion: tuple[float, float, float]):
        """Plan the next cycle; a motion the feet cannot follow from where they stand is
        halved, and at worst replaced by a step back to the standing posture."""
        error = None
        for scale in (1.0, 0.5, 0.25, 0.0):
            scaled = tuple(v * scale for v in motion)
            try:
                plan, state = self.gait.cycle(self.state, scaled)
                return plan, state, scaled
            except GaitError as exc:
                error = exc
        raise ActionFailure(f"cannot plan motion {motion}: {error}")

    # Steering ----------------------------------------------------------------------------
    def _track_yaw(self) -> None:
        yaw = self.robot.pose()[2]
        self._unwrapped += _wrap(yaw - self._last_yaw)
        self._last_yaw = yaw

    def _next_motion(self) -> tuple[float, float, float]:
        """The next cycle's motion toward the first unfinished route item (zero when the
        route is done)."""
        gait = self.gait
        while self.route:
            item = self.route[0]
            x, y, _ = self.robot.pose()
            yaw = self._unwrapped
            if item[0] == "face":
                error = self._face_error(item[1], yaw)
                if abs(error) <= self._angle_tolerance():
                    self.route.pop(0)
                    continue
                return (0.0, 0.0, _clamp(error, gait.max_turn))
            _, gx, gy, backwards = item
            distance = math.hypot(gx - x, gy - y)
            if distance <= self.params["tolerance"]:
                self.route.pop(0)
                self.best, self.stalled = math.inf, 0
                continue
            bearing = math.atan2(gy - y, gx - x) + (math.pi if backwards else 0.0)
            error = _wrap(bearing - yaw)
            if abs(error) > math.pi / 2 and distance <= 2 * self.params["tolerance"]:
                self.route.pop(0)  # just overshot: close enough, do not turn back
                continue
            if abs(error) > self.TURN_FIRST:
                return (0.0, 0.0, _clamp(error, gait.max_turn))
            if distance < self.best - 0.01:
                self.best, self.stalled = distance, 0
            else:
                self.stalled += 1
                if self.stalled > self.PATIENCE:
                    raise ActionFailure(f"robot {self.robot.name!r} is not advancing ({distance:.3f} m to go)")
            step = min(gait.stride, distance) * (-1.0 if backwards else 1.0)
            return (step, 0.0, _clamp(error, self.STEER))
        return (0.0, 0.0, 0.0)

    def _face_error(self, heading: float, yaw: float) -> float:
        return _wrap(heading - yaw)

    def _angle_tolerance(self) -> float:
        return 0.05


class Turn(Walk):
    """Turn a legged robot on the spot by ``angle`` rad (counter-clockwise positive),
    to within ``tolerance`` rad, by its gait."""

    params: ClassVar[dict[str, Param]] = {
        "robot": Param(_STR_OR_NONE, None, "body or agent to turn (default: the agent)"),
        "angle": Param(float, doc="turn (rad, counter-clockwise positive)"),
        "tolerance": Param(float, 0.05, "final heading tolerance (rad)", low=0),
        "stride": Param(_FLOAT_OR_NONE, None, "body travel per gait cycle (m; default: the gait's)"),
        "speed": Param(_FLOAT_OR_NONE, None, "walking speed at full stride (m/s; sets the cycle time)"),
    }

    def _route(self, ctx: ActionContext) -> list[tuple]:
        return [("turn", self.robot.pose()[2] + self.params["angle"])]

    def _next_motion(self) -> tuple[float, float, float]:
        if self.route:
            error = self.route[0][1] - self._unwrapped  # unwrapped: turns of more than π work
            if abs(error) > self.params["tolerance"]:
                return (0.0, 0.0, _clamp(error, self.gait.max_turn))
            self.route.pop(0)
        return (0.0, 0.0, 0.0)


def brace_route(fallen, gap: float, approach: float) -> tuple[list[tuple], tuple[float, float, float]]:
    """The moves that bring a helper behind a fallen robot's back, and the brace pose.

    Returns:
        ``([("goto", x, y, False), ("face", yaw), ...], (x, y, yaw))``: the approach
        point ``gap + approach`` behind the back, facing the robot, then the brace point
        ``gap`` from its centre, facing it.

    Raises:
        ActionFailure: the robot is not lying on a side.
    """
    position, rotation = fallen.frame()
    if lying_on(rotation) not in ("left", "right"):
        raise ActionFailure(f"robot {fallen.name!r} is not lying on a side ({lying_on(rotation)})")
    bx, by, facing = brace_point(position, rotation, gap)
    ax, ay, _ = brace_point(position, rotation, gap + approach)
    items = [("goto", ax, ay, False), ("face", facing), ("goto", bx, by, False), ("face", facing)]
    return items, (bx, by, facing)


class Brace(Walk):
    """The helper's part of the helping task (seed 003 §5.2): walk behind a fallen
    robot lying on its side, face its back and stop there, holding it.

    The helper first walks to a point ``approach`` metres further out on the same line,
    turns to face the fallen robot, then walks straight in to ``gap`` metres from the
    fallen robot's centre; its motors then hold that posture.
    """

    params: ClassVar[dict[str, Param]] = {
        "robot": Param(_STR_OR_NONE, None, "the helper's body or agent (default: the agent)"),
        "target": Param(str, doc="the fallen robot's body or agent"),
        "gap": Param(float, 0.17, "distance from the fallen robot's centre to the helper's (m)", low=0),
        "approach": Param(float, 0.15, "extra distance of the approach point (m)", low=0),
        "stride": Param(_FLOAT_OR_NONE, None, "body travel per gait cycle (m; default: the gait's)"),
        "speed": Param(_FLOAT_OR_NONE, None, "walking speed at full stride (m/s; sets the cycle time)"),
        "tolerance": Param(float, 0.03, "arrival distance (m)", low=0),
    }

    def _route(self, ctx: ActionContext) -> list[tuple]:
        items, self.brace = brace_route(self._robot(self.params["target"]), self.params["gap"],
                                        self.params["approach"])
        return items

    def _angle_tolerance(self) -> float:
        return 0.08

    def poll(self, ctx: ActionContext) -> Status:
        status = super().poll(ctx)
        if status is Status.OK:
            ctx.result = dict(ctx.result, brace=[round(v, 4) for v in self.brace])
        return status


class StandUp(_LeggedAction):
    """A fallen Robot4L rolls from its side onto its feet and stands, leaning on its
    ``helper`` when one is named (which must be braced behind its back, see
    ``gait.brace``). Ends ``ok`` upright in the standing posture; ``failed`` on its back
    or if the helper is not in place.
    """

    params: ClassVar[dict[str, Param]] = {
        "robot": Param(_STR_OR_NONE, None, "the fallen robot's body or agent (default: the agent)"),
        "helper": Param(_STR_OR_NONE, None, "the helper bracing it, if any"),
        "reach": Param(float, 0.12, "largest distance of the helper from its brace point (m)", low=0),
        "gap": Param(float, 0.17, "brace distance the helper was sent to (m)", low=0),
        "attempts": Param(int, 2, "righting attempts before failing", low=1),
    }

    def start(self, ctx: ActionContext) -> None:
        self.robot = self._robot(self.params["robot"] or ctx.agent)
        self.dt = float(self.world.dt)
        self.attempts = 0
        self.steps: list[tuple[float, dict]] = []
        self.move: _JointMove | None = None
        self.wait = 0.0
        self.side = "?"
        self._settled = False
        self._assess()

    def _assess(self) -> None:
        robot = self.robot
        position, rotation = robot.frame()
        side = lying_on(rotation)
        self.side = side
        if side == "upright":
            self.steps = [(1.0, robot.nominal())]
            return
        if side == "back" or robot.tilt() > BACK_TILT:
            raise ActionFailure(f"robot {robot.name!r} lies on its back: its legs cannot reach the ground")
        if self.params["helper"] is not None:
            helper = self._robot(self.params["helper"])
            bx, by, _ = brace_point(position, rotation, self.params["gap"])
            hx, hy, _ = helper.pose()
            off = math.hypot(hx - bx, hy - by)
            if off > self.params["reach"]:
                raise ActionFailure(f"helper {helper.name!r} is {off:.2f} m from the brace point behind"
                                    f" {robot.name!r}; brace it first (gait.brace)")
        self.attempts += 1
        self.steps = list(righting_motion(robot.design, side))

    @timed("control")
    def poll(self, ctx: ActionContext) -> Status:
        if self.wait > 0:
            self.wait -= self.dt
            return Status.RUNNING
        if self.move is not None:
            if not self.move.tick(self.dt):
                return Status.RUNNING
            self.move = None
        if self.steps:
            duration, target = self.steps.pop(0)
            self.move = _JointMove(self.robot, target, duration)
            self.move.tick(self.dt)
            return Status.RUNNING
        # the motion is over: settle, then judge
        if not self._settled:
            self._settled = True
            self.wait = 0.5
            return Status.RUNNING
        self._settled = False
        if self.robot.upright():
            ctx.result = {"tilt": round(math.degrees(self.robot.tilt()), 1), "from": self.side,
                          "attempts": self.attempts}
            return Status.OK
        if self.attempts >= self.params["attempts"]:
            raise ActionFailure(f"robot {self.robot.name!r} is still down after {self.attempts} attempts"
                                f" (tilt {math.degrees(self.robot.tilt()):.0f}°)")
        self._assess()
        return Status.RUNNING
