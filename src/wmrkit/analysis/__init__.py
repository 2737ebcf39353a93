"""Structural analysis of wheeled robots (thesis ch. 5-6): vehicle type, isotropy, singularity, ICR, report.

Listed by hand (no star imports): see ``docs/analysis.md`` for a guide.
"""

from .classification import Classification, SpecialConfiguration, classify, instantaneous_mobility
from .icr import ICRSet, icr, icr_of_twist, icr_points, steer_to_icr, twist_of_icr
from .isotropy import (
    condition_map,
    condition_number,
    default_joints,
    isotropy_length,
    isotropy_matrix,
    natural_length,
    twist_condition_number,
    twist_model,
)
from .lines import constraint_lines, line_residual, line_through
from .optimize import Conditioning, best_configurations, isotropic_configurations, optimize_geometry
from .singularity import SingularSet, is_singular, is_singular_rank, singular_set, singularity_distance
from .summary import Analysis, analyze

__all__ = [
    "Analysis",
    "Classification",
    "Conditioning",
    "ICRSet",
    "SingularSet",
    "SpecialConfiguration",
    "analyze",
    "best_configurations",
    "classify",
    "condition_map",
    "condition_number",
    "constraint_lines",
    "default_joints",
    "icr",
    "icr_of_twist",
    "icr_points",
    "instantaneous_mobility",
    "is_singular",
    "is_singular_rank",
    "isotropic_configurations",
    "isotropy_length",
    "isotropy_matrix",
    "line_residual",
    "line_through",
    "natural_length",
    "optimize_geometry",
    "singular_set",
    "singularity_distance",
    "steer_to_icr",
    "twist_condition_number",
    "twist_model",
    "twist_of_icr",
]
