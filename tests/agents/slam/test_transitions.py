"""Every kind of transition of seed 001's nets fired alone, with its real action."""

from __future__ import annotations

import pytest

from petriflow import examples
from petriflow.agents.slam.agent import Base, Beacon, Central, Robot, Wireless, frame
from petriflow.agents.slam.nets import build
from petriflow.io import load_net
from petriflow.testing import fire_one


@pytest.fixture(scope="module")
def net():
    return load_net(examples.path("slam", "slam-decentralised.yaml"))


@pytest.fixture(scope="module")
def central_net():
    return load_net(examples.path("slam", "slam-centralised.yaml"))


def booted(net, world, config, fire, agent="ra1", **beacons):
    fired = fire(net, f"{agent}_boot", {f"{agent}_start": [None]}, world=world, config=config, beacons=beacons)
    assert fired.outcome(f"{agent}_boot") == "ok"
    return fired.state(agent), fired


def place(world, name, x, y):
    world.p.resetBasePositionAndOrientation(world.body(name), (x, y, 0.03), (0, 0, 0, 1),
                                            physicsClientId=world.client)


def test_boot_makes_the_ra_calibrates_its_wheels_and_reports_umbmark(net, world, config, fire):
    state, fired = booted(net, world, config, fire)
    assert isinstance(state, Robot) and state.body.start == (0.0, 0.0) and fired.tokens == {"ra1_ready": [None]}
    (report,) = fired.custom("slam.umbmark")
    before, after = report["passes"][0]["e_max"], report["passes"][-1]["e_max"]
    assert before > 0.8 and after < 0.06
    assert state.hopper == 16 and not state.needs_wa and state.can_move()


def test_the_first_explore_makes_the_start_vertex_and_asks_for_a_wa(net, world, config, fire):
    state, _ = booted(net, world, config, fire)
    fired = fire(net, "ra1_explore", {"ra1_ready": [None]}, states={"ra1": state}, world=world, config=config)
    assert fired.outcome("ra1_explore") == "ok"
    assert fired.result.time == pytest.approx(3.2, abs=1.2)   # it turned round to look behind it
    assert state.history.table() == [(0, 0.0, 0.0, 0, "1")] and state.needs_wa   # open north only, no WA heard


def test_explore_drives_a_leg_to_the_next_vertex(net, world, config, fire):
    """From the start north: the lateral opening towards vertex 28 makes vertex 1 near (0, 5.85)."""
    state, _ = booted(net, world, config, fire)
    fire(net, "ra1_explore", {"ra1_ready": [None]}, states={"ra1": state}, world=world, config=config)
    state.needs_wa = False
    fired = fire(net, "ra1_explore", {"ra1_ready": [None]}, states={"ra1": state}, world=world, config=config)
    (leg,) = fired.custom("slam.leg")
    assert leg["why"] == "lateral" and leg["new"] and leg["vertex"] == 1
    x, y = state.history.rows[1].x, state.history.rows[1].y
    assert abs(x) < 0.1 and abs(y - 5.85) < 0.15 and state.history.rows[1].pending == [0, 1]
    assert fired.result.time == pytest.approx(5.85 / 0.325 + 2.1, rel=0.1)   # turn north again, drive


def test_a_motor_failure_routes_explore_to_broken_and_silences_the_radio(net, world, config, fire):
    failing = build(fail_at=0.0, was=2)
    state, fired = booted(failing, world, config, fire)
    air = fired.scheduler.resources.get("slam.air")
    broken = fire(failing, "ra1_explore", {"ra1_ready": [None]}, states={"ra1": state}, world=world, config=config)
    assert broken.outcome("ra1_explore") == "failed" and broken.tokens == {"ra1_broken": [None]}
    assert state.broken and "ra1" not in broken.scheduler.resources.get("slam.air").beacons
    assert air is not None
    off = fire_one(failing, "ra1_write_off", {"ra1_broken": 1})
    assert off.marking == {"ra1_out": 1}


