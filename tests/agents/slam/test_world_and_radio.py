"""The environment rebuilt from Table 6, the world file, the ESP8266 link, the paper's speed."""

from __future__ import annotations

import math

import pytest

from petriflow import examples
from petriflow.agents.slam import fig6
from petriflow.agents.slam.corridors import fig6_world, free_space, to_map, to_world
from petriflow.agents.slam.history import direction_between
from petriflow.agents.slam.radio import ESP8266
from petriflow.runtime.channels import Message
from petriflow.world import load_world


def test_the_corridors_are_the_tree_plus_ten_loops_with_their_reasons():
    edges, why = fig6.derive_corridors()
    assert len(edges) == 45
    tree = {(min(v, last), max(v, last)) for v, (_, _, last) in fig6.TABLE6.items() if v}
    assert len(tree) == 35 and tree <= edges
    assert sorted((rule, min(a, b), max(a, b)) for rule, a, b in why) == [
        ("opening", 13, 29), ("opening", 15, 31), ("opening", 16, 32), ("opening", 20, 25), ("opening", 22, 25),
        ("opening", 22, 34), ("opening", 26, 34), ("table8", 1, 28), ("table8", 3, 28), ("table8", 4, 35)]


def test_every_vertex_is_one_algorithm1_would_make():
    """No vertex of the graph is crossed straight by two corridors (it would be invisible)."""
    graph = fig6.corridor_graph()
    for v in graph.nodes:
        sides = {direction_between(graph.nodes[v]["pos"], graph.nodes[u]["pos"]) for u in graph[v]}
        assert len(sides) == graph.degree(v), v   # no two corridors leave one way
        assert not (len(sides) == 2 and sides in ({0, 2}, {1, 3})), v


def test_corridors_meet_only_at_vertices():
    """Two corridors cross only at a vertex: else the RA would see a junction the map lacks."""
    graph = fig6.corridor_graph()
    pos = {v: graph.nodes[v]["pos"] for v in graph.nodes}
    segments = [(a, b) for a, b in graph.edges]
    for i, (a, b) in enumerate(segments):
        for c, d in segments[i + 1:]:
            if {a, b} & {c, d}:
                continue
            horizontal = direction_between(pos[a], pos[b]) in (0, 2)
            other = direction_between(pos[c], pos[d]) in (0, 2)
            if horizontal == other:
                continue
            h, v = ((a, b), (c, d)) if horizontal else ((c, d), (a, b))
            y, x = pos[h[0]][1], pos[v[0]][0]
            inside_h = min(pos[h[0]][0], pos[h[1]][0]) < x < max(pos[h[0]][0], pos[h[1]][0])
            inside_v = min(pos[v[0]][1], pos[v[1]][1]) < y < max(pos[v[0]][1], pos[v[1]][1])
            assert not (inside_h and inside_v), (a, b, c, d)


def test_the_papers_positions_scatter_about_the_corridor_lines():
    scatter = fig6.paper_scatter()
    assert 0.05 < scatter < 0.3


def test_the_speed_comes_from_the_papers_own_distances_and_times():
    """15 m/s would be 15 km in experiment 2's 16:43: the route Table 6 implies over 1003 s
    is about a third of a metre a second."""
    assert fig6.paper_route_length() == pytest.approx(326.25, abs=0.01)
    assert fig6.derived_speed() == pytest.approx(0.325, abs=0.001)
    assert 15.0 * fig6.TIMES["centralised"] > 40 * fig6.paper_route_length()


def test_the_shipped_world_is_the_generated_one():
    shipped = load_world(examples.path("slam", "world.yaml"))
    try:
        built = fig6_world()
        assert shipped.meta == built["meta"]
        assert len(shipped.bodies) == 1 + len(built["boxes"]) + len(built["robots"])
        x, y = shipped.position("ra1")
        assert to_map((x, y), tuple(shipped.meta["slam"]["origin"])) == (0.0, 0.0)
    finally:
        shipped.close()


def test_the_start_is_a_dead_end_facing_north_and_every_vertex_is_free():
    meta = fig6_world()["meta"]["slam"]
    origin = tuple(meta["origin"])
    vertices = {int(v): tuple(p) for v, p in meta["vertices"].items()}
    free = free_space(vertices, meta["edges"], origin, (25.0, 25.0))
    for v, p in vertices.items():
        x, y = to_world(p, origin)
        assert free[int(y / 0.05), int(x / 0.05)], v
    x, y = to_world((0.0, 0.0), origin)
    assert (x, y) == (23.5, 1.5) and not free[int((y - 1.0) / 0.05), int(x / 0.05)]


def test_the_esp8266_link_budget_of_fig5():
    radio = ESP8266()
    assert radio.rssi(5.0) == pytest.approx(-64.0, abs=1e-6) and radio.range() == pytest.approx(5.0)
    assert radio.rssi(1.0) == pytest.approx(-50.0, abs=0.05)   # Fig. 5b's -50 dB
    assert radio.loss(-60) == 0 and 0 < radio.loss(-66) < 1 and radio.loss(-75) == 1
    assert radio.latency(1024) == pytest.approx(0.00188) and radio.latency(1025) == pytest.approx(0.00376)


class _Place:
    def __init__(self, positions):
        self.positions = positions
        self.meta = {"slam": {"nodes": [[0.0, 0.0], [20.0, 0.0]]}}
        self.path = None  # a world described in code (capabilities.Described)

    def position(self, name):
        return self.positions.get(name)

    def distance(self, a, b):  # with position: what capabilities.Positions names
        return math.dist(self.positions[a], self.positions[b])


def test_the_channel_delivers_near_loses_far_and_reaches_the_central_unit_by_the_nodes():
    import random

    radio = ESP8266()
    radio.bind(_Place({"a": (0.0, 0.0), "b": (3.0, 0.0), "c": (30.0, 0.0), "ra1": (21.0, 0.0)}))
    rng = random.Random(1)
    near = Message("air", None, None, {"from": "a", "to": "b"}, 0.0, 100)
    far = Message("air", None, None, {"from": "a", "to": "c"}, 0.0, 100)
    central = Message("air", None, None, {"from": "ra1", "to": "central"}, 0.0, 100)
    assert radio.deliver(near, rng) == pytest.approx(0.00188)
    assert radio.deliver(far, rng) is None and "out of reach" in radio.loss_reason
    assert radio.deliver(central, rng) == pytest.approx(0.00188 + 0.010)
    radio.fade_db = 0.0
    assert radio.loss(-64.5) == 1.0 and math.isclose(radio.loss(-63.9), 0.0)
