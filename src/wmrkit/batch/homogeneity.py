"""Do a fleet's runs agree as a whole? A homogeneity statistic over every run that measures its own noise.

The residual ratio (:mod:`wmrkit.batch.consistency`) judges one run at a time against the others' fit and their
error; two or more bad runs inflate that error and hide each other (3 runs of a left radius +20 % among 8: every
ratio under 10, the fleet reported clean). Here each run ``g`` whose own fit has :data:`MIN_DOF` degrees of freedom
or more estimates its own noise, ``s_g = own_g / dof_g``, and its parameters ``t_g``, on the errors of its motions
between reference poses (:func:`increments`: independent from one interval to the next, where the pose errors are a
random walk); with ``A_g = J_g' J_g``, ``b_g = J_g' r_g`` of those (linear at the fleet fit: ``t_g = -A_g^+ b_g``)
the statistic is Cochran's, multivariate::

    Q = min_t  sum_g (t - t_g)' A_g (t - t_g) / s_g  =  sum_g b_g' A_g^+ b_g / s_g  -  B' W^+ B,

``W`` the sum of ``A_g / s_g`` and ``B`` that of ``b_g / s_g``: the excess residual of the fit that weighs each run
by its own noise, each run's part over that run's noise. ``H = Q / df``, ``df`` the sum of the runs' ranks less that
of ``W``: 2-3 when the runs agree, whatever their noise levels (each is judged against its own). The fleet fit's
unweighted excess over each run's own (tried first) let a quiet run among noisy ones reach 33 (agreeing fleets of 4).

When ``H`` exceeds :data:`MAX_HOMOGENEITY` the fewest runs whose removal leaves runs that agree are sought, every
subset of 1, 2, ... runs up to :data:`SEARCH` subsets: that many runs at least disagree with the others.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from itertools import combinations

import numpy as np

from ..odometry.calibration import RANK_TOL, CalibrationProblem, CalibrationRun

#: Largest ``H`` of a fleet whose runs agree. Simulated fleets (random arcs as the tests', noise 1e-5 per rad or drawn
#: per run among 1e-6, 1e-5 and 1e-4, 3 to 12 runs; docs/batch.md): 3,000 agreeing fleets through ``fleet_calibrate``
#: none flagged, largest 34.4 (a run at 1e-4 whose data alone ask for a track +266 %, among quieter runs), next 25.0,
#: 99.9th percentile 11.1 (1,500 with references every 5th sample); 140,000 drawn from a pool of runs: at most 23.6.
#: Fleets with 2 to 4 runs of a left radius +5 % or +20 %: 67.7 or more (714 fleets of 4-12 runs, all flagged).
MAX_HOMOGENEITY = 60.0
#: Fewest degrees of freedom of a run's own fit (of its motions' errors) for this check: its noise estimate must be
#: good, one small by chance weighs the run up. Agreeing fleets of runs of 4 reference poses (6 degrees) reached 333,
#: of 8 (18) 39.6, of 11 (27) 30.0, every 5th sample (33) 23.6 (200,000 fleets each, from pools). Runs with fewer are
#: not covered by this check (their residual ratios or closed-path scores still are).
MIN_DOF = 27
#: Most subsets of runs left out in the search for the fewest runs that explain a disagreement.
SEARCH = 5000
#: Why a whole-fleet check (this one, or :mod:`wmrkit.batch.likelihood`'s) is not made for runs it would judge
#: ({check}: which; {why}: :func:`plain_only`): the motions' errors need the plain residuals and the odometry's
#: heading. Said in ``not_judged``; before, a Python fit with ``run_weights`` or ``heading_weight=0`` skipped it
#: unsaid (three runs of another robot among 8: 'inconsistent' false, no warning, 'not_judged' null).
NOT_PLAIN = ("the whole-fleet check ({check}, which finds several runs that disagree) is not made: the fit {why} (the "
             "check needs each run's plain residuals with their heading, as batch calibrate fits them); each run is "
             "still checked against the others on its own, several runs that disagree may hide each other")


def plain_only(problem: CalibrationProblem) -> str | None:
    """Why the problem's residuals are not the plain ones the whole-fleet checks need (:data:`NOT_PLAIN`), or
    ``None``."""
    if problem.run_weights is not None:
        return "weighs its residuals by run_weights"
    return "has no heading (heading_weight 0)" if problem.heading_weight == 0 else None


def increments(run: CalibrationRun, heading_weight: float, jac: np.ndarray,
               res: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The run's residuals `res` (``(3M,)``: ``x``, ``y`` and weighted heading error per reference pose) as the
    errors of the motions between consecutive reference poses, each in the frame of the first (odometry's motion less
    the reference's, exact), and their Jacobian from `jac` ``(3M, n)`` (linear at the odometry's poses). An
    encoder's noise accumulates along the run, so the pose errors are a random walk whose own fit hides most of it
    (agreeing runs' parameters 4-6 times as far apart as their own residuals said), while the motions' errors are
    independent from one interval to the next (0.7-1.9 times)."""
    ref = np.asarray(run.reference, dtype=float).reshape(-1, 3)
    odo = ref + res.reshape(-1, 3) / [1.0, 1.0, heading_weight]

    def motions(poses: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        prev = np.vstack([run.start(), poses[:-1]])
        step = poses - prev
        return prev, step, np.column_stack([_turn(step[:, :2], -prev[:, 2]), step[:, 2] * heading_weight])

    prev, step, moved = motions(odo)
    e = jac.reshape(len(ref), 3, -1)
    before = np.concatenate([np.zeros_like(e[:1]), e[:-1]])  # the run starts at its start pose: no error there
    turn = before[:, 2] / heading_weight  # the heading error before the interval turns its motion
    dx = e[:, 0] - before[:, 0] + step[:, 1, None] * turn
    dy = e[:, 1] - before[:, 1] - step[:, 0, None] * turn
    c, s = np.cos(prev[:, 2])[:, None], np.sin(prev[:, 2])[:, None]
    rows = np.stack([c * dx + s * dy, c * dy - s * dx, e[:, 2] - before[:, 2]], axis=1).reshape(jac.shape)
    return rows, (moved - motions(ref)[2]).ravel()


def _turn(xy: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Each row of `xy` turned by `angle` [rad]."""
    c, s = np.cos(angle), np.sin(angle)
    return np.column_stack([c * xy[:, 0] - s * xy[:, 1], s * xy[:, 0] + c * xy[:, 1]])


def homogeneity(a: np.ndarray, b: np.ndarray, own: np.ndarray, dof: np.ndarray) -> tuple[float, int]:
    """``H`` (module docstring) of the runs of normal matrices `a` ``(G, n, n)``, scores `b` ``(G, n)``, own-fit
    residual sums of squares `own` and their degrees of freedom `dof`; and its ``df`` (0: nothing to compare)."""
    s = own / dof
    inv = np.linalg.pinv(a, rcond=RANK_TOL ** 2, hermitian=True)
    ranks = np.linalg.matrix_rank(a, tol=None, hermitian=True)
    w = np.einsum("gij,g->ij", a, 1 / s)
    big = np.einsum("gi,g->i", b, 1 / s)
    df = int(ranks.sum()) - int(np.linalg.matrix_rank(w, hermitian=True))
    if df <= 0:
        return 0.0, 0
    q = float(np.einsum("gi,gij,gj,g->", b, inv, b, 1 / s)
              - big @ np.linalg.pinv(w, rcond=RANK_TOL ** 2, hermitian=True) @ big)
    return max(q, 0.0) / df, df


def fleet_warning(problem: CalibrationProblem, jac: np.ndarray, res: np.ndarray, which: Sequence[int],
                  floors: Sequence[float], logs: Sequence[str],
                  named: bool) -> tuple[str | None, str | None, list[int]]:
    """The warning when the runs `which` of the fleet fit (`jac`, `res`; `floors`: least RSS root of each run's own
    fit [m], per run of the problem) do not agree as a whole (``H`` over :data:`MAX_HOMOGENEITY`), else ``None``;
    runs of fewer than :data:`MIN_DOF` are left out; why the check is not made (:data:`NOT_PLAIN`) where it would
    judge 3 runs or more, else ``None``: a fleet whose residuals carry run weights or no heading (``heading_weight``
    0) is not checked, the motions' errors need the plain residuals and the odometry's heading; and the runs of
    :data:`MIN_DOF` or more (those it covers). `named`: the residual ratio already named one run, so a disagreement
    one run explains is not said twice."""
    sizes = problem.sizes()
    ends = np.cumsum(sizes)
    rows = {k: (int(ends[k] - sizes[k]), int(ends[k])) for k in which}
    why = plain_only(problem)
    if why is not None:  # the runs it would judge, by their pose errors' degrees of freedom (as many as the motions')
        judged = [k for k, (lo, hi) in rows.items() if _own_fit(jac[lo:hi], res[lo:hi])[1] >= MIN_DOF]
        return None, NOT_PLAIN.format(check="the fleet homogeneity", why=why) if len(judged) >= 3 else None, judged
    keep, a, b, own, dof = [], [], [], [], []
    for k, (lo, hi) in rows.items():
        run = problem.runs[k]
        j, r = increments(run, problem.heading_weight, jac[lo:hi], res[lo:hi])
        step, free = _own_fit(j, r)
        if free >= MIN_DOF:
            keep.append(k)
            a.append(j.T @ j)
            b.append(j.T @ r)
            own.append(max(float(np.sum(np.square(r - j @ step))), floors[k] ** 2 * (hi - lo)))
            dof.append(free)
    if len(keep) < 3:
        return None, None, keep
    parts = tuple(np.array(x, dtype=float) for x in (a, b, own, dof))
    h, _ = homogeneity(*parts)
    if h <= MAX_HOMOGENEITY:
        return None, None, keep
    n, out = fewest_apart(*parts)
    if n == 1 and named:
        return None, None, keep
    without = f" (without {', '.join(logs[keep[i]] for i in out)} the others agree)" if out else ""
    return (f"the runs disagree among themselves (fleet homogeneity {h:.3g}, over {MAX_HOMOGENEITY:g}: their "
            "parameters are further apart than each run's own noise allows): at least "
            f"{'one run disagrees' if n == 1 else f'{n} runs disagree'} with the others{without}: another robot, load "
            "or floor? The fit averages them; calibrate them apart"), None, keep


def _own_fit(j: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, int]:
    """A run's own least-squares step on its rows `j`, `r` and its degrees of freedom: its rows that carry
    information (not zero with their Jacobian row) less the rank of `j`."""
    step, _, rank, _ = np.linalg.lstsq(j, r, rcond=None)
    return step, int(np.count_nonzero(np.any(j != 0, axis=1) | (r != 0))) - int(rank)


def fewest_apart(a: np.ndarray, b: np.ndarray, own: np.ndarray, dof: np.ndarray) -> tuple[int, tuple[int, ...]]:
    """The fewest runs whose removal leaves runs that agree (``H`` at most :data:`MAX_HOMOGENEITY`) and the subset of
    them leaving the least ``H`` (:func:`fewest`)."""
    def h(keep: np.ndarray) -> float | None:
        value, df = homogeneity(a[keep], b[keep], own[keep], dof[keep])
        return value if df else None

    return fewest(len(a), h, MAX_HOMOGENEITY)


def fewest(g: int, stat: Callable[[np.ndarray], float | None], limit: float) -> tuple[int, tuple[int, ...]]:
    """The fewest of `g` runs whose removal leaves runs that agree (`stat` of the runs kept, indices, at most `limit`;
    ``None``: nothing to compare; two runs left at least) and the subset of them leaving the least `stat`; ``(k,
    ())`` when no subset of fewer than ``k`` runs does, within :data:`SEARCH` subsets (``k`` is then a lower
    bound)."""
    tried = 0
    for k in range(1, g - 1):
        best = None
        for out in combinations(range(g), k):
            if tried >= SEARCH:
                return k, ()
            tried += 1
            value = stat(np.delete(np.arange(g), out))
            if value is not None and value <= limit and (best is None or value < best[0]):
                best = (value, out)
        if best is not None:
            return k, best[1]
    return g - 1, ()
