"""A ``gear`` coupling fixes its unsensed joints from its sensed ones (``q_j = ratio_j * u``): ``fk``, ``odometry``,
the sensing analysis and analyze's sensed singular set use them (``wmrkit.couplings.gear_fill``). Checked against
the differential drive's closed form: ``vx = r (q_l + q_r) / 2``, ``omega = r (q_r - q_l) / (2 b)``."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from geared import B, R, cart_yaml
from wmrkit import Robot
from wmrkit.analysis.summary import analyze
from wmrkit.cli.main import main
from wmrkit.couplings import Coupling, gear_fill
from wmrkit.kinematics.sensing import sensing_analysis
from wmrkit.kinematics.wheel_ik import forward_kinematics, forward_kinematics_check, twist_is_determined
from wmrkit.odometry.model import odometry_model


def axle(tmp_path, ratio: float = 2.0):
    path = tmp_path / "axle.yaml"
    path.write_text(cart_yaml(ratio))
    return path, Robot.from_file(path)


def closed_form(left: float, ratio: float) -> np.ndarray:
    right = ratio * left
    return np.array([R * (left + right) / 2, 0.0, R * (right - left) / (2 * B)])


@pytest.mark.parametrize("ratio", [1.0, 2.0, -1.0, 0.5])
def test_fk_fills_the_geared_spin(tmp_path, ratio):
    """Before: left.spin alone left omega free: 'do not determine the twist', the minimum-norm twist printed
    (0.348, 0, -2.01) for left = 10 on a 1:1 gear; now the gear's right.spin = ratio * left.spin is used."""
    _, robot = axle(tmp_path, ratio)
    twist, residual = forward_kinematics(robot, {"left": 10.0})
    np.testing.assert_allclose(twist, closed_form(10.0, ratio), atol=1e-12)
    assert residual < 1e-12 and bool(twist_is_determined(robot, ["left"]))
    fk = forward_kinematics_check(robot, {"left": 10.0})
    np.testing.assert_allclose(fk.twist, closed_form(10.0, ratio), atol=1e-12)
    assert fk.consistent


