"""A module's firmware as actions a net binds: seed 002's algorithms 1 and 2 over a bus.

The module's state (:class:`Module`) is the token its subnet's places carry: its
address, its scheme (:mod:`~petriflow.agents.bus.algorithms`: when to send, to whom,
what to keep), its own phase oscillator (:class:`Oscillator`: eq. 2 with what it last
heard from each neighbour) and its message count.

========================  ==============================================================
``bus.boot``              auto-addressing (the module whose front sensor is free takes
                          address 0), the scheme, a random start phase; tells the bus how
                          often this module reads its receive buffer
``bus.cpg``               ``θi = CPG(...)``; ``Move actuator()``: one control step
``bus.wait``              algorithm 1's ``Wait(Delay)``
``bus.send``              ``Send a message``: the CPG message, one frame to its addressees
                          (a token in each addressee's channel place)
``bus.available``         algorithm 2's *bus available* interrupt: the bus has been quiet
                          for this module's random time, and is free
``bus.overflow``          algorithm 2's 1 s *overflow* interrupt: ``Indicator ~ U[0, 1]``
``bus.receive``           the reception routine: keep a message from a neighbour
                          addressed to this module (or learn that a frame was lost)
``bus.drain``             a frame for an address no module holds leaves the bus
``bus.sniffer``           the sniffer joins the bus as a node that only listens
``bus.sniffed``           the sniffer's record: frames captured per module
========================  ==============================================================

Every send, read and loss is a custom event (``bus.sent``, ``bus.read``); the metrics
of :mod:`~petriflow.agents.bus.metrics` count them per sender, as Tables 1–3 do.

The firmware asks its bus only through the view the bus declares
(:class:`~petriflow.agents.bus.channel.BusView`, ``ctx.medium(place)``): ``boot``
says how often and from when the module reads its receive buffer
(``reads_every(period, start=)``: from the first iteration of its loop), ``send``
whether the sender's address travels in the frame's identifier
(``sender_in_identifier``: CAN), ``available`` how long the bus has been quiet
(``quiet_for()``). It never reconfigures the bus model or tests its type.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from petriflow.agents.bus.algorithms import BusAwareScheme, NativeScheme
from petriflow.agents.bus.cpg import CpgParameters, motor_angle, wrap
from petriflow.agents.bus.packet import Packet, can_identifier, decode, encode
from petriflow.capabilities import Bodies, Physics, provides
from petriflow.runtime.action import Action, ActionContext, ActionFailure, InstantAction, Param, Status

__all__ = ["GUARDS", "Module", "Oscillator"]


@dataclass
class Oscillator:
    """One module's phase oscillator (eq. 2, the sign convention of
    :mod:`~petriflow.agents.bus.cpg`): ``φ' = w + Σ c·sin(φj − φ − φij)`` over the
    neighbours heard from, each at the phase its last message carried.

    Examples:
        >>> o = Oscillator(CpgParameters(), phase=0.0, front=False, back=True)
        >>> o.step(1.0); round(o.phase, 3)          # nobody heard yet: w = 0.5 rad/s
        0.5
    """

    parameters: CpgParameters
    phase: float
    front: bool
    back: bool
    heard: list[float | None] = field(default_factory=lambda: [None, None])

    def rate(self, phase: float) -> float:
        p = self.parameters
        total = p.frequency
        for side, bias in ((0, p.lag), (1, -p.lag)):
            target = self.heard[side]
            if target is not None:
                total += p.coupling * math.sin(target - phase - bias)
        return total

    def step(self, dt: float) -> None:
        """Runge–Kutta 4 over ``dt`` (the heard phases held constant)."""
        phi = self.phase
        k1 = self.rate(phi)
        k2 = self.rate(phi + 0.5 * dt * k1)
        k3 = self.rate(phi + 0.5 * dt * k2)
        k4 = self.rate(phi + dt * k3)
        self.phase = phi + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)

    def hear(self, side: int, phase: float) -> None:
        self.heard[side] = phase


class Module:
    """One module's state (see the module docstring)."""

    def __init__(self, name: str, chain: list[str], algorithm: int, messages: int, scheme: Any,
                 oscillator: Oscillator, address: int) -> None:
        self.name = name
        self.chain = chain
        self.algorithm = algorithm
        self.messages = messages
        self.scheme = scheme
        self.oscillator = oscillator
        self.address = address
        self.rate = 1.0              # the module's clock: its seconds per true second (crystal error)
        self.next_overflow = 0.0     # when its overflow interrupt next fires (true time)
        self.sent = 0
        self.groups = 0
        self.send_now = False        # algorithm 2's overflow drew "send"
        self.last_sample = -math.inf
        self.updated: float | None = None  # when the oscillator was last integrated to
        self.joint: tuple[int, int] | None = None

    @property
    def done(self) -> bool:
        return self.sent >= self.messages

    def to_token(self) -> dict[str, Any]:
        """What a trace records of the module's state: who it is and how far it got."""
        return {"agent": self.name, "address": self.address, "sent": self.sent, "groups": self.groups}

    def name_at(self, address: int) -> str | None:
        return self.chain[address] if 0 <= address < len(self.chain) else None


