"""The mapping mission of seed 000 as a workflow net, built for any team.

:func:`build` builds the net (a :class:`~petriflow.net.Net`, with
:class:`~petriflow.netbuild.NetBuilder`) for ``robots`` robots, an optional monitor
agent and, in the ``centralised`` mode, a central unit that relays everything. Each
agent is a subnet whose state is a ``comm.agent``
(:class:`~petriflow.agents.comm.agent.CommAgent`, kept by the run): the four start-up
processes in order, then its work loop (``step``: a robot explores one cell, a static
agent listens; one ``send`` transition per peer, guarded by ``comm.has_message``; back
to the loop, or ``finish`` when the agent holds the whole map); and a ``receive``
transition per peer taking that peer's messages from the mailbox between them. A
mailbox (``box_S_R``, the channel place in the receiver's subnet) holds at most one
message: its slot (``slot_S_R``, with the sender) is taken by the sender and given back
by the receiver, so the net is bounded and its analysis finite; the WF envelope's
``begin`` hands out every slot and ``end`` collects them, so no message is left in
flight. A frame the radio loses leaves a loss notice in the mailbox (the comm radio's
``on_loss: notify``), which the receive takes like a message: a loss does not take the
slot with it.

Used directly by sweep files (``net: {builder: petriflow.agents.comm.nets:build}``);
``python -m petriflow.agents.comm.nets`` writes the shipped nets of ``nets/comm/``.

Examples:
    >>> net = build(robots=2)
    >>> len(net.subnets), len([p for p in net.places.values() if p.channel]), net.subnets["robot1"].state
    (2, 2, 'comm.agent')
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import yaml

from petriflow.agents.comm.framework import addresses, dhcp_pools
from petriflow.net import Net
from petriflow.netbuild import NetBuilder

__all__ = ["build", "ROBOT_STARTS", "MONITOR", "CENTRAL"]

#: Robot starts of the paper (§4.1-4.2): robot1, robot2, robot3.
ROBOT_STARTS = [(0.25, 0.25), (4.75, 4.75), (0.25, 4.75)]
#: The monitor agent's place (§4.3, Table 9).
MONITOR = (1.75, 3.25)
#: Where the central unit stands in the centralised mode (the maze's centre; the paper does not say).
CENTRAL = (2.5, 2.5)
#: The central unit's address (Table 6).
CENTRAL_ADDRESS = 129
#: The robots' cruise speed (m/s): the paper's own distance over time, 0.052-0.069 m/s
#: over the 14 robot rows of Tables 6-8 that give both (median 0.060; robot1 of Table 6:
#: 30.5 m in 472.46 s).
SPEED = 0.06
#: Seconds a robot waits without news before it gives silent robots up: the time to
#: drive 36 m at :data:`SPEED` (ours; the paper says nothing of waiting).
GIVE_UP = 600.0


def _agents(robots: int, monitor: bool, mode: str) -> list[dict[str, Any]]:
    team = addresses(robots)
    agents = [{"name": f"robot{i + 1}", "kind": "robot", "address": team[i], "index": i} for i in range(robots)]
    if monitor:
        agents.append({"name": "monitor1", "kind": "monitor", "address": dhcp_pools(robots)[0][0], "index": 0,
                       "pool_of": 0})
    if mode == "centralised":
        agents.append({"name": "central", "kind": "central", "address": CENTRAL_ADDRESS, "index": 0})
    return agents


def _peers(agent: dict[str, Any], agents: list[dict[str, Any]], mode: str) -> list[dict[str, Any]]:
    others = [a for a in agents if a["name"] != agent["name"]]
    if mode == "decentralised" or agent["kind"] == "central":
        return others
    return [a for a in others if a["kind"] == "central"]


def build(robots: int = 2, mode: str = "decentralised", monitor: bool = False, *, cell: float = 5 / 6,
          cols: int = 6, area: float = 5.0, speed: float = SPEED, give_up: float = GIVE_UP,
          listen_give_up: float = 3.75 * GIVE_UP, breakdown: str | None = None, fail_at: float = 110.0,
          **ignored: Any) -> Net:
    """The mission's net (see the module).

    Args:
        robots: robots in the team (1..126).
        mode: ``decentralised`` (every agent talks to every agent it hears) or
            ``centralised`` (robots talk only to the central unit, which relays).
        monitor: add the monitor agent (it joins when the run configuration says).
        cell, cols, area: the maze's cell size (m), cells per row, side (m).
        speed: the robots' cruise speed (m/s; :data:`SPEED`, from the paper's distances and times).
        give_up: seconds a robot waits for silent robots (see ``comm.explore``).
        listen_give_up: the same for a monitor or the central unit, which are there to
            relay and so wait longer.
        breakdown: a robot that has a mechanical failure at ``fail_at`` s (it stops
            moving, its radio goes on: ``comm.explore``'s ``stop_at``); ``None``: none.
        fail_at: the time of that failure (s; the paper's 110 s).
        ignored: other sweep parameters (they go elsewhere).
    """
    if mode not in ("decentralised", "centralised"):
        raise ValueError(f"mode is decentralised or centralised, not {mode!r}")
    if not 1 <= robots <= 126:
        raise ValueError(f"robots must be from 1 to 126, got {robots}")
    agents = _agents(robots, monitor, mode)
    robot_names = [a["name"] for a in agents if a["kind"] == "robot"]
    if breakdown is not None and breakdown not in robot_names:
        raise ValueError(f"breakdown names no robot of the team ({', '.join(robot_names)}): {breakdown!r}")
    breakdown = {} if breakdown is None else {breakdown: float(fail_at)}
    peers = {a["name"]: [p["name"] for p in _peers(a, agents, mode)] for a in agents}
    b = NetBuilder(f"comm-{mode}-{robots}{'-monitor' if monitor else ''}",
                   label=f"mapping mission: {robots} robots, {mode}{', a monitor' if monitor else ''}")
    subnets = {a["name"]: b.agent(a["name"], label=f"{a['kind']} {a['name']} (192.168.1.{a['address']})",
                                  state="comm.agent") for a in agents}
    address = {a["name"]: a["address"] for a in agents}
    for a in subnets.values():
        for local in ("start", "c1", "c2", "c3", "idle", "out", "listen", "done"):
            a.place(local)
    # one mailbox per ordered pair that talks: the channel place with the receiver, the slot with the sender
    boxes = {(name, other): b.mailbox(other, channel="radio", id=f"box_{name}_{other}", label=f"{name} to {other}",
                                      slot=f"slot_{name}_{other}", slot_label=f"{name} may send to {other}",
                                      slot_agent=name)
             for name in peers for other in peers[name]}
    for agent in agents:
        name, kind = agent["name"], agent["kind"]
        a = subnets[name]
        characterise = {"kind": kind, "cell": round(cell, 6), "cols": cols, "area": [area, area]}
        initialise: dict[str, Any] = {"agents": robots, "peers": {
            other: {"address": address[other], "box": boxes[name, other].id} for other in peers[name]}}
        if kind == "robot":
            initialise["index"] = agent["index"]
        elif kind == "monitor":
            initialise["pool_of"] = agent["pool_of"]
        else:
            initialise["address"] = agent["address"]
        a.transition("characterise", label="process 1: characterisation", action="comm.characterise",
                     params=characterise, inputs=["start"], outputs=["c1"])
        analyse = {}
        if peers[name]:  # process 2 on the radio of the first peer's channel towards this agent
            analyse = {"action": "comm.analyse", "params": {"channel_place": f"box_{peers[name][0]}_{name}"}}
        a.transition("analyse", label="process 2: transmission analysis", inputs=["c1"], outputs=["c2"], **analyse)
        a.transition("initialise", label="process 3: initialisation", action="comm.initialise",
                     params=initialise, inputs=["c2"], outputs=["c3"])
        a.transition("history", label="process 4: history", action="comm.history", inputs=["c3"],
                     outputs=["idle", "listen"])
        a.transition("step", label="explore a cell" if kind == "robot" else "listen",
                     action="comm.explore" if kind == "robot" else "comm.listen",
                     params=({"speed": speed, "give_up": give_up, "reexplore": mode == "decentralised",
                              "meet": mode == "decentralised",
                              **({"stop_at": float(breakdown[name])} if name in breakdown else {})}
                             if kind == "robot" else {"give_up": listen_give_up}),
                     inputs=["idle"], outputs=["out"])
        a.transition("loop", label="go on", guard="comm.going_on", priority=1, inputs=["out"], outputs=["idle"])
        a.transition("finish", label="map complete", guard="comm.finished", priority=1, inputs=["out"],
                     outputs=["done"])
        for other in peers[name]:
            send = a.transition(f"send_{other}", label=f"process 5: send to {other}", action="comm.send",
                                params={"peer": other, "box": boxes[name, other].id}, guard="comm.has_message",
                                priority=2, inputs=["out"], outputs=["out"])
            b.send(send, boxes[name, other])
        for other in peers[name]:
            box = boxes[other, name]
            receive = a.transition(f"receive_{other}", label=f"receive from {other}", action="comm.receive",
                                   params={"box": box.id}, priority=3, inputs=["listen"], outputs=["listen"])
            b.receive(receive, box)
        a.start("start")
        a.done("done", "listen")
    b.envelope(begin_label="start-up", end_label="every agent holds the map")
    b.require_delivery()  # every map message can still be received; the mission can end
    return b.build()


#: The maze of the shipped world: a perfect maze (one path between any two cells) of
#: 6 x 6 cells of 5/6 m in 5 m x 5 m with 24 map vertices, as many as the paper's tables
#: imply (120 bytes = 24 vertices of 5 bytes).
MAZE_SEED = 4
MAZE_LOOPS = 0.0


def starts(robots: int, cols: int, area: float) -> list[tuple[float, float]]:
    """Robot starts: the paper's three in its 5 m maze, else spread over a k x k lattice
    of cells (k = ceil(sqrt(robots)))."""
    if robots <= len(ROBOT_STARTS) and cols == 6 and area == 5.0:
        return ROBOT_STARTS[:robots]
    import math

    cell = area / cols
    k = math.ceil(math.sqrt(robots))
    spots = [(round((a + 0.5) * cols / k - 0.5), round((b + 0.5) * cols / k - 0.5)) for a in range(k) for b in range(k)]
    return [((c + 0.5) * cell, (r + 0.5) * cell) for r, c in spots[:robots]]


def world(maze_seed: int = MAZE_SEED, robots: int = 3, cols: int = 6, area: float = 5.0) -> dict[str, Any]:
    """The mission's world description: the maze, the robots, the monitor and the central
    unit (kinematic bodies: gravity is off, nothing falls or slides)."""
    from petriflow.agents.mobile.maze import generate

    maze = generate(cols, cols, seed=maze_seed, cell=area / cols, loops=MAZE_LOOPS)
    colours = ["red", "blue", "green", "orange"]
    bodies = []
    for i, (x, y) in enumerate(starts(robots, cols, area)):
        bodies.append({"id": f"robot{i + 1}", "agent": f"robot{i + 1}", "urdf": "petriflow.agents:robots/diffdrive.urdf",
                       "position": [x, y], "z": 0.05, "colour": colours[i % len(colours)]})
    # the static agents are kinematic bodies (no mass): a robot driving past does not push them away
    bodies.append({"id": "monitor1", "agent": "monitor1", "urdf": "petriflow.agents:robots/diffdrive.urdf",
                   "position": [MONITOR[0] * area / 5.0, MONITOR[1] * area / 5.0], "z": 0.05, "colour": "yellow",
                   "motion": "kinematic"})
    bodies.append({"id": "central", "agent": "central", "urdf": "petriflow.agents:robots/diffdrive.urdf",
                   "position": [area / 2, area / 2], "z": 0.6, "colour": "white", "motion": "kinematic"})
    description = maze.world(bodies, dt=0.05)
    description["gravity"] = 0.0
    return description


def draw_world(description: dict[str, Any], path: str | Path) -> None:
    """A top view of a mission world: walls, the maze's topological map (vertices and
    corridors, the ground truth), the robots' starts, the monitor and the central unit."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from petriflow.agents.mobile.maze import from_meta

    maze = from_meta(description["meta"]["maze"])
    figure, axis = plt.subplots(figsize=(6, 6))
    for box in description["boxes"]:
        (x, y, _), (w, d, _) = box["position"], box["size"]
        axis.add_patch(plt.Rectangle((x - w / 2, y - d / 2), w, d, color="0.25"))
    graph = maze.graph()
    for a, b in graph.edges:
        (xa, ya), (xb, yb) = maze.centre(a), maze.centre(b)
        axis.plot([xa, xb], [ya, yb], color="tab:green", linewidth=1, alpha=0.6)
    xs, ys = zip(*(maze.centre(v) for v in graph.nodes))
    axis.scatter(xs, ys, s=14, color="tab:green", zorder=3, label=f"map vertices ({graph.number_of_nodes()})")
    for body in description["robots"]:
        x, y = body["position"]
        role = "robot" if body["id"].startswith("robot") else body["id"]
        marker = {"robot": "o", "monitor1": "s", "central": "^"}[role]
        axis.scatter([x], [y], s=90, marker=marker, color=body["colour"] if role == "robot" else "k", zorder=4,
                     edgecolors="k")
        axis.annotate(body["id"], (x, y), textcoords="offset points", xytext=(6, 6), fontsize=8)
    axis.set_aspect("equal")
    axis.set_xlim(-0.2, maze.size[0] + 0.2)
    axis.set_ylim(-0.2, maze.size[1] + 0.2)
    axis.set_xlabel("x (m)")
    axis.set_ylabel("y (m)")
    axis.set_title("seed 000 maze: walls, topological map, agents")
    axis.legend(loc="upper right", fontsize=7)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def main(argv: list[str] | None = None) -> None:
    """Write the shipped world and nets (``nets/comm/``)."""
    from petriflow.io.yaml import dumps_net

    parser = argparse.ArgumentParser(description="write seed 000's world and nets")
    parser.add_argument("--out", default="nets/comm")
    args = parser.parse_args(argv)
    out = Path(args.out)
    head = ("# The 5 m x 5 m maze of seed 000's experiments (generated: python -m petriflow.agents.comm.nets;\n"
            f"# generate(6, 6, seed={MAZE_SEED}, cell=5/6, loops={MAZE_LOOPS})), the paper's robot starts, the monitor\n"
            "# at (1.75, 3.25) and the central unit above the centre. meta.maze is the maze itself: the\n"
            "# comm metrics take the ground-truth map from it; the robots only sense the walls.\n")
    description = world()
    (out / "world.yaml").write_text(head + yaml.safe_dump(description, sort_keys=False, width=120))
    draw_world(description, out / "world.png")
    print(f"wrote {out / 'world.yaml'} and {out / 'world.png'}")
    for robots, mode, monitor in ((2, "decentralised", False), (2, "centralised", False), (3, "decentralised", False),
                                  (3, "centralised", False), (3, "decentralised", True)):
        net = build(robots, mode, monitor)
        net.run = "run.yaml"
        name = f"{net.id}.yaml"
        (out / name).write_text("# Generated by python -m petriflow.agents.comm.nets; the run configuration is"
                                f" run.yaml.\n{dumps_net(net)}")
        print(f"wrote {out / name}")


if __name__ == "__main__":
    main()
