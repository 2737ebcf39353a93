"""Do runs of few reference poses agree as a whole? A likelihood ratio that each run's own noise level cannot move.

Runs whose references have three poses (start, middle, end) give 6 motion errors each
(:func:`~wmrkit.batch.homogeneity.increments`) against 3 parameters: 3 degrees of freedom of their own, too few for
Cochran's statistic (:mod:`wmrkit.batch.homogeneity`: a run's noise estimate small by chance weighs it up without bound;
references of 4 poses already reached 333). Each run ``g`` has its own unknown noise level, so the test of common
parameters is the profile likelihood ratio (normal errors, one variance per run)::

    L = min_t  sum_g m_g log RSS_g(t)  -  sum_g m_g log RSS_g(t_g),

``RSS_g(t) = |r_g + J_g t|^2`` of the ``m_g`` motion errors (linear at the fleet fit), ``t_g`` the run's own fit. A
run's term is ``m_g log(1 + excess_g / own_g)``: a ratio of two quadratic forms of the same noise, so a run's noise
level does not move its term's distribution (at the true parameters exactly; noise-free runs' own fits count as the
round-off floor), and the logarithm tames the small own fits that make Cochran's weights blow up. Agreeing fleets of
mixed noise levels score as fleets of one level (median 10.7 and 10.5 against 10.4 a run, fleets of 6). ``L`` grows with
the runs (about 10 a run in agreeing fleets), so a fleet is judged by ``L / G`` over :data:`MAX_PER_RUN`. The minimum is
found from the fleet fit and each run's own fit (the likelihood has a mode per cluster of runs) by iteratively
reweighted least squares (weights ``m_g / RSS_g``: a majorise-minimise step, never uphill).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..odometry.calibration import CalibrationProblem
from .homogeneity import fewest, increments

#: Largest ``L / G`` of a fleet whose runs agree. Simulated agreeing fleets of three-pose runs (random arcs as the
#: tests'; noise 1e-5 per rad, levels drawn per run among 1e-6, 1e-5 and 1e-4, or two runs at 1e-4 among four at
#: 1e-6): 3,800 of 5 runs at most 23.1 (next 21.1, 99.9th percentile 20.5), 2,000 of 6 at most 19.8 (one level:
#: 19.8, the worst mix: 18.5, drawn: 19.8), 500 of 8 18.4. Three runs of a left radius +5 % among 6: 23.2 or more,
#: 147 of 150 over 24.
MAX_PER_RUN = 24.0
#: Fewest degrees of freedom of every run's own fit for this check (three-pose references: 3; a closed path or a
#: reference of two poses has none, its own fit is exact, and its fleet's homogeneity is not judged).
MIN_OWN_DOF = 3
#: Most iterations of the reweighted least squares from each start.
ITERATIONS = 200


def likelihood_ratio(a: np.ndarray, b: np.ndarray, c: np.ndarray, own: np.ndarray, m: np.ndarray) -> float:
    """``L`` (module docstring) of the runs of normal matrices `a` ``(G, n, n)``, scores `b` ``(G, n)``, sums of
    squares at the fleet fit `c`, own-fit sums of squares `own` (at least the round-off floor) and motion errors
    `m`."""
    starts = np.vstack([np.zeros(a.shape[1]), -np.einsum("gij,gj->gi", np.linalg.pinv(a, hermitian=True), b)])

    def rss(d: np.ndarray) -> np.ndarray:  # (S, G) at the shifts d (S, n)
        return np.maximum(c + 2 * d @ b.T + np.einsum("si,gij,sj->sg", d, a, d), own)

    d = starts
    for _ in range(ITERATIONS):
        w = m / rss(d)
        new = -np.linalg.solve(np.einsum("sg,gij->sij", w, a), (w @ b)[..., None])[..., 0]
        done = np.allclose(new, d, rtol=1e-12, atol=1e-300)
        d = new
        if done:
            break
    return float(np.min(np.log(rss(d)) @ m) - np.log(own) @ m)


def few_pose_warning(problem: CalibrationProblem, jac: np.ndarray, res: np.ndarray, group: Sequence[int],
                     floors: Sequence[float], logs: Sequence[str], named: int = 0) -> str | None:
    """The warning when the runs `group` (as many reference poses each; `jac`, `res` of the fleet fit; `floors`:
    least RSS root of each run's own fit [m]) do not agree as a whole (``L / G`` over :data:`MAX_PER_RUN`), with the
    fewest runs whose removal leaves the others agreeing; ``None`` when they agree, or when as many runs as were
    `named` (1: by a closed-path score, 2: by the pair score) explain it."""
    sizes = problem.sizes()
    ends = np.cumsum(sizes)
    parts = [], [], [], [], []
    for k in group:
        lo, hi = int(ends[k] - sizes[k]), int(ends[k])
        j, r = increments(problem.runs[k], problem.heading_weight, jac[lo:hi], res[lo:hi])
        live = np.any(j != 0, axis=1) | (r != 0)
        j, r = j[live], r[live]
        step = np.linalg.lstsq(j, r, rcond=None)[0]
        for part, x in zip(parts, (j.T @ j, j.T @ r, r @ r, max(float(np.sum(np.square(r - j @ step))),
                                                                   floors[k] ** 2 * len(r)), len(r)), strict=True):
            part.append(x)
    a, b, c, own, m = (np.array(x, dtype=float) for x in parts)

    def per_run(keep: np.ndarray) -> float:
        return likelihood_ratio(a[keep], b[keep], c[keep], own[keep], m[keep]) / len(keep)

    score = per_run(np.arange(len(group)))
    if score <= MAX_PER_RUN:
        return None
    n, out = fewest(len(group), per_run, MAX_PER_RUN)
    if n <= named:
        return None
    without = f" (without {', '.join(logs[group[i]] for i in out)} the others agree)" if out else ""
    return (f"the runs disagree among themselves (fleet likelihood ratio {score:.3g} a run, over {MAX_PER_RUN:g}: "
            "their parameters are further apart than each run's own noise allows): at least "
            f"{'one run disagrees' if n == 1 else f'{n} runs disagree'} with the others{without}: another robot, load "
            "or floor? The fit averages them; calibrate them apart")


def own_noise(jac: np.ndarray, res: np.ndarray, hess: np.ndarray, m: np.ndarray) -> np.ndarray:
    """Each run's own fit's residual sum of squares, on its quadratic model (`jac` ``(G, M, n)``, `res` ``(G, M)``,
    `hess` ``(G, M, n, n)``: a bad run's own fit is far from the fleet fit, where the linear model left 8 times its
    sum), and its degrees of freedom (`m` rows count), ``(G, 2)``, where it has :data:`MIN_OWN_DOF` or more
    (three-pose references), else zeros. For the pair score (:func:`wmrkit.batch.consistency._pair`): against the
    others' pooled noise alone, the pair of the two noisiest runs of a fleet scored the ratio of the noise levels (two
    runs at 1e-4 per rad among four at 1e-6: up to 44.9, 4 of 500 agreeing fleets flagged); a pair's score is over
    the two runs' pooled own noise where larger."""
    from scipy.optimize import least_squares

    out = np.zeros((len(jac), 2))
    for k, (j, r, h) in enumerate(zip(jac, res, hess, strict=True)):
        rank = np.linalg.matrix_rank(j)
        if m[k] - rank >= MIN_OWN_DOF:
            fit = least_squares(lambda d: r + j @ d + 0.5 * np.einsum("mij,i,j->m", h, d, d),  # noqa: B023
                                np.zeros(j.shape[1]), jac=lambda d: j + np.einsum("mij,j->mi", h, d),  # noqa: B023
                                method="lm", xtol=1e-12, ftol=1e-12)
            out[k] = float(np.sum(np.square(fit.fun))), m[k] - rank
    return out