def _module(ctx: ActionContext) -> Module:
    for tokens in ctx.inputs.values():
        for data in tokens:
            if isinstance(data, Module):
                return data
    raise ActionFailure(f"{ctx.transition!r}: no module state among the input tokens")


class _Timed(Action):
    """Ends after :meth:`duration` simulated seconds (no polling in between)."""

    needs_world = False

    def start(self, ctx: ActionContext) -> None:
        self.module = _module(ctx)
        ctx.result = self.module
        self.wake_at = ctx.now + max(0.0, self.duration(ctx))

    def poll(self, ctx: ActionContext) -> Status:
        if ctx.now < self.wake_at - 1e-9:
            return Status.RUNNING
        self.finish(ctx)
        return Status.OK

    def duration(self, ctx: ActionContext) -> float:  # pragma: no cover - overridden
        raise NotImplementedError

    def finish(self, ctx: ActionContext) -> None:
        pass


def _chain_world(ctx: ActionContext) -> Any:
    """The run's world when it is a physics scene with the chain's body in it (the
    modules then sense and drive it), else ``None``: the firmware runs on the bus
    alone. The one place the optional world is asked what it provides."""
    world = ctx.world
    return world if provides(world, Bodies, Physics) and "chain" in world.bodies else None


def _front_free(world: Any, chain: list[str], name: str) -> bool:
    """The front proximity sensor: a ray ahead of the module's body finds nothing
    within ``reach`` (without a chain in the world: the first module is the head)."""
    if world is None:
        return chain.index(name) == 0
    from petriflow.agents.bus.chain import front_is_free

    return front_is_free(world, name)


