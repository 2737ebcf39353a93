"""``wmrkit batch odometry`` checks each bag against its IMU as ``wmrkit odometry ROBOT BAG`` does: the same warning
line (the oracle: that command run per bag with ``--json``), ``consistent`` false when it fires, the summary's
inconsistent count; an IMU found by itself that cannot be read is a "not checked" line, a named one the log's
error. The check runs in the Dask workers of a real ``LocalCluster`` (two processes, one thread each); the bags are
written here: JointState of a run and an Imu whose orientation is the run's true heading, a few hundred messages
each."""

from __future__ import annotations

import json
import math
import os
import re
from pathlib import Path

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.description import load_robot_file
from wmrkit.odometry import simulate
from wmrkit.odometry.synthetic import TwistProfile

distributed = pytest.importorskip("distributed")
pytest.importorskip("pyarrow")
pytest.importorskip("rosbags")

#: A skid steer described as a differential drive (its front wheels): two spins, nothing redundant, so only the IMU
#: sees its wheels slip sideways in a turn.
SKID_AS_DIFF = """name: skid-as-diff
wheels:
  - {name: left, type: fixed, position: [0, 0.25], heading: 0, r: 0.1, actuated: [spin], sensed: [spin]}
  - {name: right, type: fixed, position: [0, -0.25], heading: 0, r: 0.1, actuated: [spin], sensed: [spin]}
"""
JOINTS = ("left.spin", "right.spin")
T0 = 1000.0  # the bags' clock at the runs' start [s]
TURNS = re.compile(r"over the run the no-slip odometry turned (\S+) rad and the IMU (\S+) rad")


def _bag(path: Path, time, positions, imus: dict) -> Path:
    """A bag of JointState (`positions` of :data:`JOINTS` at `time` [s]) and Imu topics (`imus`: topic -> (time,
    yaw), the yaw as the orientation's quaternion about z)."""
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    T = ts.types

    def header(t):
        sec = math.floor(t)
        return T["std_msgs/msg/Header"](stamp=T["builtin_interfaces/msg/Time"](
            sec=sec, nanosec=round((t - sec) * 1e9) % 10**9), frame_id="")

    with Writer(path, version=8) as w:
        conn, empty = w.add_connection("/joint_states", "sensor_msgs/msg/JointState", typestore=ts), np.zeros(0)
        for t, row in zip(T0 + time, positions, strict=True):
            msg = T["sensor_msgs/msg/JointState"](header=header(t), name=list(JOINTS), position=row.astype(float),
                                                  velocity=empty, effort=empty)
            w.write(conn, round(t * 1e9), ts.serialize_cdr(msg, "sensor_msgs/msg/JointState"))
        for topic, (times, yaw) in imus.items():
            conn = w.add_connection(topic, "sensor_msgs/msg/Imu", typestore=ts)
            vec, cov = T["geometry_msgs/msg/Vector3"], np.zeros(9)
            for t, a in zip(T0 + times, yaw, strict=True):
                msg = T["sensor_msgs/msg/Imu"](
                    header=header(t), orientation=T["geometry_msgs/msg/Quaternion"](0.0, 0.0, math.sin(a / 2),
                                                                                     math.cos(a / 2)),
                    orientation_covariance=cov, angular_velocity=vec(x=0.0, y=0.0, z=0.0),
                    angular_velocity_covariance=cov, linear_acceleration=vec(x=0.0, y=0.0, z=9.81),
                    linear_acceleration_covariance=cov)
                w.write(conn, round(t * 1e9), ts.serialize_cdr(msg, "sensor_msgs/msg/Imu"))
    return path


