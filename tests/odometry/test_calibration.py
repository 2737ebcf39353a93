"""Calibration: known radius and track errors recovered from synthetic runs (closed squares, reference paths)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit import catalog
from wmrkit.errors import UnknownNameError, WmrkitError
from wmrkit.odometry.calibration import (
    CalibrationProblem,
    CalibrationRun,
    apply_parameters,
    calibrate,
    solve,
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


def _closed_squares(robot, side=1.5, rate=10.0, pause=0.0, first_clockwise=False, cut=0):
    """The two benchmark runs as `wmrkit batch calibrate --closed` sees them: the reference is the start pose;
    `cut` last samples dropped (a log that stops before the square ends)."""
    logs = [simulate(robot, square_path(side, clockwise=cw, pause=pause), rate).log
            for cw in (first_clockwise, not first_clockwise)]
    return [CalibrationRun.closed_path(log.slice(0, len(log) - cut)) for log in logs]


def test_a_closed_square_cut_short_biases_the_track_and_is_flagged():
    """The reported defect: zero noise, +3 % track fitted as +2.74 %. Cause: the data, not the solver. A 1.5 m
    square at 0.5 m/s and 0.5 rad/s lasts 24.566 s; sampled at 10 Hz its log ends at 24.5 s, 0.033 rad before
    the last turn ends, so the closure the fit assumes is false. The same runs fitted to the pose they really end
    at, or squares that end at rest (a pause after each turn), give the truth."""
    nominal = catalog.load("diff-drive")
    true = apply_parameters(nominal, RATIO_TRACK, [0.01, 0.03])
    short = _closed_squares(true, cut=1)
    truths = [simulate(true, square_path(1.5, clockwise=cw), 10.0).truth[-2] for cw in (False, True)]
    assert all(abs(t[2] - math.copysign(2 * math.pi, t[2])) > 0.03 for t in truths)  # not back at the start
    biased = calibrate(nominal, short, RATIO_TRACK)
    assert biased.value("left.l") / 0.2 - 1 == pytest.approx(0.0274, abs=2e-4)
    assert biased.rms_after > 1e-3 and len(biased.warnings) == 2 and "ends while the wheels still turn" in \
        biased.warnings[0]
    true_ends = calibrate(nominal, [CalibrationRun(r.log, t[None]) for r, t in zip(short, truths, strict=True)],
                          RATIO_TRACK)
    # 1e-6, not round-off: here a turn ends inside a sample interval and the next straight begins there, which one
    # arc per sample cannot reproduce exactly (discretisation of odometry, not calibration; the squares at rest
    # below have no such sample)
    assert true_ends.value("left.l") == pytest.approx(0.2 * 1.03, rel=1e-6) and not true_ends.warnings
    at_rest = calibrate(nominal, _closed_squares(true, pause=0.5), RATIO_TRACK)
    assert at_rest.value("left.l") == pytest.approx(0.2 * 1.03, rel=1e-9) and not at_rest.warnings


@settings(max_examples=36, deadline=None)
@given(ratio=st.floats(-0.02, 0.02), track=st.floats(-0.05, 0.05), side=st.sampled_from([1.0, 1.5, 2.5]),
       first_clockwise=st.booleans())
def test_zero_noise_closed_squares_recover_the_truth(ratio, track, side, first_clockwise):
    """Any radius ratio and track error, either direction first, any side: the exact solve recovers them from
    the return poses of closed squares (assumed to end at the start) to round-off."""
    nominal = catalog.load("diff-drive")
    true = apply_parameters(nominal, RATIO_TRACK, [ratio, track])
    fit = calibrate(nominal, _closed_squares(true, side=side, pause=0.3, first_clockwise=first_clockwise),
                    RATIO_TRACK)
    assert fit.success and fit.rms_after < 1e-10 and not fit.warnings
    for name, _, value in fit.values:
        wheel, field = name.split(".")
        assert value == pytest.approx(getattr(true.wheel(wheel), field), rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("clockwise", [False, True])
def test_one_direction_alone_does_not_determine_ratio_and_track(clockwise):
    """Why the benchmark drives both ways: around one square the radius ratio and the track move the return pose
    along the same direction (Jacobian of rank 1 at the truth), the two directions together separate them."""
    nominal = catalog.load("diff-drive")
    p = [0.01, 0.03]
    runs = _closed_squares(apply_parameters(nominal, RATIO_TRACK, p), pause=0.3, first_clockwise=clockwise)
    one = np.linalg.svd(CalibrationProblem(nominal, tuple(RATIO_TRACK), (runs[0],)).jacobian(p), compute_uv=False)
    both = np.linalg.svd(CalibrationProblem(nominal, tuple(RATIO_TRACK), tuple(runs)).jacobian(p), compute_uv=False)
    assert one[1] < 1e-6 * one[0]
    assert both[1] > 0.1 * both[0]


@pytest.mark.parametrize("noise", [0.0, 1e-5])
@pytest.mark.parametrize("clockwise", [False, True])
def test_equal_closed_squares_all_turning_one_way_are_refused(clockwise, noise):
    """The audit's case: three counter-clockwise squares gave left.r = -0.026 m and a 1.5 m track, no warning
    (with noise the fit slides along the valley until a radius crosses zero; without, it stops anywhere on it)."""
    nominal = catalog.load("diff-drive")
    true = apply_parameters(nominal, RATIO_TRACK, [0.01, 0.03])
    runs = [CalibrationRun.closed_path(simulate(true, square_path(1.5, clockwise=clockwise, pause=0.3), 10.0,
                                                spin_noise_per_rad=noise, seed=i).log) for i in range(3)]
    way = "clockwise" if clockwise else "counter-clockwise"
    with pytest.raises(WmrkitError, match=f"cannot tell these parameters apart: .*the 3 closed runs all turn {way}"):
        calibrate(nominal, runs, RATIO_TRACK)


def test_one_log_and_a_fleet_refuse_undetermined_runs_alike():
    """The refusal was written twice (odometry.calibrate and batch's fleet_calibrate): one text now, an
    UndeterminedError either way (the fleet's also a BatchError), which the CLI places at --param or the logs."""
    from wmrkit.batch.calibrate import fleet_calibrate
    from wmrkit.batch.engine import BatchError
    from wmrkit.odometry.calibration import UndeterminedError

    nominal = catalog.load("diff-drive")
    true = apply_parameters(nominal, RATIO_TRACK, [0.01, 0.03])
    runs = [CalibrationRun.closed_path(simulate(true, square_path(1.5, pause=0.3), 10.0, spin_noise_per_rad=1e-5,
                                                seed=i).log) for i in range(3)]
    with pytest.raises(UndeterminedError) as one:
        calibrate(nominal, runs, RATIO_TRACK)
    with pytest.raises(UndeterminedError) as fleet:
        fleet_calibrate(nominal, runs, RATIO_TRACK)
    assert isinstance(fleet.value, BatchError) and str(fleet.value) == str(one.value)
    assert str(one.value).startswith("calibrate: the runs cannot tell these parameters apart: ")


def test_closed_squares_of_different_sizes_turning_one_way_are_accepted():
    """Not a turning-direction rule: the heading drift of unequal radii grows with the side and the turn error of
    the track does not, so one-way squares of several sizes determine both (a decision on the data, not the
    shape)."""
    nominal = catalog.load("diff-drive")
    true = apply_parameters(nominal, RATIO_TRACK, [0.01, 0.03])
    runs = [CalibrationRun.closed_path(simulate(true, square_path(1.0 + 0.2 * i, pause=0.5), 10.0,
                                                spin_noise_per_rad=1e-5, seed=i).log) for i in range(5)]
    fit = calibrate(nominal, runs, RATIO_TRACK)
    assert fit.value("left.r") / 0.075 - 1 == pytest.approx(0.01, abs=1e-3)
    assert fit.value("left.l") / 0.2 - 1 == pytest.approx(0.03, abs=2e-3)


def test_undetermined_is_decided_on_relative_changes_of_the_fitted_values():
    """The scales make a unit step a relative change of the fitted value (the smaller of 1 +- p for a ratio); a
    length through zero, a direction the runs do not see and one the residuals leave loose are each named."""
    nominal = catalog.load("diff-drive")
    params = (*RATIO_TRACK, "left.alpha")
    runs = _closed_squares(apply_parameters(nominal, RATIO_TRACK, [0.01, 0.03]), pause=0.3)
    both = CalibrationProblem(nominal, tuple(RATIO_TRACK), tuple(runs))
    np.testing.assert_allclose(CalibrationProblem(nominal, params, tuple(runs)).scales([0.5, -0.2, 3.0]),
                               [0.5, 0.8, 1.0])
    p = np.array([0.01, 0.03])
    jac, r = both.jacobian(p), both.residuals(p)
    assert both.undetermined(p, jac, r) is None
    assert "left.r = -0.0075 m" in both.undetermined([-1.1, 0.03], jac, r)
    one = both.with_runs(runs[:1])
    assert one.undetermined(p, one.jacobian(p), one.residuals(p)).startswith("they do not move the poses along")
    loose = both.undetermined(p, jac, r + 2.0)  # closure errors of 2 m: the weaker direction is known to +-20 %
    assert "a standard error of" in loose and "(at most 10%)" in loose


def test_problem_residuals_and_solver_are_what_calibrate_uses():
    """The shared pieces (also used by the fleet fit): residuals are zero at the true parameters, and the solver
    from the nominal robot lands there."""
    nominal = catalog.load("diff-drive")
    true_p = [0.004, -0.02]
    runs = _closed_squares(apply_parameters(nominal, RATIO_TRACK, true_p), pause=0.3)
    problem = CalibrationProblem(nominal, tuple(RATIO_TRACK), tuple(runs))
    assert problem.sizes() == [3, 3]
    assert np.max(np.abs(problem.residuals(true_p))) < 1e-12
    assert np.max(np.abs(problem.residuals([0.0, 0.0]))) > 1e-2
    np.testing.assert_allclose(solve(problem.residuals, 2).x, true_p, rtol=1e-9)
    np.testing.assert_allclose([v for _, _, v in calibrate(nominal, runs, RATIO_TRACK).values],
                               [v for _, _, v in problem.values(true_p)], rtol=1e-9)
    doubled = calibrate(nominal, runs, RATIO_TRACK, run_weights=lambda run: np.full(len(run.samples()), 2.0))
    assert doubled.rms_before == pytest.approx(2 * calibrate(nominal, runs, RATIO_TRACK).rms_before)


def test_problem_jacobian_is_the_derivative_and_splits_by_run():
    """Forward differences against central ones with a larger step; the rows of each run do not depend on the
    other runs (what lets the fleet differentiate its runs on separate workers)."""
    nominal = catalog.load("diff-drive")
    params = ("left.r", "right.r", ("left.l", "right.l"))
    true = apply_parameters(nominal, params, [0.01, -0.005, 0.02])
    sims = [simulate(true, TwistProfile.from_segments([(3.0, 0.4, 0.0, w), (2.0, 0.3, 0.0, -w)]), 10.0)
            for w in (0.3, -0.5, 0.7)]
    problem = CalibrationProblem(nominal, params, tuple(CalibrationRun(s.log, s.truth) for s in sims))
    p = np.array([0.003, 0.001, -0.01])
    jac = problem.jacobian(p)
    h = 1e-6
    central = np.column_stack([(problem.residuals(p + h * e) - problem.residuals(p - h * e)) / (2 * h)
                               for e in np.eye(3)])
    np.testing.assert_allclose(jac, central, atol=1e-6 * np.abs(central).max())
    rows = np.split(jac, np.cumsum(problem.sizes())[:-1])
    for k, run in enumerate(problem.runs):
        np.testing.assert_array_equal(problem.with_runs([run]).jacobian(p), rows[k])


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
    assert square_path_error([0.3, 0.4], [0.0, 0.1]) == pytest.approx(0.5)  # one run each
    for bad in ([], [[np.nan, 0.0]], [[1.0, 2.0, 3.0]], [[1.0, 2.0, 3.0, 4.0]]):  # NaN, NaN, ValueError, two runs
        with pytest.raises(WmrkitError, match=r"errors_cw: expected the finite return-position errors \(n, 2\)"):
            square_path_error(bad, ccw)


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


def test_references_samples_and_heading_weight_that_cannot_be_are_refused_by_name():
    """A NaN reference or heading weight reached the solver ("Residuals are not finite in the initial point"),
    an `at` past the log an IndexError, too few `at` a broadcasting error, and negative `at` counted from the end."""
    robot = catalog.load("diff-drive")
    run = simulate(robot, square_path(1.0), 10.0)
    bad = run.truth.copy()
    bad[5, 0] = np.nan
    with pytest.raises(WmrkitError, match=r"CalibrationRun\.reference: expected finite poses .* NaN or infinite"):
        CalibrationRun(run.log, bad)
    with pytest.raises(WmrkitError, match=r"CalibrationRun\.reference: expected finite poses \(M, 3\), got shape"):
        CalibrationRun(run.log, run.truth[:, :2])
    three = run.truth[-3:]
    for at in ([10**6, 1, 2], [-1, -2, -3], [1, 2], [0.5, 1.5, 2.5]):
        with pytest.raises(WmrkitError, match=r"CalibrationRun\.at: expected 3 sample indices"):
            CalibrationRun(run.log, three, np.array(at))
    good = CalibrationRun(run.log, run.truth)
    for weight in (float("nan"), -1.0):
        with pytest.raises(WmrkitError, match="heading_weight must be finite and >= 0"):
            calibrate(robot, [good], ["left.r"], heading_weight=weight)
    with pytest.raises(WmrkitError, match=r"sensed: expected a sequence of 'wheel.joint' names, got the string"):
        calibrate(robot, [good], ["left.r"], sensed="left.spin")  # not the letters l, e, f, t, ...


def test_calibration_section_of_the_odometry_page_runs():
    """The Python example of docs/odometry.md's calibration section prints what its comments say."""
    import contextlib
    import io
    import re
    from pathlib import Path

    page = (Path(__file__).resolve().parents[2] / "docs" / "odometry.md").read_text()
    section = page[page.index("## Calibration\n"):]
    section = section[:section.index("\n## ", 1)]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) == 1
    expected = [m.strip() for m in re.findall(r"print\(.*\)\s+#\s*(.*)$", blocks[0], flags=re.M)]
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(blocks[0], "docs/odometry.md", "exec"), {})  # our own documentation, not user text
    assert out.getvalue().splitlines() == expected
