"""FK1/FK2 across gaps in time: the random walk's Q per nominal sample period, ``n Q`` over a step of n periods
(docs/errata.md, a wmrkit extension). Expected values from the wheels' travel, computed here from the speeds."""

from __future__ import annotations

import json

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.errors import WmrkitError
from wmrkit.odometry.log_writer import write_log
from wmrkit.odometry.logs import JointLog
from wmrkit.slip.estimators import estimator
from wmrkit.slip.kalman import KalmanNoise, fk2_noise, kalman_filter, kalman_model, kalman_odometry, nominal_period

R = 0.23  # the forklift's wheel radius [m]
JOINTS = ("right_drive.spin", "left_drive.spin", "steer.steer")


def straight(steps, speeds) -> JointLog:
    """The forklift driving straight ahead, both drive wheels at `speeds` [m/s] over the `steps` [s]."""
    steps, speeds = np.asarray(steps, dtype=float), np.asarray(speeds, dtype=float)
    time = np.concatenate([[0.0], np.cumsum(steps)])
    spin = np.concatenate([[0.0], np.cumsum(speeds * steps / R)])
    return JointLog(time, JOINTS, np.column_stack([spin, spin, np.full_like(time, np.pi / 2)]))


def pause_log() -> tuple[JointLog, float]:
    """100 Hz at 1.8 m/s for 5 s, a 10 s step in which the wheels did not turn, 1.8 m/s for 5 s; the travel [m]."""
    steps = np.r_[np.full(500, 0.01), 10.0, np.full(500, 0.01)]
    speeds = np.r_[np.full(500, 1.8), 0.0, np.full(500, 1.8)]
    return straight(steps, speeds), 1.8 * 10.0


@pytest.mark.parametrize("kind", ["fk2", "fk1"])
def test_a_pause_in_which_the_wheels_did_not_turn_adds_no_travel(kind, tmp_path, capsys):
    """docs/slip.md's example: Q was per sample, so the filters carried the 1.8 m/s from before the pause across its
    10 s and fk2 ended 4.8 m beyond the wheels' 18 m; Q over the pause is now 1000 periods' worth, the pause's
    measurement takes over and the filters end within 5 mm of the wheels (default noise, as the CLI's)."""
    log, travel = pause_log()
    fork = catalog.load("forklift")
    end = kalman_odometry(kalman_model(fork, kind), log).poses[-1]
    np.testing.assert_allclose(end, [travel, 0.0, 0.0], rtol=0, atol=5e-3)
    path = tmp_path / "pause.csv"
    write_log(path, log, fork)
    assert main(["odometry", "forklift", str(path), "--method", kind, "--json"]) == 0
    np.testing.assert_allclose(json.loads(capsys.readouterr().out)["final_pose"], end, rtol=0, atol=1e-9)


def test_a_slower_log_after_a_faster_one_follows_the_wheels():
    """100 Hz at 1.8 m/s, then 10 Hz, the wheels at 0.9 m/s from the first 10 Hz sample on: each 0.1 s step adds
    10 periods' Q, so the twist takes the new speed within 0.3 s (three samples: 0.03 m/s off; 0.28 with Q per
    sample) and the log ends within 5 cm of the wheels' travel (18 cm beyond with Q per sample)."""
    steps = np.r_[np.full(500, 0.01), np.full(10, 0.1)]
    speeds = np.r_[np.full(500, 1.8), np.full(10, 0.9)]
    model = kalman_model(catalog.load("forklift"), "fk2", fk2_noise(0.28, 3.57, 0.28))  # the thesis's FK2
    run = kalman_filter(model, straight(steps, speeds))
    assert run.period == pytest.approx(0.01)
    assert abs(run.twist[502, 0] - 0.9) < 0.05
    poses = kalman_odometry(model, straight(steps, speeds)).poses
    assert abs(poses[-1, 0] - speeds @ steps) < 0.05


def gappy_log(n: int = 1600) -> JointLog:
    """Speeds varying at 100 Hz, the first intervals 0.1 s and gaps of 0.02 to 3 s between (their ratios to the
    period not whole numbers), steering changing too."""
    rng = np.random.default_rng(7)
    steps = np.full(n, 0.01)
    steps[:4] = 0.1  # the first chunks of a stream see 0.1 s intervals only
    steps[rng.choice(np.arange(10, n), 40, replace=False)] = rng.uniform(0.02, 3.0, 40)
    speeds = 1.5 + 0.3 * np.sin(np.cumsum(steps))
    log = straight(steps, speeds)
    log.positions[:, 1] *= 1.0 + 0.05 * np.sin(log.time / 3.0)  # the left wheel slower or faster: turning
    log.positions[:, 2] += np.radians(1.4118) * np.round(10 * np.sin(log.time / 4.0))
    return log


@pytest.mark.parametrize("kind", ["fk2", "fk1"])
def test_results_with_gaps_do_not_depend_on_where_the_log_is_cut(kind):
    """The nominal period comes from the log's first 1000 intervals: the stream reads them ahead across its chunks
    (cut after three samples, the first sees 0.1 s intervals only) and the API's pieces are given it, with the twist
    and covariance each ends on: both give the whole log's numbers."""
    model = kalman_model(catalog.load("forklift"), kind, KalmanNoise(1.0, 0.3, 0.2))
    log = gappy_log()
    assert nominal_period(log.time) == pytest.approx(0.01)
    whole = kalman_filter(model, log)
    x, p, period, increments = None, None, nominal_period(log.time), []
    for a, b in ((0, 3), (2, 700), (699, len(log))):  # each piece starts at the sample the one before ended on
        run = kalman_filter(model, log.slice(a, b), x0=x, p0=p, period=period)
        x, p, period = run.twist[-1], run.covariance, run.period
        increments.append(run.increments)
    np.testing.assert_array_equal(np.concatenate(increments), whole.increments)
    poses = kalman_odometry(model, log).poses
    est = estimator(model.odometry.robot, kind, noise=KalmanNoise(1.0, 0.3, 0.2))
    for size in (3, 37, len(log)):
        parts = []
        est.run([log.slice(i, i + size) for i in range(0, len(log), size)], sinks=[parts.append])
        np.testing.assert_allclose(np.vstack([t.poses for t in parts]), poses, rtol=0, atol=1e-9)


@pytest.mark.parametrize("period", [0.0, -0.01, float("nan"), float("inf"), "0.01"])
def test_a_period_that_is_not_a_positive_duration_is_refused(period):
    with pytest.raises(WmrkitError, match="period: the nominal sample period must be"):
        kalman_filter(kalman_model(catalog.load("forklift")), pause_log()[0], period=period)
