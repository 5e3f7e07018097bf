"""Sweeps on a real Ray cluster: a head node and a worker node started with ``ray start``,
token authentication, the driver run as a user runs it (``petriflow sweep --backend
ray --ray-address 127.0.0.1:6379``, or on the head through ``ray job submit``), a node
killed mid-sweep.

The cluster lives in namespaces of its own (``tests/sweep/raycluster.py``); these tests
are ``slow`` (CI runs them) and skip where namespaces or Ray are missing.
"""

from __future__ import annotations

import json
import re
import shutil
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest

from petriflow.sweep import load_sweep, run_sweep

from .conftest import write
from .raycluster import Cluster, available

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(available() is not None, reason=f"no Ray cluster here: {available()}")]


def sleepy_sweep(folder: Path, tmp_path: Path, trials: int, wall: float = 0.4) -> Path:
    """Two rows of random waits (each seed its own), each trial sleeping ``wall`` seconds."""
    return write(tmp_path, "cluster.yaml", f"""\
        petriflow-sweep: 1
        net: {folder}/odd.yaml
        trials: {trials}
        timeout: 60
        matrix: {{mean: [1.0, 4.0]}}
        set: {{net.transitions.wait.params.mean: "${{mean}}", net.transitions.sleep.params.wall: {wall}}}
        metrics:
          time_s: core.end_time
          waited: {{metric: core.reported, name: waited, field: seconds}}
          outcome: core.outcome
        """)


def recorded(db: Path) -> list[tuple]:
    with sqlite3.connect(db) as connection:
        return connection.execute("SELECT row, params, seed, status, outcome, metrics FROM trials"
                                  " ORDER BY row, seed").fetchall()


def count(db: Path) -> int:
    if not db.exists():  # (connecting would create it)
        return 0
    try:
        with sqlite3.connect(db) as connection:
            return connection.execute("SELECT COUNT(*) FROM trials").fetchone()[0]
    except sqlite3.Error:
        return 0


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    made = Cluster(tmp_path_factory.mktemp("ray-cluster"))
    try:
        made.start_head(cpus=1)
        made.add_worker(cpus=1)
        yield made
    finally:
        made.close()


def sweep_command(cluster: Cluster, spec: Path, db: Path, *extra: str) -> list[str]:
    return [sys.executable, "-m", "petriflow.cli", "sweep", str(spec), "--backend", "ray",
            "--ray-address", cluster.address, "--db", str(db), "--quiet", *extra]


