"""`wmrkit calibrate` refuses references that cannot record the log's run, whatever the slip (slip/consistency.py).

Each bad reference below was fitted to a plausible ratio (0.8-1.3 on the Husky-like runs), exit 0. The correct
references of the same runs, with noise, rotated or turning on the spot (a skid steer turns a quarter of what its
differential kinematics say, half of what unweighted least squares say), must pass.
"""

from __future__ import annotations

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.errors import WmrkitError
from wmrkit.odometry.logs import write_csv
from wmrkit.odometry.pipeline import odometry
from wmrkit.odometry.trajectories import Trajectory, write_trajectory
from wmrkit.slip.calibration import calibrate_slip
from wmrkit.slip.consistency import check_reference
from wmrkit.slip.skid import CALIBRATION, TESTS, segment_run
from wmrkit.slip.synthetic import wheel_speed_run
from wmrkit.slip.weights import wls_model

SEGMENTS = [(3.0, [8, 12, 8, 12]), (2.0, [10, 10, 10, 10]), (3.0, [12, 8, 12, 8]), (2.0, [6, 14, 6, 14])]
#: Twist segments (duration, v, omega) of the slip study (docs/slip.md) and two more: a spot turn then an arc the
#: other way (the cumulative headings of log and reference then differ in sign), and arcs driven backwards.
RUNS = {"calibration": CALIBRATION, **TESTS, "spot turn then arc": ((1.5, 0.0, 2.0), (4.0, 1.0, -0.75)),
        "reversing arcs": ((3.0, 1.0, 0.5), (3.0, -1.0, 0.5), (3.0, -0.5, -0.8))}


@pytest.fixture(scope="module")
def robot():
    return catalog.load("skid-steer-4")


@pytest.fixture(scope="module")
def husky_run(robot):
    return wheel_speed_run(robot, SEGMENTS, 20.0, model="mqe")


