"""Given (exact) rates of a ``gear``'s joints are judged to round-off, measured logs to 10 %.

Before: ``fk``, ``forward_kinematics_check`` and the extended solutions (§4.5) judged rates typed by a person with
the 10 % meant for encoder logs (``couplings.GEAR_BREACH_RTOL``): ``right.spin`` 1.9 for ``left.spin`` 1 on the
castor cart's 1:2 axle was used as given (a turn, ``omega`` 0.169 rad/s instead of the gear's 0.1875) and called
consistent, no warning. The spread is checked in closed form: ``u = q / ratio`` per joint, ``(max u - min u) /
max |u|`` = ``(1 - 1.9 / 2) / 1`` = 5 %.
"""

from __future__ import annotations

import json
import warnings

import pytest

from geared import cart_yaml
from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.kinematics.extended import GearWarning, extended_solution
from wmrkit.kinematics.wheel_ik import forward_kinematics_check

GEAR = "gear(left.spin, right.spin)"
WORDS = ("the joints of the gear of wheels 'left' and 'right' (ratios 1, 2) do not turn together (left.spin 1, "
         "right.spin 1.9 rad/s; 5% apart)")
IN_RATIO = [2.0, 2.0 * (1 + 1e-15)]  # the ratio, and the ratio to round-off


@pytest.fixture
def cart(tmp_path):
    path = tmp_path / "cart.yaml"
    path.write_text(cart_yaml(2.0))
    return path, Robot.from_file(path)


def test_python_fk_warns_of_rates_5_percent_out_of_the_gear(cart):
    _, robot = cart
    with pytest.warns(GearWarning) as caught:
        fk = forward_kinematics_check(robot, {"left.spin": 1.0, "right.spin": 1.9})
    assert len(caught) == 1 and str(caught[0].message).startswith(WORDS)
    assert fk.residual < 1e-12  # the castor takes any turn: no slip shows it
    assert fk.consistent is False and fk.out_of_gear == (GEAR,)


@pytest.mark.parametrize("right", IN_RATIO)
def test_python_fk_is_silent_on_rates_in_the_gear(cart, right):
    _, robot = cart
    with warnings.catch_warnings():
        warnings.simplefilter("error", GearWarning)
        fk = forward_kinematics_check(robot, {"left.spin": 1.0, "right.spin": right})
    assert fk.consistent is True and fk.out_of_gear == ()


@pytest.mark.parametrize(("right", "said"), [(1.9, [WORDS]), *((r, []) for r in IN_RATIO)])
def test_cli_fk_judges_given_rates_to_round_off(cart, capsys, right, said):
    path, _ = cart
    assert main(["fk", str(path), "--spin", "left.spin=1", "--spin", f"right.spin={right!r}", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [w[:len(WORDS)] for w in out["warnings"]] == said
    assert out["consistent"] is not said


def test_extended_solutions_judge_assigned_rates_to_round_off(cart):
    _, robot = cart
    with pytest.warns(GearWarning) as caught:
        sol = extended_solution(robot, ["left.spin", "right.spin"], [[1.0, 1.9], [1.0, 2.0], [1.0, IN_RATIO[1]]])
    assert len(caught) == 1 and str(caught[0].message).startswith(WORDS)
    assert sol.in_gear[:, 0].tolist() == [False, True, True]


def test_a_tiny_spread_is_not_printed_as_0_percent(cart):
    """1e-6 apart (a rate typed to 7 digits) is out of the gear beyond round-off: said as 0.0001%, not "0%"."""
    _, robot = cart
    with pytest.warns(GearWarning, match=r"; 0\.0001% apart\)"):
        forward_kinematics_check(robot, {"left.spin": 1.0, "right.spin": 2.0 * (1 - 1e-6)})
