"""The paper's sniffer, ZigBee as a network (broadcast transaction table, relaying with
passive acknowledgement, end devices polling their parent), modules that power up in
step, and the two reception models."""

from __future__ import annotations

import pytest

from petriflow import run
from petriflow.agents.bus import metrics
from petriflow.agents.bus import BusSimulator, CanBus, Frame, Loss, SerialBus, ZigbeeBus
from petriflow.agents.bus.nets import build


def frame(sender, receivers=(1,), data=bytes(8), tag=None):
    return Frame(sender, tuple(receivers), data, 0x100 + sender, tag)


# The sniffer -------------------------------------------------------------------------

def test_the_sniffer_counts_intact_frames_per_sender_whoever_they_are_for():
    """On RS-485 two overlapping frames are garbled for the sniffer too; a lone frame
    for an address nobody holds is captured."""
    sim = BusSimulator(SerialBus(), modules=[0, 1, 2], seed=1)
    sim.medium.sniff(3)
    sim.send(0.0, frame(0, (1,)))
    sim.send(0.0003, frame(1, (2,)))      # overlaps the first: both garbled
    sim.send(0.01, frame(2, (7,)))        # for nobody: crosses the bus intact
    sim.send(0.02, frame(0, (1,)))
    medium = sim.run()
    assert medium.captured == {3: {2: 1, 0: 1}}
    assert 3 not in sim.received or sim.received[3] == []  # the sniffer is no addressee


def test_a_can_sniffer_sees_every_frame_that_arbitration_serialised():
    sim = BusSimulator(CanBus(), modules=[0, 1, 2], seed=1)
    sim.medium.sniff(3)
    for sender in range(3):
        sim.send(0.0, frame(sender, ((sender + 1) % 3,)))
    medium = sim.run()
    assert medium.captured[3] == {0: 1, 1: 1, 2: 1}
    assert not [loss for loss in medium.losses if loss.reason is Loss.COLLISION]


# ZigBee as a network -------------------------------------------------------------------

def test_a_broadcast_is_relayed_once_by_every_router_and_the_passive_acks_stop_retries():
    """3 modules and the sniffer, all routers in range: the originator's frame and one
    relay from each of the 3 others; each hears everyone relay, so nobody retransmits."""
    sim = BusSimulator(ZigbeeBus(), modules=[0, 1, 2], seed=2)
    sim.medium.sniff(3)
    for module in range(3):
        sim.reads_every(module, 0.0)
    sim.send(0.0, frame(0, (1,)))
    medium = sim.run()
    assert len(medium.transmissions) == 4 and not medium.losses
    assert [medium.role(n) for n in range(4)] == ["coordinator", "router", "router", "router"]
    assert len(sim.received[1]) == 1 and medium.captured[3] == {0: 1}
    relays = medium.transmissions[1:]
    assert all(t.start - medium.transmissions[0].end <= 0.063 + 0.01 for t in relays)  # jitter <= 63 ms


def test_the_broadcast_transaction_table_overflows_and_its_entries_expire():
    """8 entries of 8 s each: the 9th and 10th broadcasts within 8 s are dropped by the
    originator's full table (lost for everyone); 8 s after the first, there is room."""
    bus = ZigbeeBus()
    sim = BusSimulator(bus, modules=[0, 1, 2], seed=3)
    for module in range(3):
        sim.reads_every(module, 0.0)
    for k in range(10):
        sim.send(0.1 * k, frame(0, (1,), tag=k))
    sim.send(8.5, frame(0, (1,), tag="late"))
    medium = sim.run(until=2.0)
    assert medium.btt_size(0) == 8 and medium.btt_size(1) == 8
    full = [loss for loss in medium.losses if loss.reason is Loss.BTT_FULL]
    assert sorted(loss.frame.tag for loss in full) == [8, 9] and all(loss.module is None for loss in full)
    medium = sim.run()
    assert [f.tag for f in sim.received[1]] == [*range(8), "late"]


def test_a_relay_whose_table_is_full_drops_the_broadcast_for_its_module():
    """A router that already holds 8 other broadcasts neither delivers nor relays a
    new one: its module loses it, the others get it."""
    sim = BusSimulator(ZigbeeBus(), modules=[0, 1, 2], seed=4)
    for module in range(3):
        sim.reads_every(module, 0.0)
    for k in range(8):
        sim.send(0.05 * k, frame(2, (1,), tag=k))   # fills every table with module 2's broadcasts
    medium = sim.run(until=1.5)
    medium.table(0).clear()                        # module 0's radio restarts: an empty table
    sim.send(1.6, frame(0, (1, 2), tag="new"))
    medium = sim.run()
    lost = [(loss.module, loss.reason) for loss in medium.losses if loss.frame.tag == "new"]
    assert lost == [(1, Loss.BTT_FULL), (2, Loss.BTT_FULL)]


