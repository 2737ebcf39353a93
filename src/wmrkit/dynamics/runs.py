"""The runs of :func:`~wmrkit.dynamics.simulate.simulate`: fixed-step (compiled, chunked, a ``tqdm`` bar on long
runs) and adaptive (scipy's LSODA, at most :data:`MAX_EVALUATIONS` evaluations), their records, and the lift-off
check both make; the re-check of a fixed step's stop at a shorter step (:func:`judge`)."""

from __future__ import annotations

import bisect
import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from ..errors import WmrkitError
from ..limits import MAX_SPEED
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
    """A fixed-step run whose state overflowed before ``t`` [s] (:class:`~wmrkit.dynamics.simulate.Stepper`).
    ``what`` states the stop without the message's advice, which a caller may replace (default: the state diverged
    before ``t``)."""

    def __init__(self, message: str, t: float, what: str = "") -> None:
        self.t, self.what = t, what or Stop.diverged(t).what
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
    divergence, a recorded state out of the physical range: :func:`first_escape`, as the adaptive run stops) is
    re-checked at a shorter step (:func:`_stop`)."""
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
    lever = levers(model, s0[list(model.steer_columns)])
    while done < n_steps:
        k, i0 = min(chunk, n_steps - done), i
        i = run(s, done, step, k, every, method, jac_every, acc, model.pack, inp, w, rec, i)
        done += k
        if bar is not None:
            bar.update(k)
        diverged = not np.all(np.isfinite(s))
        far = first_escape(model, lever, rec[0][i0:i], rec[1][i0:i], done * step, s)
        if diverged or far is not None or lifted(w, allow_lift_off):
            if bar is not None:
                bar.close()
            _stop(model, tuple(r[:i] for r in rec), inp, w, done * step, duration, step, method, jac_every,
                  allow_lift_off, far)
    if bar is not None:
        bar.close()
    return tuple(r[:i] for r in rec), {"steps": n_steps}


#: Most semi-implicit steps of the re-check of a fixed-step run that stopped (:func:`_stop`; a quarter as many rk4
#: steps): about 3 s of computing for the forklift.
RECHECK_STEPS = 1_000_000
#: Longest step [s] of that re-check, by method (0: semi-implicit, 1: rk4): the steps docs/dynamics.md finds stable
#: with the catalog's stiff tyres.
RECHECK_MAX_STEP = (1e-3, 1e-4)
#: How a caller of :func:`~wmrkit.dynamics.simulate.simulate` sets the step, as its stop's errors say it (their
#: ``where``; another door says it its own way: :func:`at_door`).
SIMULATE_STEP = "(the step keyword) or method='adaptive'"

# The re-check of a stop, in three parts: where the run stopped (a Stop), a shorter step run again over its end
# (rerun_stop: another Stop, or None), and the verdict on the two (judge, given a Recheck).


def recheck_step(step: float, method: int) -> float:
    """The step of the re-check of a fixed-step run at `step` [s] that stopped: a whole fraction of it, at most a
    quarter and at most :data:`RECHECK_MAX_STEP` (so that the re-check restarts on the run's own records' times)."""
    return step / max(4, math.ceil(step / RECHECK_MAX_STEP[method] * (1 - 1e-9)))


def recheck_budget(method: int) -> int:
    """Most steps of a re-check by `method` (0: semi-implicit, 1: rk4, whose step evaluates the model four times)."""
    return RECHECK_STEPS // (1 + 3 * method)


def recheck_end(t_stop: float, step: float) -> float:
    """``max(0.1 s, 10 steps)`` past the stop `t_stop` [s] of a run at `step` [s]: a re-check that stops by then
    reproduces that stop (:func:`judge`), and a :class:`StepLog`'s re-check runs at least to it."""
    return t_stop + max(0.1, 10 * step)


