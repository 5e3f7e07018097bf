"""Smoke test of bench/sweep.py: it runs and reports each measure (no timing is checked)."""

from __future__ import annotations

import contextlib
import importlib.util
import io
from pathlib import Path

BENCH = Path(__file__).resolve().parents[2] / "bench" / "sweep.py"


def test_bench_sweep_quick_prints_its_table():
    spec = importlib.util.spec_from_file_location("bench_sweep", BENCH)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)  # bench/ is not a package
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        rows = bench.main(["--quick", "--no-ray", "--trials", "6"])
    assert [row["measure"].split(":")[0] for row in rows] == ["overhead", "parallelism"]
    assert all(row["petriflow"] > 0 and row["peer"] > 0 for row in rows)
    assert printed.getvalue().count("\n| ") == 2  # the two rows under the header and separator
