"""Brokers and routers on loopback for the bridge's tests, each stopped by its test.

Every fixture that starts a process stops it and checks it is gone; ``mosquitto`` is
the broker ``scripts/setup.sh`` installs, the Zenoh router a session of this process.
"""

from __future__ import annotations

import getpass
import os
import shutil
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from petriflow.bridge.transport import Endpoint, open_transport, wait_for_port


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def mosquitto_binary() -> str | None:
    return shutil.which("mosquitto") or ("/usr/sbin/mosquitto" if Path("/usr/sbin/mosquitto").exists() else None)


class Broker:
    """A mosquitto on a free loopback port (small messages at once: TCP_NODELAY)."""

    def __init__(self, folder: Path, passwords: Path | None = None) -> None:
        binary = mosquitto_binary()
        if binary is None:
            pytest.skip("mosquitto is not installed (scripts/setup.sh installs it)")
        self.binary, self.port = binary, free_port()
        self.conf = folder / "mosquitto.conf"
        access = "allow_anonymous true\n" if passwords is None else f"allow_anonymous false\npassword_file {passwords}\n"
        # as root, mosquitto would become user 'mosquitto', who cannot read the test's files
        self.conf.write_text(f"listener {self.port} 127.0.0.1\n{access}set_tcp_nodelay true\n"
                             f"user {getpass.getuser()}\n")
        self.process: subprocess.Popen | None = None
        self.start()

    @property
    def connect(self) -> str:
        return f"tcp/127.0.0.1:{self.port}"

    def start(self) -> None:
        self.process = subprocess.Popen([self.binary, "-c", str(self.conf)], stdout=subprocess.DEVNULL,
                                        stderr=subprocess.DEVNULL)
        wait_for_port(self.port)

    def stop(self) -> None:
        if self.process is not None:
            self.process.terminate()
            self.process.wait(timeout=10)
            self.process = None


class Router:
    """A Zenoh router (a session of this process) on a free loopback port."""

    def __init__(self) -> None:
        pytest.importorskip("zenoh")
        from petriflow.bridge.zenoh_transport import serve_router

        self.port = free_port()
        self.session = serve_router(Endpoint(self.connect))
        wait_for_port(self.port)

    @property
    def connect(self) -> str:
        return f"tcp/127.0.0.1:{self.port}"

    def stop(self) -> None:
        if self.session is not None:
            self.session.close()
            self.session = None


class Link:
    """A TCP proxy on a free loopback port to ``port`` that the test can cut and restore: a
    network partition between one client and the broker or router, with nobody killed.

    Cut, it closes its listener and every connection through it (the client's reconnects
    are refused); restored, it listens on the same port again.
    """

    def __init__(self, port: int) -> None:
        self.target, self.port = port, free_port()
        self.lock = threading.Lock()
        self.sockets: list[socket.socket] = []
        self.listener: socket.socket | None = None
        self.threads: list[threading.Thread] = []
        self.restore()

    @property
    def connect(self) -> str:
        return f"tcp/127.0.0.1:{self.port}"

    def restore(self) -> None:
        listener = socket.socket()
        listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        listener.bind(("127.0.0.1", self.port))
        listener.listen()
        self.listener = listener
        self._thread(self._accept, listener)

    def cut(self) -> None:
        with self.lock:
            doomed, self.sockets = [self.listener, *self.sockets], []
            self.listener = None
        for sock in doomed:
            try:
                sock.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
            sock.close()

    def stop(self) -> None:
        self.cut()
        for thread in self.threads:
            thread.join(timeout=10)
        assert not any(thread.is_alive() for thread in self.threads)

    def _thread(self, target, *args) -> None:
        thread = threading.Thread(target=target, args=args, daemon=True)
        self.threads.append(thread)
        thread.start()

    def _accept(self, listener: socket.socket) -> None:
        while True:
            try:
                client, _ = listener.accept()
            except OSError:  # cut
                return
            server = socket.create_connection(("127.0.0.1", self.target))
            for sock in (client, server):
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            with self.lock:
                if self.listener is not listener:  # cut meanwhile
                    client.close()
                    server.close()
                    return
                self.sockets += [client, server]
            self._thread(self._pipe, client, server)
            self._thread(self._pipe, server, client)

    @staticmethod
    def _pipe(source: socket.socket, sink: socket.socket) -> None:
        try:
            while data := source.recv(65536):
                sink.sendall(data)
        except OSError:
            pass
        for sock in (source, sink):
            try:
                sock.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass


def children() -> set[int]:
    """The live processes whose parent is this one (from /proc; zombies count as gone)."""
    found = set()
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == os.getpid() and fields[0] != "Z":
            found.add(int(entry.name))
    return found


