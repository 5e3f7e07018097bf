"""Every net shipped in nets/ loads, plays and converts (a conformance check per file)."""

import pytest

from petriflow.engine import Simulation
from petriflow.io import load_net
from petriflow.io.yaml import dumps_net, loads_net
from tests.conftest import NETS, net_files

NET_FILES = net_files()


def test_nets_folder_is_not_empty():
    """The project ships example nets."""
    assert NET_FILES


@pytest.mark.parametrize("path", NET_FILES, ids=lambda p: str(p.relative_to(NETS)))
def test_shipped_net_loads_plays_and_round_trips(path):
    """Each shipped net loads, fires 100 random steps and survives a YAML round trip."""
    net = load_net(path)
    assert net.places and net.transitions
    sim = Simulation(net, seed=0)
    sim.run(until=100)
    assert sim.fired > 0
    assert loads_net(dumps_net(net)).structure() == net.structure()


@pytest.mark.parametrize("path", NET_FILES, ids=lambda p: str(p.relative_to(NETS)))
def test_shipped_net_binds_every_action(path):
    """Every action and guard a shipped net names is registered, with valid parameters."""
    from petriflow.runtime.binding import bind

    net = load_net(path)
    bound = bind(net, path=str(path))
    assert set(bound.actions()) == set(net.actions())
