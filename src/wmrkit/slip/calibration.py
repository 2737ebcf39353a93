"""Calibration of slip models from a log with a reference trajectory (skid steering and other over-constrained robots).

Two one-parameter models are fitted to the same run, by least squares of the position and heading errors at the
reference's samples (heading error unwrapped along them, in metres of arc at ``heading_weight`` m/rad):

- **WLS** (7.52): the ratio ``k = mu_lateral / mu_longitudinal`` of every wheel's friction coefficients (7.59);
  ``k = 1`` is today's unweighted least squares, ``k -> 0`` ignores the lateral rows.
- **Effective track**, the ``wheel_separation_multiplier`` practice of ROS's diff_drive_controller: the wheels'
  lateral positions scaled by ``m`` and only their rolling rows used.

For a robot whose fixed wheels sit symmetrically at ``(+-a, +-b)`` the two are the same model: WLS's normal
equations give ``omega = (u_r - u_l) / (2 b (1 + k a^2 / b^2))``, so ``m = 1 + k (a / b)^2`` (tested). WLS's
coefficient is physical (a tyre's cornering to longitudinal stiffness ratio) and the model serves any robot.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import real_number
from ..errors import ShapeError, WmrkitError
from ..odometry.integrators import Method
from ..odometry.logs import JointLog
from ..odometry.model import wrap_angle
from ..odometry.pipeline import odometry
from ..robot import Robot
from .consistency import check_reference
from .weights import SlipWeights, wls_model

#: Lateral weight of the effective-track model (rolling rows only, to round-off).
IGNORED = 1e-9


@dataclass(frozen=True, slots=True)
class SlipCalibration:
    """Fitted ``ratio`` (WLS, mu_lateral / mu_longitudinal) and ``multiplier`` (effective track); RMS position
    errors [m] and final position / heading errors against the reference for ``no_slip`` (unweighted LS),
    ``wls`` and ``effective_track``; ``warnings``: what makes the reference suspicious (one line each)."""

    robot: str
    ratio: float
    multiplier: float
    rms: tuple[tuple[str, float], ...]
    final: tuple[tuple[str, float, float], ...]
    warnings: tuple[str, ...] = ()  # a suspicious reference (:func:`.consistency.check_reference`)

    @property
    def best(self) -> str:
        """The model of least RMS position error on this run: ``no_slip``, ``wls`` or ``effective_track``."""
        return min(self.rms, key=lambda item: item[1])[0]

    @property
    def weights(self) -> SlipWeights:
        """The WLS coefficients to use in ``odometry --method wls``."""
        return SlipWeights.uniform(self.ratio, 1.0)

    @property
    def description(self) -> dict:
        """The description block that makes ``wmrkit odometry`` use the calibrated WLS (to paste into the robot's
        description: ``odometry: {method: wls, slip: {lateral: ratio, longitudinal: 1}}``)."""
        from .settings import OdometrySettings, settings_to_dict

        return settings_to_dict(OdometrySettings(method="wls", slip=(self.ratio, 1.0)))

    def to_dict(self) -> dict:
        """JSON-ready; ``weights`` is what ``wmrkit odometry --slip-weights FILE`` reads, ``description`` the block
        for the robot's description."""
        return {"robot": self.robot, "weights": self.weights.to_dict(), "description": self.description,
                "ratio": self.ratio, "best": self.best,
                "wheel_separation_multiplier": self.multiplier,
                "rms_position_error": dict(self.rms),
                "final_position_error": {n: p for n, p, _ in self.final},
                "final_heading_error": {n: h for n, _, h in self.final}}

    def format(self) -> str:
        """Human-readable summary."""
        lines = [f"robot {self.robot}: WLS mu_lateral / mu_longitudinal = {self.ratio:.6g}, "
                 f"effective track multiplier = {self.multiplier:.6g}"]
        for (name, rms), (_, p, h) in zip(self.rms, self.final, strict=True):
            lines.append(f"  {name:<16} rms position error {rms:.4g} m, final {p:.4g} m, {math.degrees(h):.3g} deg")
        rms = dict(self.rms)
        if self.best == "effective_track":  # not an estimator of wmrkit's: ROS's diff_drive_controller parameter
            lines.append(f"the effective track fits this run best (rms {rms['effective_track']:.4g} m, WLS "
                         f"{rms['wls']:.4g} m): it is the wheel_separation_multiplier of ROS's diff_drive_controller")
        if rms["wls"] >= rms["no_slip"]:
            lines.append("WLS fits this run no better than the no-slip odometry: no slip weights to add")
            return "\n".join(lines)
        block = self.description["odometry"]
        lines += [f"to use WLS by default (rms {rms['wls']:.4g} m, no slip {rms['no_slip']:.4g} m), add to the robot's "
                  "description:", "odometry:", f"  method: {block['method']}",
                  f"  slip: {{lateral: {self.ratio!r}, longitudinal: 1.0}}   # WLS friction coefficients (7.59)"]
        return "\n".join(lines)


