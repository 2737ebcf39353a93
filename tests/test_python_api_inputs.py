"""Values users pass to the Python API: every wrong one is one WmrkitError naming the argument and saying what was
expected, never numpy's own message ("could not convert string to float"), a Python TypeError or a silent guess.
The Python API reads no units: a string is refused, with the advice to pass radians."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from wmrkit import ShapeError, WmrkitError, catalog, inverse_model, wheel_commands
from wmrkit.analysis import (
    best_configurations,
    is_singular,
    isotropy_length,
    isotropy_matrix,
    natural_length,
    singular_set,
)
from wmrkit.analysis.coordinated import coordinated_singular_set
from wmrkit.kinematics import extended_solution, twist_is_determined
from wmrkit.kinematics.realtime import realtime
from wmrkit.odometry import odometry_model
from wmrkit.odometry.encoders import encoders_for

SWERVE = catalog.load("swerve-4")
STEER = np.array([0.1, -0.2, 0.3, 0.0])


@pytest.mark.parametrize(("call", "match"), [
    (lambda: SWERVE.with_beta("30 deg"), r"^beta: got the text '30 deg', but the Python API reads no units: pass "
                                         r"real numbers in radians \(e\.g\. math\.radians\(30\)\)$"),
    (lambda: SWERVE.with_beta(["30 deg"] * 4), r"^beta: got the text '30 deg'.*math\.radians"),
    (lambda: SWERVE.with_beta(["0.5", "0.5", "0.5", "30"]), r"^beta: got the text '0\.5'.*no units"),  # not 30 rad
    (lambda: SWERVE.constraint_matrix(heading=[0.0, 0.1, "1 deg", 0.2]), r"^heading: got the text '1 deg'"),
    (lambda: SWERVE.with_steering({"front_left": "30 deg"}), r"^front_left: heading: got the text '30 deg'.*radians"),
    (lambda: wheel_commands(SWERVE, "1 m/s"), r"^twist_robot: got the text '1 m/s'.*SI units"),
    (lambda: inverse_model(SWERVE, heading=["30 deg"] * 4), r"^heading: got the text '30 deg'"),
    (lambda: SWERVE.with_beta([True, False, True, False]), r"^beta: expected real numbers in radians.*got booleans$"),
    (lambda: SWERVE.with_steering({"front_left": True}), r"^front_left: heading: expected real numbers.*booleans$"),
    (lambda: SWERVE.with_beta([1j] * 4), r"^beta: expected real numbers.*got complex numbers$"),
    (lambda: SWERVE.constraint_matrix(heading={"front_left": 0.3}), r"^heading: expected real numbers.*got a dict "
                                                                     r"\(a mapping: pass the values as an array"),
    (lambda: SWERVE.with_beta([[0.1] * 4, [0.1] * 3]), r"^beta: expected real numbers.*rows of different lengths$"),
    (lambda: wheel_commands(SWERVE, [1.0, 0.0, 0.0], beta=[None, 0.0, "a", 0.0]), r"^beta: got the text 'a'"),
])
def test_values_that_are_no_real_numbers_are_refused_naming_the_argument(call, match):
    with pytest.raises(ShapeError, match=match):
        call()


def test_numbers_of_any_real_type_are_taken():
    as_float = SWERVE.constraint_matrix(STEER)
    for value in (STEER.tolist(), tuple(STEER)):
        np.testing.assert_array_equal(SWERVE.constraint_matrix(value), as_float)
    single = STEER.astype(np.float32)
    np.testing.assert_array_equal(SWERVE.constraint_matrix(single), SWERVE.constraint_matrix(single.astype(float)))
    np.testing.assert_array_equal(SWERVE.constraint_matrix([Fraction(1, 10), -0.2, 0.3, 0]), as_float)
    np.testing.assert_array_equal(SWERVE.constraint_matrix(np.array([0, 1, 2, 3], dtype=np.int64)),
                                  SWERVE.constraint_matrix([0.0, 1.0, 2.0, 3.0]))
    turned = SWERVE.with_steering({"front_left": np.float32(0.5), "rear_left": np.int64(1)})
    assert turned.heading[0] == pytest.approx(0.5) and turned.heading[2] == 1.0
    assert isinstance(turned.wheel("front_left").beta, float)


def test_every_refusal_is_one_line_and_a_wmrkit_error():
    for bad in ("30 deg", ["a"] * 4, {"x": 1}, [1j] * 4, [True] * 4, [[1.0], [1.0, 2.0]], object()):
        with pytest.raises(WmrkitError) as err:
            SWERVE.constraint_matrix(bad)
        assert "\n" not in str(err.value) and str(err.value).startswith("beta: ")


@pytest.mark.parametrize(("call", "match"), [
    (lambda: SWERVE.with_steering("front_left"), r"^headings: expected a mapping \{wheel name: angle \[rad\]\} such "
                                                 r"as \{'front_left': 0\.5\}, got str 'front_left'$"),
    (lambda: SWERVE.with_steering(["front_left"]), r"^headings: expected a mapping .*, got list \['front_left'\]$"),
    (lambda: SWERVE.with_beta_angles(("front_left", 0.3)), r"^angles: expected a mapping"),
    (lambda: SWERVE.with_steering({"front_left": np.array([0.3, 0.2])}),
     r"^headings: front_left: expected one angle \[rad\], got ndarray"),
    (lambda: SWERVE.with_beta_angles({"rear_right": [0.3]}), r"^angles: rear_right: expected one angle \[rad\]"),
])
def test_with_steering_takes_a_mapping_of_single_angles(call, match):
    """A wheel's name alone was read letter by letter ("no wheel 'f'"); an array value gave "expected shape (..., 1),
    got (1, 2)"."""
    with pytest.raises(ShapeError, match=match):
        call()
    assert SWERVE.with_steering({"front_left": np.array(0.25)}).heading[0] == 0.25  # a 0-d array is one angle


