"""A bag's gyro (``sensor_msgs/msg/Imu`` without orientation) whose ``angular_velocity.z`` no wheeled robot turns at:
``wmrkit odometry ROBOT BAG --imu TOPIC`` refuses it in one line naming the bag, the topic, the message and the field
(exit 2); an IMU found by itself is not checked, with a warning. 1e308 rad/s was integrated to an infinite turn: a
numpy warning on stderr, "the IMU inf rad" in the warning, exit 0."""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_bag_imu import _imu, _write

from wmrkit.cli.main import main

pytest.importorskip("rosbags")


@pytest.fixture(scope="module")
def short_run():
    from wmrkit import catalog
    from wmrkit.odometry import simulate
    from wmrkit.odometry.synthetic import TwistProfile

    return simulate(catalog.load("diff-drive"), TwistProfile.from_segments([(2.0, 0.5, 0.0, 0.2)]), 10.0)


@pytest.mark.parametrize("rate", [1e308, -1e200, 1000.5, float("inf")])
def test_a_gyro_rate_beyond_any_robot_is_refused_naming_the_message(capsys, tmp_path, short_run, rate):
    run = short_run
    t, _, rates = _imu(run.log.time, run.truth[:, 2], "gyro")
    rates = np.where(np.arange(len(t)) == 3, rate, rates)
    bag = tmp_path / "gyro"
    _write(bag, run.log.time, run.log.joints, run.log.positions, {"/imu": (t, None, rates)})
    code = main(["odometry", "diff-drive", str(bag), "--json", "--imu", "/imu"])
    out = capsys.readouterr()
    assert code == 2 and out.out == ""
    answer = json.loads(out.err)
    assert answer["file"] == str(bag)
    assert answer["error"] == (f"/imu message 3: angular_velocity.z is {rate:g} rad/s, not a finite rate within the "
                               "1000 rad/s of any wheeled robot (docs/limits.md)")
    code = main(["odometry", "diff-drive", str(bag), "--json"])  # found by itself: not checked, said so
    out = capsys.readouterr()
    answer = json.loads(out.out)
    assert code == 0 and answer["imu"] is None and "the IMU inf" not in out.err and "RuntimeWarning" not in out.err
    (line,) = answer["warnings"]
    assert "angular_velocity.z" in line and line.endswith("(the odometry is not checked against it)")


def test_a_gyro_at_the_limit_is_read(capsys, tmp_path, short_run):
    """1000 rad/s, the bound itself, is a rate (the check then says the odometry disagrees with it)."""
    run = short_run
    t, _, rates = _imu(run.log.time, run.truth[:, 2], "gyro")
    bag = tmp_path / "gyro"
    _write(bag, run.log.time, run.log.joints, run.log.positions, {"/imu": (t, None, np.full_like(rates, -1000.0))})
    code = main(["odometry", "diff-drive", str(bag), "--json", "--imu", "/imu"])
    answer = json.loads(capsys.readouterr().out)
    assert code == 0 and answer["imu"] == "/imu" and not answer["consistent"]
