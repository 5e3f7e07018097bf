"""A robot's own idea of where it is: the odometry error model of Stage 3.2 (seed 004).

Seed 004's robots are Pioneer 2DX robots in Player/Stage (Player-3.0.2 and Stage-3.2.2,
§4), and "each robot can localize itself based on data delivered by its odometry
sensors" (§4.1). Stage's position model (``libstage/model_position.cc``, documented
in its worldfile properties) has two localisation modes:

* ``gps``: the position device reports the true pose (Stage's ``pioneer.inc`` sets this
  for its Pioneer models);
* ``odom``: the pose is integrated from the commanded velocities, each axis off by a
  proportion drawn once, when the robot is made, uniformly in ``[-E/2, +E/2]``, with
  ``E`` the worldfile's ``odom_error [x y z theta]`` (default ``[0.03 0.03 0.00
  0.05]``). Every step of ``dt`` s at forward speed ``v`` and turn rate ``w``::

      theta += w dt (1 + e_theta)
      x     += v dt (1 + e_x) cos(theta)
      y     += v dt (1 + e_x) sin(theta)

  (a differential drive has no sideways speed, so ``e_y`` never acts). The estimate
  drifts from the truth for good: a robot 1.5 % slow in its odometry thinks it has
  driven 98.5 m after 100 m.

Stage 3.2's laser (``libstage/model_laser.cc``) has no noise model: a beam reads the
range of the first thing it hits (the ranges are exact here too); Stage's later ranger
model added one, after the version the paper used.

:class:`Odometry` is the robot's estimate; :func:`draw_errors` draws the proportions.

Examples:
    >>> odo = Odometry((0.0, 0.0, 0.0), errors=(0.01, 0.0, 0.0))
    >>> odo.integrate(1.0, 0.0, 10.0)
    >>> [round(v, 6) for v in odo.pose]
    [10.1, 0.0, 0.0]
    >>> exact = Odometry((1.0, 2.0, 0.5))
    >>> exact.integrate(0.4, 0.0, 2.5); [round(v, 6) for v in exact.pose]
    [1.877583, 2.479426, 0.5]
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass
from typing import Any, Sequence

from petriflow.agents.bidding.errors import BiddingError

__all__ = ["STAGE_ODOM_ERROR", "Odometry", "draw_errors"]

#: Stage 3.2's default ``odom_error`` for x, y and heading (its z term, 0, does not act
#: on a planar robot): the largest proportion of error in integrating each velocity.
STAGE_ODOM_ERROR = (0.03, 0.03, 0.05)


def draw_errors(limits: Sequence[float], rng: random.Random) -> tuple[float, float, float]:
    """The proportions ``(e_x, e_y, e_theta)``, each uniform in ``[-E/2, +E/2]`` (Stage).

    Examples:
        >>> errors = draw_errors((0.03, 0.03, 0.05), random.Random(1))
        >>> all(abs(e) <= limit / 2 for e, limit in zip(errors, (0.03, 0.03, 0.05)))
        True
        >>> draw_errors((0.0, 0.0, 0.0), random.Random(1))
        (0.0, 0.0, 0.0)
        >>> draw_errors((0.1, -1.0, 0.0), random.Random(1))
        Traceback (most recent call last):
        ...
        petriflow.agents.bidding.errors.BiddingError: odom_error is [x, y, heading], three finite numbers >= 0, got (0.1, -1.0, 0.0)
    """
    values = tuple(limits)
    if len(values) != 3 or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                                   and v >= 0 for v in values):
        raise BiddingError(f"odom_error is [x, y, heading], three finite numbers >= 0, got {limits!r}")
    return tuple(rng.uniform(-v / 2.0, v / 2.0) if v > 0 else 0.0 for v in values)  # type: ignore[return-value]


@dataclass
class Odometry:
    """A pose estimate integrated from velocities with Stage's error proportions.

    Attributes:
        pose: the estimate ``(x, y, heading)`` in the world frame (it starts at the true
            start pose: Table 2 gives the robots' starts in the global frame).
        errors: ``(e_x, e_y, e_theta)``, the proportions of :func:`draw_errors`.
    """

    pose: tuple[float, float, float]
    errors: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def integrate(self, v: float, w: float, dt: float) -> None:
        """``dt`` s at forward speed ``v`` (m/s) and turn rate ``w`` (rad/s), as Stage does."""
        x, y, a = self.pose
        ex, _, ea = self.errors
        a = a + w * dt * (1.0 + ea)
        a = math.atan2(math.sin(a), math.cos(a))
        d = v * dt * (1.0 + ex)
        self.pose = (x + d * math.cos(a), y + d * math.sin(a), a)

    def wheels(self, left: float, right: float, track: float, dt: float) -> None:
        """The same for wheel speeds ``left``, ``right`` (m/s) on a ``track`` m axle."""
        if not track > 0:
            raise BiddingError(f"the wheel track must be > 0 m, got {track!r}")
        self.integrate((left + right) / 2.0, (right - left) / track, dt)

    def to_dict(self) -> dict[str, Any]:
        return {"pose": [round(v, 4) for v in self.pose], "errors": [round(v, 6) for v in self.errors]}
