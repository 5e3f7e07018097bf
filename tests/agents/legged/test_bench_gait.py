"""Smoke test of bench/gait.py: it runs quick and prints its tables.

No timing is checked here; the benchmark's numbers are read by people, not tests.
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import json
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[3] / "bench" / "gait.py"

pytestmark = pytest.mark.slow


def test_bench_runs_quick_and_writes_json(tmp_path):
    """``--quick --json OUT``: both tables printed, every robot set measured."""
    spec = importlib.util.spec_from_file_location("bench_gait", BENCH)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)  # bench/ is not a package
    out = tmp_path / "gait.json"
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        bench.main(["--quick", "--json", str(out)])
    text = printed.getvalue()
    assert "| robots | steps | seconds | steps/s |" in text
    assert "real-time factor" in text
    data = json.loads(out.read_text(encoding="utf-8"))
    assert [row["robots"] for row in data["physics"]] == ["Robot4L", "Robot3L", "both"]
    assert {(row["robots"], row["robot"]) for row in data["walking"]} == {
        ("Robot4L", "robot4l"), ("Robot3L", "robot3l"), ("both", "robot4l"), ("both", "robot3l")}
    assert all(row["upright"] for row in data["walking"])
