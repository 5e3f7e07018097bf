"""The modules' side of a bus: transmit queues, receive buffers, reads, listeners.

Every medium (:mod:`~petriflow.agents.bus.rs485`, :mod:`~petriflow.agents.bus.can`,
:mod:`~petriflow.agents.bus.zigbee`, :mod:`~petriflow.agents.bus.network`) is a
:class:`BusMedium`: the state of one bus on a
:class:`~petriflow.runtime.media.ProcessClock` (the run's kernel, or a kernel of its
own outside a run: :class:`~petriflow.agents.bus.simulator.BusSimulator`). Modules
:meth:`~BusMedium.request` frames; the medium's access rule (its subclass) puts them on
the wire; intact frames land in every other module's receive buffer, where the module
finds them when it next reads it. What happens is told to listeners as it happens
(:meth:`~BusMedium.on_start`, :meth:`~BusMedium.on_end` of a transmission,
:meth:`~BusMedium.on_delivery`: a module read a frame addressed to it,
:meth:`~BusMedium.on_loss`: a :class:`~petriflow.agents.bus.records.Lost` with its
reason, :meth:`~BusMedium.on_idle`); with ``logs=True`` (tests, figures) the medium
also keeps them in :attr:`~BusMedium.transmissions`, :attr:`~BusMedium.deliveries` and
:attr:`~BusMedium.losses` (a run's bus keeps none unless its model says ``logs: true``,
so its memory stays bounded however long the run).

Losses common to every bus (real modules' limits):

* **Receive buffer** (``rx_buffer`` frames, default 1): a frame that arrives while the
  buffer is full overwrites the oldest unread frame, which is lost then
  (:attr:`~petriflow.agents.bus.records.Loss.OVERWRITTEN`). The paper's reception
  routine checks addresses in software ("the receiving module rejects the packets that
  have not been assigned their address"), so by default every intact frame enters
  every module's buffer and a frame for someone else can overwrite one for this
  module; ``acceptance_filter=True`` models a hardware filter (CAN acceptance masks,
  XBee unicast addressing) that keeps them out.
* **Reading the buffer**: each module reads its buffer every ``read period`` seconds
  (:meth:`BusMedium.reads_every`; by default the bus's ``read_period``; 0: on arrival,
  as an interrupt would), at the times ``phase + k · period``: the *phase* is the
  module's own (when its firmware's loop started: the firmware says so, see
  :meth:`~petriflow.agents.bus.channel.BusView.reads_every`; 0 otherwise). A read is
  scheduled only while a frame waits in the buffer: the next such time at or after
  the frame's arrival, so an idle bus schedules nothing.
* **Transmit queue** (``tx_queue`` frames waiting besides the one on the wire): a
  request finding it full is dropped
  (:attr:`~petriflow.agents.bus.records.Loss.QUEUE_FULL`). Defaults (assumed): 3
  frames for a UART driver's ring buffer and for the XBee's serial buffer, 2 on CAN (a
  controller such as the MCP2515 has three transmit buffers, one of which holds the
  frame being sent). At the paper's rates (about one message a second per module) no
  queue fills; the limit matters for heavier traffic.

A medium's access rule is a subclass: it implements :meth:`BusMedium.is_free`,
:meth:`BusMedium.busy` and the hook ``_request(frame)`` (the frame passed the checks of
:meth:`BusMedium.request`), and reports through the base's ``_enqueue``, ``_arrive``,
``_started``, ``_ended``, ``_garble``, ``_lost`` and ``_notify_idle``.

Examples:
    A module that reads its buffer every 10 ms finds two frames at its first read after
    they came (CAN serialises them; a buffer of two holds both):

    >>> from petriflow.agents.bus.parameters import CanBus
    >>> from petriflow.agents.bus.simulator import BusSimulator
    >>> sim = BusSimulator(CanBus(rx_buffer=2), modules=[0, 1, 2])
    >>> sim.reads_every(0, 0.01)
    >>> for sender in (1, 2):
    ...     sim.send(0.0, Frame(sender, (0,), b"hi", identifier=0x100 + sender))
    >>> medium = sim.run(until=0.005)
    >>> medium.waiting(0), [(d.frame.sender, d.read) for d in sim.run(until=0.02).deliveries]
    (2, [(1, 0.01), (2, 0.01)])
"""

