"""Smoke test of bench/bridge.py: it runs over both transports and loses or doubles no goal.

No timing is checked here; the benchmark's numbers are read by people (docs/benchmarks.md).
"""

import importlib.util
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow

BENCH = Path(__file__).resolve().parents[2] / "bench" / "bridge.py"


def test_the_bench_runs_and_loses_no_goal(tmp_path, capsys):
    pytest.importorskip("zenoh")
    pytest.importorskip("paho.mqtt")
    from tests.bridge.conftest import mosquitto_binary

    if mosquitto_binary() is None:
        pytest.skip("mosquitto is not installed")
    spec = importlib.util.spec_from_file_location("bench_bridge", BENCH)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    rows = bench.main(["--goals", "20", "--burst", "200", "--names", "4", "--processes", "2"])
    assert [row["transport"] for row in rows] == ["zenoh", "mqtt"]
    assert all(row["lost"] == 0 and row["duplicated"] == 0 and row["executed"] >= 220 for row in rows)
    assert "| zenoh |" in capsys.readouterr().out
