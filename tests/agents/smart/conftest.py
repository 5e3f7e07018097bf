"""Fixtures of the SMART tests: the scenario's nets and its arena (a real pybullet world,
rendered at 320 x 240 to keep the tests fast)."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("pybullet")
pytest.importorskip("cv2")

from petriflow.io import load_net

SMART = Path(__file__).resolve().parents[3] / "nets" / "smart"
#: Height of Robot3L's marker discs (vision.locate's marker_z in smart.yaml).
MARKER_Z = 0.113


@pytest.fixture(scope="module")
def net():
    """The corrected helping net, nets/smart/smart.yaml."""
    return load_net(SMART / "smart.yaml")


@pytest.fixture
def arena():
    """``arena(settle=0.5, **changes)``: the SMART world, dressed (white floor, marker
    hats), camera at 320 x 240, stepped ``settle`` seconds so the fallen Robot4L lies
    still; closed after the test. ``changes`` replace top-level keys of the world file."""
    import yaml
    from petriflow.agents.smart.arena import dress

    from petriflow.world import World

    made = []

    def build(settle: float = 0.5, camera=(320, 240), robots=None):
        data = yaml.safe_load((SMART / "world.yaml").read_text(encoding="utf-8"))
        if camera is not None:
            data["cameras"][0].update(width=camera[0], height=camera[1])
        if robots is not None:
            data["robots"] = robots(data["robots"])
        world = World(data, base=SMART, path=str(SMART / "world.yaml"))
        made.append(world)
        dress(world)
        for _ in range(int(round(settle / world.dt))):
            world.step()
        return world

    yield build
    for world in made:
        world.close()


def scene_of(world):
    """Capture a frame and process it as T2 + T3 do (a Scene in world metres)."""
    from petriflow.vision.pipeline import VisionConfig, process

    camera = world.camera("top")
    return process(camera.capture(), camera, VisionConfig(marker_z=MARKER_Z))


def place(world, name: str, x: float, y: float, yaw: float, settle: float = 0.3) -> None:
    """Test set-up: put a standing robot at ``(x, y, yaw)`` (its hat follows), then let
    it settle."""
    from petriflow.agents.smart.arena import dress

    p = world.p
    body = world.body(name)
    position, _ = p.getBasePositionAndOrientation(body, physicsClientId=world.client)
    p.resetBasePositionAndOrientation(body, [x, y, position[2]], p.getQuaternionFromEuler([0, 0, yaw]),
                                      physicsClientId=world.client)
    p.resetBaseVelocity(body, [0, 0, 0], [0, 0, 0], physicsClientId=world.client)
    dress(world).hats[name].sync()
    for _ in range(int(round(settle / world.dt))):
        world.step()
