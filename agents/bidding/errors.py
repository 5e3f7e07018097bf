"""The error the bidding package raises for a request that makes no sense.

An auction in which no robot can bid, a robot index outside the team, a cost weight
that is negative, a scan whose ranges do not match its beams: each is a
:class:`BiddingError` naming what was wrong.

Examples:
    >>> issubclass(BiddingError, ValueError)
    True
"""

from __future__ import annotations

from petriflow.errors import PetriflowError

__all__ = ["BiddingError"]


class BiddingError(PetriflowError, ValueError):
    """A bad argument to the bidding core: shapes that do not match, weights out of
    range, an unknown robot or zone, a team with nobody alive."""
