"""Seed 002's chain as a workflow net: one subnet per module, algorithm 1 or 2.

Module ``mK`` (``K`` = 1 … N, head first) boots (auto-addressing), then runs the
paper's loop as transitions bound to :mod:`~petriflow.agents.bus.firmware`:

* algorithm 1: ``cpg`` (θ = CPG, move actuator) → ``wait`` (Wait(Delay)) → ``send``
  (one frame to both neighbours), until its messages are sent;
* algorithm 2: the loop runs ``cpg`` only; the *bus available* interrupt
  (``available`` → ``send``) and the 1 s *overflow* interrupt (``overflow`` →
  ``send_overflow`` or ``skip``) are two more threads of the same module.

A module's frames to a neighbour go into a channel place on the bus (``bus``: the
run configuration picks SERIAL, CAN or ZIGBEE) that the neighbour's ``receive``
empties; one slot token per sender and receiver pair bounds it (the sender takes it,
the receiver gives it back), and the run configuration's ``on_loss: notify`` makes a
lost frame arrive as a loss notice, so the net stays bounded and live however many
frames the bus loses. Algorithm 2's tail sends to an address no module holds: its
frames go into a channel place nobody reads but ``drain`` (a transition of no agent).

The paper's sniffer is a subnet of its own (agent ``sniffer``): ``sniffer_boot`` joins
the bus as a node that only listens, and ``end`` (when every module has sent its
messages) records what it captured from each module (``bus.sniffed``).

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> net = loads_net(build(3, algorithm=1))
    >>> sorted(net.subnets), len([p for p in net.places.values() if p.channel])
    (['m1', 'm2', 'm3', 'sniffer'], 4)
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import yaml

__all__ = ["build", "main"]


def build(modules: int = 3, algorithm: int = 2, *, messages: int = 100, step_time: float = 0.02,
          max_delay: float = 1.0, idle_window: float = 3.0, world: bool = False, **ignored: Any) -> str:
    """The chain's net as petriflow YAML (see the module).

    Args:
        modules: modules in the chain (2 … 254).
        algorithm: 1 (native) or 2 (bus-aware).
        messages: messages each module sends.
        step_time: the control step (CPG and actuator), s.
        max_delay: algorithm 1's Delay ~ U[0, max_delay] s.
        idle_window: algorithm 2's bus-available time ~ U[0, idle_window] s (3 s: 100
            messages take about the paper's two minutes).
        world: the modules drive the joints of a chain in the world (the world file
            must hold it: :func:`petriflow.agents.bus.chain.world`).
        ignored: other sweep parameters (they go elsewhere).
    """
    if algorithm not in (1, 2):
        raise ValueError(f"algorithm is 1 or 2, not {algorithm!r}")
    if not 2 <= modules <= 254:
        raise ValueError(f"modules must be from 2 to 254, got {modules}")
    if messages < 1:
        raise ValueError(f"messages must be >= 1, got {messages}")
    chain = [f"m{k + 1}" for k in range(modules)]
    subnets, top_places, top_transitions, end_in = [], [], [], []
    boot = {"chain": chain, "algorithm": algorithm, "messages": messages, "step_time": step_time,
            "max_delay": max_delay, "idle_window": idle_window}
    for k, name in enumerate(chain):
        front = chain[k - 1] if k > 0 else None
        back = chain[k + 1] if k + 1 < modules else None
        places: list[Any] = [f"{name}_start", f"{name}_loop", f"{name}_listen", f"{name}_done"]
        senders = [front, back] if algorithm == 1 else [front]  # algorithm 2 sends only to address + 1
        mailboxes = [f"box_{other}_{name}" for other in senders if other is not None]
        transitions: list[dict[str, Any]] = []
        if algorithm == 1:
            targets = {"+1": back, "-1": front}
            boxes = {offset: f"box_{name}_{other}" for offset, other in targets.items() if other is not None}
            slots = [f"slot_{name}_{other}" for other in targets.values() if other is not None]
            places += [f"{name}_moved", f"{name}_waited"]
            transitions += [
                {"id": f"{name}_boot", "label": "auto-addressing", "action": "bus.boot",
                 "params": {**boot, "mailboxes": mailboxes}, "in": [f"{name}_start"],
                 "out": [f"{name}_loop", f"{name}_listen"]},
                {"id": f"{name}_cpg", "label": "θ = CPG(...); move actuator", "action": "bus.cpg",
                 "guard": "bus.sending", "in": [f"{name}_loop"], "out": [f"{name}_moved"]},
                {"id": f"{name}_wait", "label": "Wait(Delay)", "action": "bus.wait",
                 "in": [f"{name}_moved"], "out": [f"{name}_waited"]},
                {"id": f"{name}_send", "label": "send a message to the neighbours", "action": "bus.send",
                 "params": {"boxes": boxes, "state": f"{name}_loop"},
                 "in": [f"{name}_waited", *slots], "out": [f"{name}_loop", *boxes.values()]},
                {"id": f"{name}_finish", "label": "all messages sent", "guard": "bus.finished",
                 "in": [f"{name}_loop"], "out": [f"{name}_done"]},
            ]
            end_from = [f"{name}_done"]
        else:
            box = f"box_{name}_{back}" if back is not None else f"void_{name}"
            slot = f"slot_{name}_{back}" if back is not None else f"slot_{name}_void"
            places += [f"{name}_watch", f"{name}_tx", f"{name}_timer", f"{name}_tick"]
            send = {"boxes": {"+1": box}}
            transitions += [
                {"id": f"{name}_boot", "label": "auto-addressing", "action": "bus.boot",
                 "params": {**boot, "mailboxes": mailboxes}, "in": [f"{name}_start"],
                 "out": [f"{name}_loop", f"{name}_listen", f"{name}_watch", f"{name}_timer"]},
                {"id": f"{name}_cpg", "label": "θ = CPG(...); move actuator", "action": "bus.cpg",
                 "guard": "bus.sending", "in": [f"{name}_loop"], "out": [f"{name}_loop"]},
                {"id": f"{name}_available", "label": "bus available interrupt", "action": "bus.available",
                 "params": {"box": box}, "guard": "bus.sending", "in": [f"{name}_watch"], "out": [f"{name}_tx"]},
                {"id": f"{name}_send", "label": "send a message (bus available)", "action": "bus.send",
                 "params": {**send, "state": f"{name}_watch"}, "guard": "bus.sending",
                 "in": [f"{name}_tx", slot], "out": [f"{name}_watch", box]},
                {"id": f"{name}_late", "label": "nothing left to send", "guard": "bus.finished", "priority": 1,
                 "in": [f"{name}_tx"], "out": [f"{name}_watch"]},
                {"id": f"{name}_overflow", "label": "overflow interrupt (1 s)", "action": "bus.overflow",
                 "guard": "bus.sending", "in": [f"{name}_timer"], "out": [f"{name}_tick"]},
                {"id": f"{name}_send_overflow", "label": "send a message (overflow, p = 0.5)",
                 "action": "bus.send", "params": {**send, "state": f"{name}_timer"}, "guard": "bus.overflow_sends",
                 "in": [f"{name}_tick", slot], "out": [f"{name}_timer", box]},
                {"id": f"{name}_skip", "label": "overflow: no send", "guard": "bus.overflow_skips",
                 "in": [f"{name}_tick"], "out": [f"{name}_timer"]},
                {"id": f"{name}_finish", "label": "all messages sent", "guard": "bus.finished",
                 "in": [f"{name}_loop", f"{name}_watch", f"{name}_timer"], "out": [f"{name}_done"]},
            ]
            if back is None:
                top_places.append({"id": box, "channel": "bus", "label": f"{name}'s frames to address {modules}"})
                top_places.append({"id": slot, "label": f"{name} may send to address {modules}"})
                top_transitions.append({"id": f"drain_{name}", "label": "a frame for nobody leaves the bus",
                                        "action": "bus.drain", "params": {"box": box}, "in": [box], "out": [slot]})
            end_from = [f"{name}_done"]
        for other in (front, back):
            if other is None:
                continue
            box, slot = f"box_{other}_{name}", f"slot_{other}_{name}"
            if algorithm == 2 and chain.index(other) > k:
                continue  # algorithm 2 sends only to address + 1
            places += [{"id": box, "channel": "bus", "label": f"{other} to {name}"},
                       {"id": slot, "label": f"{other} may send to {name}"}]
            transitions.append({"id": f"{name}_receive_{other}", "label": f"reception from {other}",
                                "action": "bus.receive", "params": {"box": box, "state": f"{name}_listen"},
                                "priority": 2, "in": [box, f"{name}_listen"], "out": [f"{name}_listen", slot]})
            end_in.append(slot)
        subnets.append({"id": name, "agent": name, "label": f"module {name}", "places": places,
                        "transitions": transitions})
        end_in += end_from + [f"{name}_listen"]
    end_in += [p["id"] for p in top_places if p["id"].startswith("slot_")]
    first_box = f"box_{chain[0]}_{chain[1]}"
    subnets.append({"id": "sniffer", "agent": "sniffer", "label": "the sniffer on the bus",
                    "places": ["sniffer_start", "sniffer_on"],
                    "transitions": [
                        {"id": "sniffer_boot", "label": "the sniffer joins the bus", "action": "bus.sniffer",
                         "params": {"box": first_box}, "in": ["sniffer_start"], "out": ["sniffer_on"]},
                        {"id": "end", "label": "every module sent its messages: the sniffer's record",
                         "action": "bus.sniffed", "params": {"box": first_box}, "in": [*end_in, "sniffer_on"],
                         "out": ["o"]}]})
    net = {
        "petriflow": 1,
        "net": f"bus-algorithm{algorithm}-{modules}",
        "label": f"seed 002: {modules} modules, algorithm {algorithm}",
        "subnets": subnets,
        "places": [{"id": "i", "tokens": 1}, "o", *top_places],
        "transitions": [
            {"id": "begin", "label": "power on", "in": ["i"],
             "out": [f"{m}_start" for m in chain] + [s for s in end_in if s.startswith("slot_")] + ["sniffer_start"]},
            *top_transitions,
        ],
        "final": {"o": 1},
    }
    return yaml.safe_dump(net, sort_keys=False, width=120)


def main(argv: list[str] | None = None) -> None:
    """Write the shipped nets (``nets/bus/``)."""
    parser = argparse.ArgumentParser(description="write seed 002's nets")
    parser.add_argument("--out", default="nets/bus")
    args = parser.parse_args(argv)
    out = Path(args.out)
    for algorithm in (1, 2):
        name = f"bus-algorithm{algorithm}-3.yaml"
        (out / name).write_text("# Generated by python -m petriflow.agents.bus.nets; the run configuration is"
                                f" run.yaml.\nrun: run.yaml\n{build(3, algorithm)}")
    print(f"wrote the nets under {out}")


if __name__ == "__main__":
    main()
