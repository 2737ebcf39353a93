"""Invariants over random robots (tests/strategies.py): what must hold for ANY valid robot.

Each transformed robot is built field by field from the thesis's geometry (3.8), independently of the library
(tests/strategies.py: moved, mirrored, scaled):

- frame change: the reference point moved to c and the frame turned by phi. A wheel at p sits at R(-phi)(p - c) with
  its angles turned by -phi; the twist at the new point is v' = R(-phi)(v + omega z x c), omega' = omega; every
  joint rate is unchanged and every heading turns by -phi.
- mirror in y (x, y) -> (x, -y): directions theta -> -theta. A wheel keeps its spin sign if its rolling direction
  (heading = beta + delta - 90 deg) is mirrored, so beta' = pi - beta, delta' = -delta, gamma' = -gamma (the roller's
  axis line mirrored), d' = d; a double unit's axle then points the other way, so spin1 and spin2 swap. The twist
  (vx, vy, omega) -> (vx, -vy, -omega). A joint rate is a pseudovector w u about its axis u: mirrored it is
  -M(w u) = w (-M u), and the mirrored wheel's spin and roller axes are -M u, so those rates keep their sign; the
  steering axis z is kept (M z = z), so steering rates change sign. Ball and orthogonal wheels have gamma = 90 deg
  by type, not -90 deg: their roller axis keeps its line but points the other way, so their roller rate changes sign.
- scale: every length times k: (vx, vy, omega) -> (k vx, k vy, omega) with the same joint rates.
- wheel order: the per-wheel results permute with the wheels, the twist does not change.
"""

from __future__ import annotations

import inspect
import math
from dataclasses import replace

import numpy as np
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from strategies import mirrored, moved, moved_twist, robots, scaled
from wmrkit import Robot, Wheel, forward_kinematics, wheel_commands
from wmrkit.kinematics.wheel_ik import twist_is_determined

SLIP_TOL = inspect.signature(wheel_commands).parameters["slip_tol"].default  # [m/s], absolute

_twists = st.lists(st.floats(-2, 2), min_size=3, max_size=3).map(np.array)


def _wrap(a):
    """Angles into (-pi, pi]."""
    return np.pi - np.mod(np.pi - np.asarray(a), 2 * np.pi)


def _rates(robot: Robot, commands) -> dict[str, float]:
    return dict(zip(robot.rate_names, commands.rates.tolist(), strict=True))


def _defined(commands) -> bool:
    """No angle held (undefined: a policy, not a solution) and every heading clear of the +-pi wrap."""
    return not commands.held.any() and not (np.abs(np.abs(commands.heading[np.isfinite(commands.heading)])
                                                   - np.pi) < 1e-6).any()


def _scale(robot: Robot, twist) -> float:
    return 1.0 + float(np.abs(twist).sum()) * (1 + max(w.l + abs(w.d) + w.b for w in robot.wheels))


@settings(max_examples=500)
@given(robot=robots(max_wheels=4), twist=_twists, c=st.lists(st.floats(-1, 1), min_size=2, max_size=2).map(np.array),
       phi=st.floats(-math.pi, math.pi))
@example(robot=Robot(name="r", wheels=(Wheel(name="w0", type="steerable", l=0.0, alpha=0.0, beta=0.0, r=0.5),)),
         twist=np.array([0.0, 2.497482797838103e-12, 1.0]), c=np.array([1.0, 0.0]), phi=0.0)  # 2.5e-12 m from the ICR
def test_moving_the_reference_frame_transforms_the_twist_and_keeps_the_joint_rates(robot, twist, c, phi):
    other = moved(robot, c, phi)
    a, b = wheel_commands(robot, twist), wheel_commands(other, moved_twist(twist, c, phi))
    assume(_defined(a) and _defined(b))
    tol = 1e-9 * _scale(robot, twist)
    np.testing.assert_allclose(b.rates, a.rates, atol=tol)
    np.testing.assert_allclose(b.slip, a.slip, atol=tol)
    np.testing.assert_array_equal(b.feasible, a.feasible)
    steered = np.isfinite(a.heading)
    np.testing.assert_array_equal(np.isfinite(b.heading), steered)
    # a heading is the direction of its wheel's velocity: the moved twist's round-off (eps times the twist's terms)
    # turns it by that over the wheel's speed (a wheel 2.5e-12 m from the ICR: 5e-5 rad); 100 times that bound
    speed = np.abs(a.spin * np.array([w.r for w in robot.wheels]))[steered]
    noise = 100 * np.finfo(float).eps * _scale(robot, twist) / np.maximum(speed, np.finfo(float).tiny)
    np.testing.assert_array_less(np.abs(_wrap(b.heading[steered] - a.heading[steered] + phi)), 1e-9 + noise)
    # fk: the same joint rates give the moved twist back
    got, res = forward_kinematics(robot, _rates(robot, a), a.beta)
    got2, res2 = forward_kinematics(other, _rates(other, b), b.beta)
    np.testing.assert_allclose(res2, res, atol=1e-7 * _scale(robot, twist))
    if not twist_is_determined(robot, list(robot.rate_names), a.beta):
        return  # the minimum-norm twist of underdetermined rates depends on the frame
    np.testing.assert_allclose(got2, moved_twist(got, c, phi), atol=1e-6 * _scale(robot, twist))