def _imu(time, heading):
    """``(time, yaw)`` of an IMU reading `heading` 7 ms after the joint states, at their rate."""
    t = time[1:] + 0.007
    return t, np.interp(t, time, heading)


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    """The robot file and three bags: the skid steer turning on the spot (its wheels turn 5 rad, the IMU 1.25 rad:
    the quasi-static slip model), a differential drive rolling through turns (its IMU agreeing), and that run with
    its IMU's 10th orientation NaN (unreadable). The slipping bag's (wheels' turn, true turn) come with it."""
    from wmrkit.slip.skid import segment_run

    d = tmp_path_factory.mktemp("imu-fleet")
    robot = d / "skid.yaml"
    robot.write_text(SKID_AS_DIFF)
    log, truth = segment_run(catalog.load("skid-steer-4"), ((2.0, 1.0, 0.0), (4.0, 0.0, 1.25), (2.0, 1.0, 0.0)), 50.0,
                             source="quasi-static")
    k = [log.joints.index("front_left.spin"), log.joints.index("front_right.spin")]
    slips = _bag(d / "slips", log.time, log.positions[:, k], {"/imu": _imu(log.time, truth[:, 2])})
    turned = log.positions[-1, k] - log.positions[0, k]
    turns = (0.1 * (turned[1] - turned[0]) / 0.5, truth[-1, 2] - truth[0, 2])  # r (right - left) / track; the truth
    profile = TwistProfile.from_segments([(4.0, 0.3, 0.0, 0.0), (4.0, 0.3, 0.0, 0.4), (4.0, 0.3, 0.0, -0.3),
                                          (4.0, 0.3, 0.0, 0.0)])
    run = simulate(load_robot_file(robot), profile, 25.0)
    clean = _bag(d / "clean", run.log.time, run.log.positions, {"/imu": _imu(run.log.time, run.truth[:, 2])})
    t, yaw = _imu(run.log.time, run.truth[:, 2])
    yaw[10] = np.nan
    unread = _bag(d / "unread", run.log.time, run.log.positions, {"/imu": (t, yaw)})
    return robot, [slips, clean, unread], turns


@pytest.fixture(scope="module")
def scheduler():
    """The address of a two-worker LocalCluster (the workers read this clone's wmrkit: PYTHONPATH)."""
    path = os.pathsep.join(p for p in (str(Path(__file__).parent), os.environ.get("PYTHONPATH", "")) if p)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=50, env={"PYTHONPATH": path}) as c:
        yield c.scheduler_address


def _single(capsys, robot, bag, *extra) -> dict:
    """``wmrkit odometry ROBOT BAG --json``'s answer."""
    code = main(["odometry", str(robot), str(bag), "--json", *extra])
    out = capsys.readouterr()
    assert code == 0, out
    return json.loads(out.out)


