"""batch calibrate's fleet-level check: runs that disagree as a whole, each judged against its own noise."""

from __future__ import annotations

import numpy as np
from batch_params import PARAMS, TRUE_P
from scipy.optimize import minimize
from test_calibrate_judge import short_runs

from wmrkit.batch.calibrate import fleet_calibrate
from wmrkit.batch.homogeneity import MAX_HOMOGENEITY, fewest_apart, homogeneity, increments
from wmrkit.odometry.calibration import CalibrationProblem

#: A robot of a 20 % larger left radius than the fleet's (TRUE_P: +1 %).
FAR = [TRUE_P[0] + 0.2, *TRUE_P[1:]]


def fleet_warnings(res) -> list[str]:
    return [w for w in res.warnings if "disagree among themselves" in w]


def test_increments_are_the_errors_of_the_motions_between_reference_poses(diff):
    """Against the SE(2) motions computed here: odometry's and the reference's between consecutive reference poses,
    each in the frame of the first (heading weight 2), for a noisy run at parameters off the truth; and their
    Jacobian against central differences of those motion errors."""
    run = short_runs(diff, 3, 1, None, noise=1e-4)[0]
    problem = CalibrationProblem(diff, tuple(PARAMS), (run,), heading_weight=2.0)
    ref = np.asarray(run.reference, dtype=float)

    def motions(poses):
        prev = np.vstack([run.start(), poses[:-1]])
        d = poses[:, :2] - prev[:, :2]
        c, s = np.cos(prev[:, 2]), np.sin(prev[:, 2])
        return np.column_stack([c * d[:, 0] + s * d[:, 1], c * d[:, 1] - s * d[:, 0], poses[:, 2] - prev[:, 2]])

    def errors(p):
        odo = ref + problem.residuals(p).reshape(-1, 3) / [1.0, 1.0, 2.0]
        return ((motions(odo) - motions(ref)) * [1.0, 1.0, 2.0]).ravel()

    p = np.add(TRUE_P, [0.01, -0.005, 0.03])
    res = problem.residuals(p)
    rows, got = increments(run, 2.0, problem.jacobian(p, res), res)
    assert np.abs(res).max() > 1e-2
    np.testing.assert_allclose(got, errors(p), atol=1e-12)
    h = 1e-6
    numeric = np.column_stack([(errors(p + h * u) - errors(p - h * u)) / (2 * h) for u in np.eye(3)])
    np.testing.assert_allclose(rows, numeric, atol=2e-6 * np.abs(numeric).max())


def test_homogeneity_is_cochrans_q_of_the_runs_own_fits():
    """Against a direct minimisation over the parameters of the runs' noise-weighted distances to their own fits."""
    rng = np.random.default_rng(1)
    g, n = 5, 3
    js = [rng.normal(size=(20, n)) for _ in range(g)]
    rs = [rng.normal(size=20) * (k + 1) for k in range(g)]
    a = np.array([j.T @ j for j in js])
    b = np.array([j.T @ r for j, r in zip(js, rs, strict=True)])
    own = np.array([np.sum((r - j @ np.linalg.lstsq(j, r, rcond=None)[0]) ** 2) for j, r in zip(js, rs, strict=True)])
    dof = np.full(g, 17.0)
    t = [-np.linalg.solve(ak, bk) for ak, bk in zip(a, b, strict=True)]
    q = minimize(lambda x: sum((x - tk) @ ak @ (x - tk) * d / o for tk, ak, o, d in zip(t, a, own, dof, strict=True)),
                 np.zeros(n), tol=1e-12).fun
    h, df = homogeneity(a, b, own, dof)
    assert df == n * (g - 1)
    assert np.isclose(h, q / df, rtol=1e-6)


