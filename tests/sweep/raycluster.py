"""A real Ray cluster on this machine for the sweep tests: a head node and worker nodes,
each its own ``ray start --block`` process tree, as a person would start them.

Everything runs inside a user, network and PID namespace of its own (``unshare``):
there only the loopback interface exists, so every node registers 127.0.0.1 and no
server is reachable from outside; when the cluster is closed, the namespace's first
process ends and the kernel ends every process left in it (nothing is stopped by
name, so another Ray on the machine is never touched). The cluster uses token
authentication, with a token of its own passed to every process in the environment,
and finds ``ray`` and ``petriflow`` on ``PATH`` (this Python's ``bin`` folder first),
as in a shell with the environment activated.
"""

from __future__ import annotations

import os
import secrets
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

#: Ray's checks of a node's health, made fast so a killed node is declared dead in a
#: second or two (Ray's defaults take about 15 s).
FAST_HEALTH = {"RAY_health_check_period_ms": "300", "RAY_health_check_timeout_ms": "300",
               "RAY_health_check_failure_threshold": "3", "RAY_health_check_initial_delay_ms": "0"}


def _die_with_parent() -> None:
    """In the namespace's holder: end (and so end the whole namespace) when the test
    process ends, however it ends."""
    import ctypes

    try:
        ctypes.CDLL(None).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


def available() -> str | None:
    """Why a cluster cannot be made here, or ``None``."""
    if shutil.which("unshare") is None or shutil.which("nsenter") is None:
        return "unshare/nsenter missing"
    try:
        import ray  # noqa: F401
    except ImportError:
        return "ray is not installed"
    probe = subprocess.run(["unshare", "-rnpf", "--mount-proc", "sh", "-c", "ip link set lo up"],
                           capture_output=True, text=True)
    if probe.returncode != 0:
        return f"no user/network namespaces here: {probe.stderr.strip()}"
    return None


