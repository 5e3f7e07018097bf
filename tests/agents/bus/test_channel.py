"""The buses as petriflow media: a run's messages become frames on the bus, and each
message is delivered or lost when that happens (never decided ahead of time)."""

from __future__ import annotations

import random

import pytest
from petriflow.agents.bus.errors import BusError
from petriflow.agents.bus import CanBus, SerialBus, ZigbeeBus

from petriflow.errors import NetFormatError
from petriflow.io.yaml import loads_net
from petriflow.runtime import channels
from petriflow.runtime.channels import Message, build_channel
from petriflow.runtime.config import RunConfig
from petriflow.runtime.kernel import Kernel
from petriflow.runtime.media import MediumPort, ProcessClock
from petriflow.runtime.scheduler import Scheduler

BIT_SERIAL = 1 / 115_200
SERIAL_FRAME = 100 * BIT_SERIAL  # 9 bytes and a checksum byte, 8N1


def attached(bus, seed=0):
    """``bus`` attached to a kernel of its own; the fates it gives: ``(fate, n, time)``."""
    clock = ProcessClock(Kernel(1e-5))
    fates = []
    port = MediumPort(clock, lambda m: fates.append(("delivered", m.data["n"], clock.now)),
                      lambda m, why: fates.append((why, m.data["n"], clock.now)), random.Random(seed))
    bus.attach(port)
    return clock, fates


def message(n, sender, receiver, size=9, place="inbox", **data):
    return Message(place, sender, receiver, {"n": n, "size": size, **data}, 0.0, size)


def test_serial_delivers_at_the_frame_end_and_an_overlap_loses_both_then():
    """(9 + 1) bytes × 10 bits at 115 200 baud, read on arrival; a frame sent while it is
    on the line garbles both: both messages are lost at that moment."""
    bus = SerialBus()
    clock, fates = attached(bus)
    bus.send(message(1, "a", "b"))
    clock.run(until=0.01)
    assert fates == [("delivered", 1, pytest.approx(SERIAL_FRAME))]
    clock.at(0.01, bus.send, message(2, "a", "b"))
    clock.at(0.01 + 50 * BIT_SERIAL, bus.send, message(3, "c", "b"))
    clock.run(until=0.02)
    assert fates[1:] == [("collision", 2, pytest.approx(0.01 + 50 * BIT_SERIAL)),
                         ("collision", 3, pytest.approx(0.01 + 50 * BIT_SERIAL))]


def test_can_queues_a_message_behind_the_frame_on_the_bus():
    """A CAN message sent while the bus is busy waits for it and its intermission."""
    bus = CanBus(logs=True)
    clock, fates = attached(bus)
    bus.send(message(1, "a", "b", 8))
    clock.at(0.0001, bus.send, message(2, "c", "b", 8))
    clock.run(until=0.01)
    first, second = bus.state.transmissions
    assert second.start == pytest.approx(first.end + 3 / 512_000)
    assert fates == [("delivered", 1, first.end), ("delivered", 2, second.end)]


def test_a_receiver_that_reads_every_period_gets_the_message_at_its_next_read():
    """Receivers read every 20 ms (the bus's read_period): a message reaches the buffer
    and waits for the read."""
    bus = CanBus(read_period=0.02)
    clock, fates = attached(bus)
    clock.at(0.001, bus.send, message(1, "a", "b", 8))
    clock.run(until=0.1)
    assert fates == [("delivered", 1, pytest.approx(0.02))]


def test_an_overwritten_message_is_lost_when_the_later_frame_arrives_not_when_sent():
    """CAN, one-frame buffers, reads every 20 ms: the second message's frame overwrites the
    first in b's buffer; the first is lost then (when the second frame ends), the second is
    read at 20 ms; a third after that read overwrites nothing."""
    bus = CanBus(read_period=0.02, logs=True)
    clock, fates = attached(bus)
    clock.at(0.001, bus.send, message(1, "a", "b", 8))
    clock.at(0.005, bus.send, message(2, "c", "b", 8))
    clock.at(0.025, bus.send, message(3, "c", "b", 8))
    clock.run(until=0.1)
    second = bus.state.transmissions[1]
    assert second.start == pytest.approx(0.005)
    assert fates == [("overwritten", 1, second.end), ("delivered", 2, pytest.approx(0.02)),
                     ("delivered", 3, pytest.approx(0.04))]


