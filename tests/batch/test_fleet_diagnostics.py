"""``wmrkit batch odometry`` gives each log ``wmrkit odometry``'s diagnostic lines: a log whose wheel slips names the
wheels as the single-log command does (per-wheel slip), one breaking a description's gear says so in its words, a
clean log says nothing; the row's ``warnings`` column, the ``wmrkit: warning: LOG: ...`` lines and the ``--json``
answer's warnings hold exactly the lines of ``wmrkit odometry ROBOT LOG`` (the oracle: the other door, run per log),
and the row's ``consistent`` is that command's ``"consistent"``."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from geared import TWO_ENCODERS as GEARED
from wmrkit import catalog
from wmrkit.batch import fleet
from wmrkit.batch.parquet import parts_dir
from wmrkit.cli.main import main
from wmrkit.odometry import JointLog, simulate, write_log
from wmrkit.odometry.synthetic import TwistProfile


def _single(capsys, robot: str, log) -> list[str]:
    """``wmrkit odometry ROBOT LOG --json``'s warnings (each also said on stderr)."""
    assert main(["odometry", robot, str(log), "--json"]) == 0
    out = capsys.readouterr()
    answer = json.loads(out.out)
    assert [f"wmrkit: warning: {w}" for w in answer["warnings"]] == out.err.splitlines()
    return answer["warnings"]


