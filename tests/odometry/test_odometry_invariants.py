"""Odometry invariants over random robots (tests/strategies.py) with every joint sensed, driven along an arc (one
constant twist, which the robot's fixed wheels allow) by :func:`simulate`: the exact scheme recovers the synthetic
poses, the chunk size changes nothing, and the log played backwards from the end pose retraces the path."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from strategies import robots
from wmrkit.errors import WmrkitError
from wmrkit.odometry import JointLog, SensingError, TwistProfile, odometry, odometry_model, simulate

METHODS = ("exact", "rk2", "euler", "paper002")


def _arc_run(robot, raw):
    """`robot` with every joint sensed and its synthetic run along the arc of `raw` projected onto the twists its
    fixed wheels allow (their lateral rows, (3.11) row 0), or None when its joints do not determine the motion."""
    robot = replace(robot, wheels=tuple(replace(w, sensed=w.kind.joints) for w in robot.wheels))
    rows = np.array([[math.cos(w.beta), math.sin(w.beta), w.l * math.sin(w.beta - w.alpha)]
                     for w in robot.wheels if w.type == "fixed"]).reshape(-1, 3)
    twist = np.array(raw) - (np.linalg.pinv(rows) @ (rows @ raw) if len(rows) else 0.0)
    try:
        run = simulate(robot, TwistProfile(np.array([2.0]), twist[None]), 20.0)
        model = odometry_model(robot)
        odometry(model, run.log.slice(0, 2))
    except (SensingError, WmrkitError):  # the sensed joints do not determine the twist (there, or anywhere)
        return None
    return robot, model, run


_arcs = {"robot": robots(max_wheels=4), "raw": st.lists(st.floats(-1, 1), min_size=3, max_size=3).map(np.array)}


@settings(max_examples=20)
@given(**_arcs, chunk=st.integers(1, 7))
def test_exact_odometry_recovers_the_synthetic_arc_and_chunks_change_nothing(robot, raw, chunk):
    arc = _arc_run(robot, raw)
    assume(arc is not None)
    robot, model, run = arc
    for method in METHODS:
        whole = odometry(model, run.log, method=method)
        chunked = odometry(model, run.log, method=method, chunk_size=chunk)
        np.testing.assert_array_equal(chunked.poses, whole.poses, err_msg=method)
        np.testing.assert_array_equal(chunked.slip, whole.slip, err_msg=method)
        if method == "exact" and not any(w.type in ("castor", "double_castor") for w in robot.wheels):
            # constant steering: each interval's twist is exact, so is the SE(2) step (castors turn within it)
            np.testing.assert_allclose(whole.poses, run.truth, atol=1e-12 * (1 + np.abs(run.truth).max()))


@settings(max_examples=20)
@given(**_arcs)
def test_the_log_played_backwards_from_the_end_retraces_the_path(robot, raw):
    """The exact step's inverse is the step of the negated increment, and RK2's midpoint rule is symmetric: both
    schemes retrace their own path; Euler's (and 002's) are first order and do not (not checked)."""
    arc = _arc_run(robot, raw)
    assume(arc is not None)
    _, model, run = arc
    log = run.log
    back = JointLog(log.time[-1] - log.time[::-1], log.joints, log.positions[::-1])
    for method in ("exact", "rk2"):
        forward = odometry(model, log, method=method)
        backward = odometry(model, back, method=method, pose0=forward.poses[-1])
        np.testing.assert_allclose(backward.poses[::-1], forward.poses, atol=1e-12 * (1 + np.abs(forward.poses).max()),
                                   err_msg=method)
        np.testing.assert_allclose(backward.slip[1:], forward.slip[1:][::-1], atol=1e-12, err_msg=method)
