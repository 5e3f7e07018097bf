"""The CPG message's bytes."""

from __future__ import annotations

import math

import pytest
from petriflow.agents.bus.frames import FrameError
from petriflow.agents.bus.packet import NOBODY, Packet, can_identifier, decode, encode


def test_round_trip_keeps_addresses_and_parameters():
    """Decoding the bytes gives the packet back (phase to 2π/65536, x and r to 1 mrad)."""
    packet = Packet((2, 0), 1, phase=7.0, offset=-0.25, amplitude=0.5)
    back = decode(encode(packet))
    assert back.receivers == (2, 0) and back.sender == 1
    assert back.phase == pytest.approx(7.0 - 2 * math.pi, abs=1e-4)
    assert (back.offset, back.amplitude) == (-0.25, 0.5)


def test_can_data_field_has_eight_bytes_and_sender_in_identifier():
    """Without the sender byte the packet fits a CAN frame; the identifier carries it."""
    packet = Packet((1,), 0, phase=1.0)
    data = encode(packet, with_sender=False)
    assert len(data) == 8 and data[1] == NOBODY
    assert decode(data, sender=0).sender == 0
    assert can_identifier(0) < can_identifier(1) < can_identifier(254)


def test_bad_packets_are_refused():
    """No receiver, three receivers, address 255, an amplitude too large."""
    for packet in (Packet((), 0, 0.0), Packet((1, 2, 3), 0, 0.0), Packet((NOBODY,), 0, 0.0),
                   Packet((1,), 0, 0.0, amplitude=40.0)):
        with pytest.raises(FrameError):
            encode(packet)
    with pytest.raises(FrameError):
        decode(b"\x00" * 5)
