"""``fk`` flags given steering angles that break a held ``linkage``'s law (kinematics/linkage_check.py).

Before: ``wmrkit fk synchro.yaml --spin a=10 --steer b=10deg`` (a synchro drive, all wheels in one ``parallel``
linkage, described at heading 0) used b's 10 deg as given and named only the slip it left; with headings that
leave no slip (a car's front wheels off the Ackermann angles, its rear spins free) nothing was said. The tolerance is
fk's slip one: a wheel off by ``e`` slips sideways at ``sin(e)`` of its speed, so ``asin(0.02)`` = 1.146 deg.
"""

from __future__ import annotations

import json
import math
import warnings

import pytest

from wmrkit import Robot, catalog
from wmrkit.cli.main import main
from wmrkit.kinematics.linkage_check import LinkageAngleWarning
from wmrkit.kinematics.wheel_ik import forward_kinematics_check

TRIANGLE = [(0.2, 0.0), (-0.1, 0.173), (-0.1, -0.173)]
DATA = {"name": "synchro", "wheels": [{"name": n, "type": "steerable", "position": list(p), "heading": 0, "r": 0.05}
                                      for n, p in zip("abc", TRIANGLE, strict=True)],
        "couplings": [{"kind": "linkage", "joints": ["a.steer", "b.steer", "c.steer"]}]}


def fk(robot, headings_deg, rates):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = forward_kinematics_check(robot, rates, heading=[math.radians(h) for h in headings_deg])
    return out, [str(w.message) for w in caught if issubclass(w.category, LinkageAngleWarning)]


@pytest.mark.parametrize(("b_deg", "broken"), [(0.0, False), (1.1, False), (1.2, True), (10.0, True),
                                                (180.0, True), (-180.0, True)])
def test_a_parallel_linkage_s_given_headings_are_judged_within_fk_s_slip_tolerance(b_deg, broken):
    """The linkage sets b at a's heading (equal rest headings); 180 deg off is a wheel the chain cannot turn so."""
    assert (math.sin(math.radians(abs(b_deg) % 180 or abs(b_deg))) > 0.02 or abs(b_deg) == 180) is broken
    out, said = fk(Robot.from_dict(DATA), [0.0, b_deg, 0.0], {"a": 10.0})
    assert bool(out.out_of_linkage) is broken and len(said) == int(broken)
    if broken:
        shown = abs(b_deg) if abs(b_deg) == 180 else b_deg  # headings print in (-180, 180]
        assert out.out_of_linkage == ("linkage(a.steer, b.steer, c.steer)",) and not out.consistent
        assert said[0].startswith("the headings break a steering linkage: the steering linkage of wheels 'a', 'b' "
                                  f"and 'c' (law parallel) sets b at heading 0 deg with a at 0 deg, not {shown:g} deg")


def test_headings_that_leave_no_slip_but_break_the_linkage_are_flagged():
    """Two synchro wheels: any two headings leave no slip (their axles meet at an ICR), so only the law can tell:
    at 0 and 10 deg fk found a turn, silently, that the chain (both at one heading) cannot make."""
    data = {**DATA, "wheels": DATA["wheels"][:2], "couplings": [{"kind": "linkage", "joints": ["a.steer", "b.steer"]}]}
    out, said = fk(Robot.from_dict(data), [0.0, 10.0], {"a": 10.0})
    assert out.residual < 1e-9 and abs(out.twist[2]) > 0.1  # a turn, and no slip to show it
    assert out.out_of_linkage == ("linkage(a.steer, b.steer)",) and not out.consistent and len(said) == 1


def test_headings_off_the_ackermann_angles_are_flagged():
    """At 20 deg of front_left the axles meet on the rear axle at y = 0.775 + 2.70 / tan(20 deg), so front_right is
    at atan(2.70 / (that + 0.775)) (computed here from the ICR, not from the law's formula)."""
    robot = catalog.load("ackermann")
    icr = 0.775 + 2.70 / math.tan(math.radians(20.0))
    want = math.degrees(math.atan2(2.70, icr + 0.775))
    rates = {"rear_left": 10.0, "rear_right": 10.0 * (icr + 0.775) / (icr - 0.775)}
    out, said = fk(robot, [20.0, want], rates)
    assert out.out_of_linkage == () and said == [] and out.consistent
    out, said = fk(robot, [20.0, want + 5.0], rates)
    assert out.out_of_linkage == ("linkage(front_left.steer, front_right.steer)",)
    assert not out.consistent and f"sets front_right at heading {want:.6g} deg with front_left at 20 deg" in said[0]


def test_the_cli_warns_and_says_inconsistent(tmp_path, capsys):
    path = tmp_path / "synchro.yaml"
    path.write_text(json.dumps(DATA))
    assert main(["fk", str(path), "--spin", "a=10", "--steer", "b=10deg"]) == 0
    out, err = capsys.readouterr()
    assert "INCONSISTENT" in out
    assert err.startswith("wmrkit: warning: the headings break a steering linkage: the steering linkage of wheels "
                          "'a', 'b' and 'c' (law parallel) sets b at heading 0 deg with a at 0 deg, not 10 deg")
    assert main(["fk", str(path), "--spin", "a=10", "--steer", "b=10deg", "--json"]) == 0
    data = json.loads(capsys.readouterr()[0])
    assert data["consistent"] is False and data["warnings"][0].startswith("the headings break a steering linkage")


def test_the_textbook_angles_of_the_catalog_car_pass_and_ik_s_printed_ones_too(capsys):
    """Rounded headings (9.66 / 8.79 deg, 0.024 deg off the law) and ik's six digits are within the tolerance."""
    argv = ["fk", "ackermann", "--spin", "rear_left=14.4", "--spin", "rear_right=15.9", "--steer",
            "front_left=9.66deg", "--steer", "front_right=8.79deg"]
    assert main(argv) == 0 and capsys.readouterr()[1] == ""
    assert main(["fk", "ackermann", "--spin", "rear_left=2.56061", "--spin", "rear_right=3.5", "--steer",
                 "front_left=32.5807deg", "--steer", "front_right=25.0576deg"]) == 0
    assert capsys.readouterr()[1] == ""
