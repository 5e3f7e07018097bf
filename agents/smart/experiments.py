"""The SMART experiments of seed 003 (§5), run and measured beside the paper's results.

::

    python -m petriflow.agents.smart.experiments {reinsertion,crossing,helping,all} [--out DIR]

Each experiment runs a net of ``nets/smart/`` with ``petriflow``'s runtime (the same
as ``petriflow run``) over its pybullet world, writes the run's trace
(``NAME.jsonl``) and a top view of the arena with the paths planned (dashed) and
walked as the camera saw them (solid) (``NAME.png``) into ``--out`` (default
``out/smart/``), and prints what it measured next to what the paper reports. Every
robot walks by its legs (Robot3L's sliding gait, Robot4L's righting motion); the
camera renders 640 x 480 frames at 6 Hz of simulated time.

1. ``reinsertion`` (§5.1, Fig. 14): ``reinsertion.yaml``: Robot3L walks an A* path;
   at t = 20 s a 5 N push for 0.3 s shoves it sideways; path tracking (§4.2) measures
   ``dc`` after every move and reinserts it at the farthest path point within reach.
2. ``crossing`` (§5.1, Fig. 15): ``crossing.yaml`` over ``world-crossing.yaml``: two
   Robot3L on crossing paths; the lower-priority one holds, the other re-plans.
3. ``helping`` (§5.2, Fig. 16-18): ``smart.yaml``: Robot3L walks to the fallen Robot4L
   and braces it; Robot4L stands up.

The paper's figures are printed as the comparison column only; nothing measured is
taken from them.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from petriflow import examples

__all__ = ["NETS", "Run", "crossing", "helping", "main", "reinsertion", "run_net", "world_with_camera"]


#: Where the SMART nets and worlds are (``nets/smart``, installed with petriflow).
NETS = examples.path("smart")
#: The camera loop's transitions (left out of the firing sequences printed).
LOOP = {"T1", "T2", "T3", "T4", "detect"}


@dataclass
class Run:
    """One experiment run: its outcome, events, timers and files."""

    name: str
    outcome: Any
    events: list
    timers: Any
    world: dict[str, Any]
    files: list[str] = field(default_factory=list)

    def ends(self, transition: str) -> list:
        return [e for e in self.events if e.kind == "end" and e.transition == transition]

    def custom(self, name: str) -> list:
        return [e for e in self.events if e.kind == "custom" and e.data.get("name") == name]

    def seen(self) -> list[tuple[float, dict[str, Any]]]:
        """``(time, {colour: {x, y, heading}})`` of every processed image (``T3``)."""
        return [(e.time, (e.data.get("result") or {}).get("robots") or {}) for e in self.ends("T3")]


def world_with_camera(world: Path, out: Path, camera: tuple[int, int] | None) -> Path:
    """The world file, or a copy in ``out`` with the camera resized."""
    if camera is None:
        return world
    import yaml

    data = yaml.safe_load(world.read_text(encoding="utf-8"))
    for entry in data.get("cameras") or []:
        entry["width"], entry["height"] = int(camera[0]), int(camera[1])
    copy = out / f"{world.stem}-{camera[0]}x{camera[1]}.yaml"
    copy.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return copy


def run_net(name: str, net: Path, world: Path, out: Path, *, until: float, seed: int = 1,
            camera: tuple[int, int] | None = None) -> Run:
    """Run ``net`` over ``world`` as ``petriflow run`` does, timing its parts, writing
    ``out/NAME.jsonl``."""
    import yaml
    from petriflow.agents.planning.astar import warm_up
    from petriflow.agents.smart.timing import Timers

    from petriflow.runtime.session import run_files

    out.mkdir(parents=True, exist_ok=True)
    world_path = world_with_camera(world, out, camera)
    warm_up()  # numba compiles (or loads) A* once per process: not part of a planning time
    trace = out / f"{name}.jsonl"
    with Timers() as timers:
        outcome = run_files(net, world=world_path, seed=seed, until=until, trace=trace, keep_events=True,
                            stopwatch=timers)
    data = yaml.safe_load(world_path.read_text(encoding="utf-8"))
    return Run(name, outcome, outcome.events, timers, data, [str(trace)])


# Printing ------------------------------------------------------------------------------
def _table(title: str, rows: Sequence[tuple[str, str, str]]) -> str:
    lines = [f"\n{title}\n", "| quantity | measured | paper (seed 003) |", "|---|---|---|"]
    lines += [f"| {a} | {b} | {c} |" for a, b, c in rows]
    return "\n".join(lines)


def _xy(point: Sequence[float] | None) -> str:
    return "-" if point is None else f"({point[0]:.3f}, {point[1]:.3f}) m"


def _track_of(run: Run, colour: str) -> list[tuple[float, float, float]]:
    return [(t, r[colour]["x"], r[colour]["y"]) for t, r in run.seen()
            if colour in r and r[colour].get("x") is not None]


def _draw_common(run: Run, view: Any, colours: dict[str, str]) -> None:
    for robot in run.world.get("robots") or []:
        x, y = robot.get("position", (0.0, 0.0))
        view.square((x, y, robot.get("yaw", 0.0)), 0.26, "grey", 1)
        view.text((x - 0.13, y - 0.17), robot["id"] + (" (lying)" if robot.get("roll") else ""), "grey", 0.4)
    for colour, drawn in colours.items():
        track = _track_of(run, colour)
        if track:
            view.path([(x, y) for _, x, y in track], drawn, thickness=2)
    for event in run.custom("smart.path"):
        colour = event.data["data"].get("colour")
        path = event.data["data"].get("path")
        if isinstance(path, list) and colour in colours:
            view.path(path, "dark" if colour != "blue" else "purple", thickness=1, dashed=True)


# 1. Reinsertion ------------------------------------------------------------------------
def reinsertion(out: Path, camera: tuple[int, int] | None = None) -> dict[str, Any]:
    """Experiment 1: a pushed robot returns to its path (see the module)."""
    import numpy as np
    from petriflow.agents.planning.tracking import densify, distance_to_path
    from petriflow.agents.smart.draw import TopView

    run = run_net("reinsertion", NETS / "reinsertion.yaml", NETS / "world.yaml", out, until=120, camera=camera)
    result = run.outcome.result
    push = run.ends("push")[0] if run.ends("push") else None
    walks = run.ends("walk")
    checks = [c for w in walks for c in ((w.data.get("result") or {}).get("checks") or [])]
    push_t = push.time if push else 0.0
    after = [c for c in checks if c["t"] >= push_t - 1e-9]
    first = next((c for c in after if c["decision"] != "on_track"), None)
    paths = [e.data["data"] for e in run.custom("smart.path")]
    planned = paths[0] if paths else {}
    summary: dict[str, Any] = {
        "reason": result.reason, "time": result.time, "push": push.data.get("result") if push else None,
        "first_off_track": first, "replans": sum(1 for w in walks if w.data["outcome"] == "failed"),
    }
    candidates = None
    ahead = None
    if first is not None and planned.get("path"):
        dense = densify(planned["path"], 0.01)
        position = np.asarray(first["position"])
        reach = max(planned.get("reach", 0.16), first["dc"])
        within = np.flatnonzero(np.hypot(*(dense - position).T) <= reach + 1e-9)
        _, nearest, _ = distance_to_path(dense, position)
        candidates = int(within.size)
        if first.get("point") is not None:
            _, index, _ = distance_to_path(dense, first["point"])
            steps = np.hypot(*np.diff(dense, axis=0).T)
            ahead = float(steps[nearest:index].sum()) if index >= nearest else -float(steps[index:nearest].sum())
        summary["candidates"] = candidates
        summary["ahead_m"] = ahead
    rejoined = None
    if first is not None and first["decision"] == "reinsert":
        back = next((c for c in after if c["t"] > first["t"] and c["decision"] == "on_track"), None)
        rejoined = back
    summary["rejoined"] = rejoined
    summary["arrived"] = bool(walks) and walks[-1].data["outcome"] == "ok"
    final_dc = after[-1]["dc"] if after else None
    summary["final_dc"] = final_dc
    # picture
    view = TopView(run.world, scale=300)
    _draw_common(run, view, {"yellow": "orange"})
    if push:
        res = push.data["result"]
        view.arrow(res["from"], [res["from"][0] + 2 * (res["to"][0] - res["from"][0]) + 0.001,
                                 res["from"][1] + 2 * (res["to"][1] - res["from"][1])], "red")
        view.text([res["from"][0] - 0.2, res["from"][1] - 0.08], "push", "red")
    if first is not None:
        view.mark(first["position"], "purple")
        if planned.get("reach"):
            view.disc(first["position"], max(planned["reach"], first["dc"]), "purple", thickness=1)
        if first.get("point"):
            view.disc(first["point"], 0.015, "green")
            view.text([first["point"][0] + 0.03, first["point"][1] - 0.05], "reinsertion point", "green")
    view.legend([("planned path (A*)", "dark", True), ("walked (camera)", "orange", False),
                 ("reach of one move", "purple", False)])
    run.files.append(view.save(out / "reinsertion.png"))
    rows = [
        ("run", f"{result.reason} at t = {result.time:.1f} s", "real Robot3L, hand push"),
        ("disturbance", f"{push.data['result']['force'][1]:.1f} N for {push.data['result']['duration']} s "
                        f"at t = {push_t:.1f} s" if push else "-", "robot leaves the path (Fig. 14a)"),
        ("dmin (one move) / r (radius)", f"{planned.get('step', 0):.3f} m / {planned.get('radius', 0):.3f} m",
         "dmin = standard displacement, r = robot radius"),
        ("first check off the path", "-" if first is None else
         f"t = {first['t']:.2f} s, dc = {first['dc']:.3f} m -> {first['decision']}",
         "detected by path tracking"),
        ("candidate points within reach", "-" if candidates is None else f"{candidates} (1 cm apart)",
         "neighbouring points (Fig. 14b)"),
        ("chosen reinsertion point", "-" if first is None or first.get("point") is None else
         f"{_xy(first['point'])}, {ahead:.3f} m ahead along the path", "the farthest one"),
        ("rejoined", "no" if rejoined is None else f"yes, t = {rejoined['t']:.2f} s (dc = {rejoined['dc']:.3f} m)",
         "yes"),
        ("re-plans", str(summary["replans"]), "0 (dc <= r)"),
        ("goal reached", (f"{'yes' if summary['arrived'] else 'no'}, last dc = "
                          f"{'-' if final_dc is None else f'{final_dc:.3f} m'}"), "yes"),
    ]
    print(_table("Experiment 1: reinsertion of a robot pushed off its path (Fig. 14)", rows))
    summary["files"] = run.files
    return summary


# 2. Crossing ----------------------------------------------------------------------------
def crossing(out: Path, camera: tuple[int, int] | None = None) -> dict[str, Any]:
    """Experiment 2: two robots on crossing paths (see the module)."""
    from petriflow.agents.smart.draw import TopView

    run = run_net("crossing", NETS / "crossing.yaml", NETS / "world-crossing.yaml", out, until=150,
                  camera=camera)
    result = run.outcome.result
    orders = [e for e in run.custom("smart.order")]
    first = next((e for e in orders if e.data["data"]["order"] == "replan"), None)
    seen = run.seen()
    at = None
    if first is not None:
        before = [r for t, r in seen if t <= first.time + 1e-9]
        at = before[-1] if before else None
    gap = None
    if at and "yellow" in at and "blue" in at:
        gap = math.dist((at["yellow"]["x"], at["yellow"]["y"]), (at["blue"]["x"], at["blue"]["y"]))
    closest = min((math.dist((r["yellow"]["x"], r["yellow"]["y"]), (r["blue"]["x"], r["blue"]["y"]))
                   for _, r in seen if "yellow" in r and "blue" in r), default=None)
    plans = {c: [e.data["result"] for e in run.ends(f"{c}_plan") if e.data["outcome"] == "ok"] for c in "yb"}
    walks = {c: run.ends(f"{c}_walk") for c in "yb"}
    releases = run.custom("smart.release")
    held = sum(e.data["data"]["held"] for e in releases if e.data["data"]["robot"] == "blue3l")
    arrived = {c: bool(walks[c]) and walks[c][-1].data["outcome"] == "ok" for c in "yb"}
    summary = {"reason": result.reason, "time": result.time,
               "detected_at": None if first is None else first.time, "centre_distance_at_detection": gap,
               "closest_centres": closest, "yellow_plans": [p["length_m"] for p in plans["y"]],
               "blue_plans": [p["length_m"] for p in plans["b"]], "blue_held_s": held, "arrived": arrived,
               "frames": [e.data["data"] for e in run.custom("smart.frame")
                          if e.data["data"]["action"] == "STOP"]}
    view = TopView(run.world, scale=300)
    _draw_common(run, view, {"yellow": "orange", "blue": "blue"})
    if first is not None and at:
        for colour in ("yellow", "blue"):
            if colour in at:
                view.square((at[colour]["x"], at[colour]["y"], at[colour]["heading"]), 0.26,
                            "orange" if colour == "yellow" else "blue", 1)
        view.text([at["blue"]["x"] + 0.16, at["blue"]["y"]], f"conflict t={first.time:.1f}s", "red")
    view.legend([("planned (A*, dashed: first, re-plan)", "dark", True), ("yellow walked (camera)", "orange", False),
                 ("blue walked (camera)", "blue", False)])
    run.files.append(view.save(out / "crossing.png"))
    limit = 2 * 0.08 + 2 * 0.13
    rows = [
        ("run", f"{result.reason} at t = {result.time:.1f} s", "two real walking robots"),
        ("conflict detected", "-" if first is None else
         f"t = {first.time:.2f} s, centres {gap:.3f} m apart (< {limit:.2f} m: gap < 2 steps)",
         "Agent 2 interferes with Agent 1 (Fig. 15a)"),
        ("lower priority (blue, agent 2)", f"held {held:.1f} s (STOP frame), then resumed its own path",
         "stopped until agent 1 passes"),
        ("higher priority (yellow, agent 1)",
         f"re-planned around blue: {', '.join(f'{v:.2f}' for v in summary['yellow_plans'])} m",
         "new path planning (Fig. 15b)"),
        ("closest approach (centres)", "-" if closest is None else f"{closest:.3f} m (robots are 0.26 m wide)",
         "no collision"),
        ("goals reached", f"yellow {'yes' if arrived['y'] else 'no'}, blue {'yes' if arrived['b'] else 'no'}",
         "-"),
    ]
    print(_table("Experiment 2: collision avoidance on crossing paths (Fig. 15)", rows))
    summary["files"] = run.files
    return summary


# 3. Helping -----------------------------------------------------------------------------
def helping(out: Path, camera: tuple[int, int] | None = None) -> dict[str, Any]:
    """Experiment 3: the helping task of the corrected Fig. 17 net (see the module)."""
    from petriflow.agents.smart.draw import TopView

    run = run_net("helping", NETS / "smart.yaml", NETS / "world.yaml", out, until=150, camera=camera)
    result = run.outcome.result
    timers = run.timers
    starts = [e.transition for e in run.events if e.kind == "start"]
    cut = starts.index("T5") if "T5" in starts else len(starts)
    sequence = starts[:cut] + [t for t in starts[cut:] if t not in LOOP]
    captures = len(run.ends("T2")) + len(run.ends("T0"))
    dispatch = run.ends("T5")[0].data.get("result") if run.ends("T5") else {}
    plan = run.ends("T7")[0].data.get("result") if run.ends("T7") else {}
    follow = run.ends("T8")[0].data.get("result") if run.ends("T8") else {}
    stand = run.ends("T6")[0].data.get("result") if run.ends("T6") else {}
    frames = [e.data["data"] for e in run.custom("smart.frame")]
    render = timers.samples["render"]
    vision = timers.samples["vision"]
    planning = timers.samples["planning"]
    search = timers.samples["search"]
    mean = (lambda xs: sum(xs) / len(xs) if xs else float("nan"))
    summary = {
        "reason": result.reason, "time": result.time, "wall": run.outcome.wall,
        "sequence": sequence, "images": captures, "loop_hz": captures / result.time if result.time else None,
        "render_fps": 1 / mean(render), "processing_fps": 1 / (mean(render) + mean(vision)),
        "planning_ms": [round(1000 * s, 3) for s in planning], "search_ms": [round(1000 * s, 3) for s in search],
        "path_m": plan.get("length_m"), "path_cells": plan.get("steps"),
        "stand_up": stand, "frames": frames, "fallen": dispatch.get("fallen"), "helper_end": follow,
    }
    view = TopView(run.world, scale=300)
    _draw_common(run, view, {"yellow": "orange", "red": "red"})
    fallen = dispatch.get("fallen") or {}
    if fallen:
        view.disc((fallen["x"], fallen["y"]), 0.15, "red", thickness=1)
        view.text((fallen["x"] + 0.12, fallen["y"] + 0.1), "Robot4L (fallen)", "red")
        view.mark(fallen["brace"][:2], "green")
        view.text((fallen["brace"][0] + 0.05, fallen["brace"][1] - 0.04), "brace point", "green")
    goal = (dispatch.get("goal") or {}).get("yellow")
    if goal:
        view.disc(goal, 0.015, "purple")
        view.text((goal[0] + 0.03, goal[1] - 0.05), "final point (HELP)", "purple")
    view.legend([("planned path (A*)", "dark", True), ("Robot3L walked (camera)", "orange", False),
                 ("Robot4L (camera, once upright)", "red", False)])
    run.files.append(view.save(out / "helping.png"))
    paper_sequence = "T1 T3 T4 T5 T7 T8 T6 T9 (Fig. 18)"
    rows = [
        ("run", f"{result.reason} at t = {result.time:.1f} s simulated, {run.outcome.wall:.1f} s wall",
         "task completed (Fig. 16)"),
        ("firings (camera loop left out after T5)", " ".join(sequence), paper_sequence),
        ("control loop (images per simulated s)", f"{summary['loop_hz']:.2f} Hz ({captures} images)", "6 fps"),
        ("capture (render) rate, wall clock", (f"{summary['render_fps']:.1f} fps at "
                                               f"{(camera or (640, 480))[0]}x{(camera or (640, 480))[1]}"),
         "15 fps (IP camera, VGA)"),
        ("capture + processing rate, wall clock", f"{summary['processing_fps']:.1f} fps", "11 fps"),
        ("path planning (map + C-space + A*, optimal)",
         (f"{', '.join(f'{v:.1f}' for v in summary['planning_ms'])} ms (A* search "
          f"{', '.join(f'{v:.1f}' for v in summary['search_ms'])} ms); path {summary['path_m']:.2f} m"),
         "< 30 ms (A*, 320x240 maps)"),
        ("SMART frames", " ".join(f"{f['action']}[{f['hex']}]" for f in frames if f["action"] != "MOVE_TO")
         + f" + {sum(f['action'] == 'MOVE_TO' for f in frames)} MOVE_TO", "command, robot id, ',' params, '%'"),
        ("Robot4L after T6", f"upright (tilt {stand.get('tilt', float('nan')):.1f} deg, from its "
                             f"{stand.get('from', '?')} side)" if stand else "-", "stands up leaning on Robot3L"),
    ]
    print(_table("Experiment 3: the helping task, net smart.yaml (Fig. 16-18)", rows))
    summary["files"] = run.files
    return summary


EXPERIMENTS = {"reinsertion": reinsertion, "crossing": crossing, "helping": helping}


def _size(text: str) -> tuple[int, int]:
    try:
        width, height = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"a camera size is WIDTHxHEIGHT, got {text!r}") from None
    return width, height


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m petriflow.agents.smart.experiments",
                                     description="Run the SMART experiments of seed 003 and print them "
                                                 "beside the paper's results.")
    parser.add_argument("experiment", choices=[*EXPERIMENTS, "all"])
    parser.add_argument("--out", default="out/smart", help="folder for traces and pictures (default: out/smart)")
    parser.add_argument("--camera", type=_size, default=None,
                        help="render at WIDTHxHEIGHT instead of the worlds' 640x480 (e.g. 320x240)")
    parser.add_argument("--json", default=None, help="also write the measured results to this JSON file")
    args = parser.parse_args(argv)
    out = Path(args.out)
    names = list(EXPERIMENTS) if args.experiment == "all" else [args.experiment]
    results = {}
    for name in names:
        results[name] = EXPERIMENTS[name](out, camera=args.camera)
        print("\nwrote " + ", ".join(results[name]["files"]))
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(results, indent=2, default=str), encoding="utf-8")
    ok = all(r["reason"] == "final" for r in results.values())
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
