"""Batch odometry, serially: rows against the in-memory pipeline, failures, resume, Parquet, log expansion."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

from wmrkit.batch.engine import BatchError
from wmrkit.batch.fleet import SUMMARY_SCHEMA, batch_odometry, expand_logs
from wmrkit.batch.parquet import RowSink, parts_dir, read_rows, write_rows
from wmrkit.odometry.bags import write_joint_states
from wmrkit.odometry.logs import load_csv
from wmrkit.odometry.pipeline import odometry
from wmrkit.odometry.trajectories import read_tum

pq = pytest.importorskip("pyarrow.parquet")


def test_rows_match_the_in_memory_pipeline(fleet_dir, diff, tmp_path):
    out = tmp_path / "res.parquet"
    res = batch_odometry(diff, [fleet_dir], out=out, closed=True, trajectories=tmp_path)
    assert len(res.rows) == 6 and res.failed == 1 and res.skipped == 0
    for row in res.rows:
        if row["error"]:
            assert row["log"].endswith("broken.csv") and "repeats the previous sample" in row["error"]
            assert row["x"] is None and row["trajectory"] is None
            continue
        log = load_csv(row["log"], ("left.spin", "right.spin"))
        traj = odometry(diff, log)
        x, y, th = traj.poses[-1]
        assert (row["x"], row["y"], row["theta"]) == pytest.approx((x, y, th), abs=1e-12)
        assert row["duration"] == pytest.approx(log.time[-1] - log.time[0])
        dq = np.diff(log.positions, axis=0)  # wheel travel: the body moves r (dq_left + dq_right) / 2 per step
        assert row["path_length"] == pytest.approx(np.sum(np.abs(0.075 * dq.sum(axis=1) / 2)), rel=1e-9)
        assert row["closure_error"] == pytest.approx(math.hypot(x, y))
        assert row["closure_heading"] == pytest.approx(math.remainder(th, 2 * math.pi), abs=1e-12)
        assert row["samples"] == len(log) and row["max_slip"] == 0.0  # a differential drive cannot see slip
        _, poses = read_tum(row["trajectory"])
        np.testing.assert_allclose(poses[:, :2], traj.poses[:, :2], atol=1e-9)
    table = pq.read_table(out)
    assert table.schema.names == [n for n, _ in SUMMARY_SCHEMA] and table.num_rows == 6
    assert not parts_dir(out).exists()
    units = {f.name: (f.metadata or {}).get(b"unit", b"").decode() for f in table.schema}  # as the sweep's table
    assert {k: units[k] for k in ("x", "theta", "duration", "path_length", "closure_heading", "max_slip")} == {
        "x": "m", "theta": "rad", "duration": "s", "path_length": "m", "closure_heading": "rad", "max_slip": "m"}
    assert units["log"] == "" and units["samples"] == ""


def test_rerun_resumes_and_retries_failures(fleet_dir, diff, tmp_path):
    out = tmp_path / "res.parquet"
    first = batch_odometry(diff, [fleet_dir / "*.csv"], out=out, trajectories=tmp_path)
    again = batch_odometry(diff, [fleet_dir / "*.csv"], out=out, trajectories=tmp_path)
    assert again.skipped == 5 and again.failed == 1
    kept = [r["wall_time"] for r in first.rows if not r["error"]]
    assert [r["wall_time"] for r in again.rows if not r["error"]] == kept
    os.remove(first.rows[-1]["trajectory"])  # a missing trajectory is redone
    third = batch_odometry(diff, [fleet_dir / "*.csv"], out=out, trajectories=tmp_path)
    assert third.skipped == 4 and os.path.exists(first.rows[-1]["trajectory"])
    other = batch_odometry(diff, [fleet_dir / "*.csv"], out=out, method="euler")  # other options: all redone
    assert other.skipped == 0


def test_a_table_from_before_the_wall_time_rename_is_redone(fleet_dir, diff, tmp_path):
    """Each row's wall time [s] is the column 'wall_time' (sweep and park say so too); a table written when it was
    'seconds' is of this command but lacks the column: it is redone, not resumed nor refused."""
    out = tmp_path / "old.parquet"
    old = tuple(("seconds", kind) if name == "wall_time" else (name, kind) for name, kind in SUMMARY_SCHEMA)
    first = batch_odometry(diff, [fleet_dir], out=tmp_path / "ref.parquet")
    write_rows(out, [{("seconds" if k == "wall_time" else k): v for k, v in r.items()} for r in first.rows], old)
    res = batch_odometry(diff, [fleet_dir], out=out)
    assert res.skipped == 0 and all(r["wall_time"] > 0 for r in res.rows)
    assert pq.read_table(out).schema.names == [n for n, _ in SUMMARY_SCHEMA]


def test_resume_from_the_parts_of_an_interrupted_run(fleet_dir, diff, tmp_path):
    out = tmp_path / "res.parquet"
    full = batch_odometry(diff, [fleet_dir], out=tmp_path / "ref.parquet")
    sink = RowSink(out, SUMMARY_SCHEMA)  # a run that stopped after two logs left only its part file
    for row in full.rows[1:3]:
        sink.add(row)
    sink.flush()
    assert not out.exists() and len(read_rows(out)) == 2
    res = batch_odometry(diff, [fleet_dir], out=out)
    assert res.skipped == 2
    strip = lambda rows: [{k: v for k, v in r.items() if k != "wall_time"} for r in rows]  # noqa: E731
    assert strip(res.rows) == strip(full.rows)
    assert not parts_dir(out).exists() and len(read_rows(out)) == 6


def test_expand_logs_and_bags(fleet_dir, diff, tmp_path):
    log = load_csv(fleet_dir / "run0.csv", ("left.spin", "right.spin"))
    bag = tmp_path / "bags" / "run0_bag"
    bag.parent.mkdir()
    write_joint_states(bag, log)
    assert expand_logs([tmp_path / "bags"]) == [str(bag)]
    assert expand_logs([fleet_dir / "run[01].csv", fleet_dir / "run0.csv"]) == [str(fleet_dir / "run0.csv"),
                                                                                str(fleet_dir / "run1.csv")]
    res = batch_odometry(diff, [bag, fleet_dir / "run0.csv"])
    assert res.failed == 0 and res.rows[0]["x"] == pytest.approx(res.rows[1]["x"], abs=1e-9)
    with pytest.raises(BatchError, match="no file matches"):
        expand_logs([tmp_path / "nothing*.csv"])
    with pytest.raises(BatchError, match="no such file"):
        expand_logs([tmp_path / "missing.csv"])
    with pytest.raises(BatchError, match="does not exist"):
        batch_odometry(diff, [fleet_dir], out=tmp_path / "nope" / "r.parquet")
    (tmp_path / "a-file").write_text("")
    with pytest.raises(BatchError, match="a-file: cannot make the folder"):
        batch_odometry(diff, [fleet_dir], trajectories=tmp_path / "a-file")


def test_the_trajectories_folder_is_made_when_missing(fleet_dir, diff, tmp_path, capsys):
    """docs/batch.md's command with '--trajectories traj/' failed 'no such folder' (after starting the cluster),
    while every other output folder of the CLI (analyze --report) is made with its parents."""
    from wmrkit.cli.main import main

    res = batch_odometry(diff, [fleet_dir / "run0.csv"], trajectories=tmp_path / "made" / "here")
    assert res.failed == 0 and (tmp_path / "made" / "here" / "run0.tum").is_file()
    assert main(["batch", "odometry", "diff-drive", str(fleet_dir / "run1.csv"), "--workers", "0",
                 "--trajectories", str(tmp_path / "traj")]) == 0
    assert (tmp_path / "traj" / "run1.tum").is_file()


def test_each_log_is_read_as_its_header_says(fleet_dir, diff, tmp_path):
    """A log whose header gives its units ('time [ms]', 'left.spin [rad/s]'), as 'wmrkit odometry' reads it: batch
    odometry failed on it ("missing column 'time' (did you mean 'time [s]'?)"), and so did the README's
    example on the forklift log the example script writes. Fleet calibration reads it the same way."""
    from wmrkit.batch.calibrate import load_run
    from wmrkit.odometry.logs import LogFormat, write_csv

    log = load_csv(fleet_dir / "run0.csv", ("left.spin", "right.spin"))
    units = tmp_path / "units.csv"
    rates = np.gradient(log.positions, log.time, axis=0)  # velocities, integrated by the trapezoidal rule
    write_csv(units, ("time [ms]", "left.spin [rad/s]", "right.spin [rad/s]"), np.column_stack([1e3 * log.time, rates]))
    velocity = tmp_path / "velocity.csv"
    write_csv(velocity, ("time", "left.spin", "right.spin"), np.column_stack([log.time, rates]))
    plain = batch_odometry(diff, [velocity], fmt=LogFormat(spin="velocity")).rows[0]
    (row,) = batch_odometry(diff, [units]).rows
    assert row["error"] is None
    assert (row["x"], row["y"], row["theta"]) == pytest.approx((plain["x"], plain["y"], plain["theta"]), abs=1e-9)
    (row,) = batch_odometry(diff, [units], header={"time_unit": "s"}).rows  # an option against the header
    assert "the header says --time-unit ms, the option says s" in row["error"]
    run = load_run(diff, str(units), closed=True)
    want = load_csv(velocity, ("left.spin", "right.spin"), LogFormat(spin="velocity"))
    np.testing.assert_allclose(run.log.time, want.time, atol=1e-12)
    np.testing.assert_allclose(run.log.positions, want.positions, atol=1e-9)


def test_a_rerun_with_other_settings_redoes_the_logs(fleet_dir, diff, tmp_path):
    """Rows were reused on the robot's name and the method alone: a rerun with a calibrated robot of the same name
    returned the old geometry's poses, and one with closed=True rows without a closure error."""
    from wmrkit.odometry.calibration import apply_parameters

    out, logs = tmp_path / "res.parquet", [fleet_dir / "run0.csv", fleet_dir / "run1.csv"]
    batch_odometry(diff, logs, out=out)
    bigger = apply_parameters(diff, ["left.r", "right.r"], [0.05, 0.05])
    assert bigger.name == diff.name
    res = batch_odometry(bigger, logs, out=out)
    want = odometry(bigger, load_csv(logs[0], ("left.spin", "right.spin"))).poses[-1]
    assert res.skipped == 0 and (res.rows[0]["x"], res.rows[0]["y"]) == pytest.approx(tuple(want[:2]), abs=1e-12)
    closed = batch_odometry(bigger, logs, out=out, closed=True)
    assert closed.skipped == 0 and all(r["closure_error"] is not None for r in closed.rows)
    assert batch_odometry(bigger, logs, out=out, closed=True).skipped == 2
    stat = os.stat(logs[1])  # a log recorded again under the same name is redone
    os.utime(logs[1], ns=(stat.st_atime_ns, stat.st_mtime_ns + 10**9))
    assert batch_odometry(bigger, logs, out=out, closed=True).skipped == 1


