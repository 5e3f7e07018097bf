"""Frame lengths on the wire, in bits, for the three buses of seed 002.

The paper (Montiel Ariza et al. 2022) runs the EMERGE modules' CPG messages over
RS-485 at 115 200 baud, CAN at 512 kbit/s and ZigBee radios at 57 600 baud (the
XBee's serial side). How long a message keeps a bus busy decides how often two of
them meet, so each bus gets its own frame arithmetic here:

* **UART / RS-485** (:func:`uart_frame_bits`): every byte travels as a character
  with a start bit, the data bits, an optional parity bit and the stop bits
  (8N1: 10 bits a byte). We assume bytes go back to back (no idle gap between
  characters); a gap would only lengthen a frame.
* **CAN 2.0A data frame** (:func:`can_frame_bits`): SOF, 11-bit identifier, RTR,
  IDE, r0, 4-bit DLC, 0–8 data bytes, 15-bit CRC, CRC delimiter, ACK slot and
  delimiter, 7-bit EOF, plus the 3-bit intermission before the next frame may
  start (``interframe=True``). From SOF to the end of the CRC the transmitter
  inserts a complementary *stuff bit* after five equal bits; we stuff the actual
  bit pattern (identifier, data and its real CRC-15, :func:`can_crc15`), so a frame
  is 44 + 8n + stuff bits, between the unstuffed length and the worst case
  :func:`can_worst_case_bits` (135 bits for 8 bytes with the intermission).
* **IEEE 802.15.4 (ZigBee)** (:func:`ieee802154_frame_bits`): the radio sends
  O-QPSK at 250 kbit/s in the 2.4 GHz band; a PPDU is a 4-byte preamble, the SFD
  and the PHY header byte, then the MAC frame: a 9-byte header (frame control,
  sequence number, PAN id, short destination and source addresses with PAN-id
  compression), the network-layer bytes, the payload and a 2-byte FCS. The MAC
  frame may not exceed 127 bytes. The ZigBee network and APS headers (8 + 8
  bytes) are the ``network_bytes`` parameter of the ZigBee bus; plain 802.15.4
  firmware has none. No stuffing: the radio spreads every 4 bits into 32 chips at
  a fixed rate.

Examples:
    >>> uart_frame_bits(10)                     # 10 bytes, 8N1
    100
    >>> can_frame_bits(0x000, b"", interframe=False)  # 34 zero bits to stuff: 6 stuff bits
    50
    >>> can_worst_case_bits(8)
    135
    >>> ieee802154_frame_bits(9)                # 9-byte payload: 26 bytes on the air
    208
"""

from __future__ import annotations

from collections.abc import Sequence

from petriflow.agents.bus.errors import FrameError

__all__ = [
    "CAN_FIXED_BITS",
    "CAN_INTERFRAME_BITS",
    "IEEE802154_ACK_BITS",
    "IEEE802154_MAC_HEADER_BYTES",
    "IEEE802154_MAX_FRAME_BYTES",
    "IEEE802154_PHY_BYTES",
    "FrameError",
    "can_bits",
    "can_crc15",
    "can_frame_bits",
    "can_worst_case_bits",
    "ieee802154_frame_bits",
    "stuff",
    "uart_frame_bits",
]

#: Bits of a CAN 2.0A data frame besides the data bytes, before stuffing and without
#: the intermission: SOF 1, identifier 11, RTR 1, IDE 1, r0 1, DLC 4, CRC 15, CRC
#: delimiter 1, ACK slot 1, ACK delimiter 1, EOF 7.
CAN_FIXED_BITS = 44
#: The intermission (3 recessive bits) that must pass before the next frame's SOF.
CAN_INTERFRAME_BITS = 3
#: Bytes of an 802.15.4 PPDU before the MAC frame: preamble 4, SFD 1, PHY header 1.
IEEE802154_PHY_BYTES = 6
#: MAC header of a data frame with short addresses and PAN-id compression.
IEEE802154_MAC_HEADER_BYTES = 9
#: aMaxPHYPacketSize: the longest MAC frame (header, payload and FCS) in bytes.
IEEE802154_MAX_FRAME_BYTES = 127
#: An acknowledgement PPDU: 6 PHY bytes and a 5-byte MAC frame.
IEEE802154_ACK_BITS = 8 * (IEEE802154_PHY_BYTES + 5)

_CRC15_POLY = 0x4599  # x^15 + x^14 + x^10 + x^8 + x^7 + x^4 + x^3 + 1


def uart_frame_bits(n_bytes: int, data_bits: int = 8, parity: bool = False, stop_bits: int = 1) -> int:
    """Bits on the line for ``n_bytes`` characters sent back to back.

    Args:
        n_bytes: characters in the frame.
        data_bits: 5 to 9 data bits per character.
        parity: one parity bit per character.
        stop_bits: 1 or 2.

    Raises:
        FrameError: a setting a UART does not have.

    Examples:
        >>> uart_frame_bits(1), uart_frame_bits(1, parity=True, stop_bits=2)
        (10, 12)
    """
    if n_bytes < 0 or not 5 <= data_bits <= 9 or stop_bits not in (1, 2):
        raise FrameError(f"no UART frame of {n_bytes} bytes with {data_bits} data bits and {stop_bits} stop bits")
    return n_bytes * (1 + data_bits + int(parity) + stop_bits)


