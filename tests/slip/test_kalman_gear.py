"""The velocity filters FK1/FK2 know a ``gear``'s unsensed joints from its sensed ones, as odometry and ``fk`` do
(``OdometryModel.fill``): on slip-free logs of constant twist they give the exact poses, as WLS does
(tests/slip/test_odometry.py mirrors this for catalog robots). The truth: ``simulate``'s poses, and the closed form
of a differential axle ``vx = r (q_l + q_r) / 2``, ``omega = r (q_r - q_l) / (2 b)``, ``q_r = ratio q_l``."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from geared import CASTOR, STEERED, B, R, cart_yaml
from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.errors import WmrkitError
from wmrkit.kinematics.wheel_ik import twist_is_determined
from wmrkit.odometry.model import odometry_model
from wmrkit.odometry.pipeline import odometry
from wmrkit.odometry.synthetic import TwistProfile, simulate
from wmrkit.slip.estimators import estimator
from wmrkit.slip.kalman import KalmanNoise, kalman_model


def cart(tmp_path, ratio: float, front: str = CASTOR) -> tuple:
    path = tmp_path / "cart.yaml"
    path.write_text(cart_yaml(ratio, front))
    return path, Robot.from_file(path)


def twist_of(rate: float, ratio: float) -> np.ndarray:
    return np.array([R * (1 + ratio) * rate / 2, 0.0, R * (ratio - 1) * rate / (2 * B)])


@pytest.mark.parametrize(("kind", "front", "ratio"), [
    pytest.param("fk2", CASTOR, 1.0, id="fk2-castor-1"), pytest.param("fk2", CASTOR, 2.0, id="fk2-castor-2"),
    pytest.param("fk2", CASTOR, -0.5, id="fk2-castor--0.5"), pytest.param("fk1", STEERED, 1.5, id="fk1-steered-1.5"),
    pytest.param("fk2", STEERED, 1.5, id="fk2-steered-1.5")])
def test_a_filter_on_a_geared_axle_is_exact_without_slip(tmp_path, kind, front, ratio):
    """Before: 'fk2: the sensed rows of robot 'geared-axle' do not determine its twist' (the right wheel's rows were
    left out, its spin unsensed); FK1 with a steered front wheel, whose lateral row it keeps, the same ('use fk2')."""
    _, robot = cart(tmp_path, ratio, front)
    run = simulate(robot, TwistProfile.from_segments([(3.0, *twist_of(8.0, ratio))]), 20.0)
    assert run.log.joints[0] == "left.spin" and "right.spin" not in run.log.joints
    poses = estimator(robot, kind).run([run.log]).final_pose
    np.testing.assert_allclose(poses, run.truth[-1], atol=1e-9)
    np.testing.assert_allclose(poses, odometry(robot, run.log).poses[-1], atol=1e-9)


def test_fk1_still_needs_a_lateral_row(tmp_path):
    """With the castor (no row without an unknown rate) FK1 keeps the two rolling rows only: vy is not measured,
    as on a differential drive, and it says so."""
    _, robot = cart(tmp_path, 1.0)
    with pytest.raises(WmrkitError, match=r"fk1: the sensed rows .* do not determine its twist.*use fk2"):
        kalman_model(robot, "fk1")


def test_odometry_cli_fk2_on_a_solid_axle_with_one_encoder(tmp_path, capsys):
    """`wmrkit odometry cart.yaml log.csv --method fk2` exited 2 before; now 10 rad of the left spin in 1 s move the
    cart 10 r = 0.75 m straight ahead, as --method wls prints."""
    path, _ = cart(tmp_path, 1.0)
    log = tmp_path / "log.csv"
    log.write_text("time,left.spin\n" + "".join(f"{t / 10:.1f},{t}\n" for t in range(11)))
    assert main(["odometry", str(path), str(log), "--method", "fk2", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    np.testing.assert_allclose(out["final_pose"], [10 * R, 0, 0], atol=1e-12)
    assert out["warnings"] == []


#: A Mecanum front wheel (rollers at 45 deg) whose spin alone is sensed: its rolling row gives the speed along it,
#: the axle's lateral rows vy = 0, and only the gear (neither axle spin sensed) relates omega to them.
MECANUM = "front, type: swedish, position: [0.6, 0], beta: 0, gamma: 0.7853981633974483, r: 0.05, r_r: 0.01}"
STEERED_FULL = "front, type: steerable, position: [0.6, 0], heading: 0, r: 0.1}"


@pytest.mark.parametrize(("kind", "front", "sensed", "ratio"), [
    pytest.param("fk2", MECANUM, ["front.spin"], 1.0, id="fk2-mecanum-1"),
    pytest.param("fk2", MECANUM, ["front.spin"], 2.0, id="fk2-mecanum-2"),
    pytest.param("fk2", MECANUM, ["front.spin"], -0.5, id="fk2-mecanum--0.5"),
    pytest.param("fk1", STEERED_FULL, ["front.steer", "front.spin"], 1.5, id="fk1-steered-1.5"),
    pytest.param("fk1", STEERED_FULL, ["front.steer", "front.spin"], -2.0, id="fk1-steered--2")])
def test_a_filter_holds_a_gear_with_no_sensed_joint(tmp_path, kind, front, sensed, ratio):
    """Neither axle spin sensed: the gear's turn is one unknown of its two rolling rows (as WLS holds it). Before,
    both rows were left out and the filter refused ('fk2: the sensed rows ... do not determine its twist'), though
    twist_is_determined (and WLS) use the gear. Without the gear the Mecanum's spin does not fix the twist, and
    FK1 (no lateral rows of fixed wheels) with the steered wheel is refused."""
    _, robot = cart(tmp_path, ratio, front)
    ungeared = Robot.from_dict({k: v for k, v in yaml.safe_load(cart_yaml(ratio, front)).items() if k != "couplings"})
    rates = [s for s in sensed if not s.endswith(".steer")]
    assert twist_is_determined(robot, rates)
    if kind == "fk2":
        assert not twist_is_determined(ungeared, rates)
    else:
        with pytest.raises(WmrkitError, match=r"fk1: the sensed rows .* do not determine its twist"):
            kalman_model(ungeared, kind, sensed=sensed)
    run = simulate(robot, TwistProfile.from_segments([(3.0, *twist_of(8.0, ratio))]), 20.0, sensed=sensed)
    poses = estimator(robot, kind, sensed=sensed).run([run.log]).final_pose
    np.testing.assert_allclose(poses, run.truth[-1], atol=1e-9)
    np.testing.assert_allclose(poses, odometry(odometry_model(robot, sensed), run.log).poses[-1], atol=1e-9)


def test_the_gear_turn_is_marginalised_with_the_rows_noise(tmp_path):
    """The information the kept rows give of the twist, the gear's turn u unknown, is the Schur complement of u in
    the information of (twist, u) (a flat prior on u), with unequal row noise so the weighting shows."""
    _, robot = cart(tmp_path, 2.0, MECANUM)
    noise = KalmanNoise(0.5, 0.2, 0.3, (("left", 0.05, 0.07), ("front", 0.4, 0.11)))
    model = kalman_model(robot, "fk2", noise, ["front.spin"])
    a = robot.constraint_matrix(robot.beta)[model.rows]
    names = robot.velocity_names
    turn = np.zeros(len(names))
    turn[[names.index("left.spin"), names.index("right.spin")]] = 1.0, 2.0  # the gear's ratios
    ct = np.concatenate([a[:, :3], (a @ turn)[:, None]], axis=1)  # (twist, u) columns
    info = ct.T @ (ct / (model.sigma ** 2 / model.process)[:, None])
    expected = info[:3, :3] - np.outer(info[:3, 3], info[3, :3]) / info[3, 3]
    h = model.matrices(robot.beta[None])[0][0]
    np.testing.assert_allclose(h, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())
