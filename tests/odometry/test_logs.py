"""CSV logs in (formats, chunks, validation with located errors) and trajectories out (CSV, TUM)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.odometry.encoders import IncrementalEncoder, catalog_encoders
from wmrkit.odometry.logs import JointLog, LogError, LogFormat, concatenate, load_csv, read_csv, write_csv
from wmrkit.odometry.pipeline import odometry
from wmrkit.odometry.synthetic import TwistProfile, simulate
from wmrkit.odometry.trajectories import (
    Trajectory,
    TrajectoryWriter,
    quaternion_z,
    read_trajectory_csv,
    read_tum,
    write_trajectory,
    yaw_of_quaternion,
)

JOINTS = ("left.spin", "right.spin")
WHEELS = ("left", "right", "caster")


def _write(path, header, rows):
    path.write_text(header + "\n" + "".join(r + "\n" for r in rows))
    return str(path)


@pytest.mark.parametrize("chunk", [1, 7, 1 << 16])
def test_csv_round_trip_in_any_chunk_size(diff_csv, diff_run, chunk):
    chunks = list(read_csv(diff_csv, JOINTS, chunk_size=chunk))
    assert len(chunks) == math.ceil(len(diff_run.log) / chunk)
    log = concatenate(chunks)
    np.testing.assert_array_equal(log.time, diff_run.log.time)
    np.testing.assert_array_equal(log.positions, diff_run.log.positions)  # %.17g round-trips exactly
    assert chunks[-1].first_line == 2 + chunk * (len(chunks) - 1)


def test_renamed_columns_time_unit_and_column_order(tmp_path, diff_run, write_log):
    path = write_log(tmp_path / "r.csv", diff_run, names=("t_ms", "enc_l", "enc_r"))
    raw = np.column_stack([diff_run.log.time * 1000, diff_run.log.positions])
    write_csv(path, ("t_ms", "enc_r", "enc_l"), raw[:, [0, 2, 1]])
    fmt = LogFormat(time_column="t_ms", time_unit="ms", columns=(("left.spin", "enc_l"), ("right.spin", "enc_r")))
    log = load_csv(path, JOINTS, fmt)
    np.testing.assert_allclose(log.time, diff_run.log.time, rtol=1e-15)
    np.testing.assert_array_equal(log.positions, diff_run.log.positions)


def test_counts_with_a_wrapping_16_bit_counter(tmp_path):
    """Forklift encoders (8290 pulses/rev) on 16-bit counters: the counters wrap during the run."""
    robot = catalog.load("forklift")
    enc = {**catalog_encoders("forklift"), "right_drive.spin": IncrementalEncoder(8290, bits=16),
           "left_drive.spin": IncrementalEncoder(8290, bits=16)}
    profile = TwistProfile.from_segments([(30.0, 1.0, 0.0, 0.0)])  # 30 m: 172000 counts, the counter wraps twice
    run = simulate(robot, profile, 10.0, encoders=enc)
    joints = run.log.joints
    counts = np.column_stack([run.counts[j] for j in joints])
    assert counts[:, 0].max() < 65536 and np.any(np.diff(counts[:, 0]) < 0)
    path = str(tmp_path / "counts.csv")
    write_csv(path, ("time", *joints), np.column_stack([run.log.time, counts]), fmt="%.10g")
    fmt = LogFormat(spin="counts", steer="counts", encoders=tuple(enc.items()))
    log = load_csv(path, joints, fmt, robot=robot)
    np.testing.assert_allclose(log.positions[:, :2], run.log.positions[:, :2] - run.log.positions[0, :2],
                               rtol=0, atol=1e-9)
    np.testing.assert_allclose(log.positions[:, 2], run.log.positions[:, 2], atol=1e-12)
    traj = odometry(robot, log)
    assert traj.final_pose[0] == pytest.approx(30.0, abs=2 * math.pi * 0.23 / 8290 * 2)  # within two counts


def test_velocity_logs_are_integrated_by_the_trapezoidal_rule(tmp_path):
    t = np.linspace(0, 2, 41)
    rates = np.column_stack([1.0 + 0.5 * t, 2.0 - 0.25 * t])  # linear rates: trapezoids are exact
    path = _write(tmp_path / "v.csv", "time,left.spin,right.spin", [f"{a!r},{b!r},{c!r}" for a, b, c in
                                                                    np.column_stack([t, rates]).tolist()])
    for chunk in (3, 100):
        log = concatenate(list(read_csv(path, JOINTS, LogFormat(spin="velocity"), chunk_size=chunk)))
        np.testing.assert_allclose(log.positions[:, 0], t + 0.25 * t**2, atol=1e-13)
        np.testing.assert_allclose(log.positions[:, 1], 2 * t - 0.125 * t**2, atol=1e-13)


def test_heading_and_gyro_columns(tmp_path):
    t = np.linspace(0, 4, 81)
    yaw = 0.9 * t  # passes +pi: the IMU column wraps
    wrapped = (yaw + math.pi) % (2 * math.pi) - math.pi
    rows = [f"{a!r},0,0,{b!r},0.9" for a, b in zip(t.tolist(), wrapped.tolist(), strict=True)]
    path = _write(tmp_path / "h.csv", "time,left.spin,right.spin,yaw,gyro_z", rows)
    for chunk in (5, 1000):
        log = concatenate(list(read_csv(path, JOINTS, LogFormat(heading_column="yaw"), chunk_size=chunk)))
        np.testing.assert_allclose(log.heading_world, yaw, atol=1e-12)
        log = concatenate(list(read_csv(path, JOINTS, LogFormat(gyro_column="gyro_z"), chunk_size=chunk)))
        np.testing.assert_allclose(log.heading_world, yaw, atol=1e-12)


@pytest.mark.parametrize(("header", "rows", "fmt", "message"), [
    ("time,left.spin,right.spin", ["0,0,0", "0.1,1,1", "0.1,2,2"], LogFormat(),
     r"x\.csv:4: time 0\.1 s repeats the previous sample \(a zero time step\)"),
    ("time,left.spin,right.spin", ["0,0,0", "0.2,1,1", "0.1,2,2"], LogFormat(),
     r"x\.csv:4: time 0\.1 s goes backwards"),
    ("time,left.spin,right.spin", ["0,0,0", "0.1,nan,1"], LogFormat(),
     r"x\.csv:3: column 'left\.spin': value nan is not a finite number \(field 2\)"),
    # the gyro's column was called 'heading', and neither it nor the time's was named as a column (--json: no field)
    ("time,left.spin,right.spin,gz", ["0,0,0,0", "0.1,1,1,nan"], LogFormat(gyro_column="gz"),
     r"x\.csv:3: column 'gz': value nan is not a finite number"),
    ("stamp,left.spin,right.spin", ["0,0,0", "inf,1,1"], LogFormat(time_column="stamp"),
     r"x\.csv:3: column 'stamp': value inf is not a finite number"),
    ("time,left.spin,right.spin", ["0,0,0", "0.1,,1"], LogFormat(),
     r"x\.csv:3: column 'left\.spin': cannot read '' as a number \(field 2\)"),
    ("time,left.spin,right.spin", ["0,0,0", "0.1,1"], LogFormat(), r"x\.csv:3: expected 3 fields, got 2"),
    ("time,left.spin,right.spin", ["0,0,0", "0.1,abc,1"], LogFormat(),
     r"x\.csv:3: column 'left\.spin': cannot read 'abc'"),
    ("time,left.spin,rigth.spin", ["0,0,0"], LogFormat(),
     r"x\.csv:1: column 'rigth\.spin' names no wheel of the robot \(did you mean 'right\.spin'\?\) \(wheels: left, "
     r"right, caster\)"),
    ("time,lefft.spin,right.spin", ["0,0,0"], LogFormat(),  # a misspelt wheel got no hint
     r"x\.csv:1: column 'lefft\.spin' names no wheel of the robot \(did you mean 'left\.spin'\?\) \(wheels: "),
    ("time,front_left.spin,left.spin,right.spin", ["0,0,0,0"], LogFormat(),  # another robot's log: no hint
     r"x\.csv:1: column 'front_left\.spin' names no wheel of the robot \(wheels: "),
    ("time,left.spin,right.spin", ["0,0,0"], LogFormat(columns=(("left.spn", "left.spin"),)),
     r"x\.csv: a column is given for 'left\.spn', no joint of the robot \(did you mean 'left\.spin'\?\)"),
    ("time,left.spin,right_spin", ["0,0,0"], LogFormat(),
     r"x\.csv:1: missing column 'right\.spin' \(did you mean 'right_spin'\?\)"),
    ("time,left.spin", ["0,0"], LogFormat(),  # not 'did you mean left.spin', read for the left wheel
     r"x\.csv:1: missing column 'right\.spin' \(columns: 'time, left\.spin'\)"),
    ("t,left.spin,right.spin", ["0,0,0"], LogFormat(), r"x\.csv:1: missing column 'time'"),
    ("time,left.spin,right.spin,left.spin", ["0,0,0,0"], LogFormat(), r"x\.csv:1: column 'left\.spin' appears twice"),
    ("time,left.spin,right.spin", [], LogFormat(), r"x\.csv: no samples after the header"),
    ("time,left.spin,right.spin", ["0,0,0", "0.1,1,1", "5.0,2,2"], LogFormat(max_gap=1.0),
     r"x\.csv:4: time step of 4\.9 s exceeds max_gap = 1 s \(a gap\)"),
    ("time,left.spin,right.spin", ["0,0,0", "0.1,70000,1"],
     LogFormat(spin="counts", encoders=(("left.spin", IncrementalEncoder(100, bits=16)),
                                        ("right.spin", IncrementalEncoder(100, bits=16)))),
     r"column 'left\.spin': count 70000 outside the 16-bit unsigned counter range"),
    ("time,left.spin,right.spin", ["0,0,0"], LogFormat(spin="counts"),
     r"joint 'left\.spin' is logged as counts but has no IncrementalEncoder"),
])
def test_bad_logs_are_refused_with_their_location(tmp_path, header, rows, fmt, message):
    path = _write(tmp_path / "x.csv", header, rows)
    with pytest.raises(LogError, match=message):
        load_csv(path, JOINTS, fmt, wheels=WHEELS)


def test_errors_in_later_chunks_name_the_right_line(tmp_path):
    rows = [f"{0.1 * k!r},{k},{k}" for k in range(50)]
    rows[37] = "3.6,nan,1"
    path = _write(tmp_path / "x.csv", "time,left.spin,right.spin", rows)
    with pytest.raises(LogError, match=r"x\.csv:39: column 'left\.spin'"):
        list(read_csv(path, JOINTS, chunk_size=8))


@pytest.mark.parametrize("chunk", [1, 8, 1 << 16])
@pytest.mark.parametrize(("bad", "message"), [
    ("70000", r"column 'right\.spin': count 70000 outside the 16-bit unsigned counter range"),
    ("12.5", r"column 'right\.spin': counts must be whole numbers, got 12\.5"),
    ("1e300", r"column 'right\.spin': counts beyond 2\*\*53"),
])
def test_bad_counts_name_their_line(tmp_path, chunk, bad, message):
    """Counts outside the counter, fractional or beyond 2**53 were refused naming the column but not the line."""
    rows = [f"{0.1 * k!r},{k},{k}" for k in range(50)]
    rows[37] = f"3.7,37,{bad}"
    path = _write(tmp_path / "x.csv", "time,left.spin,right.spin", rows)
    enc = IncrementalEncoder(100, bits=16)
    fmt = LogFormat(spin="counts", encoders=(("left.spin", enc), ("right.spin", enc)))
    with pytest.raises(LogError, match=r"x\.csv:39: " + message):
        list(read_csv(path, JOINTS, fmt, chunk_size=chunk))


def test_bad_steering_counts_name_their_line(tmp_path):
    robot = catalog.load("forklift")
    joints = ("right_drive.spin", "left_drive.spin", "steer.steer")
    rows = [f"{0.1 * k!r},{k},{k},0" for k in range(20)]
    rows[11] = "1.1,11,11,2.5"  # an angle in a counts column
    path = _write(tmp_path / "f.csv", "time," + ",".join(joints), rows)
    fmt = LogFormat(spin="counts", steer="counts", encoders=tuple(catalog_encoders("forklift").items()))
    for chunk in (3, 1 << 16):
        with pytest.raises(LogError, match=r"f\.csv:13: column 'steer\.steer': counts must be whole numbers, got "
                                           r"2\.5"):
            list(read_csv(path, joints, fmt, robot=robot, chunk_size=chunk))


def test_missing_and_empty_files(tmp_path):
    with pytest.raises(LogError, match=r"nope\.csv: cannot open"):
        load_csv(tmp_path / "nope.csv", JOINTS)
    (tmp_path / "e.csv").write_text("")
    with pytest.raises(LogError, match=r"e\.csv:1: empty file"):
        load_csv(tmp_path / "e.csv", JOINTS)


def test_log_format_and_value_checks():
    with pytest.raises(LogError, match="unknown time unit 'min'"):
        LogFormat(time_unit="min")
    with pytest.raises(LogError, match="not both"):
        LogFormat(heading_column="a", gyro_column="b")
    with pytest.raises(LogError, match="max_gap must be > 0"):
        LogFormat(max_gap=0)
    with pytest.raises(LogError, match=r"expected time \(N,\) and positions \(N, 2\)"):
        JointLog(np.zeros(3), JOINTS, np.zeros((3, 3)))
    log = JointLog(np.zeros(3), JOINTS, np.zeros((3, 2)), source="mem")
    with pytest.raises(LogError, match=r"mem: no samples of joint 'steer\.steer'"):
        log.select(["steer.steer"])


def test_quaternions_and_yaw():
    theta = np.array([0.0, 0.5, -2.0, math.pi - 1e-9, 4.0])
    q = quaternion_z(theta)
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1.0)
    np.testing.assert_allclose(np.remainder(yaw_of_quaternion(q) - theta + math.pi, 2 * math.pi) - math.pi, 0,
                               atol=1e-12)
    scipy_rot = pytest.importorskip("scipy.spatial.transform").Rotation
    np.testing.assert_allclose(q, scipy_rot.from_euler("z", theta[:, None]).as_quat(), atol=1e-15)


def test_yaw_of_any_nonzero_quaternion_is_scipys():
    """The yaw of quaternions of any attitude and any nonzero norm (1e-3 .. 1e200) is the Z angle of scipy's ZYX
    Euler angles of the normalised quaternion; the unit-only form got a scaled one wrong."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(3)
    q = rng.normal(size=(200, 4))
    expected = Rotation.from_quat(q).as_euler("ZYX")[:, 0]  # scipy normalises, (x, y, z, w) order as ours
    for scale in (1e-3, 1.0, 7.5, 1e200):
        np.testing.assert_allclose(yaw_of_quaternion(q * scale), expected, atol=1e-12)


