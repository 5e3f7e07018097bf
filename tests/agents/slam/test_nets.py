"""Seed 001's nets: sound workflow nets for the shipped sizes and others, the shipped files
are the builder's, every name a net uses is registered and checked when it loads."""

from __future__ import annotations

import pytest

from petriflow import examples
from petriflow.agents.slam.actions import addressed
from petriflow.agents.slam.agent import Robot
from petriflow.agents.slam.nets import build
from petriflow.analysis.report import check_net
from petriflow.errors import NetFormatError
from petriflow.io import load_net
from petriflow.io.yaml import loads_net
from petriflow.runtime.binding import bind
from petriflow.runtime.registry import default_registry


@pytest.mark.parametrize("mode", ["decentralised", "centralised"])
def test_the_shipped_nets_are_sound_workflow_nets(mode):
    result = check_net(load_net(examples.path("slam", f"slam-{mode}.yaml")))
    assert result["workflow_net"] and result["sound"], result["violations"]
    assert result["complete"] and result["states"] < 100_000


@pytest.mark.parametrize("kwargs", [dict(was=3, reserves=2), dict(robots=3, reserves=0, was=2),
                                    dict(mode="centralised", robots=2, reserves=1)])
def test_other_teams_are_sound_too(kwargs):
    result = check_net(build(**kwargs))
    assert result["workflow_net"] and result["sound"], result["violations"]


@pytest.mark.parametrize("mode", ["decentralised", "centralised"])
def test_the_shipped_nets_are_the_builders(mode):
    built = build(mode)
    built.run = "run.yaml"
    shipped = load_net(examples.path("slam", f"slam-{mode}.yaml"))
    assert shipped.structure() == built.structure()


def test_the_installed_was_grow_the_state_space_linearly():
    """Installing in order keeps the installed WAs a prefix: the markings grow with the
    number of WAs, not with their subsets."""
    states = [check_net(build(was=n))["states"] for n in (2, 4, 8)]
    assert states[2] - states[1] < 3 * (states[1] - states[0]) + 2000


def test_the_registered_names():
    assert default_registry.state_type("slam.robot") is Robot
    assert default_registry.guard_reads("slam.has_frame") == ("outbox",)
    assert default_registry.guard_reads("slam.addressed") is None   # a guard over the frame itself
    binding = bind(load_net(examples.path("slam", "slam-decentralised.yaml")))
    assert binding.transitions["ra1_install_1"].reads == ("install",)


def test_a_misspelt_place_in_a_parameter_fails_when_the_net_loads():
    with open(examples.path("slam", "slam-decentralised.yaml"), encoding="utf-8") as handle:
        text = handle.read()
    assert "'on': wa_r1_1_on" in text
    broken = loads_net(text.replace("'on': wa_r1_1_on", "'on': wa_r1_1_onn", 1))
    with pytest.raises(NetFormatError, match="wa_r1_1_onn"):
        bind(broken)


def test_the_frame_guard_takes_addressed_frames_and_notices_of_own_losses():
    mine = {"from": "wa_r1_1", "to": "ra1", "kind": "data"}
    params = {"air": "air", "me": "ra1"}
    assert addressed({"air": [mine]}, params)
    assert not addressed({"air": [mine]}, {"air": "air", "me": "ra2"})
    notice = {"lost": True, "why": "faded", "data": {"from": "ra1", "to": "wa_r1_2"}}
    assert addressed({"air": [notice]}, params) and not addressed({"air": [notice]}, {"air": "air", "me": "wa_r1_2"})
