"""Runs whose subnets execute on remote agents, over a real broker or router on loopback."""

import json

import pytest

from petriflow.bridge import protocol
from petriflow.bridge.transport import Endpoint, from_agent, open_transport, to_agent
from petriflow.errors import NetFormatError
from petriflow.runtime.session import run_files

NET = """\
petriflow: 1
net: relay
subnets:
  - id: r1
    agent: r1
    places: [{id: a, tokens: 1}, b]
    transitions:
      - {id: go, action: core.wait, params: {seconds: 0.2}, in: [a], out: [b]}
      - {id: mark, action: core.set, params: {value: {x: 1}}, in: [b], out: [c]}
  - id: here
    agent: here
    places: []
    transitions:
      - {id: finish, action: core.wait, params: {seconds: 0.1}, in: [c], out: [o]}
places: [c, o, broken]
final: {o: 1}
"""


def write(folder, kind, connect, net=NET, **bridge):
    spec = {"transport": kind, "connect": connect, "agents": {"r1": "robot1"}, "wait": 10, **bridge}
    (folder / "net.yaml").write_text(net)
    (folder / "run.yaml").write_text(f"seed: 1\nbridge: {json.dumps(spec)}\n")
    return folder / "net.yaml"


def test_a_bridged_run_reaches_its_final_marking_with_the_agents_data(middleware, serve, tmp_path):
    """The remote subnet's firings run on the agent; their data reaches the local transition; the
    trace names the agent and the round trip of each remote firing."""
    kind, server = middleware
    agent = serve(kind, server.connect, ["robot1"], heartbeat=0.1)
    net = write(tmp_path, kind, server.connect)
    result = run_files(net, trace=tmp_path / "t.jsonl", xes=tmp_path / "run.xes")
    assert result.reason == "final" and result.marking.to_dict() == {"o": 1}
    assert result.tokens["o"] == [{"x": 1}]
    xes = (tmp_path / "run.xes").read_text()
    assert xes.count('key="petriflow:transition"') == 3 and 'value="r1"' in xes  # org:resource: the subnet
    events = [json.loads(line) for line in (tmp_path / "t.jsonl").read_text().splitlines()]
    remote = [e for e in events if e["kind"] == "custom" and e["data"]["name"] == "remote"]
    assert [(e["transition"], e["data"]["data"]["agent"]) for e in remote] == [("go", "robot1"), ("mark", "robot1")]
    assert all(e["data"]["data"]["round_trip_ms"] > 0 for e in remote)
    assert remote[0]["data"]["data"]["round_trip_ms"] >= 200  # core.wait 0.2 s ran on the agent
    assert agent.server.executed == 2


def test_a_parameter_the_agent_does_not_take_fails_at_bind_time_with_the_line(broker, serve, tmp_path):
    """An action only the agent knows is checked against what it announced: file:line, no run."""
    serve("mqtt", broker.connect, ["robot1"], heartbeat=0.1)
    net = write(tmp_path, "mqtt", broker.connect,
                net=NET.replace("action: core.set, params: {value: {x: 1}}", "action: robot.blink, params: {}"))
    with pytest.raises(NetFormatError, match=r"net.yaml:9: 'mark': remote agent 'robot1' does not serve action"
                                             r" 'robot.blink'"):
        run_files(net)
    net = write(tmp_path, "mqtt", broker.connect, net=NET.replace("{seconds: 0.2}", "{secnds: 0.2}"))
    with pytest.raises(NetFormatError, match=r"net.yaml:\d+: 'go': .*'secnds' \(did you mean 'seconds'\?\)"):
        run_files(net)


def test_an_agent_that_never_announces_itself_is_named(broker, tmp_path):
    net = write(tmp_path, "mqtt", broker.connect, wait=0.3)
    with pytest.raises(NetFormatError, match="remote agent 'robot1' did not announce itself within 0.3 s"):
        run_files(net)


def test_an_agent_executes_a_goal_sent_twice_once(middleware, serve, tmp_path):
    """The same goal id again (a re-send after a reconnect) gets the same result, not a second execution."""
    kind, server = middleware
    agent = serve(kind, server.connect, ["robot1"], heartbeat=0.1)
    client = open_transport(kind, Endpoint(server.connect), "test")
    got = []
    client.subscribe(from_agent("robot1"), lambda topic, data: got.append(protocol.decode(data)))
    try:
        import time

        deadline = time.monotonic() + 10
        while not any(isinstance(m, protocol.Announce) for m in got) and time.monotonic() < deadline:
            time.sleep(0.02)
        goal = protocol.encode(protocol.Goal("run/1/1", "robot1", "core.set", {"value": 3}, "t"))
        for _ in range(3):
            client.publish(to_agent("robot1"), goal)
            time.sleep(0.1)
        deadline = time.monotonic() + 5
        while sum(isinstance(m, protocol.Result) for m in got) < 3 and time.monotonic() < deadline:
            time.sleep(0.02)
        results = [m for m in got if isinstance(m, protocol.Result)]
        assert agent.server.executed == 1
        assert len(results) == 3 and {(r.outcome, r.data) for r in results} == {("ok", 3)}
    finally:
        client.close()