@dataclass(frozen=True)
class Stop:
    """Where a fixed-step run stopped: at ``t`` [s], ``what`` stopped it (in words, with its time), and for a
    lift-off the ``contact`` that lost its load (empty: the state, or a loop's command, diverged); ``whose`` stop it
    is when a shorter step reproduces it (a loop's law diverging is the loop's, not the robot's)."""

    t: float
    what: str
    contact: str = ""
    whose: str = "the robot's"

    @classmethod
    def diverged(cls, t: float) -> Stop:
        """The state diverged before `t` [s]."""
        return cls(t, f"the simulation diverged before t = {t:.6g} s")

    @classmethod
    def lift_off(cls, t: float, contact: str) -> Stop:
        """`contact` lost its load at `t` [s]."""
        return cls(t, f"contact '{contact}' lost its load at t = {t:.6g} s", contact)

    @classmethod
    def escaped(cls, t: float, why: str) -> Stop:
        """The state left the physical range at `t` [s] (:func:`escaped` says `why`)."""
        return cls(t, f"the simulation left the physical range at t = {t:.6g} s ({why})")

    @classmethod
    def of_run(cls, model: DynamicModel, w: tuple, t_run: float, allow_lift_off: bool,
               far: tuple[float, str] | None = None) -> Stop:
        """The stop of a run advanced to `t_run` [s]: the lift-off that its work arrays `w` recorded (unless
        `allow_lift_off`), which comes first when the state diverged later in the same run (:func:`lifted`), or the
        state out of the physical range at ``far = (t, why)`` (:func:`first_escape`), or the divergence before
        `t_run`."""
        if lifted(w, allow_lift_off):
            return cls.lift_off(float(w[16][1]), model.contacts[int(w[16][2])])
        return cls.diverged(t_run) if far is None else cls.escaped(*far)


def lifted(w: tuple, allow_lift_off: bool) -> bool:
    """Whether a run stops at the lift-off its work arrays `w` recorded (unless `allow_lift_off`): before a state
    diverges, the loads of the motion leading there empty a wheel (1e9 N m on a 0.1 kg robot lifts a wheel off at
    the first step and overflows the state later), and the lift-off says why, with the advice that fits."""
    return bool(w[16][0]) and not allow_lift_off


@dataclass(frozen=True)
class Recheck:
    """A stop's re-check: the run's ``step`` and the re-run's ``fine`` step [s] (``rerun`` names the re-run in the
    error: "a run", "the same loop"); where the re-run stopped (``stop``; None: it did not); how far it went
    (``reached`` [s]) of the ``end`` [s] it was to reach (-inf: no end to judge it by)."""

    step: float
    fine: float
    stop: Stop | None
    reached: float
    end: float
    rerun: str = "a run"


def judge(stop: Stop, check: Recheck, where: str) -> WmrkitError | None:
    """The verdict on a fixed-step run's `stop` given its re-check `check`, as the error to raise:

    - None when the re-run stops too, by :func:`recheck_end`: the stop is the robot's (the caller raises it);
    - an :class:`UnstableStepError` when the re-run goes on to its end: the step's (the integration is unstable, not
      the robot); or, when it went on but fell short of ``check.end`` (its budget ended first), not known;
    - when the re-run stops only later, the robot's later stop, which the step brought early: a
      :class:`LiftOffError` (or :class:`DivergedError`) at the re-run's time, naming both stops.

    `where` says how to set the step (each error's ``where``, for :func:`at_door`)."""
    step, fine, rerun, later = check.step, check.fine, check.rerun, check.stop
    if later is None and check.reached < check.end * (1 - 1e-12):
        return UnstableStepError(
            f"{stop.what} at step {step:g} s; {rerun} at step {fine:.3g} s goes on without it to t = "
            f"{check.reached:.6g} s, where the re-check's budget ends, short of the end at t = {check.end:.6g} s: "
            "whether the step (the integration unstable) or the robot stops it is not known", fine, where,
            conclusive=False)
    if later is None:
        return UnstableStepError(f"{stop.what} at step {step:g} s, but {rerun} at step {fine:.3g} s goes on to t = "
                                 f"{check.reached:.6g} s without it: the step is too long for the tyres (the "
                                 "integration is unstable, not the robot)", fine, where)
    if later.t <= recheck_end(stop.t, step):
        return None
    head = (f"{stop.what} at step {step:g} s, but {rerun} at step {fine:.3g} s goes on without it until "
            f"{later.what}: {later.whose} stop, which the step brought early")
    advice = f"use smaller torques or speeds, and a step of at most {fine:.3g} s {where}"
    err = (LiftOffError(head, advice, later.t, later.contact) if later.contact else
           DivergedError(f"{head}; {advice}", later.t, head))
    err.where = where
    return err


