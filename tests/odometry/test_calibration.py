"""Calibration: known radius and track errors recovered from synthetic runs (closed squares, reference paths)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.errors import UnknownNameError, WmrkitError
from wmrkit.odometry.calibration import (
    CalibrationRun,
    apply_parameters,
    calibrate,
    square_path_error,
)
from wmrkit.odometry.pipeline import odometry
from wmrkit.odometry.synthetic import TwistProfile, simulate, square_path

RATIO_TRACK = [("left.r", "-right.r"), ("left.l", "right.l")]


def _squares(robot, side=3.0):
    return [simulate(robot, square_path(side, clockwise=cw, turn_rate=math.pi / 8, speed=0.75), 20.0)
            for cw in (False, True)]


@pytest.mark.parametrize("errors", [(0.01, 0.03), (-0.004, -0.02), (0.0, 0.05)])
def test_closed_squares_in_both_directions_recover_the_radius_ratio_and_track(errors):
    nominal = catalog.load("diff-drive")
    true = apply_parameters(nominal, RATIO_TRACK, errors)
    runs = [CalibrationRun(r.log, r.truth[-1:]) for r in _squares(true)]  # only the return poses are known
    fit = calibrate(nominal, runs, RATIO_TRACK)
    assert fit.success and fit.rms_after < 1e-9 < fit.rms_before
    for name, _, value in fit.values:
        wheel, field = name.split(".")
        assert value == pytest.approx(getattr(true.wheel(wheel), field), rel=1e-9)
    for run in _squares(true):  # and the calibrated odometry closes the squares
        assert np.hypot(*odometry(fit.robot, run.log).final_pose[:2]) < 1e-9


def test_squares_cannot_tell_the_scale():
    """A closed path returns to its start at any scale: the mean radius is not observable from return poses."""
    nominal = catalog.load("diff-drive")
    scaled = apply_parameters(nominal, [("left.r", "right.r", "left.l", "right.l")], [0.1])
    for run in _squares(nominal):
        np.testing.assert_allclose(odometry(scaled, run.log).final_pose, odometry(nominal, run.log).final_pose,
                                   atol=1e-9)


def test_a_reference_trajectory_recovers_both_radii_and_the_track():
    nominal = catalog.load("diff-drive")
    params = ["left.r", "right.r", ("left.l", "right.l")]
    true = apply_parameters(nominal, params, [0.012, -0.006, 0.025])
    profile = TwistProfile.from_segments([(4.0, 0.5, 0.0, 0.4), (4.0, 0.4, 0.0, -0.5)])
    run = simulate(true, profile, 20.0)
    fit = calibrate(nominal, [CalibrationRun(run.log, run.truth)], params)
    assert fit.value("left.r") == pytest.approx(true.wheel("left").r, rel=1e-8)
    assert fit.value("right.r") == pytest.approx(true.wheel("right").r, rel=1e-8)
    assert fit.value("left.l") == pytest.approx(true.wheel("left").l, rel=1e-8)


def test_any_geometric_parameter_forklift_wheelbase():
    """The forklift's steered-wheel distance (wheelbase) from a reference path with turns."""
    nominal = catalog.load("forklift")
    true = apply_parameters(nominal, ["steer.l"], [0.03])
    # arcs with the ICR on the drive axle (1 m behind the origin), steering while stopped in between
    profile = TwistProfile.from_segments([(3.0, 1.0, 0.25, 0.25), (1.0, 0, 0, 0), (3.0, 1.0, -0.3, -0.3)])
    run = simulate(true, profile, 20.0)
    every = np.arange(0, len(run.log), 5)
    fit = calibrate(nominal, [CalibrationRun(run.log, run.truth[every], at=every)], ["steer.l"])
    assert fit.value("steer.l") == pytest.approx(true.wheel("steer").l, rel=1e-9)


def test_angle_parameters_are_offsets():
    robot = catalog.load("diff-drive")
    moved = apply_parameters(robot, ["-left.beta", ("left.r",)], [0.01, 0.5])
    assert moved.wheel("left").beta == pytest.approx(robot.wheel("left").beta - 0.01)
    assert moved.wheel("left").r == pytest.approx(robot.wheel("left").r * 1.5)


def test_square_path_error_is_the_larger_centroid_distance():
    cw = [[0.1, 0.0], [0.3, 0.0]]  # centroid (0.2, 0)
    ccw = [[0.0, -0.3], [0.0, -0.1], [0.0, -0.2]]  # centroid (0, -0.2)... and 0.2 again
    assert square_path_error(cw, ccw) == pytest.approx(0.2)
    assert square_path_error([[0.3, 0.4]], [[0.0, 0.1]]) == pytest.approx(0.5)


def test_calibration_errors():
    robot = catalog.load("diff-drive")
    run = CalibrationRun(simulate(robot, square_path(1.0), 10.0).log, np.zeros((1, 3)))
    with pytest.raises(UnknownNameError, match="a fixed wheel has no field 'gamma'"):
        calibrate(robot, [run], ["left.gamma"])
    with pytest.raises(UnknownNameError, match="has no wheel 'lft'"):
        calibrate(robot, [run], ["lft.r"])
    with pytest.raises(WmrkitError, match="no parameters"):
        calibrate(robot, [run], [])
    with pytest.raises(WmrkitError, match="no runs"):
        calibrate(robot, [], ["left.r"])
    with pytest.raises(WmrkitError, match="3 residuals cannot fix 4 parameters"):
        calibrate(robot, [run], ["left.r", "right.r", "left.l", "right.l"])
    with pytest.raises(WmrkitError, match=r"parameter 'rear\.l': its nominal value is 0"):
        apply_parameters(catalog.load("bicycle"), ["rear.l"], [0.1])  # the rear wheel is at the origin
