"""Small nets and sweep files for the sweep tests, written into a temporary folder."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

NET = """\
petriflow: 1
run: run.yaml
places: [{id: i, tokens: 1}, o]
transitions:
  - {id: rest, action: core.wait, params: {seconds: 1}, in: [i], out: [o]}
final: {o: 1}
"""

#: Actions a sweep can misbehave with: a random wait (depends on the seed only), a
#: crash of the whole process, a wall-clock sleep, an exception.
ACTIONS = '''
import os, time
from petriflow import Param, action

@action("test.random_wait", params={"mean": Param(float, 1.0)})
def random_wait(ctx):
    yield ctx.rng.expovariate(1.0 / ctx.params["mean"])
    ctx.emit("waited", seconds=ctx.now)

@action("test.crash", params={"when": Param(float, 0.0)})
def crash(ctx):
    if ctx.params["when"] > 0:
        os._exit(3)

@action("test.sleep", params={"wall": Param(float, 0.0)})
def sleep(ctx):
    time.sleep(ctx.params["wall"])

@action("test.raise", params={"when": Param(float, 0.0)})
def fail_hard(ctx):
    if ctx.params["when"] > 0:
        raise ZeroDivisionError("boom")
'''

MISBEHAVING = """\
petriflow: 1
run: run.yaml
places: [{id: i, tokens: 1}, a, b, c, o]
transitions:
  - {id: wait, action: test.random_wait, params: {mean: 2}, in: [i], out: [a]}
  - {id: crash, action: test.crash, in: [a], out: [b]}
  - {id: sleep, action: test.sleep, in: [b], out: [c]}
  - {id: raise, action: test.raise, in: [c], out: [o]}
final: {o: 1}
"""


@pytest.fixture(scope="session")
def folder(tmp_path_factory) -> Path:
    """A folder with net.yaml (core.wait), odd.yaml (misbehaving actions), run.yaml and
    the actions module (one folder per session: a module name is imported once)."""
    tmp_path = tmp_path_factory.mktemp("sweep")
    (tmp_path / "net.yaml").write_text(NET)
    (tmp_path / "odd.yaml").write_text(MISBEHAVING)
    (tmp_path / "run.yaml").write_text("seed: 0\nuntil: 100\nactions: [sweep_test_actions.py]\n")
    (tmp_path / "sweep_test_actions.py").write_text(ACTIONS)
    return tmp_path


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(textwrap.dedent(text))
    return path
