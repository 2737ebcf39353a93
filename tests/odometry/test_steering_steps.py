"""A steering angle that steps within one sample interval while its wheel rolls: ``wmrkit odometry`` says so.

The no-slip rows take the steering at mid-interval (second order for a smoothly changing angle); a step made at an
unknown instant of the interval puts that interval's travel up to ``2 s sin(|step| / 4)`` off its direction.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.odometry import JointLog, odometry, odometry_model, simulate, square_path, write_log
from wmrkit.odometry.encoders import catalog_encoders
from wmrkit.odometry.steering import STEP_RTOL, steering_steps
from wmrkit.odometry.synthetic import TwistProfile

ROOT = Path(__file__).resolve().parents[2]


def _run(capsys, robot: str, path) -> tuple[dict, str]:
    assert main(["odometry", robot, str(path), "--json"]) == 0
    out = capsys.readouterr()
    return json.loads(out.out), out.err


def _steps(out: dict) -> list[str]:
    return [w for w in out["warnings"] if "within one interval" in w]


def test_a_drive_unit_pivoting_within_a_sample_warns(capsys, tmp_path):
    """The AGV's drive unit pivots 90 deg within one sample at each corner of a square without pauses: 0.09 rad
    off at 20 Hz with no warning before. The warning's bound holds the interval's real error, measured from the
    true poses, and that error is far beyond the slip tolerance."""
    robot = catalog.load("agv-drive-unit")
    run = simulate(robot, square_path(1.5), 20.0)
    write_log(tmp_path / "agv.csv", run.log, robot)
    out, err = _run(capsys, "agv-drive-unit", tmp_path / "agv.csv")
    assert abs(out["final_pose"][2] - 2 * math.pi) > 0.08 and out["consistent"]  # the sampling, not the data
    (line,) = _steps(out)
    assert err.count("within one interval") == 1 and line in err
    assert line.startswith("unit.steer steps -90 deg within one interval (t = 2.95 to 3 s;")
    assert "log faster" in line and "uniformly within an interval" in line
    travel, bound = (float(v) for v in
                     (line.split("wheel travels ")[1].split(" m")[0], line.split("up to ")[1].split(" m")[0]))
    # independently: the unit's axis moved 0.025 m straight ahead (the profile, 0.5 m/s for 0.05 s) while the log
    # says it turned 90 deg; the model put that travel at mid-angle, 45 deg off: 2 s sin(45 deg / 2)
    assert travel == pytest.approx(0.025, rel=0.01)
    assert bound == pytest.approx(2 * 0.025 * math.sin(math.pi / 8), rel=0.01)
    model = odometry_model(robot)
    k = 59  # t = 2.95 to 3 s
    inc = model.from_positions(run.log.positions[k:k + 2]).increments_robot[0]
    x, y = robot.wheel("unit").position
    th0, th1 = run.truth[k, 2], run.truth[k + 1, 2]
    true_axis = (run.truth[k + 1, :2] + x * np.array([math.cos(th1), math.sin(th1)])
                 - run.truth[k, :2] - x * np.array([math.cos(th0), math.sin(th0)]))
    rot = np.array([[math.cos(th0), -math.sin(th0)], [math.sin(th0), math.cos(th0)]])
    model_axis = rot @ np.array([inc[0] - inc[2] * y, inc[1] + inc[2] * x])
    off = float(np.hypot(*(model_axis - true_axis)))
    assert STEP_RTOL * travel < off <= bound * 1.001


def test_modules_that_all_step_warn_in_one_line(capsys, tmp_path):
    """swerve-4's square without pauses: its four modules step 45 deg at each corner; one line names them all (its
    redundancy also shows the steps as slip)."""
    robot = catalog.load("swerve-4")
    write_log(tmp_path / "sq.csv", simulate(robot, square_path(1.5), 20.0).log, robot)
    out, _ = _run(capsys, "swerve-4", tmp_path / "sq.csv")
    (line,) = _steps(out)
    named = [j for j in ("front_left", "front_right", "rear_left", "rear_right") if f"{j}.steer" in line]
    assert len(named) == 4 and " 45 deg within one interval (t = 2.95 to 3 s;" in line.replace("-", " ").replace(
        "+", " ")
    assert not out["consistent"] and any("contradict" in w for w in out["warnings"])


@pytest.mark.parametrize("rate", [20.0, 100.0])
def test_the_bound_is_first_order_in_the_sample_period(rate):
    """The step's travel, and so its bound, shrinks with the sample period (0.019 m at 20 Hz, 0.0038 m at 100 Hz)."""
    robot = catalog.load("agv-drive-unit")
    (step,) = steering_steps(odometry_model(robot), simulate(robot, square_path(1.5), rate).log.positions)
    assert step.bound == pytest.approx(2 * 0.5 / rate * math.sin(math.pi / 8), rel=0.01)