def test_an_output_file_of_another_kind_is_refused(fleet_dir, diff, tmp_path):
    """A sweep's table given as --out was replaced without a word; one whose columns have other types failed
    with pyarrow's traceback (ArrowInvalid)."""
    pa = pytest.importorskip("pyarrow")
    other = tmp_path / "sweep.parquet"
    pq.write_table(pa.table({"index": [0, 1], "metric": [1.0, 2.0]}), other)
    for resume in (True, False):
        with pytest.raises(BatchError, match=r"sweep.parquet: not a table of this command \(no column 'log'"):
            batch_odometry(diff, [fleet_dir / "run0.csv"], out=other, resume=resume)
    assert pq.read_table(other).column_names == ["index", "metric"]
    typed = tmp_path / "typed.parquet"
    pq.write_table(pa.table({"log": [str(fleet_dir / "run0.csv")], "robot": ["diff-drive"], "method": ["exact"],
                             "x": ["oops"], "error": pa.array([None], pa.string()),
                             "trajectory": pa.array([None], pa.string())}), typed)
    with pytest.raises(BatchError, match=r"typed\.parquet: column 'x' is string, expected double"):
        batch_odometry(diff, [fleet_dir / "run0.csv"], out=typed)


def test_an_empty_folder_and_a_log_given_twice(fleet_dir, diff, tmp_path):
    """A folder without logs gave '0 logs: 0 done' and exit 0; one log under two spellings ran twice, both runs
    writing the same trajectory file."""
    (tmp_path / "empty").mkdir()
    with pytest.raises(BatchError, match="empty: no logs in the folder"):
        expand_logs([tmp_path / "empty"])
    with pytest.raises(BatchError, match="no logs given"):
        batch_odometry(diff, [])
    twice = [str(fleet_dir / "run0.csv"), os.path.join(str(fleet_dir), ".", "run0.csv")]
    assert expand_logs(twice) == twice[:1]
    res = batch_odometry(diff, twice, trajectories=tmp_path / "traj")
    assert len(res.rows) == 1 and res.failed == 0


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs Linux's /proc (a folder no one can write into)")
def test_a_table_that_cannot_be_written_is_named():
    """pyarrow's error carries no file name, so the command ended in a traceback (sweep --out)."""
    from wmrkit.batch.parquet import write_rows

    with pytest.raises(BatchError, match=r"/proc/x\.parquet: cannot write the table"):
        write_rows("/proc/x.parquet", [{"log": "a"}], [("log", "string")])


