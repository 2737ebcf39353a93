"""Every function that takes a steering configuration takes it as ``heading=`` (the users' angle: 0 = rolling
forward) as well as ``beta=`` (the thesis's), with the same result (``Robot.steering``'s promise). Before, about
twenty public functions took ``beta`` only: a heading passed there was read as the thesis's axle angle, 90 deg
off, without a word."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from wmrkit import analysis, catalog, kinematics, slip
from wmrkit.control.slip_control import slip_commands, slip_inverse
from wmrkit.kinematics.extended import extended_solution, no_slip_extended_solution, solve_steering
from wmrkit.kinematics.wheel_ik import twist_is_determined


def _beta(s: dict) -> tuple:
    """The positional `beta` of the functions that take it so (None: from `heading`), out of the keywords."""
    return (s.pop("beta", None),)


ROBOT = catalog.load("thesis-steer-castor")  # a steered wheel and two castors: everything depends on the steering
HEADING = np.array([0.3, 0.5, -0.4])
SPINS = ("o1.spin", "c2.spin")
FORK = catalog.load("forklift")  # mass properties and tyres, for the slip models
FORK_HEADING = np.array([0.3])
FORK_SPINS = ("right_drive.spin", "left_drive.spin")
FRICTION = slip.tyre_friction(FORK)

#: name -> (robot, heading, call): each call's result depends on the steering
CALLS = {
    "actuation_analysis": (ROBOT, HEADING, lambda **s: kinematics.actuation_analysis(ROBOT, **s).inverse_matrix),
    "sensing_analysis": (ROBOT, HEADING, lambda **s: kinematics.sensing_analysis(ROBOT, **s).direct_matrix),
    "assignable_sets": (ROBOT, HEADING, lambda **s: kinematics.assignable_sets(ROBOT, **s)),
    "is_assignable": (ROBOT, HEADING, lambda **s: kinematics.is_assignable(ROBOT, SPINS, **s)),
    "minimal_actuator_sets": (ROBOT, HEADING, lambda **s: kinematics.minimal_actuator_sets(ROBOT, **s)),
    "minimal_sensor_sets": (ROBOT, HEADING, lambda **s: kinematics.minimal_sensor_sets(ROBOT, **s)),
    "twist_is_determined": (ROBOT, HEADING, lambda **s: twist_is_determined(ROBOT, list(SPINS), **s)),
    "extended_solution": (ROBOT, HEADING, lambda **s: extended_solution(ROBOT, SPINS, [10.0, 11.0], **s).q_dot),
    # the guess: the castors' angles are kept, the steered wheel's root is the one closest to it
    "solve_steering": (ROBOT, HEADING, lambda **s: solve_steering(ROBOT, ("vx", *SPINS), [0.2, 10.0, 11.0],
                                                                  *_beta(s), **s)),
    "no_slip_extended_solution": (ROBOT, HEADING, lambda **s: no_slip_extended_solution(
        ROBOT, ("vx", *SPINS), [0.2, 10.0, 11.0], *_beta(s), **s).q_dot),
    "condition_map": (ROBOT, HEADING, lambda **s: analysis.condition_map(ROBOT, **s)),
    "icr_points": (ROBOT, HEADING, lambda **s: analysis.icr_points(ROBOT, **s)),
    "instantaneous_mobility": (ROBOT, HEADING, lambda **s: analysis.instantaneous_mobility(ROBOT, **s)),
    "is_singular": (ROBOT, HEADING, lambda **s: analysis.is_singular(ROBOT, *_beta(s), SPINS, **s)),
    "is_singular_rank": (ROBOT, HEADING, lambda **s: analysis.is_singular_rank(ROBOT, *_beta(s), SPINS, **s)),
    "singularity_distance": (ROBOT, HEADING, lambda **s: analysis.singularity_distance(ROBOT, *_beta(s), SPINS, **s)),
    "isotropy_matrix": (ROBOT, HEADING,
                        lambda **s: analysis.isotropy_matrix(ROBOT, *_beta(s), ("vx", "vy"), SPINS, **s)),
    "isotropy_length": (ROBOT, HEADING,
                        lambda **s: analysis.isotropy_length(ROBOT, *_beta(s), ("vx", "omega"), SPINS, **s)),
    "natural_length": (ROBOT, HEADING, lambda **s: analysis.natural_length(ROBOT, **s)),
    "wls": (FORK, FORK_HEADING, lambda **s: slip.wls(FORK, FORK_SPINS, [10.0, 11.0], **s).q_dot),
    "mcd": (FORK, FORK_HEADING, lambda **s: slip.mcd(FORK, FORK_SPINS, [10.0, 11.0], FRICTION, **s).q_dot),
    "mqe": (FORK, FORK_HEADING, lambda **s: slip.mqe(FORK, FORK_SPINS, [10.0, 11.0], FRICTION, **s).q_dot),
    "normal_loads": (ROBOT, HEADING,  # the forklift's body over the contacts' centroid: all wheels stay down
                     lambda **s: slip.normal_loads(ROBOT, replace(FORK.body, com=(0.0, -0.29)), (0.5, 0.2), **s)),
    "slip_commands": (FORK, FORK_HEADING,  # the steering is where the search starts: the same commands
                      lambda **s: slip_commands(slip_inverse(FORK, "mcd"), [1.0, 0.0, 0.1], **s).rates),
}
#: Answers that are the same at almost every configuration (sets, yes/no, a mobility), and the slip inverse,
#: whose steering is only where its search starts: checked for heading = beta only.
INDEPENDENT = {"slip_commands", "assignable_sets", "is_assignable", "minimal_actuator_sets", "minimal_sensor_sets",
               "twist_is_determined", "instantaneous_mobility", "is_singular", "is_singular_rank"}


def _same(a, b) -> bool:
    if isinstance(a, tuple) and not isinstance(a, np.ndarray):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return bool(np.allclose(np.asarray(a, dtype=float), np.asarray(b, dtype=float), rtol=1e-12, atol=1e-12,
                            equal_nan=True)) if np.asarray(a).dtype.kind in "fiub" else a == b


@pytest.mark.parametrize("name", list(CALLS))
def test_heading_and_beta_give_the_same_result(name):
    robot, heading, call = CALLS[name]
    beta = robot.beta_of_heading(heading)
    by_heading, by_beta = call(heading=heading), call(beta=beta)
    assert _same(by_heading, by_beta)
    if name not in INDEPENDENT:
        assert not _same(call(beta=heading), by_beta), "the heading read as beta must change the result"
    with pytest.raises(Exception, match="not both"):
        call(heading=heading, beta=beta)
