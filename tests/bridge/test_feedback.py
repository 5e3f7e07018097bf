"""An agent's feedback becomes ``feedback`` events: in the trace, on the run's page, and to an
observer (over a real broker or router on loopback, from an agent that speaks the protocol)."""

import base64
import gzip
import json
import re
import threading
import time

import pytest

import petriflow
from petriflow.bridge import protocol
from petriflow.bridge.transport import Endpoint, from_agent, open_transport, to_agent
from petriflow.bridge.watch import FEEDBACK_BYTES
from petriflow.runtime.registry import Registry
from petriflow.runtime.session import run_files
from petriflow.view.columns import decoded

from tests.bridge.test_bridged_run import write

pytestmark = pytest.mark.slow

NET = """\
petriflow: 1
net: reporting
subnets:
  - id: r1
    agent: r1
    places: [{id: a, tokens: 1}]
    transitions:
      - {id: go, action: robot.walk, params: {}, in: [a], out: [b]}
places: [b]
final: {b: 1}
"""


class ReportingRobot:
    """A robot that speaks the protocol: it serves ``robot.walk``, reports its progress three
    times (once with data far over the trace's limit), then ends ``ok``."""

    def __init__(self, kind: str, connect: str) -> None:
        self.name = "robot1"
        self.transport = open_transport(kind, Endpoint(connect), "reporting-robot")
        self.stop = threading.Event()
        self.goals: list[protocol.Goal] = []
        self.results: dict[str, protocol.Result] = {}  # answered again to a goal sent again
        self.transport.subscribe(to_agent(self.name), self.receive)
        self.beat = threading.Thread(target=self.heartbeats, daemon=True)
        self.beat.start()

    def send(self, message) -> None:
        self.transport.publish(from_agent(self.name), protocol.encode(message))

    def heartbeats(self) -> None:
        while not self.stop.is_set():
            self.send(protocol.Announce(self.name, {"robot.walk": {}}, "one"))
            self.send(protocol.Heartbeat(self.name, [g.id for g in self.goals if g.id not in self.results]))
            self.stop.wait(0.1)

    def receive(self, topic, payload) -> None:
        message = protocol.decode(payload)
        if not isinstance(message, protocol.Goal):
            return
        if message.id in self.results:
            self.send(self.results[message.id])
        elif any(g.id == message.id for g in self.goals):
            self.send(protocol.Accepted(message.id, self.name))
        else:
            self.goals.append(message)
            threading.Thread(target=self.walk, args=(message,), daemon=True).start()

    def walk(self, goal) -> None:
        self.send(protocol.Accepted(goal.id, self.name))
        for k, data in enumerate([{"progress": 0.25}, "x" * (4 * FEEDBACK_BYTES), {"progress": 0.75}]):
            time.sleep(0.15)
            self.send(protocol.Feedback(goal.id, self.name, data))
        time.sleep(0.15)
        self.results[goal.id] = protocol.Result(goal.id, self.name, "ok", {"walked": 1})
        self.send(self.results[goal.id])

    def close(self) -> None:
        self.stop.set()
        self.beat.join(timeout=5)
        self.transport.close()


def page_records(page) -> list[dict]:
    """Every event's record as the page's columns hold it."""
    text = page.read_text(encoding="utf-8")
    data = json.loads(re.search(r'<script type="application/json" id="pf-data">(.*?)</script>', text, re.S).group(1))
    return decoded(gzip.decompress(base64.b64decode(data["columns"])))[0]


