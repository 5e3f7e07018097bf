"""Algorithm 2: the exchange between two WAs (Tables 4 and 5), roles, and the arrays' merge."""

from __future__ import annotations

import pytest

from petriflow import examples
from petriflow.agents.slam.agent import Wireless
from petriflow.agents.slam.history import BLOCK, History, exchange_role
from petriflow.io import load_net

#: Table 4: the arrays of WA_R1_1 (access point, 4 nodes) and WA_R1_2 (client, 6 nodes).
TABLE4 = [(0, 0, 0, 0), (1, 0, 1, 1), (2, 1, 3, 2), (3, 2, 3, 3), (4, 2, 5, 3), (5, 3, 5, 4)]


def array(rows):
    h = History(block=-1)
    for vid, x, y, last in rows:
        h.merge({"rows": [[vid, x, y, last, [], {}]]})
    return h


def place(world, name, x, y):
    world.p.resetBasePositionAndOrientation(world.body(name), (x, y, 0.03), (0, 0, 0, 1),
                                            physicsClientId=world.client)


def test_the_holder_of_more_nodes_sends_the_difference():
    ap, client = array(TABLE4[:4]), array(TABLE4)
    assert exchange_role(client.counts(), ap.counts()) == "send"
    assert exchange_role(ap.counts(), client.counts()) == "pull"
    assert [v.id for v in client.missing_for(ap.counts())] == [4, 5]
    ap.merge(client.payload(ap.counts()))
    assert ap.table() == client.table()


@pytest.fixture
def net():
    return load_net(examples.path("slam", "slam-decentralised.yaml"))


def test_tables_4_and_5_two_was_exchange_and_swap_roles(net, world, config, fire):
    """WA_R1_2 (client, 6 nodes) finds WA_R1_1 (access point, 4 nodes) 2 m away, sends
    it the 2 nodes it lacks; afterwards both hold the 6 nodes, WA_R1_2 is the access
    point and WA_R1_1 the client (Table 5)."""
    place(world, "wa_r1_1", 10.0, 10.0)
    place(world, "wa_r1_2", 12.0, 10.0)
    one = Wireless("wa_r1_1", "WA_R1_1", "ra1", (0, 0), role="ap")
    two = Wireless("wa_r1_2", "WA_R1_2", "ra1", (2, 0), role="client")
    one.history, two.history = array(TABLE4[:4]), array(TABLE4)
    beacons = {"wa_r1_1": one.beacon(), "wa_r1_2": two.beacon()}
    states = {"wa_r1_1": one, "wa_r1_2": two}
    fired = fire(net, "wa_r1_2_scan", {"wa_r1_2_on": [None]}, states=states, world=world, config=config,
                 beacons=beacons)
    assert fired.outcome("wa_r1_2_scan") == "ok" and two.role == "ap"
    assert [f["kind"] for f in two.outbox] == ["data"] and [r[0] for r in two.outbox[0]["payload"]["rows"]] == [4, 5]
    frame = dict(two.outbox[0])
    sent = fire(net, "wa_r1_2_send", {"wa_r1_2_on": [None], "air_slot": [None]}, states=states, world=world,
                config=config)
    assert sent.custom("slam.sent") == [{"to": "wa_r1_1", "frame": "data", "bytes": frame["size"]}]
    assert frame["from"] == "wa_r1_2" and not two.outbox
    got = fire(net, "wa_r1_1_receive", {"wa_r1_1_listen": [None], "air": [frame]}, states=states, world=world,
               config=config)
    assert got.outcome("wa_r1_1_receive") == "ok" and got.tokens == {"wa_r1_1_listen": [None], "air_slot": [None]}
    assert one.history.table() == two.history.table() and len(one.history) == 6
    assert one.role == "client"


def test_a_client_that_finds_no_access_point_becomes_one_after_five_seconds(net, world, config, fire):
    place(world, "wa_r1_1", 10.0, 10.0)
    wa = Wireless("wa_r1_1", "WA_R1_1", "ra1", (0, 0), role="client")
    wa.window_end = 5.0
    states = {"wa_r1_1": wa}
    fire(net, "wa_r1_1_scan", {"wa_r1_1_on": [None]}, states=states, world=world, config=config)
    assert wa.role == "client"   # 1 s: still looking
    for _ in range(4):
        fire(net, "wa_r1_1_scan", {"wa_r1_1_on": [None]}, states=states, world=world, config=config)
    # every call starts a new run at time 0; the window is measured from the run's clock
    wa.window_end = 0.5
    fire(net, "wa_r1_1_scan", {"wa_r1_1_on": [None]}, states=states, world=world, config=config)
    assert wa.role == "ap"


def test_the_nearest_node_by_rssi_is_the_one_a_client_connects_to(net, world, config, fire):
    place(world, "wa_r1_1", 10.0, 10.0)
    place(world, "wa_r1_2", 13.0, 10.0)
    place(world, "wa_r1_3", 11.0, 10.0)
    me = Wireless("wa_r1_1", "WA_R1_1", "ra1", (0, 0), role="client")
    far = Wireless("wa_r1_2", "WA_R1_2", "ra1", (3, 0), role="ap")
    near = Wireless("wa_r1_3", "WA_R1_3", "ra1", (1, 0), role="ap")
    for other in (far, near):
        other.history.add((0, 0), None, [1])
    beacons = {w.name: w.beacon() for w in (me, far, near)}
    fire(net, "wa_r1_1_scan", {"wa_r1_1_on": [None]}, states={"wa_r1_1": me}, world=world, config=config,
         beacons=beacons)
    assert me.outbox[0]["to"] == "wa_r1_3" and me.outbox[0]["kind"] == "pull"


def test_a_client_whose_nearest_access_point_holds_the_same_nodes_exchanges_nothing(net, world, config, fire):
    """Algorithm 2 moves data only from the holder of more nodes: equal holders send nothing."""
    place(world, "wa_r1_1", 10.0, 10.0)
    place(world, "wa_r1_3", 11.0, 10.0)
    me = Wireless("wa_r1_1", "WA_R1_1", "ra1", (0, 0), role="client")
    near = Wireless("wa_r1_3", "WA_R1_3", "ra1", (1, 0), role="ap")
    me.window_end = 10.0
    fire(net, "wa_r1_1_scan", {"wa_r1_1_on": [None]}, states={"wa_r1_1": me}, world=world, config=config,
         beacons={w.name: w.beacon() for w in (me, near)})
    assert me.outbox == [] and me.role == "client"


def test_two_ras_arrays_merge_by_block_and_a_place_both_found_is_one_vertex():
    """RAs number their vertices in blocks of 1000; each block is a prefix, so counts per
    block say what is missing; a vertex two RAs found at one place is kept once."""
    a, b = History(block=0), History(block=1)
    a.add((0, 0), None, [1])
    a.add((0, 6), 0, [0, 1])
    b.add((10, 0), None, [1])
    b.add((0.2, 6.1), BLOCK, [1, 3])   # the place of a's vertex 1
    assert a.counts() == {0: 2} and b.counts() == {1: 2}
    assert exchange_role(a.counts(), b.counts()) == "send"   # equal totals: the one with what the other lacks
    a.merge(b.payload(a.counts()))
    assert len(a) == 4 and len(a.vertices()) == 3 and a.alias == {BLOCK + 1: 1}
    assert a.rows[1].pending == [1]   # a path the other RA did not have pending is taken
