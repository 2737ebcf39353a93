"""The runs of :func:`~wmrkit.dynamics.simulate.simulate`: fixed-step (compiled, chunked, a ``tqdm`` bar on long
runs) and adaptive (scipy's LSODA, at most :data:`MAX_EVALUATIONS` evaluations), their records, and the lift-off
check both make."""

from __future__ import annotations

import bisect
import math
from collections import deque

import numpy as np

from ..errors import WmrkitError
from .model import DynamicModel


class LiftOffError(WmrkitError):
    """A wheel loaded at rest lost its load: the run stops there (:func:`check_lift_off`). ``what`` states it
    (contact, time, load at rest), ``t`` its time [s], ``contact`` its name; the message adds what to change, which a
    caller may replace."""

    def __init__(self, what: str, advice: str = "use smaller torques or speeds", t: float = math.nan,
                 contact: str = "") -> None:
        self.what, self.advice, self.t, self.contact = what, advice, t, contact
        super().__init__(f"{what}; {advice}")


class DivergedError(WmrkitError):
    """A fixed-step run whose state overflowed before ``t`` [s] (:class:`~wmrkit.dynamics.simulate.Stepper`)."""

    def __init__(self, message: str, t: float) -> None:
        self.t = t
        super().__init__(message)


def check_lift_off(model: DynamicModel, w: tuple) -> None:
    """Refuse a run in which a wheel loaded at rest lost its load (lifts off), as the integrator's work arrays `w`
    recorded it: the planar model clips the load at 0 and keeps the wheel down, so the motion that follows is not
    physical (with friction)."""
    lift = w[16]
    if lift[0]:
        e = int(lift[2])
        raise LiftOffError(f"contact '{model.contacts[e]}' lifts off the ground at t = {lift[1]:.6g} s (normal load "
                           f"0; {model.normal_loads()[e]:.4g} N at rest): the planar model keeps every wheel on the "
                           "ground, so the motion would not be physical", t=float(lift[1]), contact=model.contacts[e])


def records(model: DynamicModel, n_rec: int) -> tuple:
    """Zeroed record arrays of `n_rec` samples: time, state, contact forces, loads, slip velocities and speeds,
    joint torques (:func:`._integrate.observe` fills them)."""
    e = len(model.contacts)
    return (np.zeros(n_rec), np.zeros((n_rec, 2 * model.n)), np.zeros((n_rec, e, 2)), np.zeros((n_rec, e)),
            np.zeros((n_rec, e, 2)), np.zeros((n_rec, e)), np.zeros((n_rec, model.n)))