def test_a_long_message_is_split_into_can_frames_and_arrives_with_its_last():
    bus = CanBus(logs=True)
    clock, fates = attached(bus)
    bus.send(Message("inbox", "a", "b", {"n": 1, "payload": bytes(16)}, 0.0, 16))
    clock.run(until=0.01)
    frames = bus.state.transmissions
    assert [len(t.frame.data) for t in frames] == [8, 8]
    assert fates == [("delivered", 1, frames[1].end)]


def test_zigbee_delay_includes_both_uarts_and_the_air():
    """At least the two UART legs at 57 600 baud and the frame on the air."""
    bus = ZigbeeBus()
    clock, fates = attached(bus)
    bus.send(message(1, "a", "b"))
    clock.run(until=0.1)
    [(fate, _, time)] = fates
    assert fate == "delivered" and time > 2 * 90 / 57_600 + 336 / 250_000


def test_a_multicast_group_is_one_frame_read_by_each_receiver_when_it_reads():
    """The firmware's one message to both neighbours: a copy per receiver's place, one
    frame on the bus; each copy is delivered when its receiver reads the frame."""
    bus = SerialBus(logs=True)
    clock, fates = attached(bus)
    bus.view("c").reads_every(0.005)
    group = {"payload": bytes(9), "multicast": 1, "receivers": ["b", "c"]}
    bus.send(Message("box_a_b", "a", "b", {"n": "b", **group}, 0.0, 9))
    bus.send(Message("box_a_c", "a", "c", {"n": "c", **group}, 0.0, 9))
    clock.run(until=0.01)
    [frame] = bus.state.transmissions
    assert frame.frame.receivers == (bus.carrier.numbers["b"], bus.carrier.numbers["c"])
    assert fates == [("delivered", "b", pytest.approx(SERIAL_FRAME)),
                     ("delivered", "c", pytest.approx(0.005))]


def test_a_copy_that_joins_a_group_already_lost_is_lost_at_once():
    """No room in the transmit queue: the group's frame is refused when the first copy
    is sent; the second copy learns its fate when it joins."""
    bus = SerialBus(tx_queue=0)
    clock, fates = attached(bus)
    group = {"payload": bytes(9), "multicast": 7, "receivers": ["b", "c"]}
    bus.send(Message("box_a_b", "a", "b", {"n": "b", **group}, 0.0, 9))
    bus.send(Message("box_a_c", "a", "c", {"n": "c", **group}, 0.0, 9))
    assert fates == [("queue_full", "b", 0.0), ("queue_full", "c", 0.0)]


def test_a_message_for_nobody_arrives_when_its_frame_leaves_the_bus_intact():
    bus = SerialBus()
    clock, fates = attached(bus)
    bus.send(message(1, "a", None))
    clock.run(until=0.01)
    clock.at(0.01, bus.send, message(2, "a", None))
    clock.at(0.0101, bus.send, message(3, "b", "a"))
    clock.run(until=0.02)
    assert fates == [("delivered", 1, pytest.approx(SERIAL_FRAME)), ("collision", 2, pytest.approx(0.0101)),
                     ("collision", 3, pytest.approx(0.0101))]


def test_the_view_is_what_firmware_may_ask():
    """Is the bus quiet, how often do I read my buffer, does my address travel in the
    identifier; a bus not attached to a run has no view."""
    with pytest.raises(BusError, match="not attached"):
        CanBus().view("a")
    bus = CanBus()
    clock, _ = attached(bus)
    view = bus.view("b")
    assert view.sender_in_identifier and view.read_period == 0.0
    view.reads_every(0.5)
    assert view.read_period == 0.5
    clock.at(0.1, bus.send, message(1, "a", "b", 8))
    seen = []
    clock.at(0.1001, lambda: seen.append(view.quiet_for()))  # the frame is on the bus (about 0.2 ms)
    clock.at(0.3, lambda: seen.append(view.quiet_for()))
    clock.run(until=1.0)
    assert seen[0] == 0.0 and seen[1] == pytest.approx(0.2, abs=0.001)
    serial = SerialBus()
    attached(serial)
    assert not serial.view("a").sender_in_identifier
    with pytest.raises(BusError):
        view.reads_every(float("nan"))


