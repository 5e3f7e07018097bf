"""The CPG message of seed 002 and its bytes.

Algorithm 2's ``Build message`` packs a *String*: ``String[0]`` the receiver's address,
``String[1]`` the sender's, then the CPG parameters (phase φ, offset x, amplitude r).
Algorithm 1 sends one message "to the neighbours (myaddress + 1, myaddress − 1)", so a
:class:`Packet` has one or two receivers. The paper gives no byte layout; ours is the
smallest that fits one CAN frame:

====  ==========================================================================
byte  content
====  ==========================================================================
0     first receiver's address
1     second receiver's address, or 0xFF for none
2     sender's address (on CAN it travels in the identifier instead, see below)
3–4   phase φ as an unsigned 16-bit fraction of a turn (2π / 65 536 rad a step)
5–6   offset x in milliradians, signed 16 bits
7–8   amplitude r in milliradians, signed 16 bits
====  ==========================================================================

A :class:`Packet` is a payload: :func:`encode` gives the bytes a
:class:`~petriflow.runtime.channel_models.Message` carries through a bus channel place
(its data's ``payload``), and the bus turns those into a
:class:`~petriflow.agents.bus.records.Frame`.

Big-endian throughout. The motor angle θ is not sent: no receiver uses it (the
reception routine reads only φ, x and r). On CAN the sender's address sets the 11-bit
identifier (:func:`can_identifier`: ``0x100 + address``, so the lower address wins
arbitration) and the 8 remaining bytes are the data field. Addresses are 0–254
(the paper's auto-addressing supports 254 modules); 0xFF means "nobody".

Examples:
    >>> packet = Packet(receivers=(1,), sender=0, phase=3.0, offset=0.0, amplitude=0.5)
    >>> data = encode(packet)
    >>> len(data), data[:3].hex()
    (9, '01ff00')
    >>> back = decode(data)
    >>> back.receivers, back.sender, round(back.phase, 3), back.amplitude
    ((1,), 0, 3.0, 0.5)
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass

from petriflow.agents.bus.frames import FrameError

__all__ = ["NOBODY", "PACKET_BYTES", "Packet", "can_identifier", "decode", "encode"]

#: The address byte that stands for "no receiver".
NOBODY = 0xFF
#: Length of an encoded packet with the sender byte.
PACKET_BYTES = 9
_LAYOUT = struct.Struct(">BBBHhh")
_TURN = 65536 / (2 * math.pi)


@dataclass(frozen=True)
class Packet:
    """One CPG message: who it is for, who sent it, and the sender's oscillator.

    Attributes:
        receivers: one or two addresses (0–254).
        sender: the sender's address.
        phase: the sender's phase φ in radians (sent modulo 2π).
        offset: the sender's offset x in radians.
        amplitude: the sender's amplitude r in radians.
        number: the sender's count of this message (0 for the first); not encoded, it
            lets a simulation follow each message.
    """

    receivers: tuple[int, ...]
    sender: int
    phase: float
    offset: float = 0.0
    amplitude: float = 0.0
    number: int = 0

    def is_for(self, address: int) -> bool:
        """Whether ``address`` is one of the receivers."""
        return address in self.receivers


def _address(value: int) -> int:
    if not 0 <= value < NOBODY:
        raise FrameError(f"an address is 0 to 254, got {value!r}")
    return value


def _milliradians(value: float) -> int:
    scaled = round(value * 1000.0)
    if not -32768 <= scaled <= 32767:
        raise FrameError(f"{value!r} rad does not fit the packet's 16-bit milliradians")
    return scaled


def encode(packet: Packet, *, with_sender: bool = True) -> bytes:
    """The packet's bytes (8 without the sender byte, as in a CAN data field).

    Raises:
        FrameError: no receiver, more than two, an address out of range, or an offset or
            amplitude beyond ±32.767 rad.
    """
    receivers = packet.receivers
    if not 1 <= len(receivers) <= 2:
        raise FrameError(f"a packet has one or two receivers, got {receivers!r}")
    second = _address(receivers[1]) if len(receivers) == 2 else NOBODY
    phase = round((packet.phase % (2 * math.pi)) * _TURN) % 65536
    data = _LAYOUT.pack(_address(receivers[0]), second, _address(packet.sender), phase,
                        _milliradians(packet.offset), _milliradians(packet.amplitude))
    return data if with_sender else data[:2] + data[3:]


def decode(data: bytes, sender: int | None = None) -> Packet:
    """Read a packet from its bytes; pass ``sender`` when the bytes lack it (CAN).

    Raises:
        FrameError: the bytes have the wrong length.
    """
    if sender is not None:
        if len(data) != PACKET_BYTES - 1:
            raise FrameError(f"a packet without its sender has {PACKET_BYTES - 1} bytes, got {len(data)}")
        data = data[:2] + bytes([sender]) + data[2:]
    if len(data) != PACKET_BYTES:
        raise FrameError(f"a packet has {PACKET_BYTES} bytes, got {len(data)}")
    first, second, source, phase, offset, amplitude = _LAYOUT.unpack(data)
    receivers = (first,) if second == NOBODY else (first, second)
    return Packet(receivers, source, phase / _TURN, offset / 1000.0, amplitude / 1000.0)


def can_identifier(sender: int) -> int:
    """The 11-bit CAN identifier of a module's messages: ``0x100 + address``.

    Examples:
        >>> hex(can_identifier(0)), can_identifier(0) < can_identifier(2)
        ('0x100', True)
    """
    return 0x100 + _address(sender)
