"""Shared by the batch tests and importable by the cluster's workers (the cluster fixture puts this folder on
their PYTHONPATH): calibration parameters with their true values, and a task that kills its worker once."""

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


def write_log(path, run) -> str:
    """The run's log as a default-format CSV; the path as a string."""
    write_csv(path, ("time", *run.log.joints), np.column_stack([run.log.time, run.log.positions]))
    return str(path)
