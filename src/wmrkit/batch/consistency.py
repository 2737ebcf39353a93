"""Runs that disagree with the rest of a fleet: a leave-one-run-out residual ratio per run.

A fleet fit averages its runs: one run of another robot (a left radius +6 % among runs at +1 %) moved the fitted
radius to +1.72 % and the track by 3 %, and only the interval widened. For run ``g`` the ratio is the RMS of its
residuals at the fit of the *other* runs over what noise alone would leave there: its RMS at its *own* fit plus the
error of the others' fit (:func:`_spread`): about one when the others' parameters explain it, large when they do not
(its data ask for other parameters). Both are first order at the fleet fit, from the Jacobian ``J`` and the
residuals ``r`` already there (no refit): with ``A_g = J_g' J_g``, ``b_g = J_g' r_g`` and ``S`` the sum of the
``A_g``, the others' fit is ``d_g = (S - A_g)^+ b_g`` away (as in the jackknife interval,
:func:`~wmrkit.batch.calibrate._sandwich_interval`), where run ``g``'s residuals are ``r_g + J_g d_g``; its own fit
leaves ``r_g`` minus its projection on the columns of ``J_g`` (a run that does not determine every parameter alone
has a well-defined best residual all the same), and the others' fit's error adds ``trace(A_g V_g)`` to its sum of
squares, ``V_g`` the jackknife covariance of that fit from the other runs' own scores. Without that term (before)
the ratio was the others' noise over this run's: a quiet run among noisy ones (1e-6 per rad among 1e-4) got 30-63
and agreeing fleets of mixed noise levels were flagged (4 of 20 fleets of 6), the noisy run named; and the ratios of
good runs of a fleet with a bad one reached 110 (the others' fit pulled by it), so a removal test had to find the
run to name. With it, agreeing fleets stay under 13 whatever their runs' noise levels, good runs in a fleet with a
bad one under 3, and the run of largest ratio is named (docs/batch.md's table).

The denominator is at least :data:`ROUNDOFF` times the run's wheel travel: noise-free runs fit to round-off
(1e-15 m on 6 m) and a ratio of round-off is meaningless; a noise-free run that disagrees still is flagged.

Closed paths (a final pose: no own noise to divide by) are judged by :func:`judge` against the other runs' pooled
noise instead, with 5 runs or more, from a quadratic model of each run about the fleet fit and one refit (of every
run in a fleet of 5); with 6 or more and no run over the threshold, pairs of runs are left out together too (two bad
runs hide each other, :func:`_pair`). Runs with references of 4 poses or more are also judged as a whole
(:mod:`wmrkit.batch.whole`): several bad runs hide each other from their ratios too.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..odometry.calibration import RANK_TOL, CalibrationProblem, CalibrationRun
from ..robot import Robot
from .likelihood import MIN_OWN_DOF, few_pose_warning, own_noise
from .motions import REFERENCE_NOISE, moved_at_rest
from .refits import REFIT_FAILED as REFIT_FAILED  # re-exported: batch.consistency.REFIT_FAILED
from .refits import own_dof, own_scores, own_skipped, refits
from .whole import NO_OWN_NOISE, whole_fleet

#: Largest residual ratio of a fleet whose runs agree. Simulated fleets with encoder noise (1e-5 per rad, or drawn
#: per run among 1e-6, 1e-5 and 1e-4), 4 to 16 runs (docs/batch.md's table): largest ratio 12.1 over 260 fleets;
#: a run with its left radius 5 % off 7-153 (10th percentile 10-45), good runs of such fleets at most 2.7. Before
#: the others' fit's error counted (:func:`_spread`), agreeing fleets of one noise level reached 26.2 (the threshold
#: was 30) and of mixed levels 63.
MAX_RATIO = 20.0
#: Least residual RMS of a run's own fit, as a fraction of its wheel travel (at least 1 m): round-off.
ROUNDOFF = 1e-9
#: Fewest runs to judge: with two, each is the other's "others" and the two ratios cannot say which one is off. With
#: three the ratio as it was (a run's own noise alone in the denominator) flagged 3 of 100 agreeing fleets (up to 66).
#: The present ratio (the others' fit's error counted), measured over fleets of 3 (random arcs, references every 5th
#: sample; seeds 10000-10999 and 20000-20399): 1000 agreeing fleets of noise 1e-5 per rad, largest 11.4 (99th
#: percentile 7.0), 1000 of levels drawn per run among 1e-6, 1e-5 and 1e-4, largest 11.6 (6.7): none flagged; one
#: run of a left radius +5 % flagged in 310 of 400 fleets (253 of 400 with mixed levels), always that run (good runs
#: at most 2.3 and 7.4); fleets of 4 flag 95 and 75 of 100. Hence 3 (4 before: fleets of 3 were not judged).
MIN_RUNS = 3
#: Fewest residuals of a run beyond the rank of its own Jacobian for a ratio: with one (a closed path's final pose,
#: three numbers, against two parameters) its own fit is near exact by chance and the ratio noise's (303 for a
#: good closed square of four); a chi with 6 degrees of freedom is seldom near zero. A reference pose where the run
#: starts does not count (:func:`counts`): with it, runs whose references have three poses (start, middle, end: 3)
#: had ratios, and agreeing fleets of 6 such runs had them up to 42, 2 of 12 flagged.
MIN_DOF = 6
#: Why a fleet is not judged (said by ``batch calibrate``'s text and JSON, ``not_judged``): too few runs.
FEW_RUNS = (f"fewer than {MIN_RUNS} runs: the runs are not checked against each other (with 2, a run of "
            "another robot cannot be told from the other), a run that disagrees is averaged in unseen")
#: ... and every run a closed path (or as short): its own noise cannot be measured from its one residual beyond the
#: parameters, which the ratio's denominator needs; with 5 closed runs or more they are judged against the others'
#: pooled noise instead (:func:`judge`), with fewer not (4 squares, two each way: each run moves the fit far, and
#: the odd run's partner in direction scored 123; by refits of every run up to 57).
CLOSED = ("no run has 6 residuals beyond its own parameters (closed paths: a final pose) and there are fewer than 5 "
          "runs: the runs are not checked against each other, a run of another robot is averaged in unseen; 5 closed "
          "runs or more, or runs with reference trajectories, are checked")
#: ... the same with runs of references of few poses (2 or 3: one or two poses beyond the start; they said "closed
#: paths ... runs with reference trajectories are checked" to runs with reference trajectories). A reference of two
#: poses is one final pose, as a closed path's, and 5 such runs or more are judged as closed paths are (docs/batch.md).
SHORT = ("no run has 6 residuals beyond its own parameters (references of 2 or 3 poses, or closed paths) and there "
         "are fewer than 5 runs: the runs are not checked against each other, a run of another robot is averaged in "
         "unseen; 5 such runs or more, or references of 4 poses or more, are checked")
#: ... and with 5 runs or more of such runs, fewer than 5 of any one number of reference poses (the closed-path judge
#: compares runs of equal numbers of residuals).
UNEQUAL = ("no run has 6 residuals beyond its own parameters (references of 2 or 3 poses, or closed paths) and no "
           "5 runs have as many reference poses (a closed path counts as a reference of 2): the runs are not checked "
           "against each other, a run of another robot is averaged in unseen; give 5 runs or more as many poses, or "
           "references of 4 poses or more")
#: ... and why runs of such a fleet are set aside while the others are judged: each kind of 5 runs or more of as many
#: reference poses is judged on its own ({runs}: the others; {judged}: the kinds judged). Before, a fleet of 5 runs
#: of two-pose references and one of three was not judged at all (UNEQUAL).
SET_ASIDE = ("{runs}: set aside, fewer than 5 runs have as many reference poses as each of these (the judged runs: "
             "{judged}): not checked against the other runs (a closed-path score compares runs of as many poses), a "
             "run of another robot among them is averaged in unseen")
#: ... and why some runs are not judged while the others are: a closed path among runs with references, or a run
#: whose reference has too few poses ({runs}: those runs, their per-run values null).
SOME_RUNS = (f"{{runs}}: fewer than {MIN_DOF} residuals beyond the run's own parameters (a closed path, or a "
             "reference of few poses) among runs with more: not checked against the other runs, a run of another "
             "robot is averaged in unseen (the other runs are checked)")
#: Why ``batch calibrate --slip`` does not judge its runs: the residual ratio is one of noise, and a slip fit's own
#: residuals are the slip model's error. Simulated skid-steer fleets (quasi-static slip, 6 runs): agreeing runs up to
#: 1.6 in 4 fleets, a run of a robot with twice the tyres' cornering stiffness (its friction ratio 1.59 against
#: 0.77) 6 to 10, one with a 10 % larger wheel radius 1 to 7 (6 fleets); no threshold like MAX_RATIO separates them.
SLIP_NOT_JUDGED = ("the runs are not checked against each other (a slip fit's residuals are its model's error, not "
                   "noise): compare the per-run values; a run of another robot or floor is averaged in")


@dataclass(frozen=True)
class Consistency:
    """``ratios``: per run, or ``None`` (fewer than :data:`MIN_RUNS` runs, or fewer than :data:`MIN_DOF`
    residuals beyond its own parameters: closed paths); ``inconsistent``: the largest over
    :data:`MAX_RATIO` or a fleet homogeneity over :data:`~wmrkit.batch.homogeneity.MAX_HOMOGENEITY` (closed paths: a
    score over :data:`MAX_CLOSED_SCORE`; ``None`` when not judged);
    ``messages``: the warnings that name the runs (one a kind of runs judged); ``not_judged``: why no run was
    judged (:data:`FEW_RUNS`, :data:`CLOSED`, :data:`SHORT`, :data:`UNEQUAL`, :data:`REFIT_FAILED`,
    :data:`CURVATURE_FAILED`, :data:`UNDETERMINED`) or
    which runs were not (:data:`SOME_RUNS`, :data:`SET_ASIDE`; left out of the whole-fleet check of three-pose
    runs: :data:`~wmrkit.batch.likelihood.LEFT_OUT`, after), or ``None``; ``scores``: a fleet of closed paths'
    per-run scores (:func:`judge`; another quantity than a ratio, under its own name), empty when not scored."""

    ratios: tuple[float | None, ...]
    inconsistent: bool | None
    messages: tuple[str, ...] = ()
    not_judged: str | None = None
    scores: tuple[float | None, ...] = ()


def travel(robot: Robot, run: CalibrationRun) -> float:
    """The distance the run's wheels roll [m]: mean over its spin joints of ``r`` times the summed ``|dq|``."""
    pos = np.asarray(run.log.positions, dtype=float)
    rolled = [robot.wheel(j.partition(".")[0]).r * float(np.abs(np.diff(pos[:, k])).sum())
              for k, j in enumerate(run.log.joints) if j.endswith(".spin")]
    return float(np.mean(rolled)) if rolled else 0.0