def test_a_killed_node_s_trials_run_again_and_the_json_stays_clean(cluster, folder, tmp_path):
    spec = sleepy_sweep(folder, tmp_path, trials=8)
    clean = tmp_path / "clean.sqlite"
    run_sweep(load_sweep(spec), workers=2, db=clean)  # the local pool: what the cluster must give
    db = tmp_path / "cluster.sqlite"
    driver = cluster.popen(sweep_command(cluster, spec, db, "--json"), stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 180
    while count(db) < 3 and driver.poll() is None and time.monotonic() < deadline:
        time.sleep(0.1)
    assert driver.poll() is None, driver.stderr.read()
    cluster.kill(cluster.nodes[-1])  # the worker node, mid-sweep
    stdout, stderr = driver.communicate(timeout=240)
    document = json.loads(stdout)  # nothing but the report on standard output
    assert [row["trials"] for row in document["rows"]] == [8, 8]
    assert driver.returncode == 0, stderr
    assert "is gone" in stderr and "\x1b[" not in stderr
    assert recorded(db) == recorded(clean)
    cluster.add_worker(cpus=1, log="worker2.log")


def test_a_trials_timeout_counts_from_its_start_on_a_worker_not_from_the_queue(cluster, folder, tmp_path):
    """Six trials of 1.5 wall seconds, a timeout of 4 s, more workers asked than the
    cluster's two CPUs: the later trials wait in the queue, none times out."""
    spec = sleepy_sweep(folder, tmp_path, trials=3, wall=1.5)
    spec.write_text(spec.read_text().replace("timeout: 60", "timeout: 4"))
    db = tmp_path / "queue.sqlite"
    done = cluster.run(sweep_command(cluster, spec, db, "--workers", "8", "--json"), capture_output=True, text=True,
                       timeout=240)
    assert done.returncode == 0, done.stderr
    with sqlite3.connect(db) as connection:
        assert connection.execute("SELECT status, COUNT(*) FROM trials GROUP BY status").fetchall() == [("ok", 6)]


def test_resume_reruns_trials_recorded_as_crashed(cluster, folder, tmp_path):
    spec = sleepy_sweep(folder, tmp_path, trials=3, wall=0.0)
    clean = tmp_path / "clean.sqlite"
    run_sweep(load_sweep(spec), workers=2, db=clean)
    db = tmp_path / "cluster.sqlite"
    first = cluster.run(sweep_command(cluster, spec, db), capture_output=True, text=True, timeout=240)
    assert first.returncode == 0, first.stderr
    with sqlite3.connect(db) as connection:  # as a node lost past the retries leaves them
        connection.execute("UPDATE trials SET status = 'crashed', metrics = '{}', outcome = NULL"
                           " WHERE seed = 2")
    again = cluster.run(sweep_command(cluster, spec, db, "--resume", "--json"), capture_output=True, text=True,
                        timeout=240)
    assert again.returncode == 0, again.stderr
    assert [row["failed"] for row in json.loads(again.stdout)["rows"]] == [0, 0]
    assert recorded(db) == recorded(clean)


def test_an_unreachable_cluster_leaves_no_database(cluster, folder, tmp_path):
    spec = sleepy_sweep(folder, tmp_path, trials=1, wall=0.0)
    db = tmp_path / "never.sqlite"
    command = sweep_command(cluster, spec, db)
    command[command.index(cluster.address)] = "127.0.0.1:6390"
    failed = cluster.run(command, capture_output=True, text=True, timeout=240)
    assert failed.returncode == 2
    assert "cannot start or reach the cluster at 127.0.0.1:6390" in failed.stderr
    assert not db.exists()
    # the same command, pointed right, then runs (no "already exists")
    command[command.index("127.0.0.1:6390")] = cluster.address
    assert cluster.run(command, capture_output=True, text=True, timeout=240).returncode == 0


def test_a_cluster_with_token_authentication_refuses_a_driver_without_the_token(cluster, folder, tmp_path):
    spec = sleepy_sweep(folder, tmp_path, trials=1, wall=0.0)
    env = dict(cluster.env)
    env.pop("RAY_AUTH_TOKEN")
    env["RAY_AUTH_TOKEN_PATH"] = str(tmp_path / "no-token")
    failed = cluster.run(sweep_command(cluster, spec, tmp_path / "x.sqlite"), capture_output=True, text=True,
                         timeout=240, env=env)
    assert failed.returncode == 2
    assert "token" in failed.stderr.splitlines()[-1]
    assert len(failed.stderr.strip().splitlines()) == 1


@pytest.fixture(scope="module")
def bare_python(tmp_path_factory) -> Path:
    """A virtual environment with only Ray (and virtualenv, which Ray's pip runtime
    environments need: ``ray[default]`` brings it), from the package index."""
    import ray

    folder = tmp_path_factory.mktemp("bare") / "venv"
    installed = subprocess.run([sys.executable, "-m", "venv", str(folder)], capture_output=True)
    install = [str(folder / "bin" / "python"), "-m", "pip", "install", "-q", f"ray=={ray.__version__}", "virtualenv"]
    if installed.returncode == 0:
        installed = subprocess.run(install, capture_output=True, timeout=600)
    if installed.returncode != 0:
        pytest.skip(f"cannot make a virtual environment with Ray: {installed.stderr.decode()[-300:]}")
    return folder / "bin"


@pytest.fixture(scope="module")
def wheelhouse(tmp_path_factory) -> Path:
    """petriflow's dependencies as wheels: the cluster's network namespace reaches no
    package index, as a cluster without internet access would not (its nodes then
    install from a folder of wheels: PIP_FIND_LINKS and PIP_NO_INDEX)."""
    from petriflow.sweep.ship import requirements

    folder = tmp_path_factory.mktemp("wheels")
    got = subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "-w", str(folder), *requirements()],
                         capture_output=True, timeout=600)
    if got.returncode != 0:
        pytest.skip(f"cannot download petriflow's dependencies: {got.stderr.decode()[-300:]}")
    return folder


def test_a_node_with_only_ray_and_python_runs_trials_through_the_shipped_environment(
        bare_python, wheelhouse, folder, tmp_path):
    probe = subprocess.run([str(bare_python / "python"), "-c", "import numpy"], capture_output=True)
    assert probe.returncode != 0  # numpy, and so petriflow's other dependencies, are not there
    spec = sleepy_sweep(folder, tmp_path, trials=2, wall=0.0)
    clean = tmp_path / "clean.sqlite"
    run_sweep(load_sweep(spec), workers=2, db=clean)
    made = Cluster(tmp_path / "bare-cluster")
    try:
        made.start_head(cpus=0)  # no trial runs on the head: every one on the bare node
        made.add_worker(cpus=1, bin_folder=bare_python, env={"PIP_FIND_LINKS": str(wheelhouse), "PIP_NO_INDEX": "1"})
        db = tmp_path / "bare.sqlite"
        driver = made.run(sweep_command(made, spec, db, "--json"), capture_output=True, text=True, timeout=900)
    finally:
        made.close()
    assert driver.returncode == 0, driver.stderr
    assert "lacks petriflow's dependencies (ModuleNotFoundError: No module named" in driver.stderr
    assert [row["failed"] for row in json.loads(driver.stdout)["rows"]] == [0, 0]
    assert recorded(db) == recorded(clean)


