"""Asynchronous packet transmission on a modular robot bus (seed 002): buses, CPG, firmware, nets.

A chain of EMERGE modules runs a CPG and shares each module's phase with its
neighbours over one shared bus; messages collide, wait, or get overwritten in a
module's receive buffer, and lost messages degrade the chain's phase locking. The
buses run as processes on the run's kernel (:mod:`petriflow.runtime.media`), the
modules' firmware as actions of a net; the experiment is a sweep
(``nets/bus/experiments/tables1-3.yaml``). :mod:`.chain` adds the pybullet robot.

* :mod:`~petriflow.agents.bus.errors`: the package's errors.
* :mod:`~petriflow.agents.bus.frames`: frame lengths in bits (UART, CAN with bit
  stuffing on the real pattern, IEEE 802.15.4).
* :mod:`~petriflow.agents.bus.packet`: the CPG message and its bytes.
* :mod:`~petriflow.agents.bus.radio`: frame errors of the ZigBee radios (RSSI from the
  core's log-distance model).
* :mod:`~petriflow.agents.bus.records`: frames, transmissions, deliveries, losses and
  their reasons.
* :mod:`~petriflow.agents.bus.parameters`: the buses' parameters (RS-485, CAN, ZigBee);
  each bus is a petriflow medium.
* :mod:`~petriflow.agents.bus.buffer`: what every bus shares at bit-level timing on a
  :class:`~petriflow.runtime.media.ProcessClock`: transmit queues, receive buffers,
  reads, listeners, a sniffer node.
* :mod:`~petriflow.agents.bus.rs485`, :mod:`~petriflow.agents.bus.can`,
  :mod:`~petriflow.agents.bus.zigbee`: the three MAC layers (a line with no
  arbitration, arbitration by identifier, 802.15.4 CSMA/CA radios).
* :mod:`~petriflow.agents.bus.network`: ZigBee as a network over the 802.15.4 MAC
  (broadcast transaction tables, relaying with passive acknowledgement, end devices
  polling their parent).
* :mod:`~petriflow.agents.bus.simulator`: a bus on its own, outside a run
  (:class:`~petriflow.agents.bus.simulator.BusSimulator`).
* :mod:`~petriflow.agents.bus.channel`: a run's messages as frames on a bus, their
  fates when they happen, and the view a module's firmware asks the bus through.
* :mod:`~petriflow.agents.bus.cpg`: the phase oscillators and the phase-locking error.
* :mod:`~petriflow.agents.bus.algorithms`: the paper's algorithms 1 and 2.
* :mod:`~petriflow.agents.bus.addressing`: the chain's auto-addressing.
* :mod:`~petriflow.agents.bus.firmware`: a module's firmware as actions a net binds
  (boot, CPG step, Wait(Delay), send, the bus-available and overflow interrupts,
  reception).
* :mod:`~petriflow.agents.bus.nets`: the chain as a workflow net, algorithm 1 or 2.
* :mod:`~petriflow.agents.bus.chain`: the chain as a pybullet robot (hinges, front
  sensors).
* :mod:`~petriflow.agents.bus.metrics`: lost messages per module (at the addressees
  and at the sniffer), phase error, speed.
* :mod:`~petriflow.agents.bus.figures`: lost messages beside Tables 1-3, CPG phases.
* :mod:`~petriflow.agents.bus.plugin`: registers the buses as channel models, the
  firmware's actions and guards, and the metrics.
"""

from petriflow.agents.bus.addressing import auto_address
from petriflow.agents.bus.algorithms import ALGORITHMS, BusAwareScheme, NativeScheme
from petriflow.agents.bus.cpg import CpgChain, CpgParameters, phase_error
from petriflow.agents.bus.errors import AddressingError, BusError, FrameError
from petriflow.agents.bus.channel import BusView
from petriflow.agents.bus.buffer import BusMedium
from petriflow.agents.bus.parameters import CanBus, SerialBus, ZigbeeBus
from petriflow.agents.bus.records import Frame, Loss
from petriflow.agents.bus.simulator import BusSimulator

__all__ = [
    "ALGORITHMS",
    "AddressingError",
    "BusAwareScheme",
    "BusError",
    "BusMedium",
    "BusSimulator",
    "BusView",
    "CanBus",
    "CpgChain",
    "CpgParameters",
    "Frame",
    "FrameError",
    "Loss",
    "NativeScheme",
    "SerialBus",
    "ZigbeeBus",
    "auto_address",
    "phase_error",
]