class Boot(_Timed):
    """Auto-addressing, the scheme, a random start phase; the module's start-up takes
    ``U[0, spread]`` s (modules powered through the connector start nearly in step:
    1 ms by default), and its clock runs ``1 + U[−crystal_ppm, crystal_ppm]·10⁻⁶`` times
    the true rate (every timer of the module: control step, Delay, overflow period,
    reads). ``reception`` is the reception model: ``loop`` (the reception routine runs
    once per loop iteration: algorithm 1 reads its buffer every 20 ms + Delay, after
    its wait; algorithm 2 every 20 ms) or ``interrupt`` (the pseudo-code's reception
    interrupt: every frame is read on arrival)."""

    params = {
        "chain": Param(list, doc="the modules' agents, head first (who is behind whom)"),
        "algorithm": Param(int, 2, "the paper's algorithm: 1 (native) or 2 (bus-aware)", choices=(1, 2)),
        "messages": Param(int, 100, "messages each module sends", low=1),
        "step_time": Param(float, 0.02, "one loop iteration: CPG and actuator (s)", low=1e-9),
        "max_delay": Param(float, 1.0, "algorithm 1: Delay ~ U[0, max_delay] s", low=0),
        "idle_window": Param(float, 3.0, "algorithm 2: bus available comes U[0, idle_window] s into a quiet"
                             " (3 s: 100 messages take about the paper's two minutes)",
                             low=0),
        "lag": Param(float, 2 * math.pi / 3, "the phase lag between neighbours (rad)"),
        "spread": Param(float, 0.001, "start-up times are U[0, spread] s", low=0),
        "crystal_ppm": Param(float, 50.0, "each module's clock error is U[-ppm, +ppm] parts per million", low=0),
        "reception": Param(str, "loop", "the reception model: loop (once per loop iteration) or interrupt"
                           " (on arrival)", choices=("loop", "interrupt")),
        "mailboxes": Param(list, [], "this module's channel places (to tell the bus its read period)", places="*"),
    }

    def duration(self, ctx: ActionContext) -> float:
        return ctx.rng.uniform(0.0, self.params["spread"])

    def start(self, ctx: ActionContext) -> None:
        p = self.params
        name = ctx.agent or ctx.transition
        chain = [str(m) for m in p["chain"]]
        if name not in chain:
            raise ActionFailure(f"bus.boot: {name!r} is not in the chain {chain}")
        if p["messages"] < 1 or p["step_time"] <= 0:
            raise ActionFailure("bus.boot: messages must be >= 1 and step_time > 0")
        from petriflow.agents.bus.addressing import auto_address

        behind = {m: (chain[i + 1] if i + 1 < len(chain) else None) for i, m in enumerate(chain)}
        world = _chain_world(ctx)
        addresses = auto_address(behind, {m: _front_free(world, chain, m) for m in chain})
        address = addresses[name]
        rng = ctx.rng
        rate = 1.0 + rng.uniform(-p["crystal_ppm"], p["crystal_ppm"]) * 1e-6
        # one iteration: the control step and what the bus's interface costs each iteration
        step = p["step_time"] + max((ctx.medium(place).loop_cost for place in p["mailboxes"]), default=0.0)
        if p["algorithm"] == 1:
            scheme: Any = NativeScheme(address, len(chain), rng, step_time=step, max_delay=p["max_delay"])
            read_every = step + scheme.delay  # its reception runs once per iteration, after the wait
        else:
            scheme = BusAwareScheme(address, len(chain), rng, step_time=step, idle_window=p["idle_window"])
            read_every = step
        read_every = 0.0 if p["reception"] == "interrupt" else read_every * rate
        parameters = CpgParameters(lag=p["lag"], dt=p["step_time"])
        oscillator = Oscillator(parameters, rng.uniform(0.0, 2 * math.pi), address > 0, address < len(chain) - 1)
        by_address = sorted(chain, key=lambda m: addresses[m])
        self.module = Module(name, by_address, p["algorithm"], p["messages"], scheme, oscillator, address)
        self.module.rate = rate
        self.module.updated = self.module.next_overflow = self.wake_at = ctx.now + max(0.0, self.duration(ctx))
        for place in p["mailboxes"]:  # the reception routine runs once per iteration, from the first
            ctx.medium(place).reads_every(read_every, start=self.wake_at)
        if world is not None:
            from petriflow.agents.bus.chain import joint_of

            self.module.joint = joint_of(world, name)
        ctx.emit("bus.addressed", address=address, delay=round(getattr(scheme, "delay", 0.0), 6),
                 read_every=round(read_every, 9), started=round(self.wake_at, 9), rate=rate)
        ctx.result = self.module


class Cpg(_Timed):
    """``θi = CPG(...)``, ``Move actuator()``: one control step; at its end the oscillator
    is integrated up to now (the module's clock) and the joint's target angle set
    (eq. 1); a phase sample every ``sample`` s."""

    params = {"sample": Param(float, 0.1, "seconds between phase samples (bus.phase events)", low=0),
              "offset": Param(float, 0.0, "x, the joint's offset (rad)"),
              "amplitude": Param(float, 0.5, "r, the joint's amplitude (rad)", low=0)}

    def duration(self, ctx: ActionContext) -> float:
        return self.module.scheme.step_time * self.module.rate

    def start(self, ctx: ActionContext) -> None:
        super().start(ctx)
        module = self.module
        if ctx.now - module.last_sample >= self.params["sample"] - 1e-9:
            module.last_sample = ctx.now
            ctx.emit("bus.phase", phase=round(float(wrap(module.oscillator.phase)), 6), address=module.address)
            if module.address == 0 and module.joint is not None:
                from petriflow.agents.bus.chain import pose

                x, y = pose(ctx.world)
                ctx.emit("bus.pose", x=round(x, 6), y=round(y, 6))

    def finish(self, ctx: ActionContext) -> None:
        module = self.module
        # the oscillator runs on the module's clock: the time since its last update (one
        # control step, or more after algorithm 1's wait), in steps of at most dt
        elapsed = ctx.now - (module.updated if module.updated is not None else ctx.now - module.scheme.step_time)
        dt = module.oscillator.parameters.dt
        while elapsed > 1e-12:
            h = min(dt, elapsed)
            module.oscillator.step(h)
            elapsed -= h
        module.updated = ctx.now
        if module.joint is not None:
            from petriflow.agents.bus.chain import drive

            drive(ctx.world, module.joint, motor_angle(self.params["offset"], self.params["amplitude"],
                                                       module.oscillator.phase))


