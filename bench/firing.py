"""Random token game throughput: petriflow vs PM4Py vs SNAKES.

Plays the seeded random token game (fire a transition chosen uniformly among the enabled
ones, repeat) on the dining philosophers for N = 5, 10, 20 with each library, in one
process, side by side, and prints a Markdown table of firings per second.

* petriflow: :meth:`petriflow.engine.Simulation.run`.
* PM4Py: ``pm4py.objects.petri_net.semantics.enabled_transitions`` / ``execute`` on a
  PM4Py net built from ours with PM4Py's ``PetriNet`` / ``Marking`` classes, choosing
  with ``random.choice(list(enabled))`` as PM4Py's own basic playout does. (PM4Py hashes
  transitions by identity, so its choice order, unlike the rates, is not reproducible.)
* SNAKES: ``t.modes()`` for every transition, a random ``(t, mode)`` pair, ``t.fire(mode)``,
  on the net :func:`petriflow.interop.snakes.to_snakes` builds. SNAKES is slow, so it
  plays fewer firings; compare the firings/s column.

Each engine plays a short warm-up game on each net before the timed one; the timed part
is the game only (building and converting nets is left out). Timing uses
``time.perf_counter``.

PM4Py is AGPL-licensed: it is imported here, in the benchmark, never by petriflow.

Usage::

    python bench/firing.py                 # 200 000 firings (20 000 for SNAKES)
    python bench/firing.py --quick         # a smoke run
    python bench/firing.py --json out.json # also write the results as JSON
    python bench/firing.py --repeat 3      # keep the fastest of 3 timed games (busy machines)
"""

from __future__ import annotations

import argparse
import json
import random
import sys
import time
from pathlib import Path
from typing import Any, Callable, Sequence

from petriflow.classic import dining_philosophers
from petriflow.engine import Simulation
from petriflow.net import Net

sys.path.insert(0, str(Path(__file__).resolve().parent))  # bench/ holds scripts, not a package
from peers import to_pm4py, versions as peer_versions  # noqa: E402

ENGINES = ("petriflow", "PM4Py", "SNAKES")

#: A game: ``game(firings, seed) -> (firings made, seconds)``; each engine's factory
#: builds one from a net. Building and seeding are not timed, playing is.
Game = Callable[[int, int], "tuple[int, float]"]


def petriflow_game(net: Net) -> Game:
    """petriflow's token game: a fresh :class:`Simulation` per play, then ``run``."""
    from petriflow.engine import CompiledNet

    compiled = CompiledNet(net)

    def setup(seed: int) -> Callable[[int], int]:
        sim = Simulation(net, seed=seed, compiled=compiled)
        return lambda firings: len(sim.run(firings))

    return _timed_after(setup)


def pm4py_game(net: Net) -> Game:
    """PM4Py's token game with its classic semantics functions."""
    from pm4py.objects.petri_net import semantics

    pnet, start, _ = to_pm4py(net)
    enabled_transitions, execute = semantics.enabled_transitions, semantics.execute

    def setup(seed: int) -> Callable[[int], int]:
        rng = random.Random(seed)

        def play(firings: int) -> int:
            marking, fired = start, 0
            for _ in range(firings):
                enabled = enabled_transitions(pnet, marking)
                if not enabled:
                    break
                marking = execute(rng.choice(list(enabled)), pnet, marking)
                fired += 1
            return fired

        return play

    return _timed_after(setup)


def snakes_game(net: Net) -> Game:
    """SNAKES' token game: ``modes()`` of every transition, then ``fire`` one mode."""
    from petriflow.interop.snakes import snakes_marking, to_snakes

    snet = to_snakes(net)
    start = snakes_marking(net.initial_marking)
    transitions = snet.transition()

    def setup(seed: int) -> Callable[[int], int]:
        rng = random.Random(seed)
        snet.set_marking(start)

        def play(firings: int) -> int:
            fired = 0
            for _ in range(firings):
                choices = [(t, mode) for t in transitions for mode in t.modes()]
                if not choices:
                    break
                transition, mode = rng.choice(choices)
                transition.fire(mode)
                fired += 1
            return fired

        return play

    return _timed_after(setup)


def _timed_after(setup: Callable[[int], Callable[[int], int]]) -> Game:
    """A game that sets up untimed, then times only the firings."""

    def game(firings: int, seed: int) -> tuple[int, float]:
        play = setup(seed)
        start = time.perf_counter()
        fired = play(firings)
        return fired, time.perf_counter() - start

    return game


GAMES = {"petriflow": petriflow_game, "PM4Py": pm4py_game, "SNAKES": snakes_game}