def rerun_stop(model: DynamicModel, s: np.ndarray, stretch: list, fine: float, method: int, jac_every: int,
               allow_lift_off: bool, lever: np.ndarray | None = None) -> Stop | None:
    """Where a fresh integrator run from state `s` (not changed) at step `fine` [s] through `stretch`, the
    consecutive pieces ``(k0, steps, compiled inputs)`` counted in steps of `fine`, stops: None when it neither
    diverges nor (unless `allow_lift_off`) lifts a wheel off, nor, given the :func:`levers` `lever`, leaves the
    physical range (judged every :data:`ESCAPE_CHECK` s) (the re-run of :func:`_stop`, :meth:`StepLog.recheck`)."""
    from ._integrate import model_work_arrays, run

    s, acc, w, rec = s.copy(), np.zeros(model.n), model_work_arrays(model), records(model, 0)
    every = (1 << 62) if lever is None else max(1, round(ESCAPE_CHECK / fine))
    for k0, steps, inp in stretch:
        for k in range(k0, k0 + steps, every):  # in pieces: the same steps (_integrate.run)
            run(s, k, fine, min(every, k0 + steps - k), 1 << 62, method, jac_every, acc, model.pack, inp, w, rec, 0)
            t = min(k + every, k0 + steps) * fine
            why = "" if lever is None else escaped(model, lever, s)
            if not np.all(np.isfinite(s)) or lifted(w, allow_lift_off):
                return Stop.of_run(model, w, t, allow_lift_off)
            if why:
                return Stop.escaped(t, why)
    return None


#: How often [s] the re-check of a fixed-step run that left the physical range judges its state (:func:`rerun_stop`).
ESCAPE_CHECK = 0.01
#: How often [s] a :class:`~wmrkit.dynamics.simulate.Stepper` judges its state's range within one advance (it
#: records no states; every ESCAPE_CHECK made a 10 s advance of a 1 kHz run five times as long).
RANGE_CHECK = 0.1


def first_escape(model: DynamicModel, lever: np.ndarray, t: np.ndarray, states: np.ndarray, t_run: float,
                 s: np.ndarray) -> tuple[float, str] | None:
    """``(time [s], why)`` of the first of the recorded `states` ``(N, 2n)`` at times `t` ``(N,)``, else of the
    state `s` at `t_run` [s], that is finite and out of the physical range (:func:`escaped`); None when none is (a
    state that is not finite first: the run diverged)."""
    for time, state in ((t, states), (np.array([t_run]), s[None])):
        speed = np.abs(state[:, model.n:]) * lever
        finite = np.isfinite(speed).all(axis=1)
        out = np.flatnonzero(~finite | (speed > MAX_SPEED).any(axis=1))
        if len(out):
            return (float(time[out[0]]), escaped(model, lever, state[out[0]])) if finite[out[0]] else None
    return None


def _stop(model, rows, inp, w, t_run, duration, step, method, jac_every, allow_lift_off, far=None):
    """Raise the error of a fixed-step run that stopped at `t_run` [s] (the lift-off `w` recorded, or diverged),
    after re-running it at :func:`recheck_step` to its end (`duration`): from the first of the records `rows` at
    most :func:`recheck_budget` of those steps before the end (at the latest the last one before the stop), for at
    most that many steps, and judged (:func:`judge`). To the end, not a margin past the stop: a shorter step can
    reach the robot's own lift-off much later (the forklift's arc-line at 2 m/s: 2.40 s at 1 ms, 2.52 s at 0.25 ms);
    a step too long for the tyres 'lifts off' the forklift's steered wheel on its rectangle at 25 ms (the load
    transfer lags a step: docs/dynamics.md). `far`: where a recorded state left the physical range
    (:func:`first_escape`), judged so."""
    stop = Stop.of_run(model, w, t_run, allow_lift_off, far)
    fine, budget = recheck_step(step, method), recheck_budget(method)
    k_end = round(duration / step) * round(step / fine)  # the run's end, in fine steps
    j = min(int(np.searchsorted(rows[0], (k_end - budget) * fine)),  # the first record in the budget, and at
            max(0, int(np.searchsorted(rows[0], stop.t)) - 1))  # the latest the last one before the stop
    k0 = round(rows[0][j] / fine)  # a record's time is a whole number of steps, each a whole number of fine ones
    k_last = min(k_end, k0 + budget)
    lever = levers(model, rows[1][0][list(model.steer_columns)])
    again = rerun_stop(model, rows[1][j], [(k0, k_last - k0, inp)], fine, method, jac_every, allow_lift_off, lever)
    error = judge(stop, Recheck(step, fine, again, k_last * fine, k_end * fine), SIMULATE_STEP)
    if error is not None:
        raise error
    if lifted(w, allow_lift_off):
        check_lift_off(model, w)
    if far is not None:
        raise WmrkitError(f"{stop.what}; use smaller torques or speeds")
    err = WmrkitError(f"the simulation diverged before t = {t_run:.6g} s; use a smaller step {SIMULATE_STEP} (or "
                      "smaller torques or speeds)")
    err.where = SIMULATE_STEP
    raise err


