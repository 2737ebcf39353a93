"""A differential drivetrain around the dynamic model: one traction motor through an open differential.

The thesis's forklift (§8.6.3) has one traction motor acting on the mechanical differential of the fixed wheels and
a steering motor on the orientable wheel, each with its own low-level speed / position loop. An open differential
gives both wheels the same torque and leaves their speed difference free, so the wheels slip as the tyres and the
loads dictate (unlike per-wheel rate servos, which impose each wheel's rolling speed). Here the motor's speed loop
is a discrete PI on the carrier rate (the mean of the coupled spins, the robot's ``differential`` coupling),
sampled every ``control_period``, its torque split equally (``tau / n`` per wheel) and saturated; the steering
follows the program's heading reference through the simulator's PD servo.

Co-simulation: the dynamics' :class:`~wmrkit.dynamics.simulate.Stepper` is advanced one control period at a time
from the full state it reached (tyre slip carries over), the motor torque updated between periods.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from .._shapes import real_number
from ..errors import ShapeError, WmrkitError


@dataclass(frozen=True, slots=True)
class TractionLoop:
    """PI speed loop of a traction motor on a differential carrier: ``kp`` [N m s/rad], ``ki`` [N m/rad] on the
    carrier rate error, total torque saturated at ``torque_limit`` [N m], sampled every ``control_period`` [s]."""

    kp: float
    ki: float
    torque_limit: float
    control_period: float = 0.01

    @classmethod
    def tuned(cls, inertia: float, settling: float, overshoot: float, torque_limit: float,
              control_period: float = 0.01) -> TractionLoop:
        """Gains placing the poles of ``inertia * rate' = tau`` under PI at the damping of `overshoot` (second-order
        rule ``zeta = -ln(os) / sqrt(pi^2 + ln(os)^2)``) and the 2 % `settling` time ``4 / (zeta wn)``."""
        if not (all(real_number(v) for v in (inertia, settling, overshoot, torque_limit)) and inertia > 0
                and settling > 0 and 0 < overshoot < 1 and torque_limit > 0):  # text raised "'>' not supported"
            raise ShapeError("traction loop: inertia, settling and torque limit > 0, 0 < overshoot < 1")
        lo = math.log(overshoot)
        zeta = -lo / math.sqrt(math.pi ** 2 + lo * lo)
        wn = 4.0 / (zeta * settling)
        return cls(2 * zeta * wn * inertia, wn * wn * inertia, torque_limit, control_period)


def carrier_inertia(model) -> float:
    """The inertia [kg m^2] the differential carrier drives, reflected to the wheel rate: ``M r^2`` of the whole
    vehicle plus the spin inertias of every wheel (all rolling at the same speed on a straight line)."""
    robot = model.robot
    r = np.mean([robot.wheel(j.partition(".")[0]).r for j in differential_joints(robot)])
    mass = robot.body.mass + sum(w.mass for w in robot.wheels)
    return float(mass * r * r + sum(w.spin_inertia * (r / w.r) ** 2 for w in robot.wheels))


def differential_joints(robot) -> tuple[str, ...]:
    """The joints of the robot's (first) ``differential`` coupling."""
    for c in robot.couplings:
        if c.kind == "differential":
            return c.joints
    raise WmrkitError(f"robot '{robot.name}' has no differential coupling (couplings: kind differential)")


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class DriveRun:
    """Samples of a run every record step: ``t (N,)`` [s], ``pose (N, 3)`` world, ``twist (N, 3)`` robot frame,
    ``joint_positions``, ``joint_rates (N, n - 3)`` over ``joint_names``, ``carrier_torque (N,)`` [N m] (the
    motor's total torque over the next control period)."""

    joint_names: tuple[str, ...]
    t: np.ndarray
    pose: np.ndarray
    twist: np.ndarray
    joint_positions: np.ndarray
    joint_rates: np.ndarray
    carrier_torque: np.ndarray


def simulate_differential(model, inputs, duration: float, loop: TractionLoop, *, step: float = 1e-3,
                          record_step: float = 0.05) -> DriveRun:
    """Simulate `model` (a :class:`~wmrkit.dynamics.model.DynamicModel`) driven through its differential.

    `inputs` (:class:`~wmrkit.dynamics.simulate.Inputs`, e.g. a :func:`~wmrkit.dynamics.programs.path_program`):
    its steering references and servo gains are used (held over each control period); the mean of its rate
    references of the coupled spins is the carrier reference; the per-wheel rate servos of those spins are replaced
    by the loop's equal torques. `record_step` must be a multiple of the control period.
    """
    from ..dynamics.simulate import Stepper

    joints = differential_joints(model.robot)
    cols = np.array([model.names.index(j) for j in joints])
    gain = np.array(inputs.rate_gain, dtype=float)
    gain[cols] = 0.0
    tk = np.asarray(inputs.time, dtype=float)
    reference = np.mean(np.asarray(inputs.rate_reference)[:, cols], axis=1)
    rate_ref, torque = np.asarray(inputs.rate_reference, dtype=float), np.asarray(inputs.torques, dtype=float)
    headings = np.asarray(inputs.heading_reference, dtype=float)
    period = loop.control_period
    per, every = round(duration / period), round(record_step / period)
    if per < 1 or every < 1 or abs(every * period - record_step) > 1e-9 * record_step:
        raise ShapeError("the duration and the record step must be multiples of the control period")
    stepper = Stepper(model, step=step)
    s, n = stepper.state, model.n
    rows, integral = [], 0.0
    for k in range(per + 1):
        t = k * period
        error = float(np.interp(t, tk, reference)) - float(np.mean(s[n + cols]))
        tau = loop.kp * error + loop.ki * integral
        if abs(tau) < loop.torque_limit:  # anti-windup: integrate only while not saturated
            integral += error * period
        tau = float(np.clip(tau, -loop.torque_limit, loop.torque_limit))
        if k % every == 0:
            rows.append(np.concatenate([[t, tau], s]))
        if k == per:
            break
        tau_row = _at(torque, tk, t)
        tau_row[cols] = tau / len(cols)
        stepper.advance(replace(inputs, time=np.array([t]), torques=tau_row[None], rate_gain=gain,
                                rate_reference=_at(rate_ref, tk, t)[None],
                                heading_reference=_at(headings, tk, t)[None]), period)
    r = np.array(rows)
    return DriveRun(tuple(model.names[3:]), r[:, 0], r[:, 2:5], r[:, 2 + n:5 + n], r[:, 5:2 + n], r[:, 5 + n:],
                    r[:, 1])


def _at(values: np.ndarray, tk: np.ndarray, t: float) -> np.ndarray:
    """Rows ``(K, m)`` of input knots interpolated at `t` (held outside), ``(m,)``."""
    return np.array([np.interp(t, tk, c) for c in values.T], dtype=float)
