"""The condition number (5.28) of a robot whose gear leaves m = 2 of its wheels' 3 motions: over the motions the gear
allows, each of a gear's joints counted (one mechanism). Before: ``isotropy: not computed (its gear couplings leave
m = 2 of 3 ...)`` and ``condition_number: null``. Checked against an SVD done here: the omni wheels' spins written by
hand, the gear's line of ICRs from its ratios, the thesis's pair (v, D omega) about that line (as 5.47 for an axle),
and the natural length by a dense scan of D."""

from __future__ import annotations

import json

import numpy as np
import pytest

from wmrkit import Robot, catalog
from wmrkit.analysis.isotropy import twist_condition_number
from wmrkit.analysis.summary import analyze
from wmrkit.cli.main import main


def omni(tmp_path, ratios, actuated=("front_left", "back", "front_right")) -> Robot:
    d = catalog.load("omni-3").to_dict()
    for w in d["wheels"]:
        w["actuated"] = ["spin"] if w["name"] in actuated else []
    d["couplings"] = [{"kind": "gear", "joints": ["front_left.spin", "back.spin"], "ratios": list(ratios)}]
    path = tmp_path / "omni.json"
    path.write_text(json.dumps(d))
    return Robot.from_file(path)


def spin_rows(robot: Robot) -> np.ndarray:
    """d(spin)/d(vx, vy, omega) of each 90-degree Swedish wheel: the speed of its centre along its heading over r."""
    rows = []
    for w in robot.wheels:
        (x, y), th = w.position, w.heading
        rows.append(np.array([np.cos(th), np.sin(th), -y * np.cos(th) + x * np.sin(th)]) / w.r)
    return np.array(rows)


def brute_kappa(robot: Robot, ratios, lengths: np.ndarray) -> np.ndarray:
    """kappa of the three spins as a function of (v, D omega) about the gear's line of ICRs, at each D."""
    j = spin_rows(robot)
    c = j[0] / ratios[0] - j[1] / ratios[1]  # q_fl / k_fl = q_b / k_b: c . twist = 0
    # the ICR (x, y) of a twist (omega y, -omega x, omega) obeys c0 y - c1 x + c2 = 0: a line of direction (c0, c1)
    u = np.array([c[0], c[1]]) / np.hypot(c[0], c[1])
    p = -c[2] / np.hypot(c[0], c[1]) * np.array([-u[1], u[0]])  # its point nearest the origin
    assert abs(c[0] * p[1] - c[1] * p[0] + c[2]) < 1e-9
    e_v = np.array([-u[1], u[0], 0.0])  # the translation it allows (ICR at infinity along the line's normal)
    e_w = np.array([p[1], -p[0], 1.0])  # a unit turn about p
    assert abs(c @ e_v) < 1e-9 and abs(c @ e_w) < 1e-9
    h = np.stack([np.column_stack([j @ e_v, j @ e_w / d]) for d in lengths])
    s = np.linalg.svd(h, compute_uv=False)
    return s[:, 0] / s[:, -1]


@pytest.mark.parametrize("ratios", [(1.0, 1.0), (1.0, 2.0), (1.0, -1.0), (-3.0, 0.5)])
def test_the_condition_number_is_over_the_motions_the_gear_allows(tmp_path, ratios):
    robot = omni(tmp_path, ratios)
    a = analyze(robot, resolution=8)
    assert a.coupled_mobility == 2 and a.classification.mobility == 3
    lengths = np.geomspace(1e-3, 10.0, 200001)
    kappa = brute_kappa(robot, ratios, lengths)
    best = int(np.argmin(kappa))
    assert a.natural and a.characteristic_length == pytest.approx(lengths[best], rel=1e-3)
    at_d = brute_kappa(robot, ratios, np.array([a.characteristic_length]))[0]
    assert a.condition_number == pytest.approx(at_d, rel=1e-9)
    assert a.condition_number <= kappa[best] * (1 + 1e-12)  # the scan's best is no better
    assert "not computed" not in a.format_text()
    for d in (0.05, 1.0):  # --length
        given = float(twist_condition_number(robot, joints=a.joints, length=d, geared=True))
        assert given == pytest.approx(brute_kappa(robot, ratios, np.array([d]))[0], rel=1e-9)


def test_an_isotropic_omni_robot_stays_isotropic_on_the_motions_a_1_to_1_gear_leaves(tmp_path):
    """H^T H = k I on the twists restricts to k I on any subspace: kappa 1 at the omni's D = sqrt(2) L (5.41)."""
    a = analyze(omni(tmp_path, (1.0, 1.0)), resolution=8)
    assert a.condition_number == pytest.approx(1.0, abs=1e-12)
    assert a.characteristic_length == pytest.approx(np.sqrt(2) * 0.2, rel=1e-9)


def test_a_gear_is_one_mechanism_whichever_of_its_joints_is_listed(tmp_path):
    full = analyze(omni(tmp_path, (1.0, 2.0)), resolution=8)
    one = analyze(omni(tmp_path, (1.0, 2.0), actuated=("front_left", "front_right")), resolution=8)
    assert set(one.joints) == set(full.joints) == {"front_left.spin", "back.spin", "front_right.spin"}
    assert one.condition_number == pytest.approx(full.condition_number, rel=1e-12)
    assert one.characteristic_length == pytest.approx(full.characteristic_length, rel=1e-12)


def test_analyze_prints_and_answers_the_condition_number(tmp_path, capsys):
    robot = omni(tmp_path, (1.0, 2.0))
    assert main(["analyze", str(tmp_path / "omni.json"), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    kappa = brute_kappa(robot, (1.0, 2.0), np.array([out["characteristic_length"]]))[0]
    assert out["condition_number"] == pytest.approx(kappa, rel=1e-9) and out["natural_length"] is True
    assert main(["analyze", str(tmp_path / "omni.json")]) == 0
    text = capsys.readouterr().out
    assert f"  condition number {kappa:.4g} at the natural length D = " in text
    assert "isotropy:" not in text


def test_the_report_table_gives_the_condition_number(tmp_path):
    from wmrkit.analysis.report import write_report

    a = analyze(omni(tmp_path, (1.0, 1.0)), resolution=8)
    page = write_report(a, tmp_path / "r", resolution=8, dpi=30).read_text(encoding="utf-8")
    assert ("<tr><th>condition number κ (5.28)</th><td>1 for (front_left.spin, back.spin, front_right.spin)</td>"
            in page) and "<tr><th>characteristic length D</th><td>0.2828 m (natural)</td>" in page
    assert "not computed" not in page