def test_bus_parameters_are_checked_like_built_in_models(monkeypatch):
    """As a named channel model, a bus's parameters are range-checked at load time."""
    monkeypatch.setitem(channels.CHANNEL_MODELS, "bus.can", CanBus)
    model = build_channel("cpg", {"model": "bus.can", "bitrate": 250_000.0, "read_period": 0.02})
    assert isinstance(model, CanBus) and model.bitrate == 250_000.0
    with pytest.raises(NetFormatError):
        build_channel("cpg", {"model": "bus.can", "bitrate": -1.0})
    with pytest.raises(NetFormatError):
        build_channel("cpg", {"model": "bus.can", "bitrat": 1.0})


TWO_SENDERS = """
petriflow: 1
subnets:
  - id: a
    places: [{{id: a_ready, tokens: 1}}, a_done]
    transitions:
      - {{id: a_send, action: core.set, params: {{value: {{size: 8, n: 1}}}},
         in: [a_ready], out: [a_done, inbox]}}
  - id: c
    places: [{{id: c_ready, tokens: 1}}, c_waited, c_done]
    transitions:
      - {{id: c_wait, action: core.wait, params: {{seconds: {later}}}, in: [c_ready], out: [c_waited]}}
      - {{id: c_send, action: core.set, params: {{value: {{size: 8, n: 2}}}},
         in: [c_waited], out: [c_done, inbox]}}
  - id: b
    places: [{{id: inbox, channel: bus}}, b_got]
    transitions: [{{id: b_take, in: [inbox], out: [b_got]}}]
"""


def run_two_senders(bus, later, dt, **parameters):
    net = loads_net(TWO_SENDERS.format(later=later))
    config = RunConfig(dt=dt, channels={"bus": {"model": bus, "logs": True, **parameters}})
    scheduler = Scheduler(net, config=config)
    events = []
    scheduler.on_event(events.append)
    result = scheduler.run(until=1)
    fates = [(e.time, e.data["fate"], e.data.get("why")) for e in events if e.kind == "message"]
    return result, fates, scheduler.channels.models["bus"].state


def test_in_a_run_an_overwritten_message_is_lost_when_the_later_frame_arrives():
    """CAN with one-frame buffers, b reading every 50 ms: a's message is lost when c's
    frame reaches b's buffer (at the first tick after it ended), not when it was sent;
    c's is delivered at b's read."""
    result, fates, medium = run_two_senders("bus.can", 0.01, 0.001, read_period=0.05)
    arrival = medium.transmissions[1].end
    assert 0.01 < arrival < 0.011
    assert fates == [(0.0, "sent", None), (0.01, "sent", None), (0.011, "lost", "overwritten"),
                     (0.05, "delivered", None)]
    assert result.tokens["b_got"] == [{"size": 8, "n": 2}]


def test_in_a_run_two_overlapping_rs485_frames_are_both_lost_at_the_overlap():
    """RS-485: c starts while a's frame (about 0.8 ms) is on the line: both are lost
    at that moment (0.4 ms), the first not when it was sent."""
    result, fates, medium = run_two_senders("bus.serial", 0.0004, 0.0001)
    assert [t.garbled for t in medium.transmissions] == [True, True]
    assert fates == [(0.0, "sent", None), (0.0004, "sent", None), (0.0004, "lost", "collision"),
                     (0.0004, "lost", "collision")]
    assert "b_got" not in result.tokens


def test_a_run_delivers_through_a_bus_channel(monkeypatch):
    """A two-agent net whose channel place is carried by the CAN bus model ends with the
    token delivered."""
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
