"""Geared test robots shared by the coupling tests: a cart on a solid axle and a synchro drive (YAML text).

``TWO_ENCODERS``: two fixed wheels (r 0.1 m) on a solid axle (a 1:1 gear), both spins sensed, no third wheel.
``cart_yaml(ratio, front)``: two fixed wheels (r 0.075 m, half track 0.2 m) whose spins a ``gear`` turns at ratios
``1 : ratio``, one encoder on ``left.spin``, and a front or rear wheel (:data:`CASTOR` by default, or
:data:`STEERED`). ``SYNCHRO``: three steered wheels, their spins on one gear, their steering on one linkage.
:func:`held_constraints`: the no-slip rows with every gear's rows, built here (the tests' brute force).
"""

from __future__ import annotations

import numpy as np

from wmrkit import Robot

R, B = 0.075, 0.2  # the cart's wheel radius and half track [m]
CASTOR = "caster, type: castor, position: [-0.25, 0], heading: 0, d: 0.04, r: 0.025}"
STEERED = "front, type: steerable, position: [0.6, 0], heading: 0, r: 0.1, sensed: [steer]}"
_CART = """name: geared-axle
wheels:
  - {name: left, type: fixed, position: [0, 0.2], heading: 0, r: 0.075, actuated: [spin], sensed: [spin]}
  - {name: right, type: fixed, position: [0, -0.2], heading: 0, r: 0.075}
  - {name: FRONT
couplings:
  - {kind: gear, joints: [left.spin, right.spin], ratios: [1, RATIO]}
"""
TWO_ENCODERS = """name: geared
wheels:
  - {name: left, type: fixed, position: [0, 0.2], heading: 0, r: 0.1, actuated: [spin], sensed: [spin]}
  - {name: right, type: fixed, position: [0, -0.2], heading: 0, r: 0.1, sensed: [spin]}
couplings:
  - {kind: gear, joints: [left.spin, right.spin], ratios: [1, 1]}
"""
SYNCHRO = """name: synchro-3
wheels:
  - {name: a, type: steerable, position: [0.2, 0], heading: 0, r: 0.05, actuated: [spin, steer], sensed: [spin, steer]}
  - {name: b, type: steerable, position: [-0.1, 0.1732], heading: 0, r: 0.05, sensed: [steer]}
  - {name: c, type: steerable, position: [-0.1, -0.1732], heading: 0, r: 0.05, sensed: [steer]}
couplings:
  - {kind: gear, joints: [a.spin, b.spin, c.spin]}
  - {kind: linkage, joints: [a.steer, b.steer, c.steer]}
"""


def cart_yaml(ratio: float = 1.0, front: str = CASTOR) -> str:
    """The solid-axle cart's description, its gear at ``1 : ratio``, with `front` (:data:`CASTOR`, :data:`STEERED`,
    or another wheel's fields after ``name:``)."""
    return _CART.replace("FRONT", front).replace("RATIO", repr(float(ratio)))


def held_constraints(robot: Robot, beta: np.ndarray | None = None) -> np.ndarray:
    """The slip matrix (3.22) of `robot` at `beta` with a row ``q_0 / k_0 - q_j / k_j = 0`` per further joint of each
    ``gear`` coupling (``q_j = k_j u``), built here by hand: the brute force the coupling tests check against."""
    a = robot.constraint_matrix() if beta is None else robot.constraint_matrix(beta)
    rows = [a]
    for c in (c for c in robot.couplings if c.kind == "gear"):
        for j, k in zip(c.joints[1:], c.ratios[1:], strict=True):
            row = np.zeros(a.shape[1])
            row[robot.velocity_index(c.joints[0])], row[robot.velocity_index(j)] = 1 / c.ratios[0], -1 / k
            rows.append(row[None])
    return np.vstack(rows)
