"""Grid shortest paths: petriflow's A* vs pyastar2d, networkx and scipy, side by side.

Solves the paper's three map types (seed 003 Fig. 12: spiral, labyrinth, zig-zag; drawn
by :mod:`petriflow.agents.planning.mazes` at 320 × 240 cells) with

* petriflow ``astar(variant="optimal")``: √2 diagonals, octile h (shortest path);
* petriflow ``astar(variant="paper")``: the paper's g = cells travelled, Euclidean h;
* pyastar2d (C++ A*, a peer on PyPI, not a dependency) with ``allow_diagonal=True``:
  every move costs the weight of the cell entered (1 here), so diagonals cost 1, and it
  cuts corners; its path has the fewest steps on its own graph;
* ``networkx.astar_path`` on the same 8-connected graph as petriflow (√2 diagonals,
  octile heuristic); slow, so it runs fewer times;
* ``scipy.sparse.csgraph.dijkstra`` from the start on the same graph (all distances;
  a reference for the exact cost).

Timing is ``time.perf_counter`` around the search call only (building graphs and weight
arrays is left out). Each planner runs once before timing (numba loads its compiled
code then); the timed runs then take turns, one call per planner per round. Outside
``--quick`` the script also measures, in fresh processes, petriflow's first call with
an empty numba cache (compiling) and with a warm one (loading).

Usage::

    python bench/astar.py                  # 320 x 240, 20 repeats (networkx 3)
    python bench/astar.py --quick          # a smoke run: 80 x 60, 3 repeats, no compile timing
    python bench/astar.py --json out.json  # also write the results as JSON
    python bench/astar.py --cut-corners    # petriflow, networkx and scipy cut corners too
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from petriflow.agents.planning import astar as astar_module
from petriflow.agents.planning import maps
from petriflow.agents.planning.astar import astar
from petriflow.agents.planning.mazes import Maze, all_mazes

sys.path.insert(0, str(Path(__file__).resolve().parent))  # bench/ holds scripts, not a package
from peers import versions as peer_versions  # noqa: E402

SQRT2 = math.sqrt(2.0)
PLANNERS = ("petriflow optimal", "petriflow paper", "pyastar2d", "networkx", "scipy dijkstra")


def grid_edges(grid: np.ndarray, cut_corners: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Directed edges (source index, target index, cost) of the 8-connected free grid,
    with petriflow's rules: √2 diagonals, no corner cutting unless ``cut_corners``."""
    return maps.grid_edges(grid, diagonal_cost=SQRT2, cut_corners=cut_corners)


def euclidean_length(cells: np.ndarray) -> float:
    """Length of a cell path with √2 per diagonal move."""
    if len(cells) < 2:
        return 0.0
    return float(np.hypot(*np.diff(np.asarray(cells, float), axis=0).T).sum())


def planners(maze: Maze, cut_corners: bool) -> dict[str, Callable[[], tuple[np.ndarray | None, dict]]]:
    """One closure per available planner: ``run() -> (cells or None, extra figures)``."""
    grid, start, goal = maze.grid, maze.start, maze.goal
    found: dict[str, Callable[[], tuple[np.ndarray | None, dict]]] = {}

    def petriflow(variant: str):
        def run():
            plan = astar(grid, start, goal, variant=variant, cut_corners=cut_corners)
            return (plan.cells if plan.found else None), {"expanded": plan.expanded}
        return run

    found["petriflow optimal"] = petriflow("optimal")
    found["petriflow paper"] = petriflow("paper")
    try:
        import pyastar2d
    except ImportError:
        pass
    else:
        weights = np.where(grid, np.inf, 1.0).astype(np.float32)

        def run_pyastar2d():
            cells = pyastar2d.astar_path(weights, start, goal, allow_diagonal=True)
            return cells, {}
        found["pyastar2d"] = run_pyastar2d

    rows, cols = grid.shape
    sources, targets, costs = grid_edges(grid, cut_corners)
    import networkx as nx

    graph = nx.Graph()
    graph.add_weighted_edges_from(
        ((divmod(int(s), cols), divmod(int(t), cols), float(w)) for s, t, w in zip(sources, targets, costs)))

    def octile(a, b):
        dr, dc = abs(a[0] - b[0]), abs(a[1] - b[1])
        return max(dr, dc) - min(dr, dc) + SQRT2 * min(dr, dc)

    def run_networkx():
        try:
            cells = np.array(nx.astar_path(graph, start, goal, heuristic=octile, weight="weight"))
        except nx.NetworkXNoPath:
            cells = None
        return cells, {}
    found["networkx"] = run_networkx

    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import dijkstra

    matrix = csr_matrix((costs, (sources, targets)), shape=(rows * cols, rows * cols))
    source, target = start[0] * cols + start[1], goal[0] * cols + goal[1]

    def run_scipy():
        distance = dijkstra(matrix, directed=True, indices=source)
        return None, {"cost": float(distance[target])}
    found["scipy dijkstra"] = run_scipy
    return found