class Wait(_Timed):
    """Algorithm 1's ``Wait(Delay)``."""

    def duration(self, ctx: ActionContext) -> float:
        scheme = self.module.scheme
        return (scheme.iteration() - scheme.step_time) * self.module.rate if isinstance(scheme, NativeScheme) else 0.0


class Send(InstantAction):
    """``Send a message``: the CPG message as one frame to the scheme's addressees: a
    token in each addressee's channel place (``boxes``: address offset -> place)."""

    params = {"boxes": Param(dict, doc="{'+1': place, '-1': place} (an offset with no module: its frame"
                              " goes to nobody)", places="*"),
              "state": Param(str, doc="the place the module's state goes back to", places="")}

    def run(self, ctx: ActionContext) -> Module:
        module = _module(ctx)
        if module.done:
            raise ActionFailure(f"bus.send: {module.name!r} has sent its {module.messages} messages")
        receivers = module.scheme.receivers()
        oscillator, parameters = module.oscillator, module.oscillator.parameters
        packet = Packet(receivers=receivers, sender=module.address, phase=float(wrap(oscillator.phase)) % (2 * math.pi),
                        offset=parameters.offset, amplitude=parameters.amplitude)
        boxes = self.params["boxes"]
        bus = ctx.medium(next(iter(boxes.values()))) if boxes else None
        # on CAN the sender's address travels in the identifier: 8 data bytes, one frame
        payload = encode(packet, with_sender=not (bus is not None and bus.sender_in_identifier))
        module.groups += 1
        group = module.groups
        names = [module.name_at(r) for r in receivers]
        targets = [n for n in names if n is not None]
        for offset, place in boxes.items():
            data: dict[str, Any] = {"payload": payload, "size": len(payload), "identifier": can_identifier(module.address),
                                    "sender": module.name, "address": module.address, "group": group}
            if targets:
                data.update(multicast=group, receivers=targets)
            ctx.put(place, data)
        module.sent += 1
        ctx.put(self.params["state"], module)
        ctx.emit("bus.sent", group=group, to=[n if n is not None else f"address {r}" for n, r in zip(names, receivers)],
                 number=module.sent)
        return module


class Available(Action):
    """Algorithm 2's *bus available* interrupt: wait until the bus (``box``'s medium) has
    been quiet for this module's random ``U[0, idle_window]`` s and is free; a busy
    spell in between draws a new time for the next quiet one. The quiet is counted from
    when the interrupt is re-armed (after the module's previous send) at the earliest:
    a frame that never reached the medium (dropped by its interface) does not make the
    next one due at once."""

    params = {"box": Param(str, doc="a channel place on the bus (to watch it)", places="")}

    def start(self, ctx: ActionContext) -> None:
        self.module = _module(ctx)
        ctx.result = self.module
        self.bus = ctx.medium(self.params["box"])
        self.wanted = self.module.scheme.idle_delay()
        self.quiet = None
        self.armed = ctx.now

    def poll(self, ctx: ActionContext) -> Status:
        quiet_for = min(self.bus.quiet_for(), ctx.now - self.armed)
        if self.quiet is not None and quiet_for < self.quiet - 1e-12:  # the bus was busy meanwhile
            self.wanted = self.module.scheme.idle_delay()
        self.quiet = quiet_for
        if quiet_for > 0.0 and quiet_for >= self.wanted - 1e-12:
            return Status.OK
        return Status.RUNNING


class Overflow(_Timed):
    """Algorithm 2's overflow interrupt: every ``period`` s of the module's clock from
    the end of its start-up (a free-running timer: its times do not slip with the
    run's ticks), ``Indicator ~ U[0, 1]``; the module sends if it is below the
    probability (0.5)."""

    params = {"period": Param(float, 1.0, "seconds between overflow interrupts", low=1e-9)}

    def start(self, ctx: ActionContext) -> None:
        self.module = module = _module(ctx)
        ctx.result = module
        period = self.params["period"] * module.rate
        while module.next_overflow <= ctx.now + 1e-9:
            module.next_overflow += period
        self.wake_at = module.next_overflow

    def finish(self, ctx: ActionContext) -> None:
        self.module.send_now = self.module.scheme.overflow()


