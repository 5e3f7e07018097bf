"""The one message type: a scenario's payload gives a message its kind and size."""

from dataclasses import dataclass

from petriflow.runtime.channel_models import Message, payload_size


def test_a_message_takes_its_kind_and_size_from_its_payload():
    @dataclass(frozen=True)
    class Bid:
        cost: float
        kind = "PROPOSE"
        size = 12

    message = Message(None, "robot1", "robot2", Bid(3.5))
    assert (message.kind, message.size, message.data.cost) == ("PROPOSE", 12, 3.5)
    assert Message("box", "a", "b", {"size": 40, "kind": "MAP"}).kind == "MAP"
    assert payload_size({"size": True}) == 16 and Message("box", "a", "b", None, 0.0, 7).size == 7
