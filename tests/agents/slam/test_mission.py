"""Seed 001's missions end to end: the WA installation rule, experiment 1, the alert and
the hand-over of experiment 3, the centralised system's failure, the map's quality."""

from __future__ import annotations

import math
import time

import pytest

from petriflow import examples
from petriflow.agents.slam import metrics
from petriflow.agents.slam.corridors import to_world
from petriflow.agents.slam.nets import build
from petriflow.agents.slam.radio import ESP8266
from petriflow.runtime.config import load_config
from petriflow.runtime.metrics import RunRecord
from petriflow.runtime.session import run
from petriflow.world import load_world


def mission(net, *, until=None, seed=1):
    """Run ``net`` on the shipped world: ``(record, wall seconds)``; the world stays open in the record."""
    world = load_world(examples.path("slam", "world.yaml"))
    config = load_config(examples.path("slam", "run.yaml"))
    started = time.perf_counter()
    outcome = run(net, world=world, config=config, seed=seed, until=until, keep_events=True)
    return RunRecord(outcome.result, outcome.events, world, config), time.perf_counter() - started


def custom(record, name):
    return [e for e in record.events if e.kind == "custom" and e.data.get("name") == name]


def test_a_wa_goes_in_only_where_the_ra_hears_none_within_5_m():
    """The first WA at the start; each later one where no installed WA was within the
    ESP8266's loss-free range (-64 dBm: 5 m); SSIDs are the RA's name and a number."""
    record, _ = mission(build(), until=260)
    try:
        installed = custom(record, "slam.installed")
        assert len(installed) >= 3
        assert installed[0].data["data"]["position"] == pytest.approx([0.0, 0.0], abs=0.01)
        assert installed[0].time == pytest.approx(18.0 + 2.2, abs=1.0)   # after looking round, then 18 s
        assert [e.data["data"]["ssid"] for e in installed] == [f"WA_R1_{k}" for k in range(1, len(installed) + 1)]
        reach = ESP8266().range()
        spots = [tuple(e.data["data"]["true"]) for e in installed]
        for k, spot in enumerate(spots[1:], 1):
            assert min(math.dist(spot, earlier) for earlier in spots[:k]) > reach - 0.05
        origin = tuple(record.world.meta["slam"]["origin"])
        for e in installed:
            assert record.world.position(e.data["data"]["wa"]) == pytest.approx(to_world(e.data["data"]["true"],
                                                                                        origin), abs=1e-3)
    finally:
        record.world.close()


def test_experiment_1_maps_every_vertex_with_about_nine_was():
    """Decentralised: the map done with every vertex of the ground truth, 9 +- 3 WAs, no
    false alarm (its speed is bench/slam.py's, not a unit test's)."""
    record, _ = mission(build())
    try:
        assert record.result.reason == "final"
        assert metrics.completed(record) == 1 and metrics.vertices_missing(record) == 0
        assert 6 <= metrics.was_used(record) <= 12
        assert metrics.vertex_error_m(record) < 0.35 and metrics.edges_missing(record) == 0
        assert 900 < metrics.time_s(record) < 1800
        assert custom(record, "slam.alert") == []   # no false alarm while the RA works
    finally:
        record.world.close()


def test_experiment_3_the_was_alert_and_the_second_ra_finishes_from_their_map():
    record, _ = mission(build(fail_at=420))
    try:
        (failed,) = custom(record, "slam.failed")
        assert failed.time == pytest.approx(420.0)
        alerts = custom(record, "slam.alert")
        assert alerts and 420 < alerts[0].time < 420 + 60 + 10 and alerts[0].data["data"]["ra"] == "ra1"
        (sent,) = custom(record, "slam.dispatched")
        assert sent.data["data"] == {"reserve": "ra2", "replaces": "ra1"}
        loaded = custom(record, "slam.loaded")
        assert loaded[0].agent == "ra2" and loaded[0].data["data"]["source"].startswith("wa_r1_")
        reading = custom(record, "slam.reading")
        assert reading[0].data["data"]["rule"] == "follow"
        done = custom(record, "slam.finished")
        assert [e.agent for e in done] == ["ra2"]
        assert metrics.completed(record) == 1 and metrics.vertices_missing(record) == 0
        assert record.result.reason == "final"
    finally:
        record.world.close()


def test_experiment_3_centralised_does_not_finish_when_the_central_unit_fails():
    record, _ = mission(build("centralised", fail_at=420))
    try:
        assert metrics.completed(record) == 0 and metrics.time_s(record) is None
        assert record.result.reason != "final" and record.result.time < 1000
        assert metrics.was_used(record) == 16 and metrics.vertices_missing(record) > 0
    finally:
        record.world.close()


@pytest.mark.slow
def test_experiment_2_is_faster_than_experiment_1_over_seeds():
    times = {}
    for mode in ("decentralised", "centralised"):
        values = []
        for seed in (1, 2, 3):
            record, _ = mission(build(mode), seed=seed)
            values.append(metrics.time_s(record))
            assert metrics.vertices_missing(record) == 0
            record.world.close()
        times[mode] = sum(values) / len(values)
    assert times["centralised"] < times["decentralised"]


@pytest.mark.slow
def test_five_ras_sharing_their_was_map_the_50_m_maze_sooner_than_one_would():
    """Five RAs starting in the corners and the middle of the generated maze: the map is
    done, with at most a couple of vertices lost to the merge of independent finds."""
    world = load_world(examples.path("slam", "experiments/maze-50.yaml"))
    config = load_config(examples.path("slam", "run.yaml"))
    outcome = run(build(robots=5, reserves=0, was=20), world=world, config=config, seed=1, until=20000,
                  keep_events=True)
    try:
        record = RunRecord(outcome.result, outcome.events, world, config)
        assert metrics.completed(record) == 1 and metrics.vertices_missing(record) <= 2
        assert metrics.time_s(record) < 2500 and metrics.was_used(record) <= 100
    finally:
        world.close()