def _agv_with_pauses():
    robot = catalog.load("agv-drive-unit")
    return robot, simulate(robot, square_path(1.5, pause=1.0), 20.0).log


def _forklift_counts():
    robot = catalog.load("forklift")
    profile = TwistProfile.from_segments([(4.0, 1.0, 0.2, 0.2), (1.0, 0, 0, 0), (4.0, 1.0, 0.0, 0.0)])
    return robot, simulate(robot, profile, 20.0, encoders=catalog_encoders("forklift")).log


def _smooth(name: str, twist, rate: float, duration: float, encoders=None, about=None):
    """A profile whose twist changes four times a sample interval: steering that changes smoothly."""
    robot = catalog.load(name)
    h = 1 / rate / 4
    profile = TwistProfile.from_segments([(h, *twist((i + 0.5) * h)) for i in range(int(duration / h))])
    profile = profile if about is None else profile.about(about)
    return robot, simulate(robot, profile, rate, encoders=encoders).log


def _swerve_turning(rate: float, w: float, *, spin: float = 0.8):
    """swerve-4's modules all turning at `w` [rad/s] (through several turns) while rolling at `spin` [m/s]."""
    robot = catalog.load("swerve-4")
    joints = odometry_model(robot).joints
    t = np.arange(int(2.0 * rate) + 1) / rate
    cols = [w * t if j.endswith(".steer") else spin * t / robot.wheel(j.rpartition(".")[0]).r for j in joints]
    return robot, JointLog.from_headings(robot, t, joints, np.column_stack(cols))


def _swerve_steering_at_rest():
    robot, log = _swerve_turning(20.0, 0.0)
    positions = log.positions.copy()
    steer = [k for k, j in enumerate(log.joints) if j.endswith(".steer")]
    positions[:20, :] = positions[0]  # at rest for a second, turning its modules 90 deg within one sample
    positions[10:20, steer] += math.pi / 2
    positions[20:, :4] -= positions[20, :4] - positions[0, :4]
    return robot, JointLog(log.time, log.joints, positions)


def _castor_wrapped(name: str):
    robot = catalog.load(name)
    log = simulate(robot, TwistProfile.from_segments([(3.0, 0.0, 0.5, 0.0), (math.pi, 0, 0, 0.5)] * 4), 20.0).log
    positions = log.positions.copy()
    castors = [k for k, j in enumerate(log.joints) if j.endswith(".steer")]
    positions[::3, castors] += 2 * math.pi  # the angle column flips by a turn (a wrapping encoder)
    positions[1::7, castors] -= 4 * math.pi
    return robot, JointLog(log.time, log.joints, positions)


@pytest.mark.parametrize("case", [
    _agv_with_pauses,
    _forklift_counts,  # 1.4118 deg steering counts
    lambda: _smooth("forklift", lambda t: (1.5, 0.0, 0.6 * math.sin(2 * t)), 20.0, 8.0,
                    catalog_encoders("forklift"), (-1.0, 0.0)),
    lambda: _smooth("ackermann", lambda t: (2.0, 0.0, 0.5 * math.sin(1.5 * t)), 20.0, 6.0),
    lambda: _swerve_turning(50.0, 10.0),  # 0.2 rad a sample
    lambda: _swerve_turning(20.0, 20.0),  # 1 rad a sample
    _swerve_steering_at_rest,
    lambda: _castor_wrapped("thesis-omni-castor"),
    lambda: _castor_wrapped("thesis-diff-castor"),  # the castor starts swivelling at each corner: 0.39, 0.48 rad
], ids=["agv-pause", "forklift-counts", "forklift-slalom-counts", "car-slalom", "swerve-10rad/s-50Hz",
        "swerve-20rad/s-20Hz", "swerve-steers-at-rest", "omni-castor-wraps", "diff-castor-wraps"])