def test_a_tum_file_reads_quaternions_of_any_finite_norm_without_a_python_warning(tmp_path):
    """Quaternions beyond 1e154 (their squared norm overflows) printed numpy's 'RuntimeWarning: overflow encountered
    in multiply' and its source line on stderr before `calibrate`'s answer. Their yaw is that of the normalised
    quaternion, and the zero test still refuses a quaternion of norm below 1e-6 (and only those)."""
    import warnings

    from scipy.spatial.transform import Rotation

    q = np.random.default_rng(5).normal(size=(6, 4))
    expected = Rotation.from_quat(q).as_euler("ZYX")[:, 0]
    tum = tmp_path / "t.tum"
    for scale in (1e-6, 1e200, 1e307):
        rows = q * (scale / np.abs(q).max(axis=1, keepdims=True))  # each row's largest component: 'scale'
        tum.write_text("".join(f"{k} {k} 0 0 {' '.join(repr(float(v)) for v in row)}\n" for k, row in enumerate(rows)))
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            _, pose = read_tum(tum)
        np.testing.assert_allclose(np.angle(np.exp(1j * (pose[:, 2] - expected))), 0, atol=1e-12)
    for row, zero in (("0 0 0 1e-300", True), ("4.9e-7 4.9e-7 4.9e-7 4.9e-7", True), ("5.1e-7 5e-7 5e-7 5e-7", False),
                      ("1e308 1e308 1e308 1e308", False)):  # norms 1e-300, 9.8e-7, 1.0005e-6, 2e308
        tum.write_text(f"0 0 0 0 {row}\n1 1 0 0 0 0 0 1\n")
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            if zero:
                with pytest.raises(LogError, match=r"t.tum:1: the quaternion is \(almost\) zero"):
                    read_tum(tum)
            else:
                read_tum(tum)


