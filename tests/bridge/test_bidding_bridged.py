"""nets/bidding's three-robot mission with robot1..robot3 on a `petriflow agent`, over each
transport.

The operator and the interface agent (HMIA) stay in the run, with the office world and
the global map; the three robot agents run on one agent process with its own world
(they share the office). Their states and guards live on the agent, the office plan
they navigate on (`bidding.office`, registered per world) is made there from the
agent's world, and their mailboxes' Message tokens cross the bridge tagged
(petriflow/bridge/codec.py).

What is compared with the simulated run of the same seed (docs/bridge.md, *The bidding
mission*): the auction is the net's order (each robot's create, ready, bid/decide per
zone, finish; every zone to the same winner; as many messages taken and sent to each
teammate). The explore steps, the waits and the MAPPED messages after each laser scan
follow wall-clock time: how many there are is not the simulated run's, nor is the
order of a robot's sends among its receives. A run takes about 130 s of wall-clock
time per transport (the mission's own time).
"""

import collections
import json
import os
import re
import subprocess
import sys

import pytest

from petriflow import examples
from petriflow.runtime.session import run_files

from tests.bridge.conftest import agent_command, shipped_config

pytestmark = pytest.mark.slow

ROBOTS = ("robot1", "robot2", "robot3")
#: A robot's protocol steps whose order the net fixes (its auction), not wall-clock time.
AUCTION = ("create", "ready", "bid", "decide", "finish")


def load(path):
    return [json.loads(line) for line in path.read_text().splitlines()]


def steps(events):
    """Per robot: its auction steps in order, and how many of each other step it fired."""
    auction, counts = collections.defaultdict(list), collections.defaultdict(collections.Counter)
    for event in events:
        if event["kind"] == "start" and event.get("agent") in ROBOTS:
            step = event["transition"].split("_", 1)[1]
            (auction[event["agent"]].append(step) if step in AUCTION else None)
            counts[event["agent"]][step] += 1
    return dict(auction), dict(counts)


def allocated(events):
    return [(e["data"]["data"]["zone"], e["data"]["data"]["robot"]) for e in events
            if e["kind"] == "custom" and e["data"]["name"] == "bidding.allocated"]


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    """The simulated run with the same seed."""
    folder = tmp_path_factory.mktemp("simulated")
    net = examples.path("bidding", "bidding-autonomous-3.yaml")
    result = run_files(net, config=net.parent / "run.yaml", trace=folder / "simulated.jsonl")
    assert result.reason == "final"
    return result.metrics, load(folder / "simulated.jsonl")


def test_bidding_with_three_bridged_robots_over_each_transport(middleware, tmp_path, simulated):
    """Exit 0, the final marking, every zone mapped, the coverage of the same order as the
    simulated run's, the auction in the simulated run's order with the same winners, and
    each goal executed once."""
    kind, server = middleware
    sim_metrics, sim_events = simulated
    folder = examples.path("bidding", "bidding-autonomous-3.yaml").parent
    shipped_config(folder, kind, server, tmp_path)
    env = {**os.environ, "PETRIFLOW_PATH": str(folder)}  # the run's world: the office and the global map
    agent = subprocess.Popen(agent_command(ROBOTS, kind, server, folder / "world.yaml", tmp_path / "agent.log"),
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        run = subprocess.run([sys.executable, "-m", "petriflow.cli", "run",
                              str(folder / "bidding-autonomous-3.yaml"), "--config", str(tmp_path / "run.yaml"),
                              "--trace", str(tmp_path / "bridged.jsonl")],
                             capture_output=True, text=True, env=env, timeout=600)
    finally:
        agent.terminate()
        agent.wait(timeout=20)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    assert "bidding-autonomous-3: final" in run.stdout and "marking at the end: o=1" in run.stdout
    metrics = dict(re.findall(r"^\s{4}(\S+)\s+(\S+)$", run.stdout, re.M))
    assert int(metrics["zones_mapped"]) == sim_metrics["zones_mapped"] == 8
    assert 0.6 * sim_metrics["coverage"] <= float(metrics["coverage"]) <= sim_metrics["coverage"] + 0.05
    assert int(metrics["bridge.dropped"]) == 0
    events = load(tmp_path / "bridged.jsonl")
    auction, counts = steps(events)
    sim_auction, sim_counts = steps(sim_events)
    assert auction == sim_auction
    assert all(a == ["create", "ready", *["bid", "decide"] * 8, "finish"] for a in auction.values())
    assert allocated(events) == allocated(sim_events) and len(allocated(events)) == 8
    for robot in ROBOTS:  # the messages taken, and those to each teammate: the simulated run's
        mail = {s: n for s, n in counts[robot].items() if s == "receive" or re.fullmatch(r"send_robot\d", s)}
        assert mail == {s: n for s, n in sim_counts[robot].items() if s in mail} and mail["receive"] == 27
    remote = [e["data"]["data"] for e in events if e["kind"] == "custom" and e["data"]["name"] == "remote"]
    assert remote and all(r["phase"] == "ok" for r in remote)
    executed = [json.loads(line)["goal"] for line in (tmp_path / "agent.log").read_text().splitlines()]
    assert len(executed) == len(set(executed)) == len(remote)
    assert set(executed) == {r["goal"] for r in remote}
