"""A live run in a process of its own, for the live page's and ``ctl``'s tests."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest

#: A small net with a failure route (work -> bad), a place to fill by hand (spare), a
#: count to watch (done).
NET = """\
petriflow: 1
places: [{id: start, tokens: 3}, done, bad, spare]
transitions:
- {id: work, action: core.wait, params: {seconds: 5}, in: [start], out: [done], outcomes: {failed: [bad]}}
- {id: fix, action: core.wait, params: {seconds: 1}, in: [spare], out: [done]}
"""


class LiveRun:
    """``petriflow run NET --live 0 ...`` started; :attr:`url` once it serves."""

    def __init__(self, folder: Path, *extra: str, net: str = NET) -> None:
        self.folder = folder
        (folder / "net.yaml").write_text(net)
        self.trace = folder / "run.jsonl"
        self.db = folder / "run.db"
        self.stderr = open(folder / "stderr.txt", "w+")
        self.process = subprocess.Popen(
            [sys.executable, "-c", "import sys; from petriflow.cli import main; sys.exit(main())", "run", str(folder / "net.yaml"), "--live", "127.0.0.1:0",
             "--trace", str(self.trace), "--db", str(self.db), "--quiet", *extra],
            stdout=subprocess.PIPE, stderr=self.stderr, text=True, env={**os.environ, "PYTHONWARNINGS": "ignore"})
        self.url = self._wait_url()

    def _wait_url(self) -> str:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            self.stderr.seek(0)
            found = re.search(r"live page: (http://\S+)", self.stderr.read())
            if found:
                return found.group(1)
            if self.process.poll() is not None:
                self.stderr.seek(0)
                raise AssertionError(f"the run ended before serving: {self.stderr.read()}")
            time.sleep(0.1)
        raise AssertionError("the run did not print its live URL in 120 s")

    def finish(self, timeout: float = 120) -> str:
        """Wait for the run to end; its standard output."""
        out, _ = self.process.communicate(timeout=timeout)
        return out

    def stop(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait(timeout=30)
        if self.process.stdout:
            self.process.stdout.close()
        self.stderr.close()


@pytest.fixture
def live_run(tmp_path):
    """Start live runs (``live_run(*options)``); every one is stopped after the test."""
    runs: list[LiveRun] = []

    def start(*extra: str, net: str = NET) -> LiveRun:
        folder = tmp_path / f"run{len(runs)}"
        folder.mkdir()
        runs.append(LiveRun(folder, *extra, net=net))
        return runs[-1]

    yield start
    for run in runs:
        run.stop()