def test_install_drops_boots_and_programs_the_next_wa(net, world, config, fire):
    state, _ = booted(net, world, config, fire)
    fire(net, "ra1_explore", {"ra1_ready": [None]}, states={"ra1": state}, world=world, config=config)
    fired = fire(net, "ra1_install_1", {"ra1_ready": [None], "ra1_hopper_1": [None]}, states={"ra1": state},
                 world=world, config=config)
    assert fired.outcome("ra1_install_1") == "ok"
    assert fired.result.time == pytest.approx(10 + 5 + 3 + 0.00188, abs=0.1)   # on the 0.1 s ticks
    tokens = fired.tokens
    assert set(tokens) == {"ra1_ready", "ra1_hopper_2", "wa_r1_1_on", "wa_r1_1_listen"}
    programming = tokens["wa_r1_1_on"][0]
    assert programming["ssid"] == "WA_R1_1" and programming["payload"]["rows"][0][:4] == [0, 0.0, 0.0, 0]
    assert world.position("wa_r1_1") == pytest.approx(world.position("ra1"), abs=1e-6)
    assert state.installed == 1 and not state.needs_wa


def test_a_new_wa_boots_from_its_programming_as_a_client(net, world, config, fire):
    place(world, "wa_r1_1", 23.5, 1.5)
    programming = {"ssid": "WA_R1_1", "owner": "ra1", "position": [0, 0],
                   "payload": {"rows": [[0, 0.0, 0.0, 0, [1], {}]], "pending": {}, "links": {}}, "seen": {"ra1": 0.0}}
    fired = fire(net, "wa_r1_1_scan", {"wa_r1_1_on": [programming]}, world=world, config=config)
    wa = fired.state("wa_r1_1")
    assert isinstance(wa, Wireless) and wa.ssid == "WA_R1_1" and len(wa.history) == 1 and wa.role == "client"
    assert fired.tokens == {"wa_r1_1_on": [None]} and fired.result.time == pytest.approx(1.0)


def test_send_puts_the_next_frame_in_the_air(net, world, config, fire):
    place(world, "wa_r1_1", 23.5, 3.0)
    ra = Robot("ra1")
    ra.queue(frame("ra1", "wa_r1_1", "greet"))
    fired = fire(net, "ra1_send", {"ra1_ready": [None], "air_slot": [None]}, states={"ra1": ra}, world=world,
                 config=config)
    assert fired.custom("slam.sent") == [{"to": "wa_r1_1", "frame": "greet", "bytes": 12}] and not ra.outbox
    assert [e.data["fate"] for e in fired.events if e.kind == "message"][0] == "sent"


def test_receive_takes_only_frames_addressed_to_its_agent(net):
    data = frame("wa_r1_1", "ra1", "greet")
    assert fire_one(net, "ra1_receive", tokens={"ra1_listen": [None], "air": [data]}).outcome == "ok"
    from petriflow.errors import PetriflowError

    with pytest.raises(PetriflowError, match="guard false"):
        fire_one(net, "ra2_receive", tokens={"ra2_listen": [None], "air": [data]})


def test_discard_takes_a_frame_nobody_takes(net):
    fired = fire_one(net, "discard", tokens={"air": [frame("wa_r1_1", "gone", "greet")]})
    assert fired.marking == {"air_slot": 1}


def test_the_reading_rule_on_a_loaded_map_sets_the_goal(net, world, config, fire):
    """The hand-over: a reserve RA asks the nearest WA, which holds more nodes, for its array,
    loads it and takes the first pending path of the array (§3.2)."""
    place(world, "wa_r1_1", 23.5, 2.0)
    beacon = Beacon("wa", "WA_R1_1", "ap", {0: 7})
    state, fired = booted(net, world, config, fire, agent="ra2", wa_r1_1=beacon)
    assert state.awaiting == "wa_r1_1" and [f["kind"] for f in state.outbox] == ["pull"]
    assert not state.can_move()
    wa = Wireless("wa_r1_1", "WA_R1_1", "ra1", (0, 0))
    for v, (x, y, last, pending) in enumerate([(0, 0, 0, []), (0, 6, 0, [0]), (0.2, 10, 1, []), (3, 9.7, 2, [3]),
                                               (9, 10, 3, [0]), (9, 19.7, 4, [0]), (9, 21.7, 5, [0, 2])]):
        wa.history.merge({"rows": [[v, x, y, last, pending, {}]]})
    reply = frame("wa_r1_1", "ra2", "data", counts=wa.history.counts(), payload=wa.history.payload({}))
    got = fire(net, "ra2_receive", {"ra2_listen": [None], "air": [reply]}, states={"ra2": state}, world=world,
               config=config, beacons={"wa_r1_1": beacon})
    assert got.custom("slam.reading") == [{"node": "WA_R1_1", "rule": "follow", "path": [1, 0]}]
    assert state.goal == (1, 0) and state.last_read == "WA_R1_1" and state.can_move()
    assert [row[4] for row in state.history.table()] == ["-", "-", "-", "3", "0", "0", "0.2"]


