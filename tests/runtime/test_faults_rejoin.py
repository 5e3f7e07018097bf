"""A lost agent's return starts only what the loss stopped."""

from petriflow.runtime.config import Fault
from petriflow.runtime.faults import Faults
from petriflow.runtime.kernel import Kernel
from petriflow.runtime.recorder import Recorder


def _faults(*faults):
    kernel, started = Kernel(dt=1.0), []
    return Faults(kernel, Recorder(kernel), list(faults), ["a", "b"], stopped=lambda agent: None,
                  started=started.append), started


def test_a_lost_agent_runs_again_when_back():
    faults, started = _faults()
    faults.lose("a", "silent")
    assert not faults.alive("a")
    faults.rejoin("a")
    assert faults.alive("a") and started == ["a"]


def test_a_killed_agent_stays_killed_when_its_remote_agent_is_lost_and_back():
    faults, started = _faults()
    faults.apply(Fault("kill", 1.0, "a"))
    faults.lose("a")
    faults.rejoin("a")
    assert not faults.alive("a") and started == []


def test_an_agent_killed_while_lost_stays_killed_when_back():
    faults, started = _faults()
    faults.lose("a")
    faults.apply(Fault("kill", 1.0, "a"))
    faults.rejoin("a")
    assert not faults.alive("a") and started == []


def test_an_agent_not_joined_yet_does_not_start_when_its_remote_agent_is_back():
    faults, started = _faults(Fault("join", 5.0, "b"))
    faults.lose("b")
    faults.rejoin("b")
    assert not faults.alive("b") and started == []
