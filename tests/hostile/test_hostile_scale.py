"""Issue 9: rank decisions are scale-aware. The same robot at any size of the envelope (1 um to 1 km) has the same
mobility, assignable sets, minimal actuator sets, actuation and sensing verdicts and vehicle type; its models
solve the no-slip equations of the scaled robot; its default lengths (robot size, natural length) scale with it.
And what lies outside the envelope is refused by the loader."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from strategies import robots
from wmrkit import Robot, Wheel
from wmrkit.analysis.classification import classify
from wmrkit.analysis.isotropy import default_joints, natural_length
from wmrkit.analysis.singularity import robot_size, singularity_distance
from wmrkit.description import ANGLE_MARGIN, MAX_SIZE, MIN_RATIO, MIN_SIZE, robot_from_dict, robot_to_dict
from wmrkit.errors import DescriptionError
from wmrkit.kinematics import actuation_analysis, assignable_sets, minimal_actuator_sets, mobility, sensing_analysis
from wmrkit.kinematics.linalg import LENGTH_FIELDS, characteristic_length, reach
from wmrkit.kinematics.models import direct_model


def _scaled(robot, factor: float):
    """`robot` with every length multiplied by `factor` (an independent construction: fields, not the library)."""
    return replace(robot, wheels=tuple(replace(w, **{f: getattr(w, f) * factor for f in LENGTH_FIELDS})
                                       for w in robot.wheels))


def _size(robot) -> float:
    return max(abs(getattr(w, f)) for w in robot.wheels for f in LENGTH_FIELDS)


def _factor(robot, exponent: float) -> float:
    """The factor making the robot's largest length 10**exponent, moved by ulps so that its product with that length
    lies in the envelope: at an edge it can round one ulp outside (1.427734375 * (1e3 / 1.427734375) is
    1000.0000000000001), a robot the loader rightly refuses."""
    size, factor = _size(robot), 10.0**exponent / _size(robot)
    while size * factor > MAX_SIZE:
        factor = math.nextafter(factor, 0.0)
    while size * factor < MIN_SIZE:
        factor = math.nextafter(factor, math.inf)
    return factor


@settings(max_examples=180)
@given(robot=robots(max_wheels=3), exponent=st.floats(math.log10(MIN_SIZE), math.log10(MAX_SIZE)))
@example(robot=Robot(name="r", wheels=(Wheel(name="w0", type="fixed", l=1.427734375, alpha=0.0, beta=0.0, r=0.5),)),
         exponent=3.0)  # the edge 1 km, drawn on a 2026-12-01 explore run
@example(robot=Robot(name="r", wheels=(Wheel(name="w0", type="fixed", l=0.0, alpha=0.0, beta=0.0, r=0.46875),)),
         exponent=3.0)  # a radius one ulp past 1 km under the plain factor (CI, 2026-12-01)
def test_the_same_robot_at_any_size_of_the_envelope_gets_the_same_answers(robot, exponent):
    scaled = _scaled(robot, factor := _factor(robot, exponent))
    assert robot_from_dict(robot_to_dict(scaled)) == scaled  # inside the envelope: the loader accepts it
    assert reach(scaled) == pytest.approx(10.0**exponent)  # the envelope's size (docs/limits.md)
    assert characteristic_length(scaled) == pytest.approx(characteristic_length(robot) * factor)
    assert int(mobility(scaled)) == int(mobility(robot))
    assert tuple(assignable_sets(scaled)) == tuple(assignable_sets(robot))
    assert tuple(minimal_actuator_sets(scaled)) == tuple(minimal_actuator_sets(robot))
    assert actuation_analysis(scaled).leaf.tolist() == actuation_analysis(robot).leaf.tolist()
    assert sensing_analysis(scaled).leaf.tolist() == sensing_analysis(robot).leaf.tolist()
    a, b = classify(robot), classify(scaled)
    assert (a.mobility, a.steerability, a.type) == (b.mobility, b.steerability, b.type)


@settings(max_examples=60)
@given(robot=robots(max_wheels=3), exponent=st.floats(math.log10(MIN_SIZE), math.log10(MAX_SIZE)))
def test_a_model_of_a_scaled_robot_solves_its_own_no_slip_equations(robot, exponent):
    scaled = _scaled(robot, _factor(robot, exponent))
    try:
        model = direct_model(scaled)
    except Exception:  # no assignable set of wheel rates: nothing to check here
        return
    q = model.velocities(np.linspace(1.0, 2.0, len(model.assigned)))
    a = scaled.constraint_matrix()
    assert np.linalg.norm(a @ q) <= 1e-7 * np.linalg.norm(a) * np.linalg.norm(q)


def _diff_drive(**left) -> dict:
    wheel = {"name": "left", "type": "fixed", "position": [0, 0.2], "beta": 0, "r": 0.075, **left}
    return {"name": "dd", "wheels": [wheel, {"name": "right", "type": "fixed", "position": [0, -0.2],
                                             "beta": math.pi, "r": 0.075}]}


@pytest.mark.parametrize(("changes", "field", "reason"), [
    ({"r": 1e308}, "r", "longer than 1000 m"),
    ({"position": [1e308, 1e308]}, r"position\[0\]", "longer than 1000 m"),  # the coordinate typed
    ({"r": 0.2 * MIN_RATIO * 0.99}, "r", "less than 0.0001 of the robot's size"),  # size 0.2 m: the positions
    ({"r": 1e-320}, "r", "less than 0.0001 of the robot's size"),
])
def test_lengths_outside_the_envelope_are_refused_naming_the_field(changes, field, reason):
    with pytest.raises(DescriptionError, match=rf"wheels\[0\]\.{field}: .*{reason}"):
        robot_from_dict(_diff_drive(**changes))


def test_the_envelope_s_edges_are_accepted_and_just_beyond_refused():
    ok = {"name": "o", "wheels": [{"name": f"w{i}", "type": "swedish", "l": 0.2, "alpha": 2.0944 * i, "beta": 0,
                                   "gamma": ANGLE_MARGIN * 1.001, "r": 0.05, "r_r": 0.01} for i in range(3)]}
    robot_from_dict(ok)
    ok["wheels"][1]["gamma"] = ANGLE_MARGIN * 0.999
    with pytest.raises(DescriptionError, match=r"wheels\[1\]\.gamma: .*within 1 deg of the axle"):
        robot_from_dict(ok)
    castor = _diff_drive()
    castor["wheels"].append({"name": "c", "type": "castor", "position": [-0.3, 0], "d": 0.05, "r": 0.05,
                             "delta": math.pi / 2 - ANGLE_MARGIN * 0.999})
    with pytest.raises(DescriptionError, match=r"wheels\[2\]\.delta: .*cannot steer"):
        robot_from_dict(castor)
    tiny = _diff_drive(position=[0, 0.9 * MIN_SIZE], r=0.5 * MIN_SIZE)
    tiny["wheels"][1].update(position=[0, -0.9 * MIN_SIZE], r=0.5 * MIN_SIZE)
    with pytest.raises(DescriptionError, match=r"below 1e-06 m"):
        robot_from_dict(tiny)


@settings(max_examples=75)
@given(robot=robots(max_wheels=3), exponent=st.sampled_from([math.log10(MIN_SIZE), math.log10(MAX_SIZE)]),
       beta=st.lists(st.floats(-3, 3), min_size=3, max_size=3))
def test_the_default_lengths_scale_with_the_robot_at_the_ends_of_the_envelope(robot, exponent, beta):
    """robot_size, the natural length and the distance to singularity at 1 um and 1 km are those at the robot's
    size (a robot of 1 um was sized 1 mm, a floor, so its lines were weighed at 1000 of its sizes)."""
    factor = 10.0**exponent / _size(robot)
    scaled = _scaled(robot, factor)
    assert robot_size(scaled) == pytest.approx(robot_size(robot) * factor, rel=1e-9)
    config = np.array(beta[:len(robot.beta)])
    assigned = default_joints(robot)
    np.testing.assert_allclose(singularity_distance(scaled, config, assigned),
                               singularity_distance(robot, config, assigned), rtol=1e-6, atol=1e-9)
    d, kappa = natural_length(robot, config)
    d_scaled, kappa_scaled = natural_length(scaled, config)
    assert np.isinf(kappa_scaled) == np.isinf(kappa) and np.isnan(kappa_scaled) == np.isnan(kappa)
    if np.isfinite(kappa):
        assert kappa_scaled == pytest.approx(kappa, rel=1e-4)
        assert d_scaled == pytest.approx(d * factor, rel=1e-3)
