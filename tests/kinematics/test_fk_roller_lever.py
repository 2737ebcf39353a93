"""``fk``'s slip tolerance reads a Swedish roller's rate by its roller's radius (``gear_check.contact_lever``).

Before, ``wheel_ik._speed_per_rate`` read a roller's rate by the wheel's radius ``r``: the contact speed of a
roller's rate is ``r_r |phi_r_dot|`` (the roller column of the slip rows (3.22)), so ``wmrkit fk omni-3`` with
rollers 10, -5 and 4 rad/s (slip 5.8 % of the fastest contact speed, 0.1 m/s) was called consistent (tolerance
0.01 m/s, 2 % of 0.5 m/s).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.kinematics.wheel_ik import FK_SLIP_RTOL, SLIP_TOL, forward_kinematics_check


@pytest.mark.parametrize("name", ["omni-3", "mecanum-4", "thesis-omni-swedish"])
def test_fk_tolerance_reads_a_roller_rate_by_its_radius(name):
    robot = catalog.load(name)
    wheel = next(w for w in robot.wheels if w.type == "swedish")
    assert wheel.r_r < wheel.r  # the two levers differ
    column = robot.constraint_matrix()[:, robot.velocity_index(f"{wheel.name}.roller")]
    assert np.linalg.norm(column) == pytest.approx(wheel.r_r, rel=1e-12)  # the slip rows' roller speed per rad/s
    fk = forward_kinematics_check(robot, {f"{wheel.name}.roller": -10.0})
    assert fk.tolerance == pytest.approx(FK_SLIP_RTOL * wheel.r_r * 10.0 + SLIP_TOL, rel=1e-12)


def test_fk_roller_slip_beyond_2_percent_is_inconsistent(capsys):
    """omni-3 (gamma 90 deg): a roller's contact speed r_r q is along its axle; the axles are 120 deg apart, the
    front right one reversed (beta - alpha = pi), so a rigid twist leaves ``q1 + q2 - q3 = 0`` and the slip is
    ``r_r |q1 + q2 - q3| / sqrt(3)``: rollers 10, -5, 4 slip 0.01 / sqrt(3) m/s, 5.8 % of the fastest 0.1 m/s."""
    robot = catalog.load("omni-3")
    r_r = robot.wheel("front_left").r_r
    rates = {"front_left.roller": 10.0, "back.roller": -5.0, "front_right.roller": 4.0}
    fk = forward_kinematics_check(robot, rates)
    assert fk.residual == pytest.approx(r_r * abs(10 - 5 - 4) / math.sqrt(3), rel=1e-9)
    assert fk.tolerance == pytest.approx(FK_SLIP_RTOL * r_r * 10 + SLIP_TOL) and fk.consistent is False
    argv = ["fk", "omni-3", *(a for k, v in rates.items() for a in ("--spin", f"{k}={v}")), "--json"]
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["consistent"] is False
