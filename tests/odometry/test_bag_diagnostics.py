"""A ROS 2 bag gets ``wmrkit odometry``'s diagnostics as the same log written as CSV does: one log, two files, the
two ``--json`` answers' diagnostics (``consistent``, ``warnings``) equal, and each diagnostic actually said."""

from __future__ import annotations

import json

import numpy as np
import pytest

from geared import TWO_ENCODERS as GEARED
from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.odometry import JointLog, simulate, write_log
from wmrkit.odometry.synthetic import TwistProfile

pytest.importorskip("rosbags")


def _answer(capsys, robot, path) -> dict:
    assert main(["odometry", str(robot), str(path), "--json"]) == 0
    out = capsys.readouterr()
    answer = json.loads(out.out)
    assert [f"wmrkit: warning: {w}" for w in answer["warnings"]] == out.err.splitlines()
    return answer


def _both(capsys, tmp_path, robot_arg, robot, log: JointLog) -> tuple[dict, dict]:
    """The answers for `log` written as a CSV log and as a bag (its steering as headings in both)."""
    from wmrkit.odometry.bags import write_joint_states

    write_log(tmp_path / "log.csv", log, robot)
    write_joint_states(tmp_path / "log.mcap", log, robot=robot)
    return _answer(capsys, robot_arg, tmp_path / "log.csv"), _answer(capsys, robot_arg, tmp_path / "log.mcap")


def _diagnostics(answer: dict) -> tuple:
    return answer["consistent"], answer["warnings"]


@pytest.mark.parametrize("name", ["mecanum-4", "swerve-4"])
def test_a_bag_names_the_slipping_wheel_as_its_csv_does(capsys, tmp_path, name):
    """The robot driving while its front-left wheel spins 30 % too fast (a wheel slipping on its spot). Before, the
    bag's warning said the joints contradict each other without naming a wheel (the per-wheel RMS slips read CSV
    logs only); now it is the CSV's line. swerve-4 (steering in the bag as headings) names the slipping wheel
    first; mecanum-4's four wheels and three motions leave one redundant equation, whose least-squares slip the four
    share equally, so each is named."""
    robot = catalog.load(name)
    profile = TwistProfile.from_segments([(3.0, 0.4, 0.1, 0.2), (2.0, 0.2, -0.2, -0.3)])
    log = simulate(robot, profile, 20.0).log
    k = log.joints.index("front_left.spin")
    positions = log.positions.copy()
    positions[:, k] *= 1.3
    log = JointLog(log.time, log.joints, positions)
    csv, bag = _both(capsys, tmp_path, name, robot, log)
    assert _diagnostics(bag) == _diagnostics(csv)
    (line,) = [w for w in csv["warnings"] if w.startswith("the sensed joints contradict each other")]
    assert not csv["consistent"]  # (swerve-4 also warns of its modules' steps at the profile's corner, in both)
    named = [n.split()[0] for n in line.split("(slip per wheel: ")[1].split(")")[0].split(", ")]
    assert sorted(named) == sorted(w.name for w in robot.wheels)
    if name == "swerve-4":
        assert named[0] == "front_left"
    np.testing.assert_allclose(bag["final_pose"], csv["final_pose"], atol=1e-9)




@pytest.mark.parametrize(("right", "agrees"), [(2.0, False), (1.0, True)])
def test_a_bag_breaking_a_gear_coupling_warns_as_its_csv_does(capsys, tmp_path, right, agrees):
    """A 1:1 gear (a solid axle) logged with the right spin turning twice as fast as the left: before, the CSV log
    warned and said inconsistent while the bag said "consistent": true, no warning. Now both say the same; a log
    keeping the gear warns in neither."""
    robot_path = tmp_path / "geared.yaml"
    robot_path.write_text(GEARED)
    robot = catalog.resolve(str(robot_path))
    t = np.arange(5.0)
    log = JointLog(t, ("left.spin", "right.spin"), np.column_stack([t, right * t]))
    csv, bag = _both(capsys, tmp_path, robot_path, robot, log)
    assert _diagnostics(bag) == _diagnostics(csv)
    assert csv["consistent"] is agrees
    said = [w for w in csv["warnings"] if "do not turn together" in w]
    assert len(said) == (0 if agrees else 1)
    if not agrees:
        assert said[0].startswith("the joints of the gear of wheels 'left' and 'right' (ratios 1, 1) do not turn "
                                  "together")
