"""``bidding.wait``: an agent with nothing to do sleeps until there is news.

The wait ends when the agent's state calls for a step or has something to send (its
``step`` or ``pending`` key changes and :meth:`busy` says so), or after ``period``
seconds. While it sleeps it is not polled: it wakes when one of those keys changes,
when which agents run changes (a teammate killed or joining, the run's
:data:`~petriflow.runtime.agents.RUNNING` key: the HMIA then re-offers the zones of a
robot that stopped, a robot counts the bidders left), when the HMIA's auction times
out (:func:`~petriflow.agents.bidding.interface.reoffer_due`), or at the end of its
period. It wakes at the tick an agent asking at every tick would have seen the news,
so its events and their times are those of a wait that polls at every tick.
"""

from __future__ import annotations

from petriflow.agents.bidding.agent import Interface, RobotAgent
from petriflow.agents.bidding.interface import reoffer_due, watch_team
from petriflow.agents.bidding.needs import LIVE, OFFICE
from petriflow.agents.bidding.robot import watch_teammates
from petriflow.runtime.action import Action, ActionContext, Param, Status
from petriflow.runtime.agents import RUNNING

__all__ = ["Wait"]

#: What wakes a waiting agent: its next step or its outbox changed, or who runs.
WAKES_ON = ("step", "pending", RUNNING)
#: How much before a due time a wait is woken: the due time is then checked as a poll at
#: every tick checks it (within this slack of the tick's time), never a tick late.
EARLY = 2e-9


class Wait(Action):
    """An agent with nothing to do: wait until something is (at most ``period`` s)."""

    needs_world = False
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
        due = self.until - 1e-9
        if isinstance(state, Interface) and (reoffer := reoffer_due(state)) is not None:
            due = min(due, reoffer)  # re-offered at the first tick after it
        if ctx.now == ctx.started and state.busy():  # busy already: it ends at the next tick
            due = ctx.now
        # asleep until the news or the due time (woken a hair early, it checks again and
        # sleeps to the next tick)
        self.wake_on = WAKES_ON
        self.wake_at = max(due - EARLY, ctx.now)
        return Status.RUNNING
