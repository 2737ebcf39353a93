"""Do runs of few reference poses agree as a whole? A likelihood ratio judged at one false-alarm level for any fleet.

Runs whose references have three poses (start, middle, end) give 6 motion errors each against 3 parameters: 3
degrees of freedom of their own, too few for Cochran's statistic (:mod:`wmrkit.batch.homogeneity`: a run's noise
estimate small by chance weighs it up without bound; references of 4 poses already reached 333). The errors are
those of the motions between reference poses whitened by the encoders' noise model
(:func:`~wmrkit.batch.motions.whitening`): independent and of one variance, the run's own unknown noise level. The
test of common parameters is the profile likelihood ratio (normal errors, one variance per run)::

    L = min_t  sum_g m_g log RSS_g(t)  -  sum_g m_g log RSS_g(t_g),

``RSS_g(t) = |r_g + J_g t|^2`` of the ``m_g`` whitened motion errors (linear at the fleet fit), ``t_g`` the run's own
fit. A run's term at the true parameters is ``m_g log(1 + X / Y)``, ``X`` and ``Y`` its noise's chi-square parts of
``rank_g`` (its whitened Jacobian's) and ``m_g - rank_g`` degrees of freedom, whatever its noise level: ``-m_g
log(1 - B)``, ``B`` of the beta distribution ``(rank_g / 2, (m_g - rank_g) / 2)``. Their sum over all runs bounds
``L``; where one run is much quieter than the others (the fleet fit is its own) ``L`` is exactly the sum over the
others, and it is close to so distributed for any mix of noise levels and paths (40,000 fleets of 5 and 8 runs,
precisions drawn over 4 decades: over the 1 % point 1.03 % and 0.98 %, over the 0.1 % point 0.12 % and 0.06 %). So a
fleet is flagged when ``L`` is over that sum's point of chance :data:`LEVEL` (:func:`threshold`, exact on a grid), one
design level for any number of runs (measured, 40,000 fleets each: 5 runs 0.118 %, 8 runs 0.060 %, 12 runs
0.070-0.115 % over five seeds, 0.084 % pooled: 8 and 12 runs 2.5 and 2.3 standard errors under it). Unwhitened
(before), the terms depended on each run's motions (agreeing fleets of 5: median 10.2 a run; whitened 3.9) and the
fleet was flagged at ``L / G`` over 24, 4.5 spreads of the agreeing fleets' mean for 5 runs and 5.3 for 8: no stated
level, and 3 bad runs of 6 missed in 4 of 150 fleets. Noise-free runs' own fits count as the round-off floor,
whitened. The minimum is found from the fleet fit and each run's own fit (the likelihood has a mode per cluster of
runs) by iteratively reweighted least squares (weights ``m_g / RSS_g``: a majorise-minimise step, never uphill).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from functools import lru_cache

import numpy as np

from ..odometry.calibration import CalibrationProblem
from .homogeneity import NOT_PLAIN, fewest, plain_only
from .motions import whitening

#: Chance that a fleet of agreeing runs is said to disagree (``L`` over its :func:`threshold`), for any number of runs.
#: Seeded fleets of three-pose runs (random arcs, levels drawn per run among 1e-6, 1e-5 and 1e-4 per rad): agreeing,
#: 0 of 300 of 5 and of 6 flagged, 1 of 300 of 8; 3 runs of a left radius +5 % among 6, 150 of 150 (146 at 24 a
#: run before), 2 bad: 93 of 150 (87), 4 bad: 78 of 100 (66). At 1e-4 the 2 and 4 bad runs: 44 and 45 (docs/batch.md).
LEVEL = 1e-3
#: Least step of the grid on which :func:`threshold` sums the runs' terms' distributions: the step is the sum's range
#: over 65,536 where larger (fleets of more than 6 three-pose runs; 0.09 for 50), each term rounded to its nearest
#: point (simulated sums over it: the level within 3 standard errors, tests/batch/test_calibrate_likelihood_level.py).
GRID = 0.01
#: Fewest degrees of freedom of every run's own fit for this check (three-pose references: 3; a closed path or a
#: reference of two poses has none, its own fit is exact, and its fleet's homogeneity is not judged).
MIN_OWN_DOF = 3
#: Why a run's whitened motions' errors are not judged ({free}: their degrees of freedom beyond its own fit): too
#: few (a motion left out: at rest, :data:`~wmrkit.batch.motions.AT_REST`). Before, such a run with one motion left
#: (3 errors, rank 3) made the fleet likelihood ratio's threshold NaN: ValueError out of the fleet fit.
FEW_DOF = ("its whitened motions' errors have {free} degrees of freedom beyond its own fit, fewer than "
           f"{MIN_OWN_DOF}")
#: Most iterations of the reweighted least squares from each start.
ITERATIONS = 200
#: Why runs are left out of this check (said in ``not_judged``; {runs}: the runs; {why}: each run's why; {rest}: what
#: is checked): their motions' errors cannot be whitened. Before, they were left out unsaid.
LEFT_OUT = ("{runs}: left out of the whole-fleet check (the fleet likelihood ratio of the runs' motions' errors "
            "whitened by the encoders' noise model, which finds several runs that disagree): {why}; {rest}, and each "
            "run is still scored against the others on its own")


def likelihood_ratio(a: np.ndarray, b: np.ndarray, c: np.ndarray, own: np.ndarray, m: np.ndarray) -> np.ndarray:
    """``L`` (module docstring) of the runs of normal matrices `a` ``(..., G, n, n)``, scores `b` ``(..., G, n)``, sums
    of squares at the fleet fit `c`, own-fit sums of squares `own` (at least the round-off floor) and motion errors
    `m` ``(..., G)``: one per fleet of the leading axes (a float for one fleet), each iterated until it settles."""
    lead, n = c.shape[:-1], b.shape[-1]
    m = np.broadcast_to(np.asarray(m, dtype=float), c.shape)
    a, b, c, own, m = (np.reshape(x, (-1, *x.shape[len(lead):])) for x in (a, b, c, own, m))
    d = -np.einsum("fgij,fgj->fgi", np.linalg.pinv(a, hermitian=True), b)
    d = np.concatenate([np.zeros((len(c), 1, n)), d], axis=1)  # (F, S, n): the fleet fit and each run's own

    def rss(d: np.ndarray, f: np.ndarray | slice) -> np.ndarray:  # (F', S, G) at the shifts d (F', S, n)
        ad = np.einsum("fgij,fsj->fsgi", a[f], d)
        return np.maximum(c[f][:, None] + 2 * np.einsum("fsi,fgi->fsg", d, b[f])
                          + np.einsum("fsgi,fsi->fsg", ad, d), own[f][:, None])

    live = np.arange(len(c))
    for _ in range(ITERATIONS):
        w = m[live][:, None] / rss(d[live], live)
        new = -np.linalg.solve(np.einsum("fsg,fgij->fsij", w, a[live]),
                               np.einsum("fsg,fgi->fsi", w, b[live])[..., None])[..., 0]
        moved = ~np.all(np.isclose(new, d[live], rtol=1e-12, atol=1e-300), axis=(1, 2))
        d[live] = new
        live = live[moved]
        if not live.size:
            break
    out = (np.min(np.einsum("fsg,fg->fs", np.log(rss(d, slice(None))), m), axis=1)
           - np.einsum("fg,fg->f", np.log(own), m)).reshape(lead)
    return out if lead else float(out)


def whitened_parts(problem: CalibrationProblem, p: np.ndarray, jac: np.ndarray, res: np.ndarray, group: Sequence[int],
                   floors: Sequence[float]) -> tuple[tuple[np.ndarray, ...], list[int], dict[int, str]]:
    """The arguments of :func:`likelihood_ratio` for the runs `group` (`jac`, `res` of the fleet fit at parameters
    `p`; `floors`: least RSS root of each run's own fit [m]) on their whitened motions' errors
    (:func:`~wmrkit.batch.motions.whitening`), and the rank of each run's whitened Jacobian; runs that cannot be
    whitened, or have fewer than :data:`MIN_OWN_DOF` degrees of freedom so (:data:`FEW_DOF`), are left out: the
    places in `group` kept, and those left out with why."""
    sizes = problem.sizes()
    ends = np.cumsum(sizes)
    parts, kept, left = ([], [], [], [], [], []), [], {}
    for i, k in enumerate(group):
        lo, hi = int(ends[k] - sizes[k]), int(ends[k])
        white = whitening(problem, p, problem.runs[k], res[lo:hi])
        if isinstance(white, str):
            left[i] = white
            continue
        j, r = white @ jac[lo:hi], white @ res[lo:hi]
        step, _, rank, _ = np.linalg.lstsq(j, r, rcond=None)
        if r.size - rank < MIN_OWN_DOF:
            left[i] = FEW_DOF.format(free=r.size - rank)
            continue
        own = max(float(np.sum(np.square(r - j @ step))), floors[k] ** 2 * float(np.sum(np.square(white))))
        for part, x in zip(parts, (j.T @ j, j.T @ r, r @ r, own, len(r), rank), strict=True):
            part.append(x)
        kept.append(i)
    return (*(np.array(x, dtype=float) for x in parts[:5]), np.array(parts[5], dtype=int)), kept, left


@lru_cache(maxsize=1024)
def threshold(runs: tuple[tuple[int, int], ...], level: float = LEVEL) -> float:
    """The point ``L`` of agreeing runs of `runs` ``(m_g, rank_g)`` (motion errors and rank of the whitened Jacobian,
    sorted) exceeds with the chance `level`: that of the sum of the terms at the true parameters of all runs but one
    of largest rank (module docstring), each ``-m log(1 - B)``, ``B ~ Beta(rank / 2, (m - rank) / 2)``, summed exactly
    on a grid (by FFT; each term rounded to its nearest point, :data:`GRID` apart or more)."""
    from scipy import special, stats

    terms = sorted(runs, key=lambda x: x[1])[:-1]
    tops = [-m * np.log1p(-stats.beta.isf(1e-13, r / 2, (m - r) / 2)) if r else 0.0 for m, r in terms]
    step = max(GRID, sum(tops) / (1 << 16))
    n = int(np.ceil(sum(tops) / step)) + 2
    grid = np.arange(n) * step
    size = 1 << int(np.ceil(np.log2(2 * n)))
    total = np.ones(size // 2 + 1, dtype=complex)
    for (m, r), count in Counter(terms).items():
        cdf = special.betainc(r / 2, (m - r) / 2, -np.expm1(-(grid + step / 2) / m)) if r else np.ones(n)
        total *= np.fft.rfft(np.diff(np.r_[0.0, cdf]), size) ** count
    cdf = np.cumsum(np.fft.irfft(total, size)[:n])
    return float(grid[min(int(np.searchsorted(cdf, 1 - level)), n - 1)])


def left_out(group: Sequence[int], kept: Sequence[int], left: dict[int, str], logs: Sequence[str]) -> str | None:
    """:data:`LEFT_OUT` for the runs of places `left` in `group` (with why; `kept`: those checked), or ``None``."""
    if not left:
        return None
    return LEFT_OUT.format(runs=", ".join(logs[group[i]] for i in left),
                           why="; ".join(f"{logs[group[i]]}: {why}" for i, why in left.items()),
                           rest=f"the other {len(kept)} runs are checked" if len(kept) >= 3 else
                           f"{len(kept)} runs are left, too few: the check is not made")


def few_pose_warning(problem: CalibrationProblem, p: np.ndarray, jac: np.ndarray, res: np.ndarray,
                     group: Sequence[int], floors: Sequence[float], logs: Sequence[str],
                     named: int = 0) -> tuple[str | None, str | None]:
    """The warning when the runs `group` (as many reference poses each; `jac`, `res` of the fleet fit at parameters
    `p`; `floors`: least RSS root of each run's own fit [m]) do not agree as a whole (``L`` over its
    :func:`threshold`), with the fewest runs whose removal leaves the others agreeing; ``None`` when they agree, or
    when as many runs as were `named` (1: by a closed-path score, 2: by the pair score) explain it. And the runs
    left out of the check, named with why (:data:`LEFT_OUT`), or why it is not made at all (run weights or no
    heading: :data:`~wmrkit.batch.homogeneity.NOT_PLAIN`), or ``None``."""
    why = plain_only(problem)
    if why is not None:
        return None, NOT_PLAIN.format(check="the fleet likelihood ratio of the runs' whitened motions' errors", why=why)
    (a, b, c, own, m, rank), kept, left = whitened_parts(problem, p, jac, res, group, floors)
    aside = left_out(group, kept, left, logs)
    if len(kept) < 3:
        return None, aside

    def limit(keep: np.ndarray) -> float:
        return threshold(tuple(sorted(zip(m[keep].astype(int).tolist(), rank[keep].tolist(), strict=True))))

    def over(keep: np.ndarray) -> float:  # L over its threshold: at most 1 when the runs `keep` agree
        return likelihood_ratio(a[keep], b[keep], c[keep], own[keep], m[keep]) / limit(keep)

    every = np.arange(len(kept))
    score, top = likelihood_ratio(a, b, c, own, m), limit(every)
    if score <= top:
        return None, aside
    n, out = fewest(len(kept), over, 1.0)
    if n <= named:
        return None, aside
    without = f" (without {', '.join(logs[group[kept[i]]] for i in out)} the others agree)" if out else ""
    return (f"the runs disagree among themselves (fleet likelihood ratio {score:.3g}, over {top:.3g}, which "
            f"{len(kept)} agreeing runs exceed with a chance of {LEVEL:g}: their parameters are further apart than "
            "each run's own noise allows): at least "
            f"{'one run disagrees' if n == 1 else f'{n} runs disagree'} with the others{without}: another robot, load "
            "or floor? The fit averages them; calibrate them apart"), aside


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
