"""Smoke test of bench/runtime.py: it runs every measurement and prints its tables.

No timing is checked here; the benchmark's numbers are read by people, not tests.
"""

from __future__ import annotations

import contextlib
import io
import json

import pytest

from petriflow.io.yaml import loads_net
from tests.conftest import bench_module


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    bench = bench_module("runtime")
    out = tmp_path_factory.mktemp("bench") / "runtime.json"
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        bench.main(["--quick", "--json", str(out)])
    return printed.getvalue(), json.loads(out.read_text())


def test_the_generated_nets_are_what_the_benchmark_says():
    bench = bench_module("runtime")
    agents = loads_net(bench.agents_net(4, stagger=True))
    assert len(agents.transitions) == 12 and len(agents.subnets) == 4
    messages = loads_net(bench.messages_net(4))
    assert {p.channel for p in messages.places.values()} == {None, "link"}


def test_every_table_is_printed(quick):
    text, _ = quick
    assert "| agents N | lockstep firings/s | staggered firings/s |" in text
    assert "| agents N | messages: firings/s |" in text
    assert "petriflow simulate" in text and "memory (N = 10" in text and "loading 30 transitions" in text


def test_the_numbers_are_kept_as_json(quick):
    _, data = quick
    assert set(data) >= {"scaling", "messages", "trace", "cli", "memory", "load", "world"}
    assert data["messages"]["10"]["messages"] > 0
