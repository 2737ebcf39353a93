"""A steering heading near the angle limit (within it: +-(1e6 turns - |90 deg - delta|), wheels.heading_limit) is
analysed as any other. Before, ``wmrkit analyze swerve-4 --steer front_left=999999.7turn`` failed with 'beta: angles
must be finite numbers of at most 1e+06 turns [rad], got 6283186.22', naming neither --steer nor the wheel: classify
aims each steered axle at random ICRs (steer_to_icr), and the branch nearest the described beta, up to a quarter turn
from it, could lie beyond the limit; the other branch (the same axle line) is within it."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from wmrkit import catalog
from wmrkit.analysis.icr import steer_to_icr
from wmrkit.cli.main import main
from wmrkit.units import MAX_ANGLE
from wmrkit.wheels import heading_limit


def _analysis(argv: list[str], capsys) -> dict:
    assert main([*argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.parametrize(("robot", "wheel"), [("swerve-4", "front_left"), ("forklift", "steer"),
                                               ("ackermann", "front_left")])
def test_analyze_takes_a_heading_just_within_the_limit_as_the_same_heading_a_million_turns_back(robot, wheel, capsys):
    far = _analysis(["analyze", robot, "--steer", f"{wheel}=999999.7turn"], capsys)
    near = _analysis(["analyze", robot, "--steer", f"{wheel}=0.7turn"], capsys)
    for key in ("mobility", "steerability", "type", "degenerate", "coordinated_steering"):
        assert far[key] == near[key], key


@settings(max_examples=40, deadline=None)
@given(st.floats(0.0, 0.25), st.sampled_from([1, -1]), st.floats(-5, 5), st.floats(-5, 5), st.floats(-1, 1))
def test_axles_aimed_at_an_icr_stay_within_the_angle_limit_on_the_same_line(back, sign, x, y, w):
    assume(max(abs(x), abs(y), abs(w)) > 1e-3)
    swerve = catalog.load("swerve-4")
    delta = swerve.wheel("front_left").delta
    heading = sign * (heading_limit(delta) - 2 * math.pi * back)
    robot = swerve.with_steering({"front_left": heading})
    beta = steer_to_icr(robot, np.array([x, y, w]))[0]
    assert abs(beta) <= MAX_ANGLE
    wanted = steer_to_icr(swerve.with_steering({"front_left": math.remainder(heading, 2 * math.pi)}),
                          np.array([x, y, w]))[0]
    assert abs(math.remainder(beta - wanted, math.pi)) < 1e-6  # the same axle line
