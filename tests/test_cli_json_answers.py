"""What a script can rely on in every ``--json`` answer (docs/limits.md, JSON answers): valid JSON on stdout, no
top-level ``error`` key in an answer (exit 0 or 1: ``error`` marks the failure object of exit 2), the robot named under
``robot`` by every command given a ROBOT, and the last pose of a run under ``final_pose`` ``[x, y, heading]``.
'wmrkit track --json' had a per-sample ``error`` in its successful answers, ik, fk and feasibility did not name their
robot, odometry's last pose was ``pose`` (simulate's ``final_pose``). ``tests/test_cli_contract.py`` checks the keys
every answer has (``robot``, ``warnings``) and strict JSON."""

from __future__ import annotations

import json
import math

import pytest

from cli_options import options
from test_cli_exit_codes import LEAVES, SHORT, VISION
from wmrkit.cli.main import build_parser, main

#: The commands that answer in JSON.
JSON_COMMANDS = sorted({cmd for cmd, a in options() if "--json" in a.option_strings})

#: Key endings that name a unit other than SI's (or any unit: JSON answers are SI under plain names). Image
#: quantities are in pixels (``focal_px``, as camera files write it: pixels have no SI unit).
UNIT_SUFFIXES = ("_ms", "_us", "_ns", "_s", "_sec", "_min", "_hours", "_percent", "_pct", "_deg", "_degrees", "_mm",
                 "_cm", "_km", "_m", "_kmh", "_mph", "_m_s", "_rpm", "_nm", "_n", "_kn", "_kg", "_g")
#: Names a concept had besides its one name: the path driven (``path_length``), a command's wall time
#: (``wall_time``), a final pose's errors (``final_position_error``, ``final_heading_error``).
OTHER_NAMES = {"distance": "path_length", "seconds": "wall_time", "time_ms": "wall_time",
               "final_error": "final_position_error"}
#: Where each one name is expected.
ONE_NAMES = {"path_length": {("odometry",), ("simulate",), ("park",), ("batch", "odometry")},
             "wall_time": {("park",), ("sweep",), ("batch", "odometry")},
             "final_position_error": {("calibrate",), ("slip-study",)},
             # each run of a fleet: its residual ratio (runs with references) and its closed-path score (closed
             # runs), each under its own key, the other null (the scores were under residual_ratio)
             "residual_ratio": {("batch", "calibrate")}, "closed_score": {("batch", "calibrate")}}

#: A small successful (or 'no', exit 1) command line of each; {d}: a folder of files, from the repository's root.
CASES: dict[tuple[str, ...], tuple[str, int]] = {
    ("robots",): ("robots", 0),
    ("show",): ("show diff-drive", 0),
    ("kinematics",): ("kinematics diff-drive", 0),
    ("ik",): ("ik diff-drive --twist 1 0.2 0", 1),
    ("fk",): ("fk diff-drive --spin left=10 --spin right=12", 0),
    ("analyze",): ("analyze diff-drive", 0),
    ("odometry",): ("odometry diff-drive {d}/yaw.csv", 0),
    ("feasibility",): ("feasibility forklift --reference square", 1),
    ("track",): ("track mecanum-4 --reference line --duration 1", 0),
    ("tyre",): ("tyre pacejka --load 3000 --slip-ratio 0.1", 0),
    ("simulate",): ("simulate skid-steer-4 --path straight --duration 0.2", 0),
    ("park",): ("park {d}/short.yaml", 1),
    ("follow-line",): (f"follow-line line-follower --camera {VISION}/follower-camera.yaml --duration 1", 0),
    ("vision", "locate"): (f"vision locate --points {VISION}/chufa-points.json --camera {VISION}/chufa-camera.yaml "
                           "--spacing 60cm", 0),
    ("vision", "calibrate"): ("vision calibrate --x1 71.2357 --x2 49.0727 --rows 60 --half-separation 0.035 "
                              "--row-distance 0.10221", 0),
    ("calibrate",): ("calibrate skid-steer-4 {d}/skid.csv --reference {d}/skid.tum", 0),
    ("slip-study",): ("slip-study skid-steer-4 --source quasi-static", 0),
    ("sweep",): ("sweep omni-3 --vary wheels.back.l=150mm:250mm:2 --workers 0", 0),
    ("batch", "odometry"): ("batch odometry diff-drive {d}/yaw.csv {d}/bad.csv --workers 0", 1),
    ("batch", "calibrate"): ("batch calibrate diff-drive {d}/c*.csv --reference {d}/ref --workers 0", 0),
    ("batch", "montecarlo"): ("batch montecarlo diff-drive --path arc -n 3 --workers 0", 0),
}


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    return write_case_files(tmp_path_factory.mktemp("answers"))