def test_the_slip_threshold_must_be_a_length(fleet_dir, diff):
    """slip_warning=nan never warned, and -1 flagged every log ('slip indicator up to 0 m per interval (threshold
    -1 m)')."""
    for bad in (float("nan"), -1.0, math.inf):
        with pytest.raises(BatchError, match="slip_warning must be a finite length >= 0 m"):
            batch_odometry(diff, [fleet_dir / "run0.csv"], slip_warning=bad)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs named pipes")
def test_a_named_pipe_is_refused_not_waited_on(diff, tmp_path):
    """A FIFO given as a log: its reader waited for a writer forever (the batch hung, serially or on a worker)."""
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    with pytest.raises(BatchError, match=r"pipe\.csv: not a regular file or folder"):
        batch_odometry(diff, [fifo])


def test_an_output_that_is_a_folder_is_refused_before_the_work(fleet_dir, diff, tmp_path, monkeypatch):
    """batch_odometry(out=FOLDER) ran every log and then failed to write the table ('Is a directory')."""
    import wmrkit.batch.fleet as fleet

    monkeypatch.setattr(fleet, "process_log", lambda job: pytest.fail("a log was processed"))
    with pytest.raises(BatchError, match="a folder, not a file"):
        batch_odometry(diff, [fleet_dir / "run0.csv"], out=tmp_path)



