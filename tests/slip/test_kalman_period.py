"""The nominal sample period T of FK1/FK2's process noise at every door: Python's ``period=`` (and
``KalmanNoise.period``), ``wmrkit odometry --kf-period TIME``, a description's ``odometry.noise.period``. A step of
``n = max(1, round(dt / T))`` periods adds ``n Q``; T defaults to the median of the log's first 1000 intervals."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from wmrkit import DescriptionError, catalog
from wmrkit.cli.main import main
from wmrkit.description import robot_from_text
from wmrkit.errors import ShapeError
from wmrkit.odometry.header import header_format
from wmrkit.odometry.integrators import integrate_increments
from wmrkit.odometry.log_writer import write_log
from wmrkit.odometry.logs import JointLog, load_csv
from wmrkit.slip.estimators import estimator
from wmrkit.slip.kalman import KalmanNoise, kalman_filter, kalman_model

R = 0.23  # the forklift's wheel radius [m]
JOINTS = ("right_drive.spin", "left_drive.spin", "steer.steer")


def turning_log(step: float, n: int) -> JointLog:
    """The forklift at `n` steps of `step` [s], its speed varying, the left wheel 3 % off what the steering says (so
    the rows disagree and Q matters), the steering turning slowly."""
    time = np.arange(n + 1) * step
    speed = 1.5 + 0.4 * np.sin(time)
    right = np.concatenate([[0.0], np.cumsum(speed[1:] * step / R)])
    steer = np.pi / 2 + 0.2 * np.sin(time / 2)
    return JointLog(time, JOINTS, np.column_stack([right, 1.03 * right, steer]))


@pytest.fixture(scope="module")
def log_file(tmp_path_factory):
    """A 100 Hz log of :func:`turning_log`, and the log as ``wmrkit odometry`` reads it back."""
    fork = catalog.load("forklift")
    path = tmp_path_factory.mktemp("period") / "run.csv"
    write_log(path, turning_log(0.01, 400), fork)
    joints = kalman_model(fork, "fk2").odometry.joints
    return path, load_csv(path, joints, header_format(path, fork.name, joints), robot=fork)


def _run(capsys, argv: list[str], code: int = 0) -> tuple[dict, list[str]]:
    assert main(argv) == code
    out, err = capsys.readouterr()
    return (json.loads(out) if code == 0 else json.loads(err)), err.splitlines()


def _python_pose(log: JointLog, **period) -> list[float]:
    """The final pose of the forklift's FK2 (unit noise, as the CLI's default) over `log`, integrated exactly."""
    run = kalman_filter(kalman_model(catalog.load("forklift"), "fk2"), log, **period)
    return integrate_increments(np.zeros(3), run.increments, "exact")[-1].tolist()


def test_the_option_is_python_s_period_bit_for_bit(capsys, log_file):
    """``--kf-period 2ms`` is ``period=0.002``: 5 periods of Q a 10 ms step, a different answer from the default;
    ``KalmanNoise(period=)`` is the same filter."""
    path, log = log_file
    given, said = _run(capsys, ["odometry", "forklift", str(path), "--method", "fk2", "--kf-period", "2ms", "--json"])
    assert given["final_pose"] == _python_pose(log, period=0.002)
    assert not [line for line in said if "nominal sample period" in line]
    default, _ = _run(capsys, ["odometry", "forklift", str(path), "--method", "fk2", "--json"])
    assert default["final_pose"] != given["final_pose"]
    noise = kalman_model(catalog.load("forklift"), "fk2", KalmanNoise(period=0.002))
    assert kalman_filter(noise, log).increments.tolist() == kalman_filter(
        kalman_model(catalog.load("forklift"), "fk2"), log, period=0.002).increments.tolist()
    in_seconds, _ = _run(capsys, ["odometry", "forklift", str(path), "--method", "fk2", "--kf-period", "0.002",
                                  "--json"])
    assert in_seconds["final_pose"] == given["final_pose"]


def test_the_default_is_the_median_of_the_log_s_first_intervals(capsys, log_file):
    """Without a period: T is the median of the first 1000 intervals (computed here), as before the option."""
    path, log = log_file
    median = float(np.median(np.diff(log.time)[:1000]))
    default, _ = _run(capsys, ["odometry", "forklift", str(path), "--method", "fk2", "--json"])
    named, _ = _run(capsys, ["odometry", "forklift", str(path), "--method", "fk2", "--kf-period", repr(median),
                             "--json"])
    assert default["final_pose"] == named["final_pose"] == _python_pose(log) == _python_pose(log, period=median)


def _described(tmp_path, period) -> str:
    data = yaml.safe_load(catalog.source_text("forklift"))
    data["odometry"] = {"noise": {"process": 1, "period": period}}
    path = tmp_path / "fork.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return str(path)


def test_the_description_field_is_the_option(capsys, log_file, tmp_path):
    """``odometry.noise.period: 2 ms`` runs as ``--kf-period 2ms``; the option overrides it; written back by
    ``Robot.to_dict`` in seconds and read again the same."""
    path, _ = log_file
    robot = _described(tmp_path, "2 ms")
    described, _ = _run(capsys, ["odometry", robot, str(path), "--method", "fk2", "--json"])
    option, _ = _run(capsys, ["odometry", "forklift", str(path), "--method", "fk2", "--kf-period", "2ms", "--json"])
    assert described["final_pose"] == option["final_pose"]
    overridden, _ = _run(capsys, ["odometry", robot, str(path), "--method", "fk2", "--kf-period", "5 ms", "--json"])
    five, _ = _run(capsys, ["odometry", "forklift", str(path), "--method", "fk2", "--kf-period", "5ms", "--json"])
    assert overridden["final_pose"] == five["final_pose"] != option["final_pose"]
    loaded = robot_from_text(open(robot).read(), source=robot)
    assert loaded.odometry.period == 0.002 and loaded.odometry.kalman_noise().period == 0.002
    assert loaded.to_dict()["odometry"]["noise"]["period"] == 0.002
    assert robot_from_text(json.dumps(loaded.to_dict()), source="back", fmt="json").odometry == loaded.odometry


@pytest.mark.parametrize(("value", "said"), [
    ("0", "must be a finite number of seconds in [1e-09, 86400], got 0.0"),
    ("-1 ms", "got -0.001"),
    ("1e-12", "got 1e-12"),
    ("1e9", "got 1000000000.0"),
    ("inf", "cannot read 'inf' as a time"),
    ("nan", "cannot read 'nan' as a time"),
    ("10 m", "'10 m' is a length, expected a time"),
    ("3 deg/s", "'3 deg/s' is an angular rate, expected a time"),
    ("10 min", "unknown unit 'min'"),
])
def test_bad_periods_are_refused_by_name(capsys, log_file, tmp_path, value, said):
    path, _ = log_file
    error, lines = _run(capsys, ["odometry", "forklift", str(path), "--method", "fk2", "--kf-period", value,
                                 "--json"], 2)
    assert error["error"].startswith("--kf-period: ") and said in error["error"] and len(lines) == 1
    with pytest.raises(DescriptionError, match=r"odometry\.noise\.period") as err:  # the same text in a file
        catalog.resolve(_described(tmp_path, value))
    assert said in str(err.value)


def test_a_period_for_another_method_is_refused(capsys, log_file):
    path, _ = log_file
    error, _ = _run(capsys, ["odometry", "forklift", str(path), "--method", "wls", "--kf-period", "10 ms", "--json"], 2)
    assert error["error"] == "--kf-period applies to --method fk1 or fk2, not to --method wls"


def test_python_takes_seconds_only():
    """A Python keyword takes a number of seconds (docs/conventions.md): text is refused, as a bool."""
    model = kalman_model(catalog.load("forklift"), "fk2")
    for bad in ("10 ms", "0.01", True):
        with pytest.raises(ShapeError, match=r"^period: the nominal sample period must be"):
            kalman_filter(model, turning_log(0.01, 5), period=bad)
        with pytest.raises(ShapeError, match=r"^Kalman noise period: the nominal sample period must be"):
            KalmanNoise(period=bad)


@pytest.mark.parametrize(("option", "lines"), [("10 ms", 1), ("2 ms", 0), (None, 0), ("1.9 ms", 0)])
def test_a_period_far_longer_than_the_log_s_intervals_is_said_once(capsys, tmp_path, option, lines):
    """T = 10 ms on a 1 kHz log: every step counts one period (n = 1), ten times the noise it spans; said once,
    naming both; 2 ms (twice the log's) and shorter are not said."""
    fork = catalog.load("forklift")
    path = tmp_path / "fast.csv"
    write_log(path, turning_log(0.001, 3000), fork)
    argv = ["odometry", "forklift", str(path), "--method", "fk1", "--json", "--chunk-size", "700"]
    data, said = _run(capsys, argv + (["--kf-period", option] if option else []))
    warned = [m for m in data["warnings"] if "nominal sample period" in m]
    assert len(warned) == lines and len([s for s in said if "nominal sample period" in s]) == lines
    if lines:
        assert "0.01 s" in warned[0] and "0.001 s" in warned[0] and "n = 1" in warned[0]
    est = estimator(fork, "fk1", noise=KalmanNoise(period=0.01))
    assert est.period_warning() is None  # nothing run yet


def test_track_s_fk2_feedback_takes_the_period_of_its_noise():
    """``track --feedback fk2`` filters one control period at a time with the description's noise: without a period
    each control period is one T (as before); T = 0.01 s makes a 0.05 s period five of them."""
    from wmrkit.control import track
    from wmrkit.control.references import builtin_reference

    fork, ref = catalog.load("forklift"), builtin_reference("circle", speed=1.0, size=3.0)
    runs = {p: track(fork, ref, dynamics=True, period=0.05, duration=1.0, feedback="fk2", slip_model="mqe",
                     noise=None if p is None else KalmanNoise(period=p)).estimate for p in (None, 0.05, 0.01)}
    assert runs[None].tolist() == runs[0.05].tolist() and runs[0.01].tolist() != runs[None].tolist()
