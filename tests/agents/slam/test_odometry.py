"""The RA's dead reckoning: systematic errors, encoders, the compass, UMBmark's correction."""

from __future__ import annotations

import math

import pytest

from petriflow.agents.slam.odometry import Compass, Encoders, Wheels, calibrate, corrected, square_run, umbmark

NOMINAL = Wheels.nominal(0.025, 0.2)


def test_systematic_errors_keep_the_mean_diameter():
    true = NOMINAL.with_errors(ed=1.01, eb=1.02)
    assert true.right / true.left == pytest.approx(1.01)
    assert (true.left + true.right) / 2 == pytest.approx(0.025)
    assert true.track == pytest.approx(0.204)


def test_encoders_count_whole_pulses_and_keep_the_remainder():
    encoders = Encoders(200)
    step = 2 * math.pi / 200 * 0.6   # 0.6 of a pulse
    counted = [encoders.advance(step, -step) for _ in range(5)]
    assert [c[0] for c in counted] == [0, 1, 0, 1, 1] and encoders.left == 3 and encoders.right == -3


def test_a_perfect_robot_returns_home():
    x, y = square_run(NOMINAL, NOMINAL, ppr=200)
    assert math.hypot(x, y) < 0.02


def test_umbmark_recovers_the_errors_and_the_correction_shrinks_the_return_error():
    """The bidirectional square finds Ed and Eb to a few parts in ten thousand; two passes
    of the correction cut the benchmark's E_max from about 1 m to a few centimetres."""
    true = NOMINAL.with_errors(ed=1.003, eb=1.015)
    first = umbmark(true, NOMINAL, ppr=200)
    assert first.ed == pytest.approx(1.003, abs=5e-4) and first.eb == pytest.approx(1.015, abs=6e-3)
    believed, passes = calibrate(true, NOMINAL, ppr=200)
    assert passes[0].e_max > 0.8 and passes[-1].e_max < 0.05
    assert believed.right / believed.left == pytest.approx(1.003, abs=2e-4)
    assert believed.track == pytest.approx(true.track, rel=3e-3)


def test_the_formulas_read_turns_and_curvature_apart():
    """A wheelbase error alone gives alpha (both runs err the same way in x); unequal wheels
    alone give beta (opposite ways)."""
    turns = umbmark(NOMINAL.with_errors(ed=1.0, eb=1.02), NOMINAL, ppr=2000)
    curve = umbmark(NOMINAL.with_errors(ed=1.003, eb=1.0), NOMINAL, ppr=2000)
    assert abs(turns.alpha) > 5 * abs(turns.beta) and turns.eb == pytest.approx(1.02, abs=1e-3)
    assert abs(curve.beta) > 5 * abs(curve.alpha) and curve.ed == pytest.approx(1.003, abs=2e-4)
    assert corrected(NOMINAL, curve).track == pytest.approx(NOMINAL.track * curve.eb)


def test_the_compass_reads_the_papers_bearings():
    """0 west, 90 north, 180 east, 270 south (clockwise from west), at 1 degree."""
    compass = Compass()
    assert [compass.bearing(math.radians(a)) for a in (180, 90, 0, -90)] == [0.0, 90.0, 180.0, 270.0]
    assert [compass.cardinal(math.radians(a)) for a in (178, 95, 10, -80)] == [0, 1, 2, 3]
    assert compass.bearing(math.radians(89.6)) == 90.0
    assert [round(math.degrees(Compass.yaw_of(c))) for c in range(4)] == [180, 90, 0, -90]
