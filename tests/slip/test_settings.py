"""Slip weights and Kalman noise in robot descriptions: parsing, errors, the CLI's precedence, and the round trip
``wmrkit calibrate`` -> description -> ``wmrkit odometry``."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from wmrkit import DescriptionError, catalog
from wmrkit.cli.main import main
from wmrkit.description import robot_from_text
from wmrkit.odometry.logs import write_csv
from wmrkit.odometry.trajectories import Trajectory, write_trajectory
from wmrkit.slip.settings import OdometrySettings, odometry_settings, settings_to_dict
from wmrkit.slip.synthetic import wheel_speed_run
from wmrkit.slip.weights import SlipWeights

SKID = yaml.safe_load(catalog.source_text("skid-steer-4"))
SEGMENTS = [(3.0, [8, 12, 8, 12]), (2.0, [10, 10, 10, 10]), (3.0, [12, 8, 12, 8]), (2.0, [6, 14, 6, 14])]


def _skid(odometry=None, wheel_slip=None) -> dict:
    data = json.loads(json.dumps(SKID))
    if odometry is not None:
        data["odometry"] = odometry
    if wheel_slip is not None:
        data["wheels"][1]["slip"] = wheel_slip
    return data


def _write(tmp_path, data, name="robot.yaml"):
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_settings_read_from_the_description(tmp_path):
    path = _write(tmp_path, _skid({"method": "fk2", "scheme": "rk2", "slip": {"lateral": 0.5, "longitudinal": 2},
                                   "noise": {"process": 3, "lateral": 0.1}},
                                  {"lateral": 4, "longitudinal": 1, "noise": {"lateral": 0.2, "longitudinal": 0.3}}))
    s = odometry_settings(str(path))
    assert (s.method, s.scheme, s.slip, s.noise) == ("fk2", "rk2", (0.5, 2.0), (3.0, 0.1, 1.0))
    assert s.wheel_slip == (("front_right", 4.0, 1.0),) and s.wheel_noise == (("front_right", 0.2, 0.3),)
    w = s.weights()
    assert w.of_wheel("front_right") == (4.0, 1.0) and w.of_wheel("rear_left") == (0.5, 2.0)
    n = s.kalman_noise()
    assert (n.process, n.of_wheel("front_right"), n.of_wheel("front_left")) == (3.0, (0.2, 0.3), (0.1, 1.0))
    # written back and read again: the same settings
    back = _skid()
    block = settings_to_dict(s)
    back["odometry"] = block["odometry"]
    for wheel in back["wheels"]:
        wheel.update(block["wheels"].get(wheel["name"], {}))
    assert odometry_settings(str(_write(tmp_path, back, "back.yaml"))) == s
    assert odometry_settings("skid-steer-4") == OdometrySettings() and catalog.load("skid-steer-4").odometry is None


def test_the_robot_value_keeps_its_settings_through_dict_and_file(tmp_path):
    """``Robot.odometry`` is part of the value: to_dict/from_dict and to_file/from_file keep it, and two robots
    that differ only in it are different values."""
    from wmrkit.robot import Robot

    path = _write(tmp_path, _skid({"method": "wls", "slip": {"lateral": 2, "longitudinal": 1}},
                                  {"lateral": 4, "longitudinal": 1, "noise": {"lateral": 0.2, "longitudinal": 0.3}}))
    robot = Robot.from_file(path)
    assert robot.odometry == odometry_settings(str(path)) and robot.odometry.method == "wls"
    assert Robot.from_dict(robot.to_dict()) == robot
    for name in ("again.yaml", "again.json"):
        robot.to_file(tmp_path / name)
        assert Robot.from_file(tmp_path / name) == robot
    plain = Robot.from_dict(_skid())
    assert plain.odometry is None and plain != robot and "odometry" not in plain.to_dict()


def test_a_wheel_s_kalman_noise_without_friction_coefficients_is_read_and_written_back():
    """Robot.to_dict() wrote a wheel's own Kalman noise without coefficients of its own as ``slip: {noise: ...}``,
    which the reader refused ("wheels[2].slip: missing field 'lateral'"): such a robot could not be read back, and a
    description could not give one wheel's FK noise alone. That wheel keeps the default coefficients."""
    from dataclasses import replace

    from wmrkit.robot import Robot

    fork = replace(catalog.load("forklift"),
                   odometry=OdometrySettings(method="fk2", slip=(2.0, 1.0), wheel_noise=(("steer", 0.28, 1.0),)))
    back = Robot.from_dict(fork.to_dict())
    assert back == fork and back.odometry.weights().of_wheel("steer") == (2.0, 1.0)
    assert back.odometry.kalman_noise().of_wheel("steer") == (0.28, 1.0)
    with pytest.raises(DescriptionError, match=r"wheels\[1\]\.slip: missing field 'longitudinal'"):
        robot_from_text(yaml.safe_dump(_skid(None, {"lateral": 2, "noise": {"lateral": 1, "longitudinal": 1}})),
                        source="robot.yaml")


