"""Seed 002's experiment in pure Python: a chain of modules sharing a bus, each sending
its CPG phase until it has sent 100 messages.

:func:`run_experiment` builds the chain (auto-addressed, :mod:`.addressing`), one
:mod:`scheme <.algorithms>` per module, one :class:`~.medium.Medium` and one
:class:`~.cpg.CpgChain` on a shared :class:`~.timeline.Timeline`, runs until every
module has sent ``messages`` messages and the last ones had time to be read, and
counts, per sender, the messages *received* and *lost*:

* a message is received when every addressee that exists read it from its buffer
  (algorithm 1's messages go to both neighbours, so a middle module's message needs
  both);
* a message addressed only to an address no module holds (algorithm 2's tail sends
  to ``address + 1``) is received when it crossed the bus intact, as the paper's
  sniffer would see it;
* a lost message's reason is the first :class:`~.medium.Loss` that hit it on the way
  to an addressee (``"unread"`` if it was still in a buffer at the end).

The phase error is :func:`~.cpg.phase_error` of the true phases, sampled every 0.1 s
and averaged while every module is still sending (from ``min(5 s, half that time)``
to the moment the first module sends its last message: after that its neighbours hear
nothing new from it whatever the bus does).

Other assumptions: modules finish auto-addressing and start their loops at times
spread uniformly over the first 0.1 s; each module's random numbers, the medium's and
the initial phases (uniform on [0, 2π)) come from generators seeded with ``seed`` and
their role, so two runs with the same seed are identical and runs on different buses
with the same seed share the modules' draws.

:data:`PAPER_LOST` holds the paper's Tables 1–3 (mean lost messages out of 100 per
module) for printing beside the measured values; nothing here reads it.

Examples:
    >>> result = run_experiment("can", algorithm=2, messages=20, seed=1)
    >>> [m.sent for m in result.modules]
    [20, 20, 20]
    >>> result.lost == sum(m.lost for m in result.modules)
    True
"""

from __future__ import annotations

import math
import random
import statistics
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

from petriflow.agents.bus.addressing import auto_address
from petriflow.agents.bus.algorithms import ALGORITHMS, BusAwareScheme, NativeScheme
from petriflow.agents.bus.cpg import CpgChain, CpgParameters, phase_error
from petriflow.agents.bus.medium import BusModel, CanBus, Frame, Medium, SerialBus, ZigbeeBus
from petriflow.agents.bus.packet import Packet, can_identifier, decode, encode
from petriflow.agents.bus.timeline import Timeline, Timer

__all__ = [
    "BUSES",
    "PAPER_LOST",
    "ExperimentResult",
    "ModuleResult",
    "format_table",
    "make_bus",
    "run_experiment",
    "run_grid",
]

#: The paper's buses by name.
BUSES: dict[str, type[BusModel]] = {"serial": SerialBus, "can": CanBus, "zigbee": ZigbeeBus}

#: Tables 1–3 of the paper: mean messages lost out of 100 by modules 1, 2, 3.
PAPER_LOST: dict[tuple[str, int], tuple[float, float, float]] = {
    ("serial", 1): (35, 40, 55), ("serial", 2): (20, 22, 28),
    ("can", 1): (30, 35, 65), ("can", 2): (18, 25, 21),
    ("zigbee", 1): (45, 62, 72), ("zigbee", 2): (38, 32, 38),
}

_SAMPLE_PERIOD = 0.1
_START_SPREAD = 0.1


@dataclass(frozen=True)
class ModuleResult:
    """What became of one module's messages.

    Attributes:
        address: the module's address.
        sent: messages it asked to send.
        received: messages every addressee read (or that crossed the bus, if none exists).
        reasons: lost messages by :class:`~.medium.Loss` value (or ``"unread"``).
    """

    address: int
    sent: int
    received: int
    reasons: dict[str, int] = field(default_factory=dict)

    @property
    def lost(self) -> int:
        """Messages not received."""
        return self.sent - self.received

    @property
    def lost_pct(self) -> float:
        """Lost messages in percent of those sent."""
        return 100.0 * self.lost / self.sent if self.sent else 0.0