def test_finish_records_the_map_and_tells_the_base(net, world, config, fire):
    state, _ = booted(net, world, config, fire)
    state.history.add((0, 0), None, [])
    state.finished = True
    fired = fire(net, "ra1_finish", {"ra1_ready": [None], "base_box_slot": [None]}, states={"ra1": state},
                 world=world, config=config)
    assert fired.outcome("ra1_finish") == "ok" and fired.custom("slam.finished")[0]["vertices"] == 1
    assert fired.custom("slam.map")[0] == {"vertices": "0,0.000,0.000", "edges": "", "count": 1}


def test_a_wa_raises_an_alert_when_no_one_has_heard_the_ra(net, world, config, fire):
    place(world, "wa_r1_1", 10.0, 10.0)
    place(world, "wa_r1_2", 14.0, 10.0)
    wa = Wireless("wa_r1_1", "WA_R1_1", "ra1", (0, 0), role="ap")
    wa.history.add((0, 0), None, [1])
    wa.seen = {"ra1": -100.0}
    wa.window_end = 100.0
    other = Beacon("wa", "WA_R1_2", "ap", {0: 1}, {"ra1": -90.0})
    fired = fire(net, "wa_r1_1_scan", {"wa_r1_1_on": [None]}, states={"wa_r1_1": wa}, world=world, config=config,
                 beacons={"wa_r1_2": other})
    assert wa.seen == {"ra1": -90.0}   # the neighbour's beacon had newer news
    assert [a["ra"] for a in wa.alerts] == ["ra1"]
    sent = fire(net, "wa_r1_1_alert", {"wa_r1_1_on": [None], "base_box_slot": [None]}, states={"wa_r1_1": wa},
                world=world, config=config)
    assert sent.custom("slam.sent")[0]["to"] == "base" and not wa.alerts
    assert fired.outcome("wa_r1_1_scan") == "ok"


def test_no_alert_while_a_neighbour_still_hears_the_ra(net, world, config, fire):
    place(world, "wa_r1_1", 10.0, 10.0)
    place(world, "wa_r1_2", 14.0, 10.0)
    wa = Wireless("wa_r1_1", "WA_R1_1", "ra1", (0, 0), role="ap")
    wa.history.add((0, 0), None, [1])
    wa.seen = {"ra1": -100.0}
    wa.window_end = 100.0
    other = Beacon("wa", "WA_R1_2", "ap", {0: 1}, {"ra1": 0.5})
    fire(net, "wa_r1_1_scan", {"wa_r1_1_on": [None]}, states={"wa_r1_1": wa}, world=world, config=config,
         beacons={"wa_r1_2": other})
    assert wa.alerts == []


def test_the_base_receives_an_alert_and_dispatches_the_reserve(net):
    alert = frame("wa_r1_3", "base", "alert", ra="ra1", last_heard=400.0)
    from petriflow.runtime.scheduler import Scheduler

    run = Scheduler(net, seed=0)
    run.set_tokens({"base_listen": [None], "base_box": [alert], "base_ready": [None], "ra2_standby": [None]})
    with run:
        run.fire_one("base_receive")
        base = run.firer.agents.state("base")
        assert isinstance(base, Base) and base.missing == ["ra1"]
        result = run.fire_one("base_dispatch_ra2")
    assert base.missing == [] and base.replaced == {"ra1"}
    assert result.marking == {"base_listen": 1, "base_box_slot": 1, "base_ready": 1, "ra2_start": 1}


def test_the_base_stands_the_reserve_down_once_the_map_is_done(net):
    from petriflow.runtime.scheduler import Scheduler

    run = Scheduler(net, seed=0)
    run.set_tokens({"base_listen": [None], "base_box": [frame("ra1", "base", "finished")], "base_ready": [None],
                    "ra2_standby": [None]})
    with run:
        run.fire_one("base_receive")
        result = run.fire_one("base_stand_down_ra2")
    assert result.marking == {"base_listen": 1, "base_box_slot": 1, "base_ready": 1, "ra2_out": 1}