def test_feedback_is_traced_shown_and_heard(middleware, tmp_path):
    """Three progress reports on a running goal: three ``feedback`` events before its end (the
    transition, its agent, the remote agent, the goal, the data; the oversized one as its size and
    digest), heard by an observer of that kind, and carried by the run's page."""
    kind, server = middleware
    robot = ReportingRobot(kind, server.connect)
    heard = []
    registry = Registry()
    registry.register_metric("test.feedback", lambda record: heard.extend(record.events) or len(record.events),
                             events=["feedback"])
    try:
        path = write(tmp_path, kind, server.connect, net=NET, heartbeat=0.1)
        result = run_files(path, trace=tmp_path / "t.jsonl", registry=registry, metrics=["test.feedback"])
    finally:
        robot.close()
    assert result.reason == "final" and result.tokens["b"] == [{"walked": 1}]
    events = [json.loads(line) for line in (tmp_path / "t.jsonl").read_text().splitlines()]
    feedback = [e for e in events if e["kind"] == "feedback"]
    goal = robot.goals[0].id
    assert [(e["transition"], e["agent"], e["data"]["remote_agent"], e["data"]["goal"], e["data"]["firing"])
            for e in feedback] == [("go", "r1", "robot1", goal, 1)] * 3
    assert [e["data"]["data"] for e in feedback][::2] == [{"progress": 0.25}, {"progress": 0.75}]
    assert feedback[1]["data"]["data"].startswith("<feedback ") and "sha1=" in feedback[1]["data"]["data"]
    end = next(e for e in events if e["kind"] == "end" and e["transition"] == "go")
    assert all(e["seq"] < end["seq"] and e["time"] <= end["time"] for e in feedback)
    # an observer hears them
    assert result.metrics["test.feedback"] == 3 and [e.seq for e in heard] == [e["seq"] for e in feedback]
    # the run's page carries them, as every other event
    page = petriflow.view(tmp_path / "t.jsonl", net=path, out=tmp_path / "run.html")
    assert [r for r in page_records(page) if r["kind"] == "feedback"] == feedback


CHAIN3 = NET.replace("""      - {id: go, action: robot.walk, params: {}, in: [a], out: [b]}
places: [b]""", """      - {id: go, action: robot.walk, params: {}, in: [a], out: [p1]}
      - {id: go2, action: robot.walk, params: {}, in: [p1], out: [p2]}
      - {id: go3, action: robot.walk, params: {}, in: [p2], out: [b]}
places: [p1, p2, b]""")


def test_journaled_feedback_is_replayed_when_a_killed_run_resumes(broker, tmp_path):
    """The orchestrator is killed (SIGKILL) after some feedback was journaled: ``--resume``
    replays those ``feedback`` events at their journaled place (the journal's check passes),
    re-attaches, and completes with every firing once."""
    import os
    import signal
    import subprocess
    import sys

    from petriflow.runtime.journal import Journal
    from petriflow.runtime.session import resume

    robot = ReportingRobot("mqtt", broker.connect)
    try:
        net = write(tmp_path, "mqtt", broker.connect, net=CHAIN3, heartbeat=0.1, heartbeat_timeout=5)
        db = tmp_path / "run.sqlite"
        run = subprocess.Popen([sys.executable, "-m", "petriflow.cli", "run", str(net), "--db", str(db), "--quiet"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            deadline = time.monotonic() + 60
            while len(robot.goals) < 2 and time.monotonic() < deadline:  # go ended, go2 runs
                time.sleep(0.01)
            time.sleep(0.2)  # go2's first feedback
        finally:
            os.kill(run.pid, signal.SIGKILL)
            run.wait(timeout=10)
        with Journal(db) as journal:
            journaled = [e for e in journal.events() if e.kind == "feedback"]
            assert not journal.finished and len(journaled) >= 3
        result = resume(db, trace=tmp_path / "t.jsonl")
    finally:
        robot.close()
    assert result.reason == "final" and result.firings == 3
    events = [json.loads(line) for line in (tmp_path / "t.jsonl").read_text().splitlines()]
    feedback = [e for e in events if e["kind"] == "feedback"]
    assert feedback[:len(journaled)] == [json.loads(e.to_json()) for e in journaled]
    assert sorted(e["transition"] for e in events if e["kind"] == "end") == ["go", "go2", "go3"]
    assert len(robot.goals) == 3  # each walked once
