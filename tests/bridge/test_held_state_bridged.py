"""Agent-held state over each real transport: three robots, each a subnet that keeps its state
(a counter, changed by its actions, read by its guards), bridged to `petriflow agent`
processes (robot1 alone, robot2 and robot3 sharing one), against the simulated run with
the same seed."""

import json
from pathlib import Path
import subprocess
import sys

import pytest

pytestmark = pytest.mark.slow

ROBOTS = ("robot1", "robot2", "robot3")

#: The actions module `petriflow run` and `petriflow agent` import (--actions).
ACTIONS = (Path(__file__).parent / "held_actions.py").read_text() + \
    "\nfrom petriflow.runtime.registry import default_registry\nregister(default_registry)\n"


def robot(name, seconds):
    return f"""\
- id: {name}
  agent: {name}
  state: demo.counter
  places: [{{id: {name}_start, tokens: 1}}, {name}_work, {name}_seen, {{id: {name}_eye, tokens: 1}}, {name}_done]
  transitions:
  - {{id: {name}_make, action: demo.make, in: [{name}_start], out: [{name}_work]}}
  - {{id: {name}_step, action: demo.slow, params: {{seconds: {seconds}, limit: 3, put: true}}, guard: demo.below,
     in: [{name}_work], out: [{name}_work]}}
  - {{id: {name}_first, guard: demo.reached, params: {{limit: 1}}, priority: 2, in: [{name}_eye],
     out: [{name}_seen]}}
  - {{id: {name}_finish, guard: demo.reached, params: {{limit: 3}}, in: [{name}_work], out: [{name}_done]}}
"""


NET = "petriflow: 1\nnet: held3\nfinal: {robot1_done: 1, robot2_done: 1, robot3_done: 1, robot1_seen: 1," \
      " robot2_seen: 1, robot3_seen: 1}\nsubnets:\n" + "".join(
          robot(name, seconds) for name, seconds in zip(ROBOTS, (0.6, 0.5, 0.7)))


def per_robot(events):
    order = {}
    for event in events:
        if event["kind"] in ("start", "end") and event["agent"] in ROBOTS:
            order.setdefault(event["agent"], []).append((event["kind"], event["transition"]))
    return order


def load(path):
    return [json.loads(line) for line in path.read_text().splitlines()]


def petriflow(*args, **options):
    return subprocess.run([sys.executable, "-m", "petriflow.cli", *args], capture_output=True, text=True,
                          timeout=300, **options)


