"""Core actions and guards that need no robot: waiting, failing, passing data on.

They are registered in :data:`petriflow.runtime.registry.default_registry` as
``core.*`` and are what the project's own tests and examples use to exercise the
scheduler without a world.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

from petriflow.errors import NetFormatError
from petriflow.runtime.action import Action, ActionContext, ActionFailure, Param, Status

__all__ = ["register", "Wait"]


def noop(ctx) -> Any:
    """Finish at once, passing the first input token's data on."""
    return ctx.token()


class Wait(Action):
    """Wait a fixed simulated time, then pass the input token's data on.

    The commonest action of all (every timed step of a net that has no robot), so it
    is a class rather than a generator, and a pure delay (:meth:`Action.delay`): the
    runtime ends its firings when the time comes without polling it.
    """

    params: ClassVar[dict[str, Param]] = {"seconds": Param(float, 1.0, "simulated seconds to wait", low=0)}
    needs_world = False

    @classmethod
    def check_params(cls, given: dict[str, Any], where: str) -> dict[str, Any]:
        checked = super().check_params(given, where)
        if not (math.isfinite(checked["seconds"]) and checked["seconds"] >= 0):
            error = NetFormatError(f"parameter 'seconds' must be a finite number >= 0, got {checked['seconds']!r}",
                                   element=where)
            error.param = "seconds"
            raise error
        return checked

    def delay(self) -> float | None:
        mine = type(self).start is Wait.start and type(self).poll is Wait.poll  # a subclass may do more
        return self.params["seconds"] if mine else None

    def start(self, ctx: ActionContext) -> None:
        self.wake_at = ctx.now + self.params["seconds"]

    def poll(self, ctx: ActionContext) -> Status:
        if ctx.now < self.wake_at - 1e-12:
            return Status.RUNNING
        ctx.result = ctx.token()
        return Status.OK


def fail(ctx):
    """Wait, then fail with probability ``probability`` (seeded per firing)."""
    yield ctx.params["seconds"]
    if ctx.rng.random() < ctx.params["probability"]:
        raise ActionFailure(ctx.params["reason"])
    return ctx.token()


def set_data(ctx) -> Any:
    """Finish at once with the data given in ``value``."""
    return ctx.params["value"]


def has_data(tokens, params) -> bool:
    """Guard: every consumed token carries data (is not a plain black token)."""
    return all(data is not None for items in tokens.values() for data in items)


def register(registry) -> None:
    """Register the ``core.*`` actions and guards in ``registry``."""
    registry.action("core.noop")(noop)
    registry.register("core.wait", Wait)
    registry.action(
        "core.fail",
        {
            "seconds": Param(float, 0.0, "simulated seconds before the outcome", low=0),
            "probability": Param(float, 1.0, "chance of failing", low=0, high=1),
            "reason": Param(str, "injected failure", "failure message"),
        },
    )(fail)
    registry.action("core.set", {"value": Param(object, None, "data for the output tokens")})(set_data)
    registry.predicate("core.has_data")(has_data)
