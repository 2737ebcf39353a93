"""Robot: a frozen value with named velocities, steering changes, and the composite equations (3.20)-(3.23)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.linalg import null_space

from strategies import robots
from wmrkit import Robot, ShapeError, UnknownNameError, Wheel, catalog

BATCHES = [(), (1,), (5,), (2, 3)]


def _mixed() -> Robot:
    return Robot("mixed", (
        Wheel("left", "fixed", l=0.3, alpha=math.pi / 2, beta=math.pi / 2, r=0.1, actuated=("spin",)),
        Wheel("c", "castor", l=0.5, alpha=math.pi, beta=0.2, r=0.05, d=0.04, sensed=("steer", "spin")),
        Wheel("s", "swedish", l=0.3, alpha=0.0, beta=0.0, r=0.05, gamma=math.pi / 4, r_r=0.01),
        Wheel("dw", "double", l=0.2, alpha=-1.0, beta=0.1, r=0.08, b=0.05),
        Wheel("st", "steerable", l=0.6, alpha=0.0, beta=-0.3, r=0.1, actuated=("steer", "spin")),
    ))


def test_names_and_order():
    r = _mixed()
    assert r.wheel_names == ("left", "c", "s", "dw", "st")
    assert r.velocity_names == ("vx", "vy", "omega", "left.spin", "c.steer", "c.spin", "s.spin", "s.roller",
                                "dw.steer", "dw.spin1", "dw.spin2", "st.spin")
    assert r.rate_names == r.velocity_names[3:]
    assert r.steer_names == ("c", "dw", "st")
    np.testing.assert_array_equal(r.beta, [0.2, 0.1, -0.3])
    assert r.actuated == ("left.spin", "st.steer", "st.spin")
    assert r.sensed == ("c.steer", "c.spin")
    assert r.velocity_index("dw.spin2") == 10
    assert r.constraint_matrix().shape == (2 * 6, 12)  # the double wheel has two contacts


def test_frozen_hashable_and_read_only():
    r = _mixed()
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.name = "other"  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.wheels[0].r = 1.0  # type: ignore[misc]
    assert hash(r) == hash(_mixed()) and r == _mixed()
    assert {r: 1}[_mixed()] == 1
    with pytest.raises(ValueError, match="read-only"):
        r.beta[0] = 1.0


@settings(max_examples=300)
@given(robots())
def test_dict_round_trip(robot):
    again = Robot.from_dict(robot.to_dict())
    assert again == robot and hash(again) == hash(robot)


def test_unknown_names_are_errors_with_the_list():
    r = _mixed()
    with pytest.raises(UnknownNameError) as err:
        r.wheel("front")
    assert str(err.value) == "robot 'mixed' has no wheel 'front' (wheels: left, c, s, dw, st)"
    with pytest.raises(UnknownNameError, match=r"^robot 'mixed' has no velocity 'c.spin1' \(velocities: vx, vy"):
        r.velocity_index("c.spin1")
    with pytest.raises(UnknownNameError, match=r"^robot 'mixed' has no wheel 'nope'"):
        r.with_steering({"nope": 0.1})
    with pytest.raises(UnknownNameError, match=r"^wheel 'left' of robot 'mixed' does not steer$"):
        r.with_steering({"left": 0.1})


def test_with_beta_and_with_steering():
    r = _mixed()
    beta = [1.0, -2.0, 0.5]
    moved = r.with_beta(beta)
    np.testing.assert_array_equal(moved.beta, beta)
    np.testing.assert_array_equal(r.beta, [0.2, 0.1, -0.3])  # the original is unchanged
    assert [w.beta for w in moved.wheels if not w.kind.steers] == [w.beta for w in r.wheels if not w.kind.steers]
    np.testing.assert_allclose(moved.constraint_matrix(), r.constraint_matrix(beta), rtol=0, atol=0)
    assert r.with_beta_angles({"dw": -2.0, "c": 1.0, "st": 0.5}) == moved
    assert r.with_steering({}) == r == r.with_beta_angles({})
    with pytest.raises(ShapeError, match=r"^beta: expected shape \(\.\.\., 3\), got \(2,\)$"):
        r.with_beta([0.0, 0.0])
    with pytest.raises(ShapeError, match="one configuration"):
        r.with_beta(np.zeros((2, 3)))


def test_frame_argument_is_checked():
    with pytest.raises(ValueError, match="frame must be 'roller' or 'robot'"):
        _mixed().constraint_matrix(frame="world")  # type: ignore[arg-type]


def test_forklift_drives_forward_with_positive_spins():
    """Catalog forklift: both drive wheels spinning +1 rad/s with the steered wheel straight: vx = +r."""
    fork = catalog.load("forklift")
    a = fork.constraint_matrix()
    names = fork.velocity_names
    q = np.zeros(len(names))
    q[[names.index("vx"), names.index("right_drive.spin"), names.index("left_drive.spin"),
       names.index("steer.spin")]] = [0.23, 1.0, 1.0, 1.0]
    np.testing.assert_allclose(a @ q, 0, atol=1e-15)


def _jacobian_system(robot: Robot, beta: np.ndarray) -> np.ndarray:
    """``M`` with ``M @ (twist; rates) = I_bar twist - J (rates; omega copies)`` (3.20)."""
    i_bar, j = robot.jacobian_form(beta)
    n_rates = len(robot.rate_names)
    m = np.concatenate([i_bar, -j[:, :n_rates]], axis=1)
    m[:, 2] -= j[:, n_rates:].sum(axis=1)  # every copy of omega is the twist's omega
    return m


@settings(max_examples=400)
@given(robot=robots(), seed=st.integers(0, 2**32 - 1))
def test_jacobian_form_agrees_with_constraint_matrix(robot, seed):
    """Every (twist, rates) in the null space of A (3.23) satisfies I_bar twist = J q_w (3.20), and back."""
    beta = np.random.default_rng(seed).uniform(-np.pi, np.pi, len(robot.steer_names))
    a = robot.constraint_matrix(beta)
    i_bar, j = robot.jacobian_form(beta)
    n_contacts = a.shape[0] // 2
    assert i_bar.shape == (3 * n_contacts, 3)
    assert j.shape == (3 * n_contacts, len(robot.rate_names) + n_contacts)
    np.testing.assert_array_equal(i_bar, np.tile(np.eye(3), (n_contacts, 1)))
    m = _jacobian_system(robot, beta)
    null_a, null_m = null_space(a), null_space(m)
    for q in null_a.T:
        q_w = np.r_[q[3:], np.full(n_contacts, q[2])]
        np.testing.assert_allclose(i_bar @ q[:3], j @ q_w, atol=1e-9)
    np.testing.assert_allclose(a @ null_m, 0, atol=1e-9)
    assert null_a.shape == null_m.shape


@pytest.mark.parametrize("batch", BATCHES, ids=str)
def test_jacobian_form_batch_equals_loop(batch):
    r = _mixed()
    beta = np.random.default_rng(1).uniform(-np.pi, np.pi, size=(*batch, 3))
    i_bar, j = r.jacobian_form(beta)
    assert j.shape == (*batch, 18, 9 + 6)
    for idx in np.ndindex(*batch):
        i_one, j_one = r.jacobian_form(beta[idx])
        np.testing.assert_array_equal(i_bar, i_one)
        np.testing.assert_allclose(j[idx], j_one, rtol=0, atol=1e-15)
    with pytest.raises(ShapeError, match=r"^beta: expected shape \(\.\.\., 3\), got \(4,\)$"):
        r.jacobian_form(np.zeros(4))


def test_robot_without_steering_takes_empty_beta():
    r = Robot("diff", (Wheel("l", "fixed", l=0.2, alpha=math.pi / 2, beta=math.pi / 2, r=0.05),
                       Wheel("r", "fixed", l=0.2, alpha=-math.pi / 2, beta=math.pi / 2, r=0.05)))
    assert r.steer_names == () and r.beta.shape == (0,)
    assert r.constraint_matrix(np.zeros((4, 0))).shape == (4, 4, 5)
    np.testing.assert_array_equal(r.constraint_matrix(np.zeros((4, 0)))[2], r.constraint_matrix())
    # differential drive (STYLE rule 5): (vx, omega) = (1, 0.5) needs spins 18 (left) and 22 (right) rad/s
    np.testing.assert_allclose(r.constraint_matrix() @ [1.0, 0.0, 0.5, 18.0, 22.0], 0, atol=1e-12)


def test_heading_is_the_rolling_direction():
    """Heading (users' steering angle, 0 = straight ahead): a forward spin moves the wheel's mount along it."""
    r = _mixed()
    rng = np.random.default_rng(3)
    for _ in range(20):
        heading = rng.uniform(-np.pi, np.pi, 3)
        steered = r.with_steering(dict(zip(r.steer_names, heading, strict=True)))
        np.testing.assert_allclose(np.angle(np.exp(1j * (steered.heading - heading))), 0, atol=1e-12)
        np.testing.assert_allclose(steered.beta, r.beta_of_heading(heading), atol=0)
        np.testing.assert_allclose(r.constraint_matrix(heading=heading), steered.constraint_matrix(), atol=0)
    # independent of the conversion: the rolling row (3.11) of a centred steerable wheel at the origin says a pure
    # translation along the heading needs spin r*phi_dot = speed, and one across it slips sideways.
    wheel = {"name": "w", "type": "steerable", "position": [0, 0], "r": 0.1}
    for h in (0.0, 0.5, -2.0, np.pi):
        bot = Robot.from_dict({"name": "one", "wheels": [{**wheel, "heading": float(h)}]})
        along = np.array([np.cos(h), np.sin(h), 0.0, 1 / 0.1])  # v along the heading, phi_dot = v / r
        np.testing.assert_allclose(bot.constraint_matrix() @ along, 0, atol=1e-12)
        across = np.array([-np.sin(h), np.cos(h), 0.0, 0.0])
        assert np.linalg.norm(bot.constraint_matrix() @ across) > 0.99
    with pytest.raises(ShapeError, match="not both"):
        r.constraint_matrix([0.0, 0.0, 0.0], heading=[0.0, 0.0, 0.0])


def test_castor_heading_follows_its_axle():
    """A castor's heading is its wheel's rolling direction, beta + delta - 90 deg (docs/conventions.md)."""
    c = Robot.from_dict({"name": "c", "wheels": [{"name": "c", "type": "castor", "position": [0, 0], "d": 0.05,
                                                  "delta": "20 deg", "heading": "30 deg", "r": 0.1}]})
    w = c.wheels[0]
    assert np.degrees(w.beta) == pytest.approx(30 - 20 + 90)
    assert np.degrees(w.heading) == pytest.approx(30)


def test_a_robot_built_in_python_has_wheels_with_distinct_names():
    """Robot() took two wheels named 'left' (velocity names 'left.spin' twice, a to_dict that did not load back)
    and no wheels at all (constraint_matrix: 'cannot reshape array of size 0')."""
    from wmrkit.wheels import WheelError

    r = catalog.load("diff-drive")
    with pytest.raises(WheelError, match=r"^robot 'diff-drive': wheels\[1\]: duplicate wheel name 'left'$"):
        dataclasses.replace(r, wheels=(r.wheels[0], dataclasses.replace(r.wheels[1], name="left")))
    with pytest.raises(WheelError, match=r"^robot 'diff-drive': wheels: expected a non-empty tuple of Wheel"):
        dataclasses.replace(r, wheels=())
    with pytest.raises(WheelError, match=r"^robot 'diff-drive': wheels: expected a non-empty tuple of Wheel"):
        dataclasses.replace(r, wheels=list(r.wheels))
    with pytest.raises(WheelError, match=r"^robot 'diff-drive': wheels\[0\]: expected a Wheel, got dict$"):
        dataclasses.replace(r, wheels=({"name": "left"},))
