"""The three buses: arbitration, collisions, CSMA/CA, receive buffers and transmit queues."""

from __future__ import annotations

import itertools
import random

import pytest
from petriflow.agents.bus.errors import BusError
from petriflow.agents.bus.frames import FrameError
from petriflow.agents.bus import BusSimulator, CanBus, Frame, Loss, SerialBus, ZigbeeBus
from petriflow.runtime.kernel import Kernel
from petriflow.runtime.media import ProcessClock

BIT_CAN = 1 / 512_000
BIT_SERIAL = 1 / 115_200
UNIT = 320e-6
CCA = 128e-6
TURNAROUND = 192e-6


def frame(sender, receivers=(1,), identifier=None, data=bytes(8), tag=None):
    """A frame of 8 zero bytes, by default with the identifier 0x100 + sender."""
    identifier = 0x100 + sender if identifier is None else identifier
    return Frame(sender, tuple(receivers), data, identifier, tag if tag is not None else sender)


def on_clock(bus, modules, rng=None, **options):
    """A bus on a kernel of its own (1 µs ticks); modules read only when told."""
    clock = ProcessClock(Kernel(1e-6))
    options.setdefault("read_period", None)
    return bus.medium(clock, rng or random.Random(0), modules, **options), clock


class FixedBackoff(random.Random):
    """A medium random generator whose backoffs are always ``value`` (and that records
    the ranges asked for)."""

    def __init__(self, value=0):
        super().__init__(0)
        self.value = value
        self.asked = []

    def randrange(self, *args, **kwargs):
        self.asked.append(args[0])
        return min(self.value, args[0] - 1)


# CAN --------------------------------------------------------------------------------

def test_can_lower_identifier_wins_and_loser_retries_after_it():
    """Two SOFs within one bit time arbitrate: 0x101 goes first, 0x102 right after the
    winner's frame and intermission; nothing is lost."""
    sim = BusSimulator(CanBus(), modules=[0, 1, 2])
    sim.send(0.0, frame(2, (0,), 0x102, bytes(8)))
    sim.send(0.5 * BIT_CAN, frame(1, (0,), 0x101, bytes(8)))
    medium = sim.run()
    first, second = medium.transmissions
    assert (first.frame.identifier, second.frame.identifier) == (0x101, 0x102)
    assert first.start == 0.0
    assert second.start == pytest.approx(first.end + 3 * BIT_CAN)
    assert not first.garbled and not second.garbled
    assert not [loss for loss in medium.losses if loss.reason is not Loss.OVERWRITTEN]


def test_can_frame_after_the_sof_waits_even_with_a_lower_identifier():
    """A node that has seen the SOF does not interrupt; at the next idle bus it beats
    the earlier loser."""
    sim = BusSimulator(CanBus(), modules=[0, 1, 2, 3])
    sim.send(0.0, frame(2, (0,), 0x102, bytes(8)))
    sim.send(0.0, frame(1, (0,), 0x101, bytes(8)))
    sim.send(10 * BIT_CAN, frame(3, (0,), 0x0FF, bytes(8)))
    medium = sim.run()
    assert [t.frame.identifier for t in medium.transmissions] == [0x101, 0x0FF, 0x102]
    ends = [(t.start, t.end) for t in medium.transmissions]
    assert all(later[0] >= earlier[1] for earlier, later in itertools.pairwise(ends))


def test_can_shared_identifier_is_an_error():
    """Two modules arbitrating with one identifier is a configuration error."""
    sim = BusSimulator(CanBus(), modules=[0, 1, 2])
    sim.send(0.0, frame(0, (2,), 0x100))
    sim.send(0.0, frame(1, (2,), 0x100))
    with pytest.raises(FrameError):
        sim.run()


def test_can_refuses_nine_data_bytes():
    """A request the bus cannot carry fails at once."""
    medium, _ = on_clock(CanBus(), [0, 1])
    with pytest.raises(FrameError):
        medium.request(frame(0, (1,), 0x100, bytes(9)))


# RS-485 -----------------------------------------------------------------------------

def test_rs485_overlapping_frames_garble_both_at_the_overlap():
    """A frame starting while another is on the line: both are lost to everyone, at the
    moment they overlap (not when the first was sent, nor when they end)."""
    sim = BusSimulator(SerialBus(), modules=[0, 1, 2])
    sim.send(0.0, frame(0, (1,)))
    sim.send(50 * BIT_SERIAL, frame(2, (1,)))
    sim.read(0.01, 1)
    medium = sim.run()
    assert [t.garbled for t in medium.transmissions] == [True, True]
    assert sim.received[1] == []
    collisions = sorted((loss.frame.sender, loss.time) for loss in medium.losses if loss.reason is Loss.COLLISION)
    assert collisions == [(0, pytest.approx(50 * BIT_SERIAL)), (2, pytest.approx(50 * BIT_SERIAL))]


