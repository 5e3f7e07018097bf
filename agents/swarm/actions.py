"""The swarm robot's actions and guards.

Each robot's subnet loops ``step`` (``swarm.explore``: read the radio's buffer into the
map and the history, go one cell towards the nearest cell nobody has mapped, sense it
with four rays, plan a frame for the neighbours heard now with Algorithm 1), ``share``
(``swarm.share``: the frame into the robot's radio place; guard ``swarm.has_frame``)
and ``sent`` (``swarm.sent``: the frame's airtime is over), until no unmapped cell is
within ``reach`` cells (guard ``swarm.explored``); then ``home`` (``swarm.home``: back to
its start through the cells it knows).

Motion is the kinematic world's (:meth:`petriflow.world.World.command`): a turn on the
spot, then a straight leg, each lasting a whole number of world steps at no more than
the robot's turn rate and speed, so the robot stops exactly on the cell's centre; the
action sleeps in between (``wake_at``) and is not polled while the world moves it.
Sensing is on demand: four rays (north, south, east, west, one cell long, robots
left out) asked of the world at arrival, cast with every other robot's at the next
world step in one batch.
"""

from __future__ import annotations

import math
from typing import Any

from petriflow.agents.swarm.agent import SIDES, Scout
from petriflow.agents.mobile.maze import MAZE, TILES
from petriflow.capabilities import KinematicDrive, Poses, RayTests
from petriflow.runtime.action import Action, ActionContext, ActionFailure, InstantAction, Param, Status

__all__ = ["GUARDS", "Wake", "Explore", "Share", "Sent", "Home"]


class Wake(InstantAction):
    """The robot starts: its state, its home cell (where it stands)."""

    agent_state = Scout
    uses = (Poses,)
    settings = MAZE  # the maze the metrics count the cells of, checked when the world loads
    params = {
        "air": Param(str, doc="the robot's radio place (its address is its radio's)", places=""),
        "cols": Param(int, 1, "cells per maze row", low=1),
        "rows": Param(int, 1, "rows of maze cells", low=1),
        "cell": Param(float, 1.0, "cell side (m)", low=1e-9),
        "origin": Param(list, [0.0, 0.0], "world (x, y) of the maze's south-west corner"),
        "horizon": Param(int, 0, "cells around the robot whose received data it keeps and passes on (0: all)",
                         low=0),
    }

    @classmethod
    def requirements(cls, params: dict[str, Any]) -> frozenset[str]:
        return frozenset({"world"})

    def run(self, ctx: ActionContext) -> None:
        p = self.params
        state = Scout(ctx.agent, ctx.medium(p["air"]).address(), cols=p["cols"], rows=p["rows"], cell=p["cell"],
                      origin=(float(p["origin"][0]), float(p["origin"][1])), horizon=p["horizon"])
        x, y, _ = ctx.world.pose(ctx.agent)
        state.here = state.home = state.cell_of(x, y)
        ctx.state = state


class _Mover(Action):
    """Drives the robot cell by cell through the kinematic world (see the module)."""

    needs_world = False
    agent_state = Scout
    uses = (Poses, KinematicDrive)
    params = {
        "speed": Param(float, 0.5, "cruise speed (m/s)", low=1e-9),
        "turn_rate": Param(float, 2.0, "turn rate on the spot (rad/s)", low=1e-9),
        "air": Param(str, doc="the robot's radio place", places=""),
    }

    @classmethod
    def requirements(cls, params: dict[str, Any]) -> frozenset[str]:
        return frozenset({"world"})

    def _leg(self, ctx: ActionContext, target: int) -> None:
        """Start towards the centre of the neighbouring cell ``target``: the turn first."""
        world, agent, state = ctx.world, ctx.agent, self.state
        x, y, yaw = world.pose(agent)
        tx, ty = state.centre(target)
        heading = math.atan2(ty - y, tx - x)
        self.target, self.distance = target, math.hypot(tx - x, ty - y)
        turn = math.remainder(heading - yaw, math.tau)
        dt = world.dt
        ticks = math.ceil(abs(turn) / (self.params["turn_rate"] * dt) - 1e-9)
        if ticks > 0:
            world.command(agent, w=turn / (ticks * dt))
            self.phase = "turn"
            self.wake_at = ctx.now + ticks * dt
        else:
            self._drive(ctx)

    def _drive(self, ctx: ActionContext) -> None:
        world = ctx.world
        dt = world.dt
        ticks = max(1, math.ceil(self.distance / (self.params["speed"] * dt) - 1e-9))
        world.command(ctx.agent, v=self.distance / (ticks * dt))
        self.phase = "drive"
        self.wake_at = ctx.now + ticks * dt

    def _moved(self, ctx: ActionContext) -> bool:
        """Advance the leg at a wake-up; True when the robot stands on the target."""
        if self.phase == "turn":
            self._drive(ctx)
            return False
        ctx.world.command(ctx.agent)  # stop
        self.state.here = self.target
        return True

    def cancel(self, ctx: ActionContext) -> bool:
        ctx.world.command(ctx.agent)
        return True