class Cluster:
    """A Ray cluster in namespaces of its own; :meth:`run` and :meth:`popen` run
    commands there (a sweep's driver, say)."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        folder.mkdir(parents=True, exist_ok=True)
        self.bin = Path(sys.executable).parent
        self.env = dict(os.environ, RAY_AUTH_MODE="token", RAY_AUTH_TOKEN=secrets.token_hex(16),
                        RAY_USAGE_STATS_ENABLED="0", **FAST_HEALTH)
        self.env["PATH"] = f"{self.bin}{os.pathsep}{self.env.get('PATH', '')}"
        self.env.pop("RAY_ADDRESS", None)
        self.holder = subprocess.Popen(
            ["unshare", "-rnpf", "--mount-proc", "--kill-child", "sh", "-c", "ip link set lo up && exec sleep 1800"],
            stdin=subprocess.DEVNULL, start_new_session=True, preexec_fn=_die_with_parent)
        deadline = time.monotonic() + 20
        self.target: int | None = None
        while time.monotonic() < deadline and self.target is None:
            children = Path(f"/proc/{self.holder.pid}/task/{self.holder.pid}/children")
            text = children.read_text().split() if children.exists() else []
            if text:
                self.target = int(text[0])
            else:
                time.sleep(0.05)
        if self.target is None:
            raise RuntimeError("the namespace did not start")
        time.sleep(0.2)  # lo up
        self.nodes: list[subprocess.Popen] = []
        self.address = "127.0.0.1:6379"

    def command(self, argv: list[str], cwd: str | Path | None = None) -> list[str]:
        """``argv`` run in the namespaces (in ``cwd``: entering the mount namespace
        would otherwise leave it in ``/``)."""
        where = [f"--wd={cwd}"] if cwd is not None else []
        return ["nsenter", "-t", str(self.target), "-U", "-n", "-p", "-m", "--preserve-credentials", *where, *argv]

    def run(self, argv: list[str], **options) -> subprocess.CompletedProcess:
        return subprocess.run(self.command(argv, options.pop("cwd", None)), env=options.pop("env", self.env),
                              **options)

    def popen(self, argv: list[str], **options) -> subprocess.Popen:
        return subprocess.Popen(self.command(argv, options.pop("cwd", None)), env=options.pop("env", self.env),
                                start_new_session=True, **options)

    def _node(self, argv: list[str], log: str) -> subprocess.Popen:
        handle = open(self.folder / log, "w")
        node = self.popen(argv, stdout=handle, stderr=subprocess.STDOUT)
        self.nodes.append(node)
        return node

    def start_head(self, cpus: int = 1, dashboard: bool = False) -> subprocess.Popen:
        """The head node; with ``dashboard``, Ray's dashboard and job server too (it needs
        ``ray[default]``), at :attr:`jobs` (``ray job submit --address ...``)."""
        flags = (["--include-dashboard=true", "--dashboard-host", "127.0.0.1", "--dashboard-port", "8265"]
                 if dashboard else ["--include-dashboard=false"])
        head = self._node([str(self.bin / "ray"), "start", "--head", "--block", "--port", "6379",
                           "--num-cpus", str(cpus), "--node-ip-address", "127.0.0.1", *flags,
                           "--disable-usage-stats"], "head.log")
        self.started(head, "head.log")
        if dashboard:
            self.answers(self.jobs)
        return head

    #: The job server's address, on a head started with ``dashboard=True``.
    jobs = "http://127.0.0.1:8265"

    def answers(self, address: str, timeout: float = 120) -> None:
        """Wait until the job server at ``address`` lists jobs (``ray job list``)."""
        deadline = time.monotonic() + timeout
        while True:
            try:
                done = self.run([str(self.bin / "ray"), "job", "list", "--address", address], capture_output=True,
                                text=True, timeout=60)
            except subprocess.TimeoutExpired:
                done = None
            if done is not None and done.returncode == 0:
                return
            if time.monotonic() > deadline:
                why = done.stderr[-600:] if done is not None else "ray job list did not answer"
                raise RuntimeError(f"the job server at {address} does not answer: {why}")
            time.sleep(0.5)

    def add_worker(self, cpus: int = 1, bin_folder: Path | None = None, log: str = "worker.log",
                   env: dict[str, str] | None = None) -> subprocess.Popen:
        """A worker node (``bin_folder``: the ``bin`` of another Python environment;
        ``env``: more environment variables for it)."""
        folder = bin_folder or self.bin
        env = dict(self.env, PATH=f"{folder}{os.pathsep}{self.env.get('PATH', '')}", **(env or {}))
        env.pop("VIRTUAL_ENV", None)
        handle = open(self.folder / log, "w")
        node = self.popen([str(folder / "ray"), "start", "--block", "--address", self.address,
                           "--num-cpus", str(cpus), "--node-ip-address", "127.0.0.1"],
                          stdout=handle, stderr=subprocess.STDOUT, env=env)
        self.nodes.append(node)
        self.started(node, log)
        return node

    def started(self, node: subprocess.Popen, log: str, timeout: float = 120) -> None:
        """Wait until ``ray start`` says the node runs (it has joined the cluster)."""
        deadline = time.monotonic() + timeout
        path = self.folder / log
        while time.monotonic() < deadline:
            if "Ray runtime started" in path.read_text(errors="replace"):
                return
            if node.poll() is not None:
                break
            time.sleep(0.2)
        raise RuntimeError(f"the node did not start: {path.read_text(errors='replace')[-600:]}")

    def alive(self) -> int:
        script = ("import ray; ray.init(address='auto', logging_level='ERROR');"
                  " print(sum(1 for n in ray.nodes() if n['Alive']))")
        out = self.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
        return int(out.stdout.split()[-1]) if out.returncode == 0 and out.stdout.split() else -1

    def wait_for(self, count: int, timeout: float = 90) -> None:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.alive() == count:
                return
            time.sleep(0.5)
        logs = " | ".join(p.name + ": " + p.read_text()[-400:] for p in self.folder.glob("*.log"))
        raise RuntimeError(f"the cluster did not reach {count} live nodes: {logs}")

    @staticmethod
    def kill(node: subprocess.Popen) -> None:
        """Kill a node like a lost machine: its whole process tree, SIGKILL."""
        try:
            os.killpg(node.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        node.wait(10)

    def close(self) -> None:
        for node in self.nodes:
            self.kill(node)
        self.holder.kill()  # the namespace's first process: the kernel ends the rest
        self.holder.wait(10)
