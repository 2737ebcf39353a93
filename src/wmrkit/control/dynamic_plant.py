"""The kinematic loop closed through the chapter-7 dynamics (beyond the thesis, issue item 7).

Each period the controller's twist becomes the servo references of :func:`wmrkit.dynamics.programs.twist_program`
(rate servos on the actuated wheels, PD servos on the actuated steering, at the IK's no-slip joint motion), and the
Lagrange model with tyres (:mod:`wmrkit.dynamics`) is integrated over the period by a
:class:`~wmrkit.dynamics.simulate.Stepper` that carries the *full* state (pose, steering, wheel angles, every
velocity: tyre slip carries over, and the integrator's own state). The robot needs its mass properties and tyres in
its description (the catalog ``forklift`` has them).

Per period the work outside the dynamics is a few microseconds: the per-wheel IK is the robot's compiled
single-call kernel (:func:`wmrkit.kinematics.realtime.realtime`), the references are written into the stepper's
held inputs (:meth:`~wmrkit.dynamics.simulate.Stepper.hold`), and the thesis's laws (8.1)-(8.3)/(8.53) have a
scalar form, :func:`fast_law_controller` (the numbers of :func:`.loop.law_controller`, tested).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from ..errors import WmrkitError
from ..robot import check_robot
from ..wheels import beta_from_heading, heading_from_beta
from ._loop_steps import LAW_ADVICE
from .laws import PositionLaw
from .loop import TwistController, check_command
from .points import ControlError, ControlPoint, StoppedRun, check_delay
from .references import Reference
from .steering import check_steering_driven, range_keeper
from .tick import scalar_law

if TYPE_CHECKING:
    from ..dynamics.runs import Stop

__all__ = ["fast_law_controller", "rechecked", "rolling_start", "simulate_dynamics"]

#: How a caller of the loops through the dynamics sets their step, as their errors say it (:func:`rechecked`).
STEP_ARGUMENT = "(the step argument)"

def simulate_dynamics(robot, controller: TwistController, initial_pose: np.ndarray, duration: float, *,
                      period: float, delay: int = 0, tyre: str | None = None, step: float = 1e-3,
                      feedback: str = "pose", policy: str = "closest",
                      until: Callable[[float, np.ndarray], bool] | None = None) -> dict[str, np.ndarray]:
    """Close the loop of `controller` on the dynamic model of `robot` (same outputs as :func:`.loop.simulate`).

    `period` [s]: control period (commands held); `delay`: measurement delay in samples; `tyre`: traction model
    name (default: as described); `step` [s]: integration step of the dynamics (1 kHz default, semi-implicit).
    `feedback`: ``"pose"`` (the true pose is measured) or ``"odometry"`` (the pose estimated from the sensed joints,
    one exact SE(2) step per period, :func:`wmrkit.kinematics.realtime.realtime`); the estimate is returned as
    ``estimate (n, 3)``. `policy`: which root of (8.9) each steered wheel takes, from its current heading
    (:mod:`.steering`; ``"closest"`` turns the least, reversing the spins rather than the steering). The same run
    as a plain loop of ``controller``, ``twist_program(model, [t], [twist])`` and ``Stepper.advance(inputs,
    period)`` (tested), with the per-period work done in place. A stop is re-checked at a shorter step
    (:func:`rechecked`).
    """
    check_robot(robot)
    return rechecked(lambda d, h, _: _dynamics_loop(robot, controller, initial_pose, d, period=period, delay=delay,
                                                    tyre=tyre, step=h, feedback=feedback, policy=policy,
                                                    until=until), duration, step, period)


def rechecked(loop: Callable[[float, float, bool], dict], duration: float, step: float, period: float) -> dict:
    """``loop(duration, step, False)``: a closed loop through the dynamics for `duration` [s] at `step` [s], control
    `period` [s] (its :class:`~wmrkit.dynamics.simulate.Stepper` made with ``recheck=False``; the last argument True
    for the re-run), re-checked when it stops at t (a wheel lifts off, the state or the law's command diverges): the
    same loop runs again from t = 0 at :func:`~wmrkit.dynamics.runs.recheck_step` to its end, or as far as
    :func:`~wmrkit.dynamics.runs.recheck_budget` steps reach, and judged as a fixed-step run's stop
    (:func:`~wmrkit.dynamics.runs.judge`). When that run stops too, by 0.1 s past the stop, the stop is the robot's;
    when it stops only later, the error is that later stop (the robot's, which the step brought early), naming both:
    the forklift on the arc-line at 2 m/s lifts a drive wheel off at t = 2.40 s at 1 ms, and at 2.52 s from 0.25 ms
    down (hence to its end, not 0.1 s past the stop); when it runs to the end without stopping, the error blames the
    step (the integration unstable, not the robot: the skid steer on the square 'loses' a wheel's load at t = 25 s
    at a 0.1 s step and period, and keeps its wheels down at 1 ms); when the budget ends first, it says the verdict
    is not known. The loop's `controller` and `until` are called again from t = 0 (a law is a function of its
    arguments)."""
    from ..dynamics.runs import DivergedError, LiftOffError, Recheck, judge, recheck_budget, recheck_step

    try:
        return loop(duration, step, False)
    except (LiftOffError, DivergedError, StoppedRun) as err:
        fine, t = recheck_step(step, 0), err.t
        if not math.isfinite(t):
            raise
        end = min(duration, recheck_budget(0) * fine)
        try:
            out = loop(end, fine, True)
        except (LiftOffError, DivergedError, StoppedRun) as again:
            if not math.isfinite(again.t):
                raise err from None
            later = judge(_loop_stop(err), Recheck(step, fine, _loop_stop(again), again.t, end, "the same loop"),
                          STEP_ARGUMENT)
            if later is None:  # it stops too, by recheck_end: the robot's stop, at the loop's own step
                raise _reproduced(err, step, fine) from None
            if isinstance(again, StoppedRun):  # the law diverged: its advice, not the step's nor the torques'
                raise StoppedRun(f"{later.what}; {LAW_ADVICE}", later.t) from None
            raise later from None
        reached = float(out["t"][-1])
        cut = end < duration and reached > end - period  # by the budget, not by the loop's own end (`until`)
        if reached < t and not cut:  # it ended (arrived) before the stop: no verdict
            raise
        verdict = judge(_loop_stop(err), Recheck(step, fine, None, reached, duration if cut else -math.inf,
                                                "the same loop"), STEP_ARGUMENT)
        raise verdict from None  # the re-run went on: the step's error (or not known), never None


def _reproduced(err: WmrkitError, step: float, fine: float) -> WmrkitError:
    """The stop `err` of a loop at `step` [s] that its re-run at `fine` [s] reproduced, as it is; but the state's
    divergence, whose advice (the stepper's: "use a smaller step") the shorter step did not bear out, says both."""
    from ..dynamics.runs import DivergedError, Stop

    if not isinstance(err, DivergedError):
        return err
    if err.what != Stop.diverged(err.t).what:  # the state left the physical range: a shorter step is no cure
        what = f"{err.what} at step {step:g} s, and the same loop at step {fine:.3g} s leaves it too"
        return DivergedError(f"{what}: lower the speeds or the gain", err.t, what)
    what = f"{err.what} at step {step:g} s, and the same loop at step {fine:.3g} s diverges too"
    return DivergedError(f"{what}: lower the speeds or the gain, or use a step below {fine:.3g} s {STEP_ARGUMENT}",
                         err.t, what)


def _loop_stop(err: WmrkitError) -> Stop:
    """Where a loop through the dynamics stopped, as :func:`~wmrkit.dynamics.runs.judge` takes it (a
    :class:`~wmrkit.dynamics.runs.Stop`): `err` a lift-off, a divergence of the state, or the law's command diverging
    (:class:`.points.StoppedRun`), each with its time ``t`` [s]; a divergence keeps its own words (a state out of the
    physical range, :func:`~wmrkit.dynamics.runs.first_escape`, is not "diverged before t")."""
    from ..dynamics.runs import LiftOffError, Stop

    if isinstance(err, LiftOffError):
        return Stop.lift_off(err.t, err.contact)
    if isinstance(err, StoppedRun):
        return Stop(err.t, f"the loop diverged at t = {err.t:.6g} s", whose="the loop's")
    return Stop(err.t, err.what)  # the state diverged, or left the physical range (its own words)


def _dynamics_loop(robot, controller: TwistController, initial_pose: np.ndarray, duration: float, *, period: float,
                   delay: int, tyre: str | None, step: float, feedback: str, policy: str,
                   until: Callable[[float, np.ndarray], bool] | None) -> dict[str, np.ndarray]:
    """The loop of :func:`simulate_dynamics`, not re-checked."""
    from ..dynamics.model import DynamicModel
    from ..dynamics.programs import twist_program
    from ..dynamics.simulate import Stepper
    from ..kinematics.realtime import realtime
    if not (math.isfinite(period) and period >= step > 0 and abs(period / step - round(period / step)) <= 1e-6):
        raise ControlError(f"period: expected a control period of a whole number of dynamics steps of {step} s, "
                           f"got {period}")  # 0.0015 s ran 2 ms of dynamics per 1.5 ms of the law's time
    if feedback not in ("pose", "odometry"):
        raise ControlError(f"feedback must be 'pose' or 'odometry', got {feedback!r}")
    check_delay(delay)
    check_steering_driven(robot)
    model = DynamicModel.of(robot, tyre)
    held = max(1, round(period / step)) * step
    stepper = Stepper(model, rolling_start(model, controller, initial_pose), step=step, recheck=False)
    stepper.advance(twist_program(model, [0.0], [(0.0, 0.0, 0.0)]), 0.0)  # the servo gains; references below
    s, steer = stepper.state, list(model.steer_columns)
    ik = realtime(robot).ik
    rate_reference, heading, current = np.zeros(model.n), np.zeros(len(steer)), np.zeros(len(steer))
    rates = rate_reference[3:3 + len(robot.rate_names)]  # the IK writes the references in place
    delta = np.array([w.delta for w in robot.wheels if w.kind.steers], dtype=float)
    to_heading = delta - 0.5 * math.pi
    n = math.floor(duration / period + 1e-9) + 1
    history, integral = [s[:3].copy()], np.zeros(3)
    odometer = _Odometer(robot, model, s) if feedback == "odometry" else None
    out = {key: [] for key in ("t", "pose", "twist", "beta", "target", "estimate", "in_range")}
    held_in_range = range_keeper(robot, policy)
    for k in range(n):
        t = k * period
        twist, de = controller(t, history[max(0, k - delay)], integral)
        check_command(twist, t)
        integral = integral + period * de
        np.add(np.take(s, steer), to_heading, out=current)  # heading_from_beta unwrapped (the IK wraps its input)
        ik(float(twist[0]), float(twist[1]), float(twist[2]), current, rates, heading)  # = wheel_commands(twist)
        out["in_range"].append(held_in_range(heading, rates, current))
        stepper.hold(rate_reference, heading)
        out["t"].append(t)
        out["pose"].append(s[:3].copy())
        out["twist"].append(np.asarray(twist, dtype=float))
        out["beta"].append(s[steer])
        out["target"].append(beta_from_heading(heading, delta))  # Robot.beta_of_heading
        out["estimate"].append(history[-1].copy())
        if k == n - 1 or (until is not None and until(t, out["pose"][-1])):
            break
        stepper.advance(None, held)  # a WmrkitError if the dynamics diverge
        history.append(s[:3].copy() if odometer is None else odometer.step(s))
    return {key: np.array(values) for key, values in out.items()}


def rolling_start(model, controller: TwistController, initial_pose: np.ndarray) -> np.ndarray:
    """The state a loop through the dynamics starts from: at `initial_pose`, rolling without slip at the law's
    first command (:func:`wmrkit.dynamics.simulate.initial_state`), as the kinematic loop moves at once. From rest
    the first period would be a step the servos take at the grip (1 g): a swerve robot with its centre of mass
    0.3 m high tipped over at t = 1 ms on a straight line at 0.5 m/s."""
    from ..dynamics.simulate import initial_state

    twist, _ = controller(0.0, np.asarray(initial_pose, dtype=float).copy(), np.zeros(3))
    check_command(twist, 0.0)
    return initial_state(model, twist, initial_pose)


def fast_law_controller(cp: ControlPoint, law: PositionLaw, reference: Reference) -> TwistController:
    """:func:`.loop.law_controller` in scalar arithmetic (:func:`.tick.scalar_law`; a few µs a call instead of
    tens): the same twist and error for the laws (8.1)-(8.3) with the gate (8.53), full or reduced control point."""
    law_twist = scalar_law(cp, law)

    def control(t: float, pose: np.ndarray, integral: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ref, vel = reference.at(t)
        vx, vy, w, e0, e1, e2 = law_twist(float(pose[0]), float(pose[1]), float(pose[2]), float(ref[0]),
                                          float(ref[1]), float(ref[2]), float(vel[0]), float(vel[1]), float(vel[2]),
                                          float(integral[0]), float(integral[1]), float(integral[2]))
        return np.array([vx, vy, w]), np.array([e0, e1, e2])

    return control


class _Odometer:
    """Odometry from the sensed joints of the simulated state (the robot's compiled single-call step)."""

    def __init__(self, robot, model, s: np.ndarray) -> None:
        from ..kinematics.realtime import realtime

        self.rt = realtime(robot)
        self.cols = [model.names.index(j) for j in self.rt.rate_joints]
        self.steer = [model.steer_columns[robot.steer_names.index(j.partition(".")[0])] for j in self.rt.steer_joints]
        self.delta = np.array([robot.wheel(j.partition(".")[0]).delta for j in self.rt.steer_joints], dtype=float)
        self.pose = s[:3].copy()
        self.previous = s[self.cols].copy()
        self.beta = s[self.steer].copy()

    def step(self, s: np.ndarray) -> np.ndarray:
        beta = s[self.steer]
        heading_mid = heading_from_beta(0.5 * (beta + self.beta), self.delta)
        self.beta = beta.copy()
        self.rt.odometry_step(self.pose, self.previous, np.ascontiguousarray(s[self.cols]), heading_mid)
        return self.pose.copy()