def effective_track_model(robot: Robot, multiplier: float):
    """The ``wheel_separation_multiplier`` model: lateral wheel positions times `multiplier`, rolling rows only."""
    if not (real_number(multiplier) and multiplier > 0):  # text raised math's TypeError
        raise ShapeError(f"wheel separation multiplier must be a finite number > 0, got {multiplier}")
    wheels = []
    for w in robot.wheels:
        x, y = w.position
        y *= multiplier
        wheels.append(replace(w, l=float(math.hypot(x, y)), alpha=float(math.atan2(y, x))))
    return wls_model(replace(robot, wheels=tuple(wheels)), SlipWeights.uniform(IGNORED, 1.0))


#: A slip parameter is determined by a log when changing it tenfold moves the odometry by more than this fraction of
#: the run's extent (a straight run moves it by 0: the fit returned its start guess, 10^0.1 for the track).
IDENTIFIED = 1e-6
#: A log (its no-slip odometry) or a reference that turns through more than this [rad] turns (for the message when
#: a parameter is not determined).
TURNING = 0.1
#: The reference and the log's no-slip odometry may travel distances at most this factor apart (and differ by at
#: least ``MIN_DISAGREEMENT`` m before that is refused): beyond it they are not the same run, or not in the same
#: units (a reference in millimetres travels 1000 times farther). Slip changes the distance travelled by far less.
MAX_SCALE = 2.0
MIN_DISAGREEMENT = 1.0


