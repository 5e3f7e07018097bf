"""Round trip and throughput of the bridge over Zenoh and MQTT, beside the bare transport.

    python bench/bridge.py [--goals 2000] [--burst 10000 --names 50 --processes 4] [--json OUT]

For each transport it starts the middleware on a free loopback port (``petriflow
router`` for Zenoh, ``mosquitto`` for MQTT) and measures:

* **round trip**: one goal at a time to a ``petriflow agent`` process serving an action
  that ends at once (``core.noop``): goal sent -> result received, median and p99;
  beside it, the peer: the same transport's bare ping-pong (an echo process, no
  protocol, no agent), so the ratio is what the protocol and the agent add;
* **cancel**: a goal that runs a minute, cancelled once accepted: cancel sent ->
  ``cancelled`` received (100 times);
* **burst**: ``--burst`` goals sent at once to ``--names`` agent names served by
  ``--processes`` agent processes: goals per second, and how many were lost (no result
  within 300 s of the last send) or executed twice (the agents' logs).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from petriflow.bridge import protocol
from petriflow.bridge.dispatcher import Dispatcher
from petriflow.bridge.spec import BridgeSpec
from petriflow.bridge.transport import Endpoint, open_transport, wait_for_port


#: Seconds after the last goal of a burst was sent at which a goal without a result counts as lost.
LATE = 300.0


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def start_middleware(kind: str, folder: Path) -> tuple[subprocess.Popen, str]:
    port = free_port()
    if kind == "mqtt":
        binary = shutil.which("mosquitto") or "/usr/sbin/mosquitto"
        conf = folder / "mosquitto.conf"
        conf.write_text(f"listener {port} 127.0.0.1\nallow_anonymous true\nset_tcp_nodelay true\n"
                        "max_queued_messages 100000\nmax_inflight_messages 1000\n")
        process = subprocess.Popen([binary, "-c", str(conf)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    else:
        process = subprocess.Popen([sys.executable, "-m", "petriflow.cli", "router", "--listen",
                                    f"tcp/127.0.0.1:{port}"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wait_for_port(port, 20)
    return process, f"tcp/127.0.0.1:{port}"


def stop(processes: list[subprocess.Popen]) -> None:
    for process in processes:
        process.send_signal(signal.SIGTERM)
    for process in processes:
        try:
            process.wait(timeout=20)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


def echo(kind: str, connect: str) -> None:
    """The peer's far end: send back whatever comes on ``bench/ping`` (no protocol)."""
    transport = open_transport(kind, Endpoint(connect), "echo")
    transport.subscribe("bench/ping", lambda topic, data: transport.publish("bench/pong", data))
    done = threading.Event()
    signal.signal(signal.SIGTERM, lambda *a: done.set())
    done.wait()
    transport.close()


def bare_round_trip(kind: str, connect: str, count: int) -> list[float]:
    process = subprocess.Popen([sys.executable, __file__, "--echo", kind, connect])
    transport = open_transport(kind, Endpoint(connect), "ping")
    got = threading.Event()
    transport.subscribe("bench/pong", lambda topic, data: got.set())
    try:
        for _ in range(200):  # until the echo is there
            got.clear()
            transport.publish("bench/ping", b"x")
            if got.wait(0.1):
                break
        times = []
        payload = protocol.encode(protocol.Goal("r/1/1", "a0", "core.noop", {}))  # the same size as a goal
        for _ in range(count):
            got.clear()
            began = time.perf_counter()
            transport.publish("bench/ping", payload)
            got.wait(5)
            times.append(time.perf_counter() - began)
        return times
    finally:
        transport.close()
        stop([process])


