"""One rank rule (``linalg.matrix_rank``, ``linalg.nullity``; tolerance ``RANK_RTOL`` tied to the resolution headings
are given at) for the mobility, the assignable sets, the models, the actuation and sensing analyses and analyze.

Before, the Ackermann car at the headings ``wmrkit ik ackermann --twist 1 0 0.2`` prints (32.5807 deg, 25.0576 deg,
rounded to 4 decimals) got ``mobility m = 0`` and, in the same output, six one-velocity assignable sets, models
printing ``vy = 7.69e-09`` and "the joint model's mobility 1": the smallest singular value, 2e-8, sat at the cut-off
(1e-9 times the size and the largest singular value), below it on one matrix and above it on another."""

from __future__ import annotations

import json
import math

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

from strategies import robots
from wmrkit import (
    Robot,
    SingularError,
    Wheel,
    actuation_analysis,
    assignable_sets,
    catalog,
    direct_model,
    inverse_model,
    mobility,
    sensing_analysis,
)
from wmrkit.analysis.classification import instantaneous_mobility
from wmrkit.analysis.icr import icr
from wmrkit.cli.main import main

CAR = catalog.load("ackermann")
WHEELBASE, TRACK = 2.70, 1.55  # the catalog's car (independent of the code: its description's numbers)


def ackermann(radius: float) -> np.ndarray:
    """Headings [rad] (front_left, front_right) turning about (0, radius) on the rear axle (closed form)."""
    return np.arctan(WHEELBASE / (radius - np.array([TRACK / 2, -TRACK / 2])))


EXACT = ackermann(5.0)  # the twist (1, 0, 0.2) turns about (0, 5) m
ROUNDED = np.round(np.degrees(EXACT), 4)  # as `wmrkit ik` prints them and a user types them back
OFF_LAW = np.array([30.0, 20.0])  # headings genuinely off the Ackermann law [deg]


def _steer(degrees) -> list[str]:
    return [arg for name, h in zip(CAR.steer_names, degrees, strict=True) for arg in ("--steer", f"{name}={h}deg")]


