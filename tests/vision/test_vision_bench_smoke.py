"""Smoke test of bench/vision.py: it runs in quick mode and prints its tables.

No timing is checked: the benchmark's numbers are read by people, not tests.
"""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[2] / "bench" / "vision.py"


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("bench_vision", BENCH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_quick_run_prints_tables_and_writes_json(bench, capsys, tmp_path):
    out = tmp_path / "vision.json"
    result = bench.main(["--quick", "--json", str(out)])
    printed = capsys.readouterr().out
    assert "| what | size | frames |" in printed
    assert "| stage (640x480, table) |" in printed
    assert "| size | scenes | robots found |" in printed
    for what in ("vision pipeline (RGB→label table)", "vision pipeline (explicit HSV)",
                 "rendering (pybullet TinyRenderer)"):
        assert f"| {what} |" in printed
    data = json.loads(out.read_text(encoding="utf-8"))
    assert {row["size"] for row in data["throughput"]} == {"640x480", "320x240"}
    assert set(data["stages_ms"]) == {"classify", "mode", "contours", "pose", "map", "total"}
    for quality in result["accuracy"]:
        assert quality["robots_found"] == quality["robots_placed"] == 4 * quality["scenes"]
