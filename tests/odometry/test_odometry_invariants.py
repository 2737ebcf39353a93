"""Odometry invariants over random robots (tests/strategies.py) with every joint sensed, driven along an arc (one
constant twist, which the robot's fixed wheels allow) by :func:`simulate`: the exact scheme recovers the synthetic
poses, the chunk size changes nothing, and the log played backwards from the end pose retraces the path; a program
of whole sample periods is recorded at the samples' own times (poses composed segment by segment in the test)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from strategies import robots, wheels
from wmrkit import Robot, Wheel, catalog
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


def _roundoff(model, log) -> float:
    """The pose error [m, rad] the log's own round-off allows: each recorded angle is known to eps of the largest,
    each increment to 2 eps |p|max, and the sensing map's twist rows (gain G, the largest row sum) carry it N times
    (times the path's size for x and y). G is about r / size for a well-sensed robot (the bound is far below 1e-12),
    r / gap for two parallel wheels a gap apart: 9e6 for wheels 55 nm apart, which the rank tolerance keeps."""
    maps = model.from_positions(log.positions).solution
    gain = np.abs(maps[..., :3, :]).sum(axis=-1).max()
    return 2 * np.finfo(float).eps * gain * np.abs(log.positions).max() * len(log.time)


def _parallel(gap: float, r1: float) -> Robot:
    """Two fixed wheels along x, the second `gap` m ahead of the first, spins sensed: omega is read from the spins'
    difference over the gap (the rank tolerance keeps gaps above 1e-9 of the size: theta is off by round-off / gap)."""
    return Robot("r", (Wheel("w0", "fixed", 0.0, 0.0, 0.0, 0.5, sensed=("spin",)),
                       Wheel("w1", "fixed", gap, 0.0, 0.0, r1, sensed=("spin",))))


_arcs = {"robot": robots(max_wheels=4), "raw": st.lists(st.floats(-1, 1), min_size=3, max_size=3).map(np.array)}


@settings(max_examples=60)
@given(**_arcs, chunk=st.integers(1, 7))
@example(robot=_parallel(2.7557313707070068e-06, 0.01171875), raw=np.array([0.0, 1.0, 0.0]), chunk=1)  # theta off 4e-10
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
            scale = 1 + np.abs(run.truth).max()
            np.testing.assert_allclose(whole.poses, run.truth, atol=(1e-12 + _roundoff(model, run.log)) * scale)


@settings(max_examples=60)
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


def _pose_after(pose, twist, t):
    """`pose` moved by the constant body `twist` for `t` seconds: the exact SE(2) exponential, written here."""
    x, y, th = pose
    vx, vy, w = np.asarray(twist, float) * t
    if abs(w) < 1e-12:
        dx, dy = vx, vy
    else:
        s, c = math.sin(w) / w, 2 * math.sin(w / 2) ** 2 / w  # not (1 - cos w) / w: 0 for |w| < 1e-8
        dx, dy = s * vx - c * vy, c * vx + s * vy
    return np.array([x + math.cos(th) * dx - math.sin(th) * dy, y + math.sin(th) * dx + math.cos(th) * dy, th + w])


def test_a_straight_run_is_recorded_at_the_samples_own_times():
    """1 m/s straight ahead at 5 Hz: the pose at t is x = t and each wheel has turned t / r. The fine grid of 8
    steps a sample put 8k / 40 s (rounded below k / 5) before the sample time, so samples 1, 2, 4, 5, 8-11 read the
    run one fine step late (x = 0.225 m at 0.2 s) and the log's joints with them."""
    robot = catalog.load("diff-drive")
    run = simulate(robot, TwistProfile(np.array([2.4]), np.array([[1.0, 0.0, 0.0]])), 5.0)
    np.testing.assert_allclose(run.truth[:, 0], run.log.time, atol=1e-12)
    np.testing.assert_allclose(run.log.positions, run.log.time[:, None] / 0.075 * [1.0, 1.0], atol=1e-12)


@st.composite
def _rollers_only(draw):
    """Random robots of 1-4 wheels that never steer (fixed, Swedish, ball, orthogonal), every joint sensed."""
    n = draw(st.integers(1, 4))
    kinds = st.sampled_from(["fixed", "swedish", "ball", "orthogonal"])
    return Robot("r", tuple(replace(w, sensed=w.kind.joints)
                            for w in (draw(wheels(draw(kinds), name=f"w{i}")) for i in range(n))))


@settings(max_examples=60)
@given(robot=_rollers_only(), rate=st.sampled_from([3.0, 5.0, 10.0, 20.0, 30.0]),
       pose0=st.tuples(st.floats(-3, 3), st.floats(-3, 3), st.floats(-3, 3)),
       segments=st.lists(st.tuples(st.integers(1, 10), st.lists(st.floats(-1, 1), min_size=3, max_size=3)),
                         min_size=1, max_size=4))
@example(robot=_parallel(5.478042762003488e-08, 0.5), rate=3.0,
         pose0=(0.0, 0.0, 0.0), segments=[(1, [0.0, 1.0, 0.0])])  # wheels 55 nm apart: theta off by 9.3e-10 rad
@example(robot=Robot("r", (*_parallel(0.0, 0.5).wheels, Wheel("w2", "swedish", 1.0, 0.0, 0.0, 0.5, gamma=-1.0,
                                                            r_r=0.0625, sensed=("spin",)))),
         rate=3.0, pose0=(0.0, 0.0, 0.0), segments=[(1, [0.0, 1.0, 2.5e-08])])  # x = -vy t (w t) / 2 = -1.4e-9
def test_a_program_of_whole_sample_periods_is_recorded_at_the_sample_times(robot, rate, pose0, segments):
    """Segments of whole sample periods (twists projected onto those the fixed wheels allow): each sample's true
    pose is the segments composed up to its time, and the exact scheme recovers it from the log (the twist is
    constant over every interval, no wheel steers)."""
    rows = np.array([[math.cos(w.beta), math.sin(w.beta), w.l * math.sin(w.beta - w.alpha)]
                     for w in robot.wheels if w.type == "fixed"]).reshape(-1, 3)
    twists = np.array([s[1] for s in segments])
    twists = twists - (twists @ (np.linalg.pinv(rows) @ rows).T if len(rows) else 0.0)
    periods = [s[0] for s in segments]
    try:
        run = simulate(robot, TwistProfile(np.array(periods) / rate, twists), rate, pose0=pose0)
        model = odometry_model(robot)
        got = odometry(model, run.log, method="exact", pose0=pose0)
    except (SensingError, WmrkitError):  # the sensed joints do not determine the twist
        assume(False)
    want = [np.array(pose0, float)]
    for k, twist in zip(periods, twists, strict=True):
        for _ in range(k):
            want.append(_pose_after(want[-1], twist, 1 / rate))
    scale = 1 + np.abs(want).max()
    np.testing.assert_allclose(run.truth, want, atol=1e-12 * scale * len(want))
    np.testing.assert_allclose(got.poses, want, atol=(1e-12 * len(want) + _roundoff(model, run.log)) * scale)
