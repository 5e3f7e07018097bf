"""The buses as petriflow channel models: deciding each message when it is sent."""

from __future__ import annotations

import random

import pytest
from petriflow.agents.bus.medium import CanBus, SerialBus, ZigbeeBus

from petriflow.errors import NetFormatError
from petriflow.runtime import channels
from petriflow.runtime.channels import Message, build_channel

BIT_SERIAL = 1 / 115_200


def message(sender, receiver, time, size=9, data=None):
    return Message("inbox", sender, receiver, data if data is not None else {"size": size}, time, size)


def test_serial_delay_is_the_frame_time_and_an_overlap_garbles_both():
    """(9 + 1) bytes × 10 bits at 115 200 baud; a frame sent during it collides: the
    later one is lost at once, the earlier (already promised) is revoked."""
    bus, rng = SerialBus(), random.Random(0)
    first = message("a", "b", 0.0)
    assert bus.deliver(first, rng) == pytest.approx(100 * BIT_SERIAL)
    assert bus.deliver(message("c", "b", 50 * BIT_SERIAL), rng) is None
    assert first.revoked == "collision"
    assert bus.deliver(message("c", "b", 0.01), rng) == pytest.approx(100 * BIT_SERIAL)


def test_can_queues_a_message_behind_the_frame_on_the_bus():
    """A CAN message sent while the bus is busy waits: its delay includes the wait."""
    bus, rng = CanBus(), random.Random(0)
    first = bus.deliver(message("a", "b", 0.0, 8), rng)
    second = bus.deliver(message("c", "b", first / 2, 8), rng)
    assert second is not None and second > first


def test_read_period_adds_the_wait_for_the_next_read():
    """Receivers read every 20 ms: a message arrives in the buffer and waits for the read."""
    bus, rng = CanBus(read_period=0.02), random.Random(0)
    assert bus.deliver(message("a", "b", 0.001, 8), rng) == pytest.approx(0.019)


def test_second_message_before_a_read_overwrites_the_first_in_the_buffer():
    """The receive buffer keeps the newest frame, as the hardware does: the first message
    was promised for the next read, and is revoked (lost) when the second overwrites it."""
    bus, rng = CanBus(read_period=0.02), random.Random(0)
    first = message("a", "b", 0.001, 8)
    assert bus.deliver(first, rng) is not None and first.revoked is None
    second = message("c", "b", 0.005, 8)
    assert bus.deliver(second, rng) is not None
    assert first.revoked == "overwritten" and second.revoked is None
    third = message("c", "b", 0.025, 8)  # after the read at 0.02 s: nothing to overwrite
    assert bus.deliver(third, rng) is not None and second.revoked is None


def test_long_message_is_split_into_can_frames():
    """16 bytes need two CAN frames; the message arrives with the second."""
    bus, rng = CanBus(), random.Random(0)
    short = bus.deliver(message("a", "b", 0.0, 8, data=bytes(8)), rng)
    long = CanBus().deliver(message("a", "b", 0.0, 16, data=bytes(16)), random.Random(0))
    assert long > 2 * short * 0.9


def test_zigbee_delay_includes_both_uarts_and_the_air():
    """At least the two UART legs at 57 600 baud and the frame on the air."""
    delay = ZigbeeBus().deliver(message("a", "b", 0.0), random.Random(0))
    assert delay > 2 * 90 / 57_600 + 336 / 250_000


def test_bus_parameters_are_checked_like_built_in_models(monkeypatch):
    """As a named channel model, a bus's parameters are range-checked at load time."""
    monkeypatch.setitem(channels.CHANNEL_MODELS, "bus.can", CanBus)
    model = build_channel("cpg", {"model": "bus.can", "bitrate": 250_000.0, "read_period": 0.02})
    assert isinstance(model, CanBus) and model.bitrate == 250_000.0
    with pytest.raises(NetFormatError):
        build_channel("cpg", {"model": "bus.can", "bitrate": -1.0})
    with pytest.raises(NetFormatError):
        build_channel("cpg", {"model": "bus.can", "bitrat": 1.0})


def test_a_run_delivers_through_a_bus_channel(monkeypatch):
    """A two-agent net whose channel place is carried by the CAN bus model ends with the
    token delivered."""
    from petriflow.io.yaml import loads_net
    from petriflow.runtime.config import RunConfig
    from petriflow.runtime.scheduler import Scheduler

    monkeypatch.setitem(channels.CHANNEL_MODELS, "bus.can", CanBus)
    net = loads_net("""
petriflow: 1
subnets:
  - id: a
    places: [{id: a_ready, tokens: 1}, a_done]
    transitions: [{id: send, action: core.set, params: {value: {size: 8}}, in: [a_ready], out: [a_done, inbox]}]
  - id: b
    places: [{id: inbox, channel: cpg}, b_done]
    transitions: [{id: receive, in: [inbox], out: [b_done]}]
""")
    scheduler = Scheduler(net, config=RunConfig(channels={"cpg": {"model": "bus.can"}}))
    events = []
    scheduler.on_event(events.append)
    result = scheduler.run(until=5)
    assert result.marking == {"a_done": 1, "b_done": 1}
    assert [e.data["fate"] for e in events if e.kind == "message"] == ["sent", "delivered"]
