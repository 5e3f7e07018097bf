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


def test_the_simpy_peer_is_measured_beside_the_runtime(quick):
    pytest.importorskip("simpy")  # in the dev extras; the bench leaves the peer out without it
    text, data = quick
    assert "| agents N | petriflow lockstep firings/s | SimPy events/s" in text
    assert set(data["simpy"]) == {"1", "10"}
    for n, row in data["simpy"].items():
        assert row["firings"] >= 3_000 and row["per_second"] > 0
        assert row["simulated"] == pytest.approx(3_000 / int(n), abs=1.0)  # N timeouts a second
        share = data["scaling"][n]["lockstep"]["per_second"] / row["per_second"]
        assert f"| {n} | " in text and f"{share:.0%} |" in text


def test_without_simpy_the_peer_is_left_out_with_a_line(monkeypatch, capsys):
    """Measurements faked: only what main does when SimPy cannot be imported."""
    bench = bench_module("runtime")
    asked = []

    def measure_all(configurations, firings, repeat):
        asked.extend(configurations)
        return {c: {"seconds": 1.0, "firings": 10, "per_second": 10.0, "messages": 1, "transitions": 30}
                for c in configurations}

    monkeypatch.setattr(bench, "have_simpy", lambda: False)
    monkeypatch.setattr(bench, "measure_all", measure_all)
    monkeypatch.setattr(bench, "cli", lambda n, firings, repeat: {k: {"seconds": 1.0, "per_second": 10.0}
                                                                   for k in ("simulate", "run")})
    monkeypatch.setattr(bench, "_one", lambda kind, n, firings: {"rss_mib": [[1, 1.0], [10, 1.0]]})
    monkeypatch.setattr(bench, "realtime_factor", lambda repeats: [])
    results = bench.main(["--quick"])
    assert "simpy" not in results and all(kind != "simpy" for kind, _ in asked)
    assert "SimPy peer left out: SimPy is not installed" in capsys.readouterr().out


def test_the_numbers_are_kept_as_json(quick):
    _, data = quick
    assert set(data) >= {"scaling", "messages", "trace", "cli", "memory", "load", "world"}
    if bench_module("runtime").have_simpy():
        assert "simpy" in data
    assert data["messages"]["10"]["messages"] > 0
