"""RS-485: a half-duplex line with no arbitration (:class:`SerialMedium`).

A UART sends whenever its module asks (after its own previous frame). Two frames that
overlap in time garble each other: both are lost at every receiver, at the moment they
overlap (no capture: differential drivers fighting give framing and checksum errors;
the garbled frames still hold the line to their ends). Carrier sense, for algorithm 2,
sees a frame ``sense_bits`` bit times after its start bit (the receiver must sample
the start bit), so two modules that check within that window both find the line free
and collide. The parameters are :class:`~petriflow.agents.bus.parameters.SerialBus`.

Examples:
    >>> from petriflow.agents.bus.parameters import SerialBus
    >>> from petriflow.agents.bus.simulator import BusSimulator
    >>> sim = BusSimulator(SerialBus(), modules=[0, 1])
    >>> sim.reads_every(1, 0.0)
    >>> sim.send(0.0, Frame(0, (1,), bytes(9)))   # (9 + 1) bytes of 10 bits: 868 µs
    >>> line = sim.run(until=0.0005)
    >>> type(line).__name__, line.busy(), line.is_free(1)
    ('SerialMedium', True, False)
    >>> [round(delivery.arrived * 1e6) for delivery in sim.run().deliveries]
    [868]
"""

from __future__ import annotations

import random
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from petriflow.agents.bus.buffer import MEDIUM, BusMedium
from petriflow.agents.bus.records import Frame, Transmission
from petriflow.runtime.media import ProcessClock

if TYPE_CHECKING:
    from petriflow.agents.bus.parameters import SerialBus

__all__ = ["SerialMedium"]


class SerialMedium(BusMedium):
    """An RS-485 line: a module's UART sends a frame as soon as its previous one is out;
    frames that overlap garble each other, lost at every receiver from that moment."""

    bus: SerialBus

    def __init__(self, bus: SerialBus, clock: ProcessClock, rng: random.Random, modules: Iterable[int] = (),
                 **options: Any) -> None:
        super().__init__(bus, clock, rng, modules, **options)
        self._active: list[Transmission] = []

    def is_free(self, module: int) -> bool:
        horizon = self.clock.now - self.bus.sense_bits / self.bus.baud
        return not self._queues[module] and not any(t.start <= horizon for t in self._active)

    def busy(self) -> bool:
        return bool(self._active)

    def _request(self, frame: Frame) -> bool:
        busy = bool(self._queues[frame.sender])
        if not self._enqueue(frame, busy):
            return False
        if not busy:
            self._start(frame)
        return True

    def _start(self, frame: Frame) -> None:
        now = self.clock.now
        bits = self.bus.frame_bits(frame)
        transmission = Transmission(frame, now, now + bits / self.bus.baud, bits)
        self._active.append(transmission)
        self._started(transmission)
        if len(self._active) > 1:  # the line was busy: this frame and those on it are garbled now
            for other in self._active:
                self._garble(other)
        self.clock.at(transmission.end, self._end, transmission, rank=MEDIUM)

    def _end(self, transmission: Transmission) -> None:
        self._active.remove(transmission)
        frame = transmission.frame
        self._ended(transmission)
        if not transmission.garbled:
            for module in self.modules:
                if module != frame.sender:
                    self._arrive(frame, module)
        queue = self._queues[frame.sender]
        queue.popleft()
        if queue:
            self._start(queue[0])
        if not self._active:
            self._notify_idle(self.modules)
