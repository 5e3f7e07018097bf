"""Getting a fallen Robot4L back on its feet, and where a helper braces it.

Seed 003 (§5.2): "the quadruped robot fell down and the three-leg robot help him to
stand up ... it uses the three-leg robot for leaning on". This module holds the
geometry and the joint-space motion; :mod:`petriflow.agents.legged.actions` runs them
as the ``gait.brace`` (helper) and ``gait.stand_up`` (fallen robot) actions.

* :func:`lying_on` tells how a body lies from its orientation: ``"upright"``, on its
  ``"left"`` or ``"right"`` side, or on its ``"back"``.
* :func:`righting_motion` is the stand-up sequence from a side: every joint to zero
  (legs straight under the hips, the posture in which a Robot4L rests on its side,
  held by its top plate's edge and its lower legs); the legs of the lower side swing
  their knees against their standing lean, so their feet press into the ground and
  roll the body over the lower legs onto its feet; those legs extend to finish the
  roll; then every leg takes the standing posture.
* :func:`brace_point` is where the helper stands: behind the fallen robot's back (its
  top plate, which faces sideways when it lies on a side), facing it, so the fallen
  robot cannot roll onto its back while it pushes (a robot on its back cannot right
  itself: its legs point up and do not reach the ground).

Examples:
    >>> import numpy as np
    >>> on_left = np.array([[1, 0, 0], [0, 0, 1], [0, -1, 0]])   # body y axis points down
    >>> lying_on(np.eye(3)), lying_on(on_left), lying_on(np.diag([1, -1, -1]))
    ('upright', 'left', 'back')
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from petriflow.agents.legged.robots import RobotDesign

__all__ = ["BACK_TILT", "SWEEP", "UPRIGHT_TILT", "brace_point", "lying_on", "righting_motion"]

#: Knee sweep of the lower side's legs (rad), against their standing lean.
SWEEP = 1.0
#: Tilt (rad) under which a body counts as upright.
UPRIGHT_TILT = math.radians(35)
#: Tilt (rad) over which a body counts as lying on its back.
BACK_TILT = math.radians(135)


def lying_on(rotation: np.ndarray) -> str:
    """How a body with world rotation ``rotation`` (3×3, body to world) lies.

    Returns:
        ``"upright"`` (tilt under :data:`UPRIGHT_TILT`), ``"back"`` (over
        :data:`BACK_TILT`), otherwise the lower side, ``"left"`` or ``"right"``.
    """
    rotation = np.asarray(rotation, dtype=float)
    tilt = math.acos(max(-1.0, min(1.0, rotation[2, 2])))
    if tilt < UPRIGHT_TILT:
        return "upright"
    if tilt > BACK_TILT:
        return "back"
    return "left" if rotation[2, 1] < 0 else "right"


def _legs_on(design: RobotDesign, side: str) -> list[str]:
    """Legs whose hips are on ``side`` (``"left"``: y > 0)."""
    sign = 1 if side == "left" else -1
    return [leg.name for leg in design.legs if leg.hip[1] * sign > 0]


def righting_motion(design: RobotDesign, side: str) -> list[tuple[float, dict[str, tuple[float, float, float]]]]:
    """Joint targets, each reached by linear interpolation over its duration (s), that
    roll a robot lying on ``side`` onto its feet and stand it up.

    Examples:
        >>> from petriflow.agents.legged.robots import ROBOT4L
        >>> steps = righting_motion(ROBOT4L, "right")
        >>> [round(duration, 1) for duration, _ in steps]
        [0.5, 0.8, 0.8, 1.0, 1.0]
        >>> steps[1][1]["rf"], steps[1][1]["lf"]
        ((0.0, -1.0, 0.0), (0.0, 0.0, 0.0))
    """
    if side not in ("left", "right"):
        raise ValueError(f"a robot lying on its {side} is not righted by this motion")
    down = _legs_on(design, side)
    zero = {leg.name: (0.0, 0.0, 0.0) for leg in design.legs}
    sweep = dict(zero)
    for leg in design.legs:
        if leg.name in down:
            sweep[leg.name] = (0.0, -math.copysign(SWEEP, leg.nominal[1]), 0.0)
    push = {name: (q[0], q[1], design.leg(name).geometry.q3_range[1] if name in down else q[2])
            for name, q in sweep.items()}
    nominal = {leg.name: tuple(leg.nominal) for leg in design.legs}
    return [(0.5, zero), (0.8, sweep), (0.8, push), (1.0, zero), (1.0, nominal)]


def brace_point(position: Sequence[float], rotation: np.ndarray, gap: float) -> tuple[float, float, float]:
    """Where a helper stands to brace a fallen robot: ``(x, y, yaw)``, ``gap`` metres
    from the fallen body's origin in the direction its top faces (horizontally), the
    helper facing the fallen robot.

    Examples:
        >>> on_left = np.array([[1, 0, 0], [0, 0, 1], [0, -1, 0]])  # its top faces +y
        >>> [round(v, 3) + 0.0 for v in brace_point((1.0, 0.0, 0.13), on_left, 0.2)]
        [1.0, 0.2, -1.571]
    """
    top = np.asarray(rotation, dtype=float)[:, 2]
    horizontal = top[:2]
    norm = float(np.linalg.norm(horizontal))
    if norm < 1e-6:
        raise ValueError("the body lies flat (upright or on its back): no side to brace")
    direction = horizontal / norm
    x = float(position[0] + gap * direction[0])
    y = float(position[1] + gap * direction[1])
    return (x, y, math.atan2(-direction[1], -direction[0]))
