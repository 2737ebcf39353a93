"""Odometry for any wheeled robot (papers 002 and 003, thesis (3.15) and ch. 7): encoders to trajectory.

One module per concept: :mod:`.encoders` (counts to radians), :mod:`.model` (the sensed direct model over samples,
(4.11)), :mod:`.integrators` (exact SE(2), RK2, Euler, 002 (15)), :mod:`.covariance` (003 (17), propagation),
:mod:`.calibration`, :mod:`.logs` (CSV), :mod:`.steering` (headings in files, β inside), :mod:`.trajectories`
(CSV, TUM), :mod:`.bags` (ROS 2), :mod:`.bag_imu` and :mod:`.imu_mount` (a bag's IMU, its mounting),
:mod:`.pipeline` (streaming), :mod:`.files` (what the CLI calls), :mod:`.diagnostics` (the warnings after a run over a
log),
:mod:`.synthetic` (test data). See ``docs/odometry.md``.
"""

from .calibration import Calibration, CalibrationRun, apply_parameters, calibrate, square_path_error
from .covariance import CrowleyNoise, JointNoise, propagate_covariance, step_jacobians
from .encoders import CATALOG_ENCODERS, AbsoluteEncoder, EncoderError, IncrementalEncoder, catalog_encoders
from .files import odometry_file
from .integrators import (
    METHODS,
    integrate_euler,
    integrate_exact,
    integrate_increments,
    integrate_paper002,
    integrate_rk2,
    step,
)
from .logs import JointLog, LogError, LogFormat, load_csv, read_csv, write_log
from .model import ModelIncrements, OdometryModel, SensingError, odometry_model
from .pipeline import OdometrySummary, odometry, run_odometry
from .steering import SteeringError
from .synthetic import Slip, SyntheticRun, TwistProfile, simulate, square_path
from .trajectories import Trajectory, TrajectoryWriter, read_tum, write_trajectory

__all__ = [
    "CATALOG_ENCODERS",
    "METHODS",
    "AbsoluteEncoder",
    "Calibration",
    "CalibrationRun",
    "CrowleyNoise",
    "EncoderError",
    "IncrementalEncoder",
    "JointLog",
    "JointNoise",
    "LogError",
    "LogFormat",
    "ModelIncrements",
    "OdometryModel",
    "OdometrySummary",
    "SensingError",
    "Slip",
    "SteeringError",
    "SyntheticRun",
    "Trajectory",
    "TrajectoryWriter",
    "TwistProfile",
    "apply_parameters",
    "calibrate",
    "catalog_encoders",
    "integrate_euler",
    "integrate_exact",
    "integrate_increments",
    "integrate_paper002",
    "integrate_rk2",
    "load_csv",
    "odometry",
    "odometry_file",
    "odometry_model",
    "propagate_covariance",
    "read_csv",
    "read_tum",
    "run_odometry",
    "simulate",
    "square_path",
    "square_path_error",
    "step",
    "step_jacobians",
    "write_log",
    "write_trajectory",
]