def calibrate_slip(robot: Robot, log: JointLog, reference: tuple[ArrayLike, ArrayLike], *, method: Method = "exact",
                   heading_weight: float = 1.0, source: str = "reference") -> SlipCalibration:
    """Fit the WLS ratio and the effective track of `robot` to `reference` ``(times (M,), poses (M, 3))`` (TUM).

    The odometry is placed so that it passes through the reference's first pose at the reference's first time (a
    reference may start after the log), and interpolated linearly at the reference's times within the log's span.
    A fit that runs to a bound of its search (ratio 1e-6 or 1e6, multiplier 0.01 or 100) is refused: the log and
    the reference then disagree (another run, another time base), and so is a reference that travels more than
    ``MAX_SCALE`` times farther or less far than the no-slip odometry (another run, other units), and one that turns
    or travels in ways slip cannot explain (:func:`.consistency.check_reference`: a mirror image, a turn reversed,
    missing or made up; its warnings go to ``warnings``). `source` names the reference in errors.
    """
    from scipy.optimize import least_squares

    if not (real_number(heading_weight) and heading_weight >= 0):
        raise ShapeError(f"heading_weight: expected a finite number >= 0 [m/rad], got {heading_weight!r}")
    t_ref, ref = (np.asarray(a, dtype=float) for a in reference)
    if t_ref.ndim != 1 or ref.shape != (len(t_ref), 3):
        raise WmrkitError(f"{source}: expected times (M,) and poses (M, 3), got shapes {t_ref.shape} and {ref.shape}")
    if not (np.isfinite(t_ref).all() and np.isfinite(ref).all()):
        k = int(np.argmin(np.isfinite(np.column_stack([t_ref, ref])).all(axis=1)))
        raise WmrkitError(f"{source}: pose {k + 1}: times and poses must be finite numbers")
    if np.any(np.diff(t_ref) <= 0):
        k = int(np.argmax(np.diff(t_ref) <= 0))
        raise WmrkitError(f"{source}: pose {k + 2}: time {float(t_ref[k + 1])!r} s does not increase (after "
                          f"{float(t_ref[k])!r} s)")
    t = np.asarray(log.time, dtype=float)
    if len(t) < 2:  # "another clock?" misled
        raise WmrkitError(f"{log.source}: {len(t)} sample(s): a log to calibrate on needs a run of two or more")
    inside = (t_ref >= t[0] - 1e-9) & (t_ref <= t[-1] + 1e-9)
    if inside.sum() < 2:
        spans = f"; the reference spans {t_ref[0]:.9g} to {t_ref[-1]:.9g} s" if len(t_ref) else ""
        raise WmrkitError(f"{source}: fewer than two poses within the log's time span ({t[0]:.9g} to {t[-1]:.9g} s"
                          f"{spans}): another clock or time unit?")
    t_ref, ref = t_ref[inside], ref[inside]

    def poses_of(model) -> np.ndarray:
        return _anchored(_interp(t_ref, t, odometry(model, log, method=method).poses), ref[0])

    def residuals(poses: np.ndarray) -> np.ndarray:
        err = poses - ref
        err[:, 2] = heading_weight * np.unwrap(err[:, 2])  # 0 at the start; wrapped, it had a minimum every turn
        return err.ravel()

    plain = poses_of(wls_model(robot))  # the no-slip odometry: what the log's wheels say
    travelled = _path_length(t_ref, ref[:, :2]), _path_length(t_ref, plain[:, :2])
    if abs(travelled[0] - travelled[1]) > max(MIN_DISAGREEMENT, (MAX_SCALE - 1) * min(travelled)):
        raise WmrkitError(f"{source}: the reference travels {travelled[0]:.4g} m where the log's odometry travels "
                          f"{travelled[1]:.4g} m (more than a factor {MAX_SCALE:g} apart): the log and the reference "
                          "disagree; check that they record the same run, in metres and seconds")
    warnings = check_reference(t_ref, ref, plain, source)  # refuses what cannot be one run, whatever the slip
    models = {"WLS ratio": lambda p: wls_model(robot, SlipWeights.uniform(10.0 ** p, 1.0)),
              "effective track": lambda p: effective_track_model(robot, 10.0 ** p)}
    fit_k = least_squares(lambda p: residuals(poses_of(models["WLS ratio"](p[0]))),
                          [0.0], bounds=_SEARCH["WLS ratio"], x_scale=[1.0], diff_step=[1e-6])
    fit_m = least_squares(lambda p: residuals(poses_of(models["effective track"](p[0]))),
                          [0.1], bounds=_SEARCH["effective track"], x_scale=[0.1], diff_step=[1e-6])
    scale = max(1.0, float(np.ptp(ref[:, :2], axis=0).max()))  # the run's extent [m]
    turns, turned = float(np.ptp(plain[:, 2])) > TURNING, float(np.ptp(ref[:, 2]))  # the log's, the reference's
    for fit, what in ((fit_k, "WLS ratio"), (fit_m, "effective track")):
        at = fit.fun  # the residuals at the fit
        moved = max(float(np.max(np.abs(residuals(poses_of(models[what](fit.x[0] + s))) - at))) for s in (-1, 1))
        if not moved > IDENTIFIED * scale:  # the start guess would be reported as a fit
            reason = (f"the log turns: no slip in it, or robot '{robot.name}' whose wheels make its odometry "
                      f"independent of the {what}" if turns else "a run without turning?" if turned <= TURNING else
                      f"the log's wheels do not turn it, where the reference turns {turned:.3g} rad: do they record "
                      "the same run?")  # 'the log turns' was said of a straight log whose reference turned
            if t_ref[-1] - t_ref[0] < 0.9 * (t[-1] - t[0]):  # "a run without turning?" of a log that turns after it
                reason += (f"; that is between the reference's poses, t = {t_ref[0]:.6g} to {t_ref[-1]:.6g} s of the "
                           f"log's {t[0]:.6g} to {t[-1]:.6g} s")
            raise WmrkitError(f"the log does not determine the {what}: the odometry moves less than "
                              f"{IDENTIFIED * scale:.2g} m when it changes tenfold ({reason}); "
                              "calibrate on a log that turns" + (" and slips" if turns else ""))
        if _at_bound(fit, _SEARCH[what]):
            raise WmrkitError(f"the {what} ran to the bound of its search ({_BOUNDS[what]}): the log and the "
                              "reference disagree; check that they record the same run on the same clock")
    ratio, multiplier = 10.0 ** float(fit_k.x[0]), 10.0 ** float(fit_m.x[0])
    runs = {"no_slip": wls_model(robot), "wls": wls_model(robot, SlipWeights.uniform(ratio, 1.0)),
            "effective_track": effective_track_model(robot, multiplier)}
    rms, final = [], []
    for name, model in runs.items():
        p = poses_of(model)
        d = np.hypot(*(p[:, :2] - ref[:, :2]).T)
        rms.append((name, float(np.sqrt(np.mean(d * d)))))
        final.append((name, float(d[-1]), float(abs(wrap_angle(p[-1, 2] - ref[-1, 2])))))
    return SlipCalibration(robot.name, ratio, multiplier, tuple(rms), tuple(final), tuple(warnings))


