"""Which singular configurations of a coordinated robot its held ``linkage`` couplings cannot set (``analyze``).

The coordinated singular sets (:mod:`.coordinated`) search every steering with all axles through one ICR, the
thesis's admissible configurations, the wheels steered one by one. A held linkage sets its wheels' angles from one
(:mod:`wmrkit.kinematics.linkage_law`): a synchro drive's ``parallel`` chain keeps the ICR at infinity, so a singular
ICR at a point is one it never reaches. Each configuration is judged as ``ik`` judges its angles for a twist
(:func:`wmrkit.kinematics.linkage_check.linkage_holds`) with a unit twist about the configuration's ICR; the thesis's
sets are kept, the report says which of them the robot cannot reach.
"""

from __future__ import annotations

import numpy as np

from ..couplings import linkage_law
from ..kinematics.linkage_check import _plan, _speeds, linkage_holds
from ..kinematics.wheel_ik import SLIP_TOL
from ..robot import Robot
from .icr import icr, twist_of_icr
from .singularity import SingularSet


def unreachable(robot: Robot, s: SingularSet) -> tuple[np.ndarray, tuple[str, ...]]:
    """``(n,)`` bool over ``s.configurations``: True where a held linkage cannot set that steering (judged at a unit
    twist about its ICR, as ``ik``; a configuration with no single ICR is not judged), and the linkages that break,
    each as ``"<channel> (law <law>)"``. Only coordinated sets over every steering angle are judged."""
    n = len(s.configurations)
    none = np.zeros(n, dtype=bool)
    plan = _plan(robot)
    if not n or not s.coordinated or not len(plan.lead) or s.variables != robot.steer_names:
        return none, ()
    out, broken = none.copy(), set()
    for i, beta in enumerate(np.asarray(s.configurations, dtype=float)):
        h = icr(robot, beta).homogeneous()
        if h is None:
            continue
        twist = twist_of_icr(h)
        speed = _speeds(plan, twist).max()  # the fastest steering axis at 1 m/s: the judge free of the robot's size
        holds = linkage_holds(robot, twist / speed if speed > 0 else twist, beta, SLIP_TOL)
        out[i] = not holds.all()
        broken.update(int(k) for k in np.flatnonzero(~holds))
    names = tuple(f"{robot.couplings[k].channel_name} (law {linkage_law(robot.couplings[k], robot.wheels)})"
                  for k in sorted(broken))
    return out, names


def unreachable_note(robot: Robot, s: SingularSet) -> str | None:
    """One line for the report under a singular set: how many of its configurations a held linkage cannot set, or
    None when it can set them all."""
    bad, names = unreachable(robot, s)
    if not bad.any():
        return None
    n, k = len(bad), int(bad.sum())
    which = "this singular configuration" if n == 1 else (
        f"{'every one' if k == n else k} of these {n} singular configurations")
    return (f"not reachable: {', '.join(names)} cannot set the steering of {which} (the thesis's coordinated "
            "steering turns each wheel on its own)")
