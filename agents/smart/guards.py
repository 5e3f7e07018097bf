"""Guards of the SMART nets (registered by ``petriflow.agents.plugin``).

A guard is ``f(tokens, params) -> bool`` over the tokens a firing would
take; ``params`` are the guarded transition's. ``smart.help_needed`` lets the
decision maker's AND-split (``T5``) fire only on a scene in which the helper stands
and the robot to help is seen down; otherwise the camera is asked for a new image
(``T2``). It reads the transition's own ``helper`` and ``fallen`` colours.

Examples:
    >>> help_needed({"P6": [None]}, {"helper": "yellow", "fallen": "red"})
    False
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

__all__ = ["GUARDS", "help_needed"]


def _scenes(tokens: Mapping[str, list[Any]]):
    for items in tokens.values():
        for data in items:
            if data is not None and (hasattr(data, "segmented") or
                                     (isinstance(data, Mapping) and "segmented" in data)):
                yield data


def help_needed(tokens: Mapping[str, list[Any]], params: Mapping[str, Any]) -> bool:
    """A consumed scene shows the ``helper`` upright and the ``fallen`` robot down."""
    from petriflow.agents.smart.decision import assess

    helper, fallen = params.get("helper", "yellow"), params.get("fallen", "red")
    side = float(params.get("side", 0.26))
    for scene in _scenes(tokens):
        if (assess(scene, helper, side=side).state == "upright"
                and assess(scene, fallen, side=side).state == "down"):
            return True
    return False


#: Guard names as the plugin registers them.
GUARDS = {"smart.help_needed": help_needed}