def measure(mazes: Sequence[Maze], repeats: int, slow_repeats: int,
            cut_corners: bool) -> list[dict[str, Any]]:
    """Time every planner on every maze; one row per (maze, planner).

    Each planner runs once untimed, then the timed runs go round the planners in turn
    (networkx only in the first ``slow_repeats`` rounds), so a busy machine slows them
    all alike rather than whichever happened to run at the wrong moment.
    """
    rows = []
    for maze in mazes:
        runs = planners(maze, cut_corners)
        first = {name: run() for name, run in runs.items()}
        last = dict(first)
        times: dict[str, list[float]] = {name: [] for name in runs}
        for round_ in range(repeats):
            for name, run in runs.items():
                if name == "networkx" and round_ >= slow_repeats:
                    continue
                began = time.perf_counter()
                last[name] = run()
                times[name].append((time.perf_counter() - began) * 1000.0)
        for name in runs:
            cells, extra = last[name]
            row: dict[str, Any] = {
                "map": maze.name, "size": f"{maze.grid.shape[1]}x{maze.grid.shape[0]}", "planner": name,
                "repeats": len(times[name]), "median_ms": statistics.median(times[name]),
                "min_ms": min(times[name]),
            }
            if cells is not None:
                row["steps"] = int(len(cells) - 1)
                row["length"] = euclidean_length(cells)
                row["deterministic"] = bool(np.array_equal(cells, first[name][0]))
            if "cost" in extra:
                row["length"] = extra["cost"]
            if "expanded" in extra:
                row["expanded"] = extra["expanded"]
            rows.append(row)
    return rows


