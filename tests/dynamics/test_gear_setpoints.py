"""Heading set-points of steering joints a ``gear`` holds keep its ratios, as a linkage's keep its law
(docs/dynamics.md, Couplings): the gear turns its joints ``h_j - h_j0 = k_j u`` from the described headings, so
set-points off that fight through it. Refused in a torque file (naming the file, the row and the column), in Python
``Inputs`` (``simulate``, ``Stepper.advance``, ``Stepper.hold``) and in a twist program, unless the servos are let
fight. The ratios are applied here by hand, from the description."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_linked_servos import _geared_units

from wmrkit.dynamics.programs import read_torques, steering_gains, twist_program
from wmrkit.dynamics.simulate import Inputs, Stepper, simulate
from wmrkit.errors import WmrkitError


def _file(tmp_path, front: float, rear: float):
    path = tmp_path / "h.csv"
    path.write_text(f"time,front.heading,rear.heading\n0,0,0\n1,{front},{rear}\n")
    return path


@pytest.mark.parametrize(("ratios", "front"), [((1.0, 2.0), 0.1), ((3.0, -1.0), 0.3)])
def test_a_torque_file_off_the_ratios_is_refused_naming_its_row_and_column(tmp_path, ratios, front):
    """Before, ``front.heading 0.1, rear.heading 0.1`` on a 1:2 gear ran, the servos fighting: the units settled at
    0.06 and 0.12 rad with 2.2 N m and -1.1 N m on the steering."""
    model = _geared_units(ratios)
    rear = ratios[1] / ratios[0] * front  # rest headings 0
    with pytest.raises(WmrkitError) as err:
        read_torques(model, _file(tmp_path, front, front))
    assert str(err.value) == (
        f"{_file(tmp_path, front, front)}:3: column 'rear.heading': {front:g} rad breaks the steering "
        f"gear of wheels 'front' and 'rear', which sets rear at heading {rear:.6g} rad with column 'front.heading' at "
        f"{front:g} rad: the steering servos would fight the gear the dynamics hold; give headings on its ratios "
        "(within 1e-05 rad) or one heading column per gear (docs/dynamics.md)")
    sim = simulate(model, read_torques(model, _file(tmp_path, front, rear)), 2.0, record_step=0.5)
    np.testing.assert_allclose(sim.heading[-1], [front, rear], atol=1e-3)  # no fight: both reach their set-points


def _inputs(model, headings, **kwargs) -> Inputs:
    n = model.n
    kp, kd = steering_gains(model, list(model.steer_columns))
    return Inputs(np.array([0.0, 1.0]), np.zeros((2, n)), np.zeros((2, n)), np.zeros(n), np.full(n, np.inf),
                  np.array([[0.0, 0.0], headings], float), kp, kd, **kwargs)


def test_python_inputs_off_the_ratios_are_refused_unless_let_fight():
    model = _geared_units((1.0, 2.0))
    off = _inputs(model, [0.1, 0.1])
    for run in (lambda: simulate(model, off, 0.01), lambda: Stepper(model).advance(off, 0.01)):
        with pytest.raises(WmrkitError, match=r"^heading_reference: at t = 1 s, rear's 0.1 rad breaks "
                                              r"the steering gear of wheels 'front' and 'rear', which sets rear at "
                                              r"heading 0.2 rad"):
            run()
    simulate(model, _inputs(model, [0.1, 0.1], fight_linkages=True), 0.01)
    simulate(model, _inputs(model, [0.1, 0.2]), 0.01)
    stepper = Stepper(model)
    stepper.advance(_inputs(model, [0.0, 0.0]), 0.01)
    stepper.hold(heading_reference=[-0.2, -0.4])
    with pytest.raises(WmrkitError, match=r"^hold: heading_reference: at t = 0.01 s, rear's -0.2 rad breaks the "
                                          r"steering gear"):
        stepper.hold(heading_reference=[-0.2, -0.2])


def test_a_twist_program_whose_steering_breaks_the_ratios_is_refused_unless_allow_slip():
    """Crabbing at 0.1 rad steers both units to 0.1 rad, which the 1:2 gear cannot (before: run, fighting)."""
    model = _geared_units((1.0, 2.0))
    twist = (math.cos(0.1), math.sin(0.1), 0.0)
    with pytest.raises(WmrkitError, match=r"breaks the ratios of the steering gear of wheels 'front' and 'rear' "
                                          r"\(it sets rear at heading 0.2 rad with front's at 0.1 rad, the wheel IK "
                                          r"0.1 rad\)"):
        twist_program(model, [0.0], [twist])
    inputs = twist_program(model, [0.0], [twist], allow_slip=True)
    assert inputs.fight_linkages
    simulate(model, inputs, 0.01)
