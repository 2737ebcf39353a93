"""Heading set-points of a steering ``gear`` whose ratios differ (1:2, 3:-1) keep the gear between rows. Before, a
gear's joints were continued each on its own, the short way round (``linkages.continued``; a linkage's followers
follow its law): with 1:2, the front written 130 deg then -130 deg turned +100 deg and the rear, written -100 deg
then 100 deg, turned -160 deg instead of the +200 deg the gear turns it, so half-way the rear servo's set-point was
180 deg from where the gear held the wheel and the servos fought it, unsaid. Now the gear's turn ``u`` is continued
(the reference's step the short way, among the turns every joint's row agrees with) and each joint's set-point is
its row moved by the whole turns the gear reaches: the linear interpolation between rows stays on the gear."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_linked_servos import _geared_units

from wmrkit.dynamics.inputs import compiled_inputs
from wmrkit.dynamics.linkages import SETPOINT_TOL
from wmrkit.dynamics.programs import read_torques


def _set_points(tmp_path, ratios, front_rows):
    """The compiled set-points (beta, rad) of a torque file whose front headings are `front_rows` [deg] and whose
    rear headings are on the gear from them, written wrapped."""
    k = ratios[1] / ratios[0]
    path = tmp_path / "h.csv"
    rows = [(math.radians(f), math.remainder(k * math.radians(f), 2 * math.pi)) for f in front_rows]
    path.write_text("time,front.heading,rear.heading\n" + "".join(
        f"{t},{a!r},{b!r}\n" for t, (a, b) in enumerate(rows)))
    model = _geared_units(ratios)
    tk, *_, beta, _, _, _ = compiled_inputs(model, read_torques(model, path))
    return model, tk, beta


def _off_gear(model, beta, ratios) -> float:
    """The largest distance [rad] of the rear set-point from where the gear holds it, over each step's linear
    interpolation (the gear is linear: the rows' and the middles' distances bound it), the first row's whole turns
    aside (a row is kept as written but for whole turns)."""
    mids = np.vstack([beta, 0.5 * (beta[1:] + beta[:-1])])
    rest = model.robot.beta
    d = (mids[:, 1] - rest[1]) - ratios[1] / ratios[0] * (mids[:, 0] - rest[0])
    return float(np.abs(d - 2 * math.pi * round(d[0] / (2 * math.pi))).max())


@pytest.mark.parametrize(("front", "turn"), [((130, -130), 100), ((10, 170), 160), ((-100, 100), -160),
                                             ((179, -179), 2), ((0, 60, 150, -120, -30), 330)])
def test_a_1_to_2_gear_turns_the_rear_twice_the_front_the_short_way(tmp_path, front, turn):
    model, _, beta = _set_points(tmp_path, (1.0, 2.0), front)
    assert math.degrees(beta[-1, 0] - beta[0, 0]) == pytest.approx(turn, abs=1e-9)  # the front: its short way
    assert math.degrees(beta[-1, 1] - beta[0, 1]) == pytest.approx(2 * turn, abs=1e-9)
    assert _off_gear(model, beta, (1.0, 2.0)) <= SETPOINT_TOL


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(-179.0, 179.0), min_size=2, max_size=6), st.sampled_from([(1.0, 2.0), (1.0, -3.0),
                                                                                     (2.0, 1.0), (3.0, -1.0)]))
def test_any_rows_on_a_gear_stay_on_it_between_rows(tmp_path_factory, front, ratios):
    """For a gear whose reference turns faster than its follower (2:1, 3:-1) the follower's row tells which of the
    reference's turns the gear made (the reference turning 360 deg turns the follower 180 or 120 deg)."""
    model, _, beta = _set_points(tmp_path_factory.mktemp("g"), ratios, front)
    assert _off_gear(model, beta, ratios) <= SETPOINT_TOL
    written = np.asarray(model.robot.beta_of_heading(np.column_stack([np.radians(front), [math.remainder(
        ratios[1] / ratios[0] * math.radians(f), 2 * math.pi) for f in front]])))
    turns = (beta - written) / (2 * math.pi)
    assert np.abs(turns - np.round(turns)).max() < 1e-9  # each row moved by whole turns only


def test_the_compiled_loop_is_the_python_one_bit_for_bit():
    """A long table runs :func:`_setpoint_kernel.gear_continued` (compiled): the same numbers as the plain loop."""
    from wmrkit.dynamics import _setpoint_kernel, _setpoints

    rng = np.random.default_rng(7)
    front = np.cumsum(rng.uniform(-3.0, 3.0, 5000))
    beta = np.column_stack([np.remainder(front, 2 * np.pi), np.remainder(0.5 * front, 2 * np.pi)])  # 2:1
    args = (np.array([0, 1]), np.array([2.0, 1.0]), np.zeros(2), SETPOINT_TOL, beta)
    plain, compiled = np.zeros_like(beta), np.zeros_like(beta)
    _setpoints.gear_continued(*args, plain)
    _setpoint_kernel.gear_continued(*args, compiled)
    assert np.array_equal(plain, compiled)
    d = plain[:, 1] - 0.5 * plain[:, 0]
    assert np.abs(d - d[0]).max() <= SETPOINT_TOL  # on the gear, the reference's turn the follower's row says
