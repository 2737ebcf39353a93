"""analyze with a ``gear`` coupling: the type line keeps the thesis's m (Table 5.1, the wheels alone) and says the m
the gears leave (the actuation and sensing verdicts' m); the condition number (5.28), a model of the wheels alone,
is not given where the gears leave fewer motions: one encoder of a solid axle, which fk says determines the twist,
was called 'condition number infinite (these joints do not determine the twist)'; with m = 2 left it is over those
two motions. The HTML report's table shows the
commanded steerability and the geared mobility."""

from __future__ import annotations

import json

import numpy as np
import pytest

from geared import SYNCHRO, cart_yaml
from wmrkit import Robot, catalog
from wmrkit.analysis.report import write_report
from wmrkit.analysis.summary import analyze
from wmrkit.cli.main import main
from wmrkit.kinematics.wheel_ik import twist_is_determined


def geared_mobility(robot: Robot, ratios: dict[str, float]) -> int:
    """k - rank of the no-slip matrix (3.22) with the gear's rows q_j / k_j - q_0 / k_0 = 0 appended."""
    a = robot.constraint_matrix()
    (j0, k0), *rest = ratios.items()
    rows = np.zeros((len(rest), a.shape[1]))
    for i, (j, k) in enumerate(rest):
        rows[i, robot.velocity_index(j)], rows[i, robot.velocity_index(j0)] = 1 / k, -1 / k0
    full = np.vstack([a, rows])
    return full.shape[1] - np.linalg.matrix_rank(full)


@pytest.mark.parametrize("ratio", [1.0, 2.0])
def test_a_solid_axle_reports_the_geared_mobility_and_no_infinite_condition_number(tmp_path, capsys, ratio):
    path = tmp_path / "cart.yaml"
    path.write_text(cart_yaml(ratio))
    robot = Robot.from_file(path)
    m = geared_mobility(robot, {"left.spin": 1.0, "right.spin": ratio})
    assert m == 1 and bool(twist_is_determined(robot, ["left"]))  # as fk says: one encoder gives the twist
    text = analyze(robot, resolution=8).format_text()
    first = text.splitlines()[0]
    assert first.endswith("mobility m = 2, steerability d = 0; its gear couplings leave m = 1 (couplings)")
    assert "  isotropy: does not apply (its gear couplings leave m = 1: no two motions to balance)" in text
    assert "infinite" not in text
    assert "(1 actuated rate; the joint model's mobility 1, eq. 4.3)" in str(analyze(robot, resolution=8).actuation)
    assert main(["analyze", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert (out["mobility"], out["coupled_mobility"]) == (2, m)
    assert out["condition_number"] is None and out["characteristic_length"] is None


def test_gears_that_leave_two_motions_of_three_give_the_condition_number_of_those_two(tmp_path):
    """omni-3 with two wheels on one gear: m = 3 by its wheels, 2 with the gear; kappa over the two (its value
    against an SVD: tests/analysis/test_gear_isotropy.py)."""
    d = catalog.load("omni-3").to_dict()
    d["couplings"] = [{"kind": "gear", "joints": ["front_left.spin", "back.spin"], "ratios": [1, 1]}]
    path = tmp_path / "omni.json"
    path.write_text(json.dumps(d))
    robot = Robot.from_file(path)
    a = analyze(robot, resolution=8)
    assert a.coupled_mobility == geared_mobility(robot, {"front_left.spin": 1.0, "back.spin": 1.0}) == 2
    assert "isotropy:" not in a.format_text() and "condition number 1 at the natural length" in a.format_text()
    assert a.to_dict()["condition_number"] == pytest.approx(1.0)


@pytest.mark.parametrize("name", ["diff-drive", "ackermann", "omni-3", "swerve-4", "forklift"])
def test_without_a_gear_nothing_changes(name):
    a = analyze(catalog.load(name), resolution=8)
    assert a.coupled_mobility == a.instantaneous_mobility and a.gear_mobility is None
    assert "gear couplings" not in a.format_text()


def test_the_report_table_shows_the_commanded_steerability_and_the_geared_mobility(tmp_path):
    """Before: neither row (the JSON and the text had commanded_steerability, the report did not)."""
    path = tmp_path / "synchro.yaml"
    path.write_text(SYNCHRO)
    a = analyze(Robot.from_file(path), resolution=8)
    page = write_report(a, tmp_path / "r", resolution=8, dpi=30).read_text(encoding="utf-8")
    assert "<tr><th>steerability its steering linkages command</th><td>1</td></tr>" in page
    assert f"<tr><th>mobility with its gear couplings</th><td>{a.coupled_mobility}</td></tr>" in page
