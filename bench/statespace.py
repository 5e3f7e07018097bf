"""State-space exploration speed: petriflow vs PM4Py vs SNAKES, side by side.

Builds the full reachability graph (every reachable marking and every (marking, fired
transition) edge) of:

* the dining philosophers with atomic fork taking (``petriflow.classic.dining_philosophers``,
  safe, L(N) states) for N = 5, 10, 15, 20, 25, 30;
* two non-safe bounded nets with weighted arcs: a producer and a consumer around a
  200 000-slot buffer filled 3 items at a time (long and thin: one small BFS level after
  the other), and ten producers sharing one 200-slot buffer, 3 items a put, emptied by one
  consumer (wide frontiers);

with each library:

* petriflow: :func:`petriflow.analysis.reachability.reachability_graph`;
* PM4Py: ``pm4py.objects.petri_net.utils.reachability_graph.construct_reachability_graph``
  on the same net built with PM4Py's classes. Run while its previous N took less than
  30 s and the next one, extrapolated by the state count, would too;
* SNAKES: ``snakes.nets.StateGraph(net).build()`` on ``petriflow.interop.snakes.to_snakes``,
  same rule with a 10 s budget (it is the slowest).

petriflow's exploration loops are compiled by numba and cached on disk; loading them
is a one-time cost per process (like importing PM4Py), paid before the clock starts by
``warm_up()`` and reported on its own in the first line of the output.

Each measurement runs in a fresh forked process, so its peak memory is its own: the
"peak RSS" column is ``resource.getrusage(RUSAGE_SELF).ru_maxrss`` of that process (the
whole process: interpreter, numpy and the imported library included), and "extra RSS"
is that peak minus the process's resident size just before the exploration started.
Seconds are ``time.perf_counter`` around the exploration only (building the net is not
timed); an exploration that takes less than 0.1 s is repeated (up to 1,000 runs or 1 s) and
the best run counts, for every tool alike. Counts are checked to agree between the libraries.

PM4Py is AGPL-licensed: it is imported only here and in tests, never by petriflow.

Usage::

    python bench/statespace.py                  # the full table (a few minutes)
    python bench/statespace.py --quick          # small sizes only (a smoke run)
    python bench/statespace.py --json out.json  # also write the rows as JSON
    python bench/statespace.py --runs 5 --tools petriflow   # median and range of 5 runs
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import platform
import resource
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from petriflow.classic import dining_philosophers, producer_consumer
from petriflow.net import Net

sys.path.insert(0, str(Path(__file__).resolve().parent))  # bench/ holds scripts, not a package
from peers import to_pm4py  # noqa: E402

#: Wall-clock budget per measurement beyond which a peer library is not run on bigger nets.
BUDGET = {"PM4Py": 30.0, "SNAKES": 10.0}
#: A measurement is killed after this many seconds (the row then says "timeout").
HARD_LIMIT = {"full": 60.0, "quick": 15.0}


def shared_buffer(producers: int, capacity: int, batch: int) -> Net:
    """``producers`` independent producers putting ``batch`` items at a time into one
    buffer of ``capacity`` slots (a weighted arc), emptied one item at a time by one
    consumer. Bounded (buffer + free = capacity), not safe."""
    net = Net(f"shared-buffer-{producers}x{capacity}")
    net.add_place("buffer")
    net.add_place("free", tokens=capacity)
    net.add_place("consumer_ready", tokens=1)
    net.add_place("consumer_busy")
    for k in range(producers):
        net.add_place(f"idle_{k}", tokens=1)
        net.add_place(f"full_{k}")
        net.add_transition(f"produce_{k}")
        net.add_arc(f"idle_{k}", f"produce_{k}")
        net.add_arc(f"produce_{k}", f"full_{k}")
        net.add_transition(f"put_{k}")
        net.add_arc(f"full_{k}", f"put_{k}")
        net.add_arc("free", f"put_{k}", batch)
        net.add_arc(f"put_{k}", "buffer", batch)
        net.add_arc(f"put_{k}", f"idle_{k}")
    net.add_transition("take")
    net.add_arc("consumer_ready", "take")
    net.add_arc("buffer", "take")
    net.add_arc("take", "consumer_busy")
    net.add_arc("take", "free")
    net.add_transition("consume")
    net.add_arc("consumer_busy", "consume")
    net.add_arc("consume", "consumer_ready")
    return net


# One exploration per library: explore(net) -> (states, edges); only the call is timed.

def petriflow_explore(net: Net) -> Callable[[], tuple[int, int]]:
    from petriflow.analysis.reachability import reachability_graph, warm_up

    warm_up()     # load the compiled loops from numba's cache, like an import (not timed)

    def run() -> tuple[int, int]:
        space = reachability_graph(net, max_states=10**8)
        return space.num_states, space.num_edges

    return run


def pm4py_explore(net: Net) -> Callable[[], tuple[int, int]]:
    from pm4py.objects.petri_net.utils import reachability_graph

    pn, initial, _ = to_pm4py(net)

    def run() -> tuple[int, int]:
        graph = reachability_graph.construct_reachability_graph(pn, initial)
        return len(graph.states), len(graph.transitions)

    return run


def snakes_explore(net: Net) -> Callable[[], tuple[int, int]]:
    import snakes.nets

    from petriflow.interop.snakes import to_snakes

    snet = to_snakes(net)

    def run() -> tuple[int, int]:
        graph = snakes.nets.StateGraph(snet)
        graph.build()
        edges = sum(len(list(graph.successors(state))) for state in range(len(graph)))
        return len(graph), edges

    return run


EXPLORERS = {"petriflow": petriflow_explore, "PM4Py": pm4py_explore, "SNAKES": snakes_explore}


def _rss_mib() -> float:
    with open("/proc/self/statm") as handle:
        return int(handle.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def _child(tool: str, make: Callable[[], Net], pipe) -> None:
    import contextlib
    import gc
    import io

    with contextlib.redirect_stdout(io.StringIO()):   # PM4Py prints a banner on import
        run = EXPLORERS[tool](make())
    gc.collect()
    base = _rss_mib()
    start = time.perf_counter()
    states, edges = run()
    seconds = time.perf_counter() - start
    # Sub-0.1 s runs are noisy: repeat them (same rule for every tool) and keep the best.
    spent, runs = seconds, 1
    while seconds < 0.1 and runs < 1000 and spent < 1.0:
        start = time.perf_counter()
        run()
        once = time.perf_counter() - start
        seconds, spent, runs = min(seconds, once), spent + once, runs + 1
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024   # KiB on Linux
    pipe.send({"states": states, "edges": edges, "seconds": seconds,
               "peak_rss_mib": round(peak, 1), "extra_rss_mib": round(max(0.0, peak - base), 1)})


def _warm_up_child(pipe) -> None:
    start = time.perf_counter()
    from petriflow.analysis.reachability import warm_up

    warm_up()
    pipe.send(time.perf_counter() - start)


def warm_up_seconds() -> float:
    """Seconds a fresh process takes to import the analysis and load its compiled loops."""
    context = multiprocessing.get_context("fork")
    receive, send = context.Pipe(duplex=False)
    process = context.Process(target=_warm_up_child, args=(send,))
    process.start()
    seconds = receive.recv()
    process.join()
    return seconds


def measure(tool: str, make: Callable[[], Net], limit: float) -> dict[str, Any]:
    """Run one exploration in a fresh forked process (killed after ``limit`` s)."""
    context = multiprocessing.get_context("fork")
    receive, send = context.Pipe(duplex=False)
    process = context.Process(target=_child, args=(tool, make, send))
    process.start()
    if receive.poll(limit):
        row = receive.recv()
    else:
        row = {"timeout": limit}
    process.join(5)
    if process.is_alive():
        process.kill()
        process.join()
    return row


def cases(quick: bool) -> list[tuple[str, str, Callable[[], Net]]]:
    """(family, size label, net factory), smallest first within a family."""
    philosophers = (5, 10, 15) if quick else (5, 10, 15, 20, 25, 30)
    buffers = (30, 300) if quick else (30, 300, 3000, 200_000)
    shared = (2, 20) if quick else (2, 20, 200)
    found: list[tuple[str, str, Callable[[], Net]]] = []
    found += [("philosophers", f"N={n}", (lambda n=n: dining_philosophers(n)))
              for n in philosophers]
    found += [("producer/consumer, batch 3", f"c={c}", (lambda c=c: producer_consumer(c, 3)))
              for c in buffers]
    found += [("10 producers, shared buffer, batch 3", f"c={c}",
               (lambda c=c: shared_buffer(10, c, 3))) for c in shared]
    return found


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small sizes only")
    parser.add_argument("--json", metavar="OUT", help="also write the rows as JSON")
    parser.add_argument("--runs", type=int, default=1,
                        help="measure petriflow this many times (fresh processes) and report"
                             " the median and the range of states/s")
    parser.add_argument("--tools", default="petriflow,PM4Py,SNAKES",
                        help="comma-separated subset of petriflow,PM4Py,SNAKES")
    args = parser.parse_args(argv)
    tools = [t for t in args.tools.split(",") if t]
    available = []
    for tool in tools:
        module = {"petriflow": "petriflow", "PM4Py": "pm4py", "SNAKES": "snakes"}[tool]
        try:
            __import__(module)
            available.append(tool)
        except ImportError:
            print(f"({tool} is not installed: left out)", file=sys.stderr)
    budget = dict(BUDGET)
    limit = HARD_LIMIT["quick" if args.quick else "full"]
    if args.quick:
        budget = {"PM4Py": 3.0, "SNAKES": 2.0}

    warm_up = warm_up_seconds() if "petriflow" in available else 0.0
    rows: list[dict[str, Any]] = []
    stopped: dict[tuple[str, str], str] = {}
    last: dict[tuple[str, str], dict[str, Any]] = {}
    for family, size, make in cases(args.quick):
        reference = None
        for tool in available:
            key = (tool, family)
            row: dict[str, Any] = {"tool": tool, "net": family, "size": size}
            if key in stopped:
                row["skipped"] = stopped[key]
                rows.append(row)
                continue
            previous = last.get(key)
            if tool != "petriflow" and previous and reference and "seconds" in previous:
                guess = previous["seconds"] * reference["states"] / max(previous["states"], 1)
                if guess > budget[tool]:
                    row["skipped"] = f"skipped: ~{guess:.0f} s expected (> {budget[tool]:.0f} s budget)"
                    stopped[key] = "skipped: a smaller size was already over the budget"
                    rows.append(row)
                    continue
            row.update(measure(tool, make, limit))
            if tool == "petriflow" and args.runs > 1 and "seconds" in row:
                # The machine's noise is larger than one run shows: repeat in fresh
                # processes, report the median and the range.
                times = [row["seconds"]] + [measure(tool, make, limit)["seconds"]
                                            for _ in range(args.runs - 1)]
                times.sort()
                row.update(seconds=times[len(times) // 2], seconds_min=times[0],
                           seconds_max=times[-1], runs=len(times))
            if "timeout" in row:
                stopped[key] = f"skipped: the previous size timed out (> {limit:.0f} s)"
            elif row["seconds"] > budget.get(tool, float("inf")):
                stopped[key] = f"skipped: previous size took {row['seconds']:.0f} s"
            if "states" in row:
                row["states_per_s"] = row["states"] / max(row["seconds"], 1e-9)
                if tool == "petriflow":
                    reference = row
                elif reference is not None:
                    if (row["states"], row["edges"]) != (reference["states"], reference["edges"]):
                        row["mismatch"] = (f"{tool} counts {row['states']}/{row['edges']},"
                                           f" petriflow {reference['states']}/{reference['edges']}")
                    row["petriflow_speedup"] = row["seconds"] / max(reference["seconds"], 1e-9)
                last[key] = row
            rows.append(row)
            print(_line(row), file=sys.stderr, flush=True)

    print(f"State-space exploration (full reachability graph), {platform.python_implementation()}"
          f" {platform.python_version()}, {os.cpu_count()} CPUs, {platform.machine()}")
    if "petriflow" in available:
        print(f"petriflow one-time start-up (import + loading the compiled loops, not in the"
              f" table): {warm_up:.2f} s")
    print()
    print("| tool | net | size | states | edges | seconds | states/s | peak RSS MiB | extra RSS MiB"
          " | petriflow speed-up |")
    print("|---|---|---|---:|---:|---:|---:|---:|---:|---:|")
    for row in rows:
        print(_line(row))
    print()
    print("peak RSS: ru_maxrss of the forked process that ran the exploration (interpreter and"
          " libraries included); extra RSS: peak minus resident size before the exploration.")
    print("petriflow speed-up: the tool's seconds / petriflow's seconds on the same net.")
    if any("mismatch" in row for row in rows):
        print("COUNT MISMATCH: " + "; ".join(row["mismatch"] for row in rows if "mismatch" in row))
    if args.json:
        with open(args.json, "w", encoding="utf-8") as out:
            json.dump({"python": platform.python_version(), "cpus": os.cpu_count(),
                       "rows": rows}, out, indent=2)
    return 1 if any("mismatch" in row for row in rows) else 0


def _line(row: dict[str, Any]) -> str:
    head = f"| {row['tool']} | {row['net']} | {row['size']} |"
    if "skipped" in row:
        return head + f" | | | | | | {row['skipped']} |"
    if "timeout" in row:
        return head + f" | | > {row['timeout']:.0f} | | | | timeout |"
    ratio = row.get("petriflow_speedup")
    speedup = "" if ratio is None else f"{ratio:.1f}x" if ratio < 10 else f"{ratio:,.0f}x"
    rate = f"{row['states_per_s']:,.0f}"
    if "runs" in row:
        rate += (f" ({row['states'] / row['seconds_max']:,.0f}-"
                 f"{row['states'] / max(row['seconds_min'], 1e-9):,.0f} in {row['runs']} runs)")
    return (head + f" {row['states']:,} | {row['edges']:,} | {row['seconds']:.3f} |"
            f" {rate} | {row['peak_rss_mib']:.0f} | {row['extra_rss_mib']:.0f}"
            f" | {speedup} |")


if __name__ == "__main__":
    sys.exit(main())
