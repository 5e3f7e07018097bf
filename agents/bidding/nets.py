"""Seed 004's mission as a workflow net, built for any team size.

:func:`build` builds the net (a :class:`~petriflow.net.Net`, with
:class:`~petriflow.netbuild.NetBuilder`): an operator, the interface agent (HMIA) and
``robots`` robot agents (RAs), each an agent subnet whose state the run keeps
(``bidding.operator``, ``bidding.interface``, ``bidding.robot``). Every agent but the
operator has a mailbox, a channel place every other agent sends into, bounded by slot
tokens (a sender takes one, the receiver gives it back): one by default, so the net is
bounded and its state space small enough to check, or one per sender (``mailbox=
"senders"``). The protocol is the net's structure:

* operator: ``request`` (REQUEST, INFORM), ``send_hmia``, ``finish``;
* HMIA: ``create``, then a work loop of ``team`` (INITIALIZE), ``inform`` (random
  deployment), ``cfp`` (CFP, one zone at a time), ``map`` (MAP), ``end`` (END),
  ``send_<robot>`` and ``wait``; ``receive`` takes its mail;
* each RA: ``create``, then ``ready`` (INITIALIZED), ``bid`` (PROPOSE), ``decide``
  (ALLOCATED when it won), ``explore`` (MAPPED), ``send_<peer>`` and ``wait``;
  ``receive`` takes its mail;
* with ``casts=True``, the HMIA and each RA also have ``cast``: a broadcast to the whole
  team (CFP, MAP, END; PROPOSE to the other RAs) in one firing, into every mailbox.

Guards (``bidding.next_*``) pick the one step the agent's state calls for; the
envelope's ``begin`` hands out the start tokens and the slots, ``end`` collects them.

Used directly by sweep files (``net: {builder: petriflow.agents.bidding.nets:build}``);
``python -m petriflow.agents.bidding.nets`` writes the shipped nets and worlds of
``nets/bidding/``.

Examples:
    >>> net = build(robots=2)
    >>> sorted(net.subnets), sorted(p.id for p in net.places.values() if p.channel)
    (['hmia', 'operator', 'robot1', 'robot2'], ['box_hmia', 'box_robot1', 'box_robot2'])
    >>> net.subnets["robot1"].state, net.transitions["robot1_send_robot2"].params
    ('bidding.robot', {'peer': 'robot2', 'box': 'box_robot2'})
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import yaml

from petriflow.agents.bidding.cost import SPEED_M_S
from petriflow.net import Net
from petriflow.netbuild import AgentBuilder, Mailbox, NetBuilder, is_capacity

__all__ = ["build", "main"]

#: Priorities of an agent's transitions: taking mail first, then ending, sending, the
#: protocol's steps, and waiting last. A broadcast in one firing (``casts=True``) goes
#: before the sends to one peer (it is never enabled with ``finish``, which needs an
#: empty outbox).
RECEIVE, FINISH, SEND, STEP, WAIT = 6, 5, 4, 3, 0
CAST = FINISH


def _agent(b: NetBuilder, name: str, label: str, state: str, *,
           listens: bool = True, capacity: int | str = 1) -> tuple[AgentBuilder, Mailbox | None]:
    """An agent's places (start, work, listen, done) and its mailbox ``box_<name>`` of
    ``capacity`` slots (:meth:`NetBuilder.mailbox <petriflow.netbuild.NetBuilder.mailbox>`)."""
    agent = b.agent(name, label=label, state=state)
    for local in ("start", "work", "listen", "done") if listens else ("start", "work", "done"):
        agent.place(local)
    agent.start("start")
    if not listens:
        agent.done("done")
        return agent, None
    agent.done("done", "listen")
    return agent, b.mailbox(agent, channel="lan", capacity=capacity, id=f"box_{name}",
                            label=f"{name}'s mailbox", slot=f"slot_{name}",
                            slot_label=f"{name}'s mailbox is free")


def _loop(b: NetBuilder, agent: AgentBuilder, create: tuple[str, str, dict[str, Any]],
          steps: list[tuple[str, str, str, dict[str, Any]]], peers: list[Mailbox], wait: float,
          team: list[Mailbox] | None = None) -> None:
    """An agent's transitions: ``create`` (its state), the work loop's protocol steps,
    a send per peer, a broadcast to the mailboxes of ``team`` in one firing (``cast``,
    when given), ``wait``, ``finish``, and ``receive`` on the listening place."""
    action, label, params = create
    if team:
        params = {**params, "casts": True}
    agent.transition("create", label=label, action=action, params=params or None, inputs=["start"],
                     outputs=["work", "listen"])
    for step, action, label, params in steps:
        agent.transition(step, label=label, action=action, params=params or None,
                         guard=f"bidding.next_{step}", priority=STEP, inputs=["work"], outputs=["work"])
    _sends(b, agent, peers)
    if team:
        b.broadcast(agent.transition("cast", label="broadcast to the team", action="bidding.cast",
                                     params={"boxes": {box.owner: box.id for box in team}},
                                     guard="bidding.has_cast", priority=CAST, inputs=["work"], outputs=["work"]),
                    team)
    agent.transition("wait", label="wait for news", action="bidding.wait", params={"period": wait},
                     guard="bidding.idle", priority=WAIT, inputs=["work"], outputs=["work"])
    agent.transition("finish", label="mission over", guard="bidding.finished", priority=FINISH,
                     inputs=["work"], outputs=["done"])
    b.receive(agent.transition("receive", label="take a message", action="bidding.receive",
                               params={"box": f"box_{agent.name}"}, priority=RECEIVE, inputs=["listen"],
                               outputs=["listen"]), f"box_{agent.name}")


def _sends(b: NetBuilder, agent: AgentBuilder, peers: list[Mailbox]) -> None:
    for box in peers:
        peer = box.owner
        b.send(agent.transition(f"send_{peer}", label=f"send to {peer}", action="bidding.send",
                                params={"peer": peer, "box": box.id}, guard="bidding.has_message",
                                priority=SEND, inputs=["work"], outputs=["work"]), box)


def _numbers(text: str, what: str) -> list[float]:
    try:
        return [float(v) for v in text.split()]
    except ValueError:
        raise ValueError(f"{what} is numbers separated by spaces, got {text!r}") from None


def _lists(text: str) -> list[list[int]]:
    """Zone lists written as text, a robot's after another's behind a slash.

    Examples:
        >>> _lists("2 8 1 6 5 / 7 3 4")
        [[2, 8, 1, 6, 5], [7, 3, 4]]
    """
    try:
        return [[int(z) for z in part.split()] for part in text.split("/")]
    except ValueError:
        raise ValueError(f"lists is zone numbers, one robot's after another's behind a '/', got {text!r}") from None


def build(robots: int = 2, deployment: str = "autonomous", *, lists: list[list[int]] | None = None,
          zones: list[list[float]] | None = None, speed: float = SPEED_M_S, scan_period: float = 1.0,
          filter_teammates: bool = False, spin: bool = False, visit: str = "centre", wait: float = 1.0,
          localization: str = "odom", odom_error: list[float] | None = None, until: str = "mapped",
          idle: str = "scan", mailbox: int | str = 1, casts: bool = False, **ignored: Any) -> Net:
    """The mission's net (see the module).

    Args:
        robots: robot agents in the team (1..200).
        deployment: ``autonomous`` (bidding) or ``random`` (the operator's lists).
        lists: random deployment: each robot's zone numbers (1-based, visiting order),
            as lists or as text (``"2 8 1 6 5 / 7 3 4"``); default: drawn with the run's
            seed.
        zones: zone positions; default: the world's office (``meta.office``).
        speed: the robots' speed (m/s): their cruise speed and eq. 6's P_ij (default
            0.4, Stage 3.2's position controller).
        scan_period: seconds between laser scans.
        filter_teammates: drop laser returns on teammates.
        spin: turn a full circle at each waypoint of a zone (the paper describes none).
        visit: ``centre`` (drive to the zone's position, as the paper) or ``room``
            (through waypoints over the zone's room).
        wait: longest idle wait of an agent (s).
        localization: ``odom`` (Stage's odometry error model, the robots' belief drifts)
            or ``gps`` (the true pose).
        odom_error: Stage's ``odom_error`` [x, y, heading] (default [0.03, 0.03, 0.05]),
            or as text (``"0.05 0.05 0.1"``).
        until: the HMIA ends the mission when every zone is ``mapped`` (in a laser's
            sight, or reached) or only when every zone is ``reached``.
        idle: an RA whose zones are done goes on mapping until END (``scan``) or
            stops (``stop``).
        mailbox: slots per mailbox: a whole number (default 1: a sender waits until the
            receiver took the message before, which keeps the net's state space small
            enough to check), or ``senders``: one per agent that sends into it, so no
            sender waits for a receiver while it has a message for it (the paper assumes
            communication unlimited, §4).
        casts: a broadcast to the whole team (the HMIA's CFP, MAP and END to every RA,
            an RA's PROPOSE to the others) leaves in one firing (``cast``) into every
            receiver's mailbox, as one message does on a network (§3.2.2: the RA
            "broadcasts this cost"), instead of a send firing per receiver. One to part
            of the team (after a breakdown) still goes one copy at a time.
        ignored: other sweep parameters (they go elsewhere).
    """
    if isinstance(lists, str):  # "2 8 1 6 5 / 7 3 4": a sweep report prints text, not nested lists
        lists = _lists(lists)
    if isinstance(odom_error, str):  # "0.03 0.03 0.05"
        odom_error = _numbers(odom_error, "odom_error")
    if localization not in ("odom", "gps"):
        raise ValueError(f"localization is odom or gps, not {localization!r}")
    if until not in ("mapped", "reached"):
        raise ValueError(f"until is mapped or reached, not {until!r}")
    if deployment not in ("autonomous", "random"):
        raise ValueError(f"deployment is autonomous or random, not {deployment!r}")
    if not 1 <= robots <= 200:
        raise ValueError(f"robots must be from 1 to 200, got {robots}")
    team = [f"robot{i + 1}" for i in range(robots)]
    mission: dict[str, Any] = {"hmia": "hmia", "robots": team, "deployment": deployment}
    if lists is not None:  # plain lists (a sweep file's values may be its reader's types)
        mission["lists"] = [[int(z) for z in zs] for zs in lists]
    if zones is not None:
        mission["zones"] = [[float(v) for v in z] for z in zones]
    b = NetBuilder(f"bidding-{deployment}-{robots}", label=f"collaborative mapping: {robots}"
                   f" robot{'s' if robots > 1 else ''}, {deployment} deployment")
    operator, _ = _agent(b, "operator", "the human operator", "bidding.operator", listens=False)
    if not is_capacity(mailbox):
        raise ValueError(f"mailbox is a whole number of slots >= 1 or 'senders', got {mailbox!r}")
    hmia, hmia_box = _agent(b, "hmia", "human/machine interface agent", "bidding.interface", capacity=mailbox)
    ras = [_agent(b, name, f"robot agent {name}", "bidding.robot", capacity=mailbox) for name in team]
    boxes = {box.owner: box for box in [hmia_box] + [box for _, box in ras]}
    operator.transition("request", label="REQUEST and INFORM", action="bidding.operator", params=mission,
                        inputs=["start"], outputs=["work"])
    _sends(b, operator, [boxes["hmia"]])
    operator.transition("finish", label="mission sent", guard="bidding.finished", priority=FINISH,
                        inputs=["work"], outputs=["done"])
    _loop(b, hmia, ("bidding.interface", "the interface agent", {} if until == "mapped" else {"until": until}), [
        ("team", "bidding.team", "INITIALIZE the team", {}),
        ("inform", "bidding.inform", "random deployment: INFORM zone lists", {}),
        ("cfp", "bidding.cfp", "CFP: offer the next zone", {}),
        ("map", "bidding.map", "MAP: start mapping", {}),
        ("end", "bidding.end", "END: the world mapped", {}),
    ], [boxes[name] for name in team], wait, [boxes[name] for name in team] if casts and robots > 1 else None)
    explore = {"speed": speed, "scan_period": scan_period, "filter_teammates": filter_teammates, "spin": spin,
               "visit": visit}
    if idle != "scan":
        explore["idle"] = idle
    ready: dict[str, Any] = {} if localization == "odom" else {"localization": localization}
    if odom_error is not None:
        ready["odom_error"] = [float(v) for v in odom_error]
    for rank, (ra, _) in enumerate(ras):
        _loop(b, ra, ("bidding.robot", "robot agent", {"rank": rank}), [
            ("ready", "bidding.ready", "INITIALIZED: laser and pose", dict(ready)),
            ("bid", "bidding.bid", "PROPOSE: eq. 6 cost", {"speed": speed}),
            ("decide", "bidding.decide", "best proposal; ALLOCATED if won", {}),
            ("explore", "bidding.explore", "map the zones: MAPPED", explore),
        ], [boxes[name] for name in ["hmia"] + team if name != ra.name], wait,
            [boxes[name] for name in team if name != ra.name] if casts and robots > 2 else None)
    b.envelope(begin_label="REQUEST from the operator", end_label="mission over")
    b.require_delivery()  # every CFP, PROPOSE, MAP and END can still be received; the mission can end
    return b.build()


def main(argv: list[str] | None = None) -> None:
    """Write the shipped world and nets (``nets/bidding/``)."""
    parser = argparse.ArgumentParser(description="write seed 004's worlds and nets")
    parser.add_argument("--out", default="nets/bidding")
    args = parser.parse_args(argv)
    from petriflow.agents.bidding.office import draw, generated_office, paper_office
    from petriflow.io.yaml import dumps_net

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
            net = build(robots, deployment)
            net.run = "run.yaml"
            (out / f"{net.id}.yaml").write_text("# Generated by python -m petriflow.agents.bidding.nets; the"
                                                f" run configuration is run.yaml.\n{dumps_net(net)}")
    net = build(20, "autonomous")
    net.run = "run-20.yaml"
    (out / f"{net.id}.yaml").write_text("# Generated by python -m petriflow.agents.bidding.nets: 20 robots in"
                                        f" the generated office.\n{dumps_net(net)}")
    print(f"wrote the worlds and nets under {out}")


if __name__ == "__main__":
    main()