@pytest.mark.parametrize(("odometry", "wheel_slip", "message"), [
    ({"method": "wsl"}, None, "odometry.method: must be one of exact, rk2, euler, paper002, wls, fk1, fk2, got 'wsl'"),
    ({"slip": {"lateral": 1}}, None, "odometry.slip: missing field 'longitudinal'"),
    ({"noise": {"process": 0}}, None, "odometry.noise.process: must be a number > 0, got 0.0"),
    ({"nosie": 1}, None, "odometry.nosie: unknown field 'nosie' (did you mean 'noise'?)"),
    ("wls", None, "odometry: must be a mapping"),
    (None, {"lateral": -1, "longitudinal": 1}, "wheels[1].slip.lateral: must be a number > 0, got -1.0"),
    (None, {"lateral": 1, "longitudinal": float("nan")}, "wheels[1].slip.longitudinal: must be finite"),
    (None, {"lateral": 1, "longitudinal": 1, "noise": {"lateral": 1}},
     "wheels[1].slip.noise: missing field 'longitudinal'"),
    (None, {"lateral": "1 m", "longitudinal": 1}, "wheels[1].slip.lateral: '1 m' is a length, expected a number"),
    (None, {"lat": 1}, "wheels[1].slip.lat: unknown field 'lat' (did you mean 'lateral'?)"),
])
def test_errors_name_the_file_line_wheel_and_field(odometry, wheel_slip, message):
    text = yaml.safe_dump(_skid(odometry, wheel_slip), sort_keys=False)
    with pytest.raises(DescriptionError) as err:
        robot_from_text(text, source="robot.yaml")
    line = str(err.value)
    assert "\n" not in line and line.startswith("robot.yaml:") and message in line
    assert err.value.line is not None
    key = next(k for k in reversed(err.value.loc) if isinstance(k, str))
    assert f"{key}:" in text.splitlines()[err.value.line - 1]


@pytest.fixture(scope="module")
def husky_files(tmp_path_factory):
    run = wheel_speed_run(catalog.load("skid-steer-4"), SEGMENTS, 20.0, model="mqe")
    d = tmp_path_factory.mktemp("husky")
    write_csv(d / "log.csv", ("time", *run.log.joints), np.column_stack([run.log.time, run.log.positions]))
    write_trajectory(d / "ref.tum", Trajectory(run.log.time, run.truth, np.zeros(len(run.log))), "tum")
    return d, run


def _pose(capsys, argv) -> list[float]:
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)["final_pose"]


