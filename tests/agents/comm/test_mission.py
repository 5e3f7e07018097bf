"""Seed 000's nets: sound, fireable transition by transition, and the mission end to end."""

from __future__ import annotations

import pytest

from petriflow import examples
from petriflow.agents.comm.nets import build
from petriflow.analysis.report import check_net
from petriflow.io import load_net
from petriflow.io.yaml import loads_net
from petriflow.runtime.config import load_config
from petriflow.testing import fire_one
from petriflow.world import load_world

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")


@pytest.mark.parametrize("robots, mode, monitor", [(2, "decentralised", False), (2, "centralised", False),
                                                   (3, "decentralised", False)])
def test_generated_nets_are_sound_workflow_nets(robots, mode, monitor):
    result = check_net(loads_net(build(robots, mode, monitor)))
    assert result["workflow_net"] and result["sound"], result["violations"]


def test_shipped_nets_are_the_builders():
    shipped = load_net(examples.path("comm", "comm-decentralised-3.yaml"))
    assert shipped.structure() == loads_net("run: run.yaml\n" + build(3, "decentralised")).structure()


def test_the_start_up_transitions_one_by_one():
    net = load_net(examples.path("comm", "comm-decentralised-2.yaml"))
    config = load_config(examples.path("comm", "run.yaml"))
    world = load_world(examples.path("comm", "world.yaml"))
    try:
        first = fire_one(net, "robot1_characterise", world=world, config=config, tokens={"robot1_start": [None]})
        assert first.outcome == "ok"
        state = first.tokens["robot1_c1"][0]
        assert state.robot is not None and state.explorer.cell == (0, 0)
        assert [e.data["data"]["pg"] for e in first.events if e.kind == "custom"] == [[318, 318]]
        analysed = fire_one(net, "robot1_analyse", world=world, config=config, tokens={"robot1_c1": [state]})
        report = [e.data["data"] for e in analysed.events if e.kind == "custom"][0]
        assert report["lossless_behind_wall_m"] == 7 and report["range_m"] == pytest.approx(2.0)
        init = fire_one(net, "robot1_initialise", world=world, config=config, tokens={"robot1_c2": [state]})
        assert init.tokens["robot1_c3"][0].address == 2
        history = fire_one(net, "robot1_history", world=world, config=config, tokens={"robot1_c3": [state]})
        assert set(history.tokens) == {"robot1_idle", "robot1_listen"}
        step = fire_one(net, "robot1_step", world=world, config=config, tokens={"robot1_idle": [state]},
                        timeout=60)
        assert step.outcome == "ok" and state.vertices  # it drove to its cell's centre and mapped a vertex
    finally:
        world.close()


def test_decentralised_mission_maps_the_whole_maze():
    from petriflow.runtime.session import run_files
    from petriflow.runtime.metrics import RunRecord
    from petriflow.agents.comm import metrics

    outcome = run_files(examples.path("comm", "comm-decentralised-2.yaml"), keep_events=True)
    assert outcome.result.reason == "final"
    world = load_world(examples.path("comm", "world.yaml"))
    try:
        record = RunRecord(outcome.result, outcome.events, world)
        assert metrics.maps_complete(record) == 1.0
        assert 0 < metrics.time_s(record) <= outcome.result.time
        sent = metrics.bytes_per_agent(record)
        assert set(sent) == {"robot1", "robot2"} and all(v % 5 == 0 and v > 0 for v in sent.values())
    finally:
        world.close()
