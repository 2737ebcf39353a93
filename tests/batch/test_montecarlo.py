"""Monte Carlo against the analytic propagation of paper 003: agreement for the random walk, the known
over-estimate for quantisation, slip outside the model, and the ellipse geometry."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wmrkit.batch.engine import BatchError
from wmrkit.batch.montecarlo import ellipse, monte_carlo, path_log, plot_monte_carlo

RUNS = 400
#: Relative standard error of a sample variance of RUNS Gaussian draws is sqrt(2 / RUNS); allow 3 of them.
TOL = 3 * math.sqrt(2 / RUNS)


@pytest.fixture(scope="module")
def square(diff):
    return path_log(diff, "square", 5.0)


def test_random_walk_matches_the_analytic_covariance(diff, square):
    res = monte_carlo(diff, square, RUNS, per_rad=1e-4, seed=1)
    ratio = np.diag(res.covariance) / np.diag(res.analytic)
    assert np.all(np.abs(ratio - 1) < TOL), ratio
    corr = lambda c: c[0, 1] / math.sqrt(c[0, 0] * c[1, 1])  # noqa: E731
    assert abs(corr(res.covariance) - corr(res.analytic)) < 0.2
    np.testing.assert_allclose(res.mean[:2], res.nominal[:2], atol=4 * math.sqrt(res.analytic[0, 0] / RUNS))


@pytest.mark.parametrize("name", ["swerve-4"])
def test_random_walk_matches_the_analytic_covariance_with_sensed_steering(name):
    """Robots whose sensed steering moves: the steering angles are the configuration on both sides. The Monte
    Carlo runs used to random-walk them too, and their spread came out 5-12 times the analytic one."""
    from wmrkit import catalog

    robot = catalog.load(name)
    res = monte_carlo(robot, path_log(robot, "square", 5.0), RUNS, per_rad=1e-4, seed=3)
    ratio = np.diag(res.covariance) / np.diag(res.analytic)
    assert np.all(np.abs(ratio - 1) < TOL), ratio


def test_quantisation_is_over_estimated_and_slip_is_outside_the_model(diff, square):
    res = 2 * math.pi / 256
    quant = monte_carlo(diff, square, RUNS, per_rad=0.0, resolution=res, seed=2)
    # quantisation errors of consecutive increments cancel: the empirical spread is far below the per-sample model
    assert np.all(np.diag(quant.covariance) < 0.5 * np.diag(quant.analytic))
    base = monte_carlo(diff, square, RUNS, per_rad=1e-5, seed=3)
    slip = monte_carlo(diff, square, RUNS, per_rad=1e-5, slip_std=0.01, seed=3)
    np.testing.assert_array_equal(slip.analytic, base.analytic)
    assert slip.covariance[2, 2] > 3 * base.covariance[2, 2]


def test_deterministic_for_a_seed_and_errors(diff, square):
    a = monte_carlo(diff, square, 50, seed=5, block=16)
    b = monte_carlo(diff, square, 50, seed=5, block=16)
    np.testing.assert_array_equal(a.poses, b.poses)
    assert not np.array_equal(a.poses, monte_carlo(diff, square, 50, seed=6, block=16).poses)
    with pytest.raises(BatchError, match="at least 2"):
        monte_carlo(diff, square, 1)
    with pytest.raises(BatchError, match="unknown path"):
        path_log(diff, "spiral")


def test_ellipse_points_are_at_the_chi_square_quantile():
    cov = np.array([[0.04, 0.01, 0.0], [0.01, 0.02, 0.0], [0.0, 0.0, 1.0]])
    pts = ellipse(cov, np.array([1.0, 2.0, 0.0]), level=0.9)
    d = pts - [1.0, 2.0]
    m = np.einsum("ni,ij,nj->n", d, np.linalg.inv(cov[:2, :2]), d)
    np.testing.assert_allclose(m, -2 * math.log(0.1), rtol=1e-12)


def test_plot(diff, square, tmp_path):
    res = monte_carlo(diff, square, 20, seed=0)
    plot_monte_carlo(res, tmp_path / "mc.png")
    assert (tmp_path / "mc.png").stat().st_size > 1000


def test_a_robot_that_senses_nothing_is_one_line_exit_2(tmp_path, capsys):
    """It ended in numpy's 'need at least one array to concatenate' (a traceback, exit 1)."""
    from wmrkit import Robot
    from wmrkit.cli.main import main
    from wmrkit.errors import WmrkitError

    robot = tmp_path / "blind.yaml"
    robot.write_text("name: blind\nwheels:\n"
                     "  - {name: l, type: fixed, position: [0, 0.2], heading: 0, r: 0.1, actuated: [spin]}\n"
                     "  - {name: r, type: fixed, position: [0, -0.2], heading: 0, r: 0.1, actuated: [spin]}\n")
    assert main(["batch", "montecarlo", str(robot), "--path", "arc", "-n", "5", "--workers", "0"]) == 2
    assert "the sensed joints of robot 'blind' (none) do not determine its motion" in capsys.readouterr().err
    with pytest.raises(WmrkitError, match="sensed: robot 'blind' senses no joint"):  # the synthetic log itself
        path_log(Robot.from_file(robot), "arc")