def test_end_devices_get_a_broadcast_when_they_poll_and_the_parent_keeps_only_one():
    """Modules 1 and 2 are end devices of the coordinator (module 0): a broadcast reaches
    them at their next poll (100 ms apart); a second broadcast before they polled
    replaces the first in the parent's one-broadcast buffer."""
    bus = ZigbeeBus(roles="end_devices")
    sim = BusSimulator(bus, modules=[0, 1, 2], seed=5)
    for module in range(3):
        sim.reads_every(module, 0.0)
    sim.send(0.0, frame(0, (1,), tag="first"))
    sim.send(0.0005, frame(0, (1,), tag="second"))  # on the air before anyone polls
    medium = sim.run()
    assert [medium.role(n) for n in range(3)] == ["coordinator", "end_device", "end_device"]
    lost = {(loss.frame.tag, loss.module): loss.reason for loss in medium.losses}
    assert lost == {("first", 1): Loss.PARENT_BUFFER, ("first", 2): Loss.PARENT_BUFFER}
    assert [f.tag for f in sim.received[1]] == ["second"]
    delivery = medium.deliveries[-1]
    assert 0.0 < delivery.arrived <= 0.1 + 0.01  # within one poll period of the buffering


def test_an_end_device_sends_through_its_parent():
    bus = ZigbeeBus(roles="end_devices")
    sim = BusSimulator(bus, modules=[0, 1, 2], seed=6)
    for module in range(3):
        sim.reads_every(module, 0.0)
    sim.send(0.0, frame(1, (0, 2), tag="up"))
    medium = sim.run()
    assert [t.frame.tag for t in medium.transmissions][:2] == ["up", "up"]  # to the parent, then its broadcast
    assert [f.tag for f in sim.received[0]] == ["up"] and [f.tag for f in sim.received[2]] == ["up"]


# Whole runs: power-up in step, reception models, the sniffer's count ------------------------

def _run(bus, algorithm, seed=1, **boot):
    net = build(3, algorithm, messages=20)
    for k in (1, 2, 3):
        net.transitions[f"m{k}_boot"].params.update(boot)
    config = {"channels": {"bus": {"model": f"bus.{bus}", "on_loss": "notify"}}, "dt": 0.002, "until": 300}
    outcome = run(net, config=config, seed=seed, keep_events=True)
    assert outcome.result.reason == "final"
    return outcome


def _custom(record, name):
    return [e for e in record.events if e.kind == "custom" and e.data.get("name") == name]


def test_modules_power_up_in_step_with_crystal_clocks():
    """Default start-up spread 1 ms, clocks within 50 ppm; a 0.1 s spread when asked."""
    for spread, width in ((None, 0.001), (0.1, 0.1)):
        boot = {} if spread is None else {"spread": spread}
        record = _run("can", 2, **boot)
        addressed = [e.data["data"] for e in _custom(record, "bus.addressed")]
        started = [a["started"] for a in addressed]
        assert len(started) == 3 and max(started) - min(started) <= width
        assert all(abs(a["rate"] - 1.0) <= 50e-6 for a in addressed)
        if spread is None:
            assert max(started) <= 0.001


def test_the_reception_models_read_on_the_loop_or_on_arrival():
    """Algorithm 1 reading once per loop loses messages to overwritten buffers; reading
    on arrival (the reception interrupt) overwrites nothing."""
    loop = _run("can", 1, seed=2)
    interrupt = _run("can", 1, seed=2, reception="interrupt")
    assert [e.data["data"]["read_every"] for e in _custom(interrupt, "bus.addressed")] == [0.0] * 3
    assert all(e.data["data"]["read_every"] > 0.02 for e in _custom(loop, "bus.addressed"))
    assert metrics.lost_by_reason(loop).get("overwritten", 0) > 0
    assert metrics.lost_by_reason(interrupt).get("overwritten", 0) == 0


def test_the_sniffer_counts_where_the_paper_counts():
    """Algorithm 2 on CAN: arbitration loses no frame, so the sniffer captures all of
    every module's messages (module 3's, for an address nobody holds, too), whatever
    the addressees' buffers lost; on SERIAL in step, collisions cost the sniffer's count."""
    record = _run("can", 2)
    [sniffed] = _custom(record, "bus.sniffed")
    assert sniffed.data["data"]["captured"] == {"m1": 20, "m2": 20, "m3": 20}
    assert [metrics.sniffer_lost_pct_module(record, m) for m in (1, 2, 3)] == [0.0, 0.0, 0.0]
    serial = _run("serial", 2, seed=2)
    collisions = metrics.lost_by_reason(serial).get("collision", 0)
    assert collisions > 0 and metrics.sniffer_lost_pct(serial) > 0.0