def test_trajectory_files_with_non_finite_values_are_refused_at_their_line_and_column(tmp_path):
    tum = tmp_path / "t.tum"
    tum.write_text("# t x y z qx qy qz qw\n0 0 0 0 0 0 0 1\n1 1 0 0 0 0 inf 1\n")
    with pytest.raises(LogError, match=r"t\.tum:3: column 'qz': value inf is not a finite number$"):
        read_tum(tum)
    csv = tmp_path / "t.csv"
    csv.write_text("time,x,y,theta,slip\n0,0,0,0,0\n1,1,0,nan,0\n")
    with pytest.raises(LogError, match=r"t\.csv:3: column 'theta': value nan is not a finite number$"):
        read_trajectory_csv(csv)


@pytest.mark.parametrize(("text", "message"), [
    ("time,x,y,theta,slip\n0,1,2\n1,2,3\n", "3 values per row under a header of 5 columns"),  # was IndexError
    ("time,x,y,theta,slip\n0\n1\n", "1 values per row under a header of 5 columns"),  # was a numpy ValueError
    ("time,x,y,theta,slip,cov_xx,cov_xy\n0,1,2,0,0,1,0\n", r":1: expected the columns time,x,y,theta,slip \(and"),
])
def test_trajectory_csv_with_other_columns_is_refused_by_name(tmp_path, text, message):
    """A reference trajectory CSV (batch calibrate) with missing columns failed with numpy errors; a partial
    covariance was dropped silently."""
    csv = tmp_path / "t.csv"
    csv.write_text(text)
    with pytest.raises(LogError, match=r"t\.csv" + ("" if message.startswith(":") else ": ") + message):
        read_trajectory_csv(csv)


