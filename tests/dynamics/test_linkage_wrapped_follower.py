"""A follower of a held linkage whose heading crosses +-180 deg between two rows (a wheel mounted reversed, heading
pi at rest, on a car turning left then right) turns the short way: its set-points between the rows stay on the law
of its leader's interpolation. Before, its rows were interpolated the long way round (+179 deg to -179 deg through
0), the law's turn nearest to that jumped a whole turn half-way, and keeping it within ``SETPOINT_TOL`` asked for
some 6e5 knots per step: the run was refused with advice (give one heading per linkage, smaller steps) that did
not name the cause. The law is written here as in test_linkage_setpoints (the ICR geometry)."""

from __future__ import annotations

import math

import numpy as np
from dynamics_robots import linked_car
from test_linkage_setpoints import icr_heading

from wmrkit import Robot
from wmrkit.dynamics.inputs import compiled_inputs
from wmrkit.dynamics.linkages import SETPOINT_TOL
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import read_torques, twist_program
from wmrkit.wheels import wrap_angle

TIMES = np.array([0.0, 0.5, 1.0, 1.5])
TWISTS = np.array([[0, 0, 0], [0.5, 0, 0.3], [0.5, 0, -0.3], [0.5, 0, 0.3]])


def _reversed_follower() -> DynamicModel:
    """linked_car with its follower fr mounted reversed (heading pi at rest: it rolls backward on a positive spin)."""
    data = linked_car().to_dict()
    data["wheels"][3]["heading"] = math.pi
    return DynamicModel.of(Robot.from_dict(data))


def _off_law(model: DynamicModel, inputs) -> float:
    """The largest distance [rad] of fr's interpolated set-point from the law of fl's, over the run, and checks the
    knots stay few and fr's set-points move less than 0.1 rad from knot to knot (no half-way whole turn)."""
    tk, *_ = compiled = compiled_inputs(model, inputs)
    assert len(tk) < 1000
    assert np.abs(np.diff(compiled[5][:, 1])).max() < 0.1  # the servo's set-point, beta (not wrapped)
    heading = np.unwrap(model.robot.heading_of_beta(compiled[5]), axis=0)  # as users read it, wrapped: undone
    t = np.linspace(0.0, TIMES[-1], 3001)
    fl, fr = (np.interp(t, tk, heading[:, k]) for k in (0, 1))
    law = np.array([icr_heading(0.6, -0.2, 0.2 + 0.6 / math.tan(h)) if h else 0.0 for h in fl]) + math.pi
    return float(np.abs(wrap_angle(fr - law)).max())


def test_a_twist_program_turning_a_reversed_follower_through_180_deg_runs_on_the_law():
    model = _reversed_follower()
    inputs = twist_program(model, TIMES, TWISTS)
    assert np.ptp(inputs.heading_reference[:, 1]) > math.pi  # the rows are written wrapped
    assert _off_law(model, inputs) <= SETPOINT_TOL


def test_a_torque_file_with_the_follower_written_wrapped_runs_on_the_law(tmp_path):
    model, path = _reversed_follower(), tmp_path / "h.csv"
    href = twist_program(model, TIMES, TWISTS).heading_reference
    path.write_text("time,fl.heading,fr.heading\n" + "".join(
        f"{t!r},{a!r},{b!r}\n" for t, (a, b) in zip(TIMES.tolist(), href.tolist(), strict=True)))
    assert _off_law(model, read_torques(model, path)) <= SETPOINT_TOL
