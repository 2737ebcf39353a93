"""Calibration of systematic odometry errors: fit geometric parameters to runs with known ground truth.

Systematic errors come from the robot itself: unequal wheel radii, a wrong track width, misaligned wheels
(002 (20) allows unequal radii; 003 footnote 2). Any wheel field can be fitted: a *parameter* is a group of
``WHEEL.FIELD`` names that move together. Lengths (``r``, ``l``, ``d``, ``b``, ``r_r``) are scaled by a common
factor ``1 + p``; angles (``alpha``, ``beta``, ``delta``, ``gamma``) are offset by ``p`` [rad]. E.g. the radii
``"left.r"``, ``"right.r"`` and the track ``("left.l", "right.l")`` of a differential drive. A name prefixed
with ``-`` moves the other way (``1 - p``, ``-p``): ``("left.r", "-right.r")`` changes the ratio of the radii and
keeps their mean (to first order), which is all that closed paths can tell: a closed path returns to its start
at any scale, so the mean radius needs a run with a known distance (a reference trajectory, or an open path).

The fit is nonlinear least squares (``scipy.optimize.least_squares``) of odometry against the reference poses,
over one or more runs: whole reference trajectories, or only the final poses of closed paths. Closed squares
driven clockwise and counter-clockwise (:func:`~.synthetic.square_path`) are the runs of the classic square-path
benchmark (UMBmark, Borenstein & Feng 1994, cited as 002 ref. [4]); its closed-form correction factors are not
in the seeds, so the same two runs are used here through this least-squares fit, which needs no small-error
approximation. :func:`square_path_error` gives the benchmark's figure of merit from the return-position errors.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike

from ..errors import UnknownNameError, WmrkitError
from ..robot import Robot
from ..wheels import GEOMETRY_FIELDS
from .integrators import Method
from .logs import JointLog
from .model import odometry_model, wrap_angle
from .pipeline import odometry

Parameter = str | tuple[str, ...]


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class CalibrationRun:
    """A log with ground truth: ``reference`` ``(M, 3)`` true poses at samples ``at`` ``(M,)`` of ``log``.

    ``at`` defaults to every sample when ``M == len(log)``, else to the last sample (a closed path's final pose).
    ``pose0``: the true pose at sample 0 (default: the reference there if sample 0 is referenced, else zeros).
    """

    log: JointLog
    reference: np.ndarray
    at: np.ndarray | None = None
    pose0: tuple[float, float, float] | None = None

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


@dataclass(frozen=True, slots=True)
class Calibration:
    """A fit: the calibrated ``robot``; ``values``: ``(name, nominal, fitted)`` per wheel field [m or rad];
    ``rms_before``/``rms_after``: RMS of the residuals (m, and rad times ``heading_weight``); ``success``."""

    robot: Robot
    values: tuple[tuple[str, float, float], ...]
    rms_before: float
    rms_after: float
    success: bool

    def value(self, name: str) -> float:
        """Fitted value of the wheel field `name` (``WHEEL.FIELD``)."""
        for n, _, v in self.values:
            if n == name:
                return v
        raise UnknownNameError(f"'{name}' was not calibrated (calibrated: {', '.join(n for n, _, _ in self.values)})")


def apply_parameters(robot: Robot, parameters: Sequence[Parameter], p: ArrayLike) -> Robot:
    """`robot` with parameter `k` changed by ``p[k]`` (lengths scaled by ``1 + p``, angles offset by ``p``)."""
    p = np.asarray(p, dtype=float)
    wheels = {w.name: w for w in robot.wheels}
    for group, value in zip(_groups(robot, parameters), p.tolist(), strict=True):
        for wheel, fld, sign in group:
            w, v = wheels[wheel], sign * value
            old = getattr(w, fld)
            wheels[wheel] = replace(w, **{fld: old * (1.0 + v) if GEOMETRY_FIELDS[fld] == "length" else old + v})
    return replace(robot, wheels=tuple(wheels[w.name] for w in robot.wheels))


def calibrate(robot: Robot, runs: Sequence[CalibrationRun], parameters: Sequence[Parameter], *,
              method: Method = "exact", heading_weight: float = 1.0, sensed: Sequence[str] | None = None,
              weights: Mapping[str, float] | None = None) -> Calibration:
    """Fit `parameters` of `robot` so that its odometry over `runs` matches their references (least squares).

    Residuals per referenced sample: ``x``, ``y`` error [m] and ``heading_weight`` [m/rad] times the wrapped
    heading error. Needs at least as many residuals as parameters, and parameters the runs can tell apart.
    `sensed` and `weights` choose the model as in :func:`~.model.odometry_model`.
    """
    if not runs:
        raise WmrkitError("calibrate: no runs")
    groups = _groups(robot, parameters)
    from scipy.optimize import least_squares

    def residuals(p: np.ndarray) -> np.ndarray:
        model = odometry_model(apply_parameters(robot, parameters, p), sensed, weights=weights)
        out = []
        for run in runs:
            poses = odometry(model, run.log, method=method, pose0=run.start()).poses[run.samples()]
            err = poses - np.asarray(run.reference, dtype=float).reshape(-1, 3)
            err[:, 2] = heading_weight * wrap_angle(err[:, 2])
            out.append(err.ravel())
        return np.concatenate(out)

    r0 = residuals(np.zeros(len(groups)))
    if r0.size < len(groups):
        raise WmrkitError(f"calibrate: {r0.size} residuals cannot fix {len(groups)} parameters; add runs or references")
    fit = least_squares(residuals, np.zeros(len(groups)), method="lm", x_scale=1e-2, xtol=1e-14, ftol=1e-14)
    calibrated = apply_parameters(robot, parameters, fit.x)
    values = tuple((f"{w}.{f}", float(getattr(robot.wheel(w), f)), float(getattr(calibrated.wheel(w), f)))
                   for group in groups for w, f, _ in group)
    rms = lambda r: float(np.sqrt(np.mean(r * r)))  # noqa: E731
    return Calibration(calibrated, values, rms(r0), rms(fit.fun), bool(fit.success))


def square_path_error(errors_cw: ArrayLike, errors_ccw: ArrayLike) -> float:
    """Figure of merit of the square-path benchmark: the larger distance of the centroids of the return-position
    errors of the clockwise and the counter-clockwise runs, ``max(|mean e_cw|, |mean e_ccw|)`` [m].

    ``(n, 2), (m, 2) -> float``: final minus start position of each run.
    """
    cw = np.asarray(errors_cw, dtype=float).reshape(-1, 2)
    ccw = np.asarray(errors_ccw, dtype=float).reshape(-1, 2)
    return float(max(np.hypot(*cw.mean(axis=0)), np.hypot(*ccw.mean(axis=0))))


def _groups(robot: Robot, parameters: Sequence[Parameter]) -> list[list[tuple[str, str, float]]]:
    groups = []
    for param in parameters:
        names = (param,) if isinstance(param, str) else tuple(param)
        group = []
        for signed in names:
            name, sign = (signed[1:], -1.0) if signed.startswith("-") else (signed, 1.0)
            wheel, _, fld = name.partition(".")
            w = robot.wheel(wheel)
            allowed = [f for f in GEOMETRY_FIELDS if f in ("l", "alpha") or f in w.kind.required
                       or f in w.kind.optional]
            if fld not in allowed:
                raise UnknownNameError(f"parameter '{name}': a {w.type} wheel has no field '{fld}' to calibrate "
                                       f"(fields: {', '.join(allowed)})")
            if GEOMETRY_FIELDS[fld] == "length" and getattr(w, fld) == 0:
                raise WmrkitError(f"parameter '{name}': its nominal value is 0, so it cannot be scaled")
            group.append((wheel, fld, sign))
        if not group:
            raise WmrkitError("calibrate: an empty parameter group")
        groups.append(group)
    if not groups:
        raise WmrkitError("calibrate: no parameters to fit")
    return groups
