"""The bus package's errors, under petriflow's :class:`~petriflow.errors.PetriflowError`.

Examples:
    >>> issubclass(FrameError, ValueError), issubclass(AddressingError, BusError)
    (True, True)
"""

from __future__ import annotations

from petriflow.errors import PetriflowError

__all__ = ["AddressingError", "BusError", "FrameError"]


class BusError(PetriflowError):
    """Something about a simulated bus or its modules."""


class FrameError(BusError, ValueError):
    """A frame that its bus cannot carry (too long, a bad identifier, a bad setting)."""


class AddressingError(BusError):
    """The chain cannot address itself (no head, two heads, too long, a module not reached)."""
