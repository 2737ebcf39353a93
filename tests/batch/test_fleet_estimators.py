"""``wmrkit batch odometry --method wls|fk1|fk2``: the slip-aware estimators of ``wmrkit odometry`` over a fleet's
logs. Before, batch odometry ran only the no-slip schemes and refused a description whose odometry.method was one of
them. The oracle: ``wmrkit odometry`` run on each log with the same options (the same poses bit for bit, the same
warning lines); the logs are simulated skid steers that slip (mqe) and a forklift turning on the spot with its
steered wheel at 90 deg, where FK1's rows do not fix the twist."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from wmrkit import catalog
from wmrkit.batch.engine import BatchError
from wmrkit.batch.fleet import batch_odometry
from wmrkit.cli.main import main
from wmrkit.odometry.logs import write_csv
from wmrkit.slip.kalman import KalmanNoise
from wmrkit.slip.synthetic import wheel_speed_run
from wmrkit.slip.weights import SlipWeights

pytest.importorskip("pyarrow")

SEGMENTS = [(3.0, [8, 12, 8, 12]), (2.0, [10, 10, 10, 10]), (3.0, [12, 8, 12, 8]), (2.0, [6, 14, 6, 14])]


@pytest.fixture(scope="module")
def skid_logs(tmp_path_factory):
    """Two logs of a slipping skid steer (the segments, then reversed), 20 Hz."""
    d = tmp_path_factory.mktemp("skid")
    for i, segments in enumerate((SEGMENTS, SEGMENTS[::-1])):
        run = wheel_speed_run(catalog.load("skid-steer-4"), segments, 20.0, model="mqe")
        write_csv(d / f"s{i}.csv", ("time", *run.log.joints), np.column_stack([run.log.time, run.log.positions]))
    return d


def _run(capsys, argv: list[str], code: int = 0) -> tuple[dict, list[str]]:
    assert main(argv) == code
    out, err = capsys.readouterr()
    return json.loads(out), err.splitlines()


@pytest.mark.parametrize("options", [
    ["--method", "wls"], ["--method", "wls", "--mu-default", "1,0.2", "--scheme", "rk2"],
    ["--method", "fk2"], ["--method", "fk2", "--kf-noise", "0.05", "0.5", "0.1", "--thesis-double-q"],
    ["--method", "fk2", "--kf-period", "10 ms"],  # 5 periods a 20 Hz step
    ["--method", "fk2", "--kf-period", "0.2"],  # 4 times the logs' intervals: a warning line in each row
])
def test_each_row_is_what_wmrkit_odometry_gives_that_log(capsys, skid_logs, options):
    data, _ = _run(capsys, ["batch", "odometry", "skid-steer-4", str(skid_logs), "--workers", "0", "--json",
                            *options])
    assert data["failed"] == 0 and len(data["rows"]) == 2
    plain, _ = _run(capsys, ["batch", "odometry", "skid-steer-4", str(skid_logs), "--workers", "0", "--json"])
    for row, no_slip in zip(data["rows"], plain["rows"], strict=True):
        single, said = _run(capsys, ["odometry", "skid-steer-4", row["log"], "--json", *options])
        assert row["method"] == single["method"] != no_slip["method"]
        assert [row["x"], row["y"], row["theta"]] == single["final_pose"]  # bit for bit
        assert [row["max_slip"], row["rms_slip"], row["path_length"]] == [single["max_slip"], single["rms_slip"],
                                                                           single["path_length"]]
        assert row["warnings"] == "; ".join(line.removeprefix("wmrkit: warning: ") for line in said)
        # equal coefficients make WLS the no-slip model's least squares; the others are not its answer
        assert ([row["x"], row["y"]] == [no_slip["x"], no_slip["y"]]) == (options == ["--method", "wls"])


def test_a_described_slip_aware_method_runs(capsys, skid_logs, tmp_path):
    """The description's odometry block (method, friction coefficients) is run by batch odometry as by odometry."""
    robot = tmp_path / "husky.yaml"
    described = {"odometry": {"method": "wls", "slip": {"lateral": 0.3, "longitudinal": 1.0}}}
    robot.write_text(yaml.safe_dump(catalog.load("skid-steer-4").to_dict() | described))
    data, _ = _run(capsys, ["batch", "odometry", str(robot), str(skid_logs / "s0.csv"), "--workers", "0", "--json"])
    given, _ = _run(capsys, ["odometry", "skid-steer-4", str(skid_logs / "s0.csv"), "--method", "wls",
                             "--mu-default", "0.3,1", "--json"])
    assert data["rows"][0]["method"] == "wls (exact)"
    assert [data["rows"][0][k] for k in ("x", "y", "theta")] == given["final_pose"]


