"""Actions over an agent state, for the agent-held state tests (tests/bridge/test_held_state*.py).

Plain petriflow code, no test imports: the bridged tests copy this file for `petriflow run`
and `petriflow agent` to import (``--actions``), adding ``register(default_registry)``.
"""

from petriflow.runtime.action import Action, InstantAction, Param, Status
from petriflow.runtime.agents import AgentState


class Counter(AgentState):
    """An agent's state: a count, and the keys it touches."""

    def __init__(self):
        super().__init__()
        self.n = 0

    def bump(self):
        self.n += 1
        self.touch("n")


class Make(InstantAction):
    agent_state = Counter

    def run(self, ctx):
        ctx.state = Counter()


class Bump(InstantAction):
    agent_state = Counter
    params = {"limit": Param(int, 3)}

    def run(self, ctx):
        ctx.state.bump()
        ctx.emit("demo.bumped", n=ctx.state.n)
        ctx.put("work", {"n": ctx.state.n})  # an output place's own data


class Slow(Action):
    """Counts one when it starts (a guard may then fire mid-action), ends after ``seconds``
    (with ``put``: the count into the agent's ``AGENT_work`` place)."""

    agent_state = Counter
    needs_world = False
    params = {"seconds": Param(float, 0.3), "limit": Param(int, 0), "put": Param(bool, False)}

    def start(self, ctx):
        ctx.state.bump()
        if self.params["put"]:
            ctx.emit("demo.step", n=ctx.state.n)
        self.until = ctx.now + self.params["seconds"]
        self.wake_at = self.until

    def poll(self, ctx):
        if ctx.now < self.until - 1e-9:
            return Status.RUNNING
        if self.params["put"]:
            ctx.put(f"{ctx.agent}_work", {"n": ctx.state.n})
        return Status.OK


def register(registry):
    """The state type, actions and guards, under ``demo.*``."""
    registry.register_state("demo.counter", Counter)
    registry.register("demo.make", Make)
    registry.register("demo.bump", Bump)
    registry.register("demo.slow", Slow)
    registry.predicate("demo.below", reads=("n",))(lambda state, params: state is not None and state.n < params["limit"])
    registry.predicate("demo.reached", reads=("n",))(lambda state, params: state is not None
                                                     and state.n >= params["limit"])
    registry.predicate("demo.none", reads=("n",))(lambda state, params: state is None)
    return registry
