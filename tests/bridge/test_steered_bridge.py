"""Steering a bridged run: a pause stops dispatching goals to remote agents while the
goals already running on them go on and end (docs/viewer.md, "With remote agents")."""

from __future__ import annotations

import json
import time

import pytest

from tests.bridge.test_bridged_run import CHAIN, write
from tests.live.conftest import LiveRun
from tests.live.test_steered_runs import ctl

#: Ten goals in a row on the remote agent; the first, ``s0``, runs 1 s: the run is paused then.
SLOW_FIRST = CHAIN.replace("{seconds: 0.3}, in: [a]", "{seconds: 1.0}, in: [a]")


@pytest.mark.slow
def test_a_pause_stops_dispatching_while_the_remote_action_running_ends(middleware, serve, tmp_path, capsys):
    """``petriflow run --live`` with a bridge, paused by ``ctl`` while ``s0`` runs on the
    agent: the agent finishes it during the pause and is sent nothing else; the trace has no
    event between the pause and the resume; on resume the run takes in ``s0``'s end
    before it dispatches anything, then dispatches the rest."""
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
            assert "paused" in ctl(capsys, run.url, "status")[1]
            assert ctl(capsys, run.url, "resume")[0] == 0
            run.finish()
            assert run.process.returncode == 0
        finally:
            run.stop()
    events = [json.loads(line) for line in run.trace.read_text().splitlines()]
    controls = [i for i, e in enumerate(events) if e["kind"] == "control"]
    assert [events[i]["data"]["action"] for i in controls] == ["pause", "resume"]
    paused, resumed = controls
    assert resumed == paused + 1  # no start (nor anything else) while paused
    after = [(e["kind"], e["transition"]) for e in events[resumed + 1:] if e["kind"] in ("start", "end")]
    assert after[:2] == [("end", "s0"), ("start", "s1")]
    assert [t for k, t in after if k == "start"] == [f"s{i}" for i in range(1, 10)]
    goals = [json.loads(line) for line in (tmp_path / "agent.log").read_text().splitlines()]
    assert [g["transition"] for g in goals] == [f"s{i}" for i in range(10)]
    assert goals[1]["at"] - goals[0]["at"] >= 2.5  # nothing was sent to the agent while paused