def test_three_runs_of_another_robot_among_eight_are_flagged():
    """Three runs of a left radius +20 % among 8 (references every 5th sample): every residual ratio stayed under 7
    (each bad run among the others' inflates their error) and the fleet was reported clean before; now the fleet
    warning says that at least 3 runs disagree, names the three, and the fleet is inconsistent (JSON too)."""
    from wmrkit import catalog

    diff = catalog.load("diff-drive")
    res = fleet_calibrate(diff, short_runs(diff, 5, 8, None, bad=(2, 5, 7), odd=FAR), PARAMS)
    assert max(res.residual_ratios) < 20
    assert len(fleet_warnings(res)) == 1, res.warnings
    warning = fleet_warnings(res)[0]
    assert "at least 3 runs disagree" in warning and "without r2.csv, r5.csv, r7.csv the others agree" in warning
    assert res.inconsistent is True and res.to_dict()["inconsistent"] is True
    assert warning in res.to_dict()["warnings"]


def test_a_fleet_fitted_without_heading_is_not_checked_as_a_whole(diff):
    """With ``heading_weight`` 0 the residuals hold no heading, and the motions' errors divided by it: NaN and a
    RuntimeWarning (an error here). Such a fleet is left to the residual ratios."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = fleet_calibrate(diff, short_runs(diff, 5, 4, None, bad=(2,), odd=FAR), PARAMS, heading_weight=0.0)
    assert not fleet_warnings(res) and all(np.isfinite(q) for q in res.residual_ratios)


def test_agreeing_fleets_of_mixed_noise_are_not_flagged(diff):
    """Runs of one robot whose noise levels are drawn per run among 1e-6, 1e-5 and 1e-4 per rad (a quiet run among
    noisy ones reached 33 by the fleet fit's excess over each run's own): each run is judged against its own noise,
    and the statistic stays near one."""
    for seed, n in ((226, 6), (1, 3), (2, 4), (3, 8)):
        noise = np.random.default_rng(seed).choice([1e-6, 1e-5, 1e-4], n)
        res = fleet_calibrate(diff, short_runs(diff, seed, n, None, noise=noise), PARAMS)
        assert not fleet_warnings(res) and res.inconsistent is False, (seed, res.warnings)


def test_fewest_apart_finds_the_smallest_set_of_runs_to_leave_out():
    """Runs whose own fits are two clusters, 5 at zero and 3 far: the 3 are the fewest to leave out (brute force:
    no 1 or 2 runs leave the others agreeing)."""
    a = np.array([np.eye(2) * 100.0] * 8)
    t = np.zeros((8, 2))
    t[[1, 4, 6]] = 1.0
    b = -np.einsum("gij,gj->gi", a, t)
    own, dof = np.ones(8), np.full(8, 30.0)
    assert homogeneity(a, b, own, dof)[0] > MAX_HOMOGENEITY
    assert fewest_apart(a, b, own, dof) == (3, (1, 4, 6))


def test_a_fleet_fitted_with_run_weights_says_it_is_not_checked_as_a_whole(diff):
    """The fleet of three runs of another robot among 8 (test above) fitted with ``run_weights`` of one (the same
    fit): the homogeneity check needs the plain residuals and is not made. Before, that was unsaid: 'inconsistent'
    false, no warning, 'not_judged' null, where the same fleet unweighted is flagged. Now 'not_judged' says so."""
    from wmrkit.batch.homogeneity import NOT_PLAIN

    runs = short_runs(diff, 5, 8, None, bad=(2, 5, 7), odd=FAR)
    plain = fleet_calibrate(diff, runs, PARAMS)
    weighted = fleet_calibrate(diff, runs, PARAMS, run_weights=lambda run: np.ones(len(run.samples())))
    np.testing.assert_allclose(weighted.estimate, plain.estimate, rtol=1e-12, atol=1e-15)
    assert plain.inconsistent is True and len(fleet_warnings(plain)) == 1 and plain.not_judged is None
    assert not fleet_warnings(weighted) and weighted.inconsistent is False
    assert weighted.not_judged == weighted.to_dict()["not_judged"] == NOT_PLAIN.format(
        check="the fleet homogeneity", why="weighs its residuals by run_weights")