def at_door(err: WmrkitError, where: str) -> WmrkitError:
    """`err` saying how to set the step as `where` (the CLI's option) where it says its ``where`` (an error of a
    stop's re-check: :func:`judge`, :func:`_stop`); any other error as it is."""
    said = getattr(err, "where", "")
    return WmrkitError(str(err).replace(said, where)) if said else err


class UnstableStepError(WmrkitError):
    """A fixed-step run stopped where a re-check at the shorter step `fine` [s] went on (:func:`judge`): ``head``
    says so, ``conclusive`` whether that re-check reached the run's end (else its budget ended first); the message
    ends with what to do: a step of at most `fine` set as `where` says (a door whose user sets it otherwise, or not
    at all, says so instead: :meth:`advised`)."""

    def __init__(self, head: str, fine: float, where: str, conclusive: bool = True, advice: str = "") -> None:
        self.head, self.fine, self.conclusive, self.where = head, fine, conclusive, where
        tell = "" if conclusive else " to tell, or smaller torques or speeds"
        super().__init__(f"{head}; {advice or f'use a step of at most {fine:.3g} s {where}{tell}'}")

    def advised(self, advice: str) -> UnstableStepError:
        """The same error ending with `advice` (what the door's user can change) after its ``head``."""
        return UnstableStepError(self.head, self.fine, "", self.conclusive, advice)


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
                allow_lift_off: bool, far: tuple[float, str] | None = None,
                lever: np.ndarray | None = None) -> None:
        """Raise :func:`judge`'s error when the stepper stopped at `t_now` [s] (diverged, the lift-off `w`
        recorded, or its state out of the physical range at ``far``: :func:`first_escape`, which the re-run judges
        too given the :func:`levers` `lever`), after its logged inputs are run again at :func:`recheck_step` from
        the logged state at most :func:`recheck_budget` of those steps before their end (at the latest the last
        piece before the stop), for at most that many steps; return when the re-run reproduces the stop. Their end:
        the last inputs' last knot (the program given), at least `t_now` (the run asked for) and at least
        :func:`recheck_end` (held past it: a guess of what comes next, a loop's)."""
        stop = Stop.of_run(model, w, t_now, allow_lift_off, far)
        r, fine, pieces, budget = self.ratio, self.fine, list(self.pieces), recheck_budget(method)
        last = pieces[-1]
        k_end = round(max(t_now, float(last[3][0][-1]), recheck_end(stop.t, step)) / fine)
        starts = [piece[0] for piece in pieces]
        j = min(bisect.bisect_left(starts, -(-(k_end - budget) // r)),
                max(0, bisect.bisect_left(starts, round(stop.t / step)) - 1))
        k_last = min(k_end, starts[j] * r + budget)
        stretch = [(k0 * r, min(steps * r, k_last - k0 * r), inp) for k0, steps, _, inp in pieces[j:]
                   if k0 * r < k_last]
        tail = (last[0] + last[1]) * r
        if tail < k_last:
            stretch.append((tail, k_last - tail, last[3]))
        again = rerun_stop(model, pieces[j][2], stretch, fine, method, jac_every, allow_lift_off, lever)
        error = judge(stop, Recheck(step, fine, again, k_last * fine, k_end * fine, "a run of its inputs"),
                      "(the step argument)")
        if error is not None:
            raise error


#: Most evaluations of the model an adaptive run makes (LSODA, 10-15 us each: about 2 min; the forklift's 22 s
#: rectangle takes about 7e6): without it a long run, or a discontinuous tyre law, integrated for hours.
MAX_EVALUATIONS = 10_000_000


class _OverBudget(Exception):
    """Raised by the adaptive run's right-hand side beyond :data:`MAX_EVALUATIONS` (args: the time reached)."""


def adaptive_samples(duration: float, record: float) -> int:
    """Samples of an adaptive run: the multiples of `record` within `duration` (as the fixed steps record them;
    rounding to the nearest one integrated up to half a record step past the duration)."""
    return math.floor(duration / record * (1 + 1e-12)) + 1


def levers(model: DynamicModel, beta: np.ndarray) -> np.ndarray:
    """``(n,)`` [m]: how fast a unit of each velocity column moves a point of the robot: 1 for vx, vy; the robot's
    reach for omega; a joint's largest entry of the slip matrix at the steering `beta` (a wheel's radius, a
    castor's offset), else the reach (:func:`escaped`)."""
    from ..kinematics.linalg import reach

    lever = np.abs(model.slip_matrix(beta)).max(axis=0)
    lever[:2], lever[2] = 1.0, reach(model.robot)
    lever[3:][lever[3:] == 0.0] = lever[2]
    return lever


def escaped(model: DynamicModel, lever: np.ndarray, s: np.ndarray) -> str:
    """Why the state `s` is outside the physical range (a velocity column times its :func:`levers` beyond
    :data:`~wmrkit.limits.MAX_SPEED`, or not finite), or ``""``."""
    speed = np.abs(s[model.n:]) * lever
    c = int(np.argmax(np.where(np.isfinite(speed), speed, np.inf)))
    if speed[c] <= MAX_SPEED:
        return ""
    unit = "m/s" if c < 2 else "rad/s"
    return (f"{model.names[c]} = {abs(s[model.n + c]):.3g} {unit} moves a point of the robot at {speed[c]:.3g} m/s, "
            f"beyond {MAX_SPEED:g} m/s (limits.MAX_SPEED)")


def adaptive_run(model, s0, inp, duration, record, rtol, allow_lift_off):
    """`duration` [s] from state `s0` with scipy's LSODA at `rtol`, recorded every `record` s, at most
    :data:`MAX_EVALUATIONS` evaluations of the model; ``(records, info)``. Its accepted states are checked as they
    come: a recorded sample that lifts a wheel off (unless `allow_lift_off`) stops it, and so does a state that
    leaves the physical range (:func:`escaped`; first the earliest accepted state since the last sample that lifts a
    wheel off): beyond it round-off in the forces outgrows the tolerance and the steps collapse (1e9 N m on a 0.1 kg
    robot spun it at 2.3e6 rad/s, and LSODA took 1e-9 s steps through its budget, 3 min)."""
    from scipy.integrate import LSODA

    from ._integrate import derivative, model_work_arrays, observe

    w, w_rec = model_work_arrays(model), model_work_arrays(model)
    acc, acc_rec = np.zeros(model.n), np.zeros(model.n)
    t_eval = record * np.arange(adaptive_samples(duration, record))  # the multiples within the duration
    rec = records(model, len(t_eval))

    def sample(t, s, i=-1):  # an accepted state's evaluation (the lift-off judged on these only), recorded at row i
        s = np.ascontiguousarray(s)
        derivative(t, s, acc_rec, model.pack, inp, w_rec)
        if i >= 0:
            observe(t, s, acc_rec, model.pack, inp, w_rec, rec, i)
        if not allow_lift_off:
            check_lift_off(model, w_rec)

    sample(0.0, s0, 0)  # one sample (record > duration): t = 0, as the fixed steps
    if len(t_eval) == 1:
        return rec, {"evaluations": 0}
    calls, lever = [0], levers(model, s0[list(model.steer_columns)])

    def rhs(t, s):
        calls[0] += 1
        if calls[0] > MAX_EVALUATIONS:
            raise _OverBudget(t)
        return derivative(t, np.ascontiguousarray(s), acc, model.pack, inp, w)

    solver, i, since = LSODA(rhs, 0.0, s0, t_eval[-1], rtol=rtol, atol=rtol * 1e-3), 1, []
    try:
        while solver.status == "running":
            message = solver.step()
            if solver.status == "failed":
                raise WmrkitError(f"the adaptive integration failed: {message}")
            t, y = solver.t, solver.y
            since.append((t, y.copy()))
            j = int(np.searchsorted(t_eval, t, side="right"))
            if j > i:
                dense = solver.dense_output()
                for k in range(i, j):
                    sample(t_eval[k], dense(t_eval[k]), k)
                i, since = j, [since[-1]]
            why = escaped(model, lever, y)
            if why:
                for state in since:  # a wheel that lifted off on the way there says so first
                    sample(*state)
                raise WmrkitError(f"the adaptive integration left the physical range at t = {t:.6g} s: {why}; use "
                                  "smaller torques or speeds")
    except ZeroDivisionError:  # the compiled kernels raise it where the state has overflowed
        raise WmrkitError("the adaptive integration diverged (the state overflowed)") from None
    except _OverBudget as e:
        raise WmrkitError(f"the adaptive integration needed more than {MAX_EVALUATIONS:.0e} evaluations of the "
                          f"model by t = {e.args[0]:.6g} s of {duration:g} s (stiff or discontinuous tyres, or a "
                          "long run); use the semi-implicit method or a shorter duration") from None
    return tuple(r[:i] for r in rec), {"evaluations": int(solver.nfev)}
