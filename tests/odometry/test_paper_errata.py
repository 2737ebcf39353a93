"""Errata of paper 002 (papers-odometry.md A.3, A.7): the printed forms fail, the corrected ones hold."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.odometry.integrators import step
from wmrkit.odometry.model import odometry_model

# One arc: half track l, wheel arcs dS_der (right) and dS_izq (left), start pose (x0, y0, phi0).
L, DS_DER, DS_IZQ = 0.25, 0.33, 0.21
X0, Y0, PHI0 = 1.0, -2.0, 0.6
THETA = (DS_DER - DS_IZQ) / (2 * L)  # 002 (6)
DS = (DS_DER + DS_IZQ) / 2  # 002 (1)
R_CENTRO = DS / THETA
PHI = PHI0 + THETA


def _exact():
    return step([X0, Y0, PHI0], [DS, 0.0, THETA], "exact")


def test_002_eq_10_sign_of_the_icr():
    """(8) gives Q_y = y0 + R cos(phi0); (10) prints y0 - R cos(phi - theta). The ICR is where both wheels' arcs
    are centred: at distance R_centro from P along the left normal of the start heading."""
    q_printed = Y0 - R_CENTRO * math.cos(PHI - THETA)
    q_right = Y0 + R_CENTRO * math.cos(PHI - THETA)
    q_x = X0 - R_CENTRO * math.sin(PHI - THETA)  # (9)
    end = _exact()
    assert math.hypot(end[0] - q_x, end[1] - q_right) == pytest.approx(R_CENTRO, rel=1e-12)
    assert math.hypot(end[0] - q_x, end[1] - q_printed) != pytest.approx(R_CENTRO, rel=1e-3)


def test_002_eq_12_printed_y_is_wrong_corrected_is_the_exact_step():
    y_printed = Y0 - R_CENTRO * (math.cos(PHI) * math.cos(THETA) + math.sin(PHI) * math.sin(THETA)) \
        + R_CENTRO * math.cos(PHI)  # the last line of (12) as printed
    y_right = Y0 + R_CENTRO * (math.cos(PHI - THETA) - math.cos(PHI))
    x_11 = X0 + R_CENTRO * (math.sin(PHI) - math.sin(PHI - THETA))  # (11) is right
    end = _exact()
    assert end[0] == pytest.approx(x_11, abs=1e-15)
    assert end[1] == pytest.approx(y_right, abs=1e-15)
    assert abs(end[1] - y_printed) > 0.1 * DS


def test_002_eq_5_text_the_track_is_the_difference_of_the_radii():
    """The text after (5) says 2l = dS_der - dS_izq; (2) and (6) say 2l = R_der - R_izq."""
    r_der, r_izq = DS_DER / THETA, DS_IZQ / THETA  # (3), (4)
    assert r_der - r_izq == pytest.approx(2 * L, rel=1e-12)
    assert DS_DER - DS_IZQ != pytest.approx(2 * L, rel=1e-3)


def test_002_eq_17_heading_change_is_divided_by_2l():
    """(17) prints phi - phi0 = (dS_der - dS_izq) / 2; (6), (18) and the robot's own kinematics give / (2 l)."""
    robot = catalog.load("diff-drive")  # half track 0.20 m, r = 0.075 m
    d_right, d_left = 0.4 / 0.075, 0.1 / 0.075  # wheel angles for arcs of 0.4 m and 0.1 m
    dtheta = odometry_model(robot).increments(np.array([[d_left, d_right]])).increments_robot[0, 2]
    assert dtheta == pytest.approx((0.4 - 0.1) / (2 * 0.20), rel=1e-12)
    assert dtheta != pytest.approx((0.4 - 0.1) / 2, rel=1e-3)


def test_002_section_iii_wheel_names_right_is_derecha():
    """Section III names omega_d the left wheel; with d = derecha (right), theta > 0 (a left turn) when the right
    wheel travels farther, as Section V and (16) have it."""
    robot = catalog.load("diff-drive")
    inc = odometry_model(robot).increments(np.array([[1.0, 2.0]])).increments_robot[0]  # (left, right)
    assert inc[2] > 0