def test_rs485_back_to_back_frames_both_arrive():
    """A frame starting when the previous ends does not collide."""
    bits = SerialBus().frame_bits(frame(0))
    sim = BusSimulator(SerialBus(), modules=[0, 1, 2])
    sim.send(0.0, frame(0, (1,)))
    sim.send(bits * BIT_SERIAL, frame(2, (1,)))
    sim.read(bits * BIT_SERIAL, 1)  # between the two
    sim.read(0.01, 1)
    medium = sim.run()
    assert [t.garbled for t in medium.transmissions] == [False, False]
    assert [f.sender for f in sim.received[1]] == [0, 2]


def test_rs485_carrier_sense_sees_a_frame_one_bit_after_its_start():
    """is_free is true within the sensing delay of a start bit, false after it."""
    medium, clock = on_clock(SerialBus(), [0, 1])
    medium.request(frame(0))
    clock.run(until=0.5 * BIT_SERIAL)
    assert medium.is_free(1) and medium.quiet_for() == 0.0
    clock.run(until=2 * BIT_SERIAL)
    assert not medium.is_free(1)
    clock.run(until=0.01)
    assert medium.is_free(1)
    assert medium.quiet_for() == pytest.approx(0.01 - 90 * BIT_SERIAL)  # 8 bytes and a checksum, 8N1


# Buffers and queues -----------------------------------------------------------------

def test_receive_buffer_of_one_frame_is_overwritten_when_the_newer_arrives():
    """Two frames before a read: the module gets the newer; the older is lost,
    overwritten, when the newer reached the buffer (the end of its transmission)."""
    sim = BusSimulator(CanBus(), modules=[0, 1, 2])
    sim.send(0.0, frame(0, (1,), 0x100, tag="old"))
    sim.send(0.001, frame(2, (1,), 0x102, tag="new"))
    sim.read(0.005, 1)
    medium = sim.run()
    assert [f.tag for f in sim.received[1]] == ["new"]
    new = medium.transmissions[1]
    assert [(loss.frame.tag, loss.module, loss.reason, loss.time) for loss in medium.losses
            if loss.module == 1] == [("old", 1, Loss.OVERWRITTEN, new.end)]


def test_bigger_receive_buffer_keeps_both():
    """With two places both frames are read."""
    sim = BusSimulator(CanBus(rx_buffer=2), modules=[0, 1, 2])
    sim.send(0.0, frame(0, (1,), 0x100, tag="old"))
    sim.send(0.001, frame(2, (1,), 0x102, tag="new"))
    sim.read(0.005, 1)
    sim.run()
    assert [f.tag for f in sim.received[1]] == ["old", "new"]


def test_frame_for_another_module_overwrites_without_acceptance_filter():
    """Software filtering: a frame for module 2 still takes module 1's buffer; a hardware
    acceptance filter keeps it out."""
    for filtered, expected in ((False, []), (True, ["mine"])):
        sim = BusSimulator(CanBus(acceptance_filter=filtered), modules=[0, 1, 2])
        sim.send(0.0, frame(0, (1,), 0x100, tag="mine"))
        sim.send(0.001, frame(0, (2,), 0x100, tag="theirs"))
        sim.read(0.005, 1)
        sim.run()
        assert [f.tag for f in sim.received[1]] == expected


def test_transmit_queue_overflows():
    """tx_queue=1: one frame on the line, one waiting, the third is dropped."""
    sim = BusSimulator(SerialBus(tx_queue=1), modules=[0, 1])
    medium = sim.medium
    results = [medium.request(frame(0, tag=i)) for i in range(3)]
    assert results == [True, True, False]
    assert [(loss.frame.tag, loss.reason) for loss in medium.losses] == [(2, Loss.QUEUE_FULL)]
    sim.run()
    assert [t.frame.tag for t in medium.transmissions] == [0, 1]


def test_unattached_sender_is_refused():
    """A module must be attached before it sends."""
    medium, _ = on_clock(SerialBus(), [0])
    with pytest.raises(FrameError):
        medium.request(frame(5))


# ZigBee -----------------------------------------------------------------------------

def _ready_time(bus, data_bytes=8):
    return 10 * (data_bytes + bus.packetization_chars) / bus.uart_baud


