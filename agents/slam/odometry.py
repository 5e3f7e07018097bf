"""The RA's dead reckoning: wheels with systematic errors, encoders, a compass, UMBmark.

**Systematic errors** (§3.1): the wheels' rims differ and the encoders count whole
pulses. :class:`Wheels` is a pair of wheel radii and a wheelbase; the RA's *true*
wheels come from its nominal ones by UMBmark's two error factors (Borenstein & Feng
1996, the paper's [25] applies them): ``Ed = D_R / D_L`` (unequal diameters, their mean
kept) and ``Eb = b_actual / b_nominal`` (the wheelbase). The RA *believes* either the
nominal wheels or the wheels UMBmark corrected. The motion is the kinematic model of
eq. (1): a displacement ``r`` along the heading and a rotation about the axle's centre
(:func:`petriflow.agents.mobile.kinematic.icc_step`), with the true wheels; the
estimate integrates the same model with the believed wheels and the pulses counted.

**UMBmark** (:func:`umbmark`): the robot drives a ``side`` x ``side`` square by its
odometry alone, once clockwise and once counter-clockwise, starting at the origin
heading +x; where it really ends is the return error of each run (no random error is
modelled, so one run of each stands for the centre of gravity of the paper's five). From their x errors
(``x_cw``, ``x_ccw``): ``alpha = (x_cw + x_ccw) / (-4 L)`` (the turns' error, a wheelbase
error), ``beta = (x_cw - x_ccw) / (-4 L)`` (the legs' curvature, unequal wheels),
``R = (L / 2) / sin(beta / 2)``, ``Ed = (R + b/2) / (R - b/2)``, ``Eb = (pi/2) / (pi/2 -
alpha)``; the corrected wheels are ``b' = Eb b``, ``D_L' = 2 / (Ed + 1) D``, ``D_R' = 2 /
(1 / Ed + 1) D`` (:func:`corrected`). The formulas are first order in the errors, so
:func:`calibrate` runs the test again with the corrected wheels and corrects once
more (two passes). The benchmark's measure is ``E_max`` = the larger
of the two runs' return errors, before and after the correction.

**Compass** (:class:`Compass`): the paper's bearings (0 west, 90 north, 180 east, 270
south: clockwise from west) at a resolution of ``resolution_deg``, and their cardinal
identifier (0-3).

Examples:
    >>> nominal = Wheels.nominal(0.025, 0.2)
    >>> true = nominal.with_errors(ed=1.003, eb=1.015)
    >>> result = umbmark(true, nominal, ppr=200)
    >>> round(result.e_max, 2), round(result.ed, 4), round(result.eb, 4)
    (0.98, 1.0027, 1.0113)
    >>> believed, passes = calibrate(true, nominal, ppr=200)      # two passes, then the benchmark
    >>> [round(p.e_max, 3) for p in passes]
    [0.977, 0.097, 0.032]
    >>> Compass().bearing(math.pi / 2), Compass().cardinal(math.pi / 2), Compass().cardinal(0.1)
    (90.0, 1, 2)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from petriflow.agents.mobile.kinematic import icc_step

__all__ = ["Compass", "Encoders", "UMBmarkResult", "Wheels", "calibrate", "corrected", "square_run", "umbmark"]


@dataclass(frozen=True)
class Wheels:
    """Wheel radii (m) and wheelbase (m) of a differential drive."""

    left: float
    right: float
    track: float

    @classmethod
    def nominal(cls, radius: float, track: float) -> "Wheels":
        return cls(radius, radius, track)

    def with_errors(self, ed: float, eb: float) -> "Wheels":
        """These (nominal) wheels with UMBmark's errors: diameters in the ratio ``ed``
        (right over left, their mean kept) and the wheelbase times ``eb``."""
        mean = (self.left + self.right) / 2
        return Wheels(mean * 2 / (ed + 1), mean * 2 * ed / (ed + 1), self.track * eb)

    def speeds(self, v: float, w: float) -> tuple[float, float]:
        """Wheel angular speeds (rad/s) for body speed ``v`` (m/s) and turn rate ``w``
        (rad/s), as these wheels believe."""
        half = self.track / 2
        return (v - w * half) / self.left, (v + w * half) / self.right


@dataclass
class Encoders:
    """Two wheel encoders of ``ppr`` pulses a turn: whole pulses counted."""

    ppr: int
    left: int = 0
    right: int = 0
    _left: float = 0.0
    _right: float = 0.0

    def advance(self, left_rad: float, right_rad: float) -> tuple[int, int]:
        """The wheels turned by these angles (rad): the new pulses of each."""
        self._left += left_rad * self.ppr / (2 * math.pi)
        self._right += right_rad * self.ppr / (2 * math.pi)
        new_left = math.floor(self._left) - self.left if self._left >= 0 else math.ceil(self._left) - self.left
        new_right = math.floor(self._right) - self.right if self._right >= 0 else math.ceil(self._right) - self.right
        self.left += new_left
        self.right += new_right
        return new_left, new_right

    def travel(self, pulses: tuple[int, int], wheels: Wheels) -> tuple[float, float]:
        """Metres each wheel travelled for ``pulses``, as ``wheels`` believes."""
        return (pulses[0] * 2 * math.pi * wheels.left / self.ppr, pulses[1] * 2 * math.pi * wheels.right / self.ppr)


@dataclass(frozen=True)
class Compass:
    """A digital compass read in the paper's bearings (see the module)."""

    resolution_deg: float = 1.0

    def bearing(self, yaw: float) -> float:
        """Degrees clockwise from west of a world yaw (rad, anticlockwise from east)."""
        degrees = (180.0 - math.degrees(yaw)) % 360.0
        if self.resolution_deg > 0:
            degrees = round(degrees / self.resolution_deg) * self.resolution_deg % 360.0
        return degrees

    def cardinal(self, yaw: float) -> int:
        """The cardinal identifier (0 west, 1 north, 2 east, 3 south) nearest the bearing."""
        return int(round(self.bearing(yaw) / 90.0)) % 4

    @staticmethod
    def yaw_of(cardinal: int) -> float:
        """World yaw (rad) of a cardinal identifier."""
        return math.radians(180.0 - 90.0 * cardinal)


