"""Fleet calibration: the same fit as wmrkit.odometry.calibrate, intervals that cover the truth, the weight hook."""

from __future__ import annotations

import numpy as np
import pytest
from batch_params import PARAMS, TRUE_P

from wmrkit.batch.calibrate import default_parameters, fleet_calibrate, load_runs
from wmrkit.batch.engine import BatchError
from wmrkit.batch.fleet import expand_logs
from wmrkit.odometry.calibration import apply_parameters, calibrate
from wmrkit.odometry.synthetic import simulate, square_path


@pytest.fixture(scope="module")
def runs(diff, calibration_data):
    return load_runs(diff, expand_logs([calibration_data / "*.csv"]), reference_dir=calibration_data / "ref")


def test_estimate_equals_the_serial_calibration(diff, runs):
    fleet = fleet_calibrate(diff, runs, PARAMS)
    serial = calibrate(diff, runs, PARAMS)
    for (name, nominal, value), (name2, nominal2, value2, lo, hi) in zip(serial.values, fleet.values, strict=True):
        assert (name, nominal) == (name2, nominal2)
        assert value2 == pytest.approx(value, rel=1e-9)
        assert lo < value2 < hi
    assert fleet.rms_after == pytest.approx(serial.rms_after, rel=1e-9)


def test_intervals_cover_the_truth_and_the_naive_one_would_not(diff, runs):
    true = apply_parameters(diff, PARAMS, TRUE_P)
    jac = fleet_calibrate(diff, runs, PARAMS, ci="jacobian")
    boot = fleet_calibrate(diff, runs, PARAMS, ci="bootstrap", n_boot=40)
    for name in ("left.r", "right.r", "left.l"):
        wheel, _, fld = name.partition(".")
        truth = getattr(true.wheel(wheel), fld)
        for res in (jac, boot):
            _, lo, hi = res.value(name)
            assert lo <= truth <= hi, (res.ci, name, lo, truth, hi)
        width_j, width_b = np.diff(jac.value(name)[1:])[0], np.diff(boot.value(name)[1:])[0]
        assert 0.2 < width_j / width_b < 5  # two independent interval methods agree in size
    # the i.i.d. formula s^2 (J^T J)^-1 ignores that errors accumulate along a run: far narrower than either
    k = 2  # the track parameter
    lo, hi = jac.interval[k]
    naive = _naive_half_width(diff, runs)
    assert naive[k] < 0.25 * (hi - lo) / 2


def _naive_half_width(diff, runs):
    from scipy.optimize import least_squares

    from wmrkit.batch.calibrate import _Task, run_residuals

    task = _Task(diff, tuple(PARAMS), tuple(runs), "exact", 1.0, None, None, None)
    fit = least_squares(lambda p: run_residuals(task, p), np.zeros(3), method="lm")
    s2 = fit.fun @ fit.fun / (fit.fun.size - 3)
    return 1.96 * np.sqrt(np.diag(s2 * np.linalg.inv(fit.jac.T @ fit.jac)))


def test_run_weights_hook(diff, runs):
    base = fleet_calibrate(diff, runs, PARAMS)
    scaled = fleet_calibrate(diff, runs, PARAMS, run_weights=lambda run: np.full(len(run.samples()), 3.0))
    np.testing.assert_allclose(scaled.estimate, base.estimate, rtol=1e-7)  # a common weight changes nothing
    first = runs[0]
    dropped = fleet_calibrate(diff, runs, PARAMS, run_weights=lambda run: np.full(len(run.samples()),
                                                                                 0.0 if run is first else 1.0))
    without = calibrate(diff, runs[1:], PARAMS)
    np.testing.assert_allclose([v for _, _, v, _, _ in dropped.values], [v for _, _, v in without.values], rtol=1e-8)


def test_closed_paths_fit_the_radius_ratio(diff, tmp_path):
    params = default_parameters(diff, closed=True)
    assert params == [("left.r", "-right.r"), ("left.l", "right.l")]
    true = apply_parameters(diff, params, [0.01, 0.03])
    from batch_params import write_log

    paths = [write_log(tmp_path / f"sq{i}.csv", simulate(true, square_path(1.5, clockwise=i % 2 == 1), 10.0,
                                                          spin_noise_per_rad=1e-6, seed=i)) for i in range(4)]
    runs = load_runs(diff, paths, closed=True)
    res = fleet_calibrate(diff, runs, params)
    lo, hi = res.interval[0]
    assert lo <= 0.01 <= hi and abs(res.estimate[0] - 0.01) < 1e-3
    serial = calibrate(diff, runs, params)
    np.testing.assert_allclose([v for _, _, v, _, _ in res.values], [v for _, _, v in serial.values], rtol=1e-9)


def test_errors(diff, runs, calibration_data, tmp_path):
    with pytest.raises(BatchError, match="no runs"):
        fleet_calibrate(diff, [], PARAMS)
    with pytest.raises(BatchError, match="jacobian"):
        fleet_calibrate(diff, runs, PARAMS, ci="magic")
    with pytest.raises(BatchError, match="one of the two"):
        load_runs(diff, [str(calibration_data / "c0.csv")])
    with pytest.raises(BatchError, match="no reference"):
        load_runs(diff, [str(calibration_data / "c0.csv")], reference_dir=tmp_path)
    with pytest.raises(BatchError, match="at least two runs"):
        fleet_calibrate(diff, runs[:1], PARAMS)
