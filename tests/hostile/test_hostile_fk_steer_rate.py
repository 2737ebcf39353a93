"""``fk`` judges a given steering rate by the speed it gives the contact point (lever ``hypot(d, b)``), not as 1 m/s
per rad/s: a castor steering rate no motion of a geared cart allows is INCONSISTENT."""

from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.linalg

from geared import cart_yaml, held_constraints
from wmrkit import Robot
from wmrkit.cli.main import main


def _motions(robot: Robot) -> np.ndarray:
    """Brute force: the no-slip motions, the null space of (3.22) with the gear rows."""
    return scipy.linalg.null_space(held_constraints(robot))


@pytest.mark.parametrize("steer", [1.0, -0.5, 3.0])
def test_a_castor_steering_rate_no_geared_motion_has_is_inconsistent(tmp_path, capsys, steer):
    path = tmp_path / "cart.yaml"
    gear = "joints: [left.spin, caster.spin], ratios: [1, 3]"  # left wheel and castor on one chain (equal speeds)
    path.write_text(cart_yaml().replace("joints: [left.spin, right.spin], ratios: [1, 1.0]", gear))
    robot = Robot.from_file(path)
    motions = _motions(robot)
    assert motions.shape[1] == 1 and abs(motions[robot.velocity_index("caster.steer"), 0]) < 1e-12
    assert main(["fk", str(path), "--spin", f"caster.steer={steer}", "--json"]) == 0  # an answer, with its warning
    out = json.loads(capsys.readouterr().out)
    lever = robot.wheel("caster").d  # the contact point's speed per rad/s of steering
    assert out["residual"] > 0.1 * lever * abs(steer)  # no motion has it: a sizeable part of that speed slips
    assert out["consistent"] is False  # was True: tolerance 0.02 m/s per rad/s, above the 0.0167 m/s residual


def test_a_no_slip_steering_rate_stays_consistent(tmp_path, capsys):
    path = tmp_path / "cart.yaml"
    path.write_text(cart_yaml(1.0).replace("ratios: [1, 1.0]", "ratios: [1, -1.0]"))  # spins on the spot
    robot = Robot.from_file(path)
    q = _motions(robot)[:, 0]
    q = q / q[robot.velocity_index("left.spin")]
    given = ["--spin", f"left.spin={q[robot.velocity_index('left.spin')]:.17g}",
             "--spin", f"caster.steer={q[robot.velocity_index('caster.steer')]:.17g}"]
    assert abs(q[robot.velocity_index("caster.steer")]) > 1  # the castor swings round as the cart turns
    assert main(["fk", str(path), *given, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["consistent"] is True and np.allclose(out["twist"], q[:3], atol=1e-12)
