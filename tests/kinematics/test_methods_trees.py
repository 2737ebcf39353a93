"""The tree of Fig. 4.1 on hand-made systems, and the direct/inverse trees (Figs. 4.2-4.3) on simple robots."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wmrkit import Robot, Wheel
from wmrkit.kinematics.trees import classify_system, direct_tree, inverse_tree, motion_constraints, vehicle_dof

E1, E2 = [1.0, 0.0], [0.0, 1.0]


@pytest.mark.parametrize(("a", "b", "y", "leaf"), [
    ([E1, E2], [[1.0], [2.0]], None, "determined"),  # square, full rank
    ([E1, E2, [1.0, 1.0]], [[1.0], [0.0], [0.0]], None, "overdetermined"),
    ([E1, E2, [1.0, 1.0]], [[1.0, 1.0], [0.0, 0.0], [1.0, 0.0]], [1.0, 0.0], "consistent"),  # B y in col(A)
    ([E1, E2, [1.0, 1.0]], [[1.0], [0.0], [0.0]], [1.0], "inconsistent"),
    ([[1.0, 1.0], [2.0, 2.0]], [[1.0], [2.0]], None, "indeterminate"),  # rank A < n, col(B) in col(A)
    ([[1.0, 1.0], [2.0, 2.0]], [[1.0], [0.0]], None, "underdetermined"),
    ([[1.0, 1.0], [2.0, 2.0]], [[1.0, 1.0], [0.0, 2.0]], [1.0, 0.0], "incompatible"),
    ([[1.0, 1.0], [2.0, 2.0]], [[1.0, 1.0], [0.0, 2.0]], [0.0, 1.0], "indeterminate"),
])
def test_fig_4_1_leaves(a, b, y, leaf):
    assert classify_system(a, b, y).leaf == leaf


def test_fig_4_1_is_batched():
    a = np.stack([np.eye(2), [[1.0, 1.0], [2.0, 2.0]]])
    verdict = classify_system(a, [[[1.0], [1.0]], [[1.0], [2.0]]])
    assert verdict.leaf.tolist() == ["determined", "indeterminate"]
    assert verdict.rank_a.tolist() == [2, 1] and verdict.unique.tolist() == [True, False]


def _omni(n: int) -> Robot:
    return Robot("omni", tuple(Wheel(f"s{i}", "swedish", 0.3, 2 * math.pi * i / n, 2 * math.pi * i / n + 1.2, 0.05,
                                     gamma=math.pi / 4, r_r=0.01) for i in range(n)))


def test_direct_tree_is_determined_only_for_one_wheel():
    """Fig. 4.2: rank [I_bar, J] = 3 iff one wheel: no slip is possible."""
    assert direct_tree(_omni(1)).leaf == "determined"
    assert direct_tree(_omni(3)).leaf == "overdetermined"


def test_inverse_tree_is_determined_iff_every_wheel_is_omnidirectional():
    """Fig. 4.3 and (4.21): Delta(J) I_bar = 0, 3 DOF, iff every J_i is square and regular."""
    castors = Robot("c", tuple(Wheel(f"c{i}", "castor", 0.3, 2.1 * i, 0.4 * i, 0.05, d=0.04) for i in range(3)))
    for robot in (_omni(3), castors):
        assert inverse_tree(robot).leaf == "determined" and int(vehicle_dof(robot)) == 3
        np.testing.assert_allclose(motion_constraints(robot), 0, atol=1e-12)
    mixed = Robot("m", (*castors.wheels, Wheel("f", "fixed", 0.3, 1.0, 0.2, 0.05)))
    assert inverse_tree(mixed).leaf == "overdetermined" and int(vehicle_dof(mixed)) == 2