from __future__ import annotations

import math
import random
from collections import deque
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any

from petriflow.agents.bus.errors import BusError
from petriflow.agents.bus.frames import FrameError
from petriflow.agents.bus.records import Delivery, Frame, Loss, Lost, Transmission
from petriflow.runtime.media import ProcessClock, Timer

if TYPE_CHECKING:
    from petriflow.agents.bus.parameters import BusModel

__all__ = ["MEDIUM", "MODULE", "OWN_READ_PERIOD", "BusMedium"]

#: Rank of the media's own events (frame ends, arrivals): at one instant they run first.
MEDIUM = 0
#: Rank of the modules' events (buffer reads, sends in a
#: :class:`~petriflow.agents.bus.simulator.BusSimulator`): they see the settled bus.
MODULE = 1

#: The ``read_period`` a medium gets when none is given: its bus's own ``read_period``.
OWN_READ_PERIOD: Any = object()


def _check_period(period: float | None) -> float | None:
    if period is None:
        return None
    if isinstance(period, bool) or not isinstance(period, (int, float)) \
            or not (math.isfinite(period) and period >= 0):
        raise BusError(f"a read period is a number of seconds >= 0, got {period!r}")
    return float(period)


class BusMedium:
    """The state of one bus on a clock (see the module for the rules).

    Args:
        bus: the bus parameters.
        clock: the clock it runs on (``now``, ``at(time, callback, *args, rank=)``): the
            run's :class:`~petriflow.runtime.media.ProcessClock`.
        rng: the medium's random numbers (backoffs, radio errors).
        modules: the modules attached from the start (more with :meth:`add_module`).
        logs: keep :attr:`transmissions`, :attr:`deliveries` and :attr:`losses`.
        read_period: how often a module reads its buffer until :meth:`reads_every`
            says otherwise: seconds (0: on arrival), or ``None``: only when
            :meth:`read` is called (default: the bus's ``read_period``).

    Attributes:
        transmissions: every frame put on the medium, in start order (with ``logs``).
        deliveries: every frame a module read that was addressed to it (with ``logs``).
        losses: every loss, with its reason (with ``logs``).
        keep_newest: a full receive buffer drops its oldest frame for a new one (the
            hardware's behaviour); ``False`` drops the new one.
        sniffers: the modules attached by :meth:`sniff`.
        captured: ``{sniffer: {sender: frames}}``, what each sniffer captured.
    """

    def __init__(self, bus: BusModel, clock: ProcessClock, rng: random.Random, modules: Iterable[int] = (), *,
                 logs: bool = True, read_period: float | None = OWN_READ_PERIOD) -> None:
        self.bus = bus
        self.clock = clock
        self.rng = rng
        self.modules: list[int] = []
        self.logs = logs
        self.transmissions: list[Transmission] = []
        self.deliveries: list[Delivery] = []
        self.losses: list[Lost] = []
        self.keep_newest = True
        self.read_period = _check_period(bus.read_period if read_period is OWN_READ_PERIOD else read_period)
        self.started = clock.now
        self.last_end: float | None = None  # when the last frame left the medium
        self._buffers: dict[int, deque[tuple[Frame, float]]] = {}
        self._queues: dict[int, deque[Frame]] = {}
        self._readers: dict[int, tuple[float | None, float]] = {}  # module -> (period, phase)
        self._reads: dict[int, Timer] = {}  # the read scheduled while a frame waits
        self._on_start: list[Callable[[Transmission], Any]] = []
        self._on_end: list[Callable[[Transmission], Any]] = []
        self._on_delivery: list[Callable[[Delivery], Any]] = []
        self._on_loss: list[Callable[[Lost], Any]] = []
        self._on_idle: list[Callable[[int], Any]] = []
        self.sniffers: set[int] = set()
        self.captured: dict[int, dict[int, int]] = {}
        for module in modules:
            self.add_module(module)

    # Listeners -----------------------------------------------------------------------
    def on_start(self, callback: Callable[[Transmission], Any]) -> None:
        """Call ``callback(transmission)`` when a frame goes on the medium."""
        self._on_start.append(callback)

    def on_end(self, callback: Callable[[Transmission], Any]) -> None:
        """Call ``callback(transmission)`` when a frame leaves the medium (intact or garbled)."""
        self._on_end.append(callback)

    def on_delivery(self, callback: Callable[[Delivery], Any]) -> None:
        """Call ``callback(delivery)`` when a module reads a frame addressed to it."""
        self._on_delivery.append(callback)

    def on_loss(self, callback: Callable[[Lost], Any]) -> None:
        """Call ``callback(lost)`` when a frame is lost (for one module or for all)."""
        self._on_loss.append(callback)

    def on_idle(self, callback: Callable[[int], Any]) -> None:
        """Call ``callback(module)`` whenever the bus turns free in ``module``'s view."""
        self._on_idle.append(callback)

    # The modules' side -------------------------------------------------------------
    def add_module(self, module: int) -> None:
        """Attach a module (a no-op if it is attached)."""
        if module not in self._buffers:
            self.modules.append(module)
            self._buffers[module] = deque()
            self._queues[module] = deque()

    def sniff(self, module: int) -> None:
        """Attach ``module`` as a sniffer: a node that never sends, takes every intact
        frame it receives whoever it is for (no acceptance filter), reads on arrival,
        and counts them per sender in :attr:`captured` (``{sniffer: {sender: frames}}``)."""
        self.add_module(module)
        self.sniffers.add(module)
        self.captured.setdefault(module, {})
        self._readers[module] = (0.0, 0.0)

    def request(self, frame: Frame) -> bool:
        """The sender's module asks to send ``frame`` now; ``False`` if its transmit queue
        was full and the frame is dropped.

        Raises:
            FrameError: the bus cannot carry this frame, or the sender is not attached.
        """
        if frame.sender not in self._queues:
            raise FrameError(f"module {frame.sender} is not attached to this bus")
        self.bus.frame_bits(frame)  # raises for a frame the bus cannot carry
        return self._request(frame)

    def reads_every(self, module: int, period: float | None, phase: float = 0.0) -> None:
        """``module`` reads its receive buffer at ``phase + k · period`` (``period``
        seconds; 0: on arrival; ``None``: only when :meth:`read` is called). A frame
        already waiting is read on the new schedule.

        Raises:
            BusError: a period that is not a number of seconds >= 0, or a phase that
                is not finite.
        """
        period = _check_period(period)
        if not (isinstance(phase, (int, float)) and math.isfinite(phase)):
            raise BusError(f"a read phase is a time in seconds, got {phase!r}")
        self.add_module(module)
        self._readers[module] = (period, float(phase))
        timer = self._reads.pop(module, None)
        if timer is not None:
            timer.cancel()
        if self._buffers[module]:
            if period == 0.0:
                self.read(module)
            elif period is not None:
                self._schedule_read(module)

    def read_period_of(self, module: int) -> float | None:
        """How often ``module`` reads its buffer (see :meth:`reads_every`)."""
        return self._readers.get(module, (self.read_period, 0.0))[0]

    def read(self, module: int) -> list[Frame]:
        """The module empties its receive buffer now; returns the frames addressed to it
        (oldest first), which count as delivered. Frames for others are discarded."""
        timer = self._reads.pop(module, None)
        if timer is not None:
            timer.cancel()
        buffer = self._buffers[module]
        frames = []
        now = self.clock.now
        while buffer:
            frame, arrived = buffer.popleft()
            if module in frame.receivers:
                frames.append(frame)
                self._delivered(Delivery(frame, module, arrived, now))
        return frames

    def waiting(self, module: int) -> int:
        """Frames in ``module``'s receive buffer now."""
        return len(self._buffers[module])

    def is_free(self, module: int) -> bool:
        """Whether the bus looks free to ``module`` now (algorithm 2's "bus available")."""
        raise NotImplementedError

    def busy(self) -> bool:
        """Whether a frame is on the medium now."""
        raise NotImplementedError

    def quiet_for(self) -> float:
        """Seconds the medium has carried nothing, now (0 while a frame is on it; since
        the medium started when none ever was)."""
        if self.busy():
            return 0.0
        return self.clock.now - (self.started if self.last_end is None else self.last_end)

    def pending(self, module: int) -> int:
        """Frames the module's interface still holds (waiting or on the medium)."""
        return len(self._queues[module])

    # For the access rules (subclasses) ------------------------------------------------
    def _request(self, frame: Frame) -> bool:
        """Take ``frame`` (attached sender, a frame the bus carries); ``False``: dropped."""
        raise NotImplementedError

    def _enqueue(self, frame: Frame, in_service: bool) -> bool:
        """Put a frame in its sender's queue (the head is the one in service)."""
        queue = self._queues[frame.sender]
        if len(queue) - int(in_service) >= self.bus.tx_queue:
            self._lost(Lost(frame, None, Loss.QUEUE_FULL, self.clock.now))
            return False
        queue.append(frame)
        return True

    def _arrive(self, frame: Frame, module: int) -> None:
        """An intact frame reaches ``module``'s receive buffer now."""
        if module in self.sniffers:
            counts = self.captured[module]
            counts[frame.sender] = counts.get(frame.sender, 0) + 1
            return
        if self.bus.acceptance_filter and module not in frame.receivers:
            return
        now = self.clock.now
        period = self.read_period_of(module)
        if period == 0.0:  # read on arrival
            if module in frame.receivers:
                self._delivered(Delivery(frame, module, now, now))
            return
        buffer = self._buffers[module]
        if len(buffer) >= self.bus.rx_buffer:
            if not self.keep_newest:
                self._lost(Lost(frame, module, Loss.OVERWRITTEN, now))
                return
            old, _ = buffer.popleft()
            self._lost(Lost(old, module, Loss.OVERWRITTEN, now))
        buffer.append((frame, now))
        if period is not None and module not in self._reads:
            self._schedule_read(module)

    def _schedule_read(self, module: int) -> None:
        """The module's next read at or after now, on its phase (a frame waits)."""
        period, phase = self._readers.get(module, (self.read_period, 0.0))
        assert period is not None and period > 0.0
        now = self.clock.now
        when = phase + math.ceil((now - phase) / period - 1e-9) * period
        self._reads[module] = self.clock.at(max(when, now), self._scheduled_read, module, rank=MODULE)

    def _scheduled_read(self, module: int) -> None:
        self._reads.pop(module, None)
        self.read(module)

    def _tell(self, log: list[Any], listeners: list[Callable[[Any], Any]], what: Any) -> None:
        """Keep ``what`` in ``log`` (with ``logs``) and call every listener with it."""
        if self.logs:
            log.append(what)
        for callback in listeners:
            callback(what)

    def _started(self, transmission: Transmission) -> None:
        self._tell(self.transmissions, self._on_start, transmission)

    def _ended(self, transmission: Transmission) -> None:
        self.last_end = transmission.end if self.last_end is None else max(self.last_end, transmission.end)
        for callback in self._on_end:
            callback(transmission)

    def _garble(self, transmission: Transmission) -> None:
        """``transmission`` overlaps another now: it is lost to everyone now."""
        if not transmission.garbled:
            transmission.garbled = True
            self._lost(Lost(transmission.frame, None, Loss.COLLISION, self.clock.now))

    def _delivered(self, delivery: Delivery) -> None:
        self._tell(self.deliveries, self._on_delivery, delivery)

    def _lost(self, lost: Lost) -> None:
        self._tell(self.losses, self._on_loss, lost)

    def _notify_idle(self, modules: Iterable[int]) -> None:
        for module in modules:
            for callback in self._on_idle:
                callback(module)
