"""Shared by the batch tests and importable by the cluster's workers (the cluster fixture puts this folder on
their PYTHONPATH): calibration parameters with their true values, a task that kills its worker once and one
that raises."""

import os

import numpy as np

from wmrkit.batch.fleet import process_log
from wmrkit.odometry.logs import write_csv

PARAMS = ["left.r", "right.r", ("left.l", "right.l")]
TRUE_P = [0.01, -0.005, 0.02]


def die_once(args):
    """Odometry of a log; the task for run2 first kills its worker process (as a crash or an OOM kill would)."""
    job, marker = args
    if job.path.endswith("run2.csv") and not os.path.exists(marker):
        with open(marker, "w"):
            pass
        os._exit(1)
    return process_log(job)


def write_log(path, run, robot=None) -> str:
    """The run's log as a default-format CSV (steering columns as headings, what the reader takes: `robot` needed
    then); the path as a string."""
    steered = any(j.endswith(".steer") for j in run.log.joints)
    if steered and robot is None:
        raise ValueError("write_log: a log with steering columns needs the robot (its files hold headings)")
    positions = run.log.heading_positions(robot) if steered else run.log.positions
    write_csv(path, ("time", *run.log.joints), np.column_stack([run.log.time, positions]))
    return str(path)


def write_fleet(directory, runs) -> list[str]:
    """Each calibration run's log as ``directory/STEM.csv`` and its reference poses as ``directory/ref/STEM.tum``;
    the ``batch calibrate diff-drive`` arguments that read them (no worker processes)."""
    from wmrkit.odometry.trajectories import Trajectory, write_trajectory

    (directory / "ref").mkdir()
    for run in runs:
        stem = run.log.source.removesuffix(".csv")
        write_log(directory / f"{stem}.csv", run)
        at = run.samples()
        write_trajectory(directory / "ref" / f"{stem}.tum", Trajectory(run.log.time[at], np.asarray(run.reference),
                                                                       np.zeros(len(at)), None), "tum")
    return ["batch", "calibrate", "diff-drive", str(directory / "*.csv"), "--reference", str(directory / "ref"),
            "--workers", "0"]


def closed_fleet(diff, seed, odd=None, runs=6, noise=1e-5):
    """Closed squares of 1-2.5 m, both ways, encoder noise `noise` per rad, of a robot at radius ratio +1 % and track
    +3 %; run 0 of one at `odd` ``(ratio, track)`` instead."""
    from wmrkit.batch.calibrate import default_parameters
    from wmrkit.odometry.calibration import CalibrationRun, apply_parameters
    from wmrkit.odometry.synthetic import simulate, square_path

    params = default_parameters(diff, closed=True)
    rng = np.random.default_rng(seed)
    robots = [apply_parameters(diff, params, odd if k == 0 and odd else [0.01, 0.03]) for k in range(runs)]
    return params, [CalibrationRun.closed_path(simulate(r, square_path(rng.uniform(1.0, 2.5), clockwise=k % 2 == 1,
                                                                        pause=0.5), 10.0, spin_noise_per_rad=noise,
                                                        seed=int(rng.integers(1 << 30))).log)
                    for k, r in enumerate(robots)]


def refit_fails(args):
    """In place of batch.calibrate._refit_without: the refit of a closed fleet's other runs raises (an error)."""
    raise RuntimeError("injected refit failure")


def curvature_fails(args):
    """In place of batch.calibrate._curvature_of: the closed-path judge's Jacobian one step from the fit raises."""
    raise RuntimeError("injected curvature failure")


def no_own_noise(res, runs=None) -> str:
    """The not_judged note of a fleet whose runs (`runs`, else all of `res.logs`) are scored as closed paths: not
    checked as a whole (batch.whole.NO_OWN_NOISE)."""
    from wmrkit.batch.whole import NO_OWN_NOISE

    return NO_OWN_NOISE.format(runs=", ".join(res.logs if runs is None else runs))
