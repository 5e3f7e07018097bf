"""Fixtures for the legged-robot tests: small worlds with Robot4L and Robot3L, and a
one-transition net to fire an action with its parameters."""

from __future__ import annotations

import pytest

pytest.importorskip("pybullet")

from petriflow.io.yaml import loads_net

ROBOT4L = "petriflow.agents.legged:robots/robot4l.urdf"
ROBOT3L = "petriflow.agents.legged:robots/robot3l.urdf"
#: dt of the test worlds: 250 Hz keeps the legs' contacts stable (pybullet's default is 240 Hz).
DT = 0.004


@pytest.fixture
def net_for():
    """``net_for(action, params)``: a net whose only transition ``t`` runs ``action`` with
    ``params`` (a YAML flow mapping), putting a token in ``b`` when it succeeds and in
    ``failed`` when it fails."""

    def build(action: str, params: str):
        return loads_net(f"""
petriflow: 1
places: [{{id: a, tokens: 1}}, b, failed]
transitions: [{{id: t, action: {action}, params: {params}, in: [a], out: [b], outcomes: {{failed: [failed]}}}}]
""")

    return build


@pytest.fixture
def world_of():
    """Build worlds from robot entries (closed after the test): ``world_of(dog=(x, y), cat=(x, y))``
    puts a Robot4L named ``dog`` and a Robot3L named ``cat`` at those points."""
    from petriflow.world import World

    made = []

    def build(dog=None, cat=None, **extra):
        robots = []
        if dog is not None:
            robots.append({"id": "dog", "urdf": ROBOT4L, "position": list(dog), "z": 0.14, "colour": "red"})
        if cat is not None:
            robots.append({"id": "cat", "urdf": ROBOT3L, "position": list(cat), "z": 0.08, "colour": "yellow"})
        world = World({"dt": DT, "robots": robots, **extra})
        made.append(world)
        return world

    yield build
    for world in made:
        world.close()
