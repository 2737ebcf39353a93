"""Cumulative spin angles beyond where float64 holds them (odometry.logs.MAX_SPIN_ANGLE, 2**42 rad): refused at
their sample in one line, at every door that reads a joint log; below it the answer is that of the same run logged
from 0."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from refusal import one_line_error

from wmrkit.cli.main import main


def _log(path, offset: float, columns=("left.spin", "right.spin")):
    """A 4 s run at 50 Hz, the two spins at 8 and 12 rad/s from `offset` rad."""
    t = [0.02 * k for k in range(201)]
    rows = "".join(f"{a!r}," + ",".join(repr(offset + w * a) for w in (8.0, 12.0) * (len(columns) // 2)) + "\n"
                   for a in t)
    path.write_text("time," + ",".join(columns) + "\n" + rows)
    return path


def test_a_spin_angle_whose_steps_are_round_off_is_refused_at_its_sample(tmp_path, capsys):
    # 1e17 rad: floats there are 16 rad apart, the steps (0.16, 0.24 rad) rounded to 0 or 16 rad; 'calibrate'
    # printed a fit of that noise (WLS ratio 1.19, worse than no slip), exit 0
    assert np.spacing(1e17) > 0.24 * 10
    log = _log(tmp_path / "dd.csv", 1e17)
    err = one_line_error(["odometry", "diff-drive", str(log), "--quiet"], capsys)
    assert err.startswith(f"wmrkit: error: {log}:2: left.spin: a cumulative angle of 1e+17 rad, beyond 4.4e+12 rad")
    skid = _log(tmp_path / "skid.csv", 1e17, ("front_left.spin", "front_right.spin", "rear_left.spin",
                                              "rear_right.spin"))
    ref = tmp_path / "ref.tum"
    ref.write_text("".join(f"{0.02 * k!r} {0.01 * k!r} 0 0 0 0 0 1\n" for k in range(201)))
    err = one_line_error(["calibrate", "skid-steer-4", str(skid), "--reference", str(ref)], capsys)
    assert err.startswith(f"wmrkit: error: {skid}:2: front_left.spin: a cumulative angle of 1e+17 rad")
    assert main(["odometry", "diff-drive", str(log), "--quiet", "--json"]) == 2
    assert json.loads(capsys.readouterr().err)["line"] == 2


@pytest.mark.parametrize("offset", [2.0**41, -(2.0**41)])  # half the bound, 2**42
def test_below_the_bound_the_run_is_that_of_the_same_log_from_zero(offset, tmp_path, capsys):
    """Angles are cumulative, so their round-off does not add up: the final pose of the run logged from 2**41 rad
    (floats 2**-11 rad apart there) is that of the run logged from 0 within a few of those spacings times the
    radius (0.075 m) over the half track (0.2 m)."""
    poses = []
    for start in (0.0, offset):
        assert main(["odometry", "diff-drive", str(_log(tmp_path / "dd.csv", start)), "--quiet", "--json"]) == 0
        poses.append(json.loads(capsys.readouterr().out)["final_pose"])
    bound = 4 * float(np.spacing(abs(offset))) * 0.075 / 0.2 * 4.0  # heading error times the ~3 m path, and more
    assert math.dist(poses[0][:2], poses[1][:2]) < bound and abs(poses[0][2] - poses[1][2]) < bound
