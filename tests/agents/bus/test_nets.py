"""Seed 002 as nets: soundness, each transition alone, the algorithms' send rules, the
bus channel's multicast frames and read periods, whole runs and the chain's sensors."""

from __future__ import annotations

import pytest
import yaml

from petriflow import examples
from petriflow.agents.bus.chain import front_is_free
from petriflow.agents.bus.firmware import Module
from petriflow.agents.bus.nets import build, main
from petriflow.analysis import check_net
from petriflow.io import load_net
from petriflow.io.yaml import dumps_net, loads_net
from petriflow.runtime.config import RunConfig
from petriflow.testing import fire_one
from petriflow.world import World

CAN = RunConfig(channels={"bus": {"model": "bus.can", "on_loss": "notify"}}, dt=0.002)


@pytest.mark.parametrize("modules", [2, 3, 4])
@pytest.mark.parametrize("algorithm", [1, 2])
def test_nets_are_sound(modules, algorithm):
    result = check_net(build(modules, algorithm))
    assert result["workflow_net"] and result["sound"], result["violations"]


def test_shipped_nets_are_what_the_builder_writes(tmp_path):
    """``python -m petriflow.agents.bus.nets`` writes the shipped nets: the same net, in
    the same order, with the same run configuration."""
    main(["--out", str(tmp_path)])
    for algorithm in (1, 2):
        name = f"bus-algorithm{algorithm}-3.yaml"
        shipped, written = load_net(examples.path("bus", name)), load_net(tmp_path / name)
        assert dumps_net(written) == dumps_net(shipped) and written.run == shipped.run == "run.yaml"
        assert list(written.places) == list(shipped.places) and list(written.arcs) == list(shipped.arcs)


@pytest.mark.parametrize("algorithm", [1, 2])
def test_a_built_net_reads_back_from_yaml_as_itself(algorithm):
    net = build(4, algorithm)
    again = loads_net(dumps_net(net))
    assert dumps_net(again) == dumps_net(net) and list(again.transitions) == list(net.transitions)
    assert again.initial_marking == net.initial_marking and again.final_marking == net.final_marking


def test_changing_one_transitions_params_leaves_the_others_alone():
    """A sweep may set a nested parameter of one transition: no other transition shares it."""
    net = build(3, 2)
    net.transitions["m1_send"].params["boxes"]["+1"] = "elsewhere"
    net.transitions["m1_boot"].params["chain"].append("m4")
    assert net.transitions["m1_send_overflow"].params["boxes"] == {"+1": "box_m1_m2"}
    assert net.transitions["m2_boot"].params["chain"] == ["m1", "m2", "m3"]


def test_builder_refuses_nonsense():
    for bad in ({"algorithm": 3}, {"modules": 1}, {"messages": 0}):
        with pytest.raises(ValueError):
            build(**{"modules": 3, "algorithm": 1, **bad})


def _boot(net, name, config=CAN, world=None, seed=0):
    fired = fire_one(net, f"{name}_boot", tokens={f"{name}_start": [None]}, config=config, world=world, seed=seed)
    assert fired.outcome == "ok" and 0.0 <= fired.time <= 0.1 + 1e-9  # start-up spread over 0.1 s
    return fired.tokens[f"{name}_loop"][0]