def test_each_bag_is_checked_against_its_imu_on_the_cluster(capsys, tmp_path, fleet, scheduler):
    """The slipping bag's row has the IMU line of ``wmrkit odometry --json`` for it, its turns the closed forms (the
    wheels' r (right - left) / track, the slip model's true turn), ``consistent`` false, counted and named by the
    summary; the clean bag has no line; the unreadable IMU's bag has the single command's "not checked" line and
    stays consistent. Before, every row was consistent without a warning: the batch read no IMU."""
    robot, bags, (wheels, true) = fleet
    single = {str(b): _single(capsys, robot, b) for b in bags}
    slips, clean, unread = map(str, bags)
    (line,) = single[slips]["warnings"]
    assert line.startswith("the no-slip odometry's heading contradicts the IMU on /imu: ")
    m = TURNS.search(line)
    assert float(m[1]) == pytest.approx(wheels, rel=1e-3) and float(m[2]) == pytest.approx(true, rel=1e-3)
    assert wheels == pytest.approx(5.0, rel=2e-2) and true == pytest.approx(1.25, rel=2e-2)
    assert single[clean]["warnings"] == [] and single[clean]["consistent"]
    (not_checked,) = single[unread]["warnings"]
    assert not_checked.endswith("(the odometry is not checked against it)") and "message 10" in not_checked
    out = tmp_path / "fleet.parquet"
    command = ["batch", "odometry", str(robot), *map(str, bags), "--scheduler", scheduler, "--out", str(out)]
    assert main([*command, "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    rows = {r["log"]: r for r in answer["rows"]}
    for bag, s in single.items():
        assert rows[bag]["warnings"] == ("; ".join(s["warnings"]) or None), bag
        assert (rows[bag]["consistent"], rows[bag]["imu"], rows[bag]["error"]) == (s["consistent"], s["imu"], None)
    assert (rows[slips]["imu"], rows[clean]["imu"], rows[unread]["imu"]) == ("/imu", "/imu", None)
    assert answer["inconsistent"] == 1 and answer["inconsistent_logs"] == [slips] and answer["failed"] == 0
    assert answer["warnings"] == [f"{b}: {'; '.join(s['warnings'])}" for b, s in single.items() if s["warnings"]]
    import pyarrow.parquet as pq

    table = {r["log"]: r for r in pq.read_table(out).to_pylist()}
    assert {b: (r["consistent"], r["imu"]) for b, r in table.items()} == {
        b: (s["consistent"], s["imu"]) for b, s in single.items()}
    assert main([*command, "--quiet"]) == 0  # the rerun resumes every row, the check's verdict kept
    said = capsys.readouterr()
    out_lines = said.out.splitlines()
    assert out_lines[0] == f"3 logs: 3 done (3 from an earlier run), 0 failed, 1 inconsistent ({slips})"
    assert f"wmrkit: table written to {out}\n" in said.err


def test_a_named_imu_is_the_one_checked(capsys, tmp_path, fleet):
    """A bag with two Imu topics, /imu/true (the robot's turn) and /imu/wheels (the wheels' no-slip heading): no
    topic is checked by default (imu null and a warning, as the single command's); ``--imu /imu/true`` flags it with the
    single command's line and ``--imu /imu/wheels`` does not."""
    from wmrkit.slip.skid import segment_run

    robot = fleet[0]
    log, truth = segment_run(catalog.load("skid-steer-4"), ((2.0, 1.0, 0.0), (4.0, 0.0, 1.25), (2.0, 1.0, 0.0)), 50.0,
                             source="quasi-static")
    k = [log.joints.index("front_left.spin"), log.joints.index("front_right.spin")]
    positions = log.positions[:, k]
    wheels = 0.1 * (positions[:, 1] - positions[:, 0]) / 0.5  # the differential drive's no-slip heading
    bag = _bag(tmp_path / "two", log.time, positions, {"/imu/true": _imu(log.time, truth[:, 2]),
                                                       "/imu/wheels": _imu(log.time, wheels - wheels[0])})
    for extra, flagged in (((), False), (("--imu", "/imu/true"), True), (("--imu", "/imu/wheels"), False)):
        s = _single(capsys, robot, bag, *extra)
        assert main(["batch", "odometry", str(robot), str(bag), "--workers", "0", "--json", *extra]) == 0
        (row,) = json.loads(capsys.readouterr().out)["rows"]
        assert (row["warnings"], row["consistent"], row["imu"]) == ("; ".join(s["warnings"]) or None, s["consistent"],
                                                                   s["imu"]), extra
        assert row["consistent"] is not flagged and (row["imu"] is None) is not extra
        assert ("choose one with --imu TOPIC" in (row["warnings"] or "")) == (not extra)  # said, not silently skipped


def _batch(capsys, robot, bags, *extra) -> tuple[int, dict, str]:
    """``wmrkit batch odometry ROBOT BAGS --workers 0 --json``'s exit code, answer and stderr."""
    code = main(["batch", "odometry", str(robot), *map(str, bags), "--workers", "0", "--json", *extra])
    out = capsys.readouterr()
    return code, json.loads(out.out), out.err


def test_a_named_imu_a_bag_cannot_give_fails_that_bag_as_wmrkit_odometry_refuses_it(capsys, tmp_path, fleet):
    """``--imu TOPIC`` names the IMU: a bag without that Imu topic, one whose IMU has a NaN orientation and one whose
    IMU is on another clock each fail (their error the one ``wmrkit odometry --imu TOPIC`` exits 2 with, their
    trajectory not written), the bag with a usable IMU is done, and the batch exits 1. Before, each was a "not
    checked" warning, the batch exit 0 with ``failed`` 0."""
    robot, (_, clean, unread), _ = fleet
    log = tmp_path / "log"
    log.mkdir()
    run = simulate(load_robot_file(robot), TwistProfile.from_segments([(3.0, 0.3, 0.0, 0.2)]), 25.0)
    t, yaw = _imu(run.log.time, run.truth[:, 2])
    other = _bag(log / "other", run.log.time, run.log.positions, {"/imu/other": (t, yaw)})
    clock = _bag(log / "clock", run.log.time, run.log.positions, {"/imu": (t + 500.0, yaw)})
    bags = [clean, other, unread, clock]
    errors = {}
    for bag in bags[1:]:
        code = main(["odometry", str(robot), str(bag), "--json", "--imu", "/imu"])
        answer = json.loads(capsys.readouterr().err)
        assert code == 2, bag
        errors[str(bag)] = f"{answer['file']}: {answer['error']}"
    assert "is not in the bag" in errors[str(other)] and "message 10" in errors[str(unread)]
    assert "another clock?" in errors[str(clock)]
    code, answer, _ = _batch(capsys, robot, bags, "--imu", "/imu", "--trajectories", str(tmp_path / "traj"))
    assert code == 1 and answer["failed"] == 3 and answer["errors"] == errors
    rows = {r["log"]: r for r in answer["rows"]}
    assert rows[str(clean)]["imu"] == "/imu" and rows[str(clean)]["error"] is None
    assert sorted(p.name for p in (tmp_path / "traj").iterdir()) == ["clean.tum"]
    code, answer, _ = _batch(capsys, robot, [clean, other], "--imu", "/imu/other")
    assert code == 1 and list(answer["errors"]) == [str(clean)] and answer["rows"][1]["imu"] == "/imu/other"
    assert answer["errors"][str(clean)].startswith(f"{clean}: --imu topic '/imu/other' is not in the bag")


def test_the_imu_found_in_each_bag_is_said(capsys, tmp_path, fleet):
    """Without --imu, the IMU each bag holds alone is checked: a note on stderr names the topics found (``wmrkit
    odometry``'s note; before, batch said nothing), each row's ``imu`` names its own, and the text lines without
    --out say it per bag; a bag whose IMU cannot be used is not counted (a warning says so, its imu null)."""
    robot, (slips, clean, unread), _ = fleet
    code, answer, err = _batch(capsys, robot, [clean, unread, slips])
    assert code == 0 and [r["imu"] for r in answer["rows"]] == ["/imu", None, "/imu"]
    assert ("wmrkit: note: heading of 2 bags checked against the IMU on each bag's one sensor_msgs/msg/Imu topic "
            "(/imu; --imu TOPIC chooses it; each row's imu names the topic)") in err.splitlines()
    assert main(["batch", "odometry", str(robot), str(clean), str(unread), "--workers", "0", "--quiet"]) == 0
    out = capsys.readouterr()
    assert "wmrkit: note: heading of 1 bag checked against the IMU" in out.err
    lines = out.out.splitlines()
    assert lines[1].startswith(f"  {clean}: x ") and lines[1].endswith(", heading checked against the IMU on /imu")
    assert lines[2].startswith(f"  {unread}: x ") and "IMU" not in lines[2]
    assert main(["batch", "odometry", str(robot), str(clean), "--workers", "0", "--quiet", "--imu", "/imu"]) == 0
    assert "note" not in capsys.readouterr().err  # named: nothing found by itself


def test_imu_without_a_bag_is_refused(capsys, tmp_path):
    """``--imu`` on a batch of CSV logs only would be ignored: one error line, exit 2."""
    log = tmp_path / "a.csv"
    log.write_text("time,left.spin,right.spin\n0,0,0\n1,1,1\n")
    assert main(["batch", "odometry", "diff-drive", str(log), "--workers", "0", "--imu", "/imu", "--json"]) == 2
    assert json.loads(capsys.readouterr().err)["error"] == "--imu /imu applies to ROS 2 bags; none of the 1 logs is one"


def test_a_failed_bag_keeps_what_was_said_before_it_failed(capsys, tmp_path, fleet):
    """A bag with two Imu topics (its heading not checked: choose one with --imu) whose joint states jump: ``wmrkit
    odometry`` says the not-checked line, then fails. The batch's row kept only the error ('warnings' null, nothing on
    stderr nor in the JSON answer's warnings); now it keeps that command's line, said as every log's warnings are."""
    robot = fleet[0]
    run = simulate(load_robot_file(robot), TwistProfile.from_segments([(3.0, 0.3, 0.0, 0.2)]), 25.0)
    positions = run.log.positions.copy()
    positions[40:, 0] += 1e5  # an implausible jump: the log fails
    t, yaw = _imu(run.log.time, run.truth[:, 2])
    bag = _bag(tmp_path / "jump", run.log.time, positions, {"/imu/a": (t, yaw), "/imu/b": (t, yaw)})
    assert main(["odometry", str(robot), str(bag)]) == 2
    err = capsys.readouterr().err.splitlines()
    said = [line.removeprefix("wmrkit: warning: ") for line in err if line.startswith("wmrkit: warning: ")]
    assert len(said) == 1 and "choose one with --imu TOPIC" in said[0] and err[-1].startswith("wmrkit: error: ")
    code, answer, stderr = _batch(capsys, robot, [bag])
    (row,) = answer["rows"]
    assert code == 1 and answer["failed"] == 1 and row["error"] is not None
    assert row["warnings"] == said[0] and answer["warnings"] == [f"{bag}: {said[0]}"]
    assert f"wmrkit: warning: {bag}: {said[0]}" in stderr.splitlines()


def test_a_weighted_batch_names_its_own_argument_not_another_commands_option(capsys, fleet):
    """``batch_odometry(..., weights={"left": 2})`` on the slipping bag: its warning names the weighted odometry by
    that argument, ``weights=``. Before, "the weighted no-slip (--weight) odometry's heading contradicts the IMU":
    ``--weight`` is ``wmrkit odometry``'s option, which ``wmrkit batch odometry`` does not have. Every option a
    warning names is one of its command's (``wmrkit odometry --weight`` still names ``--weight``)."""
    from cli_options import options
    from wmrkit.batch import batch_odometry

    robot, (slips, _, _), _ = fleet
    commands = {words: {o for w, a in options() if w == words for o in a.option_strings}
                for words in (("odometry",), ("batch", "odometry"))}
    (row,) = batch_odometry(load_robot_file(robot), [slips], weights={"left": 2.0}).rows
    assert row["warnings"].startswith("the weighted no-slip (weights=) odometry's heading contradicts the IMU")
    assert set(re.findall(r"--[a-z][a-z-]*", row["warnings"])) <= commands[("batch", "odometry")]
    code, answer, _ = _batch(capsys, robot, [slips])
    assert code == 0 and set(re.findall(r"--[a-z][a-z-]*", answer["rows"][0]["warnings"])) <= commands[
        ("batch", "odometry")]
    single = _single(capsys, robot, slips, "--weight", "left=2")
    assert "weighted no-slip (--weight)" in single["warnings"][0]
    assert set(re.findall(r"--[a-z][a-z-]*", " ".join(single["warnings"]))) <= commands[("odometry",)]


@pytest.mark.parametrize("mount", [(), ("0", "0", "0"), ("180deg", "5deg", "0.3")])
def test_an_imu_mount_is_the_one_wmrkit_odometry_uses(capsys, fleet, mount):
    """``--imu-mount ROLL PITCH YAW`` mounts each bag's IMU as ``wmrkit odometry --imu-mount`` does: the same lines
    and verdict, and ``imu_mount`` says where the mounting came from (the option, else level: these bags have no
    /tf_static). Before, batch odometry had no --imu-mount and its rows did not say the mounting."""
    from wmrkit.odometry.imu_mount import ASSUMED_LEVEL

    robot, (slips, clean, _), _ = fleet
    given = ("--imu-mount", *mount) if mount else ()
    code, answer, _ = _batch(capsys, robot, [slips, clean], *given)
    assert code == 0
    for row, bag in zip(answer["rows"], (slips, clean), strict=True):
        single = _single(capsys, robot, bag, *given)
        assert row["imu_mount"] == single["imu_mount"] == ("--imu-mount" if mount else ASSUMED_LEVEL)
        assert (row["warnings"], row["consistent"]) == ("; ".join(single["warnings"]) or None, single["consistent"])