def write_case_files(d):
    """The files of :data:`CASES` (``{d}``) into the folder `d`; returns it."""
    import numpy as np

    from wmrkit import catalog
    from wmrkit.odometry.logs import JointLog, write_csv
    from wmrkit.odometry.pipeline import odometry
    from wmrkit.odometry.trajectories import Trajectory, write_trajectory
    from wmrkit.slip.synthetic import wheel_speed_run

    t = np.arange(21) * 0.1
    write_csv(d / "yaw.csv", ("time", "left.spin", "right.spin", "yaw"), np.column_stack([t, 10 * t, 10 * t, 0 * t]))
    (d / "bad.csv").write_text("time,left.spin,right.spin\n0,0,0\n0.1,x,0\n")
    (d / "short.yaml").write_text(SHORT)
    run = wheel_speed_run(catalog.load("skid-steer-4"), [(3.0, [8, 12, 8, 12]), (2.0, [10, 10, 10, 10])], 20.0,
                          model="mqe")
    write_csv(d / "skid.csv", ("time", *run.log.joints), np.column_stack([run.log.time, run.log.positions]))
    write_trajectory(d / "skid.tum", Trajectory(run.log.time, run.truth, np.zeros(len(run.log))), "tum")
    (d / "ref").mkdir()
    diff = catalog.load("diff-drive")
    for i, w in enumerate((0.3, -0.2, 0.5, -0.4)):  # four open runs of the catalog robot itself
        q = np.column_stack([t * 40, (10 + 4 * w * (i + 1)) * t * 4])
        write_csv(d / f"c{i}.csv", ("time", "left.spin", "right.spin"), np.column_stack([t * 4, q]))
        truth = odometry(diff, JointLog(t * 4, ("left.spin", "right.spin"), q)).poses
        write_trajectory(d / "ref" / f"c{i}.tum", Trajectory(t * 4, truth, np.zeros(len(t))), "tum")
    return d


def test_every_json_command_has_its_case():
    assert sorted(CASES) == JSON_COMMANDS and set(JSON_COMMANDS) <= set(LEAVES)


def _takes_a_robot(command: tuple[str, ...]) -> bool:
    parser = build_parser()
    for word in command:
        parser = next(a for a in parser._actions if a.dest == "command" or (hasattr(a, "choices") and
                      isinstance(a.choices, dict) and word in a.choices)).choices[word]
    return any(a.dest == "robot" and not a.option_strings for a in parser._actions)


@pytest.mark.parametrize("command", sorted(CASES), ids=" ".join)
def test_a_json_answer_a_script_can_rely_on(command, files, capsys, monkeypatch):
    from doc_examples import ROOT

    monkeypatch.chdir(ROOT)
    line, code = CASES[command]
    argv = line.format(d=files).split()
    assert main([*argv, "--json"]) == code
    answer = json.loads(capsys.readouterr().out)
    if isinstance(answer, list):  # robots: one row a robot
        assert all("error" not in row for row in answer)
        return
    assert "error" not in answer  # the key of a failure object (exit 2)
    if _takes_a_robot(command):
        assert answer["robot"] == argv[len(command)]
    flat = {k for k, v in answer.items() if isinstance(v, list) and len(v) == 3 and
            all(isinstance(x, float) for x in v) and "pose" in k}
    assert flat <= {"final_pose"}  # the last pose of a run has one name
    if command in {("odometry",), ("simulate",)}:
        assert flat == {"final_pose"}


def keys(x) -> set[str]:
    """Every key of a JSON value, nested dicts and lists walked (keys naming data, a batch's files, included)."""
    if isinstance(x, dict):
        return set(x).union(*(keys(v) for v in x.values()))
    if isinstance(x, list):
        return set().union(*(keys(v) for v in x))
    return set()


@pytest.mark.parametrize("command", sorted(CASES), ids=" ".join)
def test_json_answers_are_si_under_one_name_per_concept(command, files, capsys, monkeypatch):
    """No key ends in a unit (park's ``time_ms`` and ``length_ratio_percent`` did); the path driven is
    ``path_length`` (odometry and simulate said ``distance``), a wall time ``wall_time`` (sweep and batch odometry
    said ``seconds``, park ``time_ms`` [ms]), a final position error ``final_position_error`` (calibrate's
    ``final_error`` was a {position, heading} object per model, track's summary a number)."""
    from doc_examples import ROOT

    monkeypatch.chdir(ROOT)
    line, code = CASES[command]
    assert main([*line.format(d=files).split(), "--json"]) == code
    found = keys(json.loads(capsys.readouterr().out))
    if command == ("track",):  # the summary of the tracking error: rms_error, max_error, final_error [m]
        found -= {"final_error"}
    assert not [k for k in found if k.lower().endswith(UNIT_SUFFIXES)]
    assert not found & OTHER_NAMES.keys()
    assert {name for name, where in ONE_NAMES.items() if command in where} <= found


def test_the_forklift_study_settings_are_si_under_plain_names():
    """``slip-study forklift --json`` prints ``settings`` (and its runs' speeds and errors): they were named with
    their units (``sample_period_s``, ``steer_resolution_deg`` in degrees, ``path_speed_m_s``, ...) and the examples
    repeated J as ``J_percent``."""
    from wmrkit.slip.study import SETTINGS

    assert not [k for k in keys(SETTINGS) if k.lower().endswith(UNIT_SUFFIXES)]
    assert SETTINGS["steer_resolution"] == pytest.approx(math.radians(1.4118))