@dataclass(frozen=True)
class ExperimentResult:
    """One run: the bus, the algorithm, the seed and what happened.

    Attributes:
        phase_error: mean phase-locking error (rad) while every module was sending.
        duration: simulated seconds until the last message was sent.
        transmissions: frames put on the medium (collided ones included).
    """

    bus: str
    algorithm: int
    seed: int
    modules: tuple[ModuleResult, ...]
    phase_error: float
    duration: float
    transmissions: int

    @property
    def sent(self) -> int:
        """Messages sent by all modules."""
        return sum(m.sent for m in self.modules)

    @property
    def lost(self) -> int:
        """Messages lost, all modules."""
        return sum(m.lost for m in self.modules)

    @property
    def lost_pct(self) -> float:
        """Lost messages in percent of those sent, all modules."""
        return 100.0 * self.lost / self.sent if self.sent else 0.0

    def reasons(self) -> dict[str, int]:
        """Lost messages by reason, all modules."""
        total: Counter[str] = Counter()
        for module in self.modules:
            total.update(module.reasons)
        return dict(total)


def make_bus(bus: str | BusModel) -> tuple[str, BusModel]:
    """A bus and its name from a name in :data:`BUSES` or a bus model.

    Raises:
        ValueError: an unknown name.
    """
    if isinstance(bus, BusModel):
        for name, cls in BUSES.items():
            if type(bus) is cls:
                return name, bus
        return type(bus).__name__, bus
    if bus not in BUSES:
        raise ValueError(f"unknown bus {bus!r} (one of {', '.join(BUSES)})")
    return bus, BUSES[bus]()


class _Module:
    """One module's firmware on the timeline: its loop, interrupts and sends."""

    def __init__(self, run: _Run, address: int, scheme: NativeScheme | BusAwareScheme, start: float) -> None:
        self.run = run
        self.address = address
        self.scheme = scheme
        self.start = start
        self.sent = 0
        self.available: Timer | None = None

    def boot(self) -> None:
        timeline = self.run.timeline
        timeline.at(self.start, self.loop)
        if isinstance(self.scheme, BusAwareScheme):
            timeline.at(self.start + self.scheme.overflow_period, self.overflow)
            timeline.at(self.start, self.arm)

    @property
    def done(self) -> bool:
        return self.sent >= self.run.messages

    def loop(self) -> None:
        """One iteration of the main loop: read the buffer, then CPG and actuator (and,
        in algorithm 1, the wait and the send at the end)."""
        self.read()
        if isinstance(self.scheme, NativeScheme):
            self.run.timeline.after(self.scheme.iteration(), self.end_iteration)
        else:
            self.run.timeline.after(self.scheme.iteration(), self.loop)

    def end_iteration(self) -> None:
        scheme = self.scheme
        assert isinstance(scheme, NativeScheme)
        if not self.done and scheme.wants_to_send(self.run.medium.is_free(self.address)):
            self.send()
        self.loop()

    def overflow(self) -> None:
        scheme = self.scheme
        assert isinstance(scheme, BusAwareScheme)
        if not self.done:
            if scheme.overflow():
                self.send()
            self.run.timeline.after(scheme.overflow_period, self.overflow)

    def quiet(self, module: int) -> None:
        """The medium says the bus turned quiet in ``module``'s view."""
        if module == self.address and isinstance(self.scheme, BusAwareScheme):
            self.arm()

    def arm(self) -> None:
        scheme = self.scheme
        assert isinstance(scheme, BusAwareScheme)
        if self.available is not None:
            self.available.cancel()
            self.available = None
        if not self.done:
            self.available = self.run.timeline.after(scheme.idle_delay(), self.bus_available)

    def bus_available(self) -> None:
        self.available = None
        scheme = self.scheme
        assert isinstance(scheme, BusAwareScheme)
        if not self.done and scheme.bus_available(self.run.medium.is_free(self.address)):
            self.send()

    def send(self) -> None:
        run = self.run
        chain = run.chain
        p = chain.parameters
        packet = Packet(self.scheme.receivers(), self.address, float(chain.phases[self.address]),
                        p.offset, p.amplitude, self.sent)
        if isinstance(run.bus, CanBus):
            frame = Frame(self.address, packet.receivers, encode(packet, with_sender=False),
                          can_identifier(self.address), (self.address, self.sent))
        else:
            frame = Frame(self.address, packet.receivers, encode(packet), 0, (self.address, self.sent))
        run.frames[frame.tag] = frame
        self.sent += 1
        if self.done:
            run.finished.append(run.timeline.now)
        run.medium.request(frame)

    def read(self) -> None:
        run = self.run
        for frame in run.medium.read(self.address):
            sender = frame.sender if isinstance(run.bus, CanBus) else None
            packet = decode(frame.data, sender)
            if self.scheme.accepts(packet):
                run.chain.hear(self.address, packet.sender, packet.phase)


