"""nets/smart's helping task with both robots on a `petriflow agent`, over each transport.

The camera, image processing and decision maker stay in the run; Robot3L (helper) and
Robot4L (fallen) run on one agent process with its own world (they touch: Robot4L
stands up leaning on Robot3L). Robot3L's walk reads the run's latest scene through its
port while it walks: served by the run over the bridge (tests/bridge/test_calls.py).
"""

import json
import os
import subprocess
import sys

import pytest

from petriflow import examples
from petriflow.runtime.session import run_files

from tests.bridge.conftest import agent_command, shipped_config

pytestmark = pytest.mark.slow

ROBOTS = ("robot3l", "robot4l")


def per_agent(events):
    order = {}
    for event in events:
        if event["kind"] == "start" and event["agent"] in ROBOTS:
            order.setdefault(event["agent"], []).append(event["transition"])
    return order


def load(path):
    return [json.loads(line) for line in path.read_text().splitlines()]


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    """The simulated run with the same seed: its robots' firings in order."""
    folder = tmp_path_factory.mktemp("simulated")
    result = run_files(examples.path("smart", "smart.yaml"), trace=folder / "simulated.jsonl")
    assert result.reason == "final"
    return per_agent(load(folder / "simulated.jsonl"))


def test_smart_helping_over_each_transport_matches_the_simulated_order(middleware, tmp_path, simulated):
    """Exit 0, the final marking, each robot's firings in the simulated run's order, each goal
    executed once, and the walk's port read answered by the run."""
    kind, server = middleware
    folder = examples.path("smart", "smart.yaml").parent
    shipped_config(folder, kind, server, tmp_path)
    env = {**os.environ, "PETRIFLOW_PATH": str(folder)}  # the run's world: the camera's arena
    agent = subprocess.Popen(agent_command(ROBOTS, kind, server, folder / "world.yaml", tmp_path / "agent.log",
                                           "--speed", "4"),
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        run = subprocess.run([sys.executable, "-m", "petriflow.cli", "run", str(folder / "smart.yaml"), "--config",
                              str(tmp_path / "run.yaml"), "--trace", str(tmp_path / "bridged.jsonl")],
                             capture_output=True, text=True, env=env, timeout=400)
    finally:
        agent.terminate()
        agent.wait(timeout=20)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "smart: final" in run.stdout and "marking at the end: o=1" in run.stdout
    events = load(tmp_path / "bridged.jsonl")
    assert per_agent(events) == simulated == {"robot3l": ["T7", "T8"], "robot4l": ["T6"]}
    remote = {e["transition"]: e["data"]["data"] for e in events
              if e["kind"] == "custom" and e["data"]["name"] == "remote"}
    assert {t: r["agent"] for t, r in remote.items()} == {"T7": "robot3l", "T8": "robot3l", "T6": "robot4l"}
    assert all(r["phase"] == "ok" for r in remote.values())
    assert remote["T8"]["calls"] > 0  # the walk read the scene through its port, answered by the run
    walked = next(e["data"]["result"] for e in events if e["kind"] == "end" and e["transition"] == "T8")
    assert walked["checks"] and all(c["decision"] == "on_track" for c in walked["checks"])  # tracked on them
    executed = [json.loads(line) for line in (tmp_path / "agent.log").read_text().splitlines()]
    assert sorted(e["transition"] for e in executed) == ["T6", "T7", "T8"]
    assert len({e["goal"] for e in executed}) == 3