def test_run_and_block_counts_must_be_whole_numbers(diff):
    """block=0 raised range()'s ValueError, a negative block numpy's 'need at least one array to concatenate',
    and runs=2.5 a TypeError: none of them said which argument was wrong."""
    log = path_log(diff, "arc", 5.0)
    for block in (0, -3, 2.5, True):
        with pytest.raises(BatchError, match="block: expected a whole number of runs >= 1"):
            monte_carlo(diff, log, 10, block=block)
    with pytest.raises(BatchError, match="at least 2 runs and at most"):
        monte_carlo(diff, log, 2.5)
    assert monte_carlo(diff, log, np.int64(3), block=2).poses.shape == (3, 3)


def test_the_plot_draws_a_bounded_number_of_runs(tmp_path, monkeypatch):
    """Every run was a point: 10^6 runs (allowed) took 51 s to draw to PNG, 75 s and 149 MB to SVG, with
    matplotlib's warning that placing the legend is slow. The ellipses still use every run."""
    from matplotlib.axes import Axes

    from wmrkit.batch.montecarlo import MAX_POINTS_DRAWN, MonteCarloResult

    drawn = []
    scatter = Axes.scatter
    monkeypatch.setattr(Axes, "scatter", lambda self, x, y, **kw: drawn.append(len(x)) or scatter(self, x, y, **kw))
    poses = np.random.default_rng(0).normal(scale=0.04, size=(20_001, 3))
    cov = np.cov(poses, rowvar=False)
    plot_monte_carlo(MonteCarloResult("r", len(poses), 100, poses, np.zeros(3), cov, cov, 1e-4, 0.0, 0.0),
                     str(tmp_path / "mc.png"))
    assert drawn == [len(poses[::5])] and drawn[0] <= MAX_POINTS_DRAWN


@pytest.mark.parametrize("name", ["diff-drive", "swerve-4", "thesis-omni-castor", "agv-drive-unit"])
def test_final_poses_are_the_odometry_of_each_run(name):
    """The Monte Carlo runs are integrated by final_poses, one compiled pass per run: each final pose is that of
    odometry() over the run's log, bit for bit, for every scheme, on fixed, steered (the steering exact) and castor
    and double-wheel robots (the configuration perturbed: new maps every run)."""
    from wmrkit import catalog
    from wmrkit.odometry.integrators import METHODS
    from wmrkit.odometry.logs import JointLog
    from wmrkit.odometry.model import odometry_model
    from wmrkit.odometry.pipeline import final_poses, odometry

    robot = catalog.load(name)
    model = odometry_model(robot)
    log = path_log(robot, "square", 5.0).select(model.joints)
    rng = np.random.default_rng(7)
    runs = log.positions + np.cumsum(rng.normal(scale=1e-3, size=(3, *log.positions.shape)), axis=1)
    for method in METHODS:
        expected = [odometry(model, JointLog(log.time, log.joints, q), method=method).poses[-1] for q in runs]
        np.testing.assert_array_equal(final_poses(model, log, runs, method=method), expected)


def test_final_poses_refuse_a_bad_run_by_its_row():
    from wmrkit import catalog
    from wmrkit.odometry.logs import LogError
    from wmrkit.odometry.model import odometry_model
    from wmrkit.odometry.pipeline import final_poses

    for name in ("diff-drive", "swerve-4"):
        robot = catalog.load(name)
        model = odometry_model(robot)
        log = path_log(robot, "arc", 5.0).select(model.joints)
        runs = np.stack([log.positions] * 2)
        runs[1, 7, 0] = np.nan
        with pytest.raises(LogError, match=rf"\(run 1\): sample 7: {model.joints[0]}: value nan is not a finite"):
            final_poses(model, log, runs)
        with pytest.raises(LogError, match=r"positions: expected \(runs, 51, "):
            final_poses(model, log, runs[:, :-1])


