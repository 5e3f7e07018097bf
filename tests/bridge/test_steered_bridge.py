"""Steering a bridged run: a pause stops dispatching goals to remote agents while the
goals already running on them go on and end (docs/viewer.md, "With remote agents")."""

from __future__ import annotations

import json
import time

import pytest

from tests.bridge.test_bridged_run import write
from tests.live.conftest import LiveRun
from tests.live.test_steered_runs import ctl

#: Three goals in a row on the remote agent: ``first`` runs when the run is paused.
CHAIN = """\
petriflow: 1
net: chain
subnets:
  - id: r1
    agent: r1
    places: [{id: a, tokens: 1}, b, c]
    transitions:
      - {id: first, action: core.wait, params: {seconds: 1.0}, in: [a], out: [b]}
      - {id: second, action: core.wait, params: {seconds: 0.2}, in: [b], out: [c]}
      - {id: third, action: core.wait, params: {seconds: 0.2}, in: [c], out: [o]}
places: [o]
final: {o: 1}
"""


@pytest.mark.slow
def test_a_pause_stops_dispatching_while_the_remote_action_running_ends(middleware, serve, tmp_path, capsys):
    """``petriflow run --live`` with a bridge, paused by ``ctl`` while ``first`` runs on the
    agent: the agent finishes it during the pause and is sent nothing else; the trace has no
    event between the pause and the resume; on resume the run takes in ``first``'s end
    before it dispatches anything, then dispatches the rest."""
    pytest.importorskip("websockets")
    kind, server = middleware
    agent = serve(kind, server.connect, ["robot1"], heartbeat=0.1, log_file=open(tmp_path / "agent.log", "w"))
    folder = tmp_path / "run"
    folder.mkdir()
    net = write(folder, kind, server.connect, net=CHAIN, heartbeat=0.1, heartbeat_timeout=5)
    run = LiveRun(folder, net=net.read_text())
    try:
        deadline = time.monotonic() + 60
        while agent.server.executed < 1:  # ``first`` was sent and runs on the agent
            assert time.monotonic() < deadline, "the first goal never reached the agent"
            time.sleep(0.02)
        assert ctl(capsys, run.url, "pause")[0] == 0
        time.sleep(2.5)  # ``first`` (1 s) ends on the agent meanwhile
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
    assert after[:2] == [("end", "first"), ("start", "second")]
    assert [t for k, t in after if k == "start"] == ["second", "third"]
    goals = [json.loads(line) for line in (tmp_path / "agent.log").read_text().splitlines()]
    assert [g["transition"] for g in goals] == ["first", "second", "third"]
    assert goals[1]["at"] - goals[0]["at"] >= 2.5  # nothing was sent to the agent while paused
