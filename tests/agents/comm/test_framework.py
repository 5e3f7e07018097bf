"""Seed 000's processes 1, 3, 4 and 5 against the paper's numbers and worked example."""

from __future__ import annotations

import math

import pytest

from petriflow.agents.comm.framework import (History, Packet, addresses, decode_vertex, dhcp_pools, dpp,
                                             encode_vertex, grid_position, grid_size, plan)


def test_process_1_distance_per_pulse_and_the_odometry_grid():
    step = dpp(0.025, 200)
    assert math.floor(step * 1e7) / 1e4 == 0.7853  # the paper's dpp, truncated as it prints it
    paper = 0.0007853
    assert grid_position((0.25, 0.25), paper) == (318, 318)
    assert grid_position((4.75, 4.75), paper) == (6048, 6048)
    assert grid_position((0.25, 4.75), paper) == (318, 6048)
    assert grid_size((5.0, 5.0), [paper, 0.0005]) == (6366, 6366)  # the largest dpp sets the grid
    with pytest.raises(ValueError):
        dpp(0.0, 200)


def test_process_3_addresses_and_pools_as_the_paper_assigns_them():
    assert addresses(2) == [2, 128]
    assert dhcp_pools(2) == [(3, 127), (129, 254)]
    assert addresses(3) == [2, 85, 170]
    assert dhcp_pools(3) == [(3, 84), (86, 169), (171, 254)]
    with pytest.raises(ValueError, match="at least one"):
        addresses(0)
    with pytest.raises(ValueError, match="no DHCP pool"):
        addresses(200)


def transfer(a: History, b: History) -> None:
    """One transfer between two agents: each sends the other what the rules say."""
    for sender, receiver in ((a, b), (b, a)):
        for source, items, _ in sender.outgoing(receiver.me):
            receiver.receive(sender.me, source, items)
            sender.sent(receiver.me, source, items)


def table(history: History) -> tuple[list, list]:
    return [(s, i) for s, i, _ in history.data], sorted(tuple(r) for r in history.rows)


def test_process_4_reproduces_tables_2_to_5():
    ro1, ro2, ro3 = History(1), History(2), History(3)
    for item in ("x0", "x1", "x2"):
        ro1.add_own(item)
    for item in ("y0", "y1"):
        ro2.add_own(item)
    for item in ("z0", "z1", "z2", "z3"):
        ro3.add_own(item)
    assert ro1.rows == ro2.rows == ro3.rows == []                      # Table 2
    transfer(ro1, ro2)                                                  # Table 3 (rule 1)
    assert table(ro1)[1] == [(1, 2, 3, 0), (2, 1, 2, 0)]
    assert table(ro2)[1] == [(1, 2, 3, 0), (2, 1, 2, 0)]
    transfer(ro2, ro3)                                                  # Table 4 (rules 1 and 2)
    assert table(ro2) == ([(2, "y0"), (2, "y1"), (1, "x0"), (1, "x1"), (1, "x2"),
                           (3, "z0"), (3, "z1"), (3, "z2"), (3, "z3")],
                          [(1, 2, 3, 0), (1, 3, 3, 0), (2, 1, 2, 0), (2, 3, 2, 0), (3, 2, 4, 0)])
    assert table(ro3) == ([(3, "z0"), (3, "z1"), (3, "z2"), (3, "z3"), (2, "y0"), (2, "y1"),
                           (1, "x0"), (1, "x1"), (1, "x2")],
                          [(1, 3, 3, 0), (2, 3, 2, 0), (3, 2, 4, 0)])
    transfer(ro2, ro1)                                                  # Table 5: Ro2 passes on Ro3's data
    assert table(ro2)[1] == [(1, 2, 3, 0), (1, 3, 3, 0), (2, 1, 2, 0), (2, 3, 2, 0), (3, 1, 4, 0), (3, 2, 4, 0)]
    assert table(ro1) == ([(1, "x0"), (1, "x1"), (1, "x2"), (2, "y0"), (2, "y1"),
                           (3, "z0"), (3, "z1"), (3, "z2"), (3, "z3")],
                          [(1, 2, 3, 0), (2, 1, 2, 0), (3, 1, 4, 0)])


def test_rule_3_new_data_becomes_pending_and_goes_by_request():
    ro1, ro2 = History(1), History(2)
    ro1.add_own("x0")
    transfer(ro1, ro2)
    assert ro1.outgoing(2) == []                   # nothing new: nothing to send, nothing echoed back
    assert ro2.outgoing(1) == []
    ro1.add_own("x1")
    assert ro1.pending(2, 1) == 1
    assert ro1.outgoing(2) == [(1, ["x1"], "pending")]
    assert [m.code for m in plan(ro1, 2)] == [0]   # Algorithm 1: a query first
    assert [(m.code, m.count, len(m.vertices)) for m in plan(ro1, 3)] == [(3, 2, 2)]  # never sent to 3: at once


def test_process_5_header_and_vertex_bytes():
    vertex = (7, 1.25, 4.75)
    assert decode_vertex(encode_vertex(*vertex)) == vertex
    message = Packet(2, 85, 2, 2, 85, [vertex, (9, 0.5, 0.5)], final=True)
    data = message.encode()
    assert len(data) == message.size == 3 + 2 * 5 and message.payload == 10
    assert data[0] == 0x82 and data[1] == 85 and data[2] == 2
    with pytest.raises(ValueError):
        encode_vertex(300, 0.0, 0.0)
