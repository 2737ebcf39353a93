"""wmrkit: kinematic modelling, analysis and odometry for any wheeled mobile robot.

Implements L. Gracia's thesis *Modelado Cinemático y Control de Robots Móviles con Ruedas* (UPV) and two
papers on odometric modelling. SI units, radians; robot frame x forward, y left, z up (REP-103); twists
``(vx, vy, omega)``.
"""

from . import catalog, kinematics
from .description import robot_from_dict, robot_to_dict
from .errors import DescriptionError, ShapeError, SingularError, UnknownNameError, WmrkitError
from .kinematics import (
    KinematicModel,
    WheelCommands,
    actuation_analysis,
    assignable_sets,
    direct_model,
    forward_kinematics,
    inverse_model,
    kinematic_model,
    mobility,
    sensing_analysis,
    wheel_commands,
)
from .robot import TWIST_NAMES, Robot
from .units import parse_quantity
from .wheels import (
    KINDS,
    Wheel,
    WheelKind,
    generic_slip_rows,
    generic_wheel_jacobian,
    wheel_jacobian,
    wheel_slip_rows,
)

__version__ = "0.1.0"


def __getattr__(name: str):
    """``wmrkit.analysis`` and ``wmrkit.odometry`` load on first use (they import scipy.optimize, numba)."""
    if name in ("analysis", "odometry", "plotting"):
        import importlib

        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module 'wmrkit' has no attribute '{name}'")

__all__ = [
    "KINDS",
    "TWIST_NAMES",
    "DescriptionError",
    "KinematicModel",
    "Robot",
    "ShapeError",
    "SingularError",
    "UnknownNameError",
    "Wheel",
    "WheelCommands",
    "WheelKind",
    "WmrkitError",
    "actuation_analysis",
    "assignable_sets",
    "catalog",
    "direct_model",
    "forward_kinematics",
    "generic_slip_rows",
    "generic_wheel_jacobian",
    "inverse_model",
    "kinematic_model",
    "kinematics",
    "mobility",
    "parse_quantity",
    "robot_from_dict",
    "robot_to_dict",
    "sensing_analysis",
    "wheel_commands",
    "wheel_jacobian",
    "wheel_slip_rows",
]
