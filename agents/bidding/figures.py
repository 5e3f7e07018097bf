"""Seed 004's figures, measured: the global maps coloured by robot (Fig. 8-9) and
mapping time, messages and accuracy against team size (Fig. 10).

``python -m petriflow.agents.bidding.figures --maps OUT_DIR`` runs the missions (2 and 4
robots, both deployments, seed 1) and draws the HMIA's global map of each;
``--trends SWEEP.csv --out OUT.png`` plots a ``petriflow sweep --csv`` of
``nets/bidding/experiments/table7.yaml`` with the paper's Table 7 beside it (the
sweep's ``_paper`` columns, drawn dashed, never used as a result).
"""

from __future__ import annotations

import argparse
import csv
import tempfile
from pathlib import Path
from typing import Any

from petriflow.agents.bidding.interface import MakeInterface

__all__ = ["mission_map", "draw_trends"]


def mission_map(robots: int, deployment: str, *, seed: int = 1, **options: Any) -> tuple[Any, Any]:
    """Run the mission in the paper's office; the HMIA's state at the end and the run outcome."""
    from petriflow import examples
    from petriflow.agents.bidding.nets import build
    from petriflow.io.yaml import dumps_net
    from petriflow.runtime.registry import Registry
    from petriflow.runtime.session import run_files

    kept: list[Any] = []

    class Keeping(MakeInterface):
        def run(self, ctx):
            super().run(ctx)
            kept.append(ctx.state)

    registry = Registry()
    registry.names()  # load the plugins first: this replaces one of their actions
    registry.register("bidding.interface", Keeping, doc="the interface agent, kept for drawing", replace=True)
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        (folder / "world.yaml").write_text(examples.path("bidding", "world.yaml").read_text())
        (folder / "run.yaml").write_text(examples.path("bidding", "run.yaml").read_text())
        (folder / "net.yaml").write_text(dumps_net(build(robots, deployment, **options)))
        outcome = run_files(folder / "net.yaml", seed=seed, registry=registry, keep_events=True)
    return kept[0], outcome


def draw_maps(out: Path, seed: int = 1) -> list[Path]:
    from petriflow.agents.bidding.grid import accuracy, draw_map, fictitious
    from petriflow.agents.bidding.office import paper_office

    office = paper_office()
    written = []
    for robots in (2, 4):
        for deployment in ("random", "autonomous"):
            hmia, outcome = mission_map(robots, deployment, seed=seed)
            score = fictitious(hmia.global_map)
            fit = accuracy(hmia.global_map.occupied, hmia.truth.occupied, 1)
            end = hmia.end_sent if hmia.end_sent is not None else outcome.result.time
            title = (f"{robots} robots, {deployment} deployment (seed {seed}): {end - hmia.map_sent:.0f} s,"
                     f" accuracy {score.percent:.1f} % (fit {fit.percent:.0f} %)")
            path = out / f"map-{robots}-{deployment}.png"
            draw_map(hmia.global_map, path, office=office, title=title)
            written.append(path)
    return written


def _float(value: str | None) -> float:
    try:
        return float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return float("nan")


def draw_trends(table: Path, out: Path) -> None:
    """Time, messages and accuracy against team size, mean ± sd per deployment, from the
    CSV ``petriflow sweep --csv`` writes (one line per row: ``<metric>_mean``,
    ``_sd`` and ``_paper``); the paper's values dashed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = list(csv.DictReader(table.open()))
    figure, axes = plt.subplots(1, 3, figsize=(13, 4))
    for axis, metric, label in zip(axes, ("time_s", "messages", "accuracy_pct"),
                                   ("mapping time (s), eq. 9", "messages", "accuracy (%), eq. 10")):
        for deployment, colour in (("random", "tab:red"), ("autonomous", "tab:blue")):
            mine = sorted((r for r in rows if r["deployment"] == deployment), key=lambda r: int(r["robots"]))
            sizes = [int(r["robots"]) for r in mine]
            axis.errorbar(sizes, [_float(r.get(f"{metric}_mean")) for r in mine],
                          yerr=[_float(r.get(f"{metric}_sd")) for r in mine], color=colour, marker="o", capsize=3,
                          label=f"{deployment} (measured)")
            axis.plot(sizes, [_float(r.get(f"{metric}_paper")) for r in mine], color=colour, linestyle="--",
                      marker="x", alpha=0.7, label=f"{deployment} (paper)")
        axis.set_xlabel("robots")
        axis.set_title(label)
        axis.set_xticks(sorted({int(r["robots"]) for r in rows}))
        axis.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    trials = max((int(r["trials"]) for r in rows), default=0)
    figure.suptitle(f"seed 004, Table 7 / Fig. 10: measured (mean ± sd of {trials} trials) and published (dashed)")
    figure.tight_layout()
    figure.savefig(out, dpi=110)
    plt.close(figure)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description="draw seed 004's figures")
    parser.add_argument("--maps", type=Path, help="folder for the global maps (Fig. 8-9)")
    parser.add_argument("--trends", type=Path, help="a sweep CSV of table7.yaml (Fig. 10)")
    parser.add_argument("--out", type=Path, default=Path("fig10.png"))
    args = parser.parse_args(argv)
    if args.maps:
        args.maps.mkdir(parents=True, exist_ok=True)
        for path in draw_maps(args.maps):
            print(f"wrote {path}")
    if args.trends:
        draw_trends(args.trends, args.out)
        print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