def can_crc15(bits: Sequence[int]) -> int:
    """CAN's CRC-15 of a bit sequence (initial value 0, no reflection, no final xor).

    Examples:
        >>> message = [int(b) for byte in b"123456789" for b in format(byte, "08b")]
        >>> hex(can_crc15(message))  # the catalogue's check value for CRC-15/CAN
        '0x59e'
    """
    crc = 0
    for bit in bits:
        feedback = ((crc >> 14) & 1) ^ (bit & 1)
        crc = (crc << 1) & 0x7FFF
        if feedback:
            crc ^= _CRC15_POLY
    return crc


def _to_bits(value: int, width: int) -> list[int]:
    return [(value >> shift) & 1 for shift in range(width - 1, -1, -1)]


def can_bits(identifier: int, data: bytes) -> list[int]:
    """The unstuffed bits of a CAN 2.0A data frame from SOF to the end of the CRC.

    Raises:
        FrameError: the identifier is not 11 bits or there are more than 8 data bytes.

    Examples:
        >>> len(can_bits(0x123, b"\\x01\\x02"))  # 19 + 16 + 15
        50
    """
    if not 0 <= identifier < 1 << 11:
        raise FrameError(f"a CAN 2.0A identifier has 11 bits, got {identifier!r}")
    if len(data) > 8:
        raise FrameError(f"a CAN data frame carries at most 8 bytes, got {len(data)}")
    bits = [0, *_to_bits(identifier, 11), 0, 0, 0, *_to_bits(len(data), 4)]
    for byte in data:
        bits.extend(_to_bits(byte, 8))
    return bits + _to_bits(can_crc15(bits), 15)


def stuff(bits: Sequence[int], run: int = 5) -> list[int]:
    """Insert a complementary bit after every ``run`` equal bits (stuff bits count
    towards the next run, as on a CAN bus).

    Examples:
        >>> stuff([0, 0, 0, 0, 0, 0])
        [0, 0, 0, 0, 0, 1, 0]
        >>> stuff([1, 1, 1, 1, 1, 0, 0, 0, 0])  # the stuff bit 0 starts a run of five 0s
        [1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 1]
    """
    out: list[int] = []
    last, length = -1, 0
    for bit in bits:
        out.append(bit)
        length = length + 1 if bit == last else 1
        last = bit
        if length == run:
            last, length = 1 - bit, 1
            out.append(last)
    return out


def can_frame_bits(identifier: int, data: bytes, *, interframe: bool = True) -> int:
    """Length in bits of the CAN 2.0A data frame carrying ``data`` under ``identifier``,
    stuffed as the transmitter stuffs it, with the 3-bit intermission if ``interframe``.

    Examples:
        >>> can_frame_bits(0x7FF, bytes(8)) >= CAN_FIXED_BITS + 64 + CAN_INTERFRAME_BITS
        True
    """
    unstuffed = can_bits(identifier, data)
    tail = CAN_FIXED_BITS - 34  # CRC delimiter, ACK slot and delimiter, EOF: never stuffed
    return len(stuff(unstuffed)) + tail + (CAN_INTERFRAME_BITS if interframe else 0)


def can_worst_case_bits(n_bytes: int, *, interframe: bool = True) -> int:
    """The longest a CAN 2.0A frame with ``n_bytes`` data bytes can be: the 34 + 8n bits
    from SOF to the CRC can need at most ⌊(34 + 8n − 1) / 4⌋ stuff bits.

    Examples:
        >>> can_worst_case_bits(0, interframe=False), can_worst_case_bits(8, interframe=False)
        (52, 132)
    """
    if not 0 <= n_bytes <= 8:
        raise FrameError(f"a CAN data frame carries 0 to 8 bytes, got {n_bytes}")
    stuffed_region = 34 + 8 * n_bytes
    return CAN_FIXED_BITS + 8 * n_bytes + (stuffed_region - 1) // 4 + (CAN_INTERFRAME_BITS if interframe else 0)


def ieee802154_frame_bits(payload_bytes: int, network_bytes: int = 0,
                          mac_header_bytes: int = IEEE802154_MAC_HEADER_BYTES) -> int:
    """Bits on the air of an 802.15.4 data frame (PHY bytes, MAC header, network-layer
    bytes, payload, FCS).

    Raises:
        FrameError: the MAC frame would exceed 127 bytes.

    Examples:
        >>> ieee802154_frame_bits(9, network_bytes=16)  # with ZigBee's NWK and APS headers
        336
        >>> ieee802154_frame_bits(200)
        Traceback (most recent call last):
        ...
        petriflow.agents.bus.errors.FrameError: an 802.15.4 MAC frame carries at most 127 bytes, this one needs 211
    """
    mac_frame = mac_header_bytes + network_bytes + payload_bytes + 2
    if payload_bytes < 0 or mac_frame > IEEE802154_MAX_FRAME_BYTES:
        raise FrameError(f"an 802.15.4 MAC frame carries at most {IEEE802154_MAX_FRAME_BYTES} bytes,"
                         f" this one needs {mac_frame}")
    return 8 * (IEEE802154_PHY_BYTES + mac_frame)
