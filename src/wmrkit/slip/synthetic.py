"""Synthetic logs with physical slip: wheel-speed segments driven through a slip model (test and documentation data).

Each segment holds the assigned wheel rates (and steering angles) constant; the quasi-static model (MQE, (7.41)-
(7.48), with the robot's tyres, mass and centre of mass) or the kinematic model with slip (MCD) gives the body
twist of uniform motion under those inputs, which is integrated exactly between samples. The encoders report the
commanded wheel angles. This is a *slip-injection model*, not the dynamic model (7.2): accelerations between
segments are instantaneous. It is what the skid-steer comparison of ``docs/slip.md`` uses until a simulator of
the dynamics is wired in.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import real_number
from ..errors import ShapeError, WmrkitError
from ..odometry.integrators import integrate_increments
from ..odometry.logs import JointLog
from ..odometry.synthetic import MAX_SAMPLES
from ..robot import Robot
from .models import mcd, mqe, normal_loads, tyre_friction


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class SlipRun:
    """A simulated run: ``log`` (the encoders), ``truth`` ``(N, 3)`` poses at the sample times, ``twists``
    ``(S, 3)`` the body twist of each segment."""

    log: JointLog
    truth: np.ndarray
    twists: np.ndarray


def wheel_speed_run(robot: Robot, segments: Sequence[tuple[float, Sequence[float]]], rate: float, *,
                    model: str = "mqe", beta: ArrayLike | None = None,
                    pose0: ArrayLike = (0.0, 0.0, 0.0)) -> SlipRun:
    """Drive `robot` with segments ``(duration [s], rates)``; `rates` [rad/s] of ``robot.sensed`` spin joints, in
    order. `model`: ``mqe`` (centripetal load transfer; needs ``body``) or ``mcd``; both use the described tyres.
    `beta`: the steering configuration (constant, default the described one)."""
    if model not in ("mqe", "mcd"):
        raise WmrkitError(f"model must be 'mqe' or 'mcd', got '{model}'")
    joints = tuple(j for j in robot.sensed if not j.endswith(".steer"))
    law = tyre_friction(robot)
    durations = np.array([float(d) for d, _ in segments])
    rates = np.array([list(r) for _, r in segments], dtype=float).reshape(len(segments), -1)
    if rates.shape[1] != len(joints) or not np.all((durations > 0) & np.isfinite(durations)) \
            or not np.isfinite(rates).all():
        raise ShapeError(f"segments: need finite durations > 0 and {len(joints)} finite rates each "
                          f"({', '.join(joints)})")
    if not (real_number(rate) and 1e-6 <= rate and durations.sum() * rate <= MAX_SAMPLES):  # NaN too: it failed in
        got = f"{rate:g}" if real_number(rate) else repr(rate)  # numpy, 1e9 Hz in memory; text: a TypeError
        raise ShapeError(f"rate {got} Hz over the segments' {durations.sum():g} s: need a rate >= 1e-06 Hz and "
                          f"at most {MAX_SAMPLES} sample periods")
    if model == "mqe":
        sol = mqe(robot, joints, rates, law, beta)
    else:
        sol = mcd(robot, joints, rates, law, beta, loads=normal_loads(robot, beta=beta))
    if not np.all(sol.converged):
        k = int(np.flatnonzero(~sol.converged)[0])
        raise WmrkitError(f"segment {k}: the {model.upper()} solve did not converge (residual {sol.residual[k]:.3g} N)")
    n = math.floor(durations.sum() * rate + 1e-9) + 1
    t = np.arange(n) / rate
    bounds = np.concatenate([[0.0], np.cumsum(durations)])
    seg = np.clip(np.searchsorted(bounds, 0.5 * (t[:-1] + t[1:]), side="right") - 1, 0, len(segments) - 1)
    # exact: split every interval at the segment boundaries inside it
    fine = np.union1d(t, bounds[(bounds > 0) & (bounds < t[-1])])
    fseg = np.clip(np.searchsorted(bounds, 0.5 * (fine[:-1] + fine[1:]), side="right") - 1, 0, len(segments) - 1)
    dt = np.diff(fine)
    poses = np.vstack([np.asarray(pose0, float)[None],
                       integrate_increments(pose0, sol.twist[fseg] * dt[:, None], "exact")])
    angles = np.vstack([np.zeros(len(joints)), np.cumsum(rates[fseg] * dt[:, None], axis=0)])
    at = np.searchsorted(fine, t)
    positions = angles[at]
    del seg
    if robot.steer_names:
        steer = [j for j in robot.sensed if j.endswith(".steer")]
        b = robot.beta if beta is None else np.asarray(beta, dtype=float)
        idx = [robot.steer_names.index(j.partition(".")[0]) for j in steer]
        positions = np.column_stack([positions, np.broadcast_to(b[idx], (n, len(idx)))])
        joints = (*joints, *steer)
    return SlipRun(JointLog(t, joints, positions, source="<slip-synthetic>"), poses[at], sol.twist)
