"""Seed 002's two message transmission schemes, as rules driven by simulated time.

Each scheme is what one module's firmware decides; it never touches a bus or a clock.
A driver (the firmware's actions, :mod:`~petriflow.agents.bus.firmware`) asks it when
the module's loop comes round, whether to send at an interrupt, whom a message is for
and whether a received one is accepted, and does the rest. Random draws come from the
``random.Random`` each scheme is given, in a fixed order, so a seed fixes a run.

**Algorithm 1, native** (:class:`NativeScheme`), as printed::

    Delay in milliseconds ~ U[0, 1000]          (once, before the loop)
    while module on:
        θi = CPG(...); Move actuator(); Wait(Delay); Send a message to the neighbours

The delay is drawn once per module at start-up, so each module sends with a fixed
period of ``step_time + delay``; ``redraw=True`` draws a new delay every iteration
instead (the looser reading "after a random delay"). The message goes to both
neighbours (``myaddress + 1``, ``myaddress − 1``, those that exist: the module checks
the number of connected modules at start-up), whatever the bus is doing.

**Algorithm 2, modified** (:class:`BusAwareScheme`), as printed: the loop only runs the
CPG and moves the actuator (no wait); a *bus available* interrupt sends a message;
an *overflow* interrupt every second draws ``Indicator ~ U[0, 1]`` and sends if it is
below 0.5. The paper says when the bus-available interrupt comes only loosely: "when
there are intervals of inactivity on the bus, a randomly selected module sends a
message", and "the only way two modules transmit at the same time depends on a random
function defined in the overflow interruption". We read it as: each module's
interface raises *bus available* once the bus has been quiet, in that module's view,
for a random time ``U[0, idle_window]`` (the first module to get there sends; the
others then see a busy bus and wait for the next quiet spell, when they draw again);
the handler sends only if the bus is still free. The paper gives no value for the
window; it says the sniffer watched each run for about two minutes, until every module
had sent 100 messages. The firmware's default (``bus.boot``) is 3 s, with which 100
messages take about two minutes (the overflow interrupt alone sends one every 2 s on
average); the scheme's own default here is 1 s, the same law as algorithm 1's delay. The message goes to ``String[0] = my address + 1`` only.

**Reception.** Both schemes' reception routines read the input buffer and keep a
message if ``String[0]`` is the module's address. Algorithm 2 also checks that
``String[1] == my address + 1``, which contradicts its own builder (a message for
``a`` is built by ``a − 1`` with ``String[1] = a − 1``), so nothing would ever be
accepted; we follow the paper's text instead ("the sender's address is the
neighbouring module") and accept a sender at ``a ± 1``. Algorithm 1's message carries
two receivers; a module accepts it if it is either.

**When a module reads.** The reception routine runs once per iteration of the main
loop (the loop polls the receive buffer; frames that arrive meanwhile wait in the
buffer, where a newer one overwrites an older one). Algorithm 1's iteration includes
its blocking ``Wait``, so it reads every ``step_time + delay``; algorithm 2's every
``step_time``. ``step_time`` (default 20 ms: a 50 Hz servo update) is the time to run
the CPG and move the actuator; the paper does not give it.

Examples:
    >>> import random
    >>> native = NativeScheme(address=1, modules=3, rng=random.Random(4))
    >>> native.receivers(), round(native.delay, 3), round(native.iteration(), 3)
    ((2, 0), 0.236, 0.256)
    >>> native.wants_to_send(bus_free=False)     # regardless of the bus
    True
    >>> aware = BusAwareScheme(address=1, modules=3, rng=random.Random(4))
    >>> aware.receivers(), aware.iteration(), aware.bus_available(bus_free=False)
    ((2,), 0.02, False)
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field

from petriflow.agents.bus.packet import Packet

__all__ = ["ALGORITHMS", "BusAwareScheme", "NativeScheme"]


@dataclass
class NativeScheme:
    """Algorithm 1: send after the module's random delay, whatever the bus is doing.

    Attributes:
        address: the module's address.
        modules: modules in the chain.
        rng: the module's random numbers.
        step_time: running the CPG and moving the actuator (s).
        max_delay: the delay is ``U[0, max_delay]`` (s).
        redraw: draw a new delay every iteration instead of once.
        delay: the current delay.
    """

    address: int
    modules: int
    rng: random.Random
    step_time: float = 0.02
    max_delay: float = 1.0
    redraw: bool = False
    delay: float = field(init=False)

    def __post_init__(self) -> None:
        self.delay = self.rng.uniform(0.0, self.max_delay)
        self._first = True

    def iteration(self) -> float:
        """Length of the loop iteration starting now: CPG, move, wait; it ends with a send."""
        if self.redraw and not self._first:
            self.delay = self.rng.uniform(0.0, self.max_delay)
        self._first = False
        return self.step_time + self.delay

    def wants_to_send(self, bus_free: bool) -> bool:
        """At the end of an iteration the module sends, whatever ``bus_free`` says."""
        return True

    def receivers(self) -> tuple[int, ...]:
        """The neighbours ``myaddress + 1`` and ``myaddress − 1`` that exist."""
        return tuple(a for a in (self.address + 1, self.address - 1) if 0 <= a < self.modules)

    def accepts(self, packet: Packet) -> bool:
        """Keep a message addressed to this module."""
        return packet.is_for(self.address)


@dataclass
class BusAwareScheme:
    """Algorithm 2: send when the bus is available, and on a 1 s overflow with
    probability 0.5.

    Attributes:
        address: the module's address.
        modules: modules in the chain (unused by the rules; kept for symmetry).
        rng: the module's random numbers.
        step_time: one loop iteration: CPG and actuator (s).
        overflow_period: the overflow interrupt's period (s).
        probability: the overflow interrupt sends if ``U[0, 1]`` is below this.
        idle_window: the bus-available interrupt comes ``U[0, idle_window]`` after the
            bus turned quiet (s).
    """

    address: int
    modules: int
    rng: random.Random
    step_time: float = 0.02
    overflow_period: float = 1.0
    probability: float = 0.5
    idle_window: float = 1.0

    def iteration(self) -> float:
        """Length of one loop iteration (the module reads its buffer once in each)."""
        return self.step_time

    def overflow(self) -> bool:
        """The overflow interrupt: ``Indicator ~ U[0, 1]``; send if it is below 0.5."""
        return self.rng.random() < self.probability

    def idle_delay(self) -> float:
        """How long after the bus turns quiet this module's bus-available interrupt comes."""
        return self.rng.uniform(0.0, self.idle_window)

    def bus_available(self, bus_free: bool) -> bool:
        """The bus-available handler sends only on a free bus."""
        return bus_free

    def receivers(self) -> tuple[int, ...]:
        """``String[0] = my address + 1`` (the tail's messages are for an address no
        module has)."""
        return (self.address + 1,)

    def accepts(self, packet: Packet) -> bool:
        """Keep a message addressed to this module from a neighbouring module."""
        return packet.is_for(self.address) and abs(packet.sender - self.address) == 1


#: The schemes by the paper's algorithm number.
ALGORITHMS: dict[int, type[NativeScheme | BusAwareScheme]] = {1: NativeScheme, 2: BusAwareScheme}
