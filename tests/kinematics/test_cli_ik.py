"""``wmrkit ik`` and ``wmrkit fk``: JSON shape, human tables, warnings on stderr, user mistakes exit 2."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_ik_json_has_the_documented_shape(capsys):
    code, out, err = run(capsys, "ik", "swerve-4", "--twist", "1", "0.5", "0.2", "--json")
    assert code == 0 and err == ""
    data = json.loads(out)
    assert set(data) == {"wheels", "slip", "feasible"} and data["feasible"] is True
    robot = catalog.load("swerve-4")
    assert list(data["wheels"]) == list(robot.wheel_names)
    for name, (x, y) in zip(robot.wheel_names, (w.position for w in robot.wheels), strict=True):
        entry = data["wheels"][name]
        assert set(entry) == {"steer", "spin", "steer_rate"} and entry["steer_rate"] is None
        ux, uy = 1 - 0.2 * y, 0.5 + 0.2 * x  # steering axis velocity; (8.9) and (8.12), closest to 90 deg
        assert entry["steer"] == pytest.approx(math.atan2(-ux, uy) + math.pi, abs=1e-12)
        assert entry["spin"] == pytest.approx(math.hypot(ux, uy) / 0.0508, rel=1e-12)


def test_ik_json_of_other_wheel_types_adds_their_joints(capsys):
    code, out, _ = run(capsys, "ik", "mecanum-4", "--twist", "0.3", "0.2", "0.1", "--json")
    data = json.loads(out)
    assert code == 0 and all(set(e) == {"steer", "spin", "steer_rate", "roller"} for e in data["wheels"].values())
    assert all(e["steer"] is None for e in data["wheels"].values())


def test_ik_warns_about_an_infeasible_twist(capsys):
    code, out, err = run(capsys, "ik", "diff-drive", "--twist", "1", "0.2", "0.5")
    assert code == 0
    assert err.startswith("wmrkit: warning: twist not feasible for robot 'diff-drive'") and err.count("\n") == 1
    assert "feasible: NO" in out and "left" in out and "caster" in out
    code, out, err = run(capsys, "ik", "diff-drive", "--twist", "1", "0", "0.5", "--json")
    assert err == "" and json.loads(out)["feasible"] is True


def test_ik_steer_accepts_degrees_and_radians(capsys):
    _, deg, _ = run(capsys, "ik", "forklift", "--twist", "-1", "0", "0", "--steer", "steer=-90deg", "--json")
    _, rad, _ = run(capsys, "ik", "forklift", "--twist", "-1", "0", "0", "--steer", f"steer={-math.pi / 2}",
                    "--json")
    assert json.loads(deg) == json.loads(rad)
    entry = json.loads(deg)["wheels"]["steer"]  # reversing with the wheel at -90 deg: it stays there
    assert entry["steer"] == pytest.approx(-math.pi / 2) and entry["spin"] == pytest.approx(1 / 0.23)


def test_fk_json_and_text(capsys):
    code, out, err = run(capsys, "fk", "diff-drive", "--spin", "left=10", "--spin", "right.spin=12", "--json")
    assert code == 0 and err == ""
    data = json.loads(out)
    assert set(data) == {"twist", "residual"}
    r, half_track = 0.075, 0.20
    np.testing.assert_allclose(data["twist"], [r * 11, 0.0, r * 2 / (2 * half_track)], atol=1e-12)
    assert data["residual"] < 1e-12
    code, out, err = run(capsys, "fk", "swerve-4", "--spin", "front_left=3", "--steer", "front_left=100deg")
    assert code == 0 and "twist (robot frame)" in out and "residual" in out and err == ""  # 8 rows, 6 unknowns
    code, out, err = run(capsys, "fk", "diff-drive", "--spin", "left=3")
    assert code == 0 and "do not determine the twist" in err and err.count("\n") == 1


@pytest.mark.parametrize(("argv", "message"), [
    (["ik", "diff-drive", "--twist", "1", "0", "0", "--steer", "left=1"], "wheel 'left' of robot 'diff-drive' does"),
    (["ik", "swerve-4", "--twist", "1", "0", "0", "--steer", "front_left=fast"], "--steer front_left: cannot read"),
    (["ik", "swerve-4", "--twist", "1", "0", "0", "--steer", "front_left"], "--steer: expected NAME=VALUE"),
    (["ik", "no-such-robot", "--twist", "1", "0", "0"], "no robot 'no-such-robot'"),
    (["fk", "diff-drive", "--spin", "lft=1"], "no joint rate 'lft' (valid: left, right"),
    (["fk", "diff-drive", "--spin", "left=nan"], "--spin left: cannot read 'nan'"),
    (["fk", "diff-drive"], "at least one joint rate"),
])
def test_user_mistakes_exit_2_with_one_line(capsys, argv, message):
    code, out, err = run(capsys, *argv)
    assert code == 2 and out == ""
    assert err.startswith("wmrkit: error: ") and message in err and err.count("\n") == 1


def test_bad_twist_is_an_argparse_error(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["ik", "swerve-4", "--twist", "1", "0", "inf"])
    assert exc.value.code == 2
    assert "--twist" in capsys.readouterr().err