def fixed_run(model, s0, inp, duration, step, every, method, progress, jac_every, allow_lift_off):
    """`duration` [s] from state `s0` in compiled fixed steps (`method` 0: semi-implicit, 1: rk4), recording every
    `every` steps, in chunks (a ``tqdm`` bar on long runs); ``(records, info)``. A run that stops (a lift-off, a
    divergence) is re-checked at a shorter step (:func:`_stop`)."""
    from ._integrate import model_work_arrays, observe, run

    n_steps = round(duration / step)
    rec = records(model, n_steps // every + 1)
    w = model_work_arrays(model)
    s, acc = s0.copy(), np.zeros(model.n)
    observe(0.0, s, acc, model.pack, inp, w, rec, 0)
    i, done = 1, 0
    chunk = max(every, (n_steps // 200) // every * every) if n_steps >= 500_000 or progress else n_steps
    bar = None
    if progress or (progress is None and n_steps >= 500_000):
        from tqdm import tqdm

        bar = tqdm(total=n_steps, unit="step", desc="simulate", leave=False)
    while done < n_steps:
        k = min(chunk, n_steps - done)
        i = run(s, done, step, k, every, method, jac_every, acc, model.pack, inp, w, rec, i)
        done += k
        if bar is not None:
            bar.update(k)
        diverged = not np.all(np.isfinite(s))
        if diverged or (w[16][0] and not allow_lift_off):
            if bar is not None:
                bar.close()
            _stop(model, tuple(r[:i] for r in rec), inp, w, done * step, duration, step, method, jac_every,
                  allow_lift_off, diverged)
    if bar is not None:
        bar.close()
    return tuple(r[:i] for r in rec), {"steps": n_steps}


#: Most semi-implicit steps of the re-check of a fixed-step run that stopped (:func:`_stop`; a quarter as many rk4
#: steps): about 3 s of computing for the forklift.
RECHECK_STEPS = 1_000_000
#: Longest step [s] of that re-check, by method (0: semi-implicit, 1: rk4): the steps docs/dynamics.md finds stable
#: with the catalog's stiff tyres.
RECHECK_MAX_STEP = (1e-3, 1e-4)


def recheck_step(step: float, method: int) -> float:
    """The step of the re-check of a fixed-step run at `step` [s] that stopped: a whole fraction of it, at most a
    quarter and at most :data:`RECHECK_MAX_STEP` (so that the re-check restarts on the run's own records' times)."""
    return step / max(4, math.ceil(step / RECHECK_MAX_STEP[method] * (1 - 1e-9)))


def recheck_budget(method: int) -> int:
    """Most steps of a re-check by `method` (0: semi-implicit, 1: rk4, whose step evaluates the model four times)."""
    return RECHECK_STEPS // (1 + 3 * method)


def _stop(model, rows, inp, w, t_run, duration, step, method, jac_every, allow_lift_off, diverged):
    """Raise the error of a fixed-step run that stopped at `t_run` [s] (diverged, or the lift-off `w` recorded),
    after re-running the stretch that led there at :func:`recheck_step`: from the first of the records `rows` at
    most :data:`RECHECK_STEPS` of those steps before its end (at the latest the last one before the stop) to
    ``max(0.1 s, 10 steps)`` past the stop (or the run's end). The stop is the robot's (or its inputs') when the
    shorter step stops too; when it does not, the step was too long for the tyres and the error says so (the load
    transfer lags a step and the tyres saturate within one, which the implicit step does not cover: the forklift's
    rectangle 'lifted off' its steered wheel from 8 ms; docs/dynamics.md)."""
    t_stop = t_run if diverged else float(w[16][1])
    fine = recheck_step(step, method)
    k_end = round(min(duration, recheck_end(t_stop, step)) / fine)
    budget = recheck_budget(method)
    j = min(int(np.searchsorted(rows[0], (k_end - budget) * fine)),  # the first record in the budget, and at
            max(0, int(np.searchsorted(rows[0], t_stop)) - 1))  # the latest the last one before the stop
    k0 = round(rows[0][j] / fine)  # a record's time is a whole number of steps, each a whole number of fine ones
    if goes_on(model, rows[1][j], [(k0, k_end - k0, inp)], fine, method, jac_every, allow_lift_off):
        raise unstable_step(stop_phrase(model, w, t_stop, diverged), step, fine, k_end * fine,
                            "(--step) or the adaptive method")
    if diverged:
        raise WmrkitError(f"the simulation diverged before t = {t_run:.6g} s; use a smaller --step (or smaller "
                          "torques or speeds)")
    check_lift_off(model, w)


def recheck_end(t_stop: float, step: float) -> float:
    """The time [s] a re-check of a run at `step` that stopped at `t_stop` runs to: ``max(0.1 s, 10 steps)`` past."""
    return t_stop + max(0.1, 10 * step)


def goes_on(model: DynamicModel, s: np.ndarray, stretch: list, fine: float, method: int, jac_every: int,
            allow_lift_off: bool) -> bool:
    """Whether a fresh integrator run from state `s` (not changed) at step `fine` [s] through `stretch`, the
    consecutive pieces ``(k0, steps, compiled inputs)`` counted in steps of `fine`, neither diverges nor (unless
    `allow_lift_off`) lifts a wheel off: the re-check of a stop (:func:`_stop`, :meth:`StepLog.recheck`)."""
    from ._integrate import model_work_arrays, run

    s, acc, w, rec = s.copy(), np.zeros(model.n), model_work_arrays(model), records(model, 0)
    for k0, steps, inp in stretch:
        run(s, k0, fine, steps, 1 << 62, method, jac_every, acc, model.pack, inp, w, rec, 0)
        if not np.all(np.isfinite(s)) or (w[16][0] and not allow_lift_off):
            return False
    return True


def stop_phrase(model: DynamicModel, w: tuple, t_stop: float, diverged: bool) -> str:
    """What stopped a fixed-step run at `t_stop` [s]: it diverged, or the lift-off the work arrays `w` recorded."""
    return (f"the simulation diverged before t = {t_stop:.6g} s" if diverged else
            f"contact '{model.contacts[int(w[16][2])]}' lost its load at t = {t_stop:.6g} s")


def unstable_step(what: str, step: float, fine: float, t_end: float, where: str, rerun: str = "a run") -> WmrkitError:
    """The error of a fixed-step run at `step` [s] that stopped (`what`: :func:`stop_phrase`) where a re-check,
    `rerun` at `fine` [s], went on to `t_end` [s]: the step's, not the robot's; `where` says how to set the step."""
    return WmrkitError(f"{what} at step {step:g} s, but {rerun} at step {fine:.3g} s goes on to t = {t_end:.6g} s "
                       "without it: the step is too long for the tyres (the integration is unstable, not the robot); "
                       f"use a step of at most {fine:.3g} s {where}")


class StepLog:
    """What a :class:`~wmrkit.dynamics.simulate.Stepper` advanced through, to re-check a stop as :func:`_stop` does:
    its pieces ``(k0, steps, state at k0, compiled inputs)`` (in its steps; each at most ``span`` of them) over its
    last :func:`recheck_budget` steps of :func:`recheck_step` (older ones are dropped)."""

    def __init__(self, step: float, method: int) -> None:
        self.fine = recheck_step(step, method)
        self.ratio = round(step / self.fine)
        self.span = max(1, recheck_budget(method) // self.ratio)
        self.pieces: deque = deque()

    def add(self, k0: int, steps: int, state: np.ndarray, inp: tuple) -> int:
        """Log the next piece of a run of `steps` steps from step `k0` at `state` (copied) with the compiled inputs
        `inp` (which the stepper no longer changes): at most ``span`` steps, how many it returns. Drops the pieces
        that start more than ``span`` steps before its end."""
        steps, pieces = min(steps, self.span), self.pieces
        pieces.append((k0, steps, state.copy(), inp))
        while pieces[0][0] < k0 + steps - self.span:
            pieces.popleft()
        return steps

    def recheck(self, model: DynamicModel, w: tuple, t_now: float, step: float, method: int, jac_every: int,
                allow_lift_off: bool, diverged: bool) -> None:
        """Raise :func:`unstable_step` when the stepper stopped at `t_now` [s] (diverged, or the lift-off `w`
        recorded), and its logged inputs, run again at :func:`recheck_step` from the logged state at most
        :func:`recheck_budget` of those steps before :func:`recheck_end` (at the latest the last piece before the
        stop), the last inputs held past `t_now`, go on without it."""
        t_stop = t_now if diverged else float(w[16][1])
        r, fine, pieces = self.ratio, self.fine, list(self.pieces)
        k_end = round(recheck_end(t_stop, step) / fine)
        starts = [piece[0] for piece in pieces]
        j = min(bisect.bisect_left(starts, -(-(k_end - recheck_budget(method)) // r)),
                max(0, bisect.bisect_left(starts, round(t_stop / step)) - 1))
        stretch = [(k0 * r, min(steps * r, k_end - k0 * r), inp) for k0, steps, _, inp in pieces[j:]
                   if k0 * r < k_end]
        last = pieces[-1]
        tail = (last[0] + last[1]) * r
        if tail < k_end:
            stretch.append((tail, k_end - tail, last[3]))
        if goes_on(model, pieces[j][2], stretch, fine, method, jac_every, allow_lift_off):
            raise unstable_step(stop_phrase(model, w, t_stop, diverged), step, fine, k_end * fine,
                                "(the step argument)", "a run of its inputs")


#: Most evaluations of the model an adaptive run makes (LSODA, 10-15 us each: about 2 min; the forklift's 22 s
#: rectangle takes about 7e6): without it a long run, or a discontinuous tyre law, integrated for hours.
MAX_EVALUATIONS = 10_000_000


class _OverBudget(Exception):
    """Raised by the adaptive run's right-hand side beyond :data:`MAX_EVALUATIONS` (args: the time reached)."""


def adaptive_samples(duration: float, record: float) -> int:
    """Samples of an adaptive run: the multiples of `record` within `duration` (as the fixed steps record them;
    rounding to the nearest one integrated up to half a record step past the duration)."""
    return math.floor(duration / record * (1 + 1e-12)) + 1


def adaptive_run(model, s0, inp, duration, record, rtol, allow_lift_off):
    """`duration` [s] from state `s0` with scipy's LSODA at `rtol`, recorded every `record` s, at most
    :data:`MAX_EVALUATIONS` evaluations of the model; ``(records, info)``."""
    from scipy.integrate import solve_ivp

    from ._integrate import derivative, model_work_arrays, observe

    w = model_work_arrays(model)
    acc = np.zeros(model.n)
    t_eval = record * np.arange(adaptive_samples(duration, record))  # the multiples within the duration
    ts, ys, evaluations = t_eval, s0[:, None], 0  # one sample (record > duration): t = 0, as the fixed steps
    if len(t_eval) > 1:
        calls = [0]

        def rhs(t, s):
            calls[0] += 1
            if calls[0] > MAX_EVALUATIONS:
                raise _OverBudget(t)
            return derivative(t, np.ascontiguousarray(s), acc, model.pack, inp, w)

        try:
            sol = solve_ivp(rhs, (0.0, t_eval[-1]), s0, method="LSODA", t_eval=t_eval, rtol=rtol, atol=rtol * 1e-3)
        except ZeroDivisionError:  # the compiled kernels raise it where the state has overflowed
            raise WmrkitError("the adaptive integration diverged (the state overflowed)") from None
        except _OverBudget as e:
            raise WmrkitError(f"the adaptive integration needed more than {MAX_EVALUATIONS:.0e} evaluations of the "
                              f"model by t = {e.args[0]:.6g} s of {duration:g} s (stiff or discontinuous tyres, or a "
                              "long run); use the semi-implicit method or a shorter duration") from None
        if not sol.success:
            raise WmrkitError(f"the adaptive integration failed: {sol.message}")
        ts, ys, evaluations = sol.t, sol.y, int(sol.nfev)
    rec = records(model, len(ts))
    w[16][:] = 0.0  # lift-off judged on the accepted states only (not on the solver's trial evaluations)
    for i, (t, s) in enumerate(zip(ts, ys.T, strict=True)):
        derivative(t, np.ascontiguousarray(s), acc, model.pack, inp, w)
        observe(t, np.ascontiguousarray(s), acc, model.pack, inp, w, rec, i)
    if not allow_lift_off:
        check_lift_off(model, w)
    return rec, {"evaluations": evaluations}