def _rotated(poses: np.ndarray, angle: float) -> np.ndarray:
    """`poses` in a frame turned by `angle` and shifted (a motion-capture frame: still a correct reference)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.column_stack([c * poses[:, 0] - s * poses[:, 1] + 5, s * poses[:, 0] + c * poses[:, 1] - 3,
                            poses[:, 2] + angle])


def _heading_off(poses: np.ndarray, degrees: float) -> np.ndarray:
    out = poses.copy()
    out[:, 2] += np.radians(degrees)
    return out


BAD = {  # name: (reference from the true poses, what the refusal says)
    "x and y swapped": (lambda p: p[:, [1, 0, 2]], r"its path turns the other way from the log's|direction of travel"),
    "mirror image": (lambda p: p * [1, -1, -1], "slip scales a turn, it does not reverse it"),
    "heading never turns": (lambda p: p * [1, 1, 0], r"the reference \+0 rad: slip scales a turn"),
    "heading turns the other way": (lambda p: p * [1, 1, -1], "slip scales a turn, it does not reverse it"),
}


@pytest.mark.parametrize("bad", list(BAD))
def test_the_walkthrough_references_are_refused(robot, husky_run, bad):
    """Each was fitted, exit 0: x and y swapped gave ratio 1.16, the heading held at 0 0.86, reversed 0.94."""
    make, message = BAD[bad]
    with pytest.raises(WmrkitError, match=message):
        calibrate_slip(robot, husky_run.log, (husky_run.log.time, make(husky_run.truth)))


@pytest.mark.parametrize("name", list(RUNS))
def test_the_slip_study_runs_pass_and_their_bad_references_do_not(robot, name):
    """The quasi-static runs of the slip study: the true poses, with 10 cm / 0.05 rad of noise, in a rotated frame,
    pass without a warning; x and y swapped (the 'calibration' run's swap was fitted to ratio 0.015, the tight
    loop's to 0.45, the spot turns' to 1.27) and the mirror image are refused."""
    log, truth = segment_run(robot, RUNS[name], 50.0, "quasi-static")
    plain = odometry(wls_model(robot), log).poses  # what calibrate_slip checks against (the reference's times)
    plain[:, 2] = np.unwrap(plain[:, 2])
    noisy = truth + np.random.default_rng(0).normal(0.0, [0.1, 0.1, 0.05], truth.shape)
    for good in (truth, noisy, _rotated(truth, 0.9)):
        assert check_reference(log.time, good, _rotated(plain, good[0, 2] - plain[0, 2])) == []
    for bad in ("x and y swapped", "mirror image"):
        ref = BAD[bad][0](truth)
        with pytest.raises(WmrkitError, match=BAD[bad][1]):
            check_reference(log.time, ref, _rotated(plain, ref[0, 2] - plain[0, 2]))
    if name == "calibration":  # the whole calibration refuses it too
        with pytest.raises(WmrkitError, match=BAD["x and y swapped"][1]):
            calibrate_slip(robot, log, (log.time, BAD["x and y swapped"][0](truth)))


def test_a_reference_that_turns_where_the_log_barely_does_is_refused(robot):
    """The reverse case: the log's wheels turn it 0.1 rad (no-slip least squares), the reference 2.26 rad, over a
    path of 4 m against 5 m. It was refused as a fit that ran to the bound of its search, which says nothing of
    why; a slight turn read as a strong slip would be worse."""
    log = wheel_speed_run(robot, [(5.0, [10, 10.2, 10, 10.2])], 50.0).log
    ref = wheel_speed_run(robot, [(5.0, [8, 12, 8, 12])], 50.0).truth
    with pytest.raises(WmrkitError, match=r"the reference turns \+2\.26 rad and the log's no-slip odometry \+0\.1 rad"):
        calibrate_slip(robot, log, (log.time, ref))


def test_a_heading_in_another_frame_warns_then_is_refused(robot, husky_run, tmp_path, capsys):
    """A heading 30 deg off the robot's (a motion-capture body frame turned on the robot) is more than a skid
    steer's lateral slip: a warning, the fit still given; 60 deg is not slip at all: refused, exit 2."""
    log = husky_run.log
    assert calibrate_slip(robot, log, (log.time, _heading_off(husky_run.truth, 0.0))).warnings == ()
    cal = calibrate_slip(robot, log, (log.time, _heading_off(husky_run.truth, 30.0)))
    assert len(cal.warnings) == 1 and "direction of travel is 30.5 deg (median) off" in cal.warnings[0]
    log_path, ref_path = tmp_path / "log.csv", tmp_path / "ref.tum"
    write_csv(log_path, ("time", *log.joints), np.column_stack([log.time, log.positions]))
    for degrees, code, json in ((30.0, 0, ["--json"]), (60.0, 2, [])):
        write_trajectory(ref_path, Trajectory(log.time, _heading_off(husky_run.truth, degrees), np.zeros(len(log))),
                         "tum")
        assert main(["calibrate", "skid-steer-4", str(log_path), "--reference", str(ref_path), *json]) == code
        out, err = capsys.readouterr()
        assert err.count("\n") == 1
        if code == 0:
            assert err.startswith(f"wmrkit: warning: {ref_path}: its direction of travel is 30.5 deg")
            assert "direction of travel" in " ".join(__import__("json").loads(out)["warnings"])
        else:
            assert err.startswith(f"wmrkit: error: {ref_path}: its direction of travel is 60.5 deg")


def test_a_sparse_reference_is_not_judged(robot):
    """Poses more than 2 s apart (batch calibrate's start and end of a closed path) say nothing of how the run
    turned: not judged."""
    run = wheel_speed_run(robot, [(2.0, [10] * 4), (5.5, [6, 14, 6, 14]), (2.0, [10] * 4)], 20.0)
    at = [0, 60, len(run.log) - 1]
    assert calibrate_slip(robot, run.log, (run.log.time[at], run.truth[at])).warnings == ()