def test_calibrate_description_odometry_round_trip(husky_files, capsys, tmp_path):
    """calibrate's description block pasted into the description makes plain ``odometry`` the calibrated WLS:
    the same poses as the options, far closer to the truth than the no-slip model; options override it."""
    d, run = husky_files
    log = str(d / "log.csv")
    assert main(["calibrate", "skid-steer-4", log, "--reference", str(d / "ref.tum"), "--json"]) == 0
    cal = json.loads(capsys.readouterr().out)
    assert cal["description"] == {"odometry": {"method": "wls", "slip": {"lateral": cal["ratio"],
                                                                         "longitudinal": 1.0}}}
    (tmp_path / "w.json").write_text(json.dumps(cal))
    robot = _write(tmp_path, _skid() | cal["description"])
    described = _pose(capsys, ["odometry", str(robot), log, "--json"])
    options = _pose(capsys, ["odometry", "skid-steer-4", log, "--method", "wls", "--slip-weights",
                             str(tmp_path / "w.json"), "--json"])
    plain = _pose(capsys, ["odometry", "skid-steer-4", log, "--json"])
    overridden = _pose(capsys, ["odometry", str(robot), log, "--method", "exact", "--json"])
    assert np.allclose(described, options, atol=1e-12)
    assert np.allclose(overridden, plain, atol=1e-12)
    truth = run.truth[-1, :2]
    assert np.hypot(*(np.array(described[:2]) - truth)) < 0.2 < np.hypot(*(np.array(plain[:2]) - truth))
    # --mu-default overrides the described coefficients: unit weights are the unweighted least squares
    unit = _pose(capsys, ["odometry", str(robot), log, "--mu-default", "1,1", "--json"])
    assert np.allclose(unit, plain, atol=1e-9)
    # the text output prints the same block, ready to paste
    assert main(["calibrate", "skid-steer-4", log, "--reference", str(d / "ref.tum")]) == 0
    text = capsys.readouterr().out
    block = yaml.safe_load(text[text.index("odometry:"):])
    assert block["odometry"]["method"] == "wls"
    assert block["odometry"]["slip"] == {"lateral": cal["ratio"], "longitudinal": 1.0}


def test_described_kalman_noise_is_used_and_options_override_it(husky_files, capsys, tmp_path):
    d, _ = husky_files
    log = str(d / "log.csv")
    robot = _write(tmp_path, _skid({"method": "fk2", "noise": {"process": 0.5, "lateral": 0.05, "longitudinal": 2}}))
    described = _pose(capsys, ["odometry", str(robot), log, "--json"])
    options = _pose(capsys, ["odometry", "skid-steer-4", log, "--method", "fk2", "--kf-noise", "0.5", "0.05", "2",
                             "--json"])
    default = _pose(capsys, ["odometry", "skid-steer-4", log, "--method", "fk2", "--json"])
    overridden = _pose(capsys, ["odometry", str(robot), log, "--kf-noise", "1", "1", "1", "--json"])
    assert np.allclose(described, options, atol=1e-12) and np.allclose(overridden, default, atol=1e-12)
    assert not np.allclose(described, default, atol=1e-3)