def test_a_file_in_the_place_of_the_parts_folder_is_refused_before_the_work(fleet_dir, diff, tmp_path, monkeypatch):
    """A file named OUT.parts made the batch run every log and then fail ('OUT.parts: File exists'): the work lost."""
    import wmrkit.batch.fleet as fleet

    (tmp_path / "r.parquet.parts").write_text("")
    monkeypatch.setattr(fleet, "process_log", lambda job: pytest.fail("a log was processed"))
    with pytest.raises(BatchError, match=r"r\.parquet\.parts is a file; the batch keeps its part files"):
        batch_odometry(diff, [fleet_dir / "run0.csv"], out=tmp_path / "r.parquet")


def test_one_path_where_a_sequence_is_expected_is_refused(diff, fleet_dir, calibration_data):
    """batch_odometry(robot, 'logs/') read the logs 'l', 'o', 'g', ... ('l: no such file or folder'), a Path
    raised TypeError ('PosixPath' object is not iterable), and load_runs(robot, 'run.csv', ...) looked for the
    reference l.tum."""
    from pathlib import Path

    from wmrkit.batch.calibrate import load_runs

    for logs in (str(fleet_dir), Path(fleet_dir)):
        with pytest.raises(BatchError, match=r"logs: expected a sequence of files, globs or folders, got the single "
                                             rf"path '{fleet_dir}' \(write \['{fleet_dir}'\]\)"):
            batch_odometry(diff, logs)
    with pytest.raises(BatchError, match=r"paths: expected a sequence .* single path '.*c0\.csv'"):
        load_runs(diff, str(calibration_data / "c0.csv"), reference_dir=calibration_data / "ref")


