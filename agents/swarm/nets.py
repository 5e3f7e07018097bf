"""The swarm mission as a workflow net, for any number of robots (:func:`build`), and
its worlds (:func:`world`).

One subnet per robot ``robotK`` (state ``swarm.scout``), the same for every robot:

* ``wake`` (``swarm.wake``): ``start`` to ``idle``;
* ``step`` (``swarm.explore``): ``idle`` to ``moved``, one cell of exploration;
* ``share`` (``swarm.share``, guard ``swarm.has_frame``, priority 2): ``moved`` to
  ``sending`` and a frame into the robot's radio place ``air`` (channel ``swarm``);
* ``sent`` (``swarm.sent``): the frame back from the medium and ``sending`` to ``idle``;
* ``go_on`` (guard ``swarm.going_on``): ``moved`` to ``idle``;
* ``finish`` (guard ``swarm.explored``): ``moved`` to ``back``;
* ``home`` (``swarm.home``): ``back`` to ``done``.

The net grows linearly with the team: 7 transitions and 7 places a robot, no place
shared between robots. Who hears a frame is the medium's business (a broadcast to the
robots in range, :mod:`petriflow.agents.swarm.radio`), not the net's: a frame goes out
of the radio place and its end of transmission comes back, so ``petriflow check``
proves each robot's loop sound and bounded whatever the team.

The world (:func:`world`): a maze generated from a seed, about ``cells_per_robot``
cells a robot (``cols`` = ``rows`` = ceil(sqrt(robots x cells_per_robot))), cells of
``cell`` metres, the robots spread over a lattice of cells, in the kinematic world mode
(masses none, poses integrated in arrays).

**Tiles** (``tiles`` = k, the same in :func:`build` and :func:`world`): the team cut into
k equal teams, each in its own copy of the (robots / k)-robot maze, the copies stacked
north of each other ``gap`` metres apart (beyond the radio's range: no robot hears
another tile). Every tile runs the same mission as the (robots / k)-robot world, so the
work is exactly k times one tile's: a control for measuring how the run's cost grows
with the team when the work per robot does not (a larger single maze has fewer robots
at its edges, so more neighbours and more map per robot). Cell ids stay unique: every
robot's map is the whole stack (``rows`` counts the gaps' rows, which no robot enters).

``python -m petriflow.agents.swarm.nets`` writes ``nets/swarm/`` (the 3-robot net and
world, the sweep's worlds).

Examples:
    >>> net = build(robots=3)
    >>> len(net.subnets), len(net.transitions), net.subnets["robot2"].state
    (3, 23, 'swarm.scout')
    >>> from petriflow.analysis.report import check_net
    >>> check_net(net)["sound"]
    True
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from petriflow.net import Net
from petriflow.netbuild import NetBuilder

__all__ = ["build", "world", "size", "starts", "tiling", "main"]

#: The robots' body (a differential-drive disc; its masses are dropped in the kinematic mode).
URDF = "petriflow.agents:robots/diffdrive.urdf"
MAZE_SEED = 7
LOOPS = 0.1


def size(robots: int, cells_per_robot: float = 8.0) -> int:
    """Cells a side of the maze for a team (at least 4)."""
    return max(4, math.ceil(math.sqrt(robots * cells_per_robot)))


def starts(robots: int, cols: int) -> list[tuple[int, int]]:
    """Start cells ``(row, col)``: a lattice of k x k (k = ceil(sqrt(robots))) spread over the maze."""
    k = math.ceil(math.sqrt(robots))
    spots = [(min(cols - 1, int((a + 0.5) * cols / k)), min(cols - 1, int((b + 0.5) * cols / k)))
             for a in range(k) for b in range(k)]
    return spots[:robots]


def tiling(robots: int, tiles: int = 1, cells_per_robot: float = 8.0, cell: float = 1.0,
           gap: float = 10.0) -> tuple[int, int, int]:
    """``(robots a tile, cells a side of a tile's maze, rows from one tile's first row to
    the next's)`` for a team cut into ``tiles`` (see the module)."""
    if not 1 <= robots <= 100_000:
        raise ValueError(f"robots must be from 1 to 100,000, got {robots}")
    if not 1 <= tiles <= robots or robots % tiles:
        raise ValueError(f"tiles must divide the robots ({robots}) into equal teams, got {tiles}")
    if not gap >= 0:
        raise ValueError(f"gap must be at least 0 m, got {gap}")
    each = robots // tiles
    side = size(each, cells_per_robot)
    return each, side, side + math.ceil(gap / cell)


def build(robots: int = 3, *, cells_per_robot: float = 8.0, cell: float = 1.0, reach: int = 4,
          speed: float = 0.5, turn_rate: float = 2.0, tiles: int = 1, gap: float = 10.0, **ignored: Any) -> Net:
    """The mission's net (see the module).

    Args:
        robots: robots in the swarm (1..100,000).
        cells_per_robot, cell: the maze's size per robot and cell side (m): they give
            the maze's side (:func:`size`), which every robot's map needs.
        reach: cells a robot looks ahead for unmapped cells; with none that near, it
            goes home.
        speed, turn_rate: the robots' cruise speed (m/s) and turn rate (rad/s).
        tiles, gap: the team cut into this many equal teams, each in its own copy of
            the maze, ``gap`` metres apart (see the module; the world's must match).
        ignored: other sweep parameters (they go elsewhere).
    """
    _, side, pitch = tiling(robots, tiles, cells_per_robot, cell, gap)
    rows = pitch * (tiles - 1) + side
    shape = f"a {side} x {side} maze" if tiles == 1 else f"{tiles} copies of a {side} x {side} maze"
    b = NetBuilder(f"swarm-{robots}" if tiles == 1 else f"swarm-{robots}-tiles-{tiles}",
                   label=f"a swarm of {robots} robots maps {shape}")
    for k in range(1, robots + 1):
        name = f"robot{k}"
        a = b.agent(name, label=f"robot {k}", state="swarm.scout")
        for local in ("start", "idle", "moved", "sending", "back", "done"):
            a.place(local)
        air = a.place("air", channel="swarm", label=f"{name}'s radio")
        move = {"speed": speed, "turn_rate": turn_rate, "air": air}
        wake = {"air": air, "cols": side, "rows": rows, "cell": cell, "origin": [0.0, 0.0], "horizon": 2 * reach}
        a.transition("wake", action="swarm.wake", params=wake, inputs=["start"], outputs=["idle"])
        a.transition("step", label="one cell of exploration", action="swarm.explore", params=dict(move, reach=reach),
                     inputs=["idle"], outputs=["moved"])
        a.transition("share", label="a frame on the air", action="swarm.share", params={"air": air},
                     guard="swarm.has_frame", priority=2, inputs=["moved"], outputs=["sending", "air"])
        a.transition("sent", label="end of transmission", action="swarm.sent", params={"air": air},
                     inputs=["sending", "air"], outputs=["idle"])
        a.transition("go_on", guard="swarm.going_on", priority=1, inputs=["moved"], outputs=["idle"])
        a.transition("finish", label="nothing unmapped within reach", guard="swarm.explored", priority=1,
                     inputs=["moved"], outputs=["back"])
        a.transition("home", label="back to the start", action="swarm.home", params=move, inputs=["back"],
                     outputs=["done"])
        a.start("start")
        a.done("done")
    b.envelope(begin_label="deploy", end_label="every robot home")
    b.require({"id": "one_frame_per_radio", "description": "a robot's radio carries one frame at a time",
               "always": " && ".join(f"robot{k}_air <= 1" for k in range(1, robots + 1))})
    b.require_delivery()  # the mission can end from every reachable marking
    return b.build()


def world(robots: int = 3, *, cells_per_robot: float = 8.0, cell: float = 1.0, maze_seed: int = MAZE_SEED,
          dt: float = 0.1, tiles: int = 1, gap: float = 10.0) -> dict[str, Any]:
    """The mission's world (see the module); ``meta.maze`` is one tile's maze and, with
    tiles, ``meta.tiles`` their count and the rows from one to the next."""
    from petriflow.agents.mobile.maze import generate

    each, side, pitch = tiling(robots, tiles, cells_per_robot, cell, gap)
    maze = generate(side, side, seed=maze_seed, cell=cell, loops=LOOPS)
    lattice = starts(each, side)
    bodies = [{"id": f"robot{t * each + k + 1}", "urdf": URDF,
               "position": [round((c + 0.5) * cell, 6), round((t * pitch + r + 0.5) * cell, 6)],
               "z": 0.0, "colour": ("red", "blue", "green", "orange")[(t * each + k) % 4]}
              for t in range(tiles) for k, (r, c) in enumerate(lattice)]
    description = maze.world(bodies, dt=dt)
    if tiles > 1:
        walls = description["boxes"]
        description["boxes"] = walls + [dict(box, id=f"tile{t}_{box['id']}",
                                             position=[x, y + t * pitch * cell, z])
                                        for t in range(1, tiles) for box in walls for x, y, z in [box["position"]]]
        description["meta"]["tiles"] = {"count": tiles, "pitch_rows": pitch}
    description["gravity"] = 0.0
    description["mode"] = "kinematic"
    return description


def _dump(description: dict[str, Any]) -> str:
    """A world as YAML with one line per box and robot (flow style inside the lists)."""
    import yaml

    head = {k: v for k, v in description.items() if k not in ("boxes", "robots", "meta")}
    lines = [yaml.safe_dump(head, sort_keys=False).rstrip()]
    for key in ("boxes", "robots"):
        lines.append(f"{key}:")
        lines += [f"  - {yaml.safe_dump(item, default_flow_style=True, width=1 << 20).strip()}"
                  for item in description[key]]
    lines.append(yaml.safe_dump({"meta": description["meta"]}, sort_keys=False, width=1 << 20).rstrip())
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> None:
    """Write the shipped world and nets (``nets/swarm/``)."""
    from petriflow.io.yaml import dumps_net

    parser = argparse.ArgumentParser(description="write the swarm scenario's worlds and nets")
    parser.add_argument("--out", default="nets/swarm")
    args = parser.parse_args(argv)
    out = Path(args.out)
    (out / "experiments").mkdir(parents=True, exist_ok=True)
    note = ("# Generated by python -m petriflow.agents.swarm.nets: a maze of about 8 cells a robot\n"
            f"# (generate(side, side, seed={MAZE_SEED}, cell=1, loops={LOOPS})), the robots on a lattice of cells,\n"
            "# the kinematic world mode. meta.maze is the maze: the metrics take the cell count from it.\n")
    (out / "world.yaml").write_text(note + _dump(world(3)))
    print(f"wrote {out / 'world.yaml'}")
    for robots in (10, 100, 1000):
        path = out / "experiments" / f"swarm-world-{robots}.yaml"
        path.write_text(note + _dump(world(robots)))
        print(f"wrote {path}")
    net = build(3)
    net.run = "run.yaml"
    (out / "swarm-3.yaml").write_text("# Generated by python -m petriflow.agents.swarm.nets; the run configuration"
                                      f" is run.yaml.\n{dumps_net(net)}")
    print(f"wrote {out / 'swarm-3.yaml'}")


if __name__ == "__main__":
    main()
