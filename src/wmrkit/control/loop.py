"""The kinematic loop of §8.2 (Fig. 8.1), closed in continuous time (scipy's RK45) or at a sample period.

Each instant: position control (a :class:`~wmrkit.control.laws.PositionLaw`, or a geometric tracker) gives the
velocity to impose; :func:`~wmrkit.control.points.twist_for_velocity` turns it into an admissible body twist;
:func:`~wmrkit.kinematics.wheel_ik.wheel_commands` gives every wheel's command at the current steering (castor
angles fed back, §8.4.3); the steering policy and ranges pick the roots (:mod:`.steering`). The plant is ideal
(the robot moves with the commanded twist, unless a wheel is held at the end of its steering range: then with the
least-squares twist (4.11) of the actuated wheels' commanded rates at the steering reached; a held wheel changes
ends only when the other end serves the asked heading better by ``HOLD_MARGIN``, an event the continuous loop
locates) or goes through
low-level loops (:mod:`.actuators`), the twist then being the least-squares one of the joints' actual rates at the
actual steering. Each record says which steered wheels were within their range (``in_range``). The pose is measured
exactly, optionally ``delay`` samples late (discrete loop).

The plant's per-run arrays and commands live in :mod:`._loop_plant`; how a run advances and records, in
:mod:`._loop_steps`.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import numpy as np

from ..robot import Robot, check_robot
from ._loop_plant import HOLD_MARGIN, Plant, _Sim
from ._loop_steps import (
    _advance,
    _given_steering,
    _integrate,
    _record,
    _record_held,
    check_command,
    check_diverged,
)
from .laws import PositionLaw, law_velocity, pose_error
from .points import ControlError, ControlPoint, check_delay, point_pose, twist_for_velocity
from .references import Reference
from .steering import discretize_twist

__all__ = ["HOLD_MARGIN", "Plant", "TwistController", "check_command", "check_diverged", "law_controller", "simulate"]

#: ``(t, measured pose (3,), integral (3,)) -> (twist_robot (3,), d integral / dt (3,))``.
TwistController = Callable[[float, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]

#: Evaluations of the continuous loop allowed: a base plus this many per simulated second (the examples take
#: 30 to 300 per second, a pole of 100/s about 1000; a start kilometres off the reference makes the loop stiff and
#: takes thousands), and at most this many seconds of computing (each evaluation costs 0.2 to 1 ms: the
#: evaluation budget alone let a car with its steering at the ends of its range run for 6 minutes).
MAX_EVALUATIONS, EVALUATIONS_PER_SECOND, MAX_CONTINUOUS_SECONDS = 20_000, 2_000, 120.0
#: Fewest evaluations of the continuous loop per simulated second per 1/s of its fastest pole: RK45 (6 evaluations a
#: step) is stable for steps up to about 3.3 / pole (4 at most off the real axis); measured 1.9 to 4.5 for Stanley
#: gains and p-law poles of 300 to 3000 1/s.
EVALUATIONS_PER_POLE = 1.5
#: Most evaluations of a sampled loop: one a period for the ideal plant's exact step, one plus four per RK4 substep
#: otherwise (castors, low-level loops). Each costs 0.5 to 1 ms (law, wheel IK, record), so 1e6 periods of a diff
#: drive at 0.02 s (its RK4 step for the castor) ran for about an hour.
MAX_SAMPLED_EVALUATIONS = 100_000



def evaluation_budget(duration: float) -> int:
    """The evaluations a continuous loop of `duration` [s] may make."""
    return int(MAX_EVALUATIONS + EVALUATIONS_PER_SECOND * duration)


def check_stiffness(pole: float, run: float, duration: float, what: str) -> None:
    """Refuse up front a continuous loop whose error decays at `pole` [1/s] so fast that its explicit integrator
    surely exhausts the :func:`evaluation_budget` of `duration` [s] in the `run` [s] it integrates (a Stanley gain of
    1e308 crawled to the budget for 40 s); `what` names the gain and its value."""
    budget = evaluation_budget(duration)
    highest = budget / (EVALUATIONS_PER_POLE * run)
    if pole > highest:
        raise ControlError(f"{what}: the continuous loop's error decays at {pole:g} 1/s, and its explicit integrator "
                           f"needs at least {EVALUATIONS_PER_POLE:g} evaluations per simulated second per 1/s of it "
                           f"(its stable step): over {run:g} s at most {highest:.4g} 1/s fits its budget of {budget} "
                           "evaluations; lower the gain, or give a sample period (--period)")


def _too_stiff(controller: TwistController, sim: _Sim, t: float, x: np.ndarray, duration: float, evaluations: int,
               seconds: float) -> ControlError:
    """The refusal of a continuous loop that ran out of evaluations or time, with the likely cause."""
    twist = controller(t, x[:3], x[3:6])[0]
    beta = x[6:6 + len(sim.passive)]
    held = [sim.robot.steer_names[k] for k in np.flatnonzero(~sim.realised(twist, beta)[1])]
    why = (f"; wheel '{held[0]}' is held at an end of its steer_range (the law asks for turns sharper than the robot "
           "can make)" if held else "")
    return ControlError(f"the closed loop is too stiff to integrate over {duration:g} s: it reached t = {t:.4g} s "
                        f"after {evaluations} evaluations and {seconds:.0f} s of computing (commanded speed "
                        f"{math.hypot(*twist[:2]):.3g} m/s){why}; start closer to the reference, lower the gain, or "
                        "give a sample period (--period)")


def law_controller(cp: ControlPoint, law: PositionLaw, reference: Reference) -> TwistController:
    """The thesis's position control (8.1)-(8.3)/(8.53) of the controlled coordinates, then the admissible twist."""

    def control(t: float, pose: np.ndarray, integral: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ref, vel = reference.at(t)
        meas = point_pose(cp, pose)
        if cp.reduced:  # the reference is followed by the point; its heading is free (zero dynamics)
            ref = np.array([ref[0], ref[1], meas[2]])
            vel = np.array([vel[0], vel[1], 0.0])
        v = law_velocity(law, ref, vel, meas, integral)
        return twist_for_velocity(cp, pose, v), pose_error(ref, meas)

    return control




def simulate(robot: Robot, controller: TwistController, initial_pose: np.ndarray, duration: float, *,
             period: float | None = None, delay: int = 0, plant: Plant | None = None, output_dt: float = 0.05,
             skew_free: bool = False, rtol: float = 1e-8, atol: float = 1e-10,
             breaks: tuple[float, ...] = (), until: Callable[[float, np.ndarray], bool] | None = None,
             ) -> dict[str, np.ndarray]:
    """Close the loop of `robot` under `controller` from `initial_pose` for `duration` [s].

    Continuous time (``period`` None; RK45 with `rtol`/`atol`, sampled every `output_dt`: :func:`_integrate`) or
    discrete (commands held for `period` [s], pose measured `delay` samples late, ``skew_free`` applies
    :func:`discretize_twist` to the held twist). Returns arrays: ``t (n,)``, ``pose (n, 3)``, ``twist (n, 3)``
    (commanded), ``beta (n, n_steer)`` (actual steering), ``target (n, n_steer)`` (commanded steering),
    ``in_range (n, n_steer)`` and, with ideal joints, ``moved (n, 3)`` (the twist the plant moved the robot with).
    ``breaks``: times where the reference is discontinuous; the continuous integration restarts there. `until`
    ``(t, pose) -> bool``: the run ends at the first output sample (or period) where it holds (a path follower that
    has driven its path).
    """
    check_robot(robot)
    plant = plant or Plant()
    sim = _Sim(robot, plant)
    n_s = len(robot.steer_names)
    beta0 = np.array(robot.beta, dtype=float)
    loop0 = np.zeros(sim.n_loop)
    if plant.loops is not None:  # joints start at rest, steering at the described angle
        for i, j in enumerate(sim.joints):
            if j.endswith(".steer"):
                loop0[i] = beta0[robot.steer_names.index(j.partition(".")[0])]
    x0 = np.concatenate([np.asarray(initial_pose, dtype=float), np.zeros(3), beta0, loop0])
    if not (math.isfinite(duration) and duration > 0):
        raise ControlError(f"duration: expected a positive number of seconds, got {duration}")

    def split(x: np.ndarray):
        return x[:3], x[3:6], x[6:6 + n_s], x[6 + n_s:]

    def rhs(t: float, x: np.ndarray, held: tuple | None = None) -> np.ndarray:
        pose, integral, beta, ls = split(x)
        if held is None:
            twist, de = controller(t, pose, integral)
            check_diverged(twist, t, sampled=False)  # the continuous loop (the sampled one holds its command)
        else:
            twist, de = held
        if plant.loops is None:  # ideal joints: the robot moves with the commanded twist, if its wheels can
            actual_beta, (moving, _) = beta, sim.realised(twist, beta)
        else:
            cmd = sim.commands(twist, beta)
            ls = plant.loops.settle_ideal(ls, sim.joint_commands(cmd))
            actual_beta = sim.actual_beta(cmd.target, beta, ls)
            moving = sim.plant_twist(twist, cmd, actual_beta, ls)
        out = np.zeros(len(x))  # d pose, d integral, d beta, d loops
        c, s = math.cos(pose[2]), math.sin(pose[2])
        m0, m1, m2 = np.asarray(moving, dtype=float).tolist()
        out[:3] = c * m0 - s * m1, s * m0 + c * m1, m2
        if held is None:
            out[3:6] = de
        if sim.castors:  # castors turn by themselves (8.24): integrate at the actual twist
            out[6:6 + n_s][sim.passive] = sim.castor_rates(moving, actual_beta)
        if plant.loops is not None:
            out[6 + n_s:] = plant.loops.derivative(ls, sim.joint_commands(cmd))
        return out

    if period is None:
        t_out = np.arange(0.0, duration + 1e-9, output_dt)
        if t_out[-1] < duration - 1e-9 or len(t_out) == 1:  # the last sample at the end of the run
            t_out = np.append(t_out, duration)
        edges = [0.0, *sorted(b for b in breaks if 0 < b < t_out[-1]), float(t_out[-1])]
        allowed = evaluation_budget(duration)
        budget, start = [allowed], time.monotonic()

        def counted(t: float, x: np.ndarray) -> np.ndarray:
            budget[0] -= 1
            if budget[0] < 0 or (budget[0] % 1000 == 0 and time.monotonic() - start > MAX_CONTINUOUS_SECONDS):
                raise _too_stiff(controller, sim, t, x, duration, allowed - budget[0], time.monotonic() - start)
            return rhs(t, x)

        sim.hold_margin = math.inf  # within a step; _given_steering switches ends as events
        records = _integrate(counted, x0, t_out, edges, lambda t, x: _record(controller, sim, t, x, split),
                             lambda t, x: _given_steering(controller, sim, t, x, split), rtol, atol,
                             None if until is None else lambda r: until(r["t"], r["pose"]))
    else:
        if not (math.isfinite(period) and period > 0):
            raise ControlError(f"period: expected a positive number of seconds, got {period}")
        check_delay(delay)
        n = math.floor(duration / period + 1e-9) + 1
        x, history, records = x0.copy(), [x0[:3].copy()], []
        integral = np.zeros(3)
        exact, step, subs = _sampled_steps(plant, bool(sim.passive.any()), period)
        work = n if exact else n * (1 + 4 * subs)
        if work > MAX_SAMPLED_EVALUATIONS:
            steps = "" if exact else (f" of {subs:.3g} RK4 substep(s) (castors, or low-level loops: each at most the "
                                      f"fastest loop's time scale, {step:.3g} s)")
            raise ControlError(f"duration {duration:g} s at a period of {period:g} s: {n} periods{steps}, more than "
                               f"{MAX_SAMPLED_EVALUATIONS} evaluations of the loop (about 2 min of computing); give a "
                               "shorter --duration or a longer --period")
        for k in range(n):
            t = k * period
            measured = history[max(0, k - delay)]
            twist, de = controller(t, measured, integral)
            check_diverged(twist, t)
            integral = integral + period * de
            held = discretize_twist(twist, period) if skew_free else twist
            x[3:6] = integral
            records.append(_record_held(sim, t, x, split, twist, x[6:6 + n_s]))
            x[6:6 + n_s] = records[-1]["beta"]  # steered wheels keep the angle they were given
            if exact:  # a wheel held at the end of its range: the twist its wheels give instead (rhs does it else)
                held = sim.realised(held, x[6:6 + n_s])[0]
            if k == n - 1 or (until is not None and until(t, x[:3])):
                break
            x = _advance(rhs, x, t, period, subs, (held, de), exact)
            history.append(x[:3].copy())
    return {key: np.array([r[key] for r in records]) for key in records[0]}


def _sampled_steps(plant: Plant, castors: bool, period: float) -> tuple[bool, float, int]:
    """How a sampled loop advances a period: ``(exact, step, subs)``, the ideal plant's exact SE(2) step (one
    evaluation a period), else `subs` RK4 substeps of at most `step` [s] (1 + 4 evaluations each)."""
    exact = plant.loops is None and not castors
    step = 0.02 if plant.loops is None else min(0.02, plant.loops.time_scale)  # RK4 is stable within a few
    return exact, step, 1 if exact else max(1, math.ceil(min(period / step, 1e18)))  # time scales of the fastest


def longest_sampled_run(robot: Robot, plant: Plant | None, period: float) -> float:
    """The longest duration [s] a sampled loop of `robot` at `period` [s] simulates within
    ``MAX_SAMPLED_EVALUATIONS`` (:func:`simulate` refuses a longer one)."""
    castors = any(robot.wheel(n).type in ("castor", "double_castor") for n in robot.steer_names)
    exact, _, subs = _sampled_steps(plant or Plant(), castors, period)
    return (MAX_SAMPLED_EVALUATIONS // (1 if exact else 1 + 4 * subs) - 1) * period
