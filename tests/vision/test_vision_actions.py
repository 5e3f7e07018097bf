"""vision.capture and vision.locate as actions: registry, conformance, firing in a net."""

from __future__ import annotations

import math

import numpy as np
import pytest

from petriflow.io.yaml import loads_net
from petriflow.runtime.registry import Registry, default_registry
from petriflow.runtime.scheduler import Scheduler
from petriflow.testing import check_action, fire_one
from petriflow.vision import plugin
from petriflow.vision.capture import Capture
from petriflow.vision.markers import ROBOT_COLOURS
from petriflow.vision.pipeline import Locate, Scene
from petriflow.world import Camera

NET = """
petriflow: 1
net: see
places: [{id: standby, tokens: 1}, captured, identified, lost]
transitions:
  - {id: capture, action: vision.capture, params: {camera: top}, in: [standby], out: [captured],
     outcomes: {failed: [lost]}}
  - {id: locate, action: vision.locate, params: {require: [red, blue, yellow, green]},
     in: [captured], out: [identified], outcomes: {failed: [lost]}}
final: {identified: 1}
"""


@pytest.fixture
def renders(monkeypatch):
    """Counts Camera.capture calls (renders)."""
    calls = []
    original = Camera.capture

    def counting(self):
        calls.append((self.id, self.width, self.height))
        return original(self)

    monkeypatch.setattr(Camera, "capture", counting)
    return calls


def test_plugin_registers_lazy_targets():
    registry = Registry(load_plugins=False)
    plugin.register(registry)
    assert [n for n in registry.names() if not n.startswith("core.")] == ["vision.capture", "vision.locate"]
    assert registry.resolve("vision.capture") is Capture
    assert registry.resolve("vision.locate") is Locate


def test_entry_point_finds_the_actions():
    """The installed package's petriflow.actions entry point reaches the run registry."""
    assert default_registry.resolve("vision.capture") is Capture
    assert default_registry.resolve("vision.locate") is Locate


def test_actions_pass_the_conformance_check(marker_scene):
    assert check_action(Capture, world=marker_scene.world) == []
    assert check_action(Capture, {"width": 64, "height": 48}, world=marker_scene.world) == []
    assert check_action(Locate, world=marker_scene.world) == []   # no frame: ends failed, cleanly
    assert check_action(Capture) == []                               # no world: ends failed, cleanly


def test_capture_renders_only_when_fired(marker_scene, renders):
    net = loads_net(NET)
    scheduler = Scheduler(net, world=marker_scene.world)
    assert renders == []                       # binding and set-up render nothing
    fired = fire_one(net, "capture", world=marker_scene.world)
    assert renders == [("top", 320, 240)]
    assert fired.outcome == "ok"
    assert scheduler.running() == []


def test_fire_capture_gives_a_frame_token(marker_scene):
    fired = fire_one(loads_net(NET), "capture", world=marker_scene.world)
    assert fired.outcome == "ok"
    assert fired.marking == {"captured": 1}
    frame = fired.tokens["captured"][0]
    assert isinstance(frame, np.ndarray) and frame.shape == (240, 320, 3) and frame.dtype == np.uint8


def test_capture_at_another_size(marker_scene):
    net = loads_net(NET.replace("params: {camera: top}", "params: {camera: top, width: 160, height: 120}"))
    fired = fire_one(net, "capture", world=marker_scene.world)
    assert fired.tokens["captured"][0].shape == (120, 160, 3)


def test_fire_locate_on_a_frame_token(marker_scene):
    """locate on the token a real capture made: a Scene with the four robots in metres."""
    frame = marker_scene.capture()
    fired = fire_one(loads_net(NET), "locate", tokens={"captured": [frame]}, world=marker_scene.world)
    assert fired.outcome == "ok", fired.reason
    assert fired.marking == {"identified": 1}
    scene = fired.tokens["identified"][0]
    assert isinstance(scene, Scene)
    assert set(scene.robots) == set(ROBOT_COLOURS)
    for colour, (x, y, _) in marker_scene.truth.items():
        px, py = scene.robots[colour].position
        assert math.hypot(px - x, py - y) < 0.02
    assert fired.result == scene.to_token()              # events carry the summary


def test_locate_fails_when_a_required_robot_is_missing(marker_scene):
    frame = np.full((240, 320, 3), 239, np.uint8)
    fired = fire_one(loads_net(NET), "locate", tokens={"captured": [frame]}, world=marker_scene.world)
    assert fired.outcome == "failed" and fired.marking == {"lost": 1}
    assert "not found: red, blue, yellow, green" in fired.reason


def test_capture_with_an_unknown_camera_fails(marker_scene):
    net = loads_net(NET.replace("params: {camera: top}", "params: {camera: side}"))
    fired = fire_one(net, "capture", world=marker_scene.world)
    assert fired.outcome == "failed" and "side" in fired.reason


def test_whole_net_passes_the_camera_with_the_frame_token(marker_scene, renders):
    """capture then locate in one run: one render; the frame token knows its camera,
    so locate measures in metres with nothing shared beside the net."""
    net = loads_net(NET.replace("params: {camera: top}", "params: {camera: top, width: 640, height: 480}")
                    .replace("params: {require", "params: {camera: null, require"))
    scheduler = Scheduler(net, world=marker_scene.world, seed=1)
    events = []
    scheduler.on_event(events.append)
    result = scheduler.run()
    assert result.reason == "final"
    assert len(renders) == 1
    scene = result.tokens["identified"][0]
    assert scene.size == (640, 480) and scene.camera is not None and scene.camera.width == 640
    for colour, (x, y, _) in marker_scene.truth.items():
        px, py = scene.robots[colour].position
        assert math.hypot(px - x, py - y) < 0.01
    ends = {e.transition: e for e in events if e.kind == "end"}
    assert ends["locate"].data["outcome"] == "ok"
