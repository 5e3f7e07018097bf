"""Steering a bridged run: a pause stops dispatching goals to remote agents while the
goals already running on them go on and end, their ends (or an agent's loss) recorded
when they happen, during the pause (docs/viewer.md, "With remote agents")."""

from __future__ import annotations

import json
import time

import pytest

from tests.bridge.test_bridged_run import CHAIN, LOSABLE, write
from tests.live.conftest import LiveRun
from tests.live.test_steered_runs import ctl

#: Ten goals in a row on the remote agent; the first, ``s0``, runs 1 s: the run is paused then.
SLOW_FIRST = CHAIN.replace("{seconds: 0.3}, in: [a]", "{seconds: 1.0}, in: [a]")


@pytest.mark.slow
def test_a_pause_stops_dispatching_while_the_remote_action_running_ends(middleware, serve, tmp_path, capsys):
    """``petriflow run --live`` with a bridge, paused by ``ctl`` while ``s0`` runs on the
    agent: the agent finishes it during the pause and is sent nothing else; ``s0``'s end is
    recorded when it comes, at a time within the pause, and nothing starts until the resume;
    then the rest is dispatched."""
    pytest.importorskip("websockets")
    kind, server = middleware
    with open(tmp_path / "agent.log", "w") as log:
        agent = serve(kind, server.connect, ["robot1"], heartbeat=0.1, log_file=log)
        folder = tmp_path / "run"
        folder.mkdir()
        net = write(folder, kind, server.connect, net=SLOW_FIRST, heartbeat=0.1, heartbeat_timeout=5)
        run = LiveRun(folder, net=net.read_text())
        try:
            deadline = time.monotonic() + 60
            while agent.server.executed < 1:  # ``s0`` was sent and runs on the agent
                assert time.monotonic() < deadline, "the first goal never reached the agent"
                time.sleep(0.02)
            assert ctl(capsys, run.url, "pause")[0] == 0
            time.sleep(2.5)  # ``s0`` (1 s) ends on the agent meanwhile
            assert agent.server.executed == 1 and not agent.server.running
            status = ctl(capsys, run.url, "status")[1]
            assert status.startswith("paused") and "'p1': 1" in status  # s0's end is taken in
            assert ctl(capsys, run.url, "resume")[0] == 0
            run.finish()
            assert run.process.returncode == 0
        finally:
            run.stop()
    events = [json.loads(line) for line in run.trace.read_text().splitlines()]
    controls = [i for i, e in enumerate(events) if e["kind"] == "control"]
    assert [events[i]["data"]["action"] for i in controls] == ["pause", "resume"]
    paused, resumed = controls
    during = [(e["kind"], e["transition"]) for e in events[paused + 1:resumed] if e["kind"] in ("start", "end")]
    assert during == [("end", "s0")]  # taken in as it came; nothing started
    end = next(e for e in events[paused + 1:resumed] if e["kind"] == "end")
    assert events[paused]["time"] < end["time"] < events[resumed]["time"]
    assert events[resumed]["time"] - events[paused]["time"] >= 2.0  # the run's time went on with the agent's
    after = [(e["kind"], e["transition"]) for e in events[resumed + 1:] if e["kind"] in ("start", "end")]
    assert after[0] == ("start", "s1")
    assert [t for k, t in after if k == "start"] == [f"s{i}" for i in range(1, 10)]
    goals = [json.loads(line) for line in (tmp_path / "agent.log").read_text().splitlines()]
    assert [g["transition"] for g in goals] == [f"s{i}" for i in range(10)]
    assert goals[1]["at"] - goals[0]["at"] >= 2.5  # nothing was sent to the agent while paused


@pytest.mark.slow
def test_an_agent_lost_during_a_pause_ends_its_firing_failed_during_the_pause(middleware, tmp_path, capsys):
    """The agent running ``go`` (30 s) is killed while the run is paused: its loss is noticed
    within the heartbeat timeout, during the pause, and ``go`` ends ``failed`` then (its
    failure route puts the token in ``broken``, the final place); the run ends only after
    the resume."""
    import subprocess
    import sys

    pytest.importorskip("websockets")
    kind, server = middleware
    agent = subprocess.Popen([sys.executable, "-m", "petriflow.cli", "agent", "--name", "robot1", "--transport",
                              kind, "--connect", server.connect, "--heartbeat", "0.1"],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    run = None
    try:
        folder = tmp_path / "run"
        folder.mkdir()
        net = write(folder, kind, server.connect, net=LOSABLE, heartbeat=0.1, heartbeat_timeout=1.0)
        run = LiveRun(folder, net=net.read_text())
        deadline = time.monotonic() + 60
        while "'go'" not in ctl(capsys, run.url, "status")[1]:  # go runs on the agent
            assert time.monotonic() < deadline, "go never started"
            time.sleep(0.1)
        assert ctl(capsys, run.url, "pause")[0] == 0
        agent.kill()
        agent.wait(timeout=10)
        deadline = time.monotonic() + 30
        while "'go'" in ctl(capsys, run.url, "status")[1]:  # lost within heartbeat_timeout, while paused
            assert time.monotonic() < deadline, "the lost agent's firing did not end during the pause"
            time.sleep(0.1)
        status = ctl(capsys, run.url, "status")[1]
        assert status.startswith("paused") and "'broken': 1" in status
        assert ctl(capsys, run.url, "resume")[0] == 0
        run.finish()
        assert run.process.returncode == 0
    finally:
        agent.kill()
        agent.wait(timeout=10)
        if run is not None:
            run.stop()
    events = [json.loads(line) for line in run.trace.read_text().splitlines()]
    controls = [i for i, e in enumerate(events) if e["kind"] == "control"]
    assert [events[i]["data"]["action"] for i in controls] == ["pause", "resume"]
    paused, resumed = controls
    end = next(i for i, e in enumerate(events) if e["kind"] == "end" and e["transition"] == "go")
    assert paused < end < resumed
    assert events[end]["data"]["outcome"] == "failed" and "lost" in events[end]["data"]["reason"]
    assert events[paused]["time"] <= events[end]["time"] <= events[resumed]["time"]
    assert not [e for e in events[paused + 1:resumed] if e["kind"] in ("start", "stop")]
    assert any(e["kind"] == "fault" and e["data"]["fault"] == "lost" for e in events[paused + 1:resumed])