def _batch(capsys, robot: str, logs) -> tuple[dict, list[str], list[str]]:
    """``wmrkit batch odometry``'s rows' warnings by log, its JSON warnings and its stderr lines (text run)."""
    assert main(["batch", "odometry", robot, *map(str, logs), "--workers", "0", "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    rows = {r["log"]: r["warnings"] for r in answer["rows"]}
    assert main(["batch", "odometry", robot, *map(str, logs), "--workers", "0", "--quiet"]) == 0
    return rows, answer["warnings"], capsys.readouterr().err.splitlines()


def _same_as_single(capsys, robot: str, logs) -> dict[str, list[str]]:
    """Assert that each log's batch diagnostics are its single-log lines; return those lines by log."""
    single = {str(log): _single(capsys, robot, log) for log in logs}
    rows, said, err = _batch(capsys, robot, logs)
    for log, lines in single.items():
        assert rows[log] == ("; ".join(lines) or None), log
    expected = [f"{log}: {'; '.join(lines)}" for log, lines in single.items() if lines]
    assert said == expected
    assert err == [f"wmrkit: warning: {w}" for w in expected]
    return single


def _mecanum_logs(folder) -> list:
    """mecanum-4 driving while its front-left wheel spins 30 % too fast (slips.csv), and the same run clean."""
    robot = catalog.load("mecanum-4")
    profile = TwistProfile.from_segments([(3.0, 0.4, 0.1, 0.2), (2.0, 0.2, -0.2, -0.3)])
    log = simulate(robot, profile, 20.0).log
    write_log(folder / "clean.csv", log, robot)
    positions = log.positions.copy()
    positions[:, log.joints.index("front_left.spin")] *= 1.3
    write_log(folder / "slips.csv", JointLog(log.time, log.joints, positions), robot)
    return [folder / "slips.csv", folder / "clean.csv"]


def test_a_slipping_wheel_is_named_per_log_as_odometry_names_it(capsys, tmp_path):
    """mecanum-4 driving while its front-left wheel spins 30 % too fast, beside the clean log. Before, the batch row
    said 'slip indicator up to ... m per interval (threshold 0.01 m)' (its own absolute rule) where ``wmrkit
    odometry`` says 'the sensed joints contradict each other: ... (slip per wheel: ...)', and nothing where that
    threshold was not crossed."""
    _mecanum_logs(tmp_path)
    single = _same_as_single(capsys, "mecanum-4", [tmp_path / "slips.csv", tmp_path / "clean.csv"])
    assert single[str(tmp_path / "clean.csv")] == []
    (line,) = single[str(tmp_path / "slips.csv")]
    assert line.startswith("the sensed joints contradict each other") and "(slip per wheel: " in line
    assert "front_left" in line


def test_a_log_breaking_a_gear_says_so_per_log_as_odometry_does(capsys, tmp_path):
    """A 1:1 gear (a solid axle) logged with the right spin turning twice as fast, beside a log keeping the gear.
    Before, the batch row had no gear line (the check was the single-log command's only)."""
    (tmp_path / "geared.yaml").write_text(GEARED)
    robot = str(tmp_path / "geared.yaml")
    t = np.arange(5.0)
    for name, right in (("breaks", 2.0), ("keeps", 1.0)):
        (tmp_path / f"{name}.csv").write_text("time,left.spin,right.spin\n" + "".join(
            f"{a:g},{a:g},{right * a:g}\n" for a in t))
    single = _same_as_single(capsys, robot, [tmp_path / "breaks.csv", tmp_path / "keeps.csv"])
    assert not any("do not turn together" in w for w in single[str(tmp_path / "keeps.csv")])
    (line,) = [w for w in single[str(tmp_path / "breaks.csv")] if "do not turn together" in w]
    assert line.startswith("the joints of the gear of wheels 'left' and 'right' (ratios 1, 1) do not turn together")


def test_a_bag_in_a_batch_gets_its_csv_s_diagnostics(capsys, tmp_path):
    """The slipping mecanum log written as a ROS 2 bag: the batch row holds the single-log command's lines."""
    pytest.importorskip("rosbags")
    from wmrkit.odometry.bags import write_joint_states

    robot = catalog.load("mecanum-4")
    log = simulate(robot, TwistProfile.from_segments([(3.0, 0.4, 0.1, 0.2)]), 20.0).log
    positions = log.positions.copy()
    positions[:, log.joints.index("front_left.spin")] *= 1.3
    write_joint_states(tmp_path / "slips.mcap", JointLog(log.time, log.joints, positions), robot=robot)
    single = _same_as_single(capsys, "mecanum-4", [tmp_path / "slips.mcap"])
    assert "(slip per wheel: " in single[str(tmp_path / "slips.mcap")][0]


@pytest.mark.parametrize("kind", ["mecanum", "gear"])
def test_each_row_says_whether_its_log_is_consistent_as_odometry_does(capsys, tmp_path, kind):
    """One inconsistent log (a slipping wheel; a broken gear) and one clean log: the rows' ``consistent`` (the --json
    rows and the Parquet column) equal each log's ``wmrkit odometry ROBOT LOG --json`` ``"consistent"``. Before, the
    rows had no such column: the verdict was only in the warnings' words."""
    pq = pytest.importorskip("pyarrow.parquet")
    if kind == "mecanum":
        robot, logs = "mecanum-4", _mecanum_logs(tmp_path)
    else:
        (tmp_path / "geared.yaml").write_text(GEARED)
        robot, logs = str(tmp_path / "geared.yaml"), [tmp_path / "breaks.csv", tmp_path / "keeps.csv"]
        for log, right in zip(logs, (2.0, 1.0), strict=True):
            log.write_text("time,left.spin,right.spin\n" + "".join(f"{a:g},{a:g},{right * a:g}\n" for a in range(5)))
    single = {}
    for log in logs:
        assert main(["odometry", robot, str(log), "--json"]) == 0
        single[str(log)] = json.loads(capsys.readouterr().out)["consistent"]
    assert list(single.values()) == [False, True]  # the oracle tells the two apart
    out = tmp_path / "fleet.parquet"
    assert main(["batch", "odometry", robot, *map(str, logs), "--workers", "0", "--out", str(out), "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["rows"]
    assert {r["log"]: r["consistent"] for r in rows} == single
    table = pq.read_table(out).to_pylist()
    assert {r["log"]: r["consistent"] for r in table} == single


@pytest.mark.parametrize("left", ["table", "parts"])
def test_rows_written_without_the_consistent_column_are_redone(tmp_path, monkeypatch, left):
    """A table written before the column (version 2 rows) lacks it: redone, not resumed with ``consistent`` null;
    so are the part files of such a run that stopped (same columns as a table, so only ROW_VERSION tells them)."""
    logs = _mecanum_logs(tmp_path)
    robot = catalog.load("mecanum-4")
    out = tmp_path / "fleet.parquet"
    with monkeypatch.context() as m:  # the batch as it was: no column, rows of version 2
        m.setattr(fleet, "SUMMARY_SCHEMA", tuple(c for c in fleet.SUMMARY_SCHEMA if c[0] != "consistent"))
        m.setattr(fleet, "ROW_VERSION", 2)
        fleet.batch_odometry(robot, logs, out=out)
    if left == "parts":  # the run stopped after flushing its rows: only its part file is left
        parts_dir(out).mkdir()
        shutil.move(out, parts_dir(out) / "part-000000.parquet")
    res = fleet.batch_odometry(robot, logs, out=out)
    assert res.skipped == 0
    assert [r["consistent"] for r in res.rows] == [False, True]


def test_the_summary_counts_and_names_the_inconsistent_logs(capsys, tmp_path):
    """Four copies of the slipping mecanum log and the clean one: the summary line and the --json answer count the
    logs that ``wmrkit odometry LOG --json`` (the oracle, run per log) calls inconsistent and name them (the text
    the first three and how many more; the JSON all); exit code 0, as the single-log command's for each. Before,
    the line said '5 logs: 5 done (0 from an earlier run), 0 failed' and the JSON had no count: a script had to
    read every row."""
    slips, clean = _mecanum_logs(tmp_path)
    logs = [tmp_path / f"s{k}.csv" for k in range(4)] + [clean]
    for log in logs[:4]:
        shutil.copy(slips, log)
    oracle = []
    for log in logs:
        assert main(["odometry", "mecanum-4", str(log), "--json"]) == 0
        if not json.loads(capsys.readouterr().out)["consistent"]:
            oracle.append(str(log))
    assert oracle == list(map(str, logs[:4]))
    assert main(["batch", "odometry", "mecanum-4", *map(str, logs), "--workers", "0", "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    assert answer["inconsistent"] == 4 and answer["inconsistent_logs"] == oracle
    assert main(["batch", "odometry", "mecanum-4", *map(str, logs), "--workers", "0", "--quiet"]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    named = f"{', '.join(oracle[:3])} and 1 more"
    assert first == f"5 logs: 5 done (0 from an earlier run), 0 failed, 4 inconsistent ({named})"
