"""``bidding.wait``: an agent with nothing to do waits for news."""

from __future__ import annotations

from petriflow.agents.bidding.agent import Interface, RobotAgent
from petriflow.agents.bidding.interface import watch_team
from petriflow.agents.bidding.needs import LIVE, OFFICE
from petriflow.agents.bidding.robot import watch_teammates
from petriflow.runtime.action import Action, ActionContext, Param, Status

__all__ = ["Wait"]


class Wait(Action):
    """An agent with nothing to do: wait until something is (at most ``period`` s)."""

    agent_state = (Interface, RobotAgent)
    resources = {**OFFICE, **LIVE}
    params = {"period": Param(float, 1.0, "longest wait (s)", low=1e-9)}

    def start(self, ctx: ActionContext) -> None:
        self.state = ctx.state
        self.until = ctx.now + self.params["period"]

    def poll(self, ctx: ActionContext) -> Status:
        state = self.state
        if isinstance(state, Interface):
            watch_team(ctx, state)
        else:
            watch_teammates(ctx, state)
        if ctx.world is None or ctx.now >= self.until - 1e-9 or (ctx.now > ctx.started and state.busy()):
            state.changed()
            return Status.OK
        return Status.RUNNING

