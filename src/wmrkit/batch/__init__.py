"""Fleet-scale work on Dask: batch odometry, fleet calibration, Monte Carlo, design sweeps (``docs/batch.md``).

One module per concept: :mod:`.engine` (serial, embedded ``LocalCluster`` or a scheduler address: one API),
:mod:`.fleet` (odometry of many logs to a Parquet table, resumable), :mod:`.calibrate` (radii and track from many
runs, confidence intervals), :mod:`.montecarlo` (sampled sensor errors against 003's propagation),
:mod:`.sweep_kernel` and :mod:`.sweep` (metrics over products of description fields as chunked Dask arrays),
:mod:`.parquet` (tables written so that a batch resumes). Dask and pyarrow (the ``batch`` extra) are imported
only when used.
"""

from .calibrate import FleetCalibration, default_parameters, fleet_calibrate, load_runs
from .engine import BatchError, Engine, TaskFailure, engine
from .fleet import FleetResult, batch_odometry, expand_logs
from .montecarlo import MonteCarloResult, monte_carlo, path_log
from .sweep import SweepResult, sweep
from .sweep_kernel import METRICS, Axis, parse_vary

__all__ = [
    "METRICS",
    "Axis",
    "BatchError",
    "Engine",
    "FleetCalibration",
    "FleetResult",
    "MonteCarloResult",
    "SweepResult",
    "TaskFailure",
    "batch_odometry",
    "default_parameters",
    "engine",
    "expand_logs",
    "fleet_calibrate",
    "load_runs",
    "monte_carlo",
    "parse_vary",
    "path_log",
    "sweep",
]
