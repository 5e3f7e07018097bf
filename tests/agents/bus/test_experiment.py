"""The 100-message experiment: determinism, bookkeeping and the trends the paper reports."""

from __future__ import annotations

import pytest
from petriflow.agents.bus.experiment import run_experiment
from petriflow.agents.bus.medium import CanBus, SerialBus


def test_same_seed_same_result_and_other_seed_differs():
    """Everything random is seeded: a run repeats exactly."""
    first = run_experiment("serial", 1, messages=20, seed=4)
    assert first == run_experiment("serial", 1, messages=20, seed=4)
    assert first != run_experiment("serial", 1, messages=20, seed=5)


def test_every_message_is_counted_received_or_lost_with_a_reason():
    """received + lost = sent for each module; lost ones carry a reason."""
    result = run_experiment("zigbee", 1, messages=30, seed=2)
    for module in result.modules:
        assert module.sent == 30
        assert module.received + module.lost == module.sent
        assert sum(module.reasons.values()) == module.lost


def test_large_receive_buffers_remove_the_loss_on_can():
    """On CAN nothing collides: with room in the buffers no message is lost."""
    result = run_experiment(CanBus(rx_buffer=1000), 1, messages=30, seed=1)
    assert result.lost == 0


@pytest.mark.parametrize("bus", ["serial", "can", "zigbee"])
def test_algorithm_two_loses_fewer_than_algorithm_one(bus):
    """The paper's main claim holds in the model on every bus (here for two seeds)."""
    for seed in (0, 1):
        native = run_experiment(bus, 1, messages=40, seed=seed)
        aware = run_experiment(bus, 2, messages=40, seed=seed)
        assert aware.lost_pct < native.lost_pct


def test_more_loss_means_worse_phase_locking():
    """A one-frame buffer that loses most of the chain's messages locks worse than a
    buffer that keeps them (algorithm 1, same seed, same sends)."""
    lossy = run_experiment(SerialBus(), 1, messages=60, seed=3)
    kept = run_experiment(SerialBus(rx_buffer=1000), 1, messages=60, seed=3)
    assert lossy.lost_pct > kept.lost_pct
    assert lossy.phase_error > kept.phase_error


def test_unknown_bus_algorithm_or_chain_are_refused():
    """Bad arguments fail early."""
    with pytest.raises(ValueError):
        run_experiment("token-ring")
    with pytest.raises(ValueError):
        run_experiment("can", 3)
    with pytest.raises(ValueError):
        run_experiment("can", modules=1)
