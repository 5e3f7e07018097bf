"""SMART command frames: encode, decode, errors."""

import pytest
from hypothesis import given
from hypothesis import strategies as st

from petriflow.agents.smart.messages import (ActionId, Command, MessageError, decode, encode,
                                             from_cells, to_cells)


def test_move_command_is_the_papers_seven_bytes():
    """[action][robot],[X],[Y]% is seven bytes with the parameters at bytes 4 and 6."""
    frame = encode(Command(ActionId.MOVE_TO, 3, (10, 20)))
    assert len(frame) == 7
    assert (frame[3], frame[5], frame[2:3], frame[4:5], frame[-1:]) == (10, 20, b",", b",", b"%")


@given(st.lists(st.builds(Command, st.sampled_from(list(ActionId)), st.integers(0, 255),
                          st.lists(st.integers(0, 255), max_size=4).map(tuple)), max_size=6))
def test_stream_of_commands_round_trips(commands):
    """Any sequence of commands decodes back, even with ',' and '%' as parameter bytes."""
    assert decode(b"".join(encode(c) for c in commands)) == commands


@pytest.mark.parametrize("frame, message", [
    (b"\x01\x03,", "truncated"),
    (b"\x01\x03,\x05", "no '%' end"),
    (b"\x09\x03%", "unknown action id 9"),
    (b"\x01\x03;\x05%", "expected ',' or '%' at byte 2"),
])
def test_malformed_frames_are_rejected_with_the_offset(frame, message):
    """Bad frames raise MessageError saying where."""
    with pytest.raises(MessageError, match=message):
        decode(frame)


def test_parameters_must_fit_a_byte():
    """A parameter of 256 cannot be sent."""
    with pytest.raises(MessageError, match="one byte"):
        encode(Command(ActionId.MOVE_TO, 1, (256, 0)))


def test_positions_travel_as_coarse_cells():
    """World points map to byte cells and back to the cell centre."""
    assert from_cells(*to_cells(1.23, 0.5, 0.025), 0.025) == pytest.approx((1.225, 0.5))
    with pytest.raises(MessageError, match="outside"):
        to_cells(7.0, 0.0, 0.025)
