"""Seed 001's mission as a workflow net, built for any team (:func:`build`).

One subnet per agent, each with its state kept by the run:

* **RA** ``raJ`` (``slam.robot``): ``boot`` (start to ``ready``), ``explore`` (a leg of
  Algorithm 1, guarded by ``slam.can_move``; a motor failure routes to ``broken``),
  ``install_K`` (guard ``slam.needs_wa``: takes the RA's hopper token ``hopper_K`` and
  gives ``hopper_K+1``, and starts WA ``wa_rJ_K``: its ``on`` and ``listen`` tokens, the
  first one carrying the programming), ``send`` and ``receive`` (frames in the air),
  ``finish`` (guard ``slam.map_done``: to ``out``, telling the base), ``write_off``
  (``broken`` to ``out``). A reserve RA starts in ``standby``, which the base turns into
  ``start`` (``dispatch``) or ``out`` (``stand_down``, once the map is done).
* **WA** ``wa_rJ_K`` (``slam.wireless``), started by its RA's ``install_K``: ``scan``
  (Algorithm 2's cycle, a loop on ``on``), ``send``, ``alert`` (to the base's mailbox),
  ``receive``, and ``switch_off`` when the mission closes.
* **central unit** ``central`` (``slam.central``, centralised mode): ``boot``, ``serve``
  (its loop; a communication error routes to ``broken``), ``send``, ``alert``,
  ``receive``, ``done`` / ``retire``.
* **base** ``base`` (``slam.base``, the external unit): ``receive`` (alerts, the end of the
  map), ``dispatch_raJ`` / ``stand_down_raJ`` for each reserve, ``close`` (every RA is
  ``out``), then the switch-off chain: through each RA's WAs in installation order
  (``off_raJ_K``: WA K switches off, or, where the RA's hopper token is, ``pass_raJ_K``
  takes it and the chain moves to the next RA), and ``done``.

Frames travel through one shared mailbox ``air`` (channel ``wifi``, one frame at a
time: the 2.4 GHz channel); each receiver's ``receive`` takes only frames addressed to
it (token guard ``slam.addressed``) and ``discard`` (lowest priority, outside every
agent) takes a frame nobody takes (its receiver gone), so the air never clogs. The
base's mailbox ``base_box`` (channel ``alert``) takes alerts and the end of the map.

Why WAs are subnets started by a token and not ``join`` faults: a ``join`` needs its time
in the run configuration, and the RA decides when (and whether) it installs a WA while
it runs. Installing in order (the hopper token) keeps the installed WAs a prefix of
``1..was``, so the reachable markings grow with the WAs linearly, not as their subsets,
and the switch-off chain ends every one of them: the net is a sound WF-net
(``petriflow check``) that :func:`build` returns for any team.

``python -m petriflow.agents.slam.nets`` writes the shipped world and nets of
``nets/slam/``; sweep files name :func:`build` (``net: {builder:
petriflow.agents.slam.nets:build}``).

Examples:
    >>> net = build(was=2)
    >>> sorted(net.subnets)
    ['base', 'ra1', 'ra2', 'wa_r1_1', 'wa_r1_2', 'wa_r2_1', 'wa_r2_2']
    >>> from petriflow.analysis.report import check_net
    >>> result = check_net(net); result["workflow_net"], result["sound"]
    (True, True)
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from petriflow.net import Net
from petriflow.netbuild import NetBuilder

__all__ = ["build", "main"]


def build(mode: str = "decentralised", robots: int = 1, reserves: int = 1, was: int = 16,
          fail_at: float | None = None, *, speed: float = 0.325, umbmark: bool = True, ed: float = 1.003,
          eb: float = 1.015, alert_after: float = 60.0, scan_period: float = 1.0, window: float = 5.0,
          drop_s: float = 10.0, connect_s: float = 3.0, match: float = 1.0, install_rule: str = "none-heard",
          **ignored: Any) -> Net:
    """The mission's net (see the module).

    Args:
        mode: ``decentralised`` (RAs install WAs) or ``centralised`` (a central unit
            works through pre-installed nodes; no WAs are installed).
        robots: RAs exploring from the start.
        reserves: RAs waiting at the base to replace one that alerts say is gone.
        was: WAs each RA carries (decentralised).
        fail_at: seconds at which ``ra1`` (and, centralised, the central unit) fails.
        speed ... match, install_rule: the agents' parameters (see their actions).
        ignored: other sweep parameters (they go elsewhere).
    """
    if mode not in ("decentralised", "centralised"):
        raise ValueError(f"mode is decentralised or centralised, not {mode!r}")
    if robots < 1 or reserves < 0 or was < 0:
        raise ValueError("robots >= 1, reserves >= 0 and was >= 0")
    was = was if mode == "decentralised" else 0
    total = robots + reserves
    names = [f"ra{j}" for j in range(1, total + 1)]
    label = f"SLAM mission: {robots} RA{'s' if robots > 1 else ''}, {reserves} in reserve, {mode}"
    b = NetBuilder(f"slam-{mode}" + (f"-{robots}" if robots > 1 else ""), label=label)
    ras = {name: b.agent(name, label=f"robotic agent {name}", state="slam.robot") for name in names}
    wa_names = {name: [f"wa_r{j}_{k}" for k in range(1, was + 1)] for j, name in enumerate(names, 1)}
    wireless = {w: b.agent(w, label=f"wireless agent WA_R{w.split('_r')[1]}",
                           state="slam.wireless") for ws in wa_names.values() for w in ws}
    central = b.agent("central", label="central unit", state="slam.central") if mode == "centralised" else None
    base = b.agent("base", label="base: alerts and reserves", state="slam.base")
    air = b.mailbox(None, "air", channel="wifi", capacity=1, label="the air: one frame at a time",
                    slot="air_slot", slot_label="the channel is free")
    box = b.mailbox(base, "box", channel="alert", capacity=1, label="alerts and the end of the map")
    for local in ("ready", "listen", "done"):
        base.place(local)
    for w, a in wireless.items():
        a.place("on", label="installed and on")
        a.place("listen")
    base.start("ready", "listen")
    base.done("done", "listen")

    def radio(agent, loop: str, me: str, *, alert: bool) -> None:
        send = agent.transition("send", label="a frame into the air", action="slam.send", params={"air": air.id},
                                guard="slam.has_frame", priority=2, inputs=[loop], outputs=[loop])
        b.send(send, air)
        receive = agent.transition("receive", label="a frame for it", action="slam.receive",
                                   params={"air": air.id, "me": me, "window": window, "radio": air.id},
                                   guard="slam.addressed", priority=5, inputs=["listen"], outputs=["listen"])
        b.receive(receive, air)
        if alert:
            b.send(agent.transition("alert", label="an alert to the base", action="slam.send",
                                    params={"air": box.id, "alert": True}, guard="slam.alert_due", priority=2,
                                    inputs=[loop], outputs=[loop]), box)

    for j, name in enumerate(names, 1):
        r = ras[name]
        reserve = j > robots
        for local in ("start", "ready", "listen", "broken", "out"):
            r.place(local)
        for k in range(1, was + 2 if was else 1):
            r.place(f"hopper_{k}", label=f"{k - 1} WAs installed" if k > 1 else "no WA installed")
        if reserve:
            r.place("standby", label="waiting at the base")
            r.start("standby", "listen")
        else:
            r.start("start", "listen")
        if was:
            r.start("hopper_1")
        r.done("out", "listen")
        r.transition("boot", label="body, wheels (UMBmark), history", action="slam.boot",
                     params={"slot": j - 1, "mode": mode, "was": was, "air": air.id, "speed": speed,
                             "umbmark": umbmark, "ed": ed, "eb": eb, "match": match,
                             **({"install_rule": install_rule} if install_rule != "none-heard" else {})},
                     inputs=["start"], outputs=["ready"])
        r.transition("explore", label="a leg of Algorithm 1", action="slam.explore",
                     params={"air": air.id, "fail_at": fail_at if j == 1 else None}, guard="slam.can_move",
                     inputs=["ready"], outputs=["ready"], outcomes={"failed": ["broken"]})
        for k, w in enumerate(wa_names[name], 1):
            r.transition(f"install_{k}", label=f"install and program {w}", action="slam.install",
                         params={"index": k, "wa": w, "on": f"{w}_on", "air": air.id, "drop_s": drop_s,
                                 "window_s": window, "connect_s": connect_s},
                         guard="slam.needs_wa", priority=3, inputs=["ready", f"hopper_{k}"],
                         outputs=["ready", f"hopper_{k + 1}", f"{w}_on", f"{w}_listen"])
        radio(r, "ready", name, alert=False)
        b.send(r.transition("finish", label="nothing pending: the map is done", action="slam.finish",
                            params={"box": box.id}, guard="slam.map_done", priority=4, inputs=["ready"],
                            outputs=["out"]), box)
        r.transition("write_off", label="broken down", priority=5, inputs=["broken"], outputs=["out"])
        if reserve:
            base.transition(f"dispatch_{name}", label=f"{name} goes in", action="slam.dispatch",
                            params={"reserve": name}, guard="slam.missing", priority=3,
                            inputs=["ready", f"{name}_standby"], outputs=["ready", f"{name}_start"])
            base.transition(f"stand_down_{name}", label=f"{name} not needed", guard="slam.over", priority=1,
                            inputs=["ready", f"{name}_standby"], outputs=["ready", f"{name}_out"])
    for ws in wa_names.values():
        for w in ws:
            a = wireless[w]
            a.transition("scan", label="Algorithm 2: scan, exchange", action="slam.scan",
                         params={"on": f"{w}_on", "air": air.id, "period": scan_period, "window": window,
                                 "alert_after": alert_after, "match": match}, inputs=["on"], outputs=["on"])
            radio(a, "on", w, alert=True)
    if central is not None:
        for local in ("start", "ready", "listen", "broken", "out"):
            central.place(local)
        central.start("start", "listen")
        central.done("out", "listen")
        central.transition("boot", label="the central unit starts", action="slam.central_boot",
                           params={"match": match}, inputs=["start"], outputs=["ready"])
        central.transition("serve", label="watch the RAs", action="slam.serve",
                           params={"period": scan_period, "alert_after": alert_after, "fail_at": fail_at},
                           inputs=["ready"], outputs=["ready"], outcomes={"failed": ["broken"]})
        radio(central, "ready", "central", alert=True)
        central.transition("done", label="the map is done", guard="slam.central_done", priority=4,
                           inputs=["ready"], outputs=["out"])
        central.transition("retire", label="broken down", priority=5, inputs=["broken"], outputs=["out"])
    b.receive(base.transition("receive", label="an alert or the end", action="slam.receive",
                              params={"air": box.id, "me": "base", "radio": None}, guard="slam.addressed",
                              priority=5, inputs=["listen"], outputs=["listen"]), box)
    outs = [f"{name}_out" for name in names]
    chain = [(name, k) for name in names for k in range(1, was + 2)] if was else []
    first = base.place(f"off_{chain[0][0]}_1") if chain else None
    for name, k in chain[1:]:
        base.place(f"off_{name}_{k}")
    base.transition("close", label="every RA is out: switch the WAs off", priority=0,
                    inputs=["ready", *outs], outputs=[*outs, first or "done"])
    for index, (name, k) in enumerate(chain):
        here = f"base_off_{name}_{k}"
        if k <= was:
            w = wa_names[name][k - 1]
            wireless[w].transition("switch_off", label="the mission is over", action="slam.switch_off",
                                   inputs=[here, "on", "listen"], outputs=[f"base_off_{name}_{k + 1}"])
        later = [n for n in names[names.index(name) + 1:]]
        following = f"base_off_{later[0]}_1" if later else "done"
        base.transition(f"pass_{name}_{k}", label=f"{name} carries its other WAs back",
                        inputs=[here, f"{name}_hopper_{k}"], outputs=[following])
    b.transition("discard", label="a frame nobody takes", priority=-10, inputs=[air.id], outputs=[air.slot])
    b.envelope(begin_label="the mission starts", end_label="the map is done, every agent stopped")
    b.require_delivery()  # one frame on the air at a time, every alert received, the map can be completed
    return b.build()


def main(argv: list[str] | None = None) -> None:
    """Write the shipped world, its picture and the nets (``nets/slam/``)."""
    import yaml

    from petriflow.agents.slam.corridors import draw, fig6_world, maze_world
    from petriflow.io.yaml import dumps_net

    parser = argparse.ArgumentParser(description="write seed 001's worlds and nets")
    parser.add_argument("--out", default="nets/slam")
    args = parser.parse_args(argv)
    out = Path(args.out)
    (out / "experiments").mkdir(parents=True, exist_ok=True)
    head = ("# Seed 001's test environment (Fig. 6) rebuilt from Table 6 (generated: python -m\n"
            "# petriflow.agents.slam.nets; see agents/slam/fig6.py and nets/slam/README.md): corridors of\n"
            "# 1.2 m cut out of a 25 m x 25 m block, the two RAs at the start (ra2 is the reserve), 16\n"
            "# WA boxes per RA parked off the plan, the 16 nodes of the centralised system. meta.slam\n"
            "# holds the ground-truth graph (map frame: x west, y north, the start at the origin).\n")
    description = fig6_world()
    (out / "world.yaml").write_text(head + yaml.safe_dump(description, sort_keys=False, width=120))
    draw(description, out / "world.png", title="Fig. 6 rebuilt: 36 vertices, 45 corridors (Table 6)")
    maze = maze_world(was_per_robot=40)
    (out / "experiments" / "maze-50.yaml").write_text(
        "# A generated 50 m x 50 m maze (10 x 10 cells of 5 m, seed 1, 10 % loops) for five RAs\n"
        "# (python -m petriflow.agents.slam.nets).\n" + yaml.safe_dump(maze, sort_keys=False, width=120))
    draw(maze, out / "maze-50.png", title="generated 50 m maze")
    for mode in ("decentralised", "centralised"):
        net = build(mode)
        net.run = "run.yaml"
        path = out / f"{net.id}.yaml"
        path.write_text(f"# Generated by python -m petriflow.agents.slam.nets (run: run.yaml).\n{dumps_net(net)}")
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
