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

The net is built with :class:`~petriflow.netbuild.NetBuilder`: every place first (a
module sends into its neighbour's mailbox), then each module's transitions, the
sniffer's, and the workflow envelope: ``begin`` hands out the start places and every
mailbox's slot, the sniffer's ``end`` collects them. Sweep files use :func:`build` directly (``net: {builder:
petriflow.agents.bus.nets:build}``); ``python -m petriflow.agents.bus.nets`` writes the
shipped nets of ``nets/bus/``.

Examples:
    >>> net = build(3, algorithm=1)
    >>> sorted(net.subnets), len([p for p in net.places.values() if p.channel])
    (['m1', 'm2', 'm3', 'sniffer'], 4)
    >>> net.preset("m2_receive_m1"), net.postset("m2_receive_m1")
    ({'box_m1_m2': 1, 'm2_listen': 1}, {'m2_listen': 1, 'slot_m1_m2': 1})
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from petriflow.net import Net
from petriflow.netbuild import AgentBuilder, NetBuilder

__all__ = ["build", "main"]

@dataclass
class _Module:
    """One module's subnet as it is built: its neighbours and the mailboxes it reads."""

    agent: AgentBuilder
    front: str | None
    back: str | None
    inboxes: list[tuple[str, str, str]]  # (sender, channel place, slot place)

    @property
    def name(self) -> str:
        return self.agent.name


def _places(b: NetBuilder, module: _Module, algorithm: int) -> None:
    """The module's state places, then a mailbox (channel place and slot) per neighbour
    that sends to it: both (algorithm 1) or the one in front (algorithm 2 sends only to
    address + 1)."""
    a, name = module.agent, module.name
    steps = ("moved", "waited") if algorithm == 1 else ("watch", "tx", "timer", "tick")
    for local in ("start", "loop", "listen", "done", *steps):
        a.place(local)
    senders = [module.front, module.back] if algorithm == 1 else [module.front]
    for other in senders:
        if other is None:
            continue
        box = b.place(f"box_{other}_{name}", agent=a, channel="bus", label=f"{other} to {name}")
        slot = b.place(f"slot_{other}_{name}", agent=a, label=f"{other} may send to {name}")
        module.inboxes.append((other, box, slot))


def _native(module: _Module, boot: dict[str, Any]) -> None:
    """Algorithm 1: boot, then cpg → wait → send to both neighbours, until done."""
    a, name = module.agent, module.name
    targets = {"+1": module.back, "-1": module.front}
    boxes = {offset: f"box_{name}_{other}" for offset, other in targets.items() if other is not None}
    slots = [f"slot_{name}_{other}" for other in targets.values() if other is not None]
    a.transition("boot", label="auto-addressing", action="bus.boot", params=boot, inputs=["start"],
                 outputs=["loop", "listen"])
    a.transition("cpg", label="θ = CPG(...); move actuator", action="bus.cpg", guard="bus.sending",
                 inputs=["loop"], outputs=["moved"])
    a.transition("wait", label="Wait(Delay)", action="bus.wait", inputs=["moved"], outputs=["waited"])
    a.transition("send", label="send a message to the neighbours", action="bus.send",
                 params={"boxes": boxes, "state": a.id("loop")}, inputs=["waited", *slots],
                 outputs=["loop", *boxes.values()])
    a.transition("finish", label="all messages sent", guard="bus.finished", inputs=["loop"], outputs=["done"])


def _bus_aware(module: _Module, boot: dict[str, Any], box: str, slot: str) -> None:
    """Algorithm 2: the loop runs cpg only; the bus-available and the overflow interrupts
    are two more threads that send into ``box`` (taking a token of ``slot``)."""
    a = module.agent

    def send(state: str) -> dict[str, Any]:  # each transition's params of its own
        return {"boxes": {"+1": box}, "state": a.id(state)}

    a.transition("boot", label="auto-addressing", action="bus.boot", params=boot, inputs=["start"],
                 outputs=["loop", "listen", "watch", "timer"])
    a.transition("cpg", label="θ = CPG(...); move actuator", action="bus.cpg", guard="bus.sending",
                 inputs=["loop"], outputs=["loop"])
    a.transition("available", label="bus available interrupt", action="bus.available", params={"box": box},
                 guard="bus.sending", inputs=["watch"], outputs=["tx"])
    a.transition("send", label="send a message (bus available)", action="bus.send",
                 params=send("watch"), guard="bus.sending", inputs=["tx", slot],
                 outputs=["watch", box])
    a.transition("late", label="nothing left to send", guard="bus.finished", priority=1, inputs=["tx"],
                 outputs=["watch"])
    a.transition("overflow", label="overflow interrupt (1 s)", action="bus.overflow", guard="bus.sending",
                 inputs=["timer"], outputs=["tick"])
    a.transition("send_overflow", label="send a message (overflow, p = 0.5)", action="bus.send",
                 params=send("timer"), guard="bus.overflow_sends", inputs=["tick", slot],
                 outputs=["timer", box])
    a.transition("skip", label="overflow: no send", guard="bus.overflow_skips", inputs=["tick"],
                 outputs=["timer"])
    a.transition("finish", label="all messages sent", guard="bus.finished", inputs=["loop", "watch", "timer"],
                 outputs=["done"])


def _receptions(module: _Module) -> None:
    """The reception routine, one transition per mailbox: it takes a frame (or a loss
    notice) and gives the sender's slot back."""
    for other, box, slot in module.inboxes:
        module.agent.transition(f"receive_{other}", label=f"reception from {other}", action="bus.receive",
                                params={"box": box, "state": module.agent.id("listen")}, priority=2,
                                inputs=[box, "listen"], outputs=["listen", slot])


def build(modules: int = 3, algorithm: int = 2, *, messages: int = 100, step_time: float = 0.02,
          max_delay: float = 1.0, idle_window: float = 3.0, world: bool = False, **ignored: Any) -> Net:
    """The chain's net (see the module).

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

    Raises:
        ValueError: an algorithm other than 1 or 2, a chain shorter than 2 or longer
            than 254 modules, or fewer than one message.
    """
    if algorithm not in (1, 2):
        raise ValueError(f"algorithm is 1 or 2, not {algorithm!r}")
    if not 2 <= modules <= 254:
        raise ValueError(f"modules must be from 2 to 254, got {modules}")
    if messages < 1:
        raise ValueError(f"messages must be >= 1, got {messages}")
    chain = [f"m{k + 1}" for k in range(modules)]
    b = NetBuilder(f"bus-algorithm{algorithm}-{modules}",
                   label=f"{modules} modules on a shared bus, algorithm {algorithm}")
    # every place first (a module sends into its neighbour's mailbox), in the net's order
    chained = [_Module(b.agent(name, label=f"module {name}"), chain[k - 1] if k > 0 else None,
                       chain[k + 1] if k + 1 < modules else None, []) for k, name in enumerate(chain)]
    sniffer = b.agent("sniffer", label="the sniffer on the bus")
    for module in chained:
        _places(b, module, algorithm)
    sniffer.place("start")
    sniffer.place("on")
    b.place("i", tokens=1)
    b.place("o")
    last = chained[-1].name
    void = (f"void_{last}", f"slot_{last}_void")  # algorithm 2's tail sends to an address no module holds
    if algorithm == 2:
        b.place(void[0], channel="bus", label=f"{last}'s frames to address {modules}")
        b.place(void[1], label=f"{last} may send to address {modules}")
    # then the transitions: each module's, the sniffer's, the envelope's
    closing: list[str] = []  # what "end" collects: each module's slots, done and listening places
    for module in chained:
        boot = {"chain": list(chain), "algorithm": algorithm, "messages": messages, "step_time": step_time,
                "max_delay": max_delay, "idle_window": idle_window,
                "mailboxes": [box for _, box, _ in module.inboxes]}  # lists of its own: a sweep may set one
        if algorithm == 1:
            _native(module, boot)
        elif module.back is not None:
            _bus_aware(module, boot, f"box_{module.name}_{module.back}", f"slot_{module.name}_{module.back}")
        else:
            _bus_aware(module, boot, *void)
        _receptions(module)
        closing += [slot for _, _, slot in module.inboxes]
        closing += [module.agent.id("done"), module.agent.id("listen")]
    if algorithm == 2:
        closing.append(void[1])
    first_box = f"box_{chain[0]}_{chain[1]}"
    sniffer.transition("boot", label="the sniffer joins the bus", action="bus.sniffer",
                       params={"box": first_box}, inputs=["start"], outputs=["on"])
    b.transition("end", agent=sniffer, label="every module sent its messages: the sniffer's record",
                 action="bus.sniffed", params={"box": first_box}, inputs=[*closing, "on"], outputs=["o"])
    slots = [place for place in closing if place.startswith("slot_")]  # one token each: a sender may send
    b.transition("begin", label="power on", inputs=["i"],
                 outputs=[*(module.agent.id("start") for module in chained), *slots, sniffer.id("start")])
    if algorithm == 2:
        b.transition(f"drain_{last}", label="a frame for nobody leaves the bus", action="bus.drain",
                     params={"box": void[0]}, inputs=[void[0]], outputs=[void[1]])
    boxes = [box for module in chained for _, box, _ in module.inboxes]
    b.require({"id": "one_frame_per_mailbox", "description": "a module's mailbox holds one frame at a time",
               "always": " && ".join(f"{box} <= 1" for box in boxes)})
    b.require({"id": "every_frame_read", "description": "every frame waiting in a mailbox can still be read",
               "ctl": "AG(" + " && ".join(f"({box} >= 1 -> EF {box} == 0)" for box in boxes) + ")"})
    b.require({"id": "bus_can_finish", "description": "from every reachable marking every module can still"
               " finish", "ctl": "AG EF o == 1"})
    net = b.build()
    net.set_final_marking({"o": 1})
    return net


def main(argv: list[str] | None = None) -> None:
    """Write the shipped nets (``nets/bus/``)."""
    from petriflow.io.yaml import dumps_net

    parser = argparse.ArgumentParser(description="write seed 002's nets")
    parser.add_argument("--out", default="nets/bus")
    args = parser.parse_args(argv)
    out = Path(args.out)
    for algorithm in (1, 2):
        net = build(3, algorithm)
        net.run = "run.yaml"
        head = "# Generated by python -m petriflow.agents.bus.nets; the run configuration is run.yaml.\n"
        (out / f"{net.id}.yaml").write_text(head + dumps_net(net))
    print(f"wrote the nets under {out}")


if __name__ == "__main__":
    main()
