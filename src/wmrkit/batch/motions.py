"""A run's motion errors whitened by its encoders' noise model: errors that are independent and of one variance.

A run's pose errors are a random walk, and its own fit hides most of it: for runs of three-pose references (6
residuals, 3 parameters) the misfit at the true parameters over the own fit's residual, each over its degrees of
freedom, had a median of 25 (pose errors) and 7.5 (the motions' errors of :func:`~wmrkit.batch.homogeneity.increments`,
whose x, y and heading differ in scale and are correlated) where the F distribution of 3 and 3 degrees of freedom has
1 (300 runs at 1e-4 per rad). Each motion's error, from one reference pose to the next in the frame of the first, has
the covariance of the odometry over that interval from a known pose (:class:`~wmrkit.odometry.covariance.JointNoise`
of 1 rad^2/rad on each sensed joint, first order); that covariance's inverse square root makes the errors independent
with one variance, the run's noise per rad: the same ratio then follows F(3, 3) (median 1.1, 90th percentile 4.7
against 5.4; tested), and a run's own fit measures its noise with the degrees of freedom it has.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .._shapes import finite_number
from ..limits import MAX_SIZE
from ..odometry.calibration import CalibrationProblem, CalibrationRun, apply_parameters
from ..odometry.covariance import JointNoise
from ..odometry.model import odometry_model
from ..odometry.pipeline import odometry
from .engine import BatchError
from .homogeneity import increments

#: Runs whose reference moves while their wheels are still ({runs}: each with its motions, how far the reference
#: moved; {tol}: how far its noise moves it, :func:`rest_tolerance`): the checks on whitened motions' errors leave
#: such a motion out (its covariance under the encoders' noise model is zero: no variance to weigh its error by).
#: Before, they were left out unsaid: a three-pose run whose middle reference, 0.5 s into a pause, was 2.2 cm from
#: the start had its F test and likelihood terms on the other motion alone, and among 5 three-pose runs the fleet
#: fit raised ValueError (a likelihood term of no degree of freedom).
AT_REST = ("{runs}: the reference moves while the wheels are still, beyond its noise ({tol}) (pushed, sliding, or a "
           "wrong reference pose?): such a motion is left out of the checks on whitened motions' errors (the fleet "
           "likelihood ratio, a run's F test against its own noise), the encoders' noise model gives it no variance")
#: The reference's noise assumed unless given (``reference_noise``, ``--reference-noise``): the standard deviation of
#: each of a reference pose's x and y [m] and of its heading [rad], a motion-capture system's order. A run's three
#: reference poses cannot measure it (its moving motions' errors hold the encoders' noise too: 5-9 mm on 2 m arcs at
#: 1e-5 rad^2/rad, where the reference's was 1 mm), so it is an option.
REFERENCE_NOISE = (1e-3, 1e-3)
#: A still motion's move is said (:data:`AT_REST`) beyond this many standard deviations of the difference of two
#: reference poses of the reference's noise (sqrt(2) times it), x and y together, heading apart. Before, any move at
#: all was said: with 1 mm and 1 mrad of noise on the references, every fleet of runs that paused between reference
#: poses was said pushed (5 of 5). Fleets of 6 three-pose runs each pausing 1 s (that noise; docs/batch.md): none said
#: over 40 fleets (240 still motions; the chance of noise alone beyond 5: 4e-6 per motion); one run pushed 1 cm said
#: in 38 of 40 (the noise moves it about the 7.07 mm tolerance), turned 0.02 rad in 40 of 40.
REST_FACTOR = 5.0


def check_reference_noise(noise: Sequence[float]) -> tuple[float, float]:
    """`noise` as ``(m, rad)``, or :class:`~wmrkit.errors.BatchError` naming ``reference_noise``: two finite
    numbers >= 0, at most ``limits.MAX_SIZE`` m and pi rad (1e308 m made an infinite tolerance)."""
    values = tuple(noise) if isinstance(noise, Sequence) and not isinstance(noise, str) else ()
    if len(values) != 2 or not all(finite_number(v) and not isinstance(v, bool) and 0 <= v <= top
                                   for v, top in zip(values, (MAX_SIZE, math.pi), strict=True)):
        raise BatchError(f"reference_noise: expected the reference's noise (x and y [m], heading [rad]): two numbers "
                         f"in [0, {MAX_SIZE:g}] m and [0, pi] rad, got {noise!r}")
    return float(values[0]), float(values[1])


def rest_tolerance(noise: Sequence[float]) -> np.ndarray:
    """``(2,)``: how far a still reference may move [m, rad] under its `noise` ``(m, rad)``
    (:data:`REST_FACTOR` times sqrt(2) times it)."""
    return REST_FACTOR * np.sqrt(2.0) * np.asarray(check_reference_noise(noise))


def motion_covariances(problem: CalibrationProblem, p: np.ndarray, run: CalibrationRun) -> np.ndarray:
    """``(M, 3, 3)``: the covariance of the odometry's motion from each reference pose (the start for the first) to
    the next of `run`, in the frame of the first, heading scaled by the problem's heading weight, of the robot at
    parameters `p`, with 1 rad^2/rad of noise on each sensed joint; zero for a motion of no sample."""
    model = odometry_model(apply_parameters(problem.robot, problem.parameters, p), problem.sensed,
                           weights=problem.weights)
    at = run.samples()
    scale = np.array([1.0, 1.0, problem.heading_weight])
    out = np.zeros((len(at), 3, 3))
    for i, (a, b) in enumerate(zip(np.r_[0, at[:-1]], at, strict=True)):
        if b > a:
            cov = odometry(model, run.log.slice(int(a), int(b) + 1), method=problem.method,
                           noise=JointNoise(per_rad=1.0)).covariance[-1]
            out[i] = cov * scale[:, None] * scale[None, :]
    return out


def whitening(problem: CalibrationProblem, p: np.ndarray, run: CalibrationRun, res: np.ndarray) -> np.ndarray | str:
    """The linear map ``(3M', 3M)`` from the run's pose residuals (unweighted, heading times the heading weight) to
    its whitened motions' errors, about its odometry at parameters `p` (`res`: its residuals there): the motions'
    errors of :func:`~wmrkit.batch.homogeneity.increments`, each motion's three times the inverse square root of its
    covariance (:func:`motion_covariances`), motions of no sample left out; or why not, where a motion's covariance
    is singular (a robot whose encoders do not see every motion, or a motion of one sample of a robot of two
    encoders), no motion moves the wheels or the fit has no heading (``heading_weight`` 0: the motions' errors
    were divided by it, NaN and a RuntimeWarning, and their covariance said the encoders did not see them)."""
    if problem.heading_weight == 0:
        return "the fit has no heading (heading_weight 0): its motions' errors are not known"
    to_motions, _ = increments(run, problem.heading_weight, np.eye(res.size), res)
    cov = motion_covariances(problem, p, run)
    at = run.samples()
    rows = []
    for c, block, a, b in zip(cov, to_motions.reshape(len(cov), 3, -1), np.r_[0, at[:-1]], at, strict=True):
        if not c.any():
            continue
        val, vec = np.linalg.eigh(c)
        if not val[0] > 1e-9 * val[-1]:
            t = run.log.time
            return (f"its motion from sample {a} to {b}, t {t[a]:.6g}-{t[b]:.6g} s, has a covariance of rank "
                    f"{int(np.sum(val > 1e-9 * val[-1]))} of 3: the encoders do not see every direction of it")
        rows.append((vec / np.sqrt(val)) @ vec.T @ block)
    return np.concatenate(rows) if rows else "its wheels do not turn between its reference poses"


def moved_at_rest(problem: CalibrationProblem, p: np.ndarray, runs: Sequence[int], res: np.ndarray,
                  logs: Sequence[str], noise: Sequence[float] = REFERENCE_NOISE) -> str | None:
    """:data:`AT_REST` for the `runs` (indices of the problem's; `res`: the fleet fit's residuals at parameters `p`)
    with a motion between reference poses that :func:`whitening` leaves out (covariance zero: no sensed wheel
    turns) while its reference moves beyond its `noise` ``(m, rad)`` (:func:`rest_tolerance`), each motion named by
    its samples with the reference's move [m, rad]; ``None`` when there is none (a still reference of a still robot
    carries no information)."""
    if problem.heading_weight == 0:  # no motion is whitened at all (whitening says why)
        return None
    tol = rest_tolerance(noise)
    sizes = problem.sizes()
    ends = np.cumsum(sizes)
    said = []
    for k in runs:
        run, r = problem.runs[k], res[int(ends[k] - sizes[k]):int(ends[k])]
        _, err = increments(run, problem.heading_weight, np.eye(r.size), r)
        moves = np.column_stack([np.hypot(*err.reshape(-1, 3)[:, :2].T), np.abs(err[2::3]) / problem.heading_weight])
        at = run.samples()
        moved = [f"samples {a}-{b}: {m[0]:.3g} m, {m[1]:.3g} rad"
                 for c, m, a, b in zip(motion_covariances(problem, p, run), moves, np.r_[0, at[:-1]], at, strict=True)
                 if not c.any() and (m > tol).any()]
        said += [f"{logs[k]} ({'; '.join(moved)})"] if moved else []
    return AT_REST.format(runs=", ".join(said), tol=f"{tol[0]:.3g} m, {tol[1]:.3g} rad") if said else None