@pytest.fixture(autouse=True)
def no_process_left():
    """Every bridge test stops every process it started (the broker, agents, a run)."""
    before = children()
    yield
    deadline = time.monotonic() + 10
    while children() - before and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not children() - before, "a test left processes running"


@pytest.fixture
def broker(tmp_path):
    pytest.importorskip("paho.mqtt")
    made = Broker(tmp_path)
    yield made
    made.stop()
    assert made.process is None


@pytest.fixture
def router():
    made = Router()
    yield made
    made.stop()


@pytest.fixture(params=["mqtt", "zenoh"])
def middleware(request, tmp_path):
    """``(transport name, the broker or router)`` for each transport."""
    made = start_middleware(request.param, tmp_path)
    yield request.param, made
    made.stop()


def start_middleware(kind: str, folder: Path) -> Broker | Router:
    """A broker (``mqtt``) or a router (``zenoh``) on loopback; the caller stops it."""
    if kind == "mqtt":
        pytest.importorskip("paho.mqtt")
        return Broker(folder)
    return Router()


#: Set in the test process started inside a network namespace of its own (:func:`own_network`).
INSIDE = "PETRIFLOW_TEST_OWN_NETWORK"


def shipped_config(folder: Path, kind: str, server, out: Path) -> Path:
    """A shipped net's ``run-KIND.yaml`` from ``folder``, its endpoint the test's ``server``
    and its world the folder's, written into ``out``."""
    config = (folder / f"run-{kind}.yaml").read_text().replace(
        f"connect: tcp/127.0.0.1:{7447 if kind == 'zenoh' else 1883}", f"connect: {server.connect}")
    assert server.connect in config
    (out / "run.yaml").write_text(config.replace("world: world.yaml", f"world: {folder / 'world.yaml'}"))
    return out / "run.yaml"


def agent_command(names, kind: str, server, world: Path, log: Path, *extra: str) -> list[str]:
    """``petriflow agent`` serving ``names`` with its own ``world``, one line per goal in ``log``."""
    return [sys.executable, "-m", "petriflow.cli", "agent", *[a for name in names for a in ("--name", name)],
            "--transport", kind, "--connect", server.connect, "--world", str(world), *extra, "--log", str(log)]


def own_network(request) -> bool:
    """Run the calling test again in a network namespace of its own (``unshare -n``, loopback
    up, everything it starts inside it) when this machine permits one; ``True`` when it did
    (and passed there), so the caller returns; ``False`` inside it, or where no namespace is
    permitted (the test then runs here, on the shared loopback)."""
    if os.environ.get(INSIDE) or shutil.which("unshare") is None or shutil.which("ip") is None:
        return False
    if subprocess.run(["unshare", "-n", "ip", "link", "set", "lo", "up"], capture_output=True, check=False).returncode != 0:
        return False
    root = Path(__file__).resolve().parents[2]
    inner = subprocess.run(["unshare", "-n", "sh", "-c", 'ip link set lo up && exec "$0" "$@"', sys.executable,
                            "-m", "pytest", "-q", "-p", "no:randomly", "-m", "slow", request.node.nodeid],
                           cwd=root, env={**os.environ, INSIDE: "1"}, capture_output=True, text=True, timeout=300, check=False)
    assert inner.returncode == 0, inner.stdout[-3000:] + inner.stderr[-2000:]
    return True


@pytest.fixture
def link():
    """``link(port)``: a :class:`Link` to ``port``, stopped after the test."""
    made: list[Link] = []

    def start(port: int) -> Link:
        made.append(Link(port))
        return made[-1]

    yield start
    for each in made:
        each.stop()


class ServedAgent:
    """An agent server in a thread of the test, with its own connection."""

    def __init__(self, kind: str, connect: str, names: list[str], user: str | None = None,
                 password: str | None = None, **options) -> None:
        from petriflow.bridge.agent import AgentServer

        self.transport = open_transport(kind, Endpoint(connect, user, password), "-".join(names))
        self.server = AgentServer(names, self.transport, **options)
        self.thread = threading.Thread(target=self.server.serve, daemon=True)
        self.thread.start()

    def stop(self) -> None:
        self.server.stop()
        self.thread.join(timeout=10)
        self.transport.close()
        assert not self.thread.is_alive()


@pytest.fixture
def serve():
    """``serve(kind, connect, names, **options)``: an agent server in a thread, stopped after the test."""
    started: list[ServedAgent] = []

    def start(kind: str, connect: str, names: list[str], **options) -> ServedAgent:
        agent = ServedAgent(kind, connect, names, **options)
        started.append(agent)
        return agent

    yield start
    for agent in started:
        agent.stop()