def counts(jac: np.ndarray, res: np.ndarray, sizes: Sequence[int]) -> np.ndarray:
    """How many of each run's residuals (`sizes` rows each of `jac` and `res`) carry information: not those zero with
    their Jacobian row, a reference pose where the run starts (it starts there by construction: a reference of two
    poses is one final pose, as a closed path's)."""
    live = np.any(jac != 0, axis=1) | (res != 0)
    return np.add.reduceat(live.astype(int), np.r_[0, np.cumsum(sizes)[:-1]].astype(int))


def _ratios(a: np.ndarray, b: np.ndarray, c: np.ndarray, own: np.ndarray, keep: np.ndarray,
            shift: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Ratios of the runs `keep` at the fit of the others among `keep` (module docstring), the residuals being
    those at the fleet fit moved by `shift` (the fit of `keep`); and each run's change ``d`` to that fit."""
    ak = a[keep]
    bk = b[keep] + ak @ shift  # J_g' (r_g + J_g shift)
    ck = c[keep] + 2 * b[keep] @ shift + np.einsum("i,gij,j->g", shift, ak, shift)
    rest = ak.sum(axis=0) - ak
    d = np.einsum("gij,gj->gi", np.linalg.pinv(rest, rcond=RANK_TOL ** 2, hermitian=True), bk)
    e2 = ck + 2 * np.einsum("gi,gi->g", bk, d) + np.einsum("gi,gij,gj->g", d, ak, d)
    return np.sqrt(np.maximum(e2, 0.0) / (own[keep] + _spread(ak, bk, d, rest))), d


def _spread(a: np.ndarray, b: np.ndarray, d: np.ndarray, rest: np.ndarray) -> np.ndarray:
    """Each run's expected sum of squares from the error of the others' fit: ``trace(A_g V_g)``, ``V_g`` the
    jackknife (CR3) covariance of the fit of the runs but ``g`` (`rest`: their ``S - A_g``; `d`: that fit's change),
    from their scores there ``b_h + A_h d_g``: each other run's own noise, whatever its level (module docstring)."""
    g = len(a)
    out = np.zeros(g)
    if g < 3:
        return out
    for k in range(g):
        others = np.delete(np.arange(g), k)
        u = b[others] + a[others] @ d[k]
        e = np.einsum("hij,hj->hi", np.linalg.pinv(rest[k] - a[others], rcond=RANK_TOL ** 2, hermitian=True), u)
        out[k] = (g - 2) / (g - 1) * np.einsum("hi,ij,hj->", e, a[k], e)
    return out


def run_consistency(jac: np.ndarray, res: np.ndarray, sizes: Sequence[int], floors: Sequence[float],
                    names: Sequence[str]) -> Consistency:
    """The residual ratio of each run (`sizes` rows each of the fleet fit's `jac` and `res`; `floors`: least RMS of
    its own fit [m]; `names`: how the warning names it), the flag and its message (module docstring)."""
    g = len(sizes)
    if g < MIN_RUNS:
        return Consistency((None,) * g, None, not_judged=FEW_RUNS)
    ends = np.cumsum(sizes)
    blocks = [(jac[e - s:e], res[e - s:e]) for s, e in zip(sizes, ends, strict=True)]
    a = np.array([j.T @ j for j, _ in blocks])
    b = np.array([j.T @ r for j, r in blocks])
    c = np.array([r @ r for _, r in blocks])
    own = np.full(g, np.nan)  # NaN: too few residuals beyond the run's own parameters (no ratio)
    for k, ((j, r), f, s, live) in enumerate(zip(blocks, floors, sizes, counts(jac, res, sizes), strict=True)):
        step, _, rank, _ = np.linalg.lstsq(j, r, rcond=None)
        if live - rank >= MIN_DOF:
            own[k] = max(float(np.sum(np.square(r - j @ step))), f * f * s)
    everyone = np.arange(g)
    ratios, d = _ratios(a, b, c, own, everyone, np.zeros(a.shape[1]))
    judged = tuple(None if np.isnan(q) else float(q) for q in ratios)
    if np.isnan(ratios).all():
        return Consistency(judged, None, not_judged=CLOSED)
    unjudged = ", ".join(names[k] for k in np.flatnonzero(np.isnan(ratios)))
    some = SOME_RUNS.format(runs=unjudged) if unjudged else None
    worst = int(np.nanargmax(ratios))
    if ratios[worst] <= MAX_RATIO:
        return Consistency(judged, False, not_judged=some)
    if g == 3:  # the two others are each other's only "others": their ratios without it say nothing
        message = (f"{names[worst]}: disagrees with the other two runs (residual ratio {ratios[worst]:.3g}, over "
                   f"{MAX_RATIO:g}): another robot, load or floor? The fit averages it in; check it or fit without it")
        return Consistency(judged, True, (message,), some)
    rest = float(np.nanmax(_ratios(a, b, c, own, everyone[everyone != worst], d[worst])[0], initial=0.0))
    if rest <= MAX_RATIO:
        message = (f"{names[worst]}: disagrees with the other runs (residual ratio {ratios[worst]:.3g}, over "
                   f"{MAX_RATIO:g}; without it the largest is {rest:.3g}): another robot, load or floor? The fit "
                   "averages it in; check it or fit without it")
    else:
        message = (f"the runs disagree (residual ratio {ratios[worst]:.3g} for {names[worst]}, over {MAX_RATIO:g}) "
                   f"and no one run explains it (without {names[worst]} the largest is still {rest:.3g}): the fit "
                   "averages them; check the runs")
    return Consistency(judged, True, (message,), some)


#: Largest closed-path score of a fleet whose runs agree (:func:`judge`). Simulated fleets of 6 closed squares
#: (diff-drive, sides 1-2.5 m, both ways, encoder noise 1e-6 to 1e-4 per rad): at most 6.6 over 600 runs of one
#: noise level a fleet, 11.6 over 360 runs of mixed levels (fleets of 8: 5.3 and 11.4 over 320 runs each); a run of a
#: robot with a 10 % larger left radius 66 or more (15 fleets), 5 % 41 or more, a track 10 % wider 17-61 (1st and
#: 50th percentiles: 18 of 20 fleets flagged), 5 % wider 9-32 (15 of 20). Fleets of 5 (every run refitted): at most 7.7
#: over 750 runs of one level, 15.5 over 450 of mixed levels; a track 5 % wider 5-47 (30 of 40 fleets flagged).
MAX_CLOSED_SCORE = 20.0
#: Fewest closed runs to judge: with 4 (two squares each way) each run moves the fleet fit far, the quadratic model
#: about it missed an odd run (scored 0.3 where the refit gave 4810), and even refits of every run do not separate:
#: the odd run's partner in direction scored 7-57 (20 fleets, a track 5 % off: 9 agreeing runs over 20).
MIN_CLOSED_RUNS = 5
#: Runs refitted without (the one whose removal moves the quadratic model's fit the most) ...
REFITS = 1
#: ... but every run in fleets of fewer closed runs: with 5 the model's one refit is not enough (each run moves the
#: fit far), refits of all five separate (docs/batch.md's table).
REFIT_EVERY = 6
#: Why a closed fleet is not judged when the other runs without one cannot tell the parameters apart
#: (:meth:`~wmrkit.odometry.calibration.CalibrationProblem.undetermined`, as the jackknife interval asks): the run's
#: score would measure the others' guess (one clockwise square among 5 equal counter-clockwise ones, all of one
#: robot: 803, named as another robot's). {run}: that run; {why}: the reason.
UNDETERMINED = ("{run}: without it the other runs cannot tell the parameters apart ({why}): the closed runs are not "
                "checked against each other, a run of another robot is averaged in unseen; add closed runs of other "
                "sizes, both ways")
#: Fewest runs of a kind for the leave-two-out step (:func:`_pair`): two bad runs hide each other (each is among the
#: other's "others" and inflates their pooled noise: 0 of 75 fleets of 6-12 three-pose runs with two of a left radius
#: +5 % flagged), so when no run scores over MAX_CLOSED_SCORE pairs are left out together; the 4 runs left must
#: determine the fit as the others of the smallest fleet judged do (MIN_CLOSED_RUNS - 1).
MIN_PAIR_RUNS = MIN_CLOSED_RUNS + 1
#: Runs of largest score among which pairs are scored: at most 15 pairs whatever the fleet's size. The planted pairs
#: ranked up to 5th of 6 by their own scores (so all pairs of 6), within the first 4 in fleets of 8 and 12.
PAIR_CANDIDATES = 6
#: Pairs refitted: those of largest score on the runs' quadratic model (no odometry). In all 115 fleets with a planted
#: pair the best of these 3 refits was the best of refits of every pair (the fit 1.7x as long, 4.5x with 15 refits).
PAIR_REFITS = 3
#: Largest pair score of a fleet whose runs agree: the largest of up to 15 pairs, so above MAX_CLOSED_SCORE (that of
#: one run of 6). Simulated fleets of 6 (docs/batch.md): agreeing runs of one noise level at most 5.4, of levels drawn
#: per run 17.5, two runs at 1e-4 per rad among four at 1e-6 (the worst mix) 28.4; two runs of a left radius +5 %
#: 24-128 (74 of 75 fleets of 6-12 over 30).
MAX_PAIR_SCORE = 30.0
#: The warning that names a pair ({a}, {b}: the runs; {score}: the pair's score).
PAIR = ("{a} and {b}: disagree with the other runs (closed-path pair score {score:.3g}, over "
        f"{MAX_PAIR_SCORE:g}: the fit of the runs but these two leaves each of them at least that many times the "
        "others' error; each alone is hidden by the other): another robot, load or floor? The fit averages them in; "
        "check them or fit without them")
#: Step [parameter units] of the forward difference of the fleet fit's Jacobian that gives each run's curvature.
CURVATURE_STEP = 1e-3
#: ... and why a closed fleet is not judged when that Jacobian fails (a worker's error, values not finite): the fleet
#: fit is returned all the same ({runs}: those of the failed task or rows; {why}: the error).
CURVATURE_FAILED = (f"{{runs}}: the Jacobian {CURVATURE_STEP:g} from the fleet fit (the closed-path judge's curvature) "
                    "failed ({why}): the closed runs are not checked against each other, a run of another robot is "
                    "averaged in unseen (the fleet fit stands)")


def names(runs: Sequence[CalibrationRun]) -> tuple[str, ...]:
    """The runs' files as the answer names them (runs made in Python share '<log>' or '<synthetic>')."""
    sources = [run.log.source for run in runs]
    return tuple(s if sources.count(s) == 1 else f"run {k + 1} ({s})" for k, s in enumerate(sources))


def _score(err: np.ndarray, k: int, rest: np.ndarray, floors: np.ndarray, n: int, m: np.ndarray,
           own: float = 0.0) -> float:
    """Run `k`'s weighted residual RMS over that of `rest` with ``R - n`` degrees of freedom (rows ``err``; `m`: each
    run's residuals that count, :func:`counts`), or over its `own` noise (mean square a row) if larger."""
    noise = max(float(np.sum(err[rest] ** 2)) / (m[rest].sum() - n), float(np.mean(floors[rest] ** 2)), own)
    return float(np.sqrt(np.sum(err[k] ** 2) / max(m[k], 1) / noise))


def _quadratic_scores(jac, res, hess, floors, m, outs=None) -> tuple[np.ndarray, np.ndarray]:
    """Each run's score against the others refitted on the runs' quadratic models (no odometry), and that fit's
    shift from the fleet fit; the score is NaN where the others do not determine the parameters (their Jacobian's
    weakest singular value under :data:`RANK_TOL` of the largest: e.g. equal squares all driven one way). With
    `outs` (tuples of runs), the same for each tuple left out together, scored by the smallest of its runs' scores.
    `own`: each run's own noise (mean square a row), the denominator where larger."""
    from scipy.optimize import least_squares

    g, _, n = jac.shape
    outs = [(k,) for k in range(g)] if outs is None else outs
    out, shift = np.full(len(outs), np.nan), np.zeros((len(outs), n))
    for k, left in enumerate(outs):
        rest = np.delete(np.arange(g), left)
        j, r, h = jac[rest].reshape(-1, n), res[rest].ravel(), hess[rest].reshape(-1, n, n)
        sv = np.linalg.svd(j, compute_uv=False)
        if m[rest].sum() <= n or sv[-1] < RANK_TOL * sv[0]:
            continue
        d = least_squares(lambda d: r + j @ d + 0.5 * np.einsum("mij,i,j->m", h, d, d), np.zeros(n),  # noqa: B023
                          jac=lambda d: j + np.einsum("mij,j->mi", h, d), method="lm", xtol=1e-12,  # noqa: B023
                          ftol=1e-12).x
        err = res + jac @ d + 0.5 * np.einsum("gmij,i,j->gm", hess, d, d)
        out[k] = min(_score(err, i, rest, floors, n, m) for i in left)
        shift[k] = d
    return out, shift


def judge(problem: CalibrationProblem, fit, curvature: Callable, refit: Callable,
          reference_noise: Sequence[float] = REFERENCE_NOISE) -> Consistency:
    """The runs of the fleet fit `fit` checked against each other: by their residual ratios
    (:func:`run_consistency`), else, for a fleet of closed paths (:data:`CLOSED`), each run against the others'
    pooled noise. A closed run's residuals (its final pose) are weighted by one over the square root of its wheel
    travel (at least 1 m: an encoder random walk's error grows so); its score is their RMS at the fit of the other
    runs over the others' RMS there (with ``R - n`` degrees of freedom); a run over :data:`MAX_CLOSED_SCORE` whose own
    fit has degrees of freedom (three-pose references) is refitted without and scored against its own noise too, the
    smaller score kept (:func:`~wmrkit.batch.refits.own_scores`, an F test: a noisy run among quiet ones scored their
    ratio of noise levels). The
    others' fit is first taken on each run's
    quadratic model about the fleet fit: the curvature from the fit's Jacobian one :data:`CURVATURE_STEP` away
    along each parameter, no new odometry (`curvature`: ``[p] -> [that Jacobian, or (the runs of a task that
    failed, its TaskFailure)]``, the engine's map; a failure or a value not finite leaves the fleet not judged,
    :data:`CURVATURE_FAILED`). That model is good for runs that agree, but an odd run pulls the fleet
    fit far from the others' (a track 10 % off) and its score there came out 25 where the others' refit gave 301
    (first order: 20 against 96). So the run whose removal moves that fit the most is refitted without, from there,
    by `refit` (``[(problem, x0)] -> [(x, residuals of the problem's runs) or a TaskFailure]``, the engine's map;
    the problem's last run is the one left out; a failure leaves the fleet not judged, :data:`REFIT_FAILED`), and its
    score is the refit's: in fleets of 6 squares the odd run's equalled a refit of every run. A fleet of fewer than
    :data:`REFIT_EVERY` runs refits every run. Over :data:`MAX_CLOSED_SCORE` the run of largest score is named;
    with none over it and :data:`MIN_PAIR_RUNS` runs or more, the pair of largest pair score over
    :data:`MAX_PAIR_SCORE` is named (:data:`PAIR`; :func:`_pair`). A reference that moves beyond its
    `reference_noise` ``(m, rad)`` while the wheels are still is said (:func:`~wmrkit.batch.motions.moved_at_rest`).
    Runs are compared with runs of as many reference poses (closed paths and references of two poses: one final
    pose each): each kind of :data:`MIN_CLOSED_RUNS` runs or more is judged on its own, the other runs are set aside
    and named (:data:`SET_ASIDE`); with no such kind the fleet is not judged (:data:`CLOSED`; runs of references of
    few poses: :data:`SHORT`; of unequal numbers of poses: :data:`UNEQUAL`), nor when a kind's runs but one cannot
    tell the parameters apart (:data:`UNDETERMINED`)."""
    robot, runs, sizes = problem.robot, problem.runs, problem.sizes()
    logs = names(runs)
    travels = np.array([max(travel(robot, run), 1.0) for run in runs])
    judged = run_consistency(fit.jac, fit.fun, sizes, ROUNDOFF * travels, logs)
    if judged.not_judged != CLOSED:
        which = [k for k, q in enumerate(judged.ratios) if q is not None]
        said, unmade = whole_fleet(problem, fit.x, fit.jac, fit.fun, which, ROUNDOFF * travels, logs,
                                   bool(judged.inconsistent))
        judged = replace(judged, not_judged="; ".join(x for x in (judged.not_judged, unmade) if x) or None)
        return replace(judged, inconsistent=True, messages=(*judged.messages, *said)) if said else judged
    g, n = len(runs), fit.x.size
    m = counts(fit.jac, fit.fun, sizes)
    kinds = [np.flatnonzero(m == c) for c in sorted(set(m.tolist()), reverse=True)]
    groups = [kind for kind in kinds if len(kind) >= MIN_CLOSED_RUNS]
    if not groups:
        closed = all(run.closed for run in runs)
        why = CLOSED if closed and g < MIN_CLOSED_RUNS else SHORT if g < MIN_CLOSED_RUNS else UNEQUAL
        return replace(judged, not_judged=why)
    blocks = np.split(np.arange(fit.fun.size), np.cumsum(sizes)[:-1])
    for group in groups:  # the others must determine the parameters for a score (the jackknife interval's test)
        for k in group:
            rows = np.concatenate([blocks[i] for i in group if i != k])
            why = problem.undetermined(fit.x, fit.jac[rows], fit.fun[rows])
            if why is not None:
                return Consistency(judged.ratios, None, not_judged=UNDETERMINED.format(run=logs[k], why=why))
    moved = curvature(list(fit.x + CURVATURE_STEP * np.eye(n)))
    for mv in moved:  # the fit stands; only the judging is lost
        if isinstance(mv, tuple) or not np.isfinite(mv).all():
            which, why = mv if isinstance(mv, tuple) else (
                [k for k, b in enumerate(blocks) if not np.isfinite(mv[b]).all()], "its values are not finite")
            return Consistency((None,) * g, None, not_judged=CURVATURE_FAILED.format(
                runs="every run" if len(which) == g else ", ".join(logs[k] for k in which), why=why))
    hess = np.stack([(j - fit.jac) / CURVATURE_STEP for j in moved], axis=-1)  # (R, n, n)
    live = np.split(np.any(fit.jac != 0, axis=1) | (fit.fun != 0), np.cumsum(sizes)[:-1])  # counts' rows
    scores, messages, left, skipped = np.full(g, np.nan), [], [], {}
    for group in groups:
        done = _group_scores(problem, fit, hess, group, [blocks[i][live[i]] for i in group], travels, live, refit,
                             skipped)
        if isinstance(done, str):
            return Consistency((None,) * g, None, not_judged=done)
        done, pair = done
        scores[group] = done
        worst = int(group[np.argmax(done)])
        if scores[worst] > MAX_CLOSED_SCORE:
            messages.append(f"{logs[worst]}: disagrees with the other runs (closed-path score {scores[worst]:.3g}, "
                            f"over {MAX_CLOSED_SCORE:g}: the others' fit leaves it that many times their error, and "
                            f"its own noise {'is not measured' if worst in skipped else 'does not explain it'}): "
                            "another robot, load or floor? The fit averages it in; check it or fit without it")
        elif pair is not None and pair[2] > MAX_PAIR_SCORE:
            messages.append(PAIR.format(a=logs[pair[0]], b=logs[pair[1]], score=pair[2]))
        named = 1 if scores[worst] > MAX_CLOSED_SCORE else 2 if pair is not None and pair[2] > MAX_PAIR_SCORE else 0
        if m[group[0]] - n >= MIN_OWN_DOF:  # not made with run_weights or heading_weight 0, and said
            said, out = few_pose_warning(problem, fit.x, fit.jac, fit.fun, group, ROUNDOFF * travels, logs, named)
            messages += [said] if said else []  # several runs that disagree (wmrkit.batch.likelihood)
            left += [out] if out else []  # runs left out of that check, or why not made (LEFT_OUT, NOT_PLAIN)
            left += [rest] if (rest := moved_at_rest(problem, fit.x, group, fit.fun, logs,
                                                       reference_noise)) else []
        else:  # closed paths, references of 2 poses (or 3 without heading): no own noise to judge by
            left.append(NO_OWN_NOISE.format(runs=", ".join(logs[k] for k in group)))
    aside = [k for k in range(g) if np.isnan(scores[k])]
    why = [] if not aside else [SET_ASIDE.format(runs=", ".join(logs[k] for k in aside), judged=", ".join(
        f"{len(group)} runs of {_poses(m[group[0]])}" for group in groups))]
    left += [own_skipped(skipped, logs)] if skipped else []  # runs not scored against their own noise
    return Consistency(judged.ratios, bool(messages), tuple(messages), "; ".join(why + left) or None,
                       tuple(None if np.isnan(q) else float(q) for q in scores))


def _poses(live: int) -> str:
    """How a kind of runs of `live` residuals is named: by its reference poses beyond the start."""
    return "one final pose (closed paths, references of 2 poses)" if live == 3 else f"{live // 3} poses past the start"


def _group_scores(problem: CalibrationProblem, fit, hess: np.ndarray, group: np.ndarray, rows: list[np.ndarray],
                  travels: np.ndarray, live: list[np.ndarray],
                  refit: Callable, skipped: dict[int, str]) -> tuple[np.ndarray, tuple[int, int, float] | None] | str:
    """The closed-path scores of the runs `group` (as many residuals each: their `rows` of the fleet fit) against
    each other (:func:`judge`; runs not scored against their own noise put in `skipped`) and, when none is over
    :data:`MAX_CLOSED_SCORE`, the pair of largest pair score
    (:func:`_pair`: the two runs, their pair score; ``None`` if none was scored); or why they are not judged."""
    logs, n = names(problem.runs), fit.x.size
    g, here = len(group), np.concatenate(rows)
    w = 1 / np.sqrt(travels[group])
    floors = ROUNDOFF * np.sqrt(travels[group])  # ROUNDOFF times the travel, weighted
    jac, res = fit.jac[here].reshape(g, -1, n), fit.fun[here].reshape(g, -1)
    m = np.full(g, res.shape[1])
    model = (jac * w[:, None, None], res * w[:, None], hess[here].reshape(g, -1, n, n) * w[:, None, None, None])
    scores, shift = _quadratic_scores(*model, floors, m)
    if np.isnan(scores).any():  # a run without which the others cannot fit: not judged
        k = int(np.flatnonzero(np.isnan(scores))[0])
        return UNDETERMINED.format(run=logs[group[k]], why=f"their weighted Jacobian's weakest direction under "
                                   f"{RANK_TOL:g} of the largest")
    again = [int(k) for k in np.argsort(np.linalg.norm(shift, axis=1))[::-1][:g if g < REFIT_EVERY else REFITS]]
    errs = refits(problem, group, [(k,) for k in again], [fit.x + shift[k] for k in again], live, w, refit, logs)
    if isinstance(errs, str):
        return errs
    errs = dict(zip(again, errs, strict=True))
    for k, err in errs.items():
        scores[k] = _score(err, k, np.delete(np.arange(g), k), floors, n, m)
    over = [int(k) for k in np.flatnonzero((scores > MAX_CLOSED_SCORE) & (own_dof(model[0], m) >= MIN_OWN_DOF))]
    more = [k for k in over if k not in errs]  # refitted without too, then scored over their own noise
    done = refits(problem, group, [(k,) for k in more], [fit.x + shift[k] for k in more], live, w, refit, logs)
    if isinstance(done, str):
        return done
    for k, err in zip(more, done, strict=True):
        errs[k] = err
        scores[k] = _score(err, k, np.delete(np.arange(g), k), floors, n, m)
    own = own_scores(problem, fit, group, live, w, refit, logs, over, errs, skipped) if over else None
    if isinstance(own, str):
        return own
    if own is not None:  # the smaller score: it disagrees beyond the others' noise and beyond its own
        scores[over] = np.minimum(scores[over], MAX_CLOSED_SCORE * own[over])
    if g < MIN_PAIR_RUNS or scores.max() > MAX_CLOSED_SCORE:
        return scores, None
    pair = _pair(problem, fit, group, rows, scores, model, live, w, floors, m, refit)
    return pair if isinstance(pair, str) else (scores, pair)


def _pair(problem: CalibrationProblem, fit, group: np.ndarray, rows: list[np.ndarray], scores: np.ndarray,
          model: tuple, live: list[np.ndarray], w: np.ndarray, floors: np.ndarray, m: np.ndarray,
          refit: Callable) -> tuple[int, int, float] | str | None:
    """The leave-two-out step of :func:`_group_scores`: each pair of the :data:`PAIR_CANDIDATES` runs of largest
    `scores` whose removal leaves the parameters determined is scored on the runs' quadratic `model` (weighted
    Jacobian, residuals, curvature), and the :data:`PAIR_REFITS` pairs of largest model score are refitted without
    (from the model's fit); a pair's score is the smaller of its two runs' scores against the other runs' pooled
    noise, or against the pair's own where larger (:func:`~wmrkit.batch.likelihood.own_noise`). The pair of largest
    refitted score (runs as indices of the problem), ``None`` if no pair was scored, or why a refit failed
    (:data:`REFIT_FAILED`)."""
    from itertools import combinations

    g, n, logs = len(group), fit.x.size, names(problem.runs)
    top = sorted(int(k) for k in np.argsort(scores)[::-1][:PAIR_CANDIDATES])
    pairs = []
    for out in combinations(top, 2):
        here = np.concatenate([rows[k] for k in range(g) if k not in out])
        if problem.undetermined(fit.x, fit.jac[here], fit.fun[here]) is None:
            pairs.append(out)
    guess, shift = _quadratic_scores(*model, floors, m, pairs)
    own = own_noise(*model, m)
    again = [k for k in np.argsort(-guess, kind="stable")[:PAIR_REFITS] if not np.isnan(guess[k])]
    errs = refits(problem, group, [pairs[k] for k in again], [fit.x + shift[k] for k in again], live, w, refit, logs)
    if isinstance(errs, str) or not again:
        return errs if isinstance(errs, str) else None
    best = None
    for k, err in zip(again, errs, strict=True):
        (a, b), rest = pairs[k], np.delete(np.arange(g), pairs[k])
        mine = own[a] + own[b]  # the pair's own noise, pooled
        mine = mine[0] / mine[1] if mine[1] else 0.0
        score = min(_score(err, a, rest, floors, n, m, mine), _score(err, b, rest, floors, n, m, mine))
        if best is None or score > best[2]:
            best = (int(group[a]), int(group[b]), score)
    return best
