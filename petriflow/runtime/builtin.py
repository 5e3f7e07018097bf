"""Core actions and guards that need no robot: waiting, failing, passing data on.

They are registered in :data:`petriflow.runtime.registry.default_registry` as
``core.*`` and are what the project's own tests and examples use to exercise the
scheduler without a world.
"""

from __future__ import annotations

from typing import Any

from petriflow.runtime.action import ActionFailure, Param

__all__ = ["register"]


def noop(ctx) -> Any:
    """Finish at once, passing the first input token's data on."""
    return ctx.token()


def wait(ctx):
    """Wait a fixed simulated time, then pass the input token's data on."""
    yield ctx.params["seconds"]
    return ctx.token()


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
    registry.action("core.wait", {"seconds": Param(float, 1.0, "simulated seconds to wait")})(wait)
    registry.action(
        "core.fail",
        {
            "seconds": Param(float, 0.0, "simulated seconds before the outcome"),
            "probability": Param(float, 1.0, "chance of failing"),
            "reason": Param(str, "injected failure", "failure message"),
        },
    )(fail)
    registry.action("core.set", {"value": Param(object, None, "data for the output tokens")})(set_data)
    registry.predicate("core.has_data")(has_data)
