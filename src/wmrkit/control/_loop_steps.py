"""How the kinematic loop (:mod:`.loop`) advances and records: the refusals of a diverged law, the sampled
loop's held period (:func:`_advance`), the continuous loop's RK45 with the held wheels' end switches as events
(:func:`_integrate`), and each record."""

from __future__ import annotations

import itertools

import numpy as np

from ..kinematics.loop_ik import checked_rates
from ..limits import MAX_QUERY_RATE, MAX_SPEED
from ..wheels import wrap_angle
from ._loop_plant import HOLD_MARGIN, _Sim
from .points import ControlError, StoppedRun

#: What to change when a loop's law diverges (its commands grow without bound).
LAW_ADVICE = "lower the gain or the period"


def check_command(twist: np.ndarray, t: float) -> None:
    """Refuse a law's twist beyond ``limits.MAX_SPEED`` (m/s, rad/s) at `t`: a loop through the dynamics has
    diverged (the plant would be driven far outside any robot's envelope, slowly and meaninglessly)."""
    if not np.all(np.abs(twist) <= MAX_SPEED):  # NaN included
        raise StoppedRun(f"the loop diverged: at t = {t:.6g} s the law commands the twist "
                         f"{tuple(float(v) for v in twist)}, beyond {MAX_SPEED:g} m/s or rad/s; {LAW_ADVICE}", t)


def check_diverged(twist: np.ndarray, t: float, sampled: bool = True) -> None:
    """Refuse a law's twist beyond ``limits.MAX_QUERY_RATE`` at `t` in a kinematic loop: no wheel command is defined
    there (:func:`wheel_commands` refuses it), the loop has diverged. Not `sampled` (a continuous loop): no period
    to lower."""
    if not all(abs(v) <= MAX_QUERY_RATE for v in np.asarray(twist, dtype=float).tolist()):  # NaN included; floats
        raise StoppedRun(f"the closed loop diverged at t = {t:.6g} s: the law commands the twist "
                         f"{tuple(float(v) for v in twist)}, beyond {MAX_QUERY_RATE:g} m/s or rad/s; "
                         f"{LAW_ADVICE if sampled else 'lower the gain'}", t)

#: Bisections locating the instant a held wheel changes ends in the continuous loop (to 2**-40 of a step).
SWITCH_BISECTIONS = 40


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
    if sim.plain:  # the IK's angles, nothing held
        out[:len(beta)][steered] = sim.targets(twist, beta)[0][steered]
        return out, False
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
    check_diverged(twist, t, sampled=False)  # the continuous loop's records
    return _record_held(sim, t, x, split, twist, beta)


def _record_held(sim: _Sim, t: float, x: np.ndarray, split, twist: np.ndarray, prev: np.ndarray) -> dict:
    pose, _, beta, ls = split(x)
    beta = np.where(sim.passive, beta, prev)  # castors: integrated state; steered wheels: the last angle given
    target, fits = sim.targets(twist, beta)
    actual = sim.actual_beta(target, beta, ls)
    out = {"t": t, "pose": pose.copy(), "twist": np.asarray(twist, dtype=float), "beta": actual,
           "target": target, "in_range": fits}
    if sim.plant.loops is None:  # the ideal plant: the twist its wheels move it with (the loops add their lag)
        out["moved"] = sim.realised(out["twist"], actual)[0]
    return out
