"""Smoke test of bench/swarm.py: a tiny team through every measurement it prints.

No timing is checked here; the benchmark's numbers are read by people, not tests.
"""

from __future__ import annotations

import contextlib
import io
import json

from tests.conftest import bench_module


def _main(*argv: str) -> str:
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        bench_module("swarm").main(list(argv))
    return printed.getvalue()


def test_tiles_repeats_and_the_work_per_robot_are_reported():
    rows = json.loads(_main("--robots", "2", "4", "--until", "5", "--tile", "2", "--repeat", "2", "--json"))
    assert [(r["robots"], r["tiles"]) for r in rows] == [(2, 1), (4, 2)]
    for row in rows:
        assert len(row["each_cpu_per_sim_s"]) == 2 and row["cpu_per_sim_s"] == min(row["each_cpu_per_sim_s"])
        assert row["sim_s"] == 5.0 and row["firings"] > 0 and row["floor_cpu_per_sim_s"] > 0
        assert set(row["per_robot"]) >= {"cells known", "history items", "neighbours now"}
        assert len(row["collector_passes"]) == 3
    # two copies of the 2-robot maze: twice the work of one, to the byte
    assert rows[1]["bytes"] == 2 * rows[0]["bytes"] and rows[1]["rays"] == 2 * rows[0]["rays"]


def test_the_ray_measurement_compares_standing_parked_and_removed_robots():
    text = _main("--rays", "--robots", "4")
    assert "among 4 robots" in text and "standing" in text and "parked" in text and "removed" in text
