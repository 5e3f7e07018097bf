"""The remote-action protocol: every message round-trips; what is not a message is refused with its reason."""

import json

import pytest

from petriflow.bridge import protocol
from petriflow.bridge.protocol import Drop, Refused, decode, encode

MESSAGES = [
    protocol.Announce("red", {"core.wait": {"seconds": {"type": "float", "default": 1.0}}}, "i1"),
    protocol.Heartbeat("red", ["run/1/1"], "i1"),
    protocol.Goal("run/1/1", "red", "core.wait", {"seconds": 2.0}, "t", {"p": [None, {"x": 1}]}, "1:1"),
    protocol.Accepted("run/1/1", "red"),
    protocol.Rejected("run/1/1", "red", "unknown action"),
    protocol.Feedback("run/1/1", "red", {"done": 0.5}),
    protocol.Result("run/1/1", "red", "ok", {"x": [1, 2]}),
    protocol.Result("run/1/1", "red", "failed", None, "motor stalled"),
    protocol.Cancel("run/1/1", "red"),
    protocol.Cancelled("run/1/1", "red"),
]


@pytest.mark.parametrize("message", MESSAGES, ids=lambda m: m.kind.value)
def test_every_message_round_trips(message):
    """Encoding then decoding gives the same message, with the version and type in the JSON."""
    data = encode(message)
    body = json.loads(data)
    assert body["v"] == protocol.VERSION and body["type"] == message.kind.value
    assert decode(data) == message


def refusal(data) -> Drop:
    with pytest.raises(Refused) as caught:
        decode(data)
    return caught.value.drop


def test_an_oversized_message_is_refused_unread():
    """Ten megabytes is refused as oversized before any parsing."""
    assert refusal(b"{" + b" " * (10 << 20)) is Drop.OVERSIZED


@pytest.mark.parametrize("data", [b"not json", b"[1, 2]", b'{"v": 1, "type": "launch"}', b"\xff\xfe",
                                  b'{"v": 1, "type": "result", "id": "x", "agent": "a"}',
                                  b'{"v": 1, "type": "result", "id": "x", "agent": "a", "outcome": "maybe"}',
                                  b'{"v": 1, "type": "accepted", "id": 3, "agent": "a"}',
                                  b'{"v": 1, "type": "accepted", "id": "x", "agent": "a", "exec": "rm"}',
                                  b'{"v": 1, "type": "heartbeat", "agent": "a", "running": [1]}'])
def test_malformed_messages_are_refused_as_malformed(data):
    """Not JSON, not an object, an unknown type, a missing, ill-typed or unknown field."""
    assert refusal(data) is Drop.MALFORMED


def test_another_version_is_refused():
    assert refusal(b'{"v": 2, "type": "accepted", "id": "x", "agent": "a"}') is Drop.VERSION


def test_deep_nesting_is_refused():
    deep = "[" * 100 + "]" * 100
    data = f'{{"v": 1, "type": "feedback", "id": "x", "agent": "a", "data": {deep}}}'.encode()
    assert refusal(data) is Drop.MALFORMED


def test_a_message_too_large_to_send_is_an_error():
    with pytest.raises(ValueError, match="over the limit"):
        encode(protocol.Feedback("x", "a", "y" * (protocol.MAX_MESSAGE + 1)))


def test_goal_ids_name_run_firing_and_attempt():
    assert protocol.goal_id("r", 7, 2) == "r/7/2"