class Explore(_Mover):
    """One cell of exploration (see the module)."""

    settings = TILES  # a tiled world's copies of the maze (the metrics count their cells)
    uses = (Poses, KinematicDrive, RayTests)
    params = dict(_Mover.params, reach=Param(int, 4, "the robot maps the cells at most this many rows and columns"
                                             " from its start (through known cells at most 4 x as far)", low=1),
                  sensor_z=Param(float, 0.1, "height of the distance rays (m)"))

    def start(self, ctx: ActionContext) -> None:
        self.state = state = ctx.state
        if state is None:
            raise ActionFailure("swarm.explore: the robot has not woken")
        radio = ctx.medium(self.params["air"])
        for sender, address, packet in radio.take():
            state.receive(sender, address, packet)
        self.phase = "plan"
        self.wake_at = None
        if state.explored:
            self.phase = "done"
            return
        if state.here not in state.sides:  # the start cell: sense it where it stands
            self.target = state.here
            self._sense(ctx)
            return
        if not state.route or state.route[-1] in state.sides:
            reach = self.params["reach"]
            state.route = state.frontier_route(state.here, 4 * reach, state.home, reach)
        if not state.route:
            state.explored = True
            state.touch("explored")
            ctx.emit("swarm.explored", cells=len(state.sensed))
            self.phase = "done"
            return
        self._leg(ctx, state.route.pop(0))

    def poll(self, ctx: ActionContext) -> Status:
        if self.phase == "done":
            return Status.OK
        if self.wake_at is not None and ctx.now < self.wake_at - 1e-9:
            return Status.RUNNING
        state = self.state
        if self.phase == "sense":
            bits = 0
            for bit, (_, hit) in enumerate(zip(SIDES, self.rays.hits)):
                if hit[0] < 0:
                    bits |= 1 << bit
            if state.sense(self.target, bits):
                ctx.emit("swarm.sensed", cell=self.target)
            self._plan(ctx)
            return Status.OK
        if not self._moved(ctx):
            return Status.RUNNING
        if self.target in state.sides:  # mapped already (by this robot or a neighbour)
            self._plan(ctx)
            return Status.OK
        self._sense(ctx)
        return Status.RUNNING

    def _sense(self, ctx: ActionContext) -> None:
        """Ask for the four rays at the target's centre; read them at the next step."""
        state, world = self.state, ctx.world
        x, y = state.centre(self.target)
        z, reach = self.params["sensor_z"], state.cell
        ends = [(x + dc * reach, y + dr * reach, z) for _, dr, dc in SIDES]
        self.rays = world.request_rays([(x, y, z)] * 4, ends)
        self.phase = "sense"
        self.wake_at = ctx.now + world.dt

    def _plan(self, ctx: ActionContext) -> None:
        state = self.state
        for peer, address in ctx.medium(self.params["air"]).neighbours():
            state.plan_for(peer, address)


class Share(InstantAction):
    """The robot's next frame into its radio place (a broadcast: see :mod:`.radio`)."""

    agent_state = Scout
    params = {"air": Param(str, doc="the robot's radio place", places="")}

    def run(self, ctx: ActionContext) -> None:
        ctx.put(self.params["air"], ctx.state.frame())


class Sent(InstantAction):
    """The frame's airtime is over (its token is back from the medium)."""

    agent_state = Scout
    params = {"air": Param(str, doc="the robot's radio place", places="")}

    def run(self, ctx: ActionContext) -> None:
        pass


class Home(_Mover):
    """Back to the start cell through the cells the robot knows."""

    def start(self, ctx: ActionContext) -> None:
        self.state = state = ctx.state
        state.route = state.route_to(state.here, state.home)
        self.phase = "plan"
        if not state.route:
            self.phase = "done"
            return
        self._leg(ctx, state.route.pop(0))

    def poll(self, ctx: ActionContext) -> Status:
        if self.phase == "done":
            ctx.emit("swarm.home", cell=self.state.here)
            return Status.OK
        if self.wake_at is not None and ctx.now < self.wake_at - 1e-9:
            return Status.RUNNING
        if not self._moved(ctx):
            return Status.RUNNING
        if not self.state.route:
            ctx.emit("swarm.home", cell=self.state.here)
            return Status.OK
        self._leg(ctx, self.state.route.pop(0))
        return Status.RUNNING


def has_frame(state: Scout | None, params: dict[str, Any]) -> bool:
    return state is not None and any(state.outbox.values())


def going_on(state: Scout | None, params: dict[str, Any]) -> bool:
    return state is not None and not state.explored and not any(state.outbox.values())


def explored(state: Scout | None, params: dict[str, Any]) -> bool:
    return state is not None and state.explored and not any(state.outbox.values())


#: Guards over the robot's state and the keys each reads.
GUARDS = {
    "swarm.has_frame": (has_frame, ("outbox",)),
    "swarm.going_on": (going_on, ("outbox", "explored")),
    "swarm.explored": (explored, ("outbox", "explored")),
}
