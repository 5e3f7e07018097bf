"""Smoke test of bench/smart.py: it runs quick and prints its tables.

No timing is checked here; the benchmark's numbers are read by people, not tests.
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import json
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[3] / "bench" / "smart.py"

pytestmark = pytest.mark.slow


def test_bench_runs_quick_and_writes_json(tmp_path):
    """``--quick --json OUT``: both cameras measured, every part of the split present."""
    spec = importlib.util.spec_from_file_location("bench_smart", BENCH)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)  # bench/ is not a package
    out = tmp_path / "smart.json"
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        bench.main(["--quick", "--json", str(out)])
    text = printed.getvalue()
    assert "real-time factor" in text and "| camera | render | vision | planning | physics |" in text
    rows = json.loads(out.read_text(encoding="utf-8"))
    assert [row["camera"] for row in rows] == ["640x480", "320x240"]
    for row in rows:
        assert row["reason"] == "until" and row["simulated_s"] == pytest.approx(5.0)
        assert set(row["split_s"]) == {"render", "vision", "planning", "physics", "control", "net"}
        assert row["frames"] == pytest.approx(6 * 5.0, abs=2)      # rendered only when a capture fires
