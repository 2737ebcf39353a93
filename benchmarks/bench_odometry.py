"""Odometry throughput against per-sample Python loops over peers' odometry updates (same run, same machine).

Targets (issue "odometry"): exact integration of a 10-million-sample log at >= 10 M samples/s on one core and
>= 50x the throughput of a per-sample Python loop calling a peer's odometry update; the first line says whether
this run meets them (a ``--quick`` run has 1 million samples: indicative only). Both sides turn the same
two-wheel angle log into poses, one update per sample; ours reads the log's time and angle columns, checks them
and stores every pose and slip value, into a trajectory the caller preallocated (``run_odometry(..., out=)``),
while the peer (which is given the heading) keeps only its last pose. The next line is the same run returning
new arrays (``odometry()``): it adds the operating system's zeroing of the fresh 240 MB of poses, which on a
shared machine varies with the other processes' memory traffic. The peer loops are timed on a slice of the log
(they are slow) and scaled linearly to the same sample count; the names say so. Times are the best of 3 calls,
after a first call that compiles the kernels (or loads them from numba's cache).
"""

from __future__ import annotations

import numpy as np

from wmrkit import catalog
from wmrkit.odometry.covariance import CrowleyNoise, propagate_covariance, step_jacobians
from wmrkit.odometry.integrators import integrate_increments
from wmrkit.odometry.logs import JointLog
from wmrkit.odometry.model import odometry_model
from wmrkit.odometry.pipeline import odometry, run_odometry
from wmrkit.odometry.trajectories import Trajectory

from ._harness import Result, best_time, forklift_log, peer


def _diff_log(n: int) -> JointLog:
    rng = np.random.default_rng(0)
    t = np.arange(n) * 1e-3  # 1 kHz
    rates = np.column_stack([10 + np.sin(t * 0.3), 10 + np.cos(t * 0.2)]) * 1e-3  # rad per sample, turning
    pos = np.cumsum(rates + rng.normal(0, 1e-5, size=(n, 2)), axis=0)
    return JointLog(t, ("left.spin", "right.spin"), pos)


def _wpimath_diff_loop(log: JointLog, headings: np.ndarray, m: int) -> float:
    kin, geo = peer("wpimath.kinematics"), peer("wpimath.geometry")
    d = (log.positions[:m] * 0.075).tolist()
    th = headings[:m].tolist()
    rot = geo.Rotation2d

    def loop():
        odo = kin.DifferentialDriveOdometry(rot(0.0), d[0][0], d[0][1])
        update = odo.update
        for a, (left, right) in zip(th, d, strict=True):
            update(rot(a), left, right)

    return best_time(loop, repeat=3)


def _verdict(n: int, ours_s: float, peer_s: float | None, quick: bool) -> str:
    """The issue's target and whether this run meets it."""
    rate_ok = n / ours_s >= 10e6
    if peer_s is None:
        verdict = "ratio NOT MEASURED (peer absent)"
    else:
        verdict = "MET" if rate_ok and peer_s / ours_s >= 50 else "NOT MET"
    return f">= 10 M/s, >= 50x: {verdict}" + (" (quick run: 1e6 samples, the target is for 1e7)" if quick else "")


def _wpimath_mecanum_loop(positions: np.ndarray, headings: np.ndarray, robot, m: int) -> float:
    kin, geo = peer("wpimath.kinematics"), peer("wpimath.geometry")
    names = ("front_left", "front_right", "rear_left", "rear_right")
    k = kin.MecanumDriveKinematics(*[geo.Translation2d(*robot.wheel(n).position) for n in names])
    rows = (positions[:m] * 0.0762).tolist()
    th = headings[:m].tolist()
    rot, wp = geo.Rotation2d, kin.MecanumDriveWheelPositions

    def loop():
        odo = kin.MecanumDriveOdometry(k, rot(0.0), wp())
        for a, r in zip(th, rows, strict=True):
            p = wp()
            p.frontLeft, p.frontRight, p.rearLeft, p.rearRight = r
            odo.update(rot(a), p)

    return best_time(loop, repeat=2)


