"""Guards that route a ``planning.track`` result: on track, reinsert, or re-plan.

A guard is a predicate ``f(tokens, params)`` over the tokens a firing would
consume (``{place: [data, ...]}``); these look at the ``decision`` that
``planning.track`` put in its output token, so three transitions sharing that place
split the flow three ways (an XOR-split decided by data).

Examples:
    >>> tokens = {"checked": [{"decision": "reinsert", "point": [0.5, 0.0]}]}
    >>> on_track(tokens, {}), reinsert(tokens, {}), replan(tokens, {})
    (False, True, False)
"""

from __future__ import annotations

from typing import Any, Mapping

__all__ = ["on_track", "reinsert", "replan", "GUARDS"]

#: ``{place: [token data, ...]}`` of the tokens a firing would consume.
Tokens = Mapping[str, list[Any]]


def _decided(tokens: Tokens, decision: str) -> bool:
    for items in tokens.values():
        for data in items:
            if isinstance(data, Mapping) and data.get("decision") == decision:
                return True
    return False


def on_track(tokens: Tokens, params: Mapping[str, Any]) -> bool:
    """A consumed token says the robot is on its path."""
    return _decided(tokens, "on_track")


def reinsert(tokens: Tokens, params: Mapping[str, Any]) -> bool:
    """A consumed token says the robot must return to its path (reinsertion)."""
    return _decided(tokens, "reinsert")


def replan(tokens: Tokens, params: Mapping[str, Any]) -> bool:
    """A consumed token says the robot is too far from its path: stop and plan again."""
    return _decided(tokens, "replan")


#: Guard names as registered by the plugin.
GUARDS = {"planning.on_track": on_track, "planning.reinsert": reinsert, "planning.replan": replan}