def test_algorithm_1_waits_its_delay_then_sends_one_frame_to_both_neighbours():
    net = build(3, 1)
    module = _boot(net, "m2")
    assert isinstance(module, Module) and module.address == 1 and 0.0 <= module.scheme.delay <= 1.0
    before = module.oscillator.phase
    module.updated = None  # each fire_one starts its own clock at 0: one control step from here
    cpg = fire_one(net, "m2_cpg", tokens={"m2_loop": [module]}, config=CAN)
    assert cpg.time == pytest.approx(0.02) and module.oscillator.phase == pytest.approx(before + 0.5 * 0.02)
    wait = fire_one(net, "m2_wait", tokens={"m2_moved": [module]}, config=CAN)
    assert wait.time == pytest.approx(module.scheme.delay, abs=0.0021)  # to the 2 ms tick
    sent = fire_one(net, "m2_send", config=CAN,
                    tokens={"m2_waited": [module], "slot_m2_m1": [None], "slot_m2_m3": [None]})
    frames = [e.data for e in sent.events if e.kind == "message" and e.data["fate"] == "sent"]
    assert sorted(f["place"] for f in frames) == ["box_m2_m1", "box_m2_m3"] and module.sent == 1
    tokens = [sent.tokens.get(p, [None])[0] for p in ("box_m2_m1", "box_m2_m3")]
    assert all(t is None or t["multicast"] == 1 for t in tokens)  # the same frame, read by both


def test_algorithm_2_sends_to_the_next_address_only_and_the_tail_to_nobody():
    net = build(3, 2)
    head = fire_one(net, "m1_boot", tokens={"m1_start": [None]}, config=CAN).tokens["m1_watch"][0]
    sent = fire_one(net, "m1_send", config=CAN, tokens={"m1_tx": [head], "slot_m1_m2": [None]})
    assert [e.data["place"] for e in sent.events if e.kind == "message"][0] == "box_m1_m2"
    tail = fire_one(net, "m3_boot", tokens={"m3_start": [None]}, config=CAN).tokens["m3_watch"][0]
    gone = fire_one(net, "m3_send", config=CAN, tokens={"m3_tx": [tail], "slot_m3_void": [None]})
    assert [e.data["place"] for e in gone.events if e.kind == "message"][0] == "void_m3"


def test_bus_available_comes_after_a_random_quiet_time_and_overflow_sends_half_the_time():
    net = build(3, 2)
    module = fire_one(net, "m1_boot", tokens={"m1_start": [None]}, config=CAN).tokens["m1_watch"][0]
    available = fire_one(net, "m1_available", tokens={"m1_watch": [module]}, config=CAN)
    assert available.outcome == "ok" and 0.0 < available.time <= 3.0 + 0.003
    draws = []
    for seed in range(40):
        module = fire_one(net, "m1_boot", tokens={"m1_start": [None]}, config=CAN, seed=seed).tokens["m1_timer"][0]
        module.next_overflow = 0.0  # each fire_one starts its own clock at 0: boot ended then
        tick = fire_one(net, "m1_overflow", tokens={"m1_timer": [module]}, config=CAN, seed=seed)
        assert abs(module.rate - 1.0) <= 50e-6  # the crystal's tolerance
        assert module.next_overflow == pytest.approx(module.rate)  # 1 s of the module's clock
        assert tick.time == pytest.approx(module.rate, abs=0.0021)  # to the 2 ms tick
        draws.append(module.send_now)
    assert 10 < sum(draws) < 30


def test_reception_keeps_a_neighbours_phase_and_counts_a_lost_frame():
    net = build(3, 1)
    m2 = _boot(net, "m2")
    from petriflow.agents.bus.packet import Packet, encode

    frame = {"payload": encode(Packet((1,), 0, 1.25, 0.0, 0.5), with_sender=False), "address": 0,
             "sender": "m1", "group": 1}  # what m1_send puts on CAN
    got = fire_one(net, "m2_receive_m1", config=CAN, tokens={"box_m1_m2": [frame], "m2_listen": [m2]})
    assert got.marking["slot_m1_m2"] == 1 and m2.oscillator.heard[0] == pytest.approx(1.25, abs=1e-3)
    read = [e.data["data"] for e in got.events if e.kind == "custom"][0]
    assert read["kept"] and not read["lost"]
    notice = {"lost": True, "why": "collision", "data": {"sender": "m1", "group": 2}}
    lost = fire_one(net, "m2_receive_m1", config=CAN, tokens={"box_m1_m2": [notice], "m2_listen": [m2]})
    assert [e.data["data"] for e in lost.events if e.kind == "custom"][0]["why"] == "collision"


