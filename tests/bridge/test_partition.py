"""A network partition between the run and one agent, the agent left running: it is lost
after ``heartbeat_timeout`` (its firing fails, the failure route fires) and, when the link
comes back, it rejoins as a late joiner; no goal is executed twice.

The partition is a TCP proxy the test owns between the agent and the broker or router
(:class:`tests.bridge.conftest.Link`), cut and restored; the run connects directly. Where
the machine permits it, the test runs in a network namespace of its own
(:func:`tests.bridge.conftest.own_network`: the broker or router, the agent, the proxy and
the run all inside it).
"""

from __future__ import annotations

import json
import threading
import time

import pytest

from tests.bridge.conftest import own_network, start_middleware
from tests.bridge.test_bridged_run import RETRY, session_run, write


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["mqtt", "zenoh"])
def test_an_agent_cut_off_is_lost_then_rejoins_with_no_goal_run_twice(kind, request, tmp_path):
    """Cut once ``go`` runs on the agent: ``go`` ends failed within heartbeat_timeout + 1 s,
    the agent is lost; restored, it announces itself again (``back``) and ``retry``, the
    failure route, runs on it; the agent executed each goal once."""
    if own_network(request):
        return
    server = start_middleware(kind, tmp_path)
    request.addfinalizer(server.stop)
    serve, link = request.getfixturevalue("serve"), request.getfixturevalue("link")
    through = link(server.port)
    with open(tmp_path / "agent.log", "w") as log:
        agent = serve(kind, through.connect, ["robot1"], heartbeat=0.1, log_file=log)
        net = write(tmp_path, kind, server.connect, net=RETRY.replace("{seconds: 30}", "{seconds: 2}"),
                    heartbeat=0.1, heartbeat_timeout=1.0)
        cut = []

        def partition():
            deadline = time.monotonic() + 60
            while not agent.server.executed:  # until go runs on the agent
                if time.monotonic() > deadline:
                    return
                time.sleep(0.01)
            through.cut()
            cut.append(time.monotonic())
            time.sleep(3.0)  # lost by then, and go (2 s) over on the agent
            through.restore()

        cutter = threading.Thread(target=partition, daemon=True)
        cutter.start()
        result, failed_at = session_run(net, tmp_path, lambda event: None)
        cutter.join(timeout=10)
        assert cut, "go never reached the agent"
    assert result.reason == "final" and result.tokens["o"] == ["retried"]
    assert failed_at - cut[0] < 1.0 + 1.0
    events = [json.loads(line) for line in (tmp_path / "t.jsonl").read_text().splitlines()]
    end = next(e for e in events if e["kind"] == "end" and e["transition"] == "go")
    assert end["data"]["outcome"] == "failed" and "lost" in end["data"]["reason"]
    faults = [e["data"]["fault"] for e in events if e["kind"] == "fault"]
    assert faults == ["lost", "back"]
    assert [e["transition"] for e in events if e["kind"] == "end"] == ["go", "retry"]
    remote = [e["transition"] for e in events if e["kind"] == "custom" and e["data"]["name"] == "remote"]
    assert remote == ["retry"]  # go's late result, sent after the link came back, is not recorded
    goals = [json.loads(line) for line in (tmp_path / "agent.log").read_text().splitlines()]
    assert [g["transition"] for g in goals] == ["go", "retry"]
    assert len({g["goal"] for g in goals}) == 2
    assert agent.server.executed == 2
