"""A steering set-point written wrapped between two rows (+179 deg then -179 deg: a wheel mounted reversed, heading pi
at rest, steering about straight ahead) turns the short way, 2 deg, whether it is a held linkage's leader or a
wheel steered on its own. Before, only a linkage's followers did (test_linkage_wrapped_follower): a leader's rows,
and any directly commanded steering's, were interpolated the long way round, 358 deg in one interval, the servo
spinning the wheel round after its set-point (and a linked follower round with it, 5049 knots)."""

from __future__ import annotations

import math

import numpy as np
from dynamics_robots import linked_car
from hypothesis import given, settings
from hypothesis import strategies as st
from test_linkage_setpoints import icr_heading

from wmrkit import Robot
from wmrkit.dynamics.inputs import compiled_inputs
from wmrkit.dynamics.linkages import SETPOINT_TOL, continued
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import read_torques, twist_program
from wmrkit.wheels import wrap_angle

TIMES = np.array([0.0, 0.5, 1.0, 1.5])
TWISTS = np.array([[0, 0, 0], [0.5, 0, 0.3], [0.5, 0, -0.3], [0.5, 0, 0.3]])


def _reversed_leader(linkage: bool = True) -> DynamicModel:
    """linked_car with its leader fl mounted reversed (heading pi at rest)."""
    data = linked_car(linkage).to_dict()
    data["wheels"][2]["heading"] = math.pi
    return DynamicModel.of(Robot.from_dict(data))


def _off_law(model: DynamicModel, inputs) -> float:
    """The largest distance [rad] of fr's interpolated set-point from the law of fl's (rolling backward), over the
    run; checks the knots stay few and fl's set-points move less than 0.1 rad from knot to knot (the short way)."""
    tk, *_ = compiled = compiled_inputs(model, inputs)
    assert len(tk) < 1000
    assert np.abs(np.diff(compiled[5][:, 0])).max() < 0.1  # the leader's servo set-point, beta (not wrapped)
    heading = np.unwrap(model.robot.heading_of_beta(compiled[5]), axis=0)  # as users read it, wrapped: undone
    t = np.linspace(0.0, TIMES[-1], 3001)
    fl, fr = (np.interp(t, tk, heading[:, k]) for k in (0, 1))
    ahead = wrap_angle(fl - math.pi)  # the heading fl would have mounted forward
    law = np.array([icr_heading(0.6, -0.2, 0.2 + 0.6 / math.tan(h)) if h else 0.0 for h in ahead])
    return float(np.abs(wrap_angle(fr - law)).max())


def test_a_twist_program_turning_a_reversed_leader_through_180_deg_runs_on_the_law():
    model = _reversed_leader()
    inputs = twist_program(model, TIMES, TWISTS)
    assert np.ptp(inputs.heading_reference[:, 0]) > math.pi  # the leader's rows are written wrapped
    assert _off_law(model, inputs) <= SETPOINT_TOL


def test_a_torque_file_with_the_leader_written_wrapped_runs_on_the_law(tmp_path):
    model, path = _reversed_leader(), tmp_path / "h.csv"
    href = twist_program(model, TIMES, TWISTS).heading_reference
    path.write_text("time,fl.heading,fr.heading\n" + "".join(
        f"{t!r},{a!r},{b!r}\n" for t, (a, b) in zip(TIMES.tolist(), href.tolist(), strict=True)))
    assert _off_law(model, read_torques(model, path)) <= SETPOINT_TOL


def test_a_wheel_steered_on_its_own_turns_the_short_way_through_180_deg(tmp_path):
    model, path = _reversed_leader(linkage=False), tmp_path / "h.csv"
    path.write_text(f"time,fl.heading,fr.heading\n0,{math.radians(179)!r},0\n1,{math.radians(-179)!r},0\n")
    tk, *_, beta, _, _, _ = compiled_inputs(model, read_torques(model, path))
    assert abs(beta[-1, 0] - beta[0, 0] - math.radians(2)) < 1e-12
    half = model.robot.heading_of_beta([np.interp(0.5, tk, beta[:, k]) for k in (0, 1)])
    assert abs(wrap_angle(half[0] - math.pi)) < 1e-12  # half-way: straight backward, not straight ahead


@settings(max_examples=50, deadline=None)
@given(st.lists(st.tuples(st.floats(-math.pi, math.pi), st.floats(-math.pi, math.pi)), min_size=2, max_size=8))
def test_continued_set_points_are_the_rows_by_whole_turns_each_step_the_short_way(rows):
    model = _reversed_leader(linkage=False)
    beta = np.asarray(model.robot.beta_of_heading(np.array(rows)))
    out = continued(model, beta, set())
    turns = (out - beta) / (2 * math.pi)
    assert np.abs(turns - np.round(turns)).max() < 1e-9
    assert np.abs(np.diff(out, axis=0)).max() <= math.pi + 1e-9
    assert np.array_equal(out[0], beta[0])
