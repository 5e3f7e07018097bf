"""Smoke test of bench/firing.py: it runs and prints a table with all three engines.

No timing is checked here; the benchmark's numbers are read by people, not tests.
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import json
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parent.parent / "bench" / "firing.py"

pytest.importorskip("pm4py")
pytest.importorskip("snakes")

# SNAKES 0.9.33 imports the deprecated imp module.
pytestmark = pytest.mark.filterwarnings("ignore:the imp module is deprecated:DeprecationWarning")


ARGS = ["--quick", "--firings", "30", "--snakes-firings", "10", "--sizes", "3"]


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """One quick run of the bench script: (rows returned, stdout, JSON written)."""
    spec = importlib.util.spec_from_file_location("bench_firing", BENCH)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)  # bench/ is not a package
    out = tmp_path_factory.mktemp("bench") / "bench.json"
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        rows = bench.main([*ARGS, "--json", str(out)])
    return rows, printed.getvalue(), json.loads(out.read_text(encoding="utf-8"))


def test_bench_prints_table_with_all_engines(run):
    """main --quick prints a Markdown table with a row for each engine."""
    _, out, _ = run
    assert "| net | engine | firings | seconds | firings/s | ratio vs petriflow |" in out
    for engine in ("petriflow", "PM4Py", "SNAKES"):
        assert f"| philosophers-3 | {engine} |" in out


def test_bench_prints_speedups(run):
    """main prints petriflow's speed-up over PM4Py and over SNAKES."""
    _, out, _ = run
    assert "| net | petriflow ÷ PM4Py | petriflow ÷ SNAKES |" in out


def test_bench_plays_requested_firings(run):
    """Each engine plays the requested number of firings on a live net."""
    rows, _, _ = run
    assert {row["engine"]: row["firings"] for row in rows} == {
        "petriflow": 30, "PM4Py": 30, "SNAKES": 10,
    }


def test_bench_writes_json(run):
    """--json writes the rows and speed-ups to a file."""
    _, _, data = run
    assert {row["engine"] for row in data["rows"]} == {"petriflow", "PM4Py", "SNAKES"}
    assert data["speedups"][0]["net"] == "philosophers-3"
