"""Constraint lines (6.15)-(6.20): the rows the elimination leaves are the thesis's lines, for every wheel type."""

from __future__ import annotations

import math

import numpy as np
import pytest
from thesis_vehicles import robot

from wmrkit import Robot, ShapeError, UnknownNameError, Wheel, catalog
from wmrkit.analysis.lines import (
    common_point,
    constraint_lines,
    element_rows,
    line_residual,
    line_through,
    normalize_lines,
)

BATCHES = [(), (1,), (5,), (2, 3)]


@pytest.mark.parametrize("name", catalog.names())
@pytest.mark.parametrize("batch", BATCHES, ids=str)
def test_element_rows_are_the_twist_columns_of_the_slip_matrix(name, batch):
    r = catalog.load(name)
    beta = np.random.default_rng(1).uniform(-np.pi, np.pi, (*batch, len(r.steer_names)))
    np.testing.assert_allclose(element_rows(r, beta), r.constraint_matrix(beta)[..., :3], atol=1e-14)


def test_line_geometry_oracles():
    # (6.18): line through (1, 2) along +x is y = 2: d = P x u = 1*0 - 2*1 = -2; (6.19) holds for (5, 2)
    lam = line_through([1.0, 2.0], [3.0, 0.0])
    np.testing.assert_allclose(lam, [1.0, 0.0, -2.0])
    assert line_residual(lam, [5.0, 2.0]) == pytest.approx(0.0)
    assert line_residual(lam, [5.0, 3.0]) != pytest.approx(0.0)
    # two lines meeting at (2, -1): common point in homogeneous coordinates
    pts = np.array([[2.0, -1.0]])
    lines = np.stack([line_through(pts[0], [1.0, 1.0]), line_through(pts[0], [0.3, -2.0])])
    x, y, w = common_point(lines)
    np.testing.assert_allclose([x / w, y / w], [2.0, -1.0], atol=1e-12)
    # parallel lines meet at infinity, in their direction
    par = np.stack([line_through([0.0, 0.0], [1.0, 2.0]), line_through([3.0, 0.0], [1.0, 2.0])])
    x, y, w = common_point(par)
    assert abs(w) < 1e-12 and abs(x * 2 - y) < 1e-12
    np.testing.assert_allclose(normalize_lines([0.0, 0.0, -3.0]), [0.0, 0.0, -1.0])


def test_wrong_shapes_name_the_argument():
    with pytest.raises(ShapeError, match=r"point: expected shape \(\.\.\., 2\)"):
        line_through([1.0, 2.0, 3.0], [1.0, 0.0])
    with pytest.raises(ShapeError, match=r"beta: expected shape \(\.\.\., 1\)"):
        element_rows(catalog.load("thesis-tricycle"), [0.1, 0.2])
    with pytest.raises(UnknownNameError, match="no velocity 'vz'"):
        constraint_lines(catalog.load("thesis-tricycle"), ("vz",))


def _thesis_rows(w: Wheel, beta: float) -> dict[str, np.ndarray]:
    """Rows (6.1)-(6.4) written out from the digest §0.2 (independent of the package's kernels)."""
    l, a, d, dl, g = w.l, w.alpha, w.d, w.delta, w.gamma
    bd = beta + dl
    return {
        "E": np.array([math.cos(beta), math.sin(beta), l * math.sin(beta - a)]),
        "F": np.array([-math.sin(beta), math.cos(beta), l * math.cos(beta - a)]),
        "Fs": np.array([math.cos(beta + g), math.sin(beta + g), l * math.sin(beta + g - a)]),
        "Fbeta": np.array([math.cos(bd), math.sin(bd), l * math.sin(bd - a) - d * math.cos(dl)]),
        "Fphi": np.array([-math.sin(bd), math.cos(bd), l * math.cos(bd - a) + d * math.sin(dl)]),
    }


def _same_line(u, v):
    u, v = normalize_lines(u), normalize_lines(v)
    return np.allclose(u, v, atol=1e-12) or np.allclose(u, -v, atol=1e-12)