def ratios(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per map: petriflow ÷ pyastar2d (time) and networkx ÷ petriflow (speed-up)."""
    by = {(r["map"], r["planner"]): r for r in rows}
    out = []
    for name in dict.fromkeys(r["map"] for r in rows):
        optimal, paper = by[(name, "petriflow optimal")], by[(name, "petriflow paper")]
        entry: dict[str, Any] = {"map": name}
        peer = by.get((name, "pyastar2d"))
        if peer:
            entry["optimal_over_pyastar2d"] = optimal["median_ms"] / peer["median_ms"]
            entry["paper_over_pyastar2d"] = paper["median_ms"] / peer["median_ms"]
        entry["networkx_over_optimal"] = by[(name, "networkx")]["median_ms"] / optimal["median_ms"]
        entry["scipy_over_optimal"] = by[(name, "scipy dijkstra")]["median_ms"] / optimal["median_ms"]
        out.append(entry)
    return out


_FIRST_CALL = """
import time
began = time.perf_counter()
from petriflow.agents.planning.astar import astar
from petriflow.agents.planning.mazes import spiral
imported = time.perf_counter()
maze = spiral()
astar(maze.grid, maze.start, maze.goal)
astar(maze.grid, maze.start, maze.goal, variant="paper")
done = time.perf_counter()
print(imported - began, done - imported)
"""


def first_call_seconds() -> dict[str, float]:
    """Import and first-call seconds in fresh processes: empty numba cache, then warm."""
    result: dict[str, float] = {}
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        for label in ("compile", "cached"):
            out = subprocess.run([sys.executable, "-c", _FIRST_CALL], env=env, check=True,
                                 capture_output=True, text=True).stdout.split()
            result["import_s"] = float(out[0])
            result[f"first_call_{label}_s"] = float(out[1])
    return result


def _number(value: Any, digits: int = 2) -> str:
    return "–" if value is None else f"{value:.{digits}f}"


def markdown(rows: list[dict[str, Any]], speed: list[dict[str, Any]]) -> str:
    """The results as two Markdown tables: timings and path figures, then ratios."""
    lines = ["| map | planner | repeats | median ms | min ms | steps | length (cells) | expanded |",
             "|---|---|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['map']} {r['size']} | {r['planner']} | {r['repeats']} | "
                     f"{_number(r['median_ms'])} | {_number(r['min_ms'])} | {r.get('steps', '–')} | "
                     f"{_number(r.get('length'), 1)} | {r.get('expanded', '–')} |")
    lines += ["", "| map | optimal ÷ pyastar2d | paper ÷ pyastar2d | networkx ÷ optimal | scipy ÷ optimal |",
              "|---|---:|---:|---:|---:|"]
    for s in speed:
        lines.append(f"| {s['map']} | {_number(s.get('optimal_over_pyastar2d'))} | "
                     f"{_number(s.get('paper_over_pyastar2d'))} | {_number(s['networkx_over_optimal'], 1)} | "
                     f"{_number(s['scipy_over_optimal'], 1)} |")
    return "\n".join(lines)


def versions() -> dict[str, str]:
    """Versions of Python and the libraries measured."""
    return peer_versions("numpy", "numba", "pyastar2d", "networkx", "scipy")


def main(argv: Sequence[str] | None = None) -> list[dict[str, Any]]:
    """Run the benchmark, print the Markdown tables, and return the result rows."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small maps, few repeats: a smoke run")
    parser.add_argument("--repeats", type=int, help="timed runs per fast planner (default 20, quick 3)")
    parser.add_argument("--slow-repeats", type=int, help="timed networkx runs (default 3, quick 1)")
    parser.add_argument("--size", help="map size COLSxROWS (default 320x240, quick 80x60)")
    parser.add_argument("--cut-corners", action="store_true",
                        help="let petriflow, networkx and scipy cut corners, as pyastar2d does")
    parser.add_argument("--json", metavar="OUT", help="also write the results to OUT as JSON")
    args = parser.parse_args(argv)
    size = args.size or ("80x60" if args.quick else "320x240")
    cols, rows_count = (int(v) for v in size.lower().split("x"))
    repeats = args.repeats or (3 if args.quick else 20)
    slow = args.slow_repeats or (1 if args.quick else 3)
    rows = measure(all_mazes(rows_count, cols), repeats, slow, args.cut_corners)
    speed = ratios(rows)
    info = versions()
    corners = ("diagonals may cut corners" if args.cut_corners
               else "no corner cutting (pyastar2d cuts corners)")
    print(f"A* on {size} grids, {corners}; {platform.machine()}, {os.cpu_count()} CPUs "
          f"({', '.join(f'{k} {v}' for k, v in info.items())}); numba compiled: {astar_module.COMPILED}")
    print()
    print(markdown(rows, speed))
    compile_times = {}
    if not args.quick:
        compile_times = first_call_seconds()
        print()
        print(f"petriflow first call in a fresh process (both variants, spiral): "
              f"{compile_times['first_call_compile_s']:.2f} s with an empty numba cache (compiling), "
              f"{compile_times['first_call_cached_s']:.2f} s with a warm one; "
              f"import {compile_times['import_s']:.2f} s")
    if args.json:
        with open(args.json, "w", encoding="utf-8") as out:
            json.dump({"size": size, "repeats": repeats, "slow_repeats": slow,
                       "cut_corners": args.cut_corners,
                       "versions": info, "cpus": os.cpu_count(), "rows": rows, "ratios": speed,
                       "first_call": compile_times}, out, indent=2)
    return rows


if __name__ == "__main__":
    main()
