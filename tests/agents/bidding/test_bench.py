"""Smoke test of bench/bidding.py's allocation table: it runs, the plain-Python auction
agrees with the numpy one (the script asserts it), and the rows are printed. No timing
is checked here."""

from __future__ import annotations

import contextlib
import importlib.util
import io
from pathlib import Path

BENCH = Path(__file__).resolve().parents[3] / "bench" / "bidding.py"


def test_allocation_table_prints_every_method():
    spec = importlib.util.spec_from_file_location("bench_bidding", BENCH)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)  # bench/ is not a package
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        bench.allocation(1)
    text = printed.getvalue()
    assert "petriflow `auction.autonomous`" in text and "plain Python" in text and "Hungarian" in text
    assert "zones per robot: 10..10" in text
