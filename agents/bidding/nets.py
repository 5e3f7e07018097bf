"""Seed 004's mission as a workflow net, generated for any team size.

:func:`build` writes the net (petriflow YAML): an operator, the interface agent (HMIA)
and ``robots`` robot agents (RAs), each a subnet. Every agent but the operator has a
mailbox, a channel place every other agent sends into, bounded by one slot token
(a sender takes it, the receiver gives it back), so the net is bounded and its state
space small enough to check. The protocol is the net's structure:

* operator: ``request`` (REQUEST, INFORM), ``send``, ``finish``;
* HMIA: ``create``, then a work loop of ``team`` (INITIALIZE), ``inform`` (random
  deployment), ``cfp`` (CFP, one zone at a time), ``map`` (MAP), ``end`` (END),
  ``send_<robot>`` and ``wait``; ``receive`` takes its mail;
* each RA: ``create``, then ``ready`` (INITIALIZED), ``bid`` (PROPOSE), ``decide``
  (ALLOCATED when it won), ``explore`` (MAPPED), ``send_<peer>`` and ``wait``;
  ``receive`` takes its mail.

Guards (``bidding.next_*``) pick the one step the agent's state calls for; ``begin``
hands out the start tokens and the slots, ``end`` collects them.

Used directly by sweep files (``net: {builder: petriflow.agents.bidding.nets:build}``);
``python -m petriflow.agents.bidding.nets`` writes the shipped nets and worlds of
``nets/bidding/``.

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> net = loads_net(build(robots=2))
    >>> sorted(s.id for s in net.subnets.values()), sorted(p.id for p in net.places.values() if p.channel)
    (['hmia', 'operator', 'robot1', 'robot2'], ['box_hmia', 'box_robot1', 'box_robot2'])
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import yaml

__all__ = ["build", "main"]


def _loop(name: str, peers: list[str], steps: list[tuple[str, str, str, dict[str, Any]]],
          wait: float) -> tuple[list[Any], list[dict[str, Any]]]:
    work, listen, done = f"{name}_work", f"{name}_listen", f"{name}_done"
    places: list[Any] = [f"{name}_start", work, listen, done]
    transitions: list[dict[str, Any]] = []
    for step, action, label, params in steps:
        t: dict[str, Any] = {"id": f"{name}_{step}", "label": label, "action": action, "guard": f"bidding.next_{step}",
                             "priority": 3, "in": [work], "out": [work]}
        if params:
            t["params"] = params
        transitions.append(t)
    for peer in peers:
        transitions.append({
            "id": f"{name}_send_{peer}", "label": f"send to {peer}", "action": "bidding.send",
            "params": {"peer": peer, "box": f"box_{peer}", "state": work}, "guard": "bidding.has_message",
            "priority": 4, "in": [work, f"slot_{peer}"], "out": [work, f"box_{peer}"]})
    transitions += [
        {"id": f"{name}_wait", "label": "wait for news", "action": "bidding.wait", "params": {"period": wait},
         "guard": "bidding.idle", "priority": 0, "in": [work], "out": [work]},
        {"id": f"{name}_finish", "label": "mission over", "guard": "bidding.finished", "priority": 5,
         "in": [work], "out": [done]},
        {"id": f"{name}_receive", "label": "take a message", "action": "bidding.receive",
         "params": {"box": f"box_{name}", "state": listen}, "priority": 6,
         "in": [f"box_{name}", listen], "out": [listen, f"slot_{name}"]},
    ]
    places += [{"id": f"box_{name}", "channel": "lan", "label": f"{name}'s mailbox"},
               {"id": f"slot_{name}", "label": f"{name}'s mailbox is free"}]
    return places, transitions


def build(robots: int = 2, deployment: str = "autonomous", *, lists: list[list[int]] | None = None,
          zones: list[list[float]] | None = None, speed: float = 0.5, scan_period: float = 1.0,
          filter_teammates: bool = False, spin: bool = True, visit: str = "centre", wait: float = 1.0, **ignored: Any) -> str:
    """The mission's net as petriflow YAML (see the module).

    Args:
        robots: robot agents in the team (1..200).
        deployment: ``autonomous`` (bidding) or ``random`` (the operator's lists).
        lists: random deployment: each robot's zone numbers (1-based, visiting order);
            default: drawn with the run's seed.
        zones: zone positions; default: the world's office (``meta.office``).
        speed: the robots' speed (m/s): their cruise speed and eq. 6's P_ij.
        scan_period: seconds between laser scans.
        filter_teammates: drop laser returns on teammates.
        spin: turn a full circle at each waypoint of a zone.
        visit: ``centre`` (drive to the zone's position, as the paper) or ``room``
            (through waypoints over the zone's room).
        wait: longest idle wait of an agent (s).
        ignored: other sweep parameters (they go elsewhere).
    """
    if deployment not in ("autonomous", "random"):
        raise ValueError(f"deployment is autonomous or random, not {deployment!r}")
    if not 1 <= robots <= 200:
        raise ValueError(f"robots must be from 1 to 200, got {robots}")
    team = [f"robot{i + 1}" for i in range(robots)]
    mission: dict[str, Any] = {"hmia": "hmia", "robots": team, "deployment": deployment}
    if lists is not None:
        mission["lists"] = lists
    if zones is not None:
        mission["zones"] = zones
    subnets = [{"id": "operator", "agent": "operator", "label": "the human operator",
                "places": ["operator_start", "operator_work", "operator_done"],
                "transitions": [
                    {"id": "operator_request", "label": "REQUEST and INFORM", "action": "bidding.operator",
                     "params": mission, "in": ["operator_start"], "out": ["operator_work"]},
                    {"id": "operator_send_hmia", "label": "send to hmia", "action": "bidding.send",
                     "params": {"peer": "hmia", "box": "box_hmia", "state": "operator_work"},
                     "guard": "bidding.has_message", "priority": 4,
                     "in": ["operator_work", "slot_hmia"], "out": ["operator_work", "box_hmia"]},
                    {"id": "operator_finish", "label": "mission sent", "guard": "bidding.finished", "priority": 5,
                     "in": ["operator_work"], "out": ["operator_done"]}]}]
    places, transitions = _loop("hmia", team, [
        ("team", "bidding.team", "INITIALIZE the team", {}),
        ("inform", "bidding.inform", "random deployment: INFORM zone lists", {}),
        ("cfp", "bidding.cfp", "CFP: offer the next zone", {}),
        ("map", "bidding.map", "MAP: start mapping", {}),
        ("end", "bidding.end", "END: every zone mapped", {}),
    ], wait)
    transitions.insert(0, {"id": "hmia_create", "label": "the interface agent", "action": "bidding.interface",
                           "in": ["hmia_start"], "out": ["hmia_work", "hmia_listen"]})
    subnets.append({"id": "hmia", "agent": "hmia", "label": "human/machine interface agent",
                    "places": places, "transitions": transitions})
    explore = {"speed": speed, "scan_period": scan_period, "filter_teammates": filter_teammates, "spin": spin,
               "visit": visit}
    for rank, name in enumerate(team):
        places, transitions = _loop(name, ["hmia"] + [r for r in team if r != name], [
            ("ready", "bidding.ready", "INITIALIZED: laser and pose", {}),
            ("bid", "bidding.bid", "PROPOSE: eq. 6 cost", {"speed": speed}),
            ("decide", "bidding.decide", "best proposal; ALLOCATED if won", {}),
            ("explore", "bidding.explore", "map the zones: MAPPED", explore),
        ], wait)
        transitions.insert(0, {"id": f"{name}_create", "label": "robot agent", "action": "bidding.robot",
                               "params": {"rank": rank}, "in": [f"{name}_start"],
                               "out": [f"{name}_work", f"{name}_listen"]})
        subnets.append({"id": name, "agent": name, "label": f"robot agent {name}", "places": places,
                        "transitions": transitions})
    agents = ["operator", "hmia"] + team
    mailboxes = ["hmia"] + team
    net = {
        "petriflow": 1,
        "net": f"bidding-{deployment}-{robots}",
        "label": f"seed 004 collaborative mapping: {robots} robot{'s' if robots > 1 else ''}, {deployment} deployment",
        "subnets": subnets,
        "places": [{"id": "i", "tokens": 1}, "o"],
        "transitions": [
            {"id": "begin", "label": "REQUEST from the operator",
             "in": ["i"], "out": [f"{a}_start" for a in agents] + [f"slot_{m}" for m in mailboxes]},
            {"id": "end", "label": "mission over",
             "in": [f"{a}_done" for a in agents] + [f"{a}_listen" for a in agents if a != "operator"]
             + [f"slot_{m}" for m in mailboxes], "out": ["o"]},
        ],
        "final": {"o": 1},
    }
    return yaml.safe_dump(net, sort_keys=False, width=120)


def main(argv: list[str] | None = None) -> None:
    """Write the shipped world and nets (``nets/bidding/``)."""
    parser = argparse.ArgumentParser(description="write seed 004's worlds and nets")
    parser.add_argument("--out", default="nets/bidding")
    args = parser.parse_args(argv)
    from petriflow.agents.bidding.office import draw, generated_office, paper_office

    out = Path(args.out)
    office = paper_office()
    head = ("# The 32 m x 22 m office of seed 004 (Fig. 6, rebuilt; generated by python -m\n"
            "# petriflow.agents.bidding.nets): seven rooms and a corridor, the zones Z1..Z8 and the five\n"
            "# robot starts of Table 2. meta.office is the plan itself: the robots navigate on it (its\n"
            "# original structure is known, §1) and the metrics take the ground truth from it.\n")
    (out / "world.yaml").write_text(head + yaml.safe_dump(office.world(5), sort_keys=False, width=120))
    draw(office, out / "world.png", title="seed 004 office: rooms, zones Z1-Z8, robot starts", robots=5)
    big = generated_office(10, 20, seed=1)
    (out / "world-20.yaml").write_text(
        "# A larger generated office (python -m petriflow.agents.bidding.nets): 20 rooms on one\n"
        "# corridor, 20 robots.\n" + yaml.safe_dump(big.world(20), sort_keys=False, width=120))
    draw(big, out / "world-20.png", title="generated office: 20 rooms, 20 robots", robots=20)
    for robots in range(1, 6):
        for deployment in ("autonomous", "random"):
            name = f"bidding-{deployment}-{robots}.yaml"
            (out / name).write_text("# Generated by python -m petriflow.agents.bidding.nets; the run configuration"
                                    f" is run.yaml.\nrun: run.yaml\n{build(robots, deployment)}")
    (out / "bidding-autonomous-20.yaml").write_text(
        "# Generated by python -m petriflow.agents.bidding.nets: 20 robots in the generated office.\n"
        f"run: run-20.yaml\n{build(20, 'autonomous')}")
    print(f"wrote the worlds and nets under {out}")


if __name__ == "__main__":
    main()
