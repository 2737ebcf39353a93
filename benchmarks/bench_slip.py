"""Slip-aware odometry cost per sample, same run (issue 10): WLS against plain differential odometry (thesis (7.79),
the forklift's drive wheels alone), FK2 against WLS.

Targets: WLS at most 2x differential odometry per sample in batch (the thesis reports 57x, Table 7.3), FK2 at most
1.2x WLS (thesis: 55 / 46 ns). All three turn the same forklift log (two drive-wheel spins and a steering angle
quantised to the 1.4118 deg encoder) into poses with the exact scheme, through the library's batch entry points
(``odometry()`` and ``kalman_odometry()``). Times are the best of 3 calls after a first one that compiles.
"""

from __future__ import annotations

import numpy as np

from wmrkit import catalog
from wmrkit.odometry.logs import JointLog
from wmrkit.odometry.model import odometry_model
from wmrkit.odometry.pipeline import odometry
from wmrkit.slip.kalman import fk2_noise, kalman_model, kalman_odometry
from wmrkit.slip.weights import SlipWeights, wls_model

from ._harness import Result, best_time


def forklift_log(n: int) -> JointLog:
    """A forklift log at 1 kHz: drive spins with noise, steering quantised to 1.4118 deg."""
    fork = catalog.load("forklift")
    rng = np.random.default_rng(2)
    steer = np.radians(90 + 1.4118 * np.round(np.cumsum(rng.normal(0, 0.05, n)) % 60 - 30))
    pos = np.column_stack([np.cumsum(rng.normal(0.01, 0.001, size=(n, 2)), axis=0), steer])
    return JointLog(np.arange(n) * 1e-3, odometry_model(fork).joints, pos)


def run(quick: bool) -> list[Result]:
    n = 200_000 if quick else 2_000_000
    fork = catalog.load("forklift")
    log = forklift_log(n)
    differential = odometry_model(fork, ("right_drive.spin", "left_drive.spin"))
    wls = wls_model(fork, SlipWeights.of({"right_drive": (1.0, 3.2e-3), "left_drive": (1.0, 3.2e-3),
                                          "steer": (19.2, 1.0)}))
    fk2 = kalman_model(fork, "fk2", fk2_noise(0.28, 3.57, 0.28))
    dlog = log.select(differential.joints)
    for f in (lambda: odometry(differential, dlog), lambda: odometry(wls, log), lambda: kalman_odometry(fk2, log)):
        f()  # compile
    t_diff = best_time(lambda: odometry(differential, dlog))
    t_wls = best_time(lambda: odometry(wls, log))
    t_fk2 = best_time(lambda: kalman_odometry(fk2, log))
    return [
        Result("odometry wls: forklift (steering configurations)", n, t_wls,
               "differential odometry (7.79), same run", t_diff,
               f"wls <= 2x differential: {'MET' if t_wls <= 2 * t_diff else 'NOT MET'} "
               f"({t_wls / t_diff:.2f}x)"),
        Result("odometry fk2: forklift (information-form KF)", n, t_fk2, "wls, same run", t_wls,
               f"fk2 <= 1.2x wls: {'MET' if t_fk2 <= 1.2 * t_wls else 'NOT MET'} ({t_fk2 / t_wls:.2f}x)"),
    ]


if __name__ == "__main__":
    for r in run(quick=True):
        print(r.line())