def test_an_end_devices_frame_goes_no_further_than_a_parent_with_a_full_table():
    sim = BusSimulator(ZigbeeBus(roles="end_devices"), modules=[0, 1, 2], seed=7)
    for module in range(3):
        sim.reads_every(module, 0.0)
    for k in range(8):
        sim.send(0.05 * k, frame(0, (1,), tag=k))   # the coordinator's table fills
    sim.send(1.0, frame(1, (0, 2), tag="up"))
    medium = sim.run()
    lost = sorted((loss.module, loss.reason.value) for loss in medium.losses if loss.frame.tag == "up")
    assert lost == [(0, "btt_full"), (2, "btt_full")]


# Unicast addressing and the bus's cost per loop iteration -----------------------------------

def test_unicast_reaches_only_its_addressee_and_leaves_no_table_entry():
    """Each device has its own address: a frame for module 1 is not handed to module 2
    (its one-frame buffer keeps its own frame), nobody relays it, no table records it;
    the sniffer overhears it."""
    sim = BusSimulator(ZigbeeBus(addressing="unicast"), modules=[0, 1, 2], seed=3)
    sim.medium.sniff(3)
    sim.send(0.0, frame(0, (1,), tag="to 1"))
    sim.send(0.05, frame(1, (0, 2), tag="to 0 and 2"))
    medium = sim.run()
    assert [t.frame.tag for t in medium.transmissions] == ["to 1", "to 0 and 2", "to 0 and 2"]
    assert medium.losses == [] and [medium.btt_size(n) for n in range(3)] == [0, 0, 0]
    assert medium.captured == {3: {0: 1, 1: 1}}  # a frame once, however many unicasts carry it
    broadcast = BusSimulator(ZigbeeBus(), modules=[0, 1, 2], seed=3)
    broadcast.send(0.0, frame(0, (1,), tag="to 1"))
    assert len(broadcast.run().transmissions) == 3  # the default: a broadcast every router relays


def test_unicast_to_an_end_device_waits_at_its_parent_and_a_frame_for_nobody_is_retried():
    sim = BusSimulator(ZigbeeBus(addressing="unicast", roles="end_devices"), modules=[0, 1, 2], seed=4)
    for module in range(3):
        sim.reads_every(module, 0.0)
    sim.send(0.0, frame(1, (2,), tag="1 to 2"))
    medium = sim.run()
    assert [t.frame.tag for t in medium.transmissions] == ["1 to 2"]  # up to the parent; 2 polls it
    assert [f.tag for f in sim.received[2]] == ["1 to 2"] and sim.received.get(0, []) == []
    nobody = BusSimulator(ZigbeeBus(addressing="unicast", mac_retries=2), modules=[0, 1], seed=4)
    nobody.send(0.0, frame(1, (), tag="nobody"))
    assert len(nobody.run().transmissions) == 3  # never acknowledged: sent 1 + mac_retries times


def test_a_bad_addressing_is_refused():
    with pytest.raises(Exception, match="addressing is 'broadcast' or 'unicast'"):
        ZigbeeBus(addressing="multicast")


def test_the_bus_loop_cost_slows_every_iteration_of_the_cpg_loop():
    """loop_cost adds to each loop iteration of a module that reads the bus (the chain's
    head reads no mailbox: nobody addresses it): it reads its buffer half as often with
    a cost of one 20 ms step, so its loop runs fewer iterations in the run."""
    def run_with(cost):
        net = build(3, 2, messages=20)
        config = {"channels": {"bus": {"model": "bus.can", "on_loss": "notify", "loop_cost": cost}},
                  "dt": 0.002, "until": 300}
        return run(net, config=config, seed=1, keep_events=True)

    fast, slow = run_with(0.0), run_with(0.02)
    reads = {e.data["agent"] if "agent" in e.data else k: (f.data["data"]["read_every"], e.data["data"]["read_every"])
             for k, (f, e) in enumerate(zip(_custom(fast, "bus.addressed"), _custom(slow, "bus.addressed")))}
    doubled = [after == pytest.approx(2 * before, rel=1e-3) for before, after in reads.values()]
    assert sorted(doubled) == [False, True, True]
    assert slow.result.reason == "final" and slow.result.firings < fast.result.firings
