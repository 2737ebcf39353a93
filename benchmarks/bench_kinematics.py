"""Kinematics benchmarks: batched per-wheel IK (thesis §8.4) against WPILib called once per twist, and the time of
one numeric model of an 8-wheel robot (constraint matrix (3.22) + least squares (4.11)).

The peer (robotpy-wpimath) is timed on a subset of the twists (its loop is Python, one call per twist) and its
per-twist time is scaled to the full count, so the printed ratio is per-twist throughput, ours / peer's.
"""

from __future__ import annotations

import numpy as np

from wmrkit import Robot
from wmrkit.kinematics.linalg import solve_assigned
from wmrkit.kinematics.wheel_ik import wheel_commands

from ._harness import Result, best_time, peer

CORNERS = [(0.25, 0.275), (0.25, -0.275), (-0.25, 0.275), (-0.25, -0.275)]  # fl, fr, rl, rr [m]
NAMES = ["front_left", "front_right", "rear_left", "rear_right"]
R = 0.0762

MECANUM = Robot.from_dict({"name": "mecanum-4", "wheels": [
    {"name": n, "type": "swedish", "position": list(p), "beta": "90 deg", "gamma": f"{g} deg", "r": R, "r_r": 0.0125}
    for n, p, g in zip(NAMES, CORNERS, (45, -45, -45, 45), strict=True)]})
SWERVE = Robot.from_dict({"name": "swerve-4", "wheels": [
    {"name": n, "type": "steerable", "position": list(p), "beta": "90 deg", "r": R}
    for n, p in zip(NAMES, CORNERS, strict=True)]})
#: Eight wheels, one of every type: the numeric-model timing robot.
EIGHT = Robot.from_dict({"name": "eight", "wheels": [
    {"name": "fix", "type": "fixed", "position": [0.3, 0.25], "beta": 1.4, "r": 0.1},
    {"name": "ste", "type": "steerable", "position": [0.4, -0.2], "beta": 0.3, "r": 0.12},
    {"name": "cas", "type": "castor", "position": [-0.3, 0.2], "beta": 2.0, "d": 0.05, "r": 0.04},
    {"name": "swe", "type": "swedish", "position": [-0.35, -0.25], "beta": 1.2, "gamma": 0.7, "r": 0.07,
     "r_r": 0.015},
    {"name": "dbl", "type": "double", "position": [0.1, 0.4], "beta": -0.5, "b": 0.06, "r": 0.05},
    {"name": "dca", "type": "double_castor", "position": [0.0, -0.4], "beta": 0.9, "d": 0.07, "b": 0.05,
     "r": 0.045},
    {"name": "bal", "type": "ball", "position": [0.5, 0.0], "beta": 0.2, "r": 0.03},
    {"name": "ort", "type": "orthogonal", "position": [-0.5, 0.05], "beta": -1.0, "r": 0.06},
]})


def run(quick: bool) -> list[Result]:
    """Mecanum-4 and swerve-4 IK on 1e6 twists (1e5 quick) vs wpimath per twist; 8-wheel model time."""
    n, n_peer = (100_000, 5_000) if quick else (1_000_000, 50_000)
    twists = np.random.default_rng(0).normal(size=(n, 3))
    kin, geo = peer("wpimath.kinematics"), peer("wpimath.geometry")
    results = []

    ours = best_time(lambda: wheel_commands(MECANUM, twists), repeat=7)
    peer_s = None
    if kin is not None:
        mk = kin.MecanumDriveKinematics(*(geo.Translation2d(*p) for p in CORNERS))
        rows = twists[:n_peer].tolist()

        def mecanum_loop() -> None:
            for vx, vy, w in rows:
                mk.toWheelSpeeds(kin.ChassisSpeeds(vx, vy, w))

        peer_s = best_time(mecanum_loop) * n / n_peer
    results.append(Result("mecanum-4 IK, batched (peer: per twist)", n, ours,
                          "wpimath MecanumDriveKinematics.toWheelSpeeds", peer_s, ">= 10 M/s, >= 50x"))

    ours = best_time(lambda: wheel_commands(SWERVE, twists), repeat=7)
    peer_s = None
    if kin is not None:
        sk = kin.SwerveDrive4Kinematics(*(geo.Translation2d(*p) for p in CORNERS))
        current = [geo.Rotation2d(0.0)] * 4  # ours: beta = 90 deg, the same wheel direction (module angle 0)
        rows = twists[:n_peer].tolist()

        def swerve_loop() -> None:
            for vx, vy, w in rows:
                for state, angle in zip(sk.toSwerveModuleStates(kin.ChassisSpeeds(vx, vy, w)), current, strict=True):
                    state.optimize(angle)

        peer_s = best_time(swerve_loop) * n / n_peer
    results.append(Result("swerve-4 IK + closest angle, batched", n, ours,
                          "wpimath toSwerveModuleStates + optimize", peer_s, ">= 50x"))

    one = twists[0]
    calls = 2_000
    ours = best_time(lambda: [wheel_commands(SWERVE, one) for _ in range(calls)])
    peer_s = None
    if kin is not None:
        vx, vy, w = one.tolist()
        peer_s = best_time(lambda: [[s.optimize(a) for s, a in zip(
            sk.toSwerveModuleStates(kin.ChassisSpeeds(vx, vy, w)), current, strict=True)] for _ in range(calls)])
    results.append(Result("swerve-4 IK, one twist per call (latency)", calls, ours,
                          "wpimath toSwerveModuleStates + optimize", peer_s, "information: Python call overhead"))

    beta = EIGHT.beta + 0.1
    twist = [0.3, -0.2, 0.5]

    def model() -> None:
        solve_assigned(EIGHT.constraint_matrix(beta), [0, 1, 2], twist)

    calls = 2_000
    total = best_time(lambda: [model() for _ in range(calls)])
    results.append(Result(f"8-wheel model: A(beta) + LS, {total / calls * 1e6:.1f} us each", calls, total,
                          "none (target only)", None, "< 100 us per model"))
    return results

