"""Kinematic control of any wheeled robot (thesis ch. 8): the three nested loops, position control, per-wheel IK in
the loop, feasible references (Table 8.1), the forklift, and the geometric trackers users use today.

Listed by hand (no star imports); see ``docs/control.md``. The one call: :func:`track` -> :class:`TrackingRun`.
"""

from .actuators import ActuatorLoop, LowLevelLoops
from .dynamic_plant import simulate_dynamics
from .feasibility import COLUMNS, Feasibility, Requirement, Violation, feasibility, requirement
from .forklift import ForkliftIK, forklift_ik, forklift_real_loops, from_thesis_pose, with_steer_range
from .laws import GateWarning, PositionLaw, SamplingWarning, check_gate, check_sampling, law_velocity, sampled_root
from .loop import Plant, law_controller, simulate
from .plots import animate_run, plot_feasibility, plot_run
from .points import ControlError, ControlPoint, control_point, point_pose, twist_for_velocity
from .references import (
    BUILTIN,
    Reference,
    ReferenceError,
    builtin_reference,
    load_reference,
    reference_from_samples,
    resolve_reference,
)
from .slip_control import SLIP_MODELS, SlipCommander, SlipCommands, SlipInverse, slip_commands, slip_inverse
from .slip_loop import FEEDBACK, simulate_slip_control
from .steering import (
    POLICIES,
    SteeringChoice,
    ackermann_twist,
    choose_steering,
    crab_twist,
    discretize_twist,
    icr_twist,
    steer_ranges,
)
from .tick import ControlTick, control_tick
from .track import CONTROLLERS, TrackingRun, initial_pose_on, track
from .trackers import pure_pursuit, stanley

__all__ = [
    "BUILTIN",
    "COLUMNS",
    "CONTROLLERS",
    "FEEDBACK",
    "POLICIES",
    "SLIP_MODELS",
    "ActuatorLoop",
    "ControlError",
    "ControlPoint",
    "ControlTick",
    "Feasibility",
    "ForkliftIK",
    "GateWarning",
    "LowLevelLoops",
    "Plant",
    "PositionLaw",
    "Reference",
    "ReferenceError",
    "Requirement",
    "SamplingWarning",
    "SlipCommander",
    "SlipCommands",
    "SlipInverse",
    "SteeringChoice",
    "TrackingRun",
    "Violation",
    "ackermann_twist",
    "animate_run",
    "builtin_reference",
    "check_gate",
    "check_sampling",
    "choose_steering",
    "control_point",
    "control_tick",
    "crab_twist",
    "discretize_twist",
    "feasibility",
    "forklift_ik",
    "forklift_real_loops",
    "from_thesis_pose",
    "icr_twist",
    "initial_pose_on",
    "law_controller",
    "law_velocity",
    "load_reference",
    "plot_feasibility",
    "plot_run",
    "point_pose",
    "pure_pursuit",
    "reference_from_samples",
    "requirement",
    "resolve_reference",
    "sampled_root",
    "simulate",
    "simulate_dynamics",
    "simulate_slip_control",
    "slip_commands",
    "slip_inverse",
    "stanley",
    "steer_ranges",
    "track",
    "twist_for_velocity",
    "with_steer_range",
]
