"""Parallel parking (thesis §9.3): the geometric planner, problems as data, exact checks, execution, comparison.

``docs/parking.md`` shows the use; ``plan_parking(vehicle, space)`` is the one call.
"""

from .geometry import Space, Vehicle, blackburn_min_length, length_ratio
from .planner import Maneuver, ParkingPlan, plan_parking, shortest_slot

__all__ = ["Maneuver", "ParkingPlan", "Space", "Vehicle", "blackburn_min_length", "length_ratio", "plan_parking",
           "shortest_slot"]
