"""A cancel that is never acknowledged in time: the run gives the goal up after
``cancel_timeout``, its firing ends ``failed`` (the failure route fires), the agent is held lost
while it still does the goal, and its late answer is dropped and counted (over a real broker or
router on loopback)."""

import json
import time

import pytest

from petriflow import Action, Param, Status
from petriflow.runtime.registry import Registry
from petriflow.runtime.session import run_files

from tests.bridge.test_bridged_run import write

pytestmark = pytest.mark.slow

HEARTBEAT, HEARTBEAT_TIMEOUT, CANCEL_TIMEOUT = 0.1, 1.0, 0.5

NET = """\
petriflow: 1
net: stubborn
places: [b, broken, late, stopped, o]
final: {o: 1}
subnets:
  - id: here
    agent: here
    transitions: [{id: recover, action: core.wait, params: {seconds: 2.5}, in: [broken], out: [o]}]
  - id: r1
    agent: r1
    transitions:
      - {id: go, action: demo.stubborn, params: {stop_after: STOP}, in: [a], out: [b]TIMEOUT,
         outcomes: {failed: [broken], timeout: [late], cancelled: [stopped]}}
    places: [{id: a, tokens: 1}]
"""


class Stubborn(Action):
    """Runs until cancelled, and ignores the cancel for ``stop_after`` seconds (then stops:
    its acknowledgement comes late)."""

    params = {"stop_after": Param(float, 1.0)}
    needs_world = False
    cancels: list[float] = []

    def start(self, ctx):
        self.asked = None
        self.wake_at = None

    def poll(self, ctx):
        return Status.RUNNING

    def cancel(self, ctx):
        now = time.monotonic()
        if self.asked is None:
            self.asked = now
            type(self).cancels.append(now)
        return now - self.asked >= self.params["stop_after"]


def registry():
    made = Registry()
    Stubborn.cancels = []
    made.register("demo.stubborn", Stubborn)
    return made


def run_stubborn(kind, server, serve, folder, *, timeout=None, stop_after=2.0, faults=""):
    agent = serve(kind, server.connect, ["robot1"], heartbeat=HEARTBEAT, registry=registry())
    text = NET.replace("STOP", str(stop_after)).replace("TIMEOUT", "" if timeout is None else f", timeout: {timeout}")
    path = write(folder, kind, server.connect, net=text, heartbeat=HEARTBEAT, heartbeat_timeout=HEARTBEAT_TIMEOUT,
                 cancel_timeout=CANCEL_TIMEOUT)
    if faults:
        (folder / "run.yaml").write_text((folder / "run.yaml").read_text() + faults)
    result = run_files(path, trace=folder / "t.jsonl")
    events = [json.loads(line) for line in (folder / "t.jsonl").read_text().splitlines()]
    return agent, result, events


def check_given_up(result, events, cancelled_at):
    """The firing ended failed once, a cancel_timeout after the cancel; the agent lost for the
    cancel, back once it stopped; the late acknowledgement dropped and counted."""
    assert result.reason == "final" and result.marking.to_dict() == {"o": 1}
    ends = [e for e in events if e["kind"] == "end" and e["transition"] == "go"]
    assert len(ends) == 1 and ends[0]["data"]["outcome"] == "failed"
    assert "cancel" in ends[0]["data"]["reason"] and "cancel_timeout" in ends[0]["data"]["reason"]
    assert cancelled_at + CANCEL_TIMEOUT - 0.05 <= ends[0]["time"] <= cancelled_at + CANCEL_TIMEOUT + 1.0
    faults = [(e["data"]["fault"], e["agent"]) for e in events if e["kind"] == "fault" and e["data"]["fault"] in
              ("lost", "back")]
    assert faults[:1] == [("lost", "r1")]
    assert "did not acknowledge the cancel of 'go'" in next(e for e in events if e["kind"] == "fault"
                                                            and e["data"]["fault"] == "lost")["data"]["why"]
    assert result.metrics["bridge.dropped.replayed"] == 1  # the late 'cancelled', never recorded
    assert len(Stubborn.cancels) == 1