def test_slip_velocity_refuses_rates_that_are_not_finite_and_batches_that_do_not_broadcast():
    """NaN gave NaN slips; a q_dot batch of 3 against a steering batch of 2 gave numpy's 'operands could not be
    broadcast together with remapped shapes'."""
    k = len(SWERVE.velocity_names)
    with pytest.raises(ShapeError, match=r"^q_dot: vy: expected finite numbers, got nan"):
        SWERVE.slip_velocity([0.0, np.nan] + [0.0] * (k - 2))
    with pytest.raises(ShapeError, match=r"^q_dot: front_left\.spin: expected finite numbers"):
        SWERVE.slip_velocity([0.0] * 3 + [np.inf] + [0.0] * (k - 4))
    # the rates of a twist within the query limit (1e6 m/s) pass 1e6 rad/s: they are taken (the studio's drive)
    fast = wheel_commands(SWERVE, [1e6, 0.0, -1e6])
    assert np.isfinite(SWERVE.slip_velocity(np.concatenate([[1e6, 0.0, -1e6], fast.rates]), fast.beta)).all()
    with pytest.raises(ShapeError, match=r"^q_dot: the slip overflows"):
        SWERVE.slip_velocity([1.7e308] * 3 + [-1.7e308] * (k - 3))
    with pytest.raises(ShapeError, match=rf"^q_dot \(3, {k}\) and the steering \(2, 4\): their batch shapes \(all "
                                         r"but the last axis\) do not broadcast$"):
        SWERVE.slip_velocity(np.zeros((3, k)), np.zeros((2, 4)))
    # the rates of a rolling twist leave no slip, and heading= is the same steering as its beta
    commands = wheel_commands(SWERVE, [0.4, 0.3, 0.5])
    q_dot = np.concatenate([[0.4, 0.3, 0.5], commands.rates])
    np.testing.assert_allclose(SWERVE.slip_velocity(q_dot, commands.beta), 0.0, atol=1e-12)
    np.testing.assert_allclose(SWERVE.slip_velocity(q_dot, heading=commands.heading), 0.0, atol=1e-12)
    assert SWERVE.slip_velocity(np.zeros((2, 1, k)), np.zeros((3, 4))).shape == (2, 3, 8)


