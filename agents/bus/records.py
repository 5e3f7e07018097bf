"""What a bus carries and what it tells: frames, transmissions, deliveries and losses.

A module asks its bus to carry a :class:`Frame`; the bus puts it on the medium as a
:class:`Transmission` (garbled when it met another), and tells its listeners each
frame's fate when it happens: a :class:`Delivery` when a module read a frame addressed
to it, a :class:`Lost` (with its :class:`Loss` reason) when a frame did not reach a
module. These values are all the media (:mod:`~petriflow.agents.bus.rs485`,
:mod:`~petriflow.agents.bus.can`, :mod:`~petriflow.agents.bus.zigbee`,
:mod:`~petriflow.agents.bus.network`) and their users share.

A :class:`Frame` is not a message between agents: it is the medium's unit (bytes and
addresses on one bus, what a MAC layer queues, arbitrates and garbles). The message
between agents is the runtime's :class:`~petriflow.runtime.channel_models.Message`
through a bus channel place; the bus's carrier (:mod:`~petriflow.agents.bus.channel`)
turns each one into a frame of its payload's bytes.

Examples:
    >>> frame = Frame(sender=0, receivers=(1, 2), data=b"phase")
    >>> Lost(frame, module=2, reason=Loss.OVERWRITTEN, time=0.5).reason.value
    'overwritten'
    >>> Loss("btt_full") is Loss.BTT_FULL, f"{Loss.RADIO}"
    (True, 'radio')
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from petriflow.outcome import Name

__all__ = ["Delivery", "Frame", "Loss", "Lost", "Transmission"]


class Loss(Name):
    """Why a frame did not reach a module."""

    COLLISION = "collision"
    """It overlapped another frame on the medium; both were garbled."""
    OVERWRITTEN = "overwritten"
    """A newer frame took its place in the receive buffer before the module read it."""
    QUEUE_FULL = "queue_full"
    """The sender's transmit queue was full when its module asked to send it."""
    ACCESS_FAILURE = "access_failure"
    """CSMA/CA found the channel busy at every clear channel assessment and gave up."""
    RADIO = "radio"
    """Bit errors on the radio link to this module."""
    BTT_FULL = "btt_full"
    """A ZigBee node's broadcast transaction table was full: it dropped a new broadcast."""
    PARENT_BUFFER = "parent_buffer"
    """A ZigBee parent replaced the one broadcast it buffers for its end devices before
    this end device polled for it."""


@dataclass(frozen=True)
class Frame:
    """A frame a module asks its bus to carry.

    Attributes:
        sender: the sending module.
        receivers: the modules it is addressed to (its bytes say so; the medium
            carries it to everyone).
        data: the payload bytes (a CAN frame's data field: at most 8).
        identifier: the CAN identifier (arbitration priority: lower wins).
        tag: anything that identifies the frame to its user (never sent).
    """

    sender: int
    receivers: tuple[int, ...]
    data: bytes
    identifier: int = 0
    tag: Any = None


@dataclass(eq=False)
class Transmission:
    """A frame on the medium from ``start`` to ``end`` (``garbled``: it met another)."""

    frame: Frame
    start: float
    end: float
    bits: int
    garbled: bool = False


@dataclass(frozen=True)
class Delivery:
    """A module read a frame addressed to it.

    Attributes:
        frame: the frame.
        module: the module that read it.
        arrived: when it reached the module's receive buffer.
        read: when the module read it (``arrived`` for a module that reads on arrival).
    """

    frame: Frame
    module: int
    arrived: float
    read: float


@dataclass(frozen=True)
class Lost:
    """A frame lost for ``module`` (``None``: for every module) at ``time``, for ``reason``."""

    frame: Frame
    module: int | None
    reason: Loss
    time: float
