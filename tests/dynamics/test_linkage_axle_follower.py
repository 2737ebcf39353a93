"""An Ackermann linkage's follower on the fixed wheels' axle line: its axle is that line, which holds every ICR the
linkage allows, so it keeps its rest angle for every leader angle (``f' = 0``). The law's general form gives ``f' =
x_i x_j / D`` with ``x_j = 0``: 0 / 0 where the ICR falls on the follower's steering point (NaN; 8.8e14 with the
round-off of the axle frame), and a flip by pi past it."""

from __future__ import annotations

import math

import numpy as np
from dynamics_robots import linked_car

from wmrkit import Robot
from wmrkit.dynamics.linkages import law, linkage_breach
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.simulate import Inputs, simulate

WHEELBASE, SIDE_Y, FL_Y = 0.6, 0.5, 0.2
#: fl's heading whose axle passes through the side wheel's steering point (0, 0.5): the ICR on it.
ON_SIDE = math.atan2(WHEELBASE, SIDE_Y - FL_Y)


def _model() -> DynamicModel:
    """The linked car with a third linked wheel, 'side', on the rear axle line (x = 0, y = 0.5)."""
    data = linked_car().to_dict()
    data["wheels"].append({"name": "side", "type": "steerable", "position": [0, SIDE_Y], "heading": 0, "r": 0.1,
                           "inertia": {"spin": 0.01, "steer": 0.05}, "tyre": "dugoff"})
    data["couplings"] = [{"kind": "linkage", "joints": ["fl.steer", "fr.steer", "side.steer"]}]
    return DynamicModel.of(Robot.from_dict(data))


def test_the_follower_on_the_axle_line_keeps_its_angle_where_the_icr_is_on_it():
    model = _model()
    row = model.pack[17][1]
    assert model.names[int(row[0])] == "side.steer" and row[5] == 0.0  # on the line: exactly
    rest = model.robot.wheel("side").beta
    for heading in (ON_SIDE - 1e-3, ON_SIDE, ON_SIDE + 1e-3, 0.3, 1.4):
        beta = float(model.robot.beta_of_heading([heading, 0.0, 0.0])[0])
        assert law(row, beta) == (rest, 0.0, 0.0)  # before: 8.8e14 and 1e31 at ON_SIDE, rest + pi past it
    exact = row.copy()  # a follower whose frame gives 0 without round-off: 0 / 0 before
    exact[5] = 0.0
    beta = float(model.robot.beta_of_heading([ON_SIDE, 0.0, 0.0])[0])
    assert np.isfinite(law(exact, beta)).all()
    fr = math.atan2(WHEELBASE, SIDE_Y + FL_Y)  # fr's axle through the same ICR (0, 0.5)
    beta3 = model.robot.beta_of_heading([ON_SIDE, fr, 0.0])
    assert linkage_breach(model, np.asarray(beta3)) is None  # before: side set at 0.147 rad, not 0


def test_a_steering_sweep_through_that_icr_leaves_the_follower_at_rest():
    """A steering torque on fl from rest turns it past ON_SIDE (1.107 rad) within 2 s; 'side' stays straight in
    every sample (before: it flipped to pi there) and fr stays on the Ackermann law, through the same ICR."""
    model = _model()
    inputs = Inputs.torques_only(model, [0.0, 2.0], {"fl.steer": [0.05, 0.05]})
    sim = simulate(model, inputs, 2.0, step=1e-3, record_step=0.01)
    fl, fr, side = sim.heading.T
    assert fl.max() > ON_SIDE + 0.1
    assert np.isfinite(sim.joint_rates).all()
    assert np.abs(side).max() == 0.0
    icr_y = FL_Y + WHEELBASE / np.tan(fl[1:])  # the ICR on the rear axle line, from fl's axle
    np.testing.assert_allclose(fr[1:], np.arctan2(WHEELBASE, icr_y + FL_Y), atol=1e-9)
