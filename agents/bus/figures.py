"""Seed 002's figures, measured: lost messages per bus and algorithm beside Tables 1–3,
and the modules' CPG phases over time in one run of each algorithm.

``python -m petriflow.agents.bus.figures --losses SWEEP.csv --out losses.png`` plots a
``petriflow sweep --csv`` of ``nets/bus/experiments/tables1-3.yaml`` (the ``_paper``
columns drawn as hollow bars, never used as results); ``--phases OUT.png`` runs the
shipped nets (seed 1, CAN) and plots each module's phase, and the neighbours' locking
error, against time.
"""

from __future__ import annotations

import argparse
import csv
import math
from pathlib import Path
from typing import Any

__all__ = ["draw_losses", "draw_phases"]


def _float(value: Any) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def draw_losses(table: Path, out: Path, reception: str = "loop") -> None:
    """Bars: mean lost % per module and bus, algorithm 1 and 2, the paper's hollow: the
    sniffer's count (``sniff_mK``, where the paper counts) when the table has it, else
    the addressees' (``lost_pct_mK``); rows of the given reception model when the
    table has several."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = list(csv.DictReader(table.open()))
    if rows and "reception" in rows[0]:
        rows = [r for r in rows if r["reception"] == reception]
    key = "sniff_m" if rows and "sniff_m1_mean" in rows[0] else "lost_pct_m"
    buses = [b for b in ("serial", "can", "zigbee") if any(r["bus"] == b for r in rows)]
    figure, axes = plt.subplots(1, len(buses), figsize=(4.2 * len(buses), 3.8), sharey=True)
    axes = [axes] if len(buses) == 1 else list(axes)
    width = 0.2
    for axis, bus in zip(axes, buses):
        for a, (algorithm, colour) in enumerate((("1", "tab:red"), ("2", "tab:blue"))):
            row = next((r for r in rows if r["bus"] == bus and str(r["algorithm"]) == algorithm), None)
            if row is None:
                continue
            for m in range(1, 4):
                x = m - 1 + (a - 0.5) * 2 * width
                axis.bar(x - width / 2, _float(row.get(f"{key}{m}_mean")), width,
                         yerr=_float(row.get(f"{key}{m}_sd")), color=colour, capsize=2,
                         label=f"algorithm {algorithm} (measured)" if m == 1 else None)
                axis.bar(x + width / 2, _float(row.get(f"{key}{m}_paper")), width, fill=False,
                         edgecolor=colour, hatch="//", label=f"algorithm {algorithm} (paper)" if m == 1 else None)
        axis.set_xticks(range(3))
        axis.set_xticklabels(["module 1", "module 2", "module 3"])
        axis.set_title(bus.upper())
        axis.grid(axis="y", alpha=0.3)
    axes[0].set_ylabel("messages lost of 100 (%)")
    axes[-1].legend(fontsize=7)
    counted = "by the sniffer" if key == "sniff_m" else "at the addressees"
    figure.suptitle(f"seed 002, Tables 1-3: lost messages per module ({counted}, reception: {reception}),"
                    " measured (mean ± sd) and published", fontsize=9)
    figure.tight_layout()
    figure.savefig(out, dpi=110)
    plt.close(figure)


def _run(algorithm: int, bus: str = "can", seed: int = 1) -> list[Any]:
    import shutil
    import tempfile

    import yaml

    from petriflow import examples
    from petriflow.runtime.session import run_files

    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        for name in ("world-3.yaml", "chain-3.urdf", f"bus-algorithm{algorithm}-3.yaml"):
            shutil.copy(examples.path("bus", name), folder / name)
        config = yaml.safe_load(examples.path("bus", "run.yaml").read_text())
        config["channels"]["bus"]["model"] = f"bus.{bus}"
        (folder / "run.yaml").write_text(yaml.safe_dump(config))
        return run_files(folder / f"bus-algorithm{algorithm}-3.yaml", seed=seed, keep_events=True).events


def draw_phases(out: Path, bus: str = "can", seed: int = 1, lag: float = 2 * math.pi / 3) -> None:
    """Each module's CPG phase relative to the head's, and the locking error, over time,
    for a run of each algorithm."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(2, 2, figsize=(12, 6), sharex="col")
    for column, algorithm in enumerate((1, 2)):
        events = _run(algorithm, bus, seed)
        series: dict[str, list[tuple[float, float]]] = {}
        for e in events:
            if e.kind == "custom" and e.data.get("name") == "bus.phase":
                series.setdefault(e.agent, []).append((e.time, e.data["data"]["phase"]))
        agents = sorted(series)
        if not agents:
            continue
        start = max(rows[0][0] for rows in series.values())
        stop = min(rows[-1][0] for rows in series.values())
        grid = [start + 0.1 * k for k in range(int((stop - start) / 0.1) + 1)]

        def at(agent: str, t: float, series: dict[str, list[tuple[float, float]]] = series) -> float:
            """The agent's phase at ``t``: its last sample, advanced at the intrinsic rate."""
            rows = series[agent]
            last = max((r for r in rows if r[0] <= t + 1e-9), key=lambda r: r[0])
            return last[1] + 0.5 * (t - last[0])

        phases = {agent: [at(agent, t) for t in grid] for agent in agents}
        top, bottom = axes[0][column], axes[1][column]
        for agent in agents[1:]:
            top.plot(grid, [math.remainder(a - b, 2 * math.pi) for a, b in zip(phases["m1"], phases[agent])],
                     linewidth=1, label=f"φ(m1) − φ({agent})")
        for k in (1, 2):
            top.axhline(math.remainder(k * lag, 2 * math.pi), color="0.6", linestyle="--", linewidth=0.8)
        top.set_ylabel("phase lag to the head (rad)")
        top.set_title(f"algorithm {algorithm}, {bus.upper()} (seed {seed})")
        top.legend(fontsize=7)
        errors = [sum(abs(math.remainder(phases[a][i] - phases[b][i] - lag, 2 * math.pi))
                      for a, b in zip(agents, agents[1:])) / (len(agents) - 1) for i in range(len(grid))]
        bottom.plot(grid, errors, color="k", linewidth=0.8)
        bottom.set_ylabel("locking error (rad)")
        bottom.set_xlabel("time (s)")
        bottom.set_ylim(0, math.pi)
        for axis in (top, bottom):
            axis.grid(alpha=0.3)
    figure.suptitle("seed 002: the CPG phases of a 3-module chain over time (dashed: the wanted lags)")
    figure.tight_layout()
    figure.savefig(out, dpi=110)
    plt.close(figure)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description="draw seed 002's figures")
    parser.add_argument("--losses", type=Path, help="a sweep CSV of tables1-3.yaml")
    parser.add_argument("--out", type=Path, default=Path("losses.png"))
    parser.add_argument("--phases", type=Path, help="where to draw the phases of one run of each algorithm")
    args = parser.parse_args(argv)
    if args.losses:
        draw_losses(args.losses, args.out)
        print(f"wrote {args.out}")
    if args.phases:
        draw_phases(args.phases)
        print(f"wrote {args.phases}")


if __name__ == "__main__":
    main()
