"""Asynchronous packet transmission on a modular robot bus (seed 002): buses, CPG, firmware, nets.

A chain of EMERGE modules runs a CPG and shares each module's phase with its
neighbours over one shared bus; messages collide, wait, or get overwritten in a
module's receive buffer, and lost messages degrade the chain's phase locking. The
core (frames to experiment) is pure Python and numpy; :mod:`.chain` adds the pybullet
robot and :mod:`.firmware` the actions its nets bind.

* :mod:`~petriflow.agents.bus.errors`: the package's errors.
* :mod:`~petriflow.agents.bus.frames`: frame lengths in bits (UART, CAN with bit
  stuffing on the real pattern, IEEE 802.15.4).
* :mod:`~petriflow.agents.bus.packet`: the CPG message and its bytes.
* :mod:`~petriflow.agents.bus.timeline`: the simulated clock everything shares.
* :mod:`~petriflow.agents.bus.radio`: RSSI and frame errors of the ZigBee radios.
* :mod:`~petriflow.agents.bus.medium`: the buses (RS-485, CAN, ZigBee) at bit-level
  timing, receive buffers and transmit queues; each bus is also a petriflow channel
  model (:mod:`~petriflow.agents.bus.channel` decides a message at send time).
* :mod:`~petriflow.agents.bus.cpg`: the phase oscillators and the phase-locking error.
* :mod:`~petriflow.agents.bus.algorithms`: the paper's algorithms 1 and 2.
* :mod:`~petriflow.agents.bus.addressing`: the chain's auto-addressing.
* :mod:`~petriflow.agents.bus.experiment`: the 100-message experiment and its table.
* :mod:`~petriflow.agents.bus.firmware`: a module's firmware as actions a net binds
  (boot, CPG step, Wait(Delay), send, the bus-available and overflow interrupts,
  reception).
* :mod:`~petriflow.agents.bus.nets`: the chain as a workflow net, algorithm 1 or 2.
* :mod:`~petriflow.agents.bus.chain`: the chain as a pybullet robot (hinges, front
  sensors).
* :mod:`~petriflow.agents.bus.metrics`: lost messages per module, phase error, speed.
* :mod:`~petriflow.agents.bus.figures`: lost messages beside Tables 1-3, CPG phases.
* :mod:`~petriflow.agents.bus.plugin`: registers the buses as channel models, the
  firmware's actions and guards, and the metrics.
"""

from petriflow.agents.bus.addressing import auto_address
from petriflow.agents.bus.algorithms import ALGORITHMS, BusAwareScheme, NativeScheme
from petriflow.agents.bus.cpg import CpgChain, CpgParameters, phase_error
from petriflow.agents.bus.errors import AddressingError, BusError, FrameError
from petriflow.agents.bus.experiment import ExperimentResult, format_table, run_experiment, run_grid
from petriflow.agents.bus.medium import BusSimulator, CanBus, Frame, Loss, SerialBus, ZigbeeBus

__all__ = [
    "ALGORITHMS",
    "AddressingError",
    "BusAwareScheme",
    "BusError",
    "BusSimulator",
    "CanBus",
    "CpgChain",
    "CpgParameters",
    "ExperimentResult",
    "Frame",
    "FrameError",
    "Loss",
    "NativeScheme",
    "SerialBus",
    "ZigbeeBus",
    "auto_address",
    "format_table",
    "phase_error",
    "run_experiment",
    "run_grid",
]