def test_zigbee_first_backoff_is_zero_to_seven_unit_periods():
    """One frame on a quiet channel: it goes on the air after the UART, k·320 µs with
    0 <= k <= 7, the CCA and the turnaround; all eight k appear over seeds."""
    bus = ZigbeeBus(network=False)
    seen = set()
    for seed in range(200):
        sim = BusSimulator(bus, modules=[0, 1], seed=seed)
        sim.send(0.0, frame(0))
        start = sim.run().transmissions[0].start
        k = (start - _ready_time(bus) - CCA - TURNAROUND) / UNIT
        assert k == pytest.approx(round(k), abs=1e-6)
        seen.add(round(k))
    assert seen == set(range(8))


def test_zigbee_busy_channel_raises_the_backoff_exponent_and_gives_up():
    """While another radio holds the air, every CCA fails: backoff ranges 2^3, 2^4, 2^5,
    2^5, 2^5, then the frame is dropped for channel access failure."""
    slow = ZigbeeBus(network=False, air_bitrate=1000.0)  # the first frame holds the air for 0.336 s
    rng = FixedBackoff(0)
    medium, clock = on_clock(slow, [0, 1, 2], rng)
    medium.request(frame(0, (2,), tag="jammer"))
    clock.run(until=0.005)
    rng.asked.clear()
    medium.request(frame(1, (2,), tag="victim"))
    clock.run(until=0.2)
    assert rng.asked == [8, 16, 32, 32, 32]
    [loss] = [loss for loss in medium.losses if loss.frame.tag == "victim"]
    assert loss.reason is Loss.ACCESS_FAILURE
    assert loss.time == pytest.approx(0.005 + _ready_time(slow) + 5 * CCA)


def test_zigbee_radios_assessing_together_collide():
    """Two radios whose CCAs end at the same time both find the air clear, both send,
    both frames are garbled."""
    medium, clock = on_clock(ZigbeeBus(network=False), [0, 1, 2], FixedBackoff(0))
    medium.request(frame(0, (2,), tag="a"))
    medium.request(frame(1, (2,), tag="b"))
    clock.run(until=0.1)
    assert [t.garbled for t in medium.transmissions] == [True, True]
    start = medium.transmissions[0].start
    assert {(loss.frame.tag, loss.time) for loss in medium.losses if loss.reason is Loss.COLLISION} == {
        ("a", start), ("b", start)}


def test_zigbee_radio_after_a_clear_assessment_waits_for_the_air():
    """A radio whose CCA comes after another's frame started defers: no collision."""
    medium, clock = on_clock(ZigbeeBus(network=False), [0, 1, 2], FixedBackoff(0))
    medium.request(frame(0, (2,), tag="a"))
    clock.run(until=0.0025)  # a is on the air now
    medium.request(frame(1, (2,), tag="b"))
    clock.run(until=0.1)
    assert [t.garbled for t in medium.transmissions] == [False, False]
    a, b = medium.transmissions
    assert b.start >= a.end


def test_zigbee_weak_link_loses_frames_to_bit_errors():
    """Far below the noise floor every frame is lost on the link (RSSI-dependent loss);
    at the default power the neighbour hears everything."""
    for power, reason in ((-80.0, Loss.RADIO), (0.0, None)):
        sim = BusSimulator(ZigbeeBus(network=False, tx_power_dbm=power), modules=[0, 1], seed=3)
        for i in range(5):
            sim.send(0.05 * i, frame(0, (1,), tag=i))
            sim.read(0.05 * i + 0.04, 1)
        medium = sim.run()
        radio = [loss for loss in medium.losses if loss.reason is Loss.RADIO]
        assert len(radio) == (5 if reason else 0)
        assert len(sim.received[1]) == (0 if reason else 5)


def test_zigbee_module_only_sees_its_own_radio():
    """The module cannot hear the air: the bus is 'free' for it while another radio sends."""
    medium, _ = on_clock(ZigbeeBus(network=False), [0, 1])
    medium.request(frame(0))
    assert not medium.is_free(0) and medium.is_free(1)


@pytest.mark.parametrize("bus", [SerialBus(), CanBus(), ZigbeeBus(network=False, shadowing_db=6.0), ZigbeeBus(shadowing_db=6.0)])
def test_same_seed_same_history(bus):
    """A seed fixes every draw: same seed, same transmissions and losses."""

    def history(seed):
        sim = BusSimulator(bus, modules=[0, 1, 2], seed=seed)
        for i in range(30):
            sender = i % 3
            sim.send(0.0007 * i, frame(sender, ((sender + 1) % 3,), 0x100 + sender, bytes(8), tag=i))
        for module in range(3):
            sim.reads_every(module, 0.02, phase=0.001 * module)
        medium = sim.run()
        return ([(t.frame.tag, round(t.start, 9), t.garbled) for t in medium.transmissions],
                [(loss.frame.tag, loss.module, loss.reason) for loss in medium.losses])

    assert history(1) == history(1)
    if isinstance(bus, ZigbeeBus):  # backoffs and fading are drawn: another seed, another history
        assert history(1) != history(2)


