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
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..kinematics._ik_fast import in_range_one, wrap_one
from ..kinematics.linalg import solve_assigned
from ..kinematics.wheel_ik import checked_rates, checked_steering_config, forward_kinematics
from ..limits import MAX_QUERY_RATE, MAX_SPEED
from ..robot import Robot
from ..wheels import wrap_angle
from .actuators import LowLevelLoops
from .laws import PositionLaw, law_velocity, pose_error
from .points import ControlError, ControlPoint, StoppedRun, check_delay, point_pose, twist_for_velocity
from .references import Reference
from .steering import checked_steering, discretize_twist, reverse_spins, spin_columns, steer_ranges, unit_spin

_SPINS = (".spin", ".spin1", ".spin2")  # the joints that drive a wheel

__all__ = ["Plant", "TwistController", "law_controller", "simulate"]

#: ``(t, measured pose (3,), integral (3,)) -> (twist_robot (3,), d integral / dt (3,))``.
TwistController = Callable[[float, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]


def check_command(twist: np.ndarray, t: float) -> None:
    """Refuse a law's twist beyond ``limits.MAX_SPEED`` (m/s, rad/s) at `t`: a loop through the dynamics has
    diverged (the plant would be driven far outside any robot's envelope, slowly and meaninglessly)."""
    if not np.all(np.abs(twist) <= MAX_SPEED):  # NaN included
        raise StoppedRun(f"the loop diverged: at t = {t:.6g} s the law commands the twist "
                         f"{tuple(float(v) for v in twist)}, beyond {MAX_SPEED:g} m/s or rad/s; lower the gain or "
                         "the period", t)


def check_diverged(twist: np.ndarray, t: float) -> None:
    """Refuse a law's twist beyond ``limits.MAX_QUERY_RATE`` at `t` in a kinematic loop: no wheel command is defined
    there (:func:`wheel_commands` refuses it), the loop has diverged."""
    if not np.all(np.abs(twist) <= MAX_QUERY_RATE):  # NaN included
        raise StoppedRun(f"the closed loop diverged at t = {t:.6g} s: the law commands the twist "
                         f"{tuple(float(v) for v in twist)}, beyond {MAX_QUERY_RATE:g} m/s or rad/s; lower the gain "
                         "or the period", t)


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

#: A steered wheel of the ideal plant held at an end of its steering range stays there unless the other end serves
#: the heading asked of it better by more than this [rad] (:func:`~.steering.choose_steering` ``hold_margin``).
HOLD_MARGIN = math.radians(2.0)
#: Bisections locating the instant a held wheel changes ends in the continuous loop (to 2**-40 of a step).
SWITCH_BISECTIONS = 40


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


class _Commands(NamedTuple):
    """One evaluation of the wheel commands: the steering targets (thesis beta), the joint rates
    (``robot.rate_names``) and the spins of the steered wheels for the chosen roots, and whether each steered
    wheel's target lies within its range."""

    target: np.ndarray
    rates: np.ndarray
    spin: np.ndarray
    fits: np.ndarray


@dataclass(frozen=True)
class Plant:
    """How the commands move the robot: `loops` (None: ideal joints), steering `policy` (see :mod:`.steering`)."""

    loops: LowLevelLoops | None = None
    policy: str = "closest"


class _Sim:
    """Per-run arrays: which steering angles are commanded, integrated (castors), or in a low-level loop."""

    def __init__(self, robot: Robot, plant: Plant) -> None:
        self.robot, self.plant = robot, plant
        names = robot.steer_names
        types = [robot.wheel(n).type for n in names]
        self.passive = np.array([t in ("castor", "double_castor") for t in types], dtype=bool)
        self.delta = np.array([robot.wheel(n).delta for n in names], dtype=float)
        self.ranges, self.spin_columns = steer_ranges(robot), spin_columns(robot)
        self.wheel_of_steer = np.array([robot.wheel_names.index(n) for n in names], dtype=int)
        self.castor_rate_columns = np.array([robot.rate_names.index(f"{n}.steer") for n, p in zip(names, self.passive,
                                                                                                    strict=True) if p],
                                            dtype=int)  # the castors' steering rates (8.24) in the IK's rates
        loops = plant.loops
        self.joints = () if loops is None else loops.joints
        for j in self.joints:
            wheel, _, joint = j.partition(".")
            w = robot.wheel(wheel)
            if joint == "steer" and w.type not in ("steerable", "double"):
                raise ControlError(f"low-level loop on '{j}': only steerable and double wheels have a commanded angle")
            if joint == "spin" and "spin" not in w.kind.rates:
                raise ControlError(f"low-level loop on '{j}': wheel '{wheel}' has no 'spin' joint")
        self.limited = bool(np.isfinite(self.ranges).any())
        self.ranged = [(k, float(self.delta[k]), float(lo), float(hi)) for k, (lo, hi) in enumerate(self.ranges)
                       if not self.passive[k] and np.isfinite([lo, hi]).any()]  # the steered wheels with a range
        spins = [j for j in self.joints if j.endswith(".spin")]
        if (loops is not None or self.limited) and not spins:
            spins = [j for j in robot.actuated if j.endswith(_SPINS)]
        if self.limited and not spins:  # no actuator described: every wheel spins as the IK commands it
            spins = [j for j in robot.rate_names if j.endswith(_SPINS)]
        self.drive = tuple(spins)
        self.drive_columns = np.array([robot.velocity_names.index(j) for j in spins], dtype=int)
        self.n_loop = 0 if loops is None else loops.size
        self.hold_margin = HOLD_MARGIN  # the continuous loop holds ends within a step (inf) and switches at events

    def commands(self, twist: np.ndarray, beta: np.ndarray, hold_margin: float | None = None,
                 ik: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None) -> _Commands:
        """Wheel commands at steering `beta`, with the policy and ranges applied to the steered wheels; a wheel held
        at an end changes ends past `hold_margin` (default ``self.hold_margin``). `ik`: the IK's rates, steering and
        spins at `(twist, beta)` (:func:`checked_rates`), when already computed."""
        rates, target, spin_all = checked_rates(self.robot, twist, beta) if ik is None else ik
        target, rates = np.array(target), np.array(rates)
        fits = np.ones(len(target), dtype=bool)
        if len(target) and (self.plant.policy != "closest" or self.limited):
            steered = ~self.passive
            heading = target - math.pi / 2 + self.delta
            margin = self.hold_margin if hold_margin is None else hold_margin
            chosen, _, in_range, reverse = checked_steering(heading, spin_all[self.wheel_of_steer],
                                                            beta - math.pi / 2 + self.delta, self.plant.policy,
                                                            self.ranges, margin)
            target = np.where(steered, chosen + math.pi / 2 - self.delta, target)
            reverse_spins(rates, self.spin_columns, reverse & steered)
            fits = in_range | self.passive
        spin = np.where(self.passive, spin_all[self.wheel_of_steer], unit_spin(rates, self.spin_columns))
        return _Commands(target, rates, spin, fits)

    def realised(self, twist: np.ndarray, beta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The ideal plant's twist and which steered wheels fit their ranges: the commanded twist, or, when a wheel
        is held at the end of its range, the least-squares twist (4.11) of the actuated wheels' commanded rates at
        the steering reached (the wheels scrub: the robot cannot move as commanded)."""
        if not self.limited:
            return twist, np.ones(len(self.ranges), dtype=bool)
        if self.all_fit(checked_steering_config(self.robot, twist, beta)):  # the commanded twist: no wheel is held
            return twist, np.ones(len(self.ranges), dtype=bool)
        cmd = self.commands(twist, beta)
        if cmd.fits.all():
            return twist, cmd.fits
        return self.least_squares_twist(cmd, cmd.target, {}), cmd.fits

    def all_fit(self, target: list[float]) -> bool:
        """Whether every steered wheel has a root of (8.9) within its range, the IK's steering `target` or that
        plus pi: :func:`.steering.checked_steering`'s ``in_range`` (of any policy), in plain floats, the same
        operations."""
        for k, delta, lo, hi in self.ranged:
            h0 = wrap_one(target[k] - math.pi / 2 + delta)
            if not (in_range_one(h0, lo, hi) or in_range_one(wrap_one(h0 + math.pi), lo, hi)):
                return False
        return True

    def least_squares_twist(self, cmd: _Commands, beta: np.ndarray, actual: dict[str, float]) -> np.ndarray:
        """Twist (4.11) of the drive joints' rates (`actual` where given, else commanded) at steering `beta`:
        :func:`forward_kinematics`' numbers, its columns found once a run."""
        q = np.array([actual[j] if j in actual else float(cmd.rates[c - 3])  # chosen roots
                      for j, c in zip(self.drive, self.drive_columns, strict=True)])
        if not (np.abs(q) <= MAX_QUERY_RATE).all():  # NaN included: refused by it, naming the rate
            return np.asarray(forward_kinematics(self.robot, dict(zip(self.drive, q.tolist(), strict=True)), beta)[0])
        return solve_assigned(self.robot.constraint_matrix(beta), self.drive_columns, q)[0][:3]

    def joint_commands(self, cmd: _Commands) -> np.ndarray:
        out = np.zeros(len(self.joints))
        for i, j in enumerate(self.joints):
            wheel, _, joint = j.partition(".")
            if joint == "steer":
                out[i] = cmd.target[self.robot.steer_names.index(wheel)]
            else:  # the rate of the chosen root
                out[i] = cmd.rates[self.robot.rate_names.index(j)]
        return out

    def plant_twist(self, twist_cmd: np.ndarray, cmd: _Commands, beta: np.ndarray,
                    loop_state: np.ndarray) -> np.ndarray:
        if self.plant.loops is None or not self.drive:
            return twist_cmd
        return self.least_squares_twist(cmd, beta, {j: loop_state[self.joints.index(j)] for j in self.drive
                                                    if j in self.joints})

    def actual_beta(self, target: np.ndarray, beta: np.ndarray, loop_state: np.ndarray) -> np.ndarray:
        out = np.where(self.passive, beta, target)
        for i, j in enumerate(self.joints):
            if j.endswith(".steer"):
                out[self.robot.steer_names.index(j.partition(".")[0])] = loop_state[i]
        return out


def simulate(robot: Robot, controller: TwistController, initial_pose: np.ndarray, duration: float, *,
             period: float | None = None, delay: int = 0, plant: Plant | None = None, output_dt: float = 0.05,
             skew_free: bool = False, rtol: float = 1e-8, atol: float = 1e-10,
             breaks: tuple[float, ...] = (), until: Callable[[float, np.ndarray], bool] | None = None,
             ) -> dict[str, np.ndarray]:
    """Close the loop of `robot` under `controller` from `initial_pose` for `duration` [s].

    Continuous time (``period`` None; RK45 with `rtol`/`atol`, sampled every `output_dt`: :func:`_integrate`) or
    discrete (commands held for `period` [s], pose measured `delay` samples late, ``skew_free`` applies
    :func:`discretize_twist` to the held twist). Returns arrays: ``t (n,)``, ``pose (n, 3)``, ``twist (n, 3)``
    (commanded), ``beta (n, n_steer)`` (actual steering), ``target (n, n_steer)`` (commanded steering).
    ``breaks``: times where the reference is discontinuous; the continuous integration restarts there. `until`
    ``(t, pose) -> bool``: the run ends at the first output sample (or period) where it holds (a path follower that
    has driven its path).
    """
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
            check_diverged(twist, t)
        else:
            twist, de = held
        if plant.loops is None:  # ideal joints: the robot moves with the commanded twist, if its wheels can
            actual_beta, (moving, _) = beta, sim.realised(twist, beta)
        else:
            cmd = sim.commands(twist, beta)
            ls = plant.loops.settle_ideal(ls, sim.joint_commands(cmd))
            actual_beta = sim.actual_beta(cmd.target, beta, ls)
            moving = sim.plant_twist(twist, cmd, actual_beta, ls)
        th = pose[2]
        dpose = np.array([math.cos(th) * moving[0] - math.sin(th) * moving[1],
                          math.sin(th) * moving[0] + math.cos(th) * moving[1], moving[2]])
        dbeta = np.zeros(n_s)
        if sim.passive.any():  # castors turn by themselves (8.24): integrate at the actual twist
            dbeta[sim.passive] = checked_rates(robot, moving, actual_beta)[0][sim.castor_rate_columns]
        dls = ls[:0] if plant.loops is None else plant.loops.derivative(ls, sim.joint_commands(cmd))
        return np.concatenate([dpose, de if held is None else np.zeros(3), dbeta, dls])

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
    return {key: np.array([r[key] for r in records]) for key in ("t", "pose", "twist", "beta", "target", "in_range")}


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


def _advance(rhs, x: np.ndarray, t: float, period: float, subs: int, held: tuple, exact: bool) -> np.ndarray:
    """One held period: the exact SE(2) step for an ideal plant, else RK4 substeps."""
    if exact:
        from ..odometry.integrators import integrate_exact

        out = x.copy()
        out[:3] = integrate_exact(x[:3], held[0], period)
        return out
    h = period / subs
    for i in range(subs):
        s = t + i * h
        k1 = rhs(s, x, held)
        k2 = rhs(s + h / 2, x + h / 2 * k1, held)
        k3 = rhs(s + h / 2, x + h / 2 * k2, held)
        k4 = rhs(s + h, x + h * k3, held)
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return x


def _integrate(fun, x0: np.ndarray, t_out: np.ndarray, edges: list[float], record, given, rtol: float,
               atol: float, until=None) -> list[dict]:
    """The continuous loop: RK45 (scipy's, as ``solve_ivp``) step by step, restarted at the `edges`; `record(t, x)`
    at each of `t_out`. The steered wheels' entries of the state are constant within a step: the steering last
    given, from which the roots and ends are chosen (:func:`~.steering.choose_steering` ``current``), as the sampled
    loop keeps each period's angle. After each step they take the steering just given, ``given(t, x)`` (an array,
    and whether a held wheel changes ends there, past ``HOLD_MARGIN``); within a step a held wheel stays at its end,
    and where it changes ends the instant is located (bisection on the step's interpolant) and the integration
    restarts there: the hysteresis makes the switch an event, not a discontinuity the integrator chatters on.
    `until(record)`: the records end at the first for which it holds."""
    from scipy.integrate import RK45

    records, x = [], x0
    for lo, hi in itertools.pairwise(edges):  # restart at the reference's known corners
        last = hi == edges[-1]
        keep = list(t_out[(t_out >= lo) & ((t_out <= hi) if last else (t_out < hi))])
        t0 = lo
        while True:
            if keep and keep[0] == t0:
                records.append(record(t0, x))
                keep.pop(0)
                if until is not None and until(records[-1]):
                    return records
            solver = RK45(fun, t0, x, hi, rtol=rtol, atol=atol, max_step=0.25)
            switched = None
            while solver.status == "running" and switched is None:
                message = solver.step()
                if solver.status == "failed":
                    raise ControlError(f"the closed loop could not be integrated: {message}")
                t_end, y = solver.t, solver.y
                dense = solver.dense_output()
                new, switch = given(t_end, y)
                if switch:  # the first instant of the step where a held wheel changes ends
                    a, b = solver.t_old, t_end
                    for _ in range(SWITCH_BISECTIONS):
                        mid = 0.5 * (a + b)
                        if given(mid, dense(mid))[1]:
                            b = mid
                        else:
                            a = mid
                    t_end, y = b, dense(b)
                    new = given(b, y)[0]
                    switched = b
                while keep and keep[0] <= t_end:
                    records.append(record(keep[0], dense(keep.pop(0))))
                    if until is not None and until(records[-1]):
                        return records
                y = y.copy()
                y[6:] = new
                if switched is None and solver.status == "running" and not np.array_equal(y, solver.y):
                    solver.y, solver.f = y, fun(t_end, y)  # the derivative there follows the steering given
            x = y if switched is not None else solver.y
            if switched is None or switched >= hi:
                break
            t0 = switched
    return records


def _given_steering(controller, sim: _Sim, t: float, x: np.ndarray, split) -> tuple[np.ndarray, bool]:
    """``x[6:]`` with the steered wheels' angles replaced by those the commands at `(t, x)` give them (a held wheel
    changing ends past ``HOLD_MARGIN``), and whether a held wheel changes ends."""
    out = x[6:].copy()
    steered = ~sim.passive
    if not steered.any():
        return out, False
    pose, integral, beta, _ = split(x)
    twist, _ = controller(t, pose, integral)
    ik = checked_rates(sim.robot, twist, beta)
    cmd = sim.commands(twist, beta, HOLD_MARGIN, ik)
    target = cmd.target
    out[:len(beta)][steered] = target[steered]
    if not sim.limited or cmd.fits.all():  # the margin only picks an end for a wheel that fits no root
        return out, False
    held = sim.commands(twist, beta, ik=ik).target  # within a step: held wheels stay at their ends
    return out, bool(np.any(np.abs(wrap_angle(target - held))[steered] > 1e-9))


def _record(controller, sim: _Sim, t: float, x: np.ndarray, split) -> dict:
    pose, integral, beta, _ = split(x)
    twist, _ = controller(t, pose, integral)
    check_diverged(twist, t)
    return _record_held(sim, t, x, split, twist, beta)


def _record_held(sim: _Sim, t: float, x: np.ndarray, split, twist: np.ndarray, prev: np.ndarray) -> dict:
    pose, _, beta, ls = split(x)
    beta = np.where(sim.passive, beta, prev)  # castors: integrated state; steered wheels: the last angle given
    cmd = sim.commands(twist, beta)
    actual = sim.actual_beta(cmd.target, beta, ls)
    return {"t": t, "pose": pose.copy(), "twist": np.asarray(twist, dtype=float), "beta": actual,
            "target": cmd.target, "in_range": cmd.fits}
