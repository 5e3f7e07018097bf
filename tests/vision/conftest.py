"""Rendered marker scenes shared by the vision tests (rendering costs ~0.1-0.3 s a frame)."""

from __future__ import annotations

import random
from dataclasses import dataclass

import numpy as np
import pytest

from petriflow.vision.markers import MarkerScene


@dataclass
class Shot:
    """One rendered frame with the truth it was rendered from."""

    frame: np.ndarray
    truth: dict[str, tuple[float, float, float]]
    obstacles: int
    camera: object


def _shots(width: int, height: int, count: int, seed: int,
           obstacles: int = 4) -> tuple[MarkerScene, list[Shot]]:
    scene = MarkerScene(width, height, obstacles=obstacles)
    rng = random.Random(seed)
    shots = []
    for _ in range(count):
        truth = scene.randomize(rng)
        shots.append(Shot(scene.capture(), truth, obstacles, scene.camera))
    return scene, shots


@pytest.fixture(scope="session")
def shots640():
    """Five random 640 x 480 scenes (seeded): four robots, four obstacles each."""
    scene, shots = _shots(640, 480, 5, seed=11)
    yield shots
    scene.close()


@pytest.fixture(scope="session")
def shots320():
    """Five random 320 x 240 scenes (seeded)."""
    scene, shots = _shots(320, 240, 5, seed=12)
    yield shots
    scene.close()


@pytest.fixture(scope="session")
def marker_scene():
    """A live 320 x 240 marker scene (for actions that render); robots at random, seeded."""
    scene = MarkerScene(320, 240, obstacles=3)
    scene.randomize(random.Random(13))
    yield scene
    scene.close()