def square_run(true: Wheels, believed: Wheels, ppr: int, side: float = 4.0, clockwise: bool = False,
               speed: float = 0.2, turn_rate: float = 1.0, dt: float = 0.02) -> tuple[float, float]:
    """Drive a ``side`` square by odometry alone from the origin heading +x (four legs,
    four 90-degree turns on the spot); the true position at the end (m), where the
    odometry says (0, 0)."""
    pose = (0.0, 0.0, 0.0)
    encoders = Encoders(ppr)
    sign = -1.0 if clockwise else 1.0
    for _ in range(4):
        for straight in (True, False):
            done = 0.0
            goal = side if straight else math.pi / 2
            while done < goal - 1e-12:
                # slow down near the goal, so the stop is decided by the pulses, not the time step
                rate = speed if straight else turn_rate
                rate = max(min(rate, (goal - done) / dt), rate * 0.02)
                v, w = (rate, 0.0) if straight else (0.0, sign * rate)
                wl, wr = believed.speeds(v, w)
                left, right = wl * dt, wr * dt
                pose = icc_step(pose, left * true.left, right * true.right, true.track, 1.0)
                dl, dr = encoders.travel(encoders.advance(left, right), believed)
                done += (dl + dr) / 2 if straight else sign * (dr - dl) / believed.track
    return pose[0], pose[1]


@dataclass(frozen=True)
class UMBmarkResult:
    """One UMBmark: the return errors (m) of the clockwise and counter-clockwise runs,
    ``e_max`` (the larger of the two), and the errors they imply."""

    x_cw: float
    y_cw: float
    x_ccw: float
    y_ccw: float
    e_max: float
    alpha: float
    beta: float
    ed: float
    eb: float

    def report(self) -> dict[str, float]:
        return {k: round(getattr(self, k), 6) for k in ("x_cw", "y_cw", "x_ccw", "y_ccw", "e_max", "alpha", "beta",
                                                          "ed", "eb")}


def umbmark(true: Wheels, believed: Wheels, ppr: int, side: float = 4.0, **run) -> UMBmarkResult:
    """The bidirectional square test and the errors it implies (see the module)."""
    x_cw, y_cw = square_run(true, believed, ppr, side, clockwise=True, **run)
    x_ccw, y_ccw = square_run(true, believed, ppr, side, clockwise=False, **run)
    alpha = (x_cw + x_ccw) / (-4.0 * side)
    beta = (x_cw - x_ccw) / (-4.0 * side)
    b = believed.track
    if abs(beta) < 1e-12:
        ed = 1.0
    else:
        radius = (side / 2) / math.sin(beta / 2)
        ed = (radius + b / 2) / (radius - b / 2)
    eb = (math.pi / 2) / (math.pi / 2 - alpha)
    e_max = max(math.hypot(x_cw, y_cw), math.hypot(x_ccw, y_ccw))
    return UMBmarkResult(x_cw, y_cw, x_ccw, y_ccw, e_max, alpha, beta, ed, eb)


def corrected(believed: Wheels, result: UMBmarkResult) -> Wheels:
    """The wheels to believe after UMBmark found ``result`` with ``believed``."""
    mean = (believed.left + believed.right) / 2
    ratio = believed.right / believed.left * result.ed
    return Wheels(mean * 2 / (ratio + 1), mean * 2 / (1 / ratio + 1), believed.track * result.eb)


def calibrate(true: Wheels, believed: Wheels, ppr: int, passes: int = 2, **run) -> tuple[Wheels, list[UMBmarkResult]]:
    """UMBmark ``passes`` times, each correcting the wheels the last one found (the
    correction is first order in the errors, so a second pass takes the rest): the
    wheels to believe and each pass's result, then the final benchmark."""
    results = []
    for _ in range(passes):
        result = umbmark(true, believed, ppr, **run)
        results.append(result)
        believed = corrected(believed, result)
    results.append(umbmark(true, believed, ppr, **run))
    return believed, results