class _Run:
    """The state of one experiment run."""

    def __init__(self, bus: BusModel, algorithm: int, n: int, messages: int, seed: int,
                 scheme_options: dict[str, Any], cpg: CpgParameters) -> None:
        self.bus = bus
        self.messages = messages
        self.timeline = Timeline()
        self.medium: Medium = bus.medium(self.timeline, random.Random(f"{seed}:medium"), range(n))
        start = random.Random(f"{seed}:start")
        phases = random.Random(f"{seed}:cpg")
        self.chain = CpgChain(n, cpg, [phases.uniform(0.0, 2.0 * math.pi) for _ in range(n)])
        # Physical chain: module i (by serial number) sits behind module i - 1.
        names = [f"m{i}" for i in range(n)]
        behind = {names[i]: names[i + 1] if i + 1 < n else None for i in range(n)}
        addresses = auto_address(behind, {name: i == 0 for i, name in enumerate(names)})
        scheme_class = ALGORITHMS[algorithm]
        self.modules = [
            _Module(self, address, scheme_class(address, n, random.Random(f"{seed}:module:{address}"),
                                                **scheme_options), start.uniform(0.0, _START_SPREAD))
            for address in sorted(addresses.values())
        ]
        for module in self.modules:
            self.medium.on_idle(module.quiet)
        self.frames: dict[Any, Frame] = {}
        self.finished: list[float] = []
        self.samples: list[tuple[float, float]] = []

    def tick(self) -> None:
        self.chain.step()
        self.timeline.after(self.chain.parameters.dt, self.tick)

    def sample(self) -> None:
        self.samples.append((self.timeline.now, phase_error(self.chain.phases, self.chain.parameters.lag)))
        self.timeline.after(_SAMPLE_PERIOD, self.sample)

    def all_done(self) -> bool:
        return len(self.finished) == len(self.modules)


def run_experiment(bus: str | BusModel = "can", algorithm: int = 2, *, modules: int = 3, messages: int = 100,
                   seed: int = 0, scheme_options: dict[str, Any] | None = None,
                   cpg: CpgParameters | None = None, drain: float = 2.5) -> ExperimentResult:
    """Run the experiment once.

    Args:
        bus: ``"serial"``, ``"can"``, ``"zigbee"`` or a bus model with its parameters.
        algorithm: 1 (native) or 2 (bus-aware).
        modules: modules in the chain.
        messages: messages each module sends.
        seed: seeds every random draw.
        scheme_options: extra arguments of the scheme (``step_time``, ``redraw``, ...).
        cpg: oscillator constants.
        drain: seconds simulated after the last send, for the last frames to be read.

    Raises:
        ValueError: an unknown bus or algorithm, or fewer than two modules.
    """
    if algorithm not in ALGORITHMS:
        raise ValueError(f"unknown algorithm {algorithm!r} (1 or 2)")
    if modules < 2:
        raise ValueError(f"a chain needs at least two modules, got {modules}")
    name, model = make_bus(bus)
    run = _Run(model, algorithm, modules, messages, seed, dict(scheme_options or {}), cpg or CpgParameters())
    for module in run.modules:
        module.boot()
    run.timeline.at(0.0, run.tick)
    run.timeline.at(0.0, run.sample)
    run.timeline.run(stop=run.all_done)
    duration = run.timeline.now
    run.timeline.run(until=duration + drain)
    return ExperimentResult(name, algorithm, seed, _count(run), _mean_phase_error(run), duration,
                            len(run.medium.transmissions))


