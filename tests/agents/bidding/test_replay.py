"""Seed 004's replay of the paper's allocations (Tables 3-6, data in
nets/bidding/experiments/replay.yaml): every row is a deployment, and a replayed
mission drives each robot through its printed list in the printed order."""

from __future__ import annotations

import pytest
import yaml

from petriflow import examples
from petriflow.agents.bidding.nets import build
from petriflow.io.yaml import dumps_net
from petriflow.sweep import load_sweep

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")

REPLAY = examples.path("bidding", "experiments/replay.yaml")


def _lists(text):
    """The file writes each robot's list as zone numbers, the next robot's behind a '/'."""
    return [[int(z) for z in part.split()] for part in text.split("/")]


def test_every_replayed_row_is_a_deployment_of_the_eight_zones_beside_its_table7_row():
    sweep = load_sweep(REPLAY)
    assert len(sweep.rows) == 8
    for row in sweep.rows:
        params = row.params
        assert params["deployment"] == "random" and params["table"] in ("random", "autonomous")
        lists = _lists(params["lists"])
        assert len(lists) == params["robots"] and all(lists)  # Tables 3-6 deploy the whole team
        assert sorted(z for zs in lists for z in zs) == list(range(1, 9))
        assert set(row.paper) >= {"time_s", "accuracy_pct"}


def test_a_replayed_mission_visits_the_printed_lists_in_order_without_an_auction(tmp_path):
    from petriflow.runtime.session import run_files

    row = next(r for r in load_sweep(REPLAY).rows if r.params["robots"] == 2 and r.params["table"] == "autonomous")
    lists = _lists(row.params["lists"])
    # the builder takes the file's text as it is
    (tmp_path / "net.yaml").write_text(dumps_net(build(2, "random", lists=row.params["lists"], until="reached")))
    (tmp_path / "world.yaml").write_text(examples.path("bidding", "world.yaml").read_text())
    config = {"seed": 1, "until": 900, "world": "world.yaml", "stall": 120,
              "channels": {"lan": {"model": "ideal", "latency": 0.0}}}
    (tmp_path / "run.yaml").write_text(yaml.safe_dump(config))
    outcome = run_files(tmp_path / "net.yaml", config=tmp_path / "run.yaml", keep_events=True)
    assert outcome.result.reason == "final"
    custom = [e for e in outcome.events if e.kind == "custom"]
    mission = [e for e in custom if e.data.get("name") == "bidding.mission"][0].data["data"]
    assert mission["lists"] == lists
    done: dict[str, list[int]] = {}
    for e in custom:
        if e.data.get("name") == "bidding.zone_done":
            done.setdefault(e.agent, []).append(e.data["data"]["zone"])
    assert done == {"robot1": lists[0], "robot2": lists[1]}
    assert not [e for e in custom if e.data.get("name") in ("bidding.cfp", "bidding.bid")]
