"""No-slip kinematic models (thesis ch. 4) and per-wheel inverse kinematics (§8.4).

Listed by hand (no star imports); see ``docs/kinematics.md`` and ``docs/wheel-ik.md``.
"""

from .actuation import ActuationAnalysis, actuation_analysis, minimal_actuator_sets
from .extended import (
    ExtendedSolution,
    GearWarning,
    extended_dof,
    extended_solution,
    no_slip_extended_solution,
    solve_steering,
)
from .linalg import delta_projector, matrix_rank, solve_assigned
from .models import (
    KinematicModel,
    assignable_sets,
    direct_model,
    generically_assignable_sets,
    inverse_model,
    is_assignable,
    kinematic_model,
    mobility,
)
from .sensing import SensingAnalysis, minimal_sensor_sets, sensing_analysis
from .wheel_ik import WheelCommands, forward_kinematics, twist_is_determined, wheel_commands

__all__ = [
    "ActuationAnalysis",
    "ExtendedSolution",
    "GearWarning",
    "KinematicModel",
    "SensingAnalysis",
    "WheelCommands",
    "actuation_analysis",
    "assignable_sets",
    "delta_projector",
    "direct_model",
    "extended_dof",
    "extended_solution",
    "forward_kinematics",
    "generically_assignable_sets",
    "inverse_model",
    "is_assignable",
    "kinematic_model",
    "matrix_rank",
    "minimal_actuator_sets",
    "minimal_sensor_sets",
    "mobility",
    "no_slip_extended_solution",
    "sensing_analysis",
    "solve_assigned",
    "solve_steering",
    "twist_is_determined",
    "wheel_commands",
]