def test_cli_reports_description_errors(tmp_path, capsys, husky_files):
    d, _ = husky_files
    robot = _write(tmp_path, _skid(None, {"lateral": 0, "longitudinal": 1}))
    assert main(["odometry", str(robot), str(d / "log.csv")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("wmrkit: error: ") and "wheels[1].slip.lateral: must be a number > 0" in err
    assert err.count("\n") == 1


def test_a_described_method_the_robot_cannot_run_is_refused_naming_the_description(tmp_path, capsys, husky_files):
    """'odometry: {method: fk1}' on a skid steer (FK1 leaves out the fixed wheels' lateral rows) was refused with
    'fk1: the sensed rows ... use fk2' and no word of where fk1 came from: the user had typed no --method."""
    d, _ = husky_files
    robot = _write(tmp_path, _skid({"method": "fk1"}))
    assert main(["odometry", str(robot), str(d / "log.csv")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"wmrkit: error: {robot}: odometry.method fk1 (--method overrides it): fk1: the sensed rows")
    assert err.count("\n") == 1
    assert main(["odometry", str(robot), str(d / "log.csv"), "--method", "fk1"]) == 2
    assert capsys.readouterr().err.startswith("wmrkit: error: fk1: the sensed rows")


def test_weights_of_settings_are_slip_weights():
    s = OdometrySettings(slip=(2.0, 1.0), wheel_slip=(("a", 1.0, 3.0),))
    assert s.weights() == SlipWeights.of({"a": (1.0, 3.0)}, (2.0, 1.0))


def test_a_slip_weights_file_giving_a_field_twice_is_refused(capsys, tmp_path):
    """JSON parsers keep the last of two equal keys; the weights file is read as descriptions are: refused, with
    the line and the field."""
    path = tmp_path / "w.json"
    path.write_text('{"weights": {"default": [1, 2],\n "default": [3, 4]}}')
    assert main(["odometry", "skid-steer-4", str(tmp_path / "log.csv"), "--method", "wls", "--slip-weights",
                 str(path)]) == 2
    err = capsys.readouterr().err
    assert "w.json:2: weights.default: field 'default' given twice" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("text,field,message", [
    ('{"weights": {"default": [true, 1]}}', "weights.default.0", "expected a finite number > 0, got true"),
    ('{"weights": {"default": ["2", 1]}}', "weights.default.0", 'expected a finite number > 0, got "2"'),
    ('{"weights": {"default": [NaN, 1]}}', "weights.default.0", "expected a finite number > 0, got NaN"),
    ('{"weights": {"default": [1, 1], "wheels": {"nose": [1, 1]}}}', "weights.wheels.nose",
     "robot 'skid-steer-4' has no wheel 'nose' (wheels: front_left, front_right, rear_left, rear_right)"),
    ('{"weights": {"default": [1, 1], "wheel": {"front_left": [1, 2]}}}', "weights",
     "unknown field 'wheel' (fields: default, wheels)"),
])
def test_a_slip_weights_file_is_checked_by_field(capsys, tmp_path, text, field, message):
    """A weights file's true or "2" was read as 1 or 2, a misspelt 'wheel' key was ignored (the default applied
    to every wheel), and NaN, negative or unknown-wheel errors did not name the file: now each is refused with the
    file and the field."""
    path = tmp_path / "w.json"
    path.write_text(text)
    assert main(["odometry", "skid-steer-4", str(tmp_path / "log.csv"), "--method", "wls", "--slip-weights",
                 str(path), "--json"]) == 2
    data = json.loads(capsys.readouterr().err)
    assert (data["file"], data["field"], data["error"]) == (str(path), field, message)


@pytest.mark.parametrize("odometry,wheel_slip,loc", [
    ({"slip": {"lateral": 1e-20, "longitudinal": 1}}, None, ("odometry", "slip", "lateral")),
    (None, {"lateral": 1e-13, "longitudinal": 1}, ("wheels", 1, "slip", "lateral")),
    ({"slip": {"lateral": 1e13, "longitudinal": 1e13}}, {"lateral": 1, "longitudinal": 1},
     ("wheels", 1, "slip", "lateral")),
])
def test_friction_coefficients_too_far_apart_are_refused_where_the_description_gives_them(odometry, wheel_slip, loc):
    """Coefficients more than 1e12 apart loaded, and `wmrkit odometry ROBOT LOG` then failed without the file or
    the field (SlipWeights.row_mu); the noises were already checked this way."""
    text = yaml.safe_dump(_skid(odometry, wheel_slip), sort_keys=False)
    with pytest.raises(DescriptionError) as err:
        robot_from_text(text, source="robot.yaml")
    assert err.value.loc == loc and "differ by more than a factor 1e+12" in err.value.message
    within = _skid({"slip": {"lateral": 1e-11, "longitudinal": 1}}, {"lateral": 1, "longitudinal": 1})
    robot_from_text(yaml.safe_dump(within, sort_keys=False), source="robot.yaml")  # 1e11 apart: accepted


@pytest.mark.parametrize("options,where", [
    (["--slip-weights", "{w}"], "--slip-weights {w}: "),
    (["--mu", "front_right=1e-13,1"], "--mu front_right and the default 1,1: "),
    (["--slip-weights", "{w}", "--mu-default", "1e13,1e13"], "--slip-weights {w} and --mu-default: "),
])
def test_friction_coefficients_too_far_apart_are_refused_naming_the_options_or_file(capsys, tmp_path, options, where):
    """Coefficients more than 1e12 apart from a --slip-weights file or --mu options were refused without the file
    or the option (SlipWeights.row_mu, when odometry ran)."""
    w = tmp_path / "w.json"
    w.write_text('{"weights": {"default": [1, 1], "wheels": {"front_left": [1e-13, 1]}}}')
    args = [a.format(w=w) for a in options]
    assert main(["odometry", "skid-steer-4", str(tmp_path / "log.csv"), "--method", "wls", *args, "--json"]) == 2
    error = json.loads(capsys.readouterr().err)["error"]
    assert error.startswith(where.format(w=w)) and "differ by more than a factor 1e+12" in error