def test_jacobian_form_checks_its_steering_and_takes_heading():
    """NaN or 1e300 rad as beta gave a Jacobian of NaN and round-off without a word."""
    for bad in (np.nan, 1e300):
        with pytest.raises(ShapeError, match=r"^beta: angles must be finite numbers of at most 1e\+06 turns"):
            SWERVE.jacobian_form([0.0, bad, 0.0, 0.0])
    twist = np.array([0.4, 0.3, 0.5])
    commands = wheel_commands(SWERVE, twist)
    i_bar, j = SWERVE.jacobian_form(heading=commands.heading)
    np.testing.assert_array_equal(j, SWERVE.jacobian_form(commands.beta)[1])
    q_dot_w = np.concatenate([commands.rates, [twist[2]] * len(SWERVE.wheels)])  # (3.20): one omega per contact
    np.testing.assert_allclose(i_bar @ twist, j @ q_dot_w, atol=1e-12)


@pytest.mark.parametrize(("rates", "match"), [
    (np.zeros(2), r"^rates: expected a mapping \{joint name: rate\} such as \{'left\.spin': 10\.0\}, got ndarray$"),
    (["left.spin", "right.spin"], r"^rates: expected a mapping .*, got list$"),
    ({"left.spin": {"a": 1}, "right.spin": 1.0}, r"^rates: left\.spin: expected real numbers in SI units"),
    ({"left.spin": True, "right.spin": 1.0}, r"^rates: left\.spin: expected real numbers .*got booleans$"),
])
def test_forward_kinematics_takes_a_mapping_of_numbers(rates, match):
    """An array raised "argument of type 'numpy.float64' is not iterable", a list "'list' object has no attribute
    'items'", a dict value a bare TypeError; True was read as 1 rad/s."""
    from wmrkit import forward_kinematics

    robot = catalog.load("diff-drive")
    with pytest.raises(ShapeError, match=match):
        forward_kinematics(robot, rates)
    twist, residual = forward_kinematics(robot, {"left.spin": np.float32(10.0), "right.spin": np.int64(10)})
    assert twist[0] == pytest.approx(10.0 * robot.wheel("left").r) and residual < 1e-12


def test_values_whose_batch_does_not_broadcast_with_the_steering_batch_are_named():
    """numpy's 'operands could not be broadcast together with remapped shapes' named neither argument."""
    from wmrkit import actuation_analysis, forward_kinematics, kinematic_model, sensing_analysis
    from wmrkit.kinematics import extended_solution

    diff = catalog.load("diff-drive")
    two = np.array([[0.1], [0.2]])  # two steering configurations of the castor
    spins = ["left.spin", "right.spin"]
    message = r"^{} \(3, {}\) and the steering configurations \(2,\): their batch shapes \(all but the last axis\) " \
              r"do not broadcast$"
    calls = [
        (lambda: kinematic_model(diff, spins, heading=two).solve(np.zeros((3, 2))), "q_assigned", 2),
        (lambda: kinematic_model(diff, spins, heading=two).velocities(np.zeros((3, 2))), "q_assigned", 2),
        (lambda: extended_solution(diff, spins, np.zeros((3, 2)), heading=two), "q_assigned", 2),
        (lambda: forward_kinematics(diff, {"left.spin": np.zeros(3), "right.spin": 1.0}, heading=two), "rates", 2),
        (lambda: actuation_analysis(SWERVE, heading=[STEER, STEER]).inverse(np.zeros((3, 3))), "twist_robot", 3),
        (lambda: sensing_analysis(SWERVE, heading=[STEER, STEER]).twist(np.zeros((3, 4))), "q_dot_s", 4),
        (lambda: sensing_analysis(SWERVE, heading=[STEER, STEER]).direct(np.zeros((3, 4))), "q_dot_s", 4),
    ]
    for call, name, n in calls:
        with pytest.raises(ShapeError, match=message.format(name, n)):
            call()
    # batches that broadcast still do: (3, 1) values against 2 configurations
    assert kinematic_model(diff, spins, heading=two).solve(np.zeros((3, 1, 2))).shape == (3, 2, 5)