def test_a_log_whose_name_is_not_utf8_is_written_and_resumed(fleet_dir, diff, tmp_path):
    """A log named with a byte that is not UTF-8 (an old Latin-1 file system) ended the batch in pyarrow's
    UnicodeEncodeError when its row was written to --out (a traceback after the work); with --trajectories, two
    such logs of one name in two folders raised it when their trajectory names were made."""
    logs = []
    for sub in ("a", "b"):
        folder = os.fsencode(tmp_path / sub)
        os.mkdir(folder)
        with open(os.path.join(folder, b"cami\xf3n.csv"), "wb") as f:
            f.write((fleet_dir / "run0.csv").read_bytes())
        logs.append(os.fsdecode(os.path.join(folder, b"cami\xf3n.csv")))
    out = tmp_path / "res.parquet"
    first = batch_odometry(diff, logs, out=out, trajectories=tmp_path / "traj")
    assert first.failed == 0 and len(first.rows) == 2
    assert len({r["trajectory"] for r in first.rows}) == 2 and all(os.path.exists(r["trajectory"]) for r in first.rows)
    table = pq.read_table(out).to_pylist()
    assert [r["log"] for r in table] == [log.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
                                         for log in logs]  # the byte shown as an escape: cami\xf3n.csv
    assert table[0]["x"] == first.rows[0]["x"]
    again = batch_odometry(diff, logs, out=out, trajectories=tmp_path / "traj")
    assert again.skipped == 2 and [r["x"] for r in again.rows] == [r["x"] for r in first.rows]


def test_a_link_to_nothing_is_named_so(tmp_path):
    """A link in a loop (or to a missing file) was 'no such file or folder', though ls lists it."""
    (tmp_path / "loop.csv").symlink_to("loop.csv")
    (tmp_path / "gone.csv").symlink_to(tmp_path / "missing.csv")
    for name in ("loop.csv", "gone.csv"):
        with pytest.raises(BatchError, match=rf"{name}: a symbolic link to nothing \(its target is missing, or a loop"):
            expand_logs([tmp_path / name])
    with pytest.raises(BatchError, match=r"missing\.csv: no such file or folder"):
        expand_logs([tmp_path / "missing.csv"])


def test_a_bag_that_cannot_be_read_is_its_error_alone(diff, tmp_path):
    """An unreadable bag (a .db3 that is not a database) failed, and its row's warnings repeated the error as the IMU
    note ('x.db3: x.db3: cannot read as a ROS 2 bag (...) (the odometry is not checked against it)'), printed as a
    warning too; 'wmrkit odometry' says the error alone."""
    (tmp_path / "x.db3").write_text("not sqlite")
    row = batch_odometry(diff, [tmp_path / "x.db3"]).rows[0]
    assert row["error"].startswith(f"{tmp_path / 'x.db3'}: cannot read as a ROS 2 bag") and row["warnings"] is None