def test_a_ray_client_address_gives_the_same_rows(cluster, folder, tmp_path):
    pytest.importorskip("grpc", reason="ray:// needs ray[client]")
    spec = sleepy_sweep(folder, tmp_path, trials=2, wall=0.0)
    clean = tmp_path / "clean.sqlite"
    run_sweep(load_sweep(spec), workers=2, db=clean)
    db = tmp_path / "client.sqlite"
    command = sweep_command(cluster, spec, db, "--json")
    command[command.index(cluster.address)] = "ray://127.0.0.1:10001"
    done = cluster.run(command, capture_output=True, text=True, timeout=240)
    assert done.returncode == 0, done.stderr
    assert [row["failed"] for row in json.loads(done.stdout)["rows"]] == [0, 0]
    assert recorded(db) == recorded(clean)


def test_a_local_ray_instance_started_for_the_sweep_gives_the_local_pools_rows(folder, tmp_path):
    """No --ray-address: petriflow starts a Ray instance of --workers CPUs for the sweep
    (in a namespace of its own here, as every server of these tests)."""
    spec = sleepy_sweep(folder, tmp_path, trials=2, wall=0.0)
    clean = tmp_path / "clean.sqlite"
    local = run_sweep(load_sweep(spec), workers=2, db=clean)
    made = Cluster(tmp_path / "alone")
    try:
        db = tmp_path / "alone.sqlite"
        done = made.run([sys.executable, "-m", "petriflow.cli", "sweep", str(spec), "--backend", "ray", "--workers",
                         "2", "--db", str(db), "--json", "--quiet"], capture_output=True, text=True, timeout=300)
    finally:
        made.close()
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["rows"] == json.loads(json.dumps(local.rows))
    assert recorded(db) == recorded(clean)


def test_a_sweep_submitted_as_a_ray_job_runs_on_the_head_and_outlives_its_submitter(folder, tmp_path):
    """The recipe of docs/sweep-format.md: ``ray job submit --address http://HEAD:8265
    --working-dir . -- petriflow sweep SPEC.yaml --backend ray --db /ABSOLUTE/PATH``
    from the folder of the sweep's files; the submitting command is killed mid-sweep
    and the job goes on. A relative --db is refused (it would land in Ray's copy of
    the working directory)."""
    pytest.importorskip("aiohttp", reason="ray job submit and the job server need ray[default]")
    project = tmp_path / "project"
    project.mkdir()
    for name in ("odd.yaml", "run.yaml", "sweep_test_actions.py"):
        shutil.copy(folder / name, project / name)
    spec = sleepy_sweep(folder, project, trials=4, wall=0.5)
    spec.write_text(spec.read_text().replace(f"net: {folder}/odd.yaml", "net: odd.yaml"))
    # the local pool's rows, from a process of its own (this one may have imported the
    # actions module from the session's folder, and a module name is imported once)
    clean = tmp_path / "clean.sqlite"
    local = subprocess.run([sys.executable, "-m", "petriflow.cli", "sweep", str(spec), "--workers", "2", "--db",
                            str(clean), "--quiet"], capture_output=True, text=True, timeout=300)
    assert local.returncode == 0, local.stderr
    made = Cluster(tmp_path / "jobs-cluster")

    def submit(db: str) -> list[str]:  # `ray` and `petriflow`: found on PATH, in the environment's bin folder
        return ["ray", "job", "submit", "--address", made.jobs, "--working-dir", ".", "--",
                "petriflow", "sweep", spec.name, "--backend", "ray", "--db", db]

    try:
        made.start_head(cpus=1, dashboard=True)
        made.add_worker(cpus=1)
        refused = made.run(submit("results.sqlite"), cwd=project, capture_output=True, text=True, timeout=300)
        db = tmp_path / "results.sqlite"
        log = tmp_path / "submit.log"
        with open(log, "w") as handle:
            submitter = made.popen(submit(str(db)), cwd=project, stdout=handle, stderr=subprocess.STDOUT)
        deadline = time.monotonic() + 240
        while count(db) < 1 and submitter.poll() is None and time.monotonic() < deadline:
            time.sleep(0.1)
        assert submitter.poll() is None, log.read_text()
        Cluster.kill(submitter)  # the submitting command (its machine) goes away mid-sweep
        assert count(db) < 8
        job = re.search(r"raysubmit_\w+", log.read_text()).group(0)
        made.run(["ray", "job", "logs", "--address", made.jobs, "--follow", job], capture_output=True, timeout=300)
        status = made.run(["ray", "job", "status", "--address", made.jobs, job], capture_output=True, text=True,
                          timeout=120)
    finally:
        made.close()
    assert refused.returncode == 1
    assert "--db results.sqlite: under `ray job submit --working-dir` a relative path" in refused.stdout
    assert f"Job '{job}' succeeded" in status.stdout, status.stdout + status.stderr
    assert recorded(db) == recorded(clean)
    assert sorted(p.name for p in project.iterdir()) == ["cluster.yaml", "odd.yaml", "run.yaml",
                                                         "sweep_test_actions.py"]
