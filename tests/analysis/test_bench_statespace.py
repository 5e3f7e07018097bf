"""Smoke test: bench/statespace.py runs in quick mode and writes its JSON (no timing checks)."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

BENCH = Path(__file__).resolve().parents[2] / "bench" / "statespace.py"


def load_bench():
    spec = importlib.util.spec_from_file_location("bench_statespace", BENCH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_quick_run_writes_a_table_and_json(tmp_path, capsys):
    """--quick --tools petriflow prints a Markdown table and writes matching JSON rows."""
    out = tmp_path / "rows.json"
    assert load_bench().main(["--quick", "--tools", "petriflow", "--json", str(out)]) == 0
    table = capsys.readouterr().out
    assert "| petriflow | philosophers | N=10 | 123 | 680 |" in table
    rows = json.loads(out.read_text())["rows"]
    states = {(r["net"], r["size"]): r["states"] for r in rows}
    assert states[("philosophers", "N=15")] == 1364
    assert states[("producer/consumer, batch 3", "c=300")] == 4 * 301


def test_repeated_runs_report_a_median_and_a_range(tmp_path, capsys):
    """--runs 2 measures petriflow twice and prints the range beside the median."""
    out = tmp_path / "rows.json"
    assert load_bench().main(["--quick", "--tools", "petriflow", "--runs", "2",
                              "--json", str(out)]) == 0
    assert "in 2 runs)" in capsys.readouterr().out
    for row in json.loads(out.read_text())["rows"]:
        assert row["runs"] == 2
        assert row["seconds_min"] <= row["seconds"] <= row["seconds_max"]


def test_shared_buffer_is_bounded_by_its_capacity():
    """The benchmark's shared-buffer net keeps buffer + free equal to the capacity."""
    from petriflow.analysis.reachability import reachability_graph

    space = reachability_graph(load_bench().shared_buffer(3, 4, 2))
    columns = [space.places.index("buffer"), space.places.index("free")]
    assert (space.markings[:, columns].sum(axis=1) == 4).all()


def test_check_mode_times_each_step_and_checks_oracle_answers(tmp_path, capsys):
    """--check --quick: a row per stress net and per file, each step's CPU seconds, and a
    file with an answer.json beside it checked against it."""
    model = Path(__file__).resolve().parents[1] / "data" / "oracle" / "mcc" / "Dekker-PT-010" / "model.pnml"
    out = tmp_path / "check.json"
    assert load_bench().main(["--check", "--quick", str(model), "--json", str(out)]) == 0
    table = capsys.readouterr().out
    assert "| Lamport fast mutex, 2 processes | 38 | 52 | 310 |" in table
    assert "Dekker-PT-010/model.pnml | 50 | 120 | 6,144 |" in table and "oracle agrees" in table
    rows = json.loads(out.read_text())["rows"]
    unbounded = next(r for r in rows if r["net"].startswith("unbounded"))
    assert unbounded["verdict"] == "PROBLEM" and unbounded["result"]["unbounded_places"] == ["heap"]


def test_reductions_mode_compares_methods(tmp_path, capsys):
    """--reductions --quick: the 5-robot team net explicitly and by symmetry (same
    verdict and full state count, fewer markings stored), the philosophers' deadlock by
    stubborn sets."""
    out = tmp_path / "reductions.json"
    assert load_bench().main(["--reductions", "--quick", "--json", str(out)]) == 0
    rows = {(r["net"], r["method"]): r for r in json.loads(out.read_text())}
    full = rows[("bidding-autonomous-5", "explicit")]
    auto = rows[("bidding-autonomous-5", "auto")]
    assert full["verdict"] == auto["verdict"] == "OK" and full["states"] == auto["states"]
    assert auto["visited"]["symmetry"] < full["visited"]["explicit"] == full["states"]
    philosophers = rows[("philosophers (one fork at a time) 100", "stubborn")]
    assert philosophers["verdict"] == "PROBLEM" and philosophers["deadlock_free"] is False
