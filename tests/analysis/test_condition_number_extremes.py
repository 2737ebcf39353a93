"""condition_number (5.28) at the ends of the float range. Before: a least singular value below the normal range
(1e-310) raised "RuntimeWarning: overflow encountered in divide" (s_max / s_min was computed before np.where chose
inf: seen once in test_analysis_invariants under -n 2), and entries of 1.7e308 gave kappa inf for an isotropic
matrix (its singular values overflowed). Checked against closed forms: a diagonal matrix's kappa is the ratio of
its largest and smallest |entries|, a multiple of an orthogonal matrix has kappa 1, and kappa is scale invariant."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest

from wmrkit import Robot
from wmrkit.analysis.isotropy import condition_number, natural_length, twist_condition_number
from wmrkit.wheels import Wheel

ROTATION = np.array([[np.cos(0.3), -np.sin(0.3)], [np.sin(0.3), np.cos(0.3)]])


@pytest.mark.parametrize("small", [1e-310, 5e-324, 1e-300])
def test_a_least_singular_value_below_the_normal_range_is_singular_without_a_warning(small):
    h = np.diag([1.0, small])  # kappa 1 / small: beyond 1e13, singular (inf)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert condition_number(h) == np.inf
        assert condition_number(np.stack([h, np.eye(2), 2e300 * np.diag([1.0, small])])).tolist() == [np.inf, 1, np.inf]
        assert condition_number(np.diag([1e300, 1e-10])) == np.inf  # 1e310: not a number of doubles


@pytest.mark.parametrize("scale", [1.7e308, 1e300, 1.0, 1e-290])
def test_kappa_does_not_depend_on_the_scale_of_the_matrix(scale):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert condition_number(scale * ROTATION) == pytest.approx(1.0, rel=1e-14)
        assert condition_number(scale * np.array([[1.0, 1.0], [1.0, -1.0]])) == pytest.approx(1.0, rel=1e-14)
        assert condition_number(scale * np.diag([1.0, 1e-3])) == pytest.approx(1e3, rel=1e-12)
        assert condition_number(scale * np.diag([1.0, 1e-14])) == np.inf  # below the 1e-13 threshold at any scale
        stacked = condition_number(np.stack([scale * (ROTATION @ np.diag([1.0, 0.5])), np.diag([3.0, 1.0])]))
        assert stacked == pytest.approx([2.0, 3.0], rel=1e-14)


def test_the_zero_matrix_is_singular():
    assert condition_number(np.zeros((3, 3))) == np.inf


def test_the_robot_hypothesis_found_two_fixed_wheels_2e_311_m_apart():
    """tests/strategies.py robots (seed 6 of test_analysis_invariants' kappa test, 1500 examples, -W error): w0 at
    the origin and w1 at x = 2.2e-311 m, both heading 0, r = 0.5. Their spins are both vx / r (y = 0): they cannot
    see omega, kappa is infinite at every D; twist_condition_number(length=1) raised the overflow warning."""
    w0 = Wheel(name="w0", type="fixed", l=0.0, alpha=0.0, beta=0.0, r=0.5)
    robot = Robot(name="r", wheels=(w0, replace(w0, name="w1", l=2.225073858507e-311)))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for d in (0.05, 1.0, 20.0):
            assert twist_condition_number(robot, length=d) == np.inf
        assert natural_length(robot)[1] == np.inf