LOSABLE = NET.replace("in: [a], out: [b]}", "in: [a], out: [b], outcomes: {failed: [broken]}}").replace(
    "{seconds: 0.2}", "{seconds: 30}").replace("final: {o: 1}", "final: {broken: 1}")


@pytest.mark.slow
def test_an_agent_killed_mid_action_fails_its_firing_within_the_timeout(middleware, tmp_path):
    """The agent process is killed (SIGKILL) while its action runs: the firing ends failed within
    heartbeat_timeout + 1 s, the net's failure route fires, the agent is recorded lost."""
    import subprocess
    import sys
    import threading
    import time

    kind, server = middleware
    agent = subprocess.Popen([sys.executable, "-m", "petriflow.cli", "agent", "--name", "robot1", "--transport",
                              kind, "--connect", server.connect, "--heartbeat", "0.1"],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        net = write(tmp_path, kind, server.connect, net=LOSABLE, heartbeat=0.1, heartbeat_timeout=1.0)
        killed = []

        def kill_when_running():
            while not killed:
                time.sleep(0.05)
                if agent.poll() is not None:
                    return
                if (tmp_path / "started").exists():
                    agent.kill()
                    killed.append(time.monotonic())

        threading.Thread(target=kill_when_running, daemon=True).start()

        def mark(event):
            if event.kind == "start" and event.transition == "go":
                (tmp_path / "started").write_text("")

        result = session_run(net, tmp_path, mark)
        assert killed, "the agent was never killed"
        noticed = result[1]
        assert result[0].reason == "final" and result[0].marking.to_dict() == {"broken": 1}
        assert noticed - killed[0] < 1.0 + 1.0
        events = [json.loads(line) for line in (tmp_path / "t.jsonl").read_text().splitlines()]
        end = next(e for e in events if e["kind"] == "end" and e["transition"] == "go")
        assert end["data"]["outcome"] == "failed" and "lost" in end["data"]["reason"]
        assert any(e["kind"] == "fault" and e["data"]["fault"] == "lost" for e in events)
    finally:
        agent.kill()
        agent.wait(timeout=10)


def session_run(net, folder, on_event):
    """Run ``net`` as run_files does, calling ``on_event`` for each event; ``(result, wall time of the
    failed end)``."""
    import time

    from petriflow.bridge.orchestrator import AgentWatch, open_bridge
    from petriflow.runtime.assembly import open_run
    from petriflow.runtime.clock import RealtimeClock
    from petriflow.runtime.loading import read_run
    from petriflow.runtime.observers import run_observed
    from petriflow.runtime.validation import check_run

    checked = check_run(read_run(net))
    ended = []

    def watch(event):
        on_event(event)
        if event.kind == "end" and event.transition == "go":
            ended.append(time.monotonic())

    with open_bridge(checked.binding, checked.config.bridge) as remote, \
            open_run(checked, clock=RealtimeClock(), remote=remote) as scheduler:
        scheduler.on_instant(AgentWatch(remote, checked.net, checked.config.bridge))
        scheduler.on_event(watch)
        result = run_observed(scheduler, trace=folder / "t.jsonl")
    return result, ended[0]


CHAIN = """\
petriflow: 1
net: chain
subnets:
  - id: r1
    agent: r1
    places: [{id: a, tokens: 1}]
    transitions:
""" + "".join(f"      - {{id: s{i}, action: core.wait, params: {{seconds: 0.3}}, in: [{'a' if i == 0 else f'p{i}'}],"
              f" out: [p{i + 1}]}}\n" for i in range(10)) + """\
places: [""" + ", ".join(f"p{i}" for i in range(1, 11)) + """]
final: {p10: 1}
"""


@pytest.mark.slow
def test_a_broker_or_router_restarted_mid_run_is_survived_with_every_firing_once(middleware, serve, tmp_path):
    """The middleware goes away for a second and comes back: the run completes, every firing is in the
    trace once, and the agent executed each goal once."""
    import threading
    import time

    kind, server = middleware
    agent = serve(kind, server.connect, ["robot1"], heartbeat=0.1, log_file=open(tmp_path / "agent.log", "w"))
    net = write(tmp_path, kind, server.connect, net=CHAIN, heartbeat=0.2, heartbeat_timeout=5)

    def restart():
        time.sleep(1.0)
        if kind == "mqtt":
            server.stop()
            time.sleep(1.0)
            server.start()
        else:
            from petriflow.bridge.transport import Endpoint
            from petriflow.bridge.zenoh_transport import serve_router

            server.stop()
            time.sleep(1.0)
            server.session = serve_router(Endpoint(server.connect))

    threading.Thread(target=restart, daemon=True).start()
    result = run_files(net, trace=tmp_path / "t.jsonl")
    assert result.reason == "final" and result.firings == 10
    events = [json.loads(line) for line in (tmp_path / "t.jsonl").read_text().splitlines()]
    ends = [e["transition"] for e in events if e["kind"] == "end"]
    assert sorted(ends) == sorted(f"s{i}" for i in range(10)) and len(set(ends)) == 10
    agent.server.log_file.flush()
    goals = [json.loads(line)["goal"] for line in (tmp_path / "agent.log").read_text().splitlines()]
    assert len(goals) == len(set(goals)) == 10


@pytest.mark.slow
def test_hostile_messages_leave_the_run_unchanged_and_are_counted(broker, serve, tmp_path):
    """Malformed JSON, 10 MB, an unknown goal id, a replayed result and an unknown agent, sent while the
    run runs: it ends as it would have, and each is counted by reason."""
    import threading
    import time

    serve("mqtt", broker.connect, ["robot1"], heartbeat=0.1)
    net = write(tmp_path, "mqtt", broker.connect, net=CHAIN.replace("seconds: 0.3", "seconds: 0.1"))
    mallory = open_transport("mqtt", Endpoint(broker.connect), "mallory")
    seen = []

    def overhear(topic, data):
        try:
            seen.append(protocol.decode(data))
        except protocol.Refused:  # its own garbage
            pass

    mallory.subscribe(from_agent("robot1"), overhear)

    def attack():
        time.sleep(0.6)
        mallory.publish(from_agent("robot1"), b"{oops")
        mallory.publish(from_agent("robot1"), b"[" * (10 << 20))
        mallory.publish(from_agent("robot1"), protocol.encode(protocol.Result("nobody/1/1", "robot1", "ok")))
        result = next(m for m in seen if isinstance(m, protocol.Result))
        mallory.publish(from_agent("robot1"), protocol.encode(result))
        mallory.publish(from_agent("eve"), protocol.encode(protocol.Announce("eve", {})))

    try:
        threading.Thread(target=attack, daemon=True).start()
        result = run_files(net, trace=tmp_path / "t.jsonl")
    finally:
        mallory.close()
    assert result.reason == "final" and result.firings == 10
    dropped = {name.rpartition(".")[2]: count for name, count in result.metrics.items()
               if name.startswith("bridge.dropped.")}
    assert {reason: dropped.get(reason, 0) for reason in ("malformed", "oversized", "unknown_goal", "unknown_agent")} \
        == {"malformed": 1, "oversized": 1, "unknown_goal": 1, "unknown_agent": 1}
    assert dropped.get("replayed", 0) >= 1
    assert result.metrics["bridge.dropped"] == sum(dropped.values())


@pytest.mark.slow
def test_a_robot_in_plain_python_drives_a_net(broker, tmp_path):
    """examples/plain_robot_mqtt.py imports no petriflow, yet serves the net's remote transitions."""
    import subprocess
    import sys
    from pathlib import Path

    script = Path(__file__).resolve().parents[2] / "examples" / "plain_robot_mqtt.py"
    assert "petriflow" not in "".join(line for line in script.read_text().splitlines()
                                      if line.startswith(("import", "from")))
    assert len(script.read_text().splitlines()) < 100
    robot = subprocess.Popen([sys.executable, str(script), "--name", "robot1", "--port", str(broker.port)],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        net = write(tmp_path, "mqtt", broker.connect, net=NET.replace(
            "action: core.wait, params: {seconds: 0.2}", "action: robot.blink, params: {times: 2}").replace(
            "action: core.set, params: {value: {x: 1}}", "action: robot.blink, params: {}"))
        result = run_files(net)
        assert result.reason == "final" and result.tokens["o"] == [{"blinked": 3}]
        bad = write(tmp_path, "mqtt", broker.connect, net=NET.replace(
            "action: core.wait, params: {seconds: 0.2}", "action: robot.beep, params: {}"))
        with pytest.raises(NetFormatError, match="'go': action robot.beep on agent 'robot1' needs parameter 'hz'"):
            run_files(bad)
    finally:
        robot.kill()
        robot.wait(timeout=10)


@pytest.mark.slow
def test_a_configured_kill_of_a_remote_agent_cancels_its_firing(broker, serve, tmp_path):
    """A kill fault on a remote agent cancels its running goal on the agent (acknowledged)."""
    agent = serve("mqtt", broker.connect, ["robot1"], heartbeat=0.1)
    net = write(tmp_path, "mqtt", broker.connect, net=LOSABLE.replace("final: {broken: 1}", "final: {o: 1}"))
    (tmp_path / "run.yaml").write_text((tmp_path / "run.yaml").read_text() + "faults: [{kill: r1, at: 0.5}]\n")
    result = run_files(net, trace=tmp_path / "t.jsonl")
    assert result.reason == "dead"
    events = [json.loads(line) for line in (tmp_path / "t.jsonl").read_text().splitlines()]
    end = next(e for e in events if e["kind"] == "end" and e["transition"] == "go")
    assert end["data"]["outcome"] == "cancelled" and end["time"] < 2.0
    assert not agent.server.running  # the agent stopped it


@pytest.mark.slow
def test_authentication_is_required_when_configured(tmp_path, serve, monkeypatch):
    """A mosquitto with a password file: the run and the agent get in with their passwords; an agent
    without one does not (the run says it never announced itself)."""
    import subprocess

    from tests.bridge.conftest import Broker

    pytest.importorskip("paho.mqtt")
    passwords = tmp_path / "passwords"
    for user, password in (("orchestrator", "o-secret"), ("robot1", "r-secret")):
        subprocess.run(["mosquitto_passwd", "-b", *(["-c"] if user == "orchestrator" else []), str(passwords),
                        user, password], check=True)
    broker = Broker(tmp_path, passwords)
    try:
        monkeypatch.setenv("BRIDGE_PW", "o-secret")
        anonymous = serve("mqtt", broker.connect, ["robot1"], heartbeat=0.1)
        net = write(tmp_path, "mqtt", broker.connect, user="orchestrator", password_env="BRIDGE_PW", wait=1)
        with pytest.raises(NetFormatError, match="did not announce itself"):
            run_files(net)
        anonymous.stop()
        serve("mqtt", broker.connect, ["robot1"], user="robot1", password="r-secret", heartbeat=0.1)
        net = write(tmp_path, "mqtt", broker.connect, user="orchestrator", password_env="BRIDGE_PW", wait=10)
        assert run_files(net).reason == "final"
    finally:
        broker.stop()


@pytest.mark.slow
@pytest.mark.parametrize("kill_after", [1.0, 1.45])
def test_an_orchestrator_killed_mid_run_resumes_and_reattaches(broker, serve, tmp_path, kill_after):
    """The run process is killed (SIGKILL) while a goal runs on the agent; --resume replays the journal,
    re-attaches to the goal still running, and completes: every firing once, every goal executed once."""
    import os
    import signal
    import subprocess
    import sys
    import time

    from petriflow.runtime.session import resume

    agent = serve("mqtt", broker.connect, ["robot1"], heartbeat=0.1, log_file=open(tmp_path / "agent.log", "w"))
    net = write(tmp_path, "mqtt", broker.connect, net=CHAIN, heartbeat=0.1, heartbeat_timeout=5)
    db = tmp_path / "run.sqlite"
    run = subprocess.Popen([sys.executable, "-m", "petriflow.cli", "run", str(net), "--db", str(db), "--quiet"],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 30
    while not db.exists() and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(kill_after)
    os.kill(run.pid, signal.SIGKILL)
    run.wait(timeout=10)
    from petriflow.runtime.journal import Journal

    with Journal(db) as journal:
        assert 0 < journal.journaled and not journal.finished
        assert [e.kind for e in journal.events()].count("end") < 10
    result = resume(db, trace=tmp_path / "t.jsonl")
    assert result.reason == "final" and result.firings == 10
    events = [json.loads(line) for line in (tmp_path / "t.jsonl").read_text().splitlines()]
    ends = [e["transition"] for e in events if e["kind"] == "end"]
    assert sorted(ends) == sorted(f"s{i}" for i in range(10))
    agent.server.log_file.flush()
    goals = [json.loads(line)["goal"] for line in (tmp_path / "agent.log").read_text().splitlines()]
    assert len(goals) == len(set(goals)) == 10


RETRY = """\
petriflow: 1
net: retry
subnets:
  - id: r1
    agent: r1
    places: [{id: a, tokens: 1}, again]
    transitions:
      - {id: go, action: core.wait, params: {seconds: 30}, in: [a], out: [o], outcomes: {failed: [again]}}
      - {id: retry, action: core.set, params: {value: retried}, in: [again], out: [o]}
places: [o]
final: {o: 1}
"""


@pytest.mark.slow
def test_a_lost_agent_that_comes_back_is_a_late_joiner(broker, tmp_path):
    """Killed mid-action: its firing fails, it is lost; a new agent process of the same name announces
    itself: it is back, and its next transition fires on it."""
    import subprocess
    import sys
    import threading
    import time

    log = tmp_path / "agent.log"

    def start():
        return subprocess.Popen([sys.executable, "-m", "petriflow.cli", "agent", "--name", "robot1", "--transport",
                                 "mqtt", "--connect", broker.connect, "--heartbeat", "0.1", "--log", str(log)],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    agents = [start()]
    try:
        net = write(tmp_path, "mqtt", broker.connect, net=RETRY, heartbeat=0.1, heartbeat_timeout=1.0)

        def kill_then_restart():
            deadline = time.monotonic() + 60
            while not (log.exists() and log.read_text()) and time.monotonic() < deadline:
                time.sleep(0.05)  # until the goal runs on it
            agents[0].kill()
            time.sleep(2.0)  # lost by now
            agents.append(start())

        threading.Thread(target=kill_then_restart, daemon=True).start()
        result = run_files(net, trace=tmp_path / "t.jsonl")
        assert result.reason == "final" and result.tokens["o"] == ["retried"]
        events = [json.loads(line) for line in (tmp_path / "t.jsonl").read_text().splitlines()]
        kinds = [(e["kind"], e["data"].get("fault") or e["transition"]) for e in events
                 if e["kind"] in ("fault", "end")]
        assert kinds == [("fault", "lost"), ("end", "go"), ("fault", "back"), ("end", "retry")] or \
            kinds == [("end", "go"), ("fault", "lost"), ("fault", "back"), ("end", "retry")]
    finally:
        for agent in agents:
            agent.kill()
            agent.wait(timeout=10)


@pytest.mark.parametrize("bridge, message", [
    ("{transport: tcp, agents: {r1: x}}", r"run.yaml:2: bridge: unknown transport 'tcp' \(one of: zenoh, mqtt\)"),
    ("{transport: mqtt, agents: {rr1: x}}", r"run.yaml:2: bridge: agents: 'rr1' is no subnet of net 'relay'"
                                           r" \(did you mean 'r1'\?\)"),
    ("{transport: mqtt, agents: {r1: 'a b'}}", r"run.yaml:2: bridge: agents: 'r1': an agent name is"),
    ("{transport: mqtt, agents: {r1: x}, heartbeat: 2, heartbeat_timeout: 1}",
     r"run.yaml:2: bridge: heartbeat_timeout \(1 s\) must be longer than heartbeat \(2 s\)"),
    ("{transport: mqtt, agents: {r1: x}, wiat: 3}", r"run.yaml:2: bridge: unknown key 'wiat' \(did you mean 'wait'\?\)"),
])
def test_a_bad_bridge_section_is_one_line_at_its_line(tmp_path, bridge, message):
    (tmp_path / "net.yaml").write_text(NET)
    (tmp_path / "run.yaml").write_text(f"seed: 1\nbridge: {bridge}\n")
    with pytest.raises(NetFormatError, match=message):
        run_files(tmp_path / "net.yaml", db=tmp_path / "run.sqlite")
    assert not (tmp_path / "run.sqlite").exists()


def test_an_action_taking_resources_cannot_be_put_on_a_remote_agent(tmp_path):
    """Resources are not served to remote agents (ports are: tests/bridge/test_calls.py):
    refused at bind time, at the line, before anything is written."""
    from petriflow import Action, Status
    from petriflow.runtime.registry import Registry

    registry = Registry()

    class Planner(Action):
        resources = {"plan": dict}

        def poll(self, ctx):
            return Status.OK

    registry.register("demo.plan", Planner)
    (tmp_path / "net.yaml").write_text(NET.replace("action: core.set, params: {value: {x: 1}}",
                                                   "action: demo.plan"))
    (tmp_path / "run.yaml").write_text("seed: 1\nbridge: {transport: mqtt, agents: {r1: x}}\n")
    with pytest.raises(NetFormatError, match=r"net.yaml:9: 'mark': action demo.plan takes the run's resource\(s\)"
                                             r" plan, which are not served to remote agents"):
        run_files(tmp_path / "net.yaml", registry=registry, db=tmp_path / "run.sqlite")
    assert not (tmp_path / "run.sqlite").exists()