def test_trajectory_files_round_trip(tmp_path):
    rng = np.random.default_rng(0)
    n = 30
    a = rng.normal(size=(n, 3, 3)) * 0.1
    traj = Trajectory(np.arange(n) * 0.05 + 1e9, np.cumsum(rng.normal(size=(n, 3)), axis=0), np.abs(rng.normal(size=n)),
                      a @ np.swapaxes(a, -1, -2))
    write_trajectory(tmp_path / "t.csv", traj, "csv")
    back = read_trajectory_csv(tmp_path / "t.csv")
    np.testing.assert_allclose(back.poses, traj.poses, rtol=1e-11)
    np.testing.assert_allclose(back.covariance, traj.covariance, rtol=1e-11)
    np.testing.assert_allclose(back.time, traj.time, atol=1e-9)
    with TrajectoryWriter(tmp_path / "t.tum", "tum") as w:  # written in two chunks
        w.write(Trajectory(traj.time[:10], traj.poses[:10], traj.slip[:10]))
        w.write(Trajectory(traj.time[10:], traj.poses[10:], traj.slip[10:]))
    lines = (tmp_path / "t.tum").read_text().splitlines()
    assert lines[0].startswith("#") and all(len(ln.split(" ")) == 8 for ln in lines[1:])  # what evo reads
    t, poses = read_tum(tmp_path / "t.tum")
    np.testing.assert_allclose(t, traj.time, atol=1e-9)
    np.testing.assert_allclose(poses[:, :2], traj.poses[:, :2], rtol=1e-11)
    np.testing.assert_allclose(np.diff(poses[:, 2]), np.diff(np.unwrap(traj.poses[:, 2])), atol=1e-10)
    with pytest.raises(LogError, match="unknown trajectory format 'kitti'"):
        TrajectoryWriter(tmp_path / "t.x", "kitti")