@settings(max_examples=500)
@given(robot=robots(max_wheels=4), twist=_twists)
def test_a_robot_mirrored_in_y_mirrors_the_twist_and_keeps_the_spins(robot, twist):
    mirror = mirrored(robot)
    m_twist = twist * np.array([1.0, -1.0, -1.0])
    a, b = wheel_commands(robot, twist), wheel_commands(mirror, m_twist)
    assume(_defined(a) and _defined(b))
    tol = 1e-9 * _scale(robot, twist)
    ra, rb = _rates(robot, a), _rates(mirror, b)
    for name, value in ra.items():
        wheel, _, joint = name.partition(".")
        other = {"spin1": "spin2", "spin2": "spin1"}.get(joint, joint)
        fixed_gamma = joint == "roller" and robot.wheel(wheel).type != "swedish"  # gamma = 90 deg, not -90 deg
        expected = -value if joint == "steer" or fixed_gamma else value
        assert math.isclose(rb[f"{wheel}.{other}"], expected, abs_tol=tol), (name, rb, ra)
    np.testing.assert_allclose(np.abs(b.slip), np.abs(a.slip), atol=tol)
    np.testing.assert_array_equal(b.feasible, a.feasible)
    steered = np.isfinite(a.heading)
    np.testing.assert_allclose(_wrap(b.heading[steered] + a.heading[steered]), 0.0, atol=1e-9)
    got, _ = forward_kinematics(robot, ra, a.beta)
    got2, _ = forward_kinematics(mirror, rb, b.beta)
    np.testing.assert_allclose(got2, got * np.array([1.0, -1.0, -1.0]), atol=1e-6 * _scale(robot, twist))


@settings(max_examples=400)
@given(robot=robots(max_wheels=4), twist=_twists, k=st.floats(1e-3, 1e3))
def test_every_length_times_k_scales_the_linear_velocities_and_keeps_the_joint_rates(robot, twist, k):
    a, b = wheel_commands(robot, twist), wheel_commands(scaled(robot, k), twist * np.array([k, k, 1.0]))
    assume(_defined(a) and _defined(b))
    np.testing.assert_allclose(b.rates, a.rates, atol=1e-9 * _scale(robot, twist))
    np.testing.assert_allclose(b.slip, a.slip * k, atol=1e-9 * k * _scale(robot, twist))
    np.testing.assert_allclose(b.heading, a.heading, atol=1e-9)
    # slip_tol is absolute (1e-9 m/s): a slip s scaled to k s may cross it (one fixed wheel at beta 0.5, twist
    # (0, 1.19e-7, 0), k = 1/64: 5.7e-8 m/s, not feasible; 8.9e-10 m/s, feasible); elsewhere feasibility is kept
    sa, sb = np.abs(a.slip), np.abs(b.slip)
    crossed = np.any((np.minimum(sa, sb) <= SLIP_TOL) & (np.maximum(sa, sb) > SLIP_TOL), axis=-1)
    np.testing.assert_array_equal(np.where(crossed, a.feasible, b.feasible), a.feasible)


@settings(max_examples=400)
@given(robot=robots(max_wheels=4), twist=_twists, data=st.data())
def test_reordering_the_wheels_permutes_the_results_and_nothing_else(robot, twist, data):
    order = data.draw(st.permutations(range(len(robot.wheels))))
    shuffled = replace(robot, wheels=tuple(robot.wheels[i] for i in order))
    a, b = wheel_commands(robot, twist), wheel_commands(shuffled, twist)
    # fixed wheels' and Swedish/ball rates are one BLAS product (_ik_fast.constant_rates), whose rounding may depend
    # on a row's place in the matrix (OpenBLAS's AVX-512 kernels: a ball's roller at 64.0 gave 63.99999999999999
    # in another row, a spin 1.4438083426874098 for 1.44380834268741): the same numbers to 4 ulp, flags exactly
    ulps = 4 * np.finfo(float).eps
    for field in ("spin", "steer_rate", "slip", "heading"):
        np.testing.assert_allclose(getattr(b, field), getattr(a, field)[list(order)], rtol=ulps,
                                   atol=ulps * _scale(robot, twist), err_msg=field)
    for field in ("held", "in_range"):
        np.testing.assert_array_equal(getattr(b, field), getattr(a, field)[list(order)], err_msg=field)
    ra, rb = _rates(robot, a), _rates(shuffled, b)
    assert rb.keys() == ra.keys()
    names = sorted(ra)
    np.testing.assert_allclose([rb[k] for k in names], [ra[k] for k in names], rtol=ulps,
                               atol=ulps * _scale(robot, twist))
    assert bool(b.feasible) == bool(a.feasible)
