"""The kinematic loop through the chapter-7 dynamics with slip-model commands and slip-aware feedback.

Each control period: the position law's twist (:class:`~wmrkit.control.loop.TwistController`) becomes joint
commands, either by the no-slip per-wheel IK (§8.4, ``slip_model="none"``) or by the inverse slip model
(:mod:`.slip_control`, ``"mqe"`` or ``"mcd"``); the commands are held for the period by the dynamic model's servos
(rate servos on the actuated wheels, PD servos on the actuated steering: the gains of
:func:`wmrkit.dynamics.programs.twist_program`) while the Lagrange model with tyres is integrated from the full
state it reached. The controller measures the pose through one of :data:`FEEDBACK`:

- ``"pose"``: the true pose; ``"odometry"``: the no-slip least-squares odometry (4.11) of the sensed joints;
- ``"wls"``: weighted least squares (7.52) with friction coefficients ``weights``;
- ``"fk2"``: the Kalman filter FK2 (7.70) with ``noise``, its state carried from period to period;
- ``"mqe"``: the quasi-static slip model itself as odometry (§7.4.3 option 1 with the full nonlinear friction): the
  sensed rates and steering in, the MQE's twist out, one exact SE(2) step per period. Commands from a slip model
  make the wheels slip on purpose (a steered wheel turned by its slip angle), which a kinematic estimator reads as
  motion; the same model on both sides reads it right (``docs/slip-control.md``).

The estimators (:mod:`wmrkit.odometry`, :mod:`wmrkit.slip`) read the sensed joints' exact positions once per period.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from .._shapes import readonly
from ..kinematics.wheel_ik import WheelCommands
from ..robot import Robot, check_robot
from ..slip.kalman import KalmanNoise
from ..slip.weights import SlipWeights
from .dynamic_plant import rechecked, rolling_start
from .loop import TwistController, check_command
from .points import ControlError, check_delay
from .slip_control import SLIP_MODELS, SlipCommander, SlipInverse, _Forward, slip_inverse
from .steering import check_steering_driven, range_keeper

__all__ = ["FEEDBACK", "simulate_slip_control", "with_commanded_rates"]

#: How the controller measures the pose.
FEEDBACK = ("pose", "odometry", "wls", "fk2", "mqe")


def simulate_slip_control(robot: Robot, controller: TwistController, initial_pose: np.ndarray, duration: float, *,
                          period: float, delay: int = 0, tyre: str | None = None, step: float = 1e-3,
                          slip_model: str = "mqe", feedback: str = "pose", weights: SlipWeights | None = None,
                          noise: KalmanNoise | None = None, inverse: SlipInverse | None = None,
                          ramp: bool = False, progress: bool = False, policy: str = "closest",
                          until: Callable[[float, np.ndarray], bool] | None = None) -> dict:
    """Close the loop of `controller` on the dynamic model of `robot` with commands from `slip_model`.

    `period` [s] control period; `delay` measurement delay in samples; `tyre` the plant's traction model (default
    as described; the slip model uses the described tyres unless `inverse` says otherwise); `step` [s] the dynamics'
    integration step. `ramp`: each period's commands are reached linearly over the period from the previous ones
    (a first-order hold, half a period of delay) instead of held from its start (zero-order hold). `progress`: a
    tqdm bar over the periods. `policy`: which root of (8.9) each steered wheel takes (:mod:`.steering`).
    `until(t, pose)`: the run ends at the first control period whose sample holds it (a path follower that arrived).

    Returns arrays: ``t``, ``pose`` (true), ``twist`` (the law's), ``beta`` (actual steering), ``target``
    (commanded steering β), ``estimate`` (the fed-back pose), ``rates`` (commanded wheel rates of
    ``info["assigned"]``), ``predicted`` (the slip model's twist at the commands; the twist itself for ``"none"``),
    ``velocity`` (the true body twist), ``joint_rates`` (the actual rates of the assigned joints) and ``info``
    (dict: ``assigned``, ``failures``, ``worst_error`` [m/s] of the inverse, ``evaluations``). A stop is re-checked
    at a shorter step (:func:`.dynamic_plant.rechecked`).
    """
    check_robot(robot)
    return rechecked(lambda d, h, again: _slip_loop(
        robot, controller, initial_pose, d, period=period, delay=delay, tyre=tyre, step=h, slip_model=slip_model,
        feedback=feedback, weights=weights, noise=noise, inverse=inverse, ramp=ramp, progress=progress and not again,
        policy=policy, until=until), duration, step, period)


def _slip_loop(robot: Robot, controller: TwistController, initial_pose: np.ndarray, duration: float, *,
               period: float, delay: int, tyre: str | None, step: float, slip_model: str, feedback: str,
               weights: SlipWeights | None, noise: KalmanNoise | None, inverse: SlipInverse | None, ramp: bool,
               progress: bool, policy: str, until: Callable[[float, np.ndarray], bool] | None) -> dict:
    """The loop of :func:`simulate_slip_control`, not re-checked."""
    from ..dynamics.model import DynamicModel
    from ..dynamics.programs import twist_program
    from ..dynamics.simulate import Stepper
    from ..kinematics.wheel_ik import wheel_commands

    if not (math.isfinite(period) and period >= step > 0 and abs(period / step - round(period / step)) <= 1e-6):
        raise ControlError(f"period: expected a control period of a whole number of dynamics steps of {step} s, "
                           f"got {period}")  # 0.0015 s ran 2 ms of dynamics per 1.5 ms of the law's time
    if slip_model not in SLIP_MODELS:
        raise ControlError(f"slip model must be one of {', '.join(SLIP_MODELS)}, got '{slip_model}'")
    if feedback not in FEEDBACK:
        raise ControlError(f"feedback must be one of {', '.join(FEEDBACK)}, got '{feedback}'")
    check_delay(delay)
    check_steering_driven(robot)
    model = DynamicModel.of(robot, tyre)
    commander = None
    if slip_model != "none":
        commander = SlipCommander(inverse if inverse is not None else slip_inverse(robot, slip_model))
    assigned = commander.inverse.assigned if commander else tuple(j for j in robot.actuated
                                                                  if not j.endswith(".steer"))
    spin_cols = [robot.rate_names.index(j) for j in assigned]
    plant_cols = [model.names.index(j) for j in assigned]
    steer = list(model.steer_columns)
    template = twist_program(model, [0.0], np.zeros((1, 3)))  # the servos' gains and limits
    stepper = Stepper(model, rolling_start(model, controller, initial_pose), step=step, recheck=False)
    s = stepper.state
    sensor = _Sensor(robot, model, s, feedback, weights, noise)
    n = math.floor(duration / period + 1e-9) + 1
    history, integral = [s[:3].copy()], np.zeros(3)
    previous = None
    keys = ("t", "pose", "twist", "beta", "target", "estimate", "rates", "predicted", "velocity", "joint_rates",
            "in_range")
    held_in_range, all_rates = range_keeper(robot, policy), np.zeros(len(robot.rate_names))
    records: dict[str, list] = {k: [] for k in keys}
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=n, unit="period", desc="track", leave=False)
    for k in range(n):
        if bar is not None:
            bar.update(1)
        t = k * period
        twist, de = controller(t, history[max(0, k - delay)], integral)
        check_command(twist, t)
        integral = integral + period * de
        beta_now = s[steer].copy()
        if commander is None:
            ik = wheel_commands(robot, twist, beta_now)
            rates, target, predicted = np.nan_to_num(np.asarray(ik.rates)[spin_cols]), np.asarray(ik.beta), twist
        else:
            c = commander(twist, beta_now)
            rates, target, predicted = np.asarray(c.rates), np.asarray(c.beta), c.twist
        heading = np.asarray(robot.heading_of_beta(target), dtype=float).reshape(-1)
        wanted = heading.copy()
        all_rates[:] = 0.0
        all_rates[spin_cols] = rates
        current = np.asarray(robot.heading_of_beta(beta_now), dtype=float)
        in_range = held_in_range(heading, all_rates, current)  # the policy's root; beyond a steer_range, its end
        if not np.array_equal(heading, wanted):
            rates, target = all_rates[spin_cols], np.asarray(robot.beta_of_heading(heading), dtype=float).reshape(-1)
        values = (t, s[:3].copy(), np.asarray(twist, float), beta_now, target, history[-1].copy(), rates,
                  np.asarray(predicted, float), s[model.n:model.n + 3].copy(), s[[model.n + c for c in plant_cols]],
                  in_range)
        for key, value in zip(keys, values, strict=True):
            records[key].append(value)
        if k == n - 1 or (until is not None and until(t, records["pose"][-1])):
            break
        reference = np.zeros((1, model.n))
        reference[0, plant_cols] = rates
        heading = heading.reshape(1, -1)
        if ramp and previous is not None:  # from the previous commands to these over the period
            inputs = replace(template, time=np.array([stepper.t, stepper.t + period]),
                             torques=np.zeros((2, model.n)), rate_reference=np.vstack([previous[0], reference]),
                             heading_reference=np.vstack([previous[1], heading]))
        else:
            inputs = replace(template, time=np.array([stepper.t]), rate_reference=reference, heading_reference=heading)
        previous = (reference, heading)
        stepper.advance(inputs, period)  # the held commands, from the full state reached (tyre slip carries over)
        history.append(sensor.step(t + period, s))
    if bar is not None:
        bar.close()
    out: dict = {key: np.array(values) for key, values in records.items()}
    out["info"] = {"assigned": list(assigned), "failures": commander.failures if commander else 0,
                   "worst_error": commander.worst if commander else 0.0,
                   "evaluations": 0 if commander is None else commander.evaluations}
    return out


def with_commanded_rates(robot: Robot, commands: WheelCommands, assigned, rates: np.ndarray) -> WheelCommands:
    """`commands` ``(n,)`` with the rates of the joints `assigned` replaced by `rates` ``(n, n_a)`` (the slip
    model's; a wheel's ``spin`` follows its ``WHEEL.spin`` joint)."""
    all_rates, spin = np.array(commands.rates, dtype=float), np.array(commands.spin, dtype=float)
    for k, joint in enumerate(assigned):
        all_rates[:, robot.rate_names.index(joint)] = rates[:, k]
        wheel, _, name = joint.partition(".")
        if name == "spin":
            spin[:, robot.wheel_names.index(wheel)] = rates[:, k]
    return replace(commands, rates=readonly(all_rates), spin=readonly(spin))


class _Sensor:
    """The pose the controller measures (module docstring), updated once per control period."""

    def __init__(self, robot: Robot, model, s: np.ndarray, feedback: str, weights: SlipWeights | None,
                 noise: KalmanNoise | None) -> None:
        from ..odometry.model import odometry_model
        from ..slip.kalman import kalman_model
        from ..slip.weights import wls_model

        self.kind, self.pose = feedback, s[:3].copy()
        self.x = self.p = None
        if feedback == "pose":
            return
        if feedback == "fk2":
            self.filter = kalman_model(robot, "fk2", noise)
            self.odometry = self.filter.odometry
        elif feedback == "mqe":
            self.odometry = odometry_model(robot)
            sensed = replace(slip_inverse(robot, "mqe", differential=False), assigned=self.odometry.rate_joints,
                             steered=readonly(np.asarray(self.odometry.steer_index, dtype=int)))
            self.model = _Forward(sensed, np.array(robot.beta, dtype=float))
            self.n_rates = len(self.odometry.rate_joints)
        else:
            self.odometry = wls_model(robot, weights) if feedback == "wls" else odometry_model(robot)
        self.joints = self.odometry.joints
        if feedback == "mqe":  # the solver's order: the rates, then the steering angles
            self.joints = (*self.odometry.rate_joints, *self.odometry.steer_joints)
        self.cols = [model.names.index(j) for j in self.joints]
        self.t, self.previous = 0.0, s[self.cols].copy()

    def step(self, t: float, s: np.ndarray) -> np.ndarray:
        """The measured pose after the period ending at `t` with state `s`."""
        from ..odometry.integrators import integrate_increments
        from ..odometry.logs import JointLog
        from ..odometry.pipeline import odometry
        from ..slip.kalman import kalman_filter

        if self.kind == "pose":
            return s[:3].copy()
        now = s[self.cols].copy()
        log = JointLog(np.array([self.t, t]), self.joints, np.vstack([self.previous, now]), source="<sim>")
        if self.kind == "mqe":
            dt = t - self.t
            d = now - self.previous
            steer = d[self.n_rates:]
            mid = self.previous[self.n_rates:] + 0.5 * np.arctan2(np.sin(steer), np.cos(steer))
            q, _ = self.model(np.concatenate([d[:self.n_rates] / dt, mid]))
            self.pose = integrate_increments(self.pose, (q[:3] * dt)[None])[-1]
        elif self.kind == "fk2":
            run = kalman_filter(self.filter, log, x0=self.x, p0=self.p)
            self.x, self.p = run.twist[-1], run.covariance
            self.pose = integrate_increments(self.pose, run.increments)[-1]
        else:
            self.pose = np.asarray(odometry(self.odometry, log, pose0=self.pose).poses[-1], dtype=float)
        self.t, self.previous = t, now
        return self.pose.copy()