def test_smooth_quantised_wrapped_or_resting_steering_does_not_warn(capsys, tmp_path, case):
    robot, log = case()
    write_log(tmp_path / "log.csv", log, robot)
    out, err = _run(capsys, robot.name, tmp_path / "log.csv")
    assert _steps(out) == [] and "within one interval" not in err
    assert steering_steps(odometry_model(robot), log.positions) == []


def test_smooth_swerve_turning_fast_is_second_order():
    """What the smooth cases rely on: modules turning 1 rad a sample keep the odometry second order (the midpoint
    rule), against the closed form: velocity 0.8 m/s along heading 20 t, no rotation."""
    robot, log = _swerve_turning(20.0, 20.0)
    pose = odometry(robot, log).final_pose
    t = log.time[-1]
    truth = np.array([0.8 * math.sin(20 * t) / 20, 0.8 * (1 - math.cos(20 * t)) / 20])
    assert np.hypot(*(pose[:2] - truth)) < 0.005 and abs(pose[2]) < 1e-12


def test_the_forklift_example_log_does_not_warn(capsys, tmp_path):
    subprocess.run([sys.executable, str(ROOT / "examples" / "odometry_forklift_log.py"), str(tmp_path)], check=True,
                   capture_output=True)
    out, _ = _run(capsys, "forklift", tmp_path / "forklift_counts.csv")
    assert _steps(out) == []


def _agv_logs(tmp_path) -> tuple[Path, Path, Path]:
    """The AGV's square without pauses (its unit pivots within a sample) as a CSV log and as a ROS 2 bag, and with
    pauses to steer (no step) as a CSV log."""
    from wmrkit.odometry.bags import write_joint_states

    robot = catalog.load("agv-drive-unit")
    log = simulate(robot, square_path(1.5), 20.0).log
    write_log(tmp_path / "agv.csv", log, robot)
    write_joint_states(tmp_path / "agv.mcap", log, robot=robot)
    write_log(tmp_path / "paused.csv", _agv_with_pauses()[1], robot)
    return tmp_path / "agv.csv", tmp_path / "agv.mcap", tmp_path / "paused.csv"


def test_a_bag_warns_of_a_steering_step_as_its_csv_does(capsys, tmp_path):
    """The same log as a ROS 2 bag: no warning before (the diagnostic read CSV logs only), the CSV's line now."""
    csv, bag, _ = _agv_logs(tmp_path)
    (line,) = _steps(_run(capsys, "agv-drive-unit", csv)[0])
    out, err = _run(capsys, "agv-drive-unit", bag)
    assert _steps(out) == [line] and err.count("within one interval") == 1
    assert line.startswith("unit.steer steps -90 deg within one interval (t = 2.95 to 3 s;")


def test_batch_odometry_warns_of_a_steering_step_per_log(capsys, tmp_path):
    """``batch odometry`` over the stepping log (CSV and bag) and the paused one: the stepping logs' rows carry
    ``wmrkit odometry``'s line in their ``warnings`` column (and the answer's ``warnings`` names each log); the
    paused log's row none. Before, no row said it."""
    csv, bag, paused = _agv_logs(tmp_path)
    (line,) = _steps(_run(capsys, "agv-drive-unit", csv)[0])
    assert main(["batch", "odometry", "agv-drive-unit", str(csv), str(bag), str(paused), "--workers", "0",
                 "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    rows = {r["log"]: r["warnings"] or "" for r in answer["rows"]}
    assert line in rows[str(csv)] and line in rows[str(bag)] and "within one interval" not in rows[str(paused)]
    said = [w for w in answer["warnings"] if "within one interval" in w]
    assert [w.split(": ")[0] for w in said] == [str(csv), str(bag)] and all(line in w for w in said)
