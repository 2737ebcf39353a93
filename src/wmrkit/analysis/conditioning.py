"""Wheels so close, or axles so nearly one, that the rank decisions of a description sit near their cut-off.

Every rank decision counts a singular value below about ``1e-9`` of the largest as zero (``kinematics.linalg``),
in the robot's size ``L`` (``characteristic_length``). Two mount points, or two parallel axles, ``1e-8 L`` apart
are distinct to the decisions, ``1e-10 L`` apart they are one: within a few decades of the cut-off a rounding
of the description decides the verdicts (two parallel fixed axles 55 nm apart make a robot that cannot turn;
on one axle it is a differential drive). :func:`ill_conditioned_pairs` names such pairs, for a warning.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from ..kinematics.linalg import characteristic_length
from ..robot import Robot
from .lines import constraint_lines

#: A distance below ``NEAR * L`` [m] between two mount points or two parallel axles, or an angle below ``NEAR``
#: [rad] between two axles, is within 1000 times the rank tolerance: the description's digits decide.
NEAR = 1e-6
#: Below ``ROUNDING * L`` (or rad) two points or axles are one, as described (rounding of ``l``, ``alpha``).
ROUNDING = 1e-12


def ill_conditioned_pairs(robot: Robot) -> list[str]:
    """One message per pair of wheels of `robot` whose mount points are closer than :data:`NEAR` ``L`` (but not
    at one point), or whose axles at the described steering are parallel within :data:`NEAR` rad (but not
    exactly) or parallel and closer than :data:`NEAR` ``L`` (but not one line)."""
    size = characteristic_length(robot)
    out = []
    for a, b in itertools.combinations(robot.wheels, 2):
        gap = math.dist(a.position, b.position)
        if ROUNDING * size < gap < NEAR * size:
            out.append(f"wheels '{a.name}' and '{b.name}' are mounted {gap:.3g} m apart ({gap / size:.2g} of the "
                       f"robot's size {size:.3g} m): too close for the rank decisions to tell reliably whether "
                       "they are at one point (ill-conditioned; docs/limits.md)")
    cl = constraint_lines(robot)
    lines = cl.lines(robot.beta)
    axles = [(w, g) for label, w, g in zip(cl.labels, cl.wheels, lines, strict=True)
             if label.startswith("axle") and " + " not in w]
    for (wa, ga), (wb, gb) in itertools.combinations(axles, 2):
        turn = abs(float(ga[0] * gb[1] - ga[1] * gb[0]))  # sin of the angle between the unit normals
        if ROUNDING < turn < NEAR:
            out.append(f"the axles of wheels '{wa}' and '{wb}' are {turn:.3g} rad from parallel: too close for "
                       "the rank decisions to tell reliably whether they are parallel (ill-conditioned; "
                       "docs/limits.md)")
        elif turn <= ROUNDING:
            gap = abs(float(ga[2] - np.sign(ga[0] * gb[0] + ga[1] * gb[1]) * gb[2]))
            if ROUNDING * size < gap < NEAR * size:
                out.append(f"the axles of wheels '{wa}' and '{wb}' are parallel and {gap:.3g} m apart "
                           f"({gap / size:.2g} of the robot's size {size:.3g} m): too close for the rank decisions "
                           "to tell reliably whether they are one axle (ill-conditioned; docs/limits.md)")
    return out