def _json(capsys, argv: list[str]) -> dict:
    assert main([*argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def _text(capsys, argv: list[str]) -> str:
    assert main(argv) == 0
    return capsys.readouterr().out


def test_the_printed_headings_are_rounded_from_the_law_by_about_a_micro_radian():
    assert list(ROUNDED) == [32.5807, 25.0576]
    assert 1e-8 < np.abs(np.radians(ROUNDED) - EXACT).max() < 1e-6


def test_rounded_ackermann_headings_give_m_1_in_the_python_api():
    h = np.radians(ROUNDED)
    assert int(mobility(CAR, heading=h)) == 1 and int(mobility(CAR, heading=h, gears=False)) == 1
    sets = assignable_sets(CAR, heading=h)
    assert sets and all(len(s) == 1 for s in sets)
    model = inverse_model(CAR, heading=h)
    assert model.assigned == ("vx",)
    twist = model.velocities([1.0])[:3]
    np.testing.assert_allclose(twist, [1.0, 0.0, 0.2], atol=1e-6)  # turning about (0, 5) m: omega = vx / 5
    assert len(direct_model(CAR, heading=h).assigned) == 1
    assert int(actuation_analysis(CAR, heading=h).mobility) == 1
    assert int(sensing_analysis(CAR, heading=h).mobility) == 1
    assert int(instantaneous_mobility(CAR, heading=h)) == 1
    found = icr(CAR, heading=h)
    assert found.kind == "point" and np.allclose(found.point, [0.0, 5.0], atol=1e-5)
    read_as = np.array([v for _, v in found.consistent])
    radius = WHEELBASE / math.tan(read_as[0]) + TRACK / 2  # headings on the law: turning about (0, radius)
    np.testing.assert_allclose(read_as, ackermann(radius), atol=1e-12)
    np.testing.assert_allclose(read_as, h, atol=1e-6)  # near those typed, to their rounding
    assert icr(CAR, heading=EXACT).consistent is None  # exact headings: nothing to say


def test_rounded_ackermann_headings_give_m_1_in_kinematics_text_and_json(capsys):
    text = _text(capsys, ["kinematics", "ackermann", *_steer(ROUNDED)])
    assert "mobility m = 1" in text and "mobility m = 0" not in text
    assert "note: its steered axles miss the ICR by" in text and "rounded headings, read as front_left 32.58070" in text
    assert "mobility 0" not in text and text.count("the joint model's mobility 1") == 2
    assert "e-09" not in text and "e-08" not in text  # no rounding slip printed as a model entry
    data = _json(capsys, ["kinematics", "ackermann", *_steer(ROUNDED)])
    assert data["mobility"] == data["coupled_mobility"] == 1
    assert data["actuation"]["mobility"] == data["sensing"]["mobility"] == 1
    assert data["assignable_sets"] and all(len(s) == 1 for s in data["assignable_sets"])
    assert data["direct_model"]["assigned"] == ["rear_left.spin"] and data["inverse_model"]["assigned"] == ["vx"]
    assert "rounded headings" in data["headings_note"]
    analyzed = _text(capsys, ["analyze", "ackermann", *_steer(ROUNDED)])
    assert "m = 0" not in analyzed and "ICR at (0.000, 5.000) m; its steered axles miss the ICR by" in analyzed


def test_headings_off_the_law_give_m_0_everywhere(capsys):
    h = np.radians(OFF_LAW)
    assert int(mobility(CAR, heading=h)) == 0 and int(actuation_analysis(CAR, heading=h).mobility) == 0
    assert int(sensing_analysis(CAR, heading=h).mobility) == 0 and int(instantaneous_mobility(CAR, heading=h)) == 0
    assert assignable_sets(CAR, heading=h) == ((),)
    assert inverse_model(CAR, heading=h).assigned == () and direct_model(CAR, heading=h).assigned == ()
    text = _text(capsys, ["kinematics", "ackermann", *_steer(OFF_LAW)])
    assert "mobility m = 0" in text and "mobility 1" not in text and text.count("the robot cannot move (m = 0)") == 2
    assert "note:" not in text  # 10 deg off: not rounding
    data = _json(capsys, ["kinematics", "ackermann", *_steer(OFF_LAW)])
    assert data["mobility"] == data["actuation"]["mobility"] == data["sensing"]["mobility"] == 0
    assert data["assignable_sets"] == [[]] and data["minimal_actuator_sets"] == [] and data["headings_note"] is None


@settings(max_examples=25, deadline=None)
@given(radius=st.floats(3.0, 40.0), side=st.sampled_from([1.0, -1.0]),
       signs=st.tuples(st.sampled_from([1.0, -1.0]), st.sampled_from([1.0, -1.0])))
def test_headings_a_tenth_of_a_micro_radian_off_the_law_move_on_one_a_hundredth_of_a_radian_off_stop(radius, side,
                                                                                                   signs):
    exact = ackermann(side * radius)
    for step, m in ((1e-7, 1), (1e-2, 0)):
        h = exact + step * np.array(signs)
        assert int(mobility(CAR, heading=h)) == m
        assert int(actuation_analysis(CAR, heading=h).mobility) == m
        assert int(instantaneous_mobility(CAR, heading=h)) == m
        assert all(len(s) == m for s in assignable_sets(CAR, heading=h))


#: Two fixed wheels on parallel axles 3.1e-6 m apart (hypothesis's example): the least singular value of the matrix
#: sat below the cut-off on the origin's twist and above it on the centroid's, so m = 1 came with no assignable set.
_NEAR_AXLES = Robot(name="r", wheels=tuple(Wheel(name=f"w{i}", type="fixed", l=x, alpha=0.0, r=0.5,
                                                 beta=2.5007353837002683e-05) for i, x in enumerate((0.5, 0.4375))))


@settings(max_examples=40, deadline=None)
@example(robot=_NEAR_AXLES, beta=())
@given(robot=robots(max_wheels=3), beta=st.lists(st.floats(-math.pi, math.pi), max_size=3))
def test_the_mobility_is_the_size_of_every_assignable_set_and_of_the_models(robot, beta):
    beta = np.resize(np.array(beta, dtype=float), len(robot.steer_names))  # random headings, one per steered joint
    m = int(mobility(robot, beta))
    sets = assignable_sets(robot, beta)
    assert sets and all(len(s) == m for s in sets)  # k - rank A columns outside a column basis: one set at least
    assert int(actuation_analysis(robot, beta).mobility) == m and int(sensing_analysis(robot, beta).mobility) == m
    for build in (direct_model, inverse_model):
        try:
            model = build(robot, beta=beta)
        except SingularError:  # no set of wheel rates (or twist components) alone can be assigned here
            assert m > 0
            continue
        assert len(model.assigned) == m and (model.kind == "none") == (m == 0)