@pytest.mark.parametrize("chunk_size", [1, 3, 1 << 16])
def test_an_endless_line_is_refused_without_reading_it_whole(tmp_path, chunk_size):
    """A log whose tail is one 'line' of NUL bytes (a logger's preallocated block after a power loss) or digits was
    read whole into memory (200 MB: 1.3 GB resident) before any check; now rows are read in bounded pieces."""
    import tracemalloc

    from wmrkit.odometry._text import MAX_LINE

    path = tmp_path / "tail.csv"
    with open(path, "wb") as f:
        f.write(b"time,left.spin,right.spin\n0,0,0\n0.1,1,1\n")
        f.write(b"\0" * (64 << 20))
    tracemalloc.start()
    try:
        with pytest.raises(LogError, match=rf"tail\.csv:4: a line longer than {MAX_LINE} characters"):
            list(read_csv(path, ("left.spin", "right.spin"), chunk_size=chunk_size))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 100 << 20  # the pieces held before the check (64 MiB of pieces at most), never the whole tail


@pytest.mark.parametrize("sep", [";", "\t", "|"])
def test_another_delimiter_is_named(tmp_path, sep):
    """A semicolon-separated log was refused as "column 'time;left.spin;right.spin' names no wheel of the robot"."""
    path = tmp_path / "sep.csv"
    path.write_text(sep.join(("time", "left.spin", "right.spin")) + "\n" + sep.join("000") + "\n")
    message = rf"sep\.csv:1: one column .*: fields separated by {re.escape(repr(sep))}, not ','"
    with pytest.raises(LogError, match=message):
        list(read_csv(path, ("left.spin", "right.spin"), robot=catalog.load("diff-drive")))