def test_a_rerun_redoes_the_logs_only_when_the_estimator_changed(capsys, skid_logs, tmp_path):
    out = tmp_path / "t.parquet"
    base = ["batch", "odometry", "skid-steer-4", str(skid_logs), "--workers", "0", "--json", "--out", str(out)]
    first, _ = _run(capsys, [*base, "--method", "fk2"])
    again, _ = _run(capsys, [*base, "--method", "fk2"])
    assert (first["skipped"], again["skipped"]) == (0, 2)
    for changed in (["--method", "fk2", "--kf-noise", "0.1", "1", "1"], ["--method", "wls"],
                    ["--method", "fk2", "--scheme", "euler"], ["--method", "fk2", "--kf-period", "10 ms"]):
        redone, _ = _run(capsys, [*base, *changed])
        assert redone["skipped"] == 0, changed


def test_fk1_says_where_its_rows_do_not_fix_the_twist_in_the_row(capsys, tmp_path):
    """The forklift turning on the spot, steered wheel at heading 90 deg: ``wmrkit odometry --method fk1`` warns;
    the batch row carries the same line (each log's filter notes its own configurations: a second log driving
    straight has no such line, though the same worker ran the first)."""
    d = tmp_path / "logs"
    d.mkdir()
    t = np.arange(0, 5.0001, 0.01)
    header = "time [s],right_drive.spin [rad],left_drive.spin [rad],steer.steer [deg]\n"
    for name, left, heading in (("a_spin", -2.0, 90), ("b_straight", 2.0, 0)):
        (d / f"{name}.csv").write_text(header + "".join(f"{a:.4f},{2 * a:.6f},{left * a:.6f},{heading}\n" for a in t))
    data, _ = _run(capsys, ["batch", "odometry", "forklift", str(d), "--method", "fk1", "--workers", "0", "--json"])
    lines = []
    for row in data["rows"]:
        _, said = _run(capsys, ["odometry", "forklift", row["log"], "--method", "fk1", "--json"])
        lines.append([s for s in said if "barely fix the twist" in s or "do not fix the twist" in s])
        assert row["warnings"] == ("; ".join(s.removeprefix("wmrkit: warning: ") for s in said) or None)
    assert [len(x) for x in lines] == [1, 0]


@pytest.mark.parametrize(("argv", "said"), [
    (["--method", "exact", "--scheme", "rk2"], "--scheme applies to --method wls, fk1 or fk2"),
    (["--method", "fk2", "--mu-default", "1,1"], "--mu-default applies to --method wls, not to --method fk2"),
    (["--method", "wls", "--kf-noise", "1", "1", "1"], "--kf-noise applies to --method fk1 or fk2"),
    (["--method", "wls", "--kf-period", "10 ms"], "--kf-period applies to --method fk1 or fk2"),
    (["--method", "fk2", "--kf-period", "10 m"], "--kf-period: '10 m' is a length, expected a time"),
    (["--method", "fk1"], "fk1: the sensed rows of robot 'skid-steer-4' do not determine its twist"),
    (["--method", "wls", "--mu", "nope=1,1"], "--mu nope: robot 'skid-steer-4' has no wheel 'nope'"),
    (["--imu-mount", "0", "0", "1"], "--imu-mount applies to the IMU of ROS 2 bags; none of the 2 logs is one"),
    (["--imu-mount", "0", "nan", "1"], "--imu-mount PITCH"),
])
def test_options_that_would_be_ignored_or_are_wrong_are_refused_before_any_log(capsys, skid_logs, argv, said):
    assert main(["batch", "odometry", "skid-steer-4", str(skid_logs), "--workers", "0", "--json", *argv]) == 2
    out, err = capsys.readouterr()
    assert out == "" and said in json.loads(err)["error"]


def test_the_python_door_refuses_options_of_another_method(skid_logs):
    robot = catalog.load("skid-steer-4")
    with pytest.raises(BatchError, match="slip_weights= applies to method wls, not to method fk2"):
        batch_odometry(robot, [skid_logs], method="fk2", slip_weights=SlipWeights.uniform(1.0, 0.5))
    with pytest.raises(BatchError, match="noise= applies to method fk1 or fk2, not to method exact"):
        batch_odometry(robot, [skid_logs], noise=KalmanNoise())
    with pytest.raises(BatchError, match="weights= applies to the no-slip methods, not to method wls"):
        batch_odometry(robot, [skid_logs], method="wls", weights={"front_left": 2.0})
    rows = batch_odometry(robot, [skid_logs], method="fk2", scheme="rk2").rows
    assert [r["method"] for r in rows] == ["fk2 (rk2)"] * 2 and not any(r["error"] for r in rows)