@pytest.mark.parametrize("bad", ["30 deg", np.nan, 1e300, [0.1, "x"]])
def test_one_wheel_s_jacobian_and_slip_rows_check_beta(bad):
    """wheel_jacobian and wheel_slip_rows gave "could not convert string to float", or NaN and round-off."""
    from wmrkit import wheel_jacobian, wheel_slip_rows

    wheel = SWERVE.wheel("front_left")
    for call in (wheel_jacobian, wheel_slip_rows):
        with pytest.raises(ShapeError, match=r"^front_left: beta: "):
            call(wheel, bad)
    assert wheel_jacobian(wheel, [0.1, 0.2]).shape == (2, 3, 2)
    single = np.float32(0.5)
    np.testing.assert_array_equal(wheel_slip_rows(wheel, single), wheel_slip_rows(wheel, float(single)))



ACKERMANN = catalog.load("ackermann")


@pytest.mark.parametrize(("argument", "call"), [
    ("assigned", lambda n: singular_set(ACKERMANN, n)),
    ("assigned", lambda n: is_singular(ACKERMANN, None, n)),
    ("assigned", lambda n: coordinated_singular_set(ACKERMANN, n)),
    ("variables", lambda n: singular_set(ACKERMANN, ("vx", "vy", "omega"), variables="front_left")),
    ("variables", lambda n: best_configurations(ACKERMANN, variables="front_left")),
    ("joints", lambda n: best_configurations(ACKERMANN, joints=n)),
    ("joints", lambda n: natural_length(ACKERMANN, joints=n)),
    ("assigned", lambda n: isotropy_matrix(ACKERMANN, None, n, ("vx",))),
    ("selected", lambda n: isotropy_length(ACKERMANN, None, ("rear_left.spin",), "vx")),
    ("sensed", lambda n: realtime(ACKERMANN, n)),
    ("names", lambda n: twist_is_determined(ACKERMANN, n)),
    ("names", lambda n: extended_solution(ACKERMANN, ("vx", "omega"), [1.0, 0.1]).values(n)),
    ("joints", lambda n: encoders_for("ackermann", n)),
    ("assigned velocities", lambda n: inverse_model(ACKERMANN, n)),
    ("sensed", lambda n: odometry_model(ACKERMANN, n)),
])
def test_a_lone_name_where_names_are_expected_is_refused_as_a_string(argument, call):
    """A lone string was iterated letter by letter ("no velocity 'r'"), and realtime's sensed=string built a model
    without FK or odometry; every door now reads names through _shapes.as_names."""
    with pytest.raises(WmrkitError, match=rf"^{argument}: expected a sequence of [a-z' .]*names, got the string '"):
        call("rear_left.spin")


def test_names_that_are_no_strings_are_refused():
    with pytest.raises(WmrkitError, match=r"^assigned: expected a sequence of velocity names, got \(1, 2\)$"):
        singular_set(ACKERMANN, (1, 2))
    with pytest.raises(WmrkitError, match=r"^assigned: expected a sequence of velocity names, got 3$"):
        singular_set(ACKERMANN, 3)
    assert singular_set(ACKERMANN, ["vx", "omega"]).assigned == ("vx", "omega")  # a list still does


@pytest.mark.parametrize(("change", "match"), [
    ({"name": 5}, r"^robot 5: name: expected a text, got int$"),  # was built, and to_file refused it
    ({"notes": ["a"]}, r"^robot 'ackermann': notes: expected a text, got list$"),  # TypeError: unhashable type
    ({"body": {"mass": 10.0}}, r"^robot 'ackermann': body: expected a wmrkit\.dynamics\.mass\.Body or None, got dict$"),
])
def test_a_robot_s_name_notes_and_body_are_checked(change, match):
    import dataclasses

    with pytest.raises(WmrkitError, match=match):
        dataclasses.replace(ACKERMANN, **change)