@pytest.mark.parametrize(("call", "message"), [
    # a lone pair raised "too many values to unpack"; a dict the same (its keys were unpacked)
    (lambda: LogFormat(columns=("left.spin", "enc_l")), r"LogFormat\.columns: expected \(joint, column\) pairs"),
    (lambda: LogFormat(encoders=("left.spin", IncrementalEncoder(100))), r"LogFormat\.encoders: expected \(joint, "),
    (lambda: LogFormat(encoders=(("left.spin", 1024),)), r"LogFormat\.encoders: expected \(joint, encoder\) pairs"),
    (lambda: LogFormat(max_gap="1"), r"LogFormat\.max_gap: expected a number or None, got '1'"),  # was a TypeError
    # a lone joint name was read as one joint per letter: "missing column 'l'"
    (lambda: load_csv(__file__, "left.spin"), r"joints: expected a sequence of joint names, got the string "
                                              r"'left\.spin'"),
])
def test_a_log_format_and_joints_of_the_wrong_kind_are_refused_by_name(call, message):
    with pytest.raises(LogError, match=message):
        call()


def test_a_log_format_takes_its_pairs_as_a_mapping(tmp_path):
    path = _write(tmp_path / "x.csv", "time,enc_l,enc_r", ["0,0,0", "0.1,1,2"])
    log = load_csv(path, JOINTS, LogFormat(columns={"left.spin": "enc_l", "right.spin": "enc_r"}))
    np.testing.assert_array_equal(log.positions, [[0, 0], [1, 2]])
    assert LogFormat(columns={"left.spin": "enc_l"}) == LogFormat(columns=(("left.spin", "enc_l"),))


def test_a_header_with_units_read_without_its_format_names_header_format(tmp_path):
    """A log with units in its header (as docs/odometry.md asks, as 'wmrkit simulate --out' writes) given to
    load_csv with the default format said "missing column 'time' (did you mean 'time [s]'?)": no argument can follow
    that hint (the joints are not named with units). The message names header_format, and following it reads the
    log as 'wmrkit odometry' does."""
    from wmrkit.odometry.header import header_format

    robot = catalog.load("diff-drive")
    path = tmp_path / "units.csv"
    write_csv(path, ("time [ms]", "left.spin [rad]", "right.spin [rad]"), np.array([[0, 0, 0], [100, 1, 2.0]]))
    with pytest.raises(LogError, match=r"units\.csv:1: missing column 'time': the header gives its unit \('time "
                                       r"\[ms\]'\); read the units it declares with fmt=header_format\(path, "):
        load_csv(path, ("left.spin", "right.spin"), robot=robot)
    log = load_csv(path, ("left.spin", "right.spin"), header_format(path, robot.name, ("left.spin", "right.spin")),
                   robot=robot)
    np.testing.assert_allclose(log.time, [0.0, 0.1])
    np.testing.assert_allclose(log.positions, [[0, 0], [1, 2]])


def test_trajectory_file_errors_name_the_file_and_line(tmp_path):
    """A zero quaternion, a coordinate too far, a time not increasing were 'FILE: pose N: ...' (N counting poses, not
    the lines of a file with comments and blank lines); now 'FILE:LINE: ...', the line an editor jumps to."""
    tum = tmp_path / "t.tum"
    head = "# timestamp tx ty tz qx qy qz qw\n\n0 0 0 0 0 0 0 1\n# a comment\n"
    for bad, message in (("1 1 0 0 0 0 0 0", r"the quaternion is \(almost\) zero"),
                         ("1 1e300 0 0 0 0 0 1", "a coordinate beyond"),
                         ("0 1 0 0 0 0 0 1", r"time 0\.0 s does not increase")):
        tum.write_text(f"{head}{bad}\n2 2 0 0 0 0 0 1\n")
        with pytest.raises(LogError, match=rf"^{re.escape(str(tum))}:5: {message}"):
            read_tum(tum)
    csv = tmp_path / "t.csv"
    csv.write_text("time,x,y,theta,slip\n0,0,0,0,0\n0,1,0,0,0\n")
    with pytest.raises(LogError, match=rf"^{re.escape(str(csv))}:3: time 0\.0 s does not increase"):
        read_trajectory_csv(csv)
