"""The CPG chain: locking with perfect communication, and what stale information does."""

from __future__ import annotations

import math

import numpy as np
import pytest
from petriflow.agents.bus.cpg import CpgChain, CpgParameters, motor_angle, phase_error, wrap


def test_chain_locks_to_the_lag_without_loss():
    """Knowing the neighbours' current phases, three modules settle one lag apart."""
    for start in ([0.0, 0.0, 0.0], [5.0, 1.0, 3.0], [0.1, 4.0, 2.2]):
        chain = CpgChain(3, phases=start)
        chain.listen_continuously = True
        assert phase_error(chain.phases, chain.parameters.lag) > 0.05 or start == [0.0, 0.0, 0.0]
        chain.advance(40.0)
        assert phase_error(chain.phases, chain.parameters.lag) < 1e-6
        assert wrap(chain.phases[0] - chain.phases[1]) == pytest.approx(2 * math.pi / 3, abs=1e-5)


def test_locked_chain_turns_at_the_intrinsic_rate():
    """Locked, every coupling term vanishes: each phase advances at w = 0.5 rad/s."""
    chain = CpgChain(3, phases=[4.0, 4.0 - 2 * math.pi / 3, 4.0 - 4 * math.pi / 3])
    chain.listen_continuously = True
    before = chain.phases.copy()
    chain.advance(2.0)
    assert np.allclose(chain.phases - before, 1.0)


def test_module_that_heard_nothing_runs_free():
    """No message read: no coupling, phase grows at w."""
    chain = CpgChain(3, phases=[0.0, 1.0, 2.0])
    chain.advance(3.0)
    assert np.allclose(chain.phases, [1.5, 2.5, 3.5])


def test_stale_phase_pulls_a_module_to_stall_ahead_of_it():
    """Chasing a phase that never updates, a module settles asin(w / wij) ahead of its
    target and stops (w < wij)."""
    chain = CpgChain(2, phases=[0.0, 0.0])
    chain.hear(1, 0, 0.0)  # module 1 heard module 0 once, at phase 0
    chain.advance(60.0)
    target = 0.0 - chain.parameters.lag  # module 1 should trail module 0 by the lag
    assert wrap(chain.phases[1] - target) == pytest.approx(math.asin(0.5 / 0.8), abs=1e-4)


def test_extrapolation_follows_a_silent_neighbour():
    """With dead reckoning one message keeps module 1 locked to a free-running module 0."""
    chain = CpgChain(2, CpgParameters(extrapolate=True), phases=[0.0, 0.0])
    chain.hear(1, 0, 0.0)  # module 0 runs free; module 1 dead-reckons its phase exactly
    chain.advance(60.0)
    assert phase_error(chain.phases, chain.parameters.lag) < 1e-3


def test_only_neighbours_are_heard():
    """A message from a module two places away does not couple."""
    chain = CpgChain(3)
    chain.hear(0, 2, 1.0)
    chain.hear(0, 1, 1.0)
    assert not chain.knows(0, 2) and chain.knows(0, 1)


def test_phase_error_and_motor_angle():
    """The metric is 0 at the lag, up to π; θ = x + r cos φ."""
    assert phase_error([0.0, -1.0, -2.0], 1.0) == pytest.approx(0.0)
    assert phase_error([0.0, -1.0 - math.pi], 1.0) == pytest.approx(math.pi)
    assert motor_angle(0.2, 0.5, math.pi) == pytest.approx(-0.3)
    assert np.allclose(CpgChain(2, CpgParameters(offset=0.1, amplitude=0.5)).angles(), [0.6, 0.6])


def test_wrong_number_of_phases_is_refused():
    """n modules need n initial phases."""
    with pytest.raises(ValueError):
        CpgChain(3, phases=[0.0])