def test_a_study_is_bounded_by_its_work_per_worker(monkeypatch):
    """1e6 runs of the diff-drive's square without workers (the documented bound on runs) did not answer within
    the option fuzzer's 200 s on a loaded machine (about 260 us a run): the bound counts each run's fixed cost and
    a castor robot's new configurations (14 ms a run of the square: 10^6 runs of it would have taken 4 hours), and
    grows with the workers."""
    from types import SimpleNamespace

    from wmrkit import catalog
    from wmrkit.batch.montecarlo import MAX_RUNS, MAX_WORK, RUN_COST, study_cost
    from wmrkit.odometry.model import odometry_model

    diff = catalog.load("diff-drive")
    square = path_log(diff, "square")
    one = len(square) * 5 + RUN_COST
    with pytest.raises(BatchError, match=rf"runs: at most {int(MAX_WORK // one)} runs of this log \(573 samples of 2 "
                                         r"joints\) on 1 worker, got 1000000: .*more workers \(--workers"):
        monte_carlo(diff, square, MAX_RUNS)
    castor = catalog.load("thesis-omni-castor")
    log = path_log(castor, "square")
    cost = study_cost(odometry_model(castor), log, 1)
    assert cost > 100 * one  # its new configurations each run
    for workers in (1, 2):
        with pytest.raises(BatchError, match=rf"at most {int(workers * MAX_WORK // cost)} runs .* on {workers} worker"):
            monte_carlo(castor, log, 10**4, runner=None if workers == 1 else SimpleNamespace(workers=workers,
                                                                                              mode="remote"))
    # --workers allows 4 a CPU: 8 embedded workers on 2 CPUs were granted 8 minutes of work, about 4 on the clock
    monkeypatch.setattr("os.cpu_count", lambda: 2)
    with pytest.raises(BatchError, match=rf"at most {int(2 * MAX_WORK // cost)} runs .* on 2 workers.* one a CPU"):
        monte_carlo(castor, log, 10**4, runner=SimpleNamespace(workers=8, mode="local"))
    swerve = catalog.load("swerve-4")
    assert study_cost(odometry_model(swerve), path_log(swerve, "square"), 1) < 3 * one


def test_a_log_with_an_external_heading_is_refused(diff, square):
    """The runs perturb the joints and integrate them without the log's external heading (IMU yaw), while the
    nominal pose and the analytic covariance used it: a yaw 5 % off the wheels' gave a nominal theta of 6.597 rad
    beside a Monte Carlo mean of 6.283 rad, exit 0. Refused by name, here and in final_poses."""
    from wmrkit.odometry.logs import JointLog, LogError
    from wmrkit.odometry.model import odometry_model
    from wmrkit.odometry.pipeline import final_poses, odometry

    yaw = 1.05 * odometry(diff, square).poses[:, 2]
    log = JointLog(square.time, square.joints, square.positions, yaw, "imu.csv")
    with pytest.raises(BatchError, match=r"imu\.csv: an external heading .* not sampled"):
        monte_carlo(diff, log, 10)
    with pytest.raises(LogError, match=r"imu\.csv: an external heading"):
        final_poses(odometry_model(diff), log, square.positions[None])


def test_the_work_bound_counts_a_steered_robots_run():
    """A run's fixed cost is not the same for every robot: about 20 us for a fixed configuration, about 100 us
    for a steered robot (its configuration maps looked up each run), 1.5-2.6 ms where the perturbed joints are
    the configuration (each run's new configurations are added to the maps the model keeps). Counted as 1000
    for all, short logs let one worker take 1e6 runs of swerve-4 (about 100 s) and 284,616 runs of
    thesis-omni-castor (about 10 min: 20,000 took 36 s) instead of the documented minute."""
    from wmrkit import catalog
    from wmrkit.batch.montecarlo import (
        CONFIGURATION_COST,
        CONFIGURATION_RUN_COST,
        MAX_RUNS,
        MAX_WORK,
        RUN_COST,
        STEERED_RUN_COST,
        study_cost,
    )
    from wmrkit.odometry.model import odometry_model

    assert RUN_COST < STEERED_RUN_COST < CONFIGURATION_RUN_COST
    for name, per_sample, per_run in (("diff-drive", 5, RUN_COST), ("swerve-4", 11, STEERED_RUN_COST),
                                      ("thesis-omni-castor", 9 + CONFIGURATION_COST, CONFIGURATION_RUN_COST)):
        robot = catalog.load(name)
        log = path_log(robot, "square", 0.05)  # 3 samples
        assert study_cost(odometry_model(robot), log, 7) == 7 * (3 * per_sample + per_run)
    swerve = catalog.load("swerve-4")
    with pytest.raises(BatchError, match=rf"at most {int(MAX_WORK // (33 + STEERED_RUN_COST))} runs of this log"):
        monte_carlo(swerve, path_log(swerve, "square", 0.05), MAX_RUNS)
    castor = catalog.load("thesis-omni-castor")
    with pytest.raises(BatchError, match=r"at most \d+ runs of this log \(3 samples of 6 joints\)"):
        monte_carlo(castor, path_log(castor, "square", 0.05), 10**5)


