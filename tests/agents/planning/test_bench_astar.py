"""Smoke test of bench/astar.py: it runs quick and prints its tables.

No timing is checked; the benchmark's numbers are for people to read.
"""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[3] / "bench" / "astar.py"
HAS_PYASTAR2D = importlib.util.find_spec("pyastar2d") is not None


@pytest.fixture(scope="module")
def bench():
    """The bench script, loaded as a module (bench/ is not a package)."""
    spec = importlib.util.spec_from_file_location("bench_astar", BENCH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_bench_quick_prints_tables_and_writes_json(bench, capsys, tmp_path):
    """--quick runs every planner on the three maps, prints both tables, writes JSON."""
    out = tmp_path / "astar.json"
    rows = bench.main(["--quick", "--size", "48x36", "--json", str(out)])
    text = capsys.readouterr().out
    assert "| map | planner | repeats | median ms | min ms | steps | length (cells) | expanded |" in text
    assert "| map | optimal ÷ pyastar2d | paper ÷ pyastar2d | networkx ÷ optimal | scipy ÷ optimal |" in text
    planners = {"petriflow optimal", "petriflow paper", "networkx", "scipy dijkstra"}
    if HAS_PYASTAR2D:
        planners.add("pyastar2d")
    assert {(r["map"], r["planner"]) for r in rows} == {(m, p) for m in ("spiral", "labyrinth", "zigzag")
                                                       for p in planners}
    data = json.loads(out.read_text(encoding="utf-8"))
    assert len(data["rows"]) == len(rows) and len(data["ratios"]) == 3


def test_bench_exact_planners_agree(bench, capsys):
    """On the same graph, petriflow optimal, networkx and scipy find the same length."""
    rows = bench.main(["--quick", "--size", "48x36"])
    capsys.readouterr()
    by = {(r["map"], r["planner"]): r for r in rows}
    for name in ("spiral", "labyrinth", "zigzag"):
        optimal = by[(name, "petriflow optimal")]["length"]
        assert by[(name, "networkx")]["length"] == pytest.approx(optimal)
        assert by[(name, "scipy dijkstra")]["length"] == pytest.approx(optimal)
        assert by[(name, "petriflow optimal")]["deterministic"]