def test_a_timeout_whose_cancel_is_never_acknowledged_ends_the_firing_failed(middleware, serve, tmp_path):
    """timeout 0.5 s, the action ignores the cancel for 2 s, cancel_timeout 0.5 s: the firing ends
    ``failed`` at about 1 s (not ``timeout``: what the action did is unknown), the failure route
    runs, the agent is lost for the cancel and back once the action stopped."""
    kind, server = middleware
    agent, result, events = run_stubborn(kind, server, serve, tmp_path, timeout=0.5)
    check_given_up(result, events, 0.5)
    assert ("back", "r1") in [(e["data"]["fault"], e["agent"]) for e in events if e["kind"] == "fault"]
    assert agent.server.executed == 1


def test_a_kill_whose_cancel_is_never_acknowledged_ends_the_firing_failed(broker, serve, tmp_path):
    """A configured kill of the remote agent's subnet at 0.3 s: the cancel is never acknowledged in
    time, the firing ends ``failed`` (not ``cancelled``), and the killed agent stays killed when its
    remote agent is back."""
    agent, result, events = run_stubborn("mqtt", broker, serve, tmp_path, faults="faults: [{kill: r1, at: 0.3}]\n")
    check_given_up(result, events, 0.3)
    assert not [e for e in events if e["kind"] == "start" and e["transition"] == "go"][1:]
    assert [e["data"]["fault"] for e in events if e["kind"] == "fault"] == ["kill", "lost"]  # never revived
    assert agent.server.executed == 1


def test_a_cancel_acknowledged_within_the_deadline_still_ends_with_its_outcome(broker, serve, tmp_path):
    """The action stops 0.2 s after the cancel, within cancel_timeout: the firing ends ``timeout``
    as before, the agent never lost, nothing dropped."""
    agent, result, events = run_stubborn("mqtt", broker, serve, tmp_path, timeout=0.5, stop_after=0.2)
    ends = [e for e in events if e["kind"] == "end" and e["transition"] == "go"]
    assert [e["data"]["outcome"] for e in ends] == ["timeout"]
    assert not [e for e in events if e["kind"] == "fault"]
    assert result.marking.to_dict() == {"late": 1} and result.metrics["bridge.dropped"] == 0


def test_an_operators_forced_end_whose_cancel_is_never_acknowledged_ends_the_firing_failed(broker, serve,
                                                                                          tmp_path, capsys):
    """``petriflow ctl force go cancelled`` on a live bridged run: the agent ignores the cancel for
    2 s, so after cancel_timeout the firing ends ``failed`` (the failure route), not ``cancelled``."""
    pytest.importorskip("websockets")
    from tests.live.conftest import LiveRun
    from tests.live.test_steered_runs import ctl

    agent = serve("mqtt", broker.connect, ["robot1"], heartbeat=HEARTBEAT, registry=registry())
    folder = tmp_path / "run"
    folder.mkdir()
    net = write(folder, "mqtt", broker.connect, net=NET.replace("STOP", "2.0").replace("TIMEOUT", ""),
                heartbeat=HEARTBEAT, heartbeat_timeout=HEARTBEAT_TIMEOUT, cancel_timeout=CANCEL_TIMEOUT)
    run = LiveRun(folder, net=net.read_text())
    try:
        deadline = time.monotonic() + 60
        while "'go'" not in ctl(capsys, run.url, "status")[1]:
            assert time.monotonic() < deadline, "go never started"
            time.sleep(0.1)
        assert ctl(capsys, run.url, "force", "go", "cancelled")[0] == 0
        run.finish()
        assert run.process.returncode == 0
    finally:
        run.stop()
    events = [json.loads(line) for line in run.trace.read_text().splitlines()]
    force = next(e for e in events if e["kind"] == "control" and e["data"]["action"] == "force")
    ends = [e for e in events if e["kind"] == "end" and e["transition"] == "go"]
    assert len(ends) == 1 and ends[0]["data"]["outcome"] == "failed" and "cancel_timeout" in ends[0]["data"]["reason"]
    assert force["time"] + CANCEL_TIMEOUT - 0.05 <= ends[0]["time"]
    assert events[-1]["data"]["marking"] == {"o": 1}
    assert agent.server.executed == 1 and len(Stubborn.cancels) == 1