class Receive(InstantAction):
    """The reception routine: a frame from ``box`` (or the notice that it was lost);
    keep the neighbour's phase when the scheme accepts the message."""

    params = {"box": Param(str, doc="the channel place", places=""), "state": Param(str, doc="the listening place", places="")}

    def run(self, ctx: ActionContext) -> None:
        module = ctx.inputs[self.params["state"]][0]
        data = ctx.inputs[self.params["box"]][0]
        if not isinstance(module, Module) or not isinstance(data, dict):
            raise ActionFailure("bus.receive: needs the module's state and a message")
        lost = bool(data.get("lost"))
        frame = data.get("data") if lost else data
        sender = frame.get("sender") if isinstance(frame, dict) else None
        kept = False
        if not lost:
            payload = frame["payload"]
            packet = decode(payload, sender=frame.get("address")) if len(payload) == 8 else decode(payload)
            if module.scheme.accepts(packet):
                side = 0 if packet.sender == module.address - 1 else 1
                module.oscillator.hear(side, packet.phase)
                kept = True
        ctx.emit("bus.read", sender=sender, group=frame.get("group") if isinstance(frame, dict) else None,
                 lost=lost, why=data.get("why") if lost else None, kept=kept)
        ctx.put(self.params["state"], module)
        return None


class Drain(InstantAction):
    """A frame addressed to no module left the bus (or was lost on it)."""

    params = {"box": Param(str, doc="the channel place", places="")}

    def run(self, ctx: ActionContext) -> None:
        data = ctx.inputs[self.params["box"]][0]
        lost = bool(data.get("lost")) if isinstance(data, dict) else True
        frame = data.get("data") if lost and isinstance(data, dict) else data
        ctx.emit("bus.read", sender=frame.get("sender") if isinstance(frame, dict) else None,
                 group=frame.get("group") if isinstance(frame, dict) else None, lost=lost, void=True,
                 why=data.get("why") if lost and isinstance(data, dict) else None)
        return None


class Sniffer(InstantAction):
    """The paper's sniffer joins the bus (``box``'s medium) as a node of its own: it
    never sends, and takes every intact frame that reaches it, whoever it is for."""

    params = {"box": Param(str, doc="a channel place on the bus", places="")}

    def run(self, ctx: ActionContext) -> None:
        ctx.medium(self.params["box"]).sniff()
        return None


class Sniffed(InstantAction):
    """The sniffer's record, when every module has sent its messages: the frames it
    captured from each module (a ``bus.sniffed`` event, ``captured: {agent: frames}``)."""

    params = {"box": Param(str, doc="a channel place on the bus", places="")}

    def run(self, ctx: ActionContext) -> None:
        ctx.emit("bus.sniffed", captured=ctx.medium(self.params["box"]).captured())
        return None


def _state(tokens: dict[str, list[Any]]) -> Module | None:
    for ts in tokens.values():
        for d in ts:
            if isinstance(d, Module):
                return d
    return None


def sending(tokens: dict[str, list[Any]], params: dict[str, Any]) -> bool:
    """Guard: the module has messages left to send."""
    module = _state(tokens)
    return module is not None and not module.done


def finished(tokens: dict[str, list[Any]], params: dict[str, Any]) -> bool:
    """Guard: the module has sent all its messages."""
    module = _state(tokens)
    return module is not None and module.done


def overflow_sends(tokens: dict[str, list[Any]], params: dict[str, Any]) -> bool:
    """Guard: the overflow interrupt drew "send" and messages are left."""
    module = _state(tokens)
    return module is not None and module.send_now and not module.done


def overflow_skips(tokens: dict[str, list[Any]], params: dict[str, Any]) -> bool:
    """Guard: the overflow interrupt drew "do not send", or nothing is left to send."""
    module = _state(tokens)
    return module is not None and (not module.send_now or module.done)


GUARDS = {"bus.sending": sending, "bus.finished": finished, "bus.overflow_sends": overflow_sends,
          "bus.overflow_skips": overflow_skips}