CASES = [  # (type, extra fields, assigned joints, expected thesis rows in order)
    ("fixed", {"beta": 0.4}, (), ["E"]),
    ("fixed", {"beta": 0.4}, ("spin",), ["E", "F"]),
    ("steerable", {"beta": 0.4}, (), ["E"]),
    ("steerable", {"beta": 0.4}, ("spin",), ["E", "F"]),
    ("swedish", {"beta": 0.4, "gamma": 1.1, "r_r": 0.02}, (), []),
    ("swedish", {"beta": 0.4, "gamma": 1.1, "r_r": 0.02}, ("spin",), ["Fs"]),
    ("castor", {"beta": 0.4, "d": 0.07, "delta": 0.0}, (), []),
    ("castor", {"beta": 0.4, "d": 0.07, "delta": 0.0}, ("steer",), ["Fbeta"]),
    ("castor", {"beta": 0.4, "d": 0.07, "delta": 0.0}, ("spin",), ["Fphi"]),
    ("castor", {"beta": 0.4, "d": 0.07, "delta": 0.5}, ("steer",), ["Fbeta"]),
    ("castor", {"beta": 0.4, "d": 0.07, "delta": 0.5}, ("steer", "spin"), ["Fbeta", "Fphi"]),
]


@pytest.mark.parametrize(("type_", "extra", "joints", "expected"), CASES)
def test_lines_are_the_thesis_rows(type_, extra, joints, expected):
    r = robot("one", {"name": "w", "type": type_, "l": 0.8, "alpha": -0.7, "r": 0.1, **extra})
    cl = constraint_lines(r, tuple(f"w.{j}" for j in joints))
    rows = _thesis_rows(r.wheels[0], r.wheels[0].beta)
    got = cl.lines()
    assert len(got) == len(expected)
    for g, key in zip(got, expected, strict=True):
        assert _same_line(g, rows[key]), (key, g, rows[key])


def test_castor_arm_line_for_delta_nonzero_passes_through_joint_and_contact():
    """Digest §6.2 (erratum 16): spin assigned, steer not -> the line through the steering joint and the contact."""
    delta, beta, d, l, alpha = 0.6, 0.9, 0.12, 0.8, -0.7
    r = robot("one", {"name": "c", "type": "castor", "l": l, "alpha": alpha, "beta": beta, "d": d, "delta": delta,
                      "r": 0.1})
    cl = constraint_lines(r, ("c.spin",))
    assert cl.labels == ("steering arm of c",)
    joint = np.array([l * math.cos(alpha), l * math.sin(alpha)])
    contact = joint + d * np.array([-math.sin(beta), math.cos(beta)])  # along S_y (3.10)
    lam = cl.lines()[0]
    assert abs(line_residual(lam, joint)) < 1e-12 and abs(line_residual(lam, contact)) < 1e-12
    plane = _thesis_rows(r.wheels[0], beta)["Fphi"]  # the wheel-plane line is a different line
    assert not _same_line(lam, plane)


def test_singular_omni_wheels_contribute_a_constraint():
    """(6.14): a castor with cos(delta) = 0 constrains the twist along its axle and leaves its rates undetermined."""
    sing = Robot("sing", (Wheel("c", "castor", 0.5, 0.3, 0.2, 0.1, d=0.05, delta=math.pi / 2),))
    cl = constraint_lines(sing)
    assert len(cl.labels) == 1 and cl.internal == ("c",)
    rows = _thesis_rows(sing.wheels[0], 0.2)
    assert _same_line(cl.lines()[0], rows["Fbeta"])
    regular = Robot("reg", (Wheel("c", "castor", 0.5, 0.3, 0.2, 0.1, d=0.05, delta=0.3),))
    assert constraint_lines(regular).labels == () and constraint_lines(regular).internal == ()


def test_double_wheel_is_an_orientable_wheel_with_its_axle_line():
    r = robot("dw", {"name": "dw", "type": "double", "l": 0.6, "alpha": 0.4, "beta": 1.1, "b": 0.1, "r": 0.05})
    cl = constraint_lines(r)
    assert cl.internal == ("dw",)  # pivoting in place: steer and opposite spins
    axle = np.array([math.cos(1.1), math.sin(1.1), 0.6 * math.sin(1.1 - 0.4)])  # E of a steerable wheel there
    assert all(_same_line(g, axle) for g in cl.lines())
