"""nets/passage with both robots on `petriflow agent` processes, each with its own world."""

import json
import subprocess
import sys

import pytest

from petriflow import examples
from petriflow.runtime.session import run_files

pytestmark = pytest.mark.slow


def per_agent(events):
    order = {}
    for event in events:
        if event["kind"] == "start":
            order.setdefault(event["agent"], []).append(event["transition"])
    return order


def test_passage_over_each_transport_matches_the_simulated_order(middleware, tmp_path):
    """Exit 0, the final marking, and each robot's firings in the simulated run's order."""
    kind, server = middleware
    folder = examples.path("passage", "passage.yaml").parent
    config = (folder / f"run-{kind}.yaml").read_text().replace(
        f"connect: tcp/127.0.0.1:{7447 if kind == 'zenoh' else 1883}", f"connect: {server.connect}")
    (tmp_path / "run.yaml").write_text(config)
    agents = [subprocess.Popen([sys.executable, "-m", "petriflow.cli", "agent", "--name", name, "--transport",
                                kind, "--connect", server.connect, "--world", str(folder / "world.yaml"),
                                "--speed", "4", "--log", str(tmp_path / f"{name}.log")],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) for name in ("red", "blue")]
    try:
        result = run_files(folder / "passage.yaml", config=tmp_path / "run.yaml", trace=tmp_path / "bridged.jsonl")
    finally:
        for agent in agents:
            agent.terminate()
        for agent in agents:
            agent.wait(timeout=20)
    assert result.reason == "final"
    assert result.marking.to_dict() == {"red_done": 1, "blue_done": 1, "mutex": 1}
    simulated = run_files(folder / "passage.yaml", trace=tmp_path / "simulated.jsonl")
    load = lambda name: [json.loads(line) for line in (tmp_path / name).read_text().splitlines()]  # noqa: E731
    assert per_agent(load("bridged.jsonl")) == per_agent(load("simulated.jsonl"))
    assert simulated.reason == "final"
    for name in ("red", "blue"):  # each goal executed once, by its own agent
        goals = [json.loads(line)["goal"] for line in (tmp_path / f"{name}.log").read_text().splitlines()]
        assert len(goals) == len(set(goals)) == 3