def test_close_and_the_switch_off_chain(net):
    """Every RA out: the chain switches ra1's installed WAs off in order, then passes its
    hopper (the WAs never installed) and goes on to ra2's."""
    closed = fire_one(net, "base_close", {"base_ready": 1, "ra1_out": 1, "ra2_out": 1})
    assert closed.marking == {"ra1_out": 1, "ra2_out": 1, "base_off_ra1_1": 1}
    off = fire_one(net, "wa_r1_1_switch_off", {"base_off_ra1_1": 1, "wa_r1_1_on": 1, "wa_r1_1_listen": 1})
    assert off.marking == {"base_off_ra1_2": 1}
    passed = fire_one(net, "base_pass_ra1_2", {"base_off_ra1_2": 1, "ra1_hopper_2": 1})
    assert passed.marking == {"base_off_ra2_1": 1}
    last = fire_one(net, "base_pass_ra2_1", {"base_off_ra2_1": 1, "ra2_hopper_1": 1})
    assert last.marking == {"base_done": 1}


def test_the_envelope(net):
    begin = fire_one(net, "begin", {"i": 1})
    assert begin.marking == {"ra1_start": 1, "ra1_listen": 1, "ra1_hopper_1": 1, "ra2_standby": 1, "ra2_listen": 1,
                             "ra2_hopper_1": 1, "base_ready": 1, "base_listen": 1, "air_slot": 1,
                             "base_box_slot": 1}
    end = fire_one(net, "end", {"ra1_out": 1, "ra1_listen": 1, "ra2_out": 1, "ra2_listen": 1, "base_done": 1,
                                "base_listen": 1, "air_slot": 1, "base_box_slot": 1})
    assert end.marking == {"o": 1}


def test_the_central_unit_keeps_the_map_and_decides_the_ras_moves(central_net, world, config, fire):
    booted_central = fire(central_net, "central_boot", {"central_start": [None]}, world=world, config=config)
    central = booted_central.state("central")
    assert isinstance(central, Central) and booted_central.custom("slam.nodes") == [{"count": 16}]
    report = frame("ra1", "central", "report", seen={"ra1": 0.0},
                   event={"position": [0.0, 0.0], "heading": 1, "openings": [1], "start": True})
    fired = fire(central_net, "central_receive", {"central_listen": [None], "air": [report]},
                 states={"central": central}, world=world, config=config)
    assert fired.outcome("central_receive") == "ok"
    assert central.history.table() == [(0, 0.0, 0.0, 0, "-")]
    assert central.outbox == [frame("central", "ra1", "decision", decision={"direction": 1})]


def test_the_centralised_ra_reports_and_waits_for_the_decision(central_net, world, config, fire):
    state, _ = booted(central_net, world, config, fire)
    fire(central_net, "ra1_explore", {"ra1_ready": [None]}, states={"ra1": state}, world=world, config=config)
    assert [f["kind"] for f in state.outbox] == ["report"] and not state.can_move()
    decision = frame("central", "ra1", "decision", decision={"direction": 1})
    fire(central_net, "ra1_receive", {"ra1_listen": [None], "air": [decision]}, states={"ra1": state},
         world=world, config=config)
    assert state.can_move()


def test_the_central_unit_fails_and_retires(world, config, fire):
    failing = build("centralised", fail_at=0.5)
    fired = fire(failing, "central_boot", {"central_start": [None]}, world=world, config=config)
    central = fired.state("central")
    served = fire(failing, "central_serve", {"central_ready": [None]}, states={"central": central}, world=world,
                  config=config)
    assert served.outcome("central_serve") == "failed" and served.tokens == {"central_broken": [None]}
    assert fire_one(failing, "central_retire", {"central_broken": 1}).marking == {"central_out": 1}
    central.done = True
    assert fire(failing, "central_done", {"central_ready": [None]}, states={"central": central}, world=world,
                config=config).tokens == {"central_out": [None]}


def test_every_transition_of_the_shipped_nets_is_of_a_kind_fired_alone_here(net, central_net):
    """Each transition, its agent's prefix and its numbers taken off, is one of the kinds
    the tests above fire alone."""
    import re

    tested = {"boot", "explore", "install", "send", "receive", "finish", "write_off", "scan", "alert", "switch_off",
              "dispatch", "stand_down", "close", "pass", "discard", "begin", "end", "serve", "done", "retire"}
    for n in (net, central_net):
        for tid, transition in n.transitions.items():
            local = tid[len(transition.subnet) + 1:] if transition.subnet else tid
            kind = re.sub(r"_(ra\d+.*|\d+)$", "", local)
            assert kind in tested, tid
