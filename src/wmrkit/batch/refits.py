"""The closed-path judge's fits on the engine (:func:`wmrkit.batch.consistency.judge`): a fleet's runs refitted with
some left out, and a run's score against its own noise (:func:`own_scores`).

A run's error at the other runs' fit is its own noise plus their fit's error. Over the others' pooled noise alone, a
noisy run among quiet ones scored the ratio of the noise levels: agreeing fleets of 6 three-pose runs, levels drawn
per run among 1e-6, 1e-5 and 1e-4 per rad, 12 of 2,000 flagged (scores 20-50), two runs at 1e-4 among four at
1e-6, 2 of 500 (docs/batch.md). A run over the threshold whose own fit has degrees of freedom
(:data:`~wmrkit.batch.likelihood.MIN_OWN_DOF`: three-pose references; closed paths and two-pose references have
none) is scored against its own noise too, by an F test of its misfit at the others' fit over its own fit's residual
on its whitened motions' errors (:mod:`wmrkit.batch.motions`), and the smaller score is kept. Over its pose errors'
own fit instead (before), whose residual hides most of the errors' random walk, 1 of the 2,000 fleets was still
flagged (seed 778: a run at 1e-4 per rad scored 22.4; 9.0 now).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ..odometry.calibration import CalibrationProblem
from .engine import TaskFailure
from .likelihood import FEW_DOF, MIN_OWN_DOF
from .motions import whitening

#: Level of the F test of a run's misfit at the other runs' fit against its own noise (:func:`own_scores`): the
#: chance that an agreeing run whose score over the others' noise is over MAX_CLOSED_SCORE (a noisy run among quiet
#: ones) is named all the same (its score against its own noise, 20 sqrt(F / F_crit), over 20 too). Over its pose
#: errors' own fit (before), whose residual hides most of their random walk, a noisy agreeing run scored over 20 in 3
#: of 150 runs (tests/batch/test_calibrate_own_noise.py) and 1 of 2,000 agreeing fleets was flagged (0 now); at 0.001
#: a run of a left radius +5 % among runs of levels drawn per run was named in 231 of 300 fleets where the pose
#: errors named it in 256; at 0.01 in 257 (docs/batch.md).
OWN_LEVEL = 0.01

#: Why a closed fleet is not judged when that refit fails (a worker's error, residuals not finite): the fleet fit is
#: returned all the same ({run}: the run left out; {why}: the error).
REFIT_FAILED = ("{run}: the fit of the other runs without {it} failed ({why}): the closed runs are not checked against "
                "each other, a run of another robot is averaged in unseen (the fleet fit stands)")
#: Why runs named over the other runs' noise were not scored against their own (said in ``not_judged``; {runs}: the
#: runs; {why}: each run's why): :func:`own_scores` has no F test for them. Before, they were skipped unsaid and
#: their warning said their own noise did not explain their score (an agreeing run at 1e-4 per rad among quieter
#: ones, its middle reference one sample after the start: 29.3, named as another robot's).
OWN_SKIPPED = ("{runs}: scored against the other runs' noise only, not against its own ({why}): a run noisier than "
               "the others scores high there too, so its warning may be its noise, not another robot")


def refits(problem: CalibrationProblem, group: np.ndarray, outs: list[tuple[int, ...]], starts: list[np.ndarray],
           live: list[np.ndarray], w: np.ndarray, refit: Callable, logs: Sequence[str],
           fits: list | None = None) -> list[np.ndarray] | str:
    """For each of `outs` (places in `group`), the weighted counted residuals of the runs of `group` (a row each, in
    its order) at the fit of its other runs from `starts` by `refit` (:func:`~wmrkit.batch.consistency.judge`'s),
    those fits' parameters appended to `fits` if given; or why not (:data:`REFIT_FAILED`; `logs`: the runs'
    names)."""
    runs = problem.runs
    orders = [[int(i) for k, i in enumerate(group) if k not in out] + [int(group[k]) for k in out] for out in outs]
    tasks = [(problem.with_runs([runs[i] for i in o]), x0, len(out))  # those left out last
             for o, x0, out in zip(orders, starts, outs, strict=True)]
    errs = []
    for out, order, done in zip(outs, orders, refit(tasks), strict=True):
        err = None if isinstance(done, TaskFailure) else np.asarray(done[1], dtype=float)
        if err is None or not np.isfinite(err).all():  # the fit stands; only the judging is lost
            return REFIT_FAILED.format(run=" and ".join(logs[group[k]] for k in out), it="them" if out[1:] else "it",
                                       why=done if err is None else "its residuals are not finite")
        if fits is not None:
            fits.append(np.asarray(done[0], dtype=float))
        parts = np.split(err, np.cumsum([live[i].size for i in order])[:-1])
        mine = dict(zip(order, (p[live[i]] for p, i in zip(parts, order, strict=True)), strict=True))
        errs.append(np.array([mine[int(i)] for i in group]) * w[:, None])
    return errs


def own_dof(jac: np.ndarray, m: np.ndarray) -> np.ndarray:
    """Each run's degrees of freedom of its own fit: its `m` residuals that count less the rank of its Jacobian
    ``(G, M, n)``."""
    return m - np.array([np.linalg.matrix_rank(j) for j in jac])


def own_scores(problem: CalibrationProblem, fit, group: np.ndarray, live: list[np.ndarray], w: np.ndarray,
               refit: Callable, logs: Sequence[str], which: Sequence[int], errs: dict,
               skipped: dict[int, str]) -> np.ndarray | str:
    """Each of the runs `which` (places in `group`; `errs`: for each, the weighted residuals of `group` at the fit of
    the others, :func:`refits`) scored against its own noise: the F statistic of its motions' errors, whitened by
    its encoders' noise model about the fleet fit (:func:`~wmrkit.batch.motions.whitening`), at the others' fit
    against its own fit (refitted alone by `refit` from the fleet fit `fit`, then one Gauss-Newton step on the
    whitened errors, the Jacobian at that fit), ``F = (S_others - S_own) / rank / (S_own / dof)``, as
    ``sqrt(F / F_crit)`` (over 1: the run disagrees beyond its own noise), ``F_crit`` the F distribution's
    :data:`OWN_LEVEL` point of ``(rank, dof)`` degrees of freedom (module docstring); ``inf`` where the run has no
    such score (fewer than :data:`~wmrkit.batch.likelihood.MIN_OWN_DOF` degrees of freedom, a motion the encoders do
    not see, a sample weighted 0: each put in `skipped`, run index to why, :func:`own_skipped`; a noise-free own
    fit, whose F is infinite), ``(G,)``; or why a fit failed."""
    from scipy import stats

    sizes = problem.sizes()
    starts = np.r_[0, np.cumsum(sizes)[:-1]]
    xs: list[np.ndarray] = []
    alone = refits(problem, group, [tuple(np.delete(np.arange(len(group)), k).tolist()) for k in which],
                   [fit.x] * len(which), live, w, refit, logs, xs)
    if isinstance(alone, str):
        return alone
    out = np.full(len(group), np.inf)
    for k, mine, x in zip(which, alone, xs, strict=True):
        i = int(group[k])
        run, rows = problem.runs[i], slice(int(starts[i]), int(starts[i] + sizes[i]))
        weight = np.ones(sizes[i]) if problem.run_weights is None else np.repeat(
            np.asarray(problem.run_weights(run), dtype=float), 3)
        white = whitening(problem, fit.x, run, fit.fun[rows] / weight) if np.all(weight > 0) else (
            "a sample of it weighted 0")
        if isinstance(white, str):
            skipped[i] = white
            continue
        poses = np.zeros((2, sizes[i]))  # its weighted live rows, alone and at the others' fit -> pose errors
        poses[:, live[i]] = np.array([mine[k], errs[k][k]]) / w[k]
        jw = white @ (problem.with_runs([run]).jacobian(x) / weight[:, None])  # at its own fit, as the worker ran
        rw, far = (white @ (poses / weight).T).T
        step, _, rank, _ = np.linalg.lstsq(jw, rw, rcond=None)
        own, free = float(np.sum(np.square(rw - jw @ step))), rw.size - rank
        if free < MIN_OWN_DOF:
            skipped[i] = FEW_DOF.format(free=free)
        elif own > 0:
            f = max(float(far @ far) - own, 0.0) / rank / (own / free)
            out[k] = np.sqrt(f / stats.f(rank, free).isf(OWN_LEVEL))
    return out


def own_skipped(skipped: dict[int, str], logs: Sequence[str]) -> str:
    """:data:`OWN_SKIPPED` for the runs `skipped` (run index to why, :func:`own_scores`)."""
    return OWN_SKIPPED.format(runs=", ".join(logs[i] for i in skipped),
                              why="; ".join(f"{logs[i]}: {why}" for i, why in skipped.items()))
