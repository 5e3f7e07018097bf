"""Frame lengths: UART characters, CAN stuffing on the real bit pattern, 802.15.4 overhead."""

from __future__ import annotations

import random

import pytest
from petriflow.agents.bus.frames import (
    CAN_FIXED_BITS,
    IEEE802154_ACK_BITS,
    FrameError,
    can_bits,
    can_crc15,
    can_frame_bits,
    can_worst_case_bits,
    ieee802154_frame_bits,
    stuff,
    uart_frame_bits,
)


def test_uart_counts_start_parity_and_stop_bits():
    """8N1 is 10 bits a byte; 8E2 is 12."""
    assert uart_frame_bits(11) == 110
    assert uart_frame_bits(11, parity=True, stop_bits=2) == 132
    with pytest.raises(FrameError):
        uart_frame_bits(1, stop_bits=3)


def test_crc15_matches_the_catalogue_check_value():
    """CRC-15/CAN of the ASCII bits of '123456789' is 0x059E."""
    bits = [int(b) for byte in b"123456789" for b in format(byte, "08b")]
    assert can_crc15(bits) == 0x059E


def test_crc15_of_message_and_crc_is_zero():
    """Appending the CRC makes the remainder zero (the receiver's check)."""
    bits = can_bits(0x2A5, b"\x12\x34\x56")
    assert can_crc15(bits) == 0


def test_stuffing_inserts_a_complement_after_five_equal_bits():
    """A stuff bit after each run of five, and the stuff bit starts the next run."""
    assert stuff([1] * 5) == [1, 1, 1, 1, 1, 0]
    assert stuff([0] * 10) == [0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1]
    assert stuff([0, 1] * 10) == [0, 1] * 10
    assert stuff([0, 0, 0, 0, 1, 1, 1, 1]) == [0, 0, 0, 0, 1, 1, 1, 1]


def test_worst_case_pattern_needs_a_stuff_bit_every_four_bits():
    """00000 1111 0000 1111 ... : after the first five, every four bits need stuffing."""
    pattern = [0] * 5 + ([1] * 4 + [0] * 4) * 4
    assert len(stuff(pattern)) - len(pattern) == 1 + 8


def test_can_frame_of_zeros_has_six_stuff_bits():
    """Identifier 0 and no data: 34 zero bits (the CRC of zeros is zero) need 6 stuff bits."""
    assert can_bits(0, b"") == [0] * 34
    assert can_frame_bits(0, b"", interframe=False) == 44 + 6
    assert can_frame_bits(0, b"") == 44 + 6 + 3


def test_can_worst_case_lengths_are_the_known_ones():
    """The well-known bounds: 8 data bytes need at most 132 bits, 135 with the intermission."""
    assert can_worst_case_bits(8) == 135
    assert can_worst_case_bits(8, interframe=False) == 132
    assert can_worst_case_bits(0) == 55


def test_can_frame_lengths_lie_between_unstuffed_and_worst_case():
    """Random frames: at least 44 + 8n bits, at most the worst case."""
    rng = random.Random(7)
    for _ in range(300):
        n = rng.randrange(9)
        data = bytes(rng.randrange(256) for _ in range(n))
        length = can_frame_bits(rng.randrange(2048), data, interframe=False)
        assert CAN_FIXED_BITS + 8 * n <= length <= can_worst_case_bits(n, interframe=False)


def test_can_stuffing_depends_on_the_data():
    """Same length, different bits, different frame lengths."""
    assert can_frame_bits(0x100, bytes(8)) != can_frame_bits(0x100, bytes([0x55] * 8))


def test_can_rejects_long_data_and_wide_identifiers():
    """A standard frame carries 8 bytes and 11 identifier bits."""
    with pytest.raises(FrameError):
        can_bits(0x100, bytes(9))
    with pytest.raises(FrameError):
        can_bits(0x800, b"")


def test_ieee802154_overhead_and_limit():
    """6 PHY bytes + 9 MAC header + payload + 2 FCS; the MAC frame at most 127 bytes."""
    assert ieee802154_frame_bits(0) == 8 * 17
    assert ieee802154_frame_bits(116) == 8 * (6 + 127)
    assert IEEE802154_ACK_BITS == 88
    with pytest.raises(FrameError):
        ieee802154_frame_bits(117)
