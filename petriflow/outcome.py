"""Closed sets of names shared from the model to the trace: outcomes and stop reasons.

An action ends with one :class:`Outcome`; the net's output arcs reserved for that
outcome produce its tokens (plain arcs produce on ``ok``). A run ends for one
:class:`StopReason`. Both are ``str`` enums, so a member equals its value
(``Outcome.FAILED == "failed"``) and is written to files as that value.

Examples:
    >>> Outcome("timeout") is Outcome.TIMEOUT, Outcome.TIMEOUT == "timeout"
    (True, True)
    >>> f"{Outcome.FAILED}", [o.value for o in ROUTED_OUTCOMES]
    ('failed', ['failed', 'timeout', 'cancelled'])
"""

from __future__ import annotations

import enum

__all__ = ["Name", "Outcome", "ROUTED_OUTCOMES", "StopReason"]


class Name(str, enum.Enum):
    """Base of petriflow's closed sets of names: a ``str`` enum whose members equal,
    print and format as their value (what files hold)."""

    def __str__(self) -> str:
        return self.value

    def __format__(self, spec: str) -> str:
        return format(self.value, spec)


class Outcome(Name):
    """How a started action ended; selects the output arcs that produce tokens."""

    OK = "ok"
    """The action did its job: the plain output arcs produce."""
    FAILED = "failed"
    """The action failed (it raised, or :meth:`poll` said so): the ``failed`` arcs produce."""
    TIMEOUT = "timeout"
    """The transition's ``timeout`` ran out: the ``timeout`` arcs produce (or else the ``failed`` ones)."""
    CANCELLED = "cancelled"
    """A cancellation region or a fault stopped the action: the ``cancelled`` arcs produce."""


#: The outcomes an output arc can be reserved for, in the order files list them.
ROUTED_OUTCOMES = (Outcome.FAILED, Outcome.TIMEOUT, Outcome.CANCELLED)


class StopReason(Name):
    """Why a run ended."""

    FINAL = "final"
    """The net's final marking was reached with nothing running or pending."""
    DEAD = "dead"
    """Nothing can fire, run or arrive any more, short of a final marking."""
    UNTIL = "until"
    """The simulated-time limit was reached."""
    FIRINGS = "firings"
    """The firing limit was reached."""
    FAILED = "failed"
    """An action failed (or timed out) and its transition routes no failure."""
    STALLED = "stalled"
    """The run stepped tick by tick with actions running and no firing starting or
    ending for the configuration's ``stall`` seconds (a robot that never arrives)."""
    FIRED = "fired"
    """:meth:`~petriflow.runtime.scheduler.Scheduler.fire_one`: the one firing ended."""
