"""Parking problems as files: units, built-in names, car-like robots, one-line located errors."""

from __future__ import annotations

import json
import math

import pytest
from parking_cases import CAR_91, SLOT_91

from wmrkit.errors import DescriptionError, UnknownNameError
from wmrkit.parking.problem import builtin_names, car_axles, load_problem, problem_from_text

TABLE_91 = """\
vehicle:
  a1: 1.5 m
  b1: 500 mm
  c1: 140 cm
  h1: 1.05
  d1: 0.5
  phi_max: 46 deg
space: {H: 3.35, J: 2 m, MS: 20 cm, dx2: 0.7, final_gap: 7 cm}
"""


def test_units_and_formats(tmp_path):
    p = problem_from_text(TABLE_91, source="t.yaml")
    assert p.vehicle.a1 == 1.5 and p.vehicle.b1 == pytest.approx(0.5) and p.vehicle.c1 == pytest.approx(1.4)
    assert p.vehicle.phi_max == pytest.approx(math.radians(46)) and p.space.MS == pytest.approx(0.2)
    path = tmp_path / "t.json"
    path.write_text(json.dumps({"vehicle": {"a1": 1.5, "b1": 0.5, "c1": 1.4, "h1": 1.05, "d1": 0.5,
                                            "phi_max": "46 deg"},
                                "space": {"H": 3.35, "J": 2, "MS": 0.2, "dx2": 0.7, "final_gap": 0.07}}))
    q = load_problem(path)
    assert q.vehicle == CAR_91 and q.space == SLOT_91 and q.name == "t"


def test_builtin_names():
    assert builtin_names() == ("thesis-9.1", "thesis-9.2")
    with pytest.raises(UnknownNameError, match=r"did you mean 'thesis-9\.1'"):
        load_problem("thesis-91")


def test_car_like_robot_gives_wheelbase_and_track(tmp_path):
    text = """\
vehicle: {robot: ackermann, a1: 3.6 m, b1: 1.0 m, c1: 1.8 m, phi_max: 34 deg}
space: {H: 7 m, J: 2.3 m, MS: 0.25 m, dx2: 1.4 m, final_gap: 0.1 m}
"""
    p = problem_from_text(text, source="car.yaml")
    assert (p.vehicle.h1, p.vehicle.track) == pytest.approx((2.70, 1.55))  # the catalog file's numbers
    assert p.robot is not None and p.robot.name == "ackermann"
    robot_file = tmp_path / "robot.yaml"
    p.robot.to_file(robot_file)
    q = problem_from_text(text.replace("ackermann", "robot.yaml"), source=str(tmp_path / "car.yaml"),
                          base=tmp_path)
    assert car_axles(q.robot) == pytest.approx((2.70, 1.55))


@pytest.mark.parametrize(("text", "message"), [
    ("vehicle: {a1: 1}\nspace: {}\n", r"^x\.yaml:1: vehicle: missing field 'b1'$"),
    ("vehicle:\n  a1: 1 deg\n", r"^x\.yaml:2: vehicle\.a1: '1 deg' is an angle, expected a length$"),
    (TABLE_91.replace("phi_max: 46 deg", "phi_max: 95 deg"), r"^x\.yaml:7: vehicle\.phi_max: must be in \(0, 90\)"),
    (TABLE_91.replace("h1: 1.05", "h1: -1"), r"^x\.yaml:5: vehicle\.h1: must be > 0"),
    (TABLE_91.replace("d1: 0.5", "dd1: 0.5"), r"vehicle\.dd1: unknown field 'dd1' \(did you mean 'd1'\?\)"),
    (TABLE_91.replace("J: 2 m", "J: 0"), r"^x\.yaml:8: space\.J: must be > 0"),
    (TABLE_91 + "extra: 1\n", r"^x\.yaml:9: extra: unknown field 'extra'"),
    (TABLE_91.replace("d1: 0.5", "d1: 0.5\n  d1: 0.6"), r"x\.yaml:7: vehicle\.d1: field 'd1' given twice"),
    ("vehicle: {robot: diff-drive, a1: 1, b1: 1, c1: 1, phi_max: 0.5}\n", r"vehicle\.robot: .*not car-like"),
    ("vehicle: [1, 2]\n", r"vehicle: must be a mapping"),
    ("- 1\n", r"a parking problem is a mapping"),
    ("vehicle: {a1: !!python/object:os.system ls}\n", r"malformed YAML"),
    ("vehicle: {a1: 1 + 1}\n", r"vehicle\.a1: cannot read"),
    (TABLE_91.replace("a1: 1.5 m", "a1: 1.0 m"), r"^x\.yaml:2: vehicle\.a1: the front end \(1 m from the rear axle\) "
     r"is behind the front axle \(h1 = 1\.05 m\)"),
    (TABLE_91.replace("d1: 0.5", "d1: 1.5"), r"^x\.yaml:6: vehicle\.d1: the rear wheels \(1\.5 m apart\) stand "
     r"outside"),
    ("vehicle: {robot: ackermann, a1: 3.6 m, b1: 1.0 m, c1: 1.5 m, phi_max: 34 deg}\n",
     r"^x\.yaml:1: vehicle\.c1: the rear wheels \(1\.55 m apart\) stand outside the body's width \(c1 = 1\.5 m\)"),
    (TABLE_91.replace("H: 3.35", "H: 40 cm"), r"^x\.yaml:8: space\.MS: the margins at both ends \(0\.4 m\) leave "
     r"nothing of the slot's length H = 0\.4 m"),  # a ZeroDivisionError traceback in the length ratio (9.37) before
    (TABLE_91.replace("final_gap: 7 cm", "final_gap: 7"), r"^x\.yaml:8: space\.final_gap: the gap to the curb \(7 m\) "
     r"must be less than the slot's width J = 2 m"),  # 7 m: 'feasible: 1 manoeuvre, final gap 7.6 cm' before
], ids=["missing", "angle-as-length", "phi-90", "negative", "typo", "zero-width", "unknown-top", "twice",
        "not-car-like", "not-mapping", "list", "python-tag", "no-eval", "front-axle-outside", "track-outside",
        "robot-track-outside", "no-free-length", "gap-wider-than-slot"])
def test_bad_input_gives_one_located_line(text, message):
    with pytest.raises(DescriptionError, match=message) as info:
        problem_from_text(text, source="x.yaml")
    assert "\n" not in str(info.value)


def test_absurd_lengths_are_refused_not_sampled_forever():
    with pytest.raises(DescriptionError, match=r"space\.H: 1e\+12 m is not a parking length"):
        problem_from_text(TABLE_91.replace("H: 3.35", "H: 1e12"), source="x.yaml")


def test_a_space_without_free_length_is_refused_in_python_too():
    from wmrkit.errors import WmrkitError
    from wmrkit.parking import Space

    with pytest.raises(WmrkitError, match=r"H - 2 MS must be > 0"):
        Space(H=0.4, J=2.0, MS=0.2, dx2=0.7, final_gap=0.07)