# Reads, listeners and logs ---------------------------------------------------------

def test_a_read_is_scheduled_only_while_a_frame_waits_on_the_modules_phase():
    """A module reading every 10 ms from 3 ms: nothing is scheduled while its buffer is
    empty; a frame arriving at about 0.24 ms is read at 3 ms, one arriving at about 13.3
    ms at 23 ms, and when the bus is done nothing is left pending (a run would end)."""
    medium, clock = on_clock(CanBus(), [0, 1])
    medium.reads_every(1, 0.01, phase=0.003)
    assert clock.kernel.pending == 0
    reads = []
    medium.on_delivery(lambda d: reads.append((d.frame.tag, d.arrived, d.read)))
    medium.request(frame(0, (1,), tag="first"))
    clock.run(until=0.0005)
    assert medium.waiting(1) == 1 and clock.kernel.pending == 1  # the read at 3 ms, nothing else
    clock.run(until=0.005)
    assert clock.kernel.pending == 0
    assert reads == [("first", medium.transmissions[0].end, pytest.approx(0.003))]
    clock.at(0.0131, medium.request, frame(0, (1,), tag="second"))
    clock.run(until=0.05)
    assert reads[1] == ("second", medium.transmissions[1].end, pytest.approx(0.023))
    assert clock.kernel.pending == 0


def test_a_read_period_of_zero_reads_on_arrival_and_a_new_period_reads_a_waiting_frame():
    medium, clock = on_clock(CanBus(), [0, 1])
    medium.request(frame(0, (1,), tag="waits"))
    clock.run(until=0.001)
    assert medium.waiting(1) == 1 and medium.read_period_of(1) is None
    medium.reads_every(1, 0.0)  # on arrival: what waits is read now
    assert medium.waiting(1) == 0 and [d.frame.tag for d in medium.deliveries] == ["waits"]
    medium.request(frame(0, (1,), tag="now"))
    clock.run(until=0.002)
    first, second = medium.transmissions
    assert [(d.arrived, d.read) for d in medium.deliveries] == [(first.end, pytest.approx(0.001)),
                                                                (second.end, second.end)]
    with pytest.raises(BusError):
        medium.reads_every(1, -1.0)


def test_listeners_hear_everything_and_logs_can_be_off():
    """Without logs the medium keeps no lists (a run's bus); listeners still hear each
    start, end, delivery and loss as it happens."""
    medium, clock = on_clock(SerialBus(), [0, 1, 2], logs=False, read_period=0.0)
    heard = []
    medium.on_start(lambda t: heard.append(("start", t.frame.tag)))
    medium.on_end(lambda t: heard.append(("end", t.frame.tag, t.garbled)))
    medium.on_delivery(lambda d: heard.append(("read", d.frame.tag, d.module)))
    medium.on_loss(lambda lost: heard.append((lost.reason.value, lost.frame.tag)))
    medium.on_idle(lambda module: heard.append(("idle", module)))
    medium.request(frame(0, (1,), tag="a"))
    clock.at(50 * BIT_SERIAL, medium.request, frame(2, (1,), tag="b"))
    clock.at(0.01, medium.request, frame(2, (1,), tag="c"))
    clock.run(until=0.02)
    assert heard == [("start", "a"), ("start", "b"), ("collision", "a"), ("collision", "b"),
                     ("end", "a", True), ("end", "b", True), ("idle", 0), ("idle", 1), ("idle", 2),
                     ("start", "c"), ("end", "c", False), ("read", "c", 1), ("idle", 0), ("idle", 1), ("idle", 2)]
    assert medium.transmissions == medium.deliveries == medium.losses == []


def test_zigbee_rssi_is_the_cores_log_distance_model():
    """One log-distance formula: the radio link's RSSI is petriflow.runtime.radio's."""
    from petriflow.runtime.radio import LogDistance

    link = ZigbeeBus(tx_power_dbm=3.0, exponent=2.5).link()
    assert link.path == LogDistance(3.0, 40.0, 2.5, 0.05)
    for distance in (0.01, 0.08, 1.0, 30.0):
        assert link.rssi(distance, walls_db=4.0) == LogDistance(3.0, 40.0, 2.5, 0.05).rssi(distance, 4.0)