def run(quick: bool) -> list[Result]:
    """Time wmrkit's odometry against peer loops; ``quick`` uses 1e6 samples instead of 1e7."""
    n = 1_000_000 if quick else 10_000_000
    m = 50_000 if quick else 200_000  # samples of the slow peer loops, scaled to n
    has_wpimath = peer("wpimath.kinematics") is not None
    results = []

    diff = catalog.load("diff-drive")
    model = odometry_model(diff)
    log = _diff_log(n)
    traj = odometry(model, log)  # the first call compiles the kernels (or loads them from the cache)
    chunk = 1 << 16  # odometry()'s default
    buffer = Trajectory(log.time, np.empty((n, 3)), np.zeros(n))  # a trajectory the caller owns and reuses
    into = best_time(lambda: run_odometry(model, (log.slice(i, i + chunk) for i in range(0, n, chunk)),
                                          out=buffer), repeat=3)
    fresh = best_time(lambda: odometry(model, log), repeat=3)
    peer_s = _wpimath_diff_loop(log, traj.poses[:, 2], m) * n / m if has_wpimath else None
    peer_name = f"wpimath DifferentialDriveOdometry.update loop (x{n // m} of {m:,})"
    results.append(Result("odometry exact: diff-drive wheel-angle log -> poses", n, into, peer_name, peer_s,
                          _verdict(n, into, peer_s, quick)))
    results.append(Result("  same, poses as new arrays (odometry())", n, fresh, peer_name, peer_s))

    inc = model.from_positions(log.positions).increments_robot
    ours = best_time(lambda: integrate_increments([0.0, 0.0, 0.0], inc, "exact"), repeat=3)
    results.append(Result("integrate_increments exact (kernel only)", n - 1, ours, peer_name, peer_s))

    mec = catalog.load("mecanum-4")
    nm = n // 4
    rng = np.random.default_rng(1)
    pos = np.cumsum(rng.normal(0.01, 0.002, size=(nm, 4)), axis=0)
    mlog = JointLog(np.arange(nm) * 1e-3, odometry_model(mec).joints, pos)
    mtraj = odometry(mec, mlog)
    ours = best_time(lambda: odometry(mec, mlog), repeat=3)
    peer_s = _wpimath_mecanum_loop(pos, mtraj.poses[:, 2], mec, m // 2) * nm / (m // 2) if has_wpimath else None
    results.append(Result("odometry exact: mecanum-4 (4 spins, slip residual)", nm, ours,
                          "wpimath MecanumDriveOdometry.update loop (scaled)", peer_s))

    fork = catalog.load("forklift")
    nf = n // 10
    flog = forklift_log(nf)
    ours = best_time(lambda: odometry(fork, flog), repeat=3)
    results.append(Result("odometry exact: forklift, quantised steering", nf, ours, "none (no tricycle peer)", None))

    nc = n // 10
    sub = inc[:nc]
    poses = np.vstack([[0.0, 0.0, 0.0], integrate_increments([0.0, 0.0, 0.0], sub, "exact")])
    q = CrowleyNoise().increment_covariance(sub)
    ours = best_time(lambda: propagate_covariance(poses, sub, q, "exact"), repeat=3)
    mc = min(nc, m // 4)

    def recursion():
        p = np.zeros((3, 3))
        for k in range(mc):
            f, g = step_jacobians(poses[k], sub[k], "exact")
            p = f @ p @ f.T + g @ q[k] @ g.T

    results.append(Result("covariance propagation (closed form, prefix sums)", nc, ours,
                          f"per-sample EKF recursion in numpy (x{nc // mc} of {mc:,})",
                          best_time(recursion, repeat=1) * nc / mc))
    return results
