"""wmrkit: kinematic modelling, analysis and odometry for any wheeled mobile robot.

Implements L. Gracia's thesis *Modelado Cinemático y Control de Robots Móviles con Ruedas* (UPV) and two
papers on odometric modelling. SI units, radians; robot frame x forward, y left, z up (REP-103); twists
``(vx, vy, omega)``.
"""

from . import catalog
from .description import robot_from_dict, robot_to_dict
from .errors import DescriptionError, ShapeError, SingularError, UnknownNameError, WmrkitError
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

__all__ = [
    "KINDS",
    "TWIST_NAMES",
    "DescriptionError",
    "Robot",
    "ShapeError",
    "SingularError",
    "UnknownNameError",
    "Wheel",
    "WheelKind",
    "WmrkitError",
    "catalog",
    "generic_slip_rows",
    "generic_wheel_jacobian",
    "parse_quantity",
    "robot_from_dict",
    "robot_to_dict",
    "wheel_jacobian",
    "wheel_slip_rows",
]