def test_a_log_of_one_sample_is_refused_by_name(diff, tmp_path, capsys):
    """A LOG of one sample has no motion to perturb: it was integrated, then every block failed with the kernel's
    'task 0 failed: positions: expected (runs, 1, 2) of a log of at least 2 samples, got (256, 1, 2)', naming
    neither the log nor the option."""
    import json

    from wmrkit.cli.main import main

    log = tmp_path / "one.csv"
    log.write_text("time,left.spin,right.spin\n0,0,0\n")
    assert main(["batch", "montecarlo", "diff-drive", str(log), "--workers", "0", "--json"]) == 2
    err = json.loads(capsys.readouterr().err)
    assert err["file"] == str(log) and "1 sample" in err["error"] and "at least 2" in err["error"]
    assert "task" not in err["error"]


def test_final_poses_take_positions_as_any_array_like(diff, square):
    """A list of runs (as JointLog takes its positions) raised AttributeError: 'list' object has no attribute
    'shape'; now read as floats, as odometry() reads the same numbers."""
    from wmrkit.odometry.model import odometry_model
    from wmrkit.odometry.pipeline import final_poses, odometry

    model = odometry_model(diff)
    got = final_poses(model, square, [square.positions.tolist()])
    np.testing.assert_array_equal(got, [odometry(model, square).poses[-1]])


@pytest.mark.parametrize("keyword", ["per_rad", "resolution", "slip_std"])
@pytest.mark.parametrize("value", ["1e-4", "2 deg", None, True])
def test_noise_keywords_must_be_numbers(diff, square, keyword, value):
    """Text or None raised TypeError ('<=' not supported between instances of 'int' and 'str') from the range
    check; True was read as 1."""
    with pytest.raises(BatchError, match=rf"{keyword}: expected a number .* got {value!r}"):
        monte_carlo(diff, square, 4, **{keyword: value})


@pytest.mark.parametrize(("option", "said"), [
    (["-n", "1"], "-n/--runs: a Monte Carlo study needs at least 2 runs and at most 1000000, got 1"),
    (["--noise", "2"], "--noise: noise must be in [0, 1] (per rad), got 2"),  # 'nan': not a number (the door's)
    (["--resolution", "4"], "--resolution: resolution must be in [0, pi] rad, got 4"),
    (["--slip", "2"], "--slip: expected a slip in [0, 1] (the standard deviation of a slip ratio), got 2"),
])
def test_the_cli_names_the_option_out_of_range_before_the_log_is_read(option, said, tmp_path, capsys):
    """'--noise nan' said 'noise must be in [0, 1] (per rad), resolution in [0, pi] rad and slip in [0, 1] ..., got
    nan, 0, 0' (three ranges, no option named) and '-n 1' 'Monte Carlo needs at least 2 runs' after reading the
    LOG; now the option, before (a LOG that does not exist is not reached)."""
    from wmrkit.cli.main import main

    assert main(["batch", "montecarlo", "diff-drive", str(tmp_path / "none.csv"), "--workers", "0", *option]) == 2
    assert capsys.readouterr().err == f"wmrkit: error: {said}\n"


def test_monte_carlo_names_the_argument_out_of_range(diff):
    log = path_log(diff, "arc", 5.0)
    for kwargs, said in (({"per_rad": -1.0}, "per_rad: noise must be in"), ({"slip_std": 1.5}, "slip_std: expected"),
                         ({"resolution": math.inf}, "resolution: resolution must be in")):
        with pytest.raises(BatchError, match=f"^{said}"):
            monte_carlo(diff, log, 4, **kwargs)