_BOUNDS = {"WLS ratio": "1e-6 to 1e6", "effective track": "multiplier 0.01 to 100"}
#: The searches' bounds, in decades of the ratio and of the multiplier.
_SEARCH = {"WLS ratio": ([-6.0], [6.0]), "effective track": ([-2.0], [2.0])}
#: A fit within this many decades of a bound ran to it: scipy's trf keeps its iterates strictly inside the bounds
#: and need not flag the bound active (a reference with x and y swapped stopped the ratio at 1.0000012e-6, which
#: was reported as a fit, exit 0).
AT_BOUND = 1e-3


def _at_bound(fit, bounds: tuple[list[float], list[float]]) -> bool:
    """Whether `fit` (scipy's least_squares) stopped at, or within :data:`AT_BOUND` of, a bound of its search."""
    x = float(fit.x[0])
    return bool(np.any(fit.active_mask != 0)) or min(x - bounds[0][0], bounds[1][0] - x) < AT_BOUND


def _anchored(poses: np.ndarray, start: np.ndarray) -> np.ndarray:
    """`poses` ``(N, 3)`` moved rigidly so that the first one is `start` (odometry from another start pose)."""
    turn = start[2] - poses[0, 2]
    c, s = math.cos(turn), math.sin(turn)
    d = poses[:, :2] - poses[0, :2]
    return np.column_stack([start[0] + c * d[:, 0] - s * d[:, 1], start[1] + s * d[:, 0] + c * d[:, 1],
                            poses[:, 2] + turn])


def _path_length(t: np.ndarray, xy: np.ndarray) -> float:
    """Distance [m] travelled along `xy` ``(N, 2)`` at times `t`, by chords at least 1 s apart (so that the noise of a
    motion-capture reference does not add up over a long run) and at most 2 s (a chord across a longer gap, such as
    a closed path's start and end poses, says nothing of the distance travelled)."""
    keep = np.unique(np.append(np.searchsorted(t, np.arange(t[0], t[-1], 1.0)), len(t) - 1))
    chords = np.hypot(*np.diff(xy[keep], axis=0).T)
    return float(chords[np.diff(t[keep]) <= 2.0].sum())


def _interp(t_new: np.ndarray, t: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """Poses ``(N, 3)`` at times `t` interpolated at `t_new` (heading unwrapped first)."""
    th = np.unwrap(poses[:, 2])
    return np.column_stack([np.interp(t_new, t, poses[:, 0]), np.interp(t_new, t, poses[:, 1]),
                            np.interp(t_new, t, th)])