def _count(run: _Run) -> tuple[ModuleResult, ...]:
    n = len(run.modules)
    medium = run.medium
    delivered = {(d.frame.tag, d.module) for d in medium.deliveries}
    intact = {t.frame.tag for t in medium.transmissions if not t.garbled}
    first_loss: dict[tuple[Any, int | None], str] = {}
    for loss in medium.losses:
        first_loss.setdefault((loss.frame.tag, loss.module), loss.reason.value)
    results = []
    for module in run.modules:
        received = 0
        reasons: Counter[str] = Counter()
        for number in range(module.sent):
            tag = (module.address, number)
            frame = run.frames[tag]
            addressees = [r for r in frame.receivers if 0 <= r < n]
            if addressees:
                ok = all((tag, r) in delivered for r in addressees)
            else:
                ok = tag in intact
            if ok:
                received += 1
                continue
            reason = first_loss.get((tag, None))
            for r in addressees:
                if reason is None and (tag, r) not in delivered:
                    reason = first_loss.get((tag, r))
            reasons[reason or "unread"] += 1
        results.append(ModuleResult(module.address, module.sent, received, dict(reasons)))
    return tuple(results)


def _mean_phase_error(run: _Run) -> float:
    end = min(run.finished) if run.finished else run.timeline.now
    begin = min(5.0, end / 2.0)
    window = [error for time, error in run.samples if begin <= time <= end]
    return statistics.fmean(window) if window else math.nan


def run_grid(buses: Iterable[str | BusModel] = ("serial", "can", "zigbee"), algorithms: Iterable[int] = (1, 2),
             seeds: Iterable[int] = range(5), **options: Any) -> list[ExperimentResult]:
    """:func:`run_experiment` for every bus × algorithm × seed (``options`` passed on)."""
    seeds = list(seeds)
    algorithms = list(algorithms)
    return [run_experiment(bus, algorithm, seed=seed, **options)
            for bus in buses for algorithm in algorithms for seed in seeds]


def _mean_sd(values: list[float]) -> str:
    sd = statistics.stdev(values) if len(values) > 1 else 0.0
    return f"{statistics.fmean(values):5.1f} ± {sd:4.1f}"


def format_table(results: Iterable[ExperimentResult]) -> str:
    """A text table: per bus and algorithm, the lost percentage of each module and of
    all (mean ± standard deviation over the seeds), the phase error, the main loss
    reasons, and the paper's lost counts per module.

    Examples:
        >>> print(format_table([run_experiment("serial", 2, messages=10, seed=0)]).splitlines()[0])
        bus     alg  lost % by module                      all %         phase err  reasons                     paper
    """
    groups: dict[tuple[str, int], list[ExperimentResult]] = {}
    for result in results:
        groups.setdefault((result.bus, result.algorithm), []).append(result)
    header = (f"{'bus':<7} {'alg':<4} {'lost % by module':<37} {'all %':<13} {'phase err':<10} "
              f"{'reasons':<27} paper")
    lines = [header]
    for (bus, algorithm), runs in groups.items():
        n = len(runs[0].modules)
        per_module = "  ".join(_mean_sd([r.modules[i].lost_pct for r in runs]) for i in range(n))
        reasons: Counter[str] = Counter()
        for r in runs:
            reasons.update(r.reasons())
        top = ", ".join(f"{k} {v}" for k, v in reasons.most_common(2))
        paper = PAPER_LOST.get((bus, algorithm))
        phase = statistics.fmean(r.phase_error for r in runs)
        lines.append(f"{bus:<7} {algorithm:<4} {per_module:<37} {_mean_sd([r.lost_pct for r in runs]):<13} "
                     f"{phase:<10.3f} {top:<27} {'/'.join(f'{v:g}' for v in paper) if paper else '-'}")
    return "\n".join(lines)
