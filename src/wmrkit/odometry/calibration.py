"""Calibration of systematic odometry errors: fit geometric parameters to runs with known ground truth.

Systematic errors come from the robot itself: unequal wheel radii, a wrong track width, misaligned wheels
(002 (20) allows unequal radii; 003 footnote 2). Any wheel field can be fitted: a *parameter* is a group of
``WHEEL.FIELD`` names that move together. Lengths (``r``, ``l``, ``d``, ``b``, ``r_r``) are scaled by a common
factor ``1 + p``; angles (``alpha``, ``beta``, ``delta``, ``gamma``) are offset by ``p`` [rad]. E.g. the radii
``"left.r"``, ``"right.r"`` and the track ``("left.l", "right.l")`` of a differential drive. A name prefixed
with ``-`` moves the other way (``1 - p``, ``-p``): ``("left.r", "-right.r")`` changes the ratio of the radii and
keeps their mean (to first order), which is all that closed paths can tell: a closed path returns to its start
at any scale, so the mean radius needs a run with a known distance (a reference trajectory, or an open path).
A Swedish wheel's roller radius ``r_r`` moves with its ``r`` (in the same parameter, same sign) unless a parameter
names it: odometry cannot see ``r_r`` (it scales the unsensed roller rate alone), and the wheel scaled as a whole
keeps its rollers within its rim (``r_r <= r``), which a smaller fitted ``r`` alone could break.

The fit is nonlinear least squares (``scipy.optimize.least_squares``) of odometry against the reference poses,
over one or more runs: whole reference trajectories, or only the final poses of closed paths. Closed squares
driven clockwise and counter-clockwise (:func:`~.synthetic.square_path`) are the runs of the classic square-path
benchmark (UMBmark, Borenstein & Feng 1994, cited as 002 ref. [4]); its closed-form correction factors are not
in the seeds, so the same two runs are used here through this least-squares fit, which needs no small-error
approximation (zero-noise data give the true values to 1e-9, tested). :func:`square_path_error` gives the
benchmark's figure of merit from the return-position errors.

A closed path's reference says only that the robot is back at its start at the *last sample*: the log must go
on until the robot has stopped there. A log that ends while the wheels still turn (e.g. a synthetic square whose
duration is not a whole number of sample periods, so its last turn is cut short) is fitted to a pose the robot
never reached and biases the fit (a +3 % track came out +2.74 %); such runs get a warning
(:meth:`CalibrationRun.warning`). One implementation serves one log and a fleet: :class:`CalibrationProblem`
holds the residuals, :func:`solve` the least squares; :mod:`wmrkit.batch.calibrate` maps the same residuals
over many logs on an engine.

Runs that cannot tell the parameters apart have an arbitrary fit (equal closed squares all driven one way: the
radius ratio and the track only move their net turn, and the solver slides along that valley to e.g. a left
radius of -0.026 m). :meth:`CalibrationProblem.undetermined` decides at the fit, on the Jacobian with each column
scaled to a relative change of the fitted value (1 rad for angles): a direction is not determined when its
singular value is under :data:`RANK_TOL` of the largest (noise-free runs), or when the residuals leave it a
standard error over :data:`MAX_STANDARD_ERROR` (noisy runs, where the noise itself breaks the degeneracy). Such
fits are refused.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_names, as_reals, finite_number
from ..errors import UnknownNameError, WmrkitError
from ..robot import Robot
from ..wheels import GEOMETRY_FIELDS, Wheel
from .integrators import Method
from .logs import JointLog
from .model import odometry_model, wrap_angle
from .pipeline import odometry

Parameter = str | tuple[str, ...]
_STEP = float(np.sqrt(np.finfo(float).eps))  # relative forward-difference step of the Jacobian

#: Least ratio of the weakest to the largest singular value of the scaled Jacobian (module docstring): below it
#: a direction is at the level of the sampled odometry's discretisation and of the forward differences (noise-free
#: equal squares driven one way: up to 5e-6; runs that determine the parameters: 0.01-0.2).
RANK_TOL = 1e-4
#: Largest standard error of a fit along any direction, in relative changes of the fitted lengths or in rad
#: (the residuals' RMS over the singular value). Equal closed squares driven one way with encoder noise: 0.15 or
#: more in 180 synthetic fleets of 1-6 squares (the noise sets the fit along the valley); both ways, with
#: residuals of 0.05-0.09 m: under 0.01; one way in five sizes: 0.03.
MAX_STANDARD_ERROR = 0.1


class UndeterminedError(WmrkitError):
    """The runs cannot tell the fitted parameters apart (:meth:`CalibrationProblem.refuse_undetermined`): the
    parameters chosen, or the runs, are at fault (the CLI names ``--param`` when given, else the logs)."""


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class CalibrationRun:
    """A log with ground truth: ``reference`` ``(M, 3)`` true poses at samples ``at`` ``(M,)`` of ``log``.

    ``at`` defaults to every sample when ``M == len(log)``, else to the last sample (a closed path's final pose).
    ``pose0``: the true pose at sample 0 (default: the reference there if sample 0 is referenced, else zeros).
    ``closed``: the reference is not measured but the path's closure (:meth:`closed_path`).
    """

    log: JointLog
    reference: np.ndarray
    at: np.ndarray | None = None
    pose0: tuple[float, float, float] | None = None
    closed: bool = False

    def __post_init__(self) -> None:
        """Refuse references that are not finite poses ``(M, 3)`` and samples ``at`` that are not indices of the
        log, one per reference pose (they reached the solver as NaN residuals or numpy index errors)."""
        ref = as_reals(self.reference, "CalibrationRun.reference")  # text raised numpy's ValueError
        if self.pose0 is not None:  # taken unchecked: '1 m' or NaN reached the odometry
            pose0 = as_reals(self.pose0, "CalibrationRun.pose0")
            if pose0.shape != (3,) or not np.isfinite(pose0).all():
                raise WmrkitError(f"CalibrationRun.pose0: expected a finite pose (x, y, theta), got {pose0.tolist()}")
        shaped = ref.ndim in (1, 2) and ref.size > 0 and ref.shape[-1] == 3
        if not (shaped and np.isfinite(ref).all()):
            raise WmrkitError(f"CalibrationRun.reference: expected finite poses (M, 3), got shape {ref.shape}"
                              + (" with NaN or infinite values" if shaped else ""))
        if self.at is not None:
            at = np.asarray(self.at).reshape(-1)
            n = len(self.log)
            if (at.shape != (ref.size // 3,) or not np.issubdtype(at.dtype, np.integer)
                    or not ((at >= 0) & (at < n)).all()):
                raise WmrkitError(f"CalibrationRun.at: expected {ref.size // 3} sample indices (one per reference "
                                  f"pose), integers in [0, {n}), got {at.tolist()}")

    @classmethod
    def closed_path(cls, log: JointLog) -> CalibrationRun:
        """A run that ends where it started: the last sample's pose is the start pose, the origin."""
        return cls(log, np.zeros((1, 3)), np.array([len(log) - 1]), (0.0, 0.0, 0.0), closed=True)

    def samples(self) -> np.ndarray:
        """Indices of the referenced samples ``(M,)``."""
        ref = np.asarray(self.reference, dtype=float).reshape(-1, 3)
        if self.at is not None:
            return np.asarray(self.at, dtype=int)
        return np.arange(len(self.log)) if len(ref) == len(self.log) else np.array([len(self.log) - 1])

    def start(self) -> np.ndarray:
        """The pose at sample 0 ``(3,)``."""
        if self.pose0 is not None:
            return np.asarray(self.pose0, dtype=float)
        at = self.samples()
        ref = np.asarray(self.reference, dtype=float).reshape(-1, 3)
        return ref[int(np.flatnonzero(at == 0)[0])] if np.any(at == 0) else np.zeros(3)

    def warning(self) -> str | None:
        """For a :attr:`closed` run whose log ends while its wheels still turn (the last step moves a spin joint
        more than a tenth of its median moving step): the closure is then not at the last sample (module
        docstring). ``None`` otherwise."""
        if not self.closed or len(self.log) < 2:
            return None
        spins = [k for k, j in enumerate(self.log.joints) if j.endswith(".spin")] or list(range(len(self.log.joints)))
        step = np.abs(np.diff(np.asarray(self.log.positions, dtype=float)[:, spins], axis=0)).max(axis=1)
        moving = step[step > 0]
        if moving.size == 0 or step[-1] <= 0.1 * float(np.median(moving)):
            return None
        return (f"{self.log.source}: the log ends while the wheels still turn ({step[-1]:.3g} rad in the last step): "
                f"a closed path must end at rest at its start, or the fit is biased")


RunWeights = Callable[[CalibrationRun], np.ndarray]


@dataclass(frozen=True, eq=False)  # eq=False: runs hold arrays
class CalibrationProblem:
    """What is fitted: `parameters` of `robot` over `runs` (picklable, so an engine can evaluate it anywhere).

    ``method``: the integration scheme; ``heading_weight`` [m/rad]; ``sensed`` and ``weights`` choose the model
    as in :func:`~.model.odometry_model`; ``run_weights(run) -> (M,)`` multiplies each referenced sample's three
    residuals (default 1: e.g. the slip package down-weights samples where slip is detected).
    """

    robot: Robot
    parameters: tuple[Parameter, ...]
    runs: tuple[CalibrationRun, ...]
    method: Method = "exact"
    heading_weight: float = 1.0
    sensed: tuple[str, ...] | None = None
    weights: Mapping[str, float] | None = None
    run_weights: RunWeights | None = None

    def residuals(self, p: ArrayLike) -> np.ndarray:
        """``(n,) -> (R,)``: per run and referenced sample, the ``x``, ``y`` error [m] of the odometry of the robot
        at parameters `p` and ``heading_weight`` times its wrapped heading error, times the sample's run weight."""
        model = odometry_model(apply_parameters(self.robot, self.parameters, p), self.sensed, weights=self.weights)
        out = []
        for run in self.runs:
            poses = odometry(model, run.log, method=self.method, pose0=run.start()).poses[run.samples()]
            err = poses - np.asarray(run.reference, dtype=float).reshape(-1, 3)
            err[:, 2] = self.heading_weight * wrap_angle(err[:, 2])
            if self.run_weights is not None:
                err *= np.asarray(self.run_weights(run), dtype=float).reshape(-1, 1)
            out.append(err.ravel())
        return np.concatenate(out) if out else np.zeros(0)

    def jacobian(self, p: ArrayLike, r: ArrayLike | None = None) -> np.ndarray:
        """``(n,) -> (R, n)``: forward differences of :meth:`residuals` at `p` (`r`: the residuals there, if
        known), step ``sqrt(eps) max(|p_j|, 1)``. Each run's rows depend on that run alone, so any split of the
        runs gives the same numbers."""
        p = np.asarray(p, dtype=float)
        r = self.residuals(p) if r is None else np.asarray(r, dtype=float)
        cols = []
        for j in range(p.size):
            q = p.copy()
            q[j] += _STEP * max(abs(p[j]), 1.0)
            cols.append((self.residuals(q) - r) / (q[j] - p[j]))
        return np.column_stack(cols) if cols else np.zeros((r.size, 0))

    def sizes(self) -> list[int]:
        """Number of residuals of each run."""
        return [3 * len(run.samples()) for run in self.runs]

    def with_runs(self, runs: Sequence[CalibrationRun]) -> CalibrationProblem:
        """The same problem over other `runs`."""
        return replace(self, runs=tuple(runs))

    def fit(self) -> np.ndarray:
        """The least-squares parameters ``(n,)`` (:func:`solve`), in this process."""
        return self.solve().x

    def solve(self):
        """The least-squares fit (:func:`solve`), in this process: a ``scipy.optimize.OptimizeResult``."""
        return solve(self.residuals, len(self.parameters), jacobian=self.jacobian)

    def values(self, p: ArrayLike) -> tuple[tuple[str, float, float], ...]:
        """``(name, nominal, value at p)`` per wheel field of every parameter [m or rad]."""
        moved = apply_parameters(self.robot, self.parameters, p)
        return tuple((f"{w}.{f}", float(getattr(self.robot.wheel(w), f)), float(getattr(moved.wheel(w), f)))
                     for group in _groups(self.robot, self.parameters) for w, f, _ in group)

    def warnings(self) -> tuple[str, ...]:
        """The runs' warnings (:meth:`CalibrationRun.warning`)."""
        return tuple(w for w in (run.warning() for run in self.runs) if w is not None)

    def scales(self, p: ArrayLike) -> np.ndarray:
        """``(n,)``: the change of each parameter that is a unit relative change of its fitted value at `p`: the
        smallest ``|1 +- p|`` of its lengths, 1 (rad) for angles."""
        p = np.asarray(p, dtype=float)
        return np.array([min([1.0] * any(GEOMETRY_FIELDS[f] == "angle" for _, f, _ in group)
                             + [abs(1.0 + sign * v) for _, f, sign in group if GEOMETRY_FIELDS[f] == "length"])
                         for group, v in zip(_groups(self.robot, self.parameters), p.tolist(), strict=True)])

    def undetermined(self, p: ArrayLike, jac: ArrayLike, r: ArrayLike) -> str | None:
        """Why the runs do not determine the parameters at the fit `p` (``jac``, ``r``: the Jacobian and the
        residuals there), or ``None`` (module docstring): a length scaled through zero; else, on the Jacobian scaled
        by :meth:`scales`, the weakest direction's singular value under :data:`RANK_TOL` of the largest, or its
        standard error (residual RMS with ``R - n`` degrees of freedom over that singular value) over
        :data:`MAX_STANDARD_ERROR`."""
        p, jac, r = np.asarray(p, dtype=float), np.asarray(jac, dtype=float), np.asarray(r, dtype=float)
        for name, nominal, value in self.values(p):
            if GEOMETRY_FIELDS[name.partition(".")[2]] == "length" and value / nominal <= 0:
                return f"the fit gives {name} = {value:.3g} m (nominal {nominal:.3g} m), a length through zero"
        _, sv, vt = np.linalg.svd(jac * self.scales(p), full_matrices=False)
        if not sv[-1] > RANK_TOL * sv[0]:  # also all zero, or NaN
            return f"they do not move the poses along {self._direction(vt[-1])}"
        dof = r.size - len(self.parameters)
        se = float(np.linalg.norm(r) / np.sqrt(dof) / sv[-1]) if dof > 0 else 0.0
        if se > MAX_STANDARD_ERROR:
            return (f"their residuals leave {self._direction(vt[-1])} a standard error of {se:.0%} "
                    f"(at most {MAX_STANDARD_ERROR:.0%})")
        return None

    def refuse_undetermined(self, fit, error: type[UndeterminedError] = UndeterminedError) -> None:
        """Raise `error` when the runs cannot tell the parameters apart at `fit` (:func:`solve`'s result;
        :meth:`undetermined`), saying why and what to add: the refusal of one log's fit and of a fleet's."""
        reason = self.undetermined(fit.x, fit.jac, fit.fun)
        if reason is not None:
            raise error(f"calibrate: the runs cannot tell these parameters apart: {reason}{self.hint()}; add runs of "
                        "other shapes or fit fewer parameters")

    def _direction(self, v: np.ndarray) -> str:
        """A direction `v` ``(n,)`` of parameter space in words: one parameter, or a combination."""
        names = [",".join((g,) if isinstance(g, str) else g) for g in self.parameters]
        if np.max(np.abs(v)) > 0.99:
            return names[int(np.argmax(np.abs(v)))]
        v = v * np.sign(v[np.argmax(np.abs(v))])
        return "the combination " + " ".join(f"{c:+.2f} ({n})" for c, n in zip(v, names, strict=True) if abs(c) >= 0.05)

    def hint(self) -> str:
        """For closed runs that all turn one way (net heading of the nominal odometry), a clause saying so and what
        to add; else ``""``."""
        if not self.runs or not all(run.closed for run in self.runs):
            return ""
        model = odometry_model(self.robot, self.sensed, weights=self.weights)
        headings = [np.unwrap(odometry(model, run.log, method=self.method).poses[:, 2]) for run in self.runs]
        turns = [h[-1] - h[0] for h in headings]
        if all(t > np.pi for t in turns) or all(t < -np.pi for t in turns):
            way = "counter-clockwise" if turns[0] > 0 else "clockwise"
            return (f"; the {len(turns)} closed runs all turn {way} (closed squares: drive them both ways, two or more "
                    f"in each direction)")
        return ""


def solve(residuals: Callable[[np.ndarray], np.ndarray], n: int, x0: ArrayLike | None = None,
          jacobian: Callable[[np.ndarray, np.ndarray | None], np.ndarray] | None = None):
    """Levenberg-Marquardt least squares of `residuals` over `n` parameters from `x0` (default 0, the nominal
    robot): the exact nonlinear solve, no small-error approximation. `jacobian(p, r)` (``r``: the residuals at
    ``p`` when just computed, else ``None``) defaults to MINPACK's forward differences. Tolerances 1e-12: with
    noisy data, tighter ones only add rejected trial steps once round-off stops the cost from falling (half the
    evaluations of a 40-log fit, same estimate to 7 digits). A ``scipy.optimize.OptimizeResult``."""
    from scipy.optimize import least_squares

    start = np.zeros(n) if x0 is None else np.asarray(x0, dtype=float)
    if jacobian is None:
        return least_squares(residuals, start, method="lm", x_scale=1e-2, xtol=1e-12, ftol=1e-12)
    last: dict[bytes, np.ndarray] = {}

    def fun(p: np.ndarray) -> np.ndarray:
        last.clear()
        last[p.tobytes()] = r = residuals(p)
        return r

    return least_squares(fun, start, jac=lambda p: jacobian(p, last.get(p.tobytes())), method="lm", x_scale=1e-2,
                         xtol=1e-12, ftol=1e-12)


@dataclass(frozen=True, slots=True)
class Calibration:
    """A fit: the calibrated ``robot``; ``values``: ``(name, nominal, fitted)`` per wheel field [m or rad];
    ``rms_before``/``rms_after``: RMS of the residuals (m, and rad times ``heading_weight``); ``success``;
    ``warnings``: runs whose data do not fit the method (:meth:`CalibrationRun.warning`)."""

    robot: Robot
    values: tuple[tuple[str, float, float], ...]
    rms_before: float
    rms_after: float
    success: bool
    warnings: tuple[str, ...] = ()

    def value(self, name: str) -> float:
        """Fitted value of the wheel field `name` (``WHEEL.FIELD``)."""
        for n, _, v in self.values:
            if n == name:
                return v
        raise UnknownNameError(f"'{name}' was not calibrated (calibrated: {', '.join(n for n, _, _ in self.values)})")


def apply_parameters(robot: Robot, parameters: Sequence[Parameter], p: ArrayLike) -> Robot:
    """`robot` with parameter `k` changed by ``p[k]`` (lengths scaled by ``1 + p``, angles offset by ``p``)."""
    groups = _groups(robot, parameters)
    p = as_reals(p, "p")  # a number or a list of another length raised a bare TypeError or ValueError from zip
    if p.shape != (len(groups),) or not np.isfinite(p).all():
        raise WmrkitError(f"p: expected {len(groups)} finite values, one per parameter group, got {p.tolist()}")
    wheels = {w.name: w for w in robot.wheels}
    for group, value in zip(groups, p.tolist(), strict=True):
        for wheel, fld, sign in group:
            w, v = wheels[wheel], sign * value
            old = getattr(w, fld)
            wheels[wheel] = _trial(w, fld, old * (1.0 + v) if GEOMETRY_FIELDS[fld] == "length" else old + v)
    return replace(robot, wheels=tuple(wheels[w.name] for w in robot.wheels))


def fitted_robot(robot: Robot, parameters: Sequence[Parameter], p: ArrayLike) -> Robot:
    """:func:`apply_parameters` at a fit `p`, each wheel checked as :class:`~wmrkit.wheels.Wheel` checks one built in
    Python: a fit that gives a wheel no description allows (Swedish rollers fitted on their own past the wheel's
    radius) is refused, naming the wheel and the field."""
    out = apply_parameters(robot, parameters, p)
    for wheel in out.wheels:
        try:
            replace(wheel)
        except WmrkitError as err:
            raise WmrkitError(f"calibrate: the fit gives a wheel that cannot exist: {err}") from None
    return out


def _trial(wheel: Wheel, field: str, value: float) -> Wheel:
    """`wheel` with `field` set to `value`, unchecked: the solver's trial values may take a length through zero,
    which :class:`~wmrkit.wheels.Wheel` refuses; a fit that ends there is refused by
    :meth:`CalibrationProblem.undetermined`, naming the length."""
    out = copy.copy(wheel)
    object.__setattr__(out, field, value)
    return out


def check_options(heading_weight: float, sensed: Sequence[str] | None) -> tuple[str, ...] | None:
    """Refuse a `heading_weight` that is not a finite number >= 0 [m/rad] and `sensed` that is not a sequence of
    names (one string read one name per letter); `sensed` as a tuple."""
    if isinstance(heading_weight, bool) or not (finite_number(heading_weight) and heading_weight >= 0):
        raise WmrkitError(f"calibrate: heading_weight must be finite and >= 0 [m/rad], got {heading_weight!r}")
    return None if sensed is None else as_names(sensed, "calibrate: sensed", "'wheel.joint' names", WmrkitError)


def calibrate(robot: Robot, runs: Sequence[CalibrationRun], parameters: Sequence[Parameter], *,
              method: Method = "exact", heading_weight: float = 1.0, sensed: Sequence[str] | None = None,
              weights: Mapping[str, float] | None = None, run_weights: RunWeights | None = None) -> Calibration:
    """Fit `parameters` of `robot` so that its odometry over `runs` matches their references (least squares).

    Residuals per referenced sample: ``x``, ``y`` error [m] and ``heading_weight`` [m/rad] times the wrapped
    heading error (:meth:`CalibrationProblem.residuals`). Needs at least as many residuals as parameters, and
    parameters the runs can tell apart (else an error says which direction they leave undetermined:
    :meth:`CalibrationProblem.undetermined`). `sensed` and `weights` choose the model as in
    :func:`~.model.odometry_model`; `run_weights` as in :class:`CalibrationProblem`.
    """
    if isinstance(runs, CalibrationRun) or not isinstance(runs, Sequence) or \
            not all(isinstance(r, CalibrationRun) for r in runs):  # a log or a run raised AttributeError or TypeError
        raise WmrkitError(f"calibrate: runs: expected a sequence of CalibrationRun, got {type(runs).__name__}")
    if run_weights is not None and not callable(run_weights):  # 'str' object is not callable, in the solver
        raise WmrkitError(f"calibrate: run_weights: expected a function of a CalibrationRun, got "
                          f"{type(run_weights).__name__}")
    if not runs:
        raise WmrkitError("calibrate: no runs")
    sensed = check_options(heading_weight, sensed)
    groups = _groups(robot, parameters)
    problem = CalibrationProblem(robot, tuple(parameters), tuple(runs), method, heading_weight,
                                 None if sensed is None else tuple(sensed), weights, run_weights)
    r0 = problem.residuals(np.zeros(len(groups)))
    if r0.size < len(groups):
        raise WmrkitError(f"calibrate: {r0.size} residuals cannot fix {len(groups)} parameters; add runs or references")
    fit = solve(problem.residuals, len(groups), jacobian=problem.jacobian)
    problem.refuse_undetermined(fit)
    return Calibration(fitted_robot(robot, parameters, fit.x), problem.values(fit.x), rms(r0), rms(fit.fun),
                       bool(fit.success), problem.warnings())


def rms(r: np.ndarray) -> float:
    """Root mean square of residuals `r`."""
    return float(np.sqrt(np.mean(np.square(r))))


def square_path_error(errors_cw: ArrayLike, errors_ccw: ArrayLike) -> float:
    """Figure of merit of the square-path benchmark: the larger distance of the centroids of the return-position
    errors of the clockwise and the counter-clockwise runs, ``max(|mean e_cw|, |mean e_ccw|)`` [m].

    ``(n, 2), (m, 2) -> float``: final minus start position of each run.
    """
    cw, ccw = _return_errors(errors_cw, "errors_cw"), _return_errors(errors_ccw, "errors_ccw")
    return float(max(np.hypot(*cw.mean(axis=0)), np.hypot(*ccw.mean(axis=0))))


def _return_errors(errors: ArrayLike, name: str) -> np.ndarray:
    """`errors` as ``(n, 2)`` with ``n >= 1``, finite, or :class:`WmrkitError` naming `name` (an empty list gave
    NaN, three columns were read as pairs)."""
    e = as_reals(errors, name)  # text raised numpy's 'could not convert string to float'
    e = e[None] if e.ndim == 1 else e
    if e.ndim != 2 or e.shape[1] != 2 or len(e) == 0 or not np.isfinite(e).all():
        raise WmrkitError(f"{name}: expected the finite return-position errors (n, 2) of one or more runs, got "
                          f"shape {np.shape(errors)}" + (" with NaN or infinite values" if e.size else ""))
    return e


def _groups(robot: Robot, parameters: Sequence[Parameter]) -> list[list[tuple[str, str, float]]]:
    if isinstance(parameters, str):  # 'left.r' read as the parameters 'l', 'e', ...: "robot has no wheel 'l'"
        raise WmrkitError(f"calibrate: parameters: expected a sequence of parameters, got the string '{parameters}' "
                          f"(write ['{parameters}'])")
    groups = []
    for param in parameters if isinstance(parameters, Iterable) else (parameters,):
        names = (param,) if isinstance(param, str) else as_names(param, "calibrate: parameters", "parameter names "
                                                                  "('wheel.field') or groups of them", WmrkitError)
        group = []
        for signed in names:
            name, sign = (signed[1:], -1.0) if signed.startswith("-") else (signed, 1.0)
            wheel, _, fld = name.partition(".")
            try:
                w = robot.wheel(wheel)
            except UnknownNameError as err:  # "robot has no wheel 'nope'" named no parameter
                raise UnknownNameError(f"parameter '{name}': {err}") from None
            allowed = [f for f in GEOMETRY_FIELDS if f in ("l", "alpha") or f in w.kind.required
                       or f in w.kind.optional]
            if fld not in allowed:
                raise UnknownNameError(f"parameter '{name}': a {w.type} wheel has no field '{fld}' to calibrate "
                                       f"(fields: {', '.join(allowed)})")
            if GEOMETRY_FIELDS[fld] == "length" and getattr(w, fld) == 0:
                raise WmrkitError(f"parameter '{name}': its nominal value is 0, so it cannot be scaled")
            if any((wheel, fld) == (g[0], g[1]) for g in (*group, *(g for gs in groups for g in gs))):
                raise WmrkitError(f"parameter '{name}': given twice (a field moved twice is scaled twice)")
            group.append((wheel, fld, sign))
        if not group:
            raise WmrkitError("calibrate: an empty parameter group")
        groups.append(group)
    if not groups:
        raise WmrkitError("calibrate: no parameters to fit")
    named = {(w, f) for group in groups for w, f, _ in group}
    for group in groups:  # a Swedish wheel's rollers scale with it (module docstring), unless fitted on their own
        group += [(w, "r_r", sign) for w, f, sign in list(group)
                  if f == "r" and robot.wheel(w).type == "swedish" and (w, "r_r") not in named]
    return groups
