"""``kinematics --symbolic`` holds a description's gears: the closed forms solve the no-slip matrix with the rows
``q_i / ratio_i - q_j / ratio_j = 0`` when the set is assignable on the motions the gears allow; a form that no exact
solution can give (the synchro's, its steering angles free symbols) stays the wheels' least squares, and says so.

The checks are independent of the symbolic code: its solutions, evaluated at random steering, against the numeric
no-slip matrix (3.22) and the gear's ratios.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import sympy as sp
import yaml

from geared import SYNCHRO, TWO_ENCODERS, cart_yaml
from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.kinematics.symbolic import steering_symbols, symbolic_model, twist_assignment


def load(text: str) -> Robot:
    return Robot.from_dict(yaml.safe_load(text))


def velocities(robot: Robot, model, beta: np.ndarray, q_assigned: np.ndarray) -> np.ndarray:
    """The whole velocity vector of the closed form at steering `beta` (the thesis's angles)."""
    values = dict(zip(steering_symbols(robot), beta.tolist(), strict=True))
    matrix = np.array(model.matrix.xreplace({k: sp.Float(v) for k, v in values.items()}).evalf(), dtype=float)
    q = np.empty(len(robot.velocity_names))
    q[[robot.velocity_index(n) for n in model.assigned]] = q_assigned
    q[[robot.velocity_index(n) for n in model.solved]] = matrix @ q_assigned
    return q


@pytest.mark.parametrize("ratio", [1.0, 2.0, -1.0])
def test_the_carts_closed_forms_roll_without_slip_and_keep_the_gear(ratio):
    robot = load(cart_yaml(ratio))
    rng = np.random.default_rng(3)
    for names in (("left.spin",), twist_assignment(robot)):
        model = symbolic_model(robot, names)
        assert model.exact and model.mobility == 1
        for _ in range(4):
            beta = rng.uniform(-np.pi, np.pi, len(robot.steer_names))
            q = velocities(robot, model, beta, rng.uniform(-2, 2, len(names)))
            assert np.abs(robot.constraint_matrix(beta) @ q).max() <= 1e-9 * np.abs(q).max()
            left, right = q[robot.velocity_index("left.spin")], q[robot.velocity_index("right.spin")]
            assert right == pytest.approx(ratio * left, rel=1e-12)


def test_a_least_squares_form_cannot_hold_a_gear():
    robot = load(cart_yaml(2.0))
    with pytest.raises(Exception, match="not an assignable set of the motions its gears allow"):
        symbolic_model(robot, ("vx", "vy", "omega"))
    wheels = symbolic_model(robot, ("vx", "vy", "omega"), gears=False)  # the wheels' least squares, as before
    assert not wheels.exact and wheels.mobility == 2


def test_cli_symbolic_holds_the_cart_gear_without_a_warning(tmp_path, capsys):
    path = tmp_path / "cart.yaml"
    path.write_text(cart_yaml(2.0))
    assert main(["kinematics", str(path), "--symbolic"]) == 0
    out, err = capsys.readouterr()
    assert err == "" and "    right.spin = 2*left.spin\n" in out and "not held" not in out


def test_cli_symbolic_says_which_forms_do_not_hold_the_synchro_gear(tmp_path, capsys):
    path = tmp_path / "synchro.yaml"
    path.write_text(SYNCHRO)
    assert main(["kinematics", str(path), "--symbolic", "--json"]) == 0
    out, err = capsys.readouterr()
    warnings = json.loads(out)["warnings"]
    assert len(warnings) == 2 and all("of the wheels alone, not holding the gear of wheels 'a', 'b' and 'c'" in w
                                      for w in warnings)
    assert err.count("wmrkit: warning: the closed-form") == 2
    assert json.loads(out)["symbolic"].count("of the wheels alone, the gears not held") == 2


def test_cli_codegen_holds_the_gear_without_a_warning(tmp_path, capsys):
    """The generated code holds gears (tests/kinematics/test_gear_codegen.py): no warning any more."""
    path = tmp_path / "axle.yaml"
    path.write_text(TWO_ENCODERS)
    assert main(["kinematics", str(path), "--codegen", "python", str(tmp_path / "out")]) == 0
    assert "warning" not in capsys.readouterr().err