def test_fk_cli_says_determined(tmp_path, capsys):
    path, _ = axle(tmp_path, 1.0)
    assert main(["fk", str(path), "--spin", "left=10", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["determined"] is True and out["warnings"] == []
    np.testing.assert_allclose(out["twist"], [0.75, 0, 0], atol=1e-12)


def test_a_gear_of_three_fills_from_the_least_squares_turn():
    """Two of three joints given: u = k_g . q_g / k_g . k_g, the third q = k u; given joints stay as given."""
    names = ("vx", "a", "b", "c")
    gear = Coupling("gear", ("a", "b", "c"), (1.0, 2.0, -3.0))
    columns, f = gear_fill((gear,), names, (1, 2))
    assert columns == (1, 2, 3)
    q = np.array([1.0, 2.2])
    u = (1.0 * 1.0 + 2.0 * 2.2) / 5.0
    np.testing.assert_allclose(f @ q, [1.0, 2.2, -3.0 * u], rtol=1e-15)
    assert gear_fill((gear,), names, (0,))[0] == (0,)  # no joint of the gear given: nothing filled


@pytest.mark.parametrize("ratio", [1.0, 2.0])
def test_sensing_analysis_counts_the_geared_joint(tmp_path, ratio):
    """Before: 'insufficient sensors ... (1 sensed rate, m = 2)'; now basic sensing with m = 1 (the gear's
    motions, as the actuation analysis counts them) and the direct matrix of the closed form."""
    _, robot = axle(tmp_path, ratio)
    s = sensing_analysis(robot)
    assert bool(s.sufficient) and s.leaf == "determined" and int(s.mobility) == 1
    np.testing.assert_allclose(s.twist([10.0]), closed_form(10.0, ratio), atol=1e-12)
    assert "right.spin" not in s.full_names
    assert not bool(sensing_analysis(dataclasses.replace(robot, couplings=())).sufficient)  # the gear makes it


def test_analyze_sensed_singular_set_with_the_geared_joint(tmp_path):
    """Before: 'singular (sensed: left.spin): always', next to 'sensing: sufficient'."""
    _, robot = axle(tmp_path, 1.0)
    a = analyze(robot, resolution=8)
    assert a.sensing["sufficient"] and a.singular["sensed"].never
    assert "singular (sensed: left.spin, right.spin): never" in a.format_text()


@pytest.mark.parametrize("ratio", [1.0, 2.0])
def test_odometry_model_fills_the_geared_spin(tmp_path, ratio):
    """Before: SensingError 'the sensed joints ... (left.spin) do not determine its motion'."""
    _, robot = axle(tmp_path, ratio)
    model = odometry_model(robot)
    inc = model.increments(np.array([[0.1], [-0.3]]))
    np.testing.assert_allclose(inc.increments_robot, [closed_form(0.1, ratio), closed_form(-0.3, ratio)],
                               atol=1e-14)
    np.testing.assert_allclose(inc.joint_increments[:, :2], [[0.1, 0.1 * ratio], [-0.3, -0.3 * ratio]], atol=1e-14)
    assert inc.slip.max() < 1e-14


def test_odometry_cli_on_a_geared_axle(tmp_path, capsys):
    """Before: exit 2, "the sensed joints of robot 'geared-axle' (left.spin) do not determine its motion"."""
    path, _ = axle(tmp_path, 1.0)
    log = tmp_path / "axle.csv"
    log.write_text("time,left.spin\n" + "".join(f"{t / 10:.1f},{t}\n" for t in range(11)))
    assert main(["odometry", str(path), str(log), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    np.testing.assert_allclose(out["final_pose"], [10 * R, 0, 0], atol=1e-12)
    assert out["consistent"] is True and out["warnings"] == []



@pytest.mark.parametrize(("ratio", "right", "spread"), [(1.0, 5.0, 0.5), (2.0, 30.0, 1 / 3), (-1.0, 10.0, 2.0),
                                                         (1.0, 10.5, 0.05), (2.0, 20.0, None),
                                                         (2.0, 20.0 * (1 + 1e-15), None)])
def test_fk_warns_of_given_rates_out_of_the_gear_as_odometry_does(tmp_path, capsys, ratio, right, spread):
    """Before: `fk cart.yaml --spin left=10 --spin right=5` on a 1:1 gear printed the differential twist, consistent,
    no warning (each given joint is read as given, so no slip shows it); `odometry` warned of such a log. Now the
    same check (couplings.gear_breaches): u = q / ratio per joint, spread = (max u - min u) / max |u|, beyond
    round-off for given rates (GEAR_EXACT_RTOL: 10.5 on a 1:1 gear, 5 % apart, passed the logs' 10 % before)."""
    path, _ = axle(tmp_path, ratio)
    assert main(["fk", str(path), "--spin", "left=10", "--spin", f"right={right!r}", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    np.testing.assert_allclose(out["twist"], [R * (10 + right) / 2, 0, R * (right - 10) / (2 * B)], atol=1e-12)
    if spread is None:  # in the ratio, to round-off
        assert out["warnings"] == [] and out["consistent"] is True
        return
    assert out["consistent"] is False and len(out["warnings"]) == 1
    want = (f"the joints of the gear of wheels 'left' and 'right' (ratios 1, {ratio:g}) do not turn together "
            f"(left.spin 10, right.spin {right:g} rad/s; {spread:.0%} apart)")
    assert out["warnings"][0].startswith(want)
    assert main(["fk", str(path), "--spin", "left=10", "--spin", f"right={right!r}"]) == 0
    text = capsys.readouterr()
    assert text.err.count("\n") == 1
    assert text.err.startswith("wmrkit: warning: the joints of the gear of wheels 'left' and 'right' (")
    assert "(INCONSISTENT)" in text.out
