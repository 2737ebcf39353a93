"""analyze's ICR holds the robot's gears. Before: omni-3 with front_left.spin and back.spin on a gear printed "ICR
anywhere in the plane" (text and JSON) and the solid-axle cart "ICR anywhere on the line through (0, 0) along (0, 1)",
the wheels' ICR without the gear. Checked against the twists the geared robot admits, from an SVD done here: the null
space of the no-slip rows (3.22) plus the gear's row, their ICRs (x, y) = (-vy / omega, vx / omega)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_gear_isotropy import omni

from geared import cart_yaml
from wmrkit import Robot
from wmrkit.analysis.icr import icr
from wmrkit.analysis.summary import analyze
from wmrkit.cli.main import main


def admitted_twists(robot: Robot, joints: tuple[str, str], ratios) -> np.ndarray:
    """An orthonormal basis (rows) of the twists (vx, vy, omega) the wheels admit with q_a / k_a = q_b / k_b."""
    a = robot.constraint_matrix()
    gear = np.zeros(a.shape[1])
    gear[robot.velocity_index(joints[0])], gear[robot.velocity_index(joints[1])] = 1 / ratios[0], -1 / ratios[1]
    rows = np.vstack([a, gear])
    _, s, vh = np.linalg.svd(rows)
    kernel = vh[int(np.sum(s > 1e-10 * s[0])):]  # (velocity, rates) the robot can have
    _, s2, vt = np.linalg.svd(kernel[:, :3])
    return vt[:int(np.sum(s2 > 1e-10))]


def cross(a, b) -> float:
    """The z component of the cross product of two plane vectors."""
    return float(a[0] * b[1] - a[1] * b[0])


def off(basis: np.ndarray, twist: np.ndarray) -> float:
    """Distance of the unit `twist` from the span of `basis`: 0 when the robot admits it."""
    t = twist / np.linalg.norm(twist)
    return float(np.linalg.norm(t - basis.T @ (basis @ t)))


@pytest.mark.parametrize("ratios", [(1.0, 1.0), (1.0, 2.0), (1.0, -1.0), (-3.0, 0.5)])
def test_the_icr_of_a_geared_omni_robot_is_on_the_line_analyze_reports_and_only_there(tmp_path, ratios):
    robot = omni(tmp_path, ratios)
    basis = admitted_twists(robot, ("front_left.spin", "back.spin"), ratios)
    assert len(basis) == 2  # m = 2: a line of ICRs
    s = analyze(robot, resolution=8).icr
    assert s.kind == "line"
    lx, ly, d = s.line
    foot, u = np.array([d * ly, -d * lx]), np.array([lx, ly])
    rng = np.random.default_rng(1)
    for twist in rng.normal(size=(50, 2)) @ basis:  # every admitted turn is about a point of the line
        x, y = -twist[1] / twist[2], twist[0] / twist[2]
        assert abs(cross([x - foot[0], y - foot[1]], u)) < 1e-9 * max(1.0, np.hypot(x, y))
    for t in (-3.0, -0.2, 0.0, 0.5, 4.0):  # every point of the line is an admitted ICR, no point beside it is
        x, y = foot + t * u
        assert off(basis, np.array([y, -x, 1.0])) < 1e-12
        x, y = foot + t * u + 0.05 * np.array([-u[1], u[0]])
        assert off(basis, np.array([y, -x, 1.0])) > 1e-3
    assert off(basis, np.array([u[1], -u[0], 0.0])) < 1e-12  # the ICR at the line's end: a translation across it


def test_a_1_to_2_gear_puts_the_line_of_icrs_off_the_origin(tmp_path, capsys):
    robot = omni(tmp_path, (1.0, 2.0))
    basis = admitted_twists(robot, ("front_left.spin", "back.spin"), (1.0, 2.0))
    normal = np.cross(basis[0], basis[1])  # normal . twist = 0: n0 vx + n1 vy + n2 omega = 0, i.e. the ICR line
    distance = abs(normal[2]) / np.hypot(normal[0], normal[1])  # n0 y - n1 x + n2 = 0 at (x, y) = (-vy, vx) / omega
    assert distance == pytest.approx(0.0756, abs=1e-4)
    d = icr(robot, geared=True).line[2]
    assert abs(d) == pytest.approx(distance, rel=1e-9)
    assert icr(robot).kind == "plane"  # the wheels alone: no axle
    assert main(["analyze", str(tmp_path / "omni.json"), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["icr"] == icr(robot, geared=True).describe() and out["icr"].startswith("ICR anywhere on the line")
    assert main(["analyze", str(tmp_path / "omni.json")]) == 0
    text = capsys.readouterr().out
    assert "anywhere in the plane" not in text and f"  {out['icr']}\n" in text


@pytest.mark.parametrize("ratio", [1.0, 2.0, -1.0, 0.5])
def test_a_solid_axle_cart_turns_about_the_point_its_gear_fixes(tmp_path, ratio):
    path = tmp_path / "cart.yaml"
    path.write_text(cart_yaml(ratio))
    robot = Robot.from_file(path)
    basis = admitted_twists(robot, ("left.spin", "right.spin"), (1.0, ratio))
    assert len(basis) == 1  # m = 1: one ICR
    s = analyze(robot, resolution=8).icr
    (vx, vy, omega), = basis
    if abs(omega) < 1e-12:  # 1:1: straight ahead only
        assert s.kind == "infinity" and abs(cross(s.direction, [vx, vy])) < 1e-12
    else:
        assert s.kind == "point" and s.point == pytest.approx((-vy / omega, vx / omega), abs=1e-12)
