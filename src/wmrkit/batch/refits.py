"""The closed-path judge's fits on the engine (:func:`wmrkit.batch.consistency.judge`): a fleet's runs refitted with
some left out, and each run's own fit (its own noise, which a run's score is over where larger than the others').

A run's error at the other runs' fit is its own noise plus their fit's error. Over the others' pooled noise alone, a
noisy run among quiet ones scored the ratio of the noise levels: agreeing fleets of 6 three-pose runs, levels drawn
per run among 1e-6, 1e-5 and 1e-4 per rad, 12 of 2,000 flagged (scores 20-50), two runs at 1e-4 among four at
1e-6, 2 of 500 (docs/batch.md). A run over the threshold whose own fit has degrees of freedom
(:data:`~wmrkit.batch.likelihood.MIN_OWN_DOF`: three-pose references; closed paths and two-pose references have
none) is scored over its own noise where larger: 1 of 2,000 and 0 of 500 flagged.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ..odometry.calibration import CalibrationProblem
from .engine import TaskFailure
from .likelihood import MIN_OWN_DOF

#: Why a closed fleet is not judged when that refit fails (a worker's error, residuals not finite): the fleet fit is
#: returned all the same ({run}: the run left out; {why}: the error).
REFIT_FAILED = ("{run}: the fit of the other runs without {it} failed ({why}): the closed runs are not checked against "
                "each other, a run of another robot is averaged in unseen (the fleet fit stands)")


def refits(problem: CalibrationProblem, group: np.ndarray, outs: list[tuple[int, ...]], starts: list[np.ndarray],
           live: list[np.ndarray], w: np.ndarray, refit: Callable, logs: Sequence[str]) -> list[np.ndarray] | str:
    """For each of `outs` (places in `group`), the weighted counted residuals of the runs of `group` (a row each, in
    its order) at the fit of its other runs from `starts` by `refit` (:func:`~wmrkit.batch.consistency.judge`'s);
    or why not (:data:`REFIT_FAILED`; `logs`: the runs' names)."""
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
        parts = np.split(err, np.cumsum([live[i].size for i in order])[:-1])
        mine = dict(zip(order, (p[live[i]] for p, i in zip(parts, order, strict=True)), strict=True))
        errs.append(np.array([mine[int(i)] for i in group]) * w[:, None])
    return errs


def own_fits(problem: CalibrationProblem, x: np.ndarray, group: np.ndarray, jac: np.ndarray, m: np.ndarray,
             live: list[np.ndarray], w: np.ndarray, refit: Callable, logs: Sequence[str],
             which: Sequence[int]) -> np.ndarray | str:
    """The own noise of the runs `which` (places in `group`; `jac` ``(G, M, n)`` their weighted Jacobians, `m` rows
    each), mean square a row: each one's own fit (by `refit` from the fleet fit `x`, the other runs left out), its
    weighted residual sum of squares over its degrees of freedom, where it has
    :data:`~wmrkit.batch.likelihood.MIN_OWN_DOF` or more, else 0, ``(G,)``; or why a fit failed. Not on the runs'
    quadratic model about the fleet fit (:func:`~wmrkit.batch.likelihood.own_noise`, the pair's): a bad run's own fit
    is far from there, and a quiet run of a left radius +20 % scored 32 over it where it scores 285 over its refit."""
    dof = m - np.array([np.linalg.matrix_rank(j) for j in jac])
    mine = [int(k) for k in which if dof[k] >= MIN_OWN_DOF]
    errs = refits(problem, group, [tuple(np.delete(np.arange(len(group)), k).tolist()) for k in mine],
                  [x] * len(mine), live, w, refit, logs)
    if isinstance(errs, str):
        return errs
    out = np.zeros(len(group))
    for k, err in zip(mine, errs, strict=True):
        out[k] = float(np.sum(err[k] ** 2)) / dof[k]
    return out
