"""Slip-model invariants over random robots (tests/strategies.py: moved, mirrored): WLS (7.52) and MCD (7.63) with
a nonlinear friction law solve for contact slips, which belong to no frame, so moving and turning the robot frame
transforms their twist by the adjoint and mirroring the robot mirrors it (spin1/spin2 swapped), the slips unchanged
(mirrored: the same magnitudes, a double unit's two contacts swapped). Only where the assigned spins determine the
other velocities: a minimum-norm twist depends on the frame."""

from __future__ import annotations

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from strategies import mirrored, moved, moved_twist, robots
from wmrkit.slip.models import mcd, wls


def _law(v_slip, v_body, loads):
    """An odd, saturating friction law (N): -tanh(v / 0.5 m/s) per component times the load."""
    return -np.tanh(v_slip / 0.5) * loads[..., None]


@settings(max_examples=300)
@given(robot=robots(max_wheels=4), c=st.tuples(st.floats(-1, 1), st.floats(-1, 1)), phi=st.floats(-3, 3),
       data=st.data())
def test_slip_models_transform_with_the_frame_and_the_mirror(robot, c, phi, data):
    spins = [n for n in robot.rate_names if n.split(".")[1].startswith("spin")]
    assume(spins)
    free = [i for i, n in enumerate(robot.velocity_names) if n not in spins]
    s = np.linalg.svd(robot.constraint_matrix()[:, free], compute_uv=False)
    assume(len(s) == len(free) and s[-1] > 1e-6 * s[0])  # the spins determine the rest
    q = np.array(data.draw(st.lists(st.floats(-2, 2), min_size=len(spins), max_size=len(spins))))
    swapped = [n.replace("spin1", "#").replace("spin2", "spin1").replace("#", "spin2") for n in spins]
    for solve in (lambda r, names: wls(r, names, q), lambda r, names: mcd(r, names, q, _law)):
        a, b, m = solve(robot, spins), solve(moved(robot, c, phi), spins), solve(mirrored(robot), swapped)
        assume(a.converged and b.converged and m.converged)
        np.testing.assert_allclose(b.twist, moved_twist(a.twist, c, phi), atol=1e-7)
        np.testing.assert_allclose(m.twist, a.twist * [1, -1, -1], atol=1e-7)
        np.testing.assert_allclose(b.slip, a.slip, atol=1e-7)
        np.testing.assert_allclose(np.sort(np.abs(m.slip)), np.sort(np.abs(a.slip)), atol=1e-7)