def test_three_robots_with_agent_held_state_fire_as_the_simulated_run(middleware, tmp_path):
    """Exit 0, the final marking, each robot's starts and ends in the simulated run's order
    (a guard made true mid-action fires before the action ends), the same output tokens and
    custom events, each goal executed once."""
    kind, server = middleware
    (tmp_path / "held_actions.py").write_text(ACTIONS)
    (tmp_path / "net.yaml").write_text(NET)
    (tmp_path / "sim.yaml").write_text("seed: 1\nuntil: 60\nactions: [held_actions.py]\n")
    simulated = petriflow("run", str(tmp_path / "net.yaml"), "--config", str(tmp_path / "sim.yaml"), "--trace",
                          str(tmp_path / "sim.jsonl"))
    assert simulated.returncode == 0, simulated.stdout + simulated.stderr
    bridge = {"transport": kind, "connect": server.connect, "agents": {r: r for r in ROBOTS}, "heartbeat": 0.2,
              "wait": 20}
    (tmp_path / "run.yaml").write_text(f"seed: 1\nuntil: 60\nactions: [held_actions.py]\nbridge: {json.dumps(bridge)}\n")
    agents = []
    try:
        for names, log in ((["robot1"], "a1.log"), (["robot2", "robot3"], "a23.log")):
            agents.append(subprocess.Popen(
                [sys.executable, "-m", "petriflow.cli", "agent", *[a for n in names for a in ("--name", n)],
                 "--transport", kind, "--connect", server.connect, "--actions", str(tmp_path / "held_actions.py"),
                 "--heartbeat", "0.2", "--log", str(tmp_path / log)],
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        run = petriflow("run", str(tmp_path / "net.yaml"), "--config", str(tmp_path / "run.yaml"), "--trace",
                        str(tmp_path / "bridged.jsonl"))
    finally:
        for agent in agents:
            agent.terminate()
        for agent in agents:
            agent.wait(timeout=20)
    assert all(agent.poll() is not None for agent in agents)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "held3: final" in run.stdout
    sim, bridged = load(tmp_path / "sim.jsonl"), load(tmp_path / "bridged.jsonl")
    assert per_robot(bridged) == per_robot(sim)
    for name in ROBOTS:
        order = per_robot(bridged)[name]
        assert order.index(("start", f"{name}_first")) < order.index(("end", f"{name}_step"))
    assert [e for e in bridged if e["kind"] == "stop"][0]["data"]["marking"] == \
        [e for e in sim if e["kind"] == "stop"][0]["data"]["marking"]

    def steps(events):
        return sorted((e["agent"], e["data"]["data"]["n"]) for e in events
                      if e["kind"] == "custom" and e["data"]["name"] == "demo.step")

    assert steps(bridged) == steps(sim) == sorted((r, n) for r in ROBOTS for n in (1, 2, 3))
    ends = {e["transition"]: e["data"].get("result") for e in bridged if e["kind"] == "end"}
    executed = [json.loads(line) for log in ("a1.log", "a23.log") for line in (tmp_path / log).read_text().splitlines()]
    assert len(executed) == len({e["goal"] for e in executed}) == 12  # make + 3 steps per robot, once each
    assert {e["agent"] for e in executed} == set(ROBOTS)
    assert ends  # every firing ended in the trace


ONE = """\
petriflow: 1
net: held1
final: {robot1_finished: 1}
subnets:
- id: robot1
  agent: robot1
  state: demo.counter
  places: [{id: robot1_start, tokens: 1}, robot1_work, robot1_finished]
  transitions:
  - {id: robot1_make, action: demo.make, in: [robot1_start], out: [robot1_work]}
  - {id: robot1_step, action: demo.slow, params: {seconds: 0.5, limit: 4, put: true}, guard: demo.below,
     in: [robot1_work], out: [robot1_work]}
  - {id: robot1_finish, guard: demo.reached, params: {limit: 4}, in: [robot1_work], out: [robot1_finished]}
"""


def test_an_orchestrator_killed_mid_run_resumes_with_the_agent_held_state(broker, tmp_path):
    """The run process is killed (SIGKILL) while a step runs: --resume replays the journaled steps
    with their guard snapshots, re-attaches to the running goal, and the agent, which kept the
    robot's state under the run's name, finishes the count: every firing once, every goal once."""
    import os
    import signal
    import time

    (tmp_path / "held_actions.py").write_text(ACTIONS)
    (tmp_path / "net.yaml").write_text(ONE)
    bridge = {"transport": "mqtt", "connect": broker.connect, "agents": {"robot1": "robot1"}, "heartbeat": 0.1,
              "heartbeat_timeout": 5, "wait": 20}
    (tmp_path / "run.yaml").write_text(f"seed: 1\nuntil: 60\nactions: [held_actions.py]\nbridge: {json.dumps(bridge)}\n")
    db = tmp_path / "run.sqlite"
    agent = subprocess.Popen([sys.executable, "-m", "petriflow.cli", "agent", "--name", "robot1", "--transport", "mqtt",
                              "--connect", broker.connect, "--actions", str(tmp_path / "held_actions.py"),
                              "--heartbeat", "0.1", "--log", str(tmp_path / "agent.log")],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        run = subprocess.Popen([sys.executable, "-m", "petriflow.cli", "run", str(tmp_path / "net.yaml"), "--config",
                                str(tmp_path / "run.yaml"), "--db", str(db), "--quiet"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not (tmp_path / "agent.log").exists() or \
                len((tmp_path / "agent.log").read_text().splitlines()) < 3:  # make and two steps sent
            assert time.monotonic() < deadline and run.poll() is None
            time.sleep(0.02)
        os.kill(run.pid, signal.SIGKILL)
        run.wait(timeout=10)
        resumed = petriflow("run", "--resume", "--db", str(db), "--trace", str(tmp_path / "t.jsonl"))
    finally:
        agent.terminate()
        agent.wait(timeout=20)
    assert agent.poll() is not None
    assert resumed.returncode == 0, resumed.stdout + resumed.stderr
    events = load(tmp_path / "t.jsonl")
    assert [e["transition"] for e in events if e["kind"] == "end"] == \
        ["robot1_make"] + ["robot1_step"] * 4 + ["robot1_finish"]
    assert [e["data"]["data"]["n"] for e in events if e["kind"] == "custom" and e["data"]["name"] == "demo.step"] \
        == [1, 2, 3, 4]
    executed = [json.loads(line) for line in (tmp_path / "agent.log").read_text().splitlines()]
    assert len(executed) == len({e["goal"] for e in executed}) == 5
