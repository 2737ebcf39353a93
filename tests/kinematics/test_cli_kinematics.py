"""``wmrkit kinematics`` in-process: exit codes, JSON shape, --steer parsing, --symbolic/--codegen wiring."""

from __future__ import annotations

import json
import math
import sys
import types
from pathlib import Path

import pytest
import yaml

from wmrkit import catalog
from wmrkit.cli.main import main

TRICYCLE = {
    "name": "tri",
    "wheels": [
        {"name": "w1", "type": "fixed", "l": 0.5, "alpha": 0.0, "beta": 0.0, "r": 0.1, "sensed": ["spin"]},
        {"name": "w2", "type": "fixed", "l": 0.5, "alpha": "180 deg", "beta": 0.0, "r": 0.1, "sensed": ["spin"]},
        {"name": "w3", "type": "steerable", "l": 1.2, "alpha": "-90 deg", "beta": 0.4, "r": 0.1,
         "actuated": ["spin", "steer"], "sensed": ["steer"]},
    ],
}


@pytest.fixture
def tricycle_file(tmp_path: Path) -> str:
    path = tmp_path / "tri.yaml"
    path.write_text(yaml.safe_dump(TRICYCLE))
    return str(path)


def run_json(capsys, argv: list[str]) -> dict:
    assert main([*argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_a_drive_unit_s_mobility_says_which_motions_are_the_body_s(capsys):
    """m = 2 (4.3) counts the unit turning on the spot under a still body; analyze's m (5.13) is 1: both named."""
    assert main(["kinematics", "agv-drive-unit"]) == 0
    line = capsys.readouterr().out.splitlines()[1]
    assert line.strip() == ("mobility m = 2 (4.3): 1 of the body (G, 4.22; the classification's m) and 1 of the joints "
                            "with the body at rest")
    data = run_json(capsys, ["kinematics", "agv-drive-unit"])
    assert (data["mobility"], data["vehicle_dof"]) == (2, 1)


def test_json_summary_of_the_tricycle(capsys, tricycle_file):
    data = run_json(capsys, ["kinematics", tricycle_file])
    assert data["mobility"] == 1 and data["generic_mobility"] == 1 and data["extended_dof"] == 2
    assert data["vehicle_dof"] == 1
    assert data["assignable_sets"] == [["vy"], ["omega"], ["w1.spin"], ["w2.spin"], ["w3.spin"]]
    assert data["lost_here"] == []
    direct = data["direct_model"]
    assert direct["assigned"] == ["w1.spin"] and direct["kind"] == "direct"  # the first sensed rate
    assert direct["solved"] == ["vx", "vy", "omega", "w2.spin", "w3.spin"]
    assert direct["matrix"][1][0] == pytest.approx(-0.121383, abs=5e-7)  # C.5 numeric oracle
    assert data["inverse_model"]["assigned"] == ["vy"]
    assert data["actuation"]["leaf"] == "determined" and data["actuation"]["consistent"] is True
    assert data["sensing"]["slip_detectable"] is True
    assert ["w1.spin", "w3.steer"] in data["minimal_actuator_sets"]


def test_steer_option_in_degrees_and_radians(capsys, tricycle_file):
    data = run_json(capsys, ["kinematics", tricycle_file, "--steer", "w3=-90deg"])  # heading -90 deg: beta3 = 0
    assert data["steering"] == {"w3": pytest.approx(-math.pi / 2)} and data["beta"] == {"w3": pytest.approx(0.0)}
    assert ["omega"] not in data["assignable_sets"] and data["lost_here"] == [["omega"]]  # C.4: beta3 = 0
    data = run_json(capsys, ["kinematics", tricycle_file, "--steer", "w3=0"])  # heading 0: beta3 = 90 deg
    assert data["lost_here"] == [["vy"]]


def test_text_output(capsys, tricycle_file):
    assert main(["kinematics", tricycle_file, "--steer", "w3=-90 deg"]) == 0
    out = capsys.readouterr().out
    assert "mobility m = 1" in out and "not assignable at this steering" in out and "(omega)" in out
    assert "direct model (direct, assigned: w1.spin)" in out and "consistent actuation" in out


@pytest.mark.parametrize(("argv", "message"), [
    (["--steer", "w9=0.1"], "no wheel 'w9'"),
    (["--steer", "w1=0.1"], "does not steer"),
    (["--steer", "w3"], "expected NAME=VALUE"),
    (["--steer", "w3=north"], "--steer w3"),
    (["--codegen", "fortran", "out"], "language must be one of c, python"),
])
def test_user_mistakes_exit_2_with_one_line(capsys, tricycle_file, argv, message):
    assert main(["kinematics", tricycle_file, *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


def test_unknown_robot_exits_2(capsys):
    assert main(["kinematics", "no-such-robot"]) == 2
    assert "no robot 'no-such-robot'" in capsys.readouterr().err


def test_symbolic_and_codegen_call_the_library(capsys, monkeypatch, tricycle_file, tmp_path):
    calls = []
    symbolic = types.ModuleType("wmrkit.kinematics.symbolic")
    symbolic.format_symbolic = lambda robot: calls.append(("symbolic", robot.name)) or "CLOSED FORMS"
    codegen = types.ModuleType("wmrkit.kinematics.codegen")
    codegen.write_code = lambda robot, lang, directory: calls.append(("codegen", lang)) or [Path(directory) / "m.c"]
    monkeypatch.setitem(sys.modules, "wmrkit.kinematics.symbolic", symbolic)
    monkeypatch.setitem(sys.modules, "wmrkit.kinematics.codegen", codegen)
    data = run_json(capsys, ["kinematics", tricycle_file, "--symbolic", "--codegen", "c", str(tmp_path)])
    assert data["symbolic"] == "CLOSED FORMS" and data["generated"] == [str(tmp_path / "m.c")]
    assert calls == [("symbolic", "tri"), ("codegen", "c")]
    assert main(["kinematics", tricycle_file, "--symbolic"]) == 0
    assert "CLOSED FORMS" in capsys.readouterr().out


@pytest.mark.parametrize("name", catalog.names())
def test_every_catalog_robot(capsys, name):
    data = run_json(capsys, ["kinematics", name])
    assert all(len(s) == data["mobility"] for s in data["assignable_sets"])
    assert data["actuation"]["leaf"] in ("determined", "overdetermined", "indeterminate", "underdetermined")


def test_a_robot_that_cannot_move(capsys, tmp_path):
    stuck = {"name": "stuck", "wheels": [
        {"name": f"w{i}", "type": "fixed", "l": 0.4, "alpha": a, "beta": a + 0.3, "r": 0.05}
        for i, a in enumerate((0.1, 2.0, 4.0))]}
    path = tmp_path / "stuck.yaml"
    path.write_text(yaml.safe_dump(stuck))
    assert main(["kinematics", str(path)]) == 0
    out = capsys.readouterr().out
    assert "mobility m = 0" in out and "cannot move (m = 0)" in out
    assert run_json(capsys, ["kinematics", str(path)])["assignable_sets"] == [[]]


def test_an_unknown_codegen_language_is_refused_before_the_work(capsys, monkeypatch, tmp_path):
    """The language was checked after the chapter-4 summary (and --symbolic): tens of seconds on a large robot."""
    import wmrkit.cli.kinematics as command

    def never(robot):
        raise AssertionError("the summary ran before the language was checked")

    monkeypatch.setattr(command, "kinematics_summary", never)
    assert main(["kinematics", "forklift", "--symbolic", "--codegen", "rust", str(tmp_path)]) == 2
    assert "--codegen: language must be one of c, python, got 'rust'" in capsys.readouterr().err


def test_a_json_error_about_a_file_in_the_output_folder_names_that_file(capsys, tmp_path):
    """--codegen c DIR over a user's file: the JSON error had "file": null (the message names DIR/FILE, argv DIR)."""
    (tmp_path / "diff_drive_kinematics.c").write_text("int main(void) { return 0; }\n")
    assert main(["kinematics", "diff-drive", "--codegen", "c", str(tmp_path), "--json"]) == 2
    error = json.loads(capsys.readouterr().err)
    assert error["file"] == f"{tmp_path}/diff_drive_kinematics.c"
    assert error["error"].startswith("exists and is not wmrkit's code for robot 'diff-drive'")
    assert main(["kinematics", "diff-drive", "--codegen", "c", f"{tmp_path}/", "--json"]) == 2  # a trailing slash
    assert json.loads(capsys.readouterr().err)["file"] == f"{tmp_path}/diff_drive_kinematics.c"


def test_a_steer_heading_beyond_the_angle_limit_names_the_option(capsys):
    """--steer steer=1e6turn gave 'beta: angles must be ... at most 1e+06 turns', naming neither option nor wheel."""
    assert main(["kinematics", "forklift", "--steer", "steer=1e6turn"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("wmrkit: error: --steer steer=1e6turn: ") and "1e+06 turns" in err
    assert err.count("\n") == 1


def test_json_models_carry_headings_beside_beta(capsys):
    """The models' configuration was given only as the thesis's beta; users read headings (0 = straight ahead):
    each model object carries `heading`, the top-level `steering`'s values in steer_names order, and keeps `beta`."""
    from wmrkit import catalog

    robot = catalog.load("ackermann")
    data = run_json(capsys, ["kinematics", "ackermann", "--steer", "front_left=20 deg", "--steer",
                             "front_right=-15 deg"])
    steered = robot.with_steering({"front_left": math.radians(20), "front_right": math.radians(-15)})
    for key in ("direct_model", "inverse_model"):
        model = data[key]
        assert model["heading"] == pytest.approx([data["steering"][n] for n in robot.steer_names])
        assert model["heading"] == pytest.approx([math.radians(20), math.radians(-15)])
        assert model["beta"] == pytest.approx(steered.beta.tolist())  # unchanged: the thesis's angles
        assert model["beta"] == pytest.approx([data["beta"][n] for n in robot.steer_names])