def agents(kind: str, connect: str, names: list[str], processes: int, folder: Path) -> list[subprocess.Popen]:
    groups = [names[i::processes] for i in range(processes)]
    started = []
    for i, group in enumerate(groups):
        command = [sys.executable, "-m", "petriflow.cli", "agent", "--transport", kind, "--connect", connect,
                   "--log", str(folder / f"agent{i}.log")]
        for name in group:
            command += ["--name", name]
        started.append(subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
    return started


def measure(kind: str, goals: int, burst: int, names: int, processes: int, cancels: int = 100) -> dict:
    folder = Path(tempfile.mkdtemp(prefix="petriflow-bench-bridge-"))
    middleware, connect = start_middleware(kind, folder)
    row: dict = {"transport": kind}
    try:
        bare = bare_round_trip(kind, connect, goals)
        row["bare_median_ms"] = statistics.median(bare) * 1e3
        row["bare_p99_ms"] = percentile(bare, 0.99) * 1e3
        agent_names = [f"a{i}" for i in range(names)]
        spec = BridgeSpec.from_dict({"transport": kind, "connect": connect,
                                     "agents": {name: name for name in agent_names}, "wait": 30})
        started = agents(kind, connect, agent_names, processes, folder)
        try:
            with Dispatcher(spec) as dispatcher:
                missing = dispatcher.wait_for(30)
                if missing:
                    raise RuntimeError(f"agents did not announce themselves: {missing}")
                trips = []
                for i in range(goals):
                    state = dispatcher.send(protocol.Goal(protocol.goal_id(dispatcher.run, i), "a0", "core.noop", {}))
                    state = dispatcher.wait_goal(state.goal.id, 5)
                    trips.append(state.round_trip if state.ended else float("inf"))
                row["median_ms"] = statistics.median(trips) * 1e3
                row["p99_ms"] = percentile(trips, 0.99) * 1e3
                acks = []
                for i in range(cancels):  # a goal that runs a minute, cancelled once it runs
                    goal = protocol.Goal(protocol.goal_id(dispatcher.run, goals + burst + i), "a0", "core.wait",
                                         {"seconds": 60.0})
                    state = dispatcher.send(goal)
                    while state.phase != "accepted" and not state.ended:
                        time.sleep(0.001)
                    began = time.perf_counter()
                    dispatcher.cancel(goal.id)
                    state = dispatcher.wait_goal(goal.id, 5)
                    acks.append(time.perf_counter() - began if state.phase == "cancelled" else float("inf"))
                row["cancel_median_ms"] = statistics.median(acks) * 1e3
                row["cancel_max_ms"] = max(acks) * 1e3
                began = time.perf_counter()
                ids = []
                for i in range(burst):
                    goal = protocol.Goal(protocol.goal_id(dispatcher.run, goals + i), agent_names[i % names],
                                         "core.noop", {})
                    dispatcher.send(goal)
                    ids.append(goal.id)
                deadline = time.perf_counter() + LATE
                ended = sum(1 for goal_id in ids
                            if dispatcher.wait_goal(goal_id, max(0.0, deadline - time.perf_counter())).ended)
                row["burst_s"] = time.perf_counter() - began
                row["burst_goals_per_s"] = ended / row["burst_s"]
                row["lost"] = burst - ended
                row["resent"] = sum(state.resent for state in dispatcher.goals.values())
        finally:
            stop(started)
        executed = []
        for i in range(processes):
            log = folder / f"agent{i}.log"
            executed += [json.loads(line)["goal"] for line in log.read_text().splitlines()] if log.exists() else []
        row["executed"] = len(executed)
        row["duplicated"] = len(executed) - len(set(executed))
    finally:
        stop([middleware])
        shutil.rmtree(folder, ignore_errors=True)
    return row


def table(rows: list[dict]) -> str:
    """The rows as the Markdown table docs/benchmarks.md shows."""
    lines = ["| transport | median ms | p99 ms | bare transport median ms | ÷ bare | cancel acknowledged ms"
             " (median / max) | burst goals/s | lost | executed twice |", "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    lines += [f"| {r['transport']} | {r['median_ms']:.3f} | {r['p99_ms']:.3f} | {r['bare_median_ms']:.3f} |"
              f" {r['median_ms'] / r['bare_median_ms']:.1f}× | {r['cancel_median_ms']:.2f} / {r['cancel_max_ms']:.2f} |"
              f" {r['burst_goals_per_s']:,.0f} | {r['lost']} | {r['duplicated']} |" for r in rows]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--goals", type=int, default=2000, help="goals one at a time (round trip)")
    parser.add_argument("--burst", type=int, default=10_000, help="goals sent at once")
    parser.add_argument("--names", type=int, default=50, help="agent names")
    parser.add_argument("--processes", type=int, default=4, help="agent processes serving them")
    parser.add_argument("--transports", nargs="+", default=["zenoh", "mqtt"])
    parser.add_argument("--json", help="write the rows as JSON")
    parser.add_argument("--echo", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.echo:
        echo(*args.echo)
        return []
    rows = [measure(kind, args.goals, args.burst, args.names, args.processes) for kind in args.transports]
    print(f"round trip of a goal whose action ends at once ({args.goals} goals), and a burst of {args.burst:,}"
          f" goals to {args.names} agent names in {args.processes} processes; load {os.getloadavg()[0]:.1f}")
    print()
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    print(table(rows))
    return rows


if __name__ == "__main__":
    main()