def measure(
    sizes: Sequence[int], firings: int, snakes_firings: int, seed: int, warmup: int,
    repeat: int = 1,
) -> list[dict[str, Any]]:
    """Play every engine on every net; one result row per (net, engine).

    With ``repeat > 1`` each timed game is played that many times (same seed) and the
    fastest is kept, which filters out a busy machine's noise.
    """
    rows = []
    for n in sizes:
        net = dining_philosophers(n)
        for engine in ENGINES:
            game = GAMES[engine](net)
            count = snakes_firings if engine == "SNAKES" else firings
            game(min(warmup, count), seed + 1)  # warm-up, not recorded
            fired, seconds = min((game(count, seed) for _ in range(max(1, repeat))),
                                 key=lambda result: result[1])
            rows.append({
                "net": f"philosophers-{n}",
                "engine": engine,
                "firings": fired,
                "seconds": seconds,
                "rate": fired / seconds if seconds > 0 else float("inf"),
            })
    base = {row["net"]: row["rate"] for row in rows if row["engine"] == "petriflow"}
    for row in rows:
        row["ratio"] = row["rate"] / base[row["net"]]
    return rows


def speedups(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per net, petriflow's rate divided by PM4Py's and by SNAKES'."""
    by_net: dict[str, dict[str, float]] = {}
    for row in rows:
        by_net.setdefault(row["net"], {})[row["engine"]] = row["rate"]
    return [
        {"net": net, "petriflow/PM4Py": rates["petriflow"] / rates["PM4Py"],
         "petriflow/SNAKES": rates["petriflow"] / rates["SNAKES"]}
        for net, rates in by_net.items()
    ]


def markdown(rows: list[dict[str, Any]], firings: int, snakes_firings: int) -> str:
    """The results as Markdown: the main table, then petriflow's speed-ups."""
    lines = [
        "| net | engine | firings | seconds | firings/s | ratio vs petriflow |",
        "|---|---|---:|---:|---:|---:|",
    ]
    for row in rows:
        lines.append(
            f"| {row['net']} | {row['engine']} | {row['firings']:,} | {row['seconds']:.3f} "
            f"| {row['rate']:,.0f} | {row['ratio']:.3f} |"
        )
    lines += [
        "",
        f"SNAKES plays {snakes_firings:,} firings instead of {firings:,} (it is slow); "
        "compare firings/s. Ratio = engine firings/s ÷ petriflow firings/s.",
        "",
        "| net | petriflow ÷ PM4Py | petriflow ÷ SNAKES |",
        "|---|---:|---:|",
    ]
    for row in speedups(rows):
        lines.append(f"| {row['net']} | {row['petriflow/PM4Py']:.1f}× | {row['petriflow/SNAKES']:.1f}× |")
    return "\n".join(lines)


def versions() -> dict[str, str]:
    """Versions of Python and the libraries measured."""
    return peer_versions("petriflow", "pm4py", "snakes")


def main(argv: Sequence[str] | None = None) -> list[dict[str, Any]]:
    """Run the benchmark, print the Markdown table, and return the result rows."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="few firings: a smoke run")
    parser.add_argument("--firings", type=int, help="firings per petriflow/PM4Py game")
    parser.add_argument("--snakes-firings", type=int, help="firings per SNAKES game")
    parser.add_argument("--sizes", type=int, nargs="+", default=[5, 10, 20],
                        help="numbers of philosophers (default: 5 10 20)")
    parser.add_argument("--seed", type=int, default=2024)
    parser.add_argument("--repeat", type=int, default=1,
                        help="play each timed game this many times and keep the fastest")
    parser.add_argument("--json", metavar="OUT", help="also write the results to OUT as JSON")
    args = parser.parse_args(argv)
    firings = args.firings or (2_000 if args.quick else 200_000)
    snakes_firings = args.snakes_firings or (200 if args.quick else 20_000)
    warmup = max(1, min(2_000, firings // 10))
    rows = measure(args.sizes, firings, snakes_firings, args.seed, warmup, args.repeat)
    info = versions()
    best = f", best of {args.repeat}" if args.repeat > 1 else ""
    print(f"Random token game on dining philosophers, seed {args.seed}{best} "
          f"({', '.join(f'{k} {v}' for k, v in info.items())})")
    print()
    print(markdown(rows, firings, snakes_firings))
    if args.json:
        with open(args.json, "w", encoding="utf-8") as out:
            json.dump({"seed": args.seed, "firings": firings, "snakes_firings": snakes_firings,
                       "repeat": args.repeat, "versions": info, "rows": rows,
                       "speedups": speedups(rows)}, out, indent=2)
    return rows


if __name__ == "__main__":
    main()
