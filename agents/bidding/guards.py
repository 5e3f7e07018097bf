"""The guards that route the agents' work loops.

Each is ``f(state, params)`` over the agent's state, and says which of its keys (see
:class:`~petriflow.agents.bidding.correspondent.Correspondent`) it reads, so after a
firing only the guards whose keys changed are asked again: ``bidding.has_message`` reads
``outbox/{peer}``, ``bidding.has_cast`` ``cast``, the step guards ``step``,
``bidding.idle`` and ``bidding.finished`` ``step`` and ``pending`` (:data:`GUARDS`).
"""

from __future__ import annotations

from typing import Any, Callable

from petriflow.agents.bidding.agent import Interface, Operator, RobotAgent

__all__ = ["GUARDS", "has_message", "has_cast", "finished", "idle", "next_is"]


def next_is(step: str) -> Callable[[Any, dict[str, Any]], bool]:
    """The guard: the agent's next step is ``step``."""

    def guard(state: Any, params: dict[str, Any]) -> bool:
        return isinstance(state, (Interface, RobotAgent)) and state.next_step() == step
    guard.__name__ = f"next_is_{step}"
    guard.__doc__ = f"Guard: the agent's next step is {step!r}."
    return guard


def has_message(state: Any, params: dict[str, Any]) -> bool:
    """Guard: a message waits for ``params['peer']``."""
    return state is not None and state.has_for(params["peer"])


def has_cast(state: Any, params: dict[str, Any]) -> bool:
    """Guard: a broadcast to exactly the agents of ``params['boxes']`` can leave in one
    firing (every copy first in its receiver's queue)."""
    return state is not None and state.ready_cast(frozenset(params["boxes"])) is not None


def finished(state: Any, params: dict[str, Any]) -> bool:
    """Guard: the agent's part is over (operator: sent everything; HMIA: END sent;
    RA: END received) and nothing waits to be sent."""
    if state is None or state.pending():
        return False
    if isinstance(state, Operator):
        return True
    if isinstance(state, Interface):
        return state.end_sent is not None
    return state.ended


def idle(state: Any, params: dict[str, Any]) -> bool:
    """Guard: nothing to do now (the agent waits for news)."""
    return isinstance(state, (Interface, RobotAgent)) and not state.busy()


#: ``{name: (guard, the state keys it reads)}``: a message for the peer; the step the
#: state calls for; whether anything waits to be sent.
GUARDS = {
    "bidding.has_message": (has_message, ("outbox/{peer}",)),
    "bidding.has_cast": (has_cast, ("cast",)),
    "bidding.finished": (finished, ("step", "pending")),
    "bidding.idle": (idle, ("step", "pending")),
    **{f"bidding.next_{step}": (next_is(step), ("step",)) for step in
       ("team", "inform", "cfp", "map", "end", "ready", "bid", "decide", "explore")},
}