def test_a_middle_modules_message_is_one_frame_read_by_both_neighbours_at_their_reads():
    """Algorithm 1 on CAN with logs: m2's send puts a copy in each neighbour's place but
    ONE frame on the bus, addressed to both; each copy arrives when its module reads
    its buffer (every 20 ms + its delay, from the end of its boot); a neighbour-less
    frame is never on the bus."""
    from petriflow.runtime.scheduler import Scheduler

    config = RunConfig(channels={"bus": {"model": "bus.can", "on_loss": "notify", "logs": True}}, dt=0.002)
    scheduler = Scheduler(build(3, 1, messages=3), config=config, seed=3)
    events = []
    scheduler.on_event(events.append)
    assert scheduler.run(until=60).reason == "final"
    medium = scheduler.channels.models["bus"].state
    carrier = scheduler.channels.models["bus"].carrier
    by_number = {number: agent for agent, number in carrier.numbers.items()}
    frames = [(by_number[t.frame.sender], sorted(by_number[r] for r in t.frame.receivers))
              for t in medium.transmissions]
    assert frames.count(("m2", ["m1", "m3"])) == 3 and len(frames) == 9  # 3 modules × 3 messages: 9 frames
    addressed = {e.agent: e.data["data"]["read_every"] for e in events
                 if e.kind == "custom" and e.data["name"] == "bus.addressed"}
    booted = {e.transition[:2]: e.time for e in events if e.kind == "end" and e.transition.endswith("_boot")}
    for delivery in medium.deliveries:  # every read on the reader's own phase
        reader = by_number[delivery.module]
        k = (delivery.read - booted[reader]) / addressed[reader]
        assert k == pytest.approx(round(k), abs=0.002 / addressed[reader] + 1e-6)


def test_a_module_tells_the_bus_its_read_period_through_its_view():
    """bus.boot asks the bus through ctx.medium: the module reads every step (algorithm 2)."""
    net = build(3, 2)
    from petriflow.runtime.scheduler import Scheduler

    scheduler = Scheduler(net, config=CAN, seed=1)
    scheduler.run(until=0.2)
    bus = scheduler.channels.models["bus"]
    # 20 ms of each module's clock (crystal error within 50 ppm)
    assert bus.view("m2").read_period == pytest.approx(0.02, rel=5e-5)
    assert bus.view("m3").read_period == pytest.approx(0.02, rel=5e-5)
    assert bus.view("m1").read_period == 0.0  # algorithm 2's head receives nothing: the bus's default
    scheduler.close()


def test_whole_runs_end_at_the_final_marking_with_every_message_counted(tmp_path):
    from petriflow.agents.bus import metrics
    from petriflow.runtime.metrics import RunRecord
    from petriflow.runtime.scheduler import Scheduler

    for algorithm in (1, 2):
        events = []
        scheduler = Scheduler(build(3, algorithm, messages=8), config=CAN, seed=2)
        scheduler.on_event(events.append)
        result = scheduler.run(until=300)
        assert result.reason == "final"
        record = RunRecord(result, events)
        sent = [e for e in events if e.kind == "custom" and e.data["name"] == "bus.sent"]
        assert len(sent) == 24
        assert 0.0 <= metrics.lost_pct(record) <= 100.0 and metrics.phase_error_rad(record) is not None


def test_the_chain_addresses_itself_with_its_front_sensors():
    world = World(yaml.safe_load(examples.path("bus", "world-3.yaml").read_text()), base=examples.path("bus", "."))
    try:
        assert [front_is_free(world, f"m{k}") for k in (1, 2, 3)] == [True, False, False]
        net = load_net(examples.path("bus", "bus-algorithm2-3.yaml"))
        module = fire_one(net, "m3_boot", tokens={"m3_start": [None]}, config=CAN, world=world).tokens["m3_loop"][0]
        assert module.address == 2 and module.joint is not None
    finally:
        world.close()
