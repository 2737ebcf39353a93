"""batch calibrate judges runs of references of 4 to 10 poses as a whole too (batch.whole): several bad runs hide each
other from their residual ratios, and Cochran's homogeneity needs 27 degrees of freedom of a run's own fit."""

from __future__ import annotations

import numpy as np
from batch_params import PARAMS
from test_calibrate_judge import short_runs

from wmrkit.batch.calibrate import fleet_calibrate


def whole(res) -> list[str]:
    return [w for w in res.warnings if "disagree among themselves (fleet likelihood ratio" in w]


def test_several_bad_runs_among_runs_of_four_to_ten_poses_are_flagged(diff):
    """Three runs of a left radius +5 % planted at random among 6 or 8 runs of 4, 6, 8 or 10 reference poses (levels
    drawn per run among 1e-6, 1e-5 and 1e-4 per rad): every residual ratio under 20, and such fleets were reported
    clean ('inconsistent' false, no warning, 'not_judged' null: 0 of 40 fleets of 6 for each number of poses). Now
    the fleet likelihood ratio of their whitened motions' errors flags them (40 of 40 each, docs/batch.md); among 8
    the runs it leaves out are planted ones. The same fleets without the bad runs are not flagged."""
    for seed, (n, poses) in enumerate(((6, 4), (8, 6), (6, 8), (8, 10))):
        bad = sorted(np.random.default_rng(seed).choice(n, 3, replace=False).tolist())
        noise = np.random.default_rng(seed + 7).choice([1e-6, 1e-5, 1e-4], n)
        res = fleet_calibrate(diff, short_runs(diff, 61000 + seed, n, poses, bad=bad, noise=noise), PARAMS)
        assert all(q is not None for q in res.residual_ratios) and res.not_judged is None
        assert res.inconsistent is True and len(whole(res)) == 1, (seed, res.warnings)
        out = whole(res)[0].partition("(without ")[2].partition(" the others agree")[0].split(", ")
        assert n == 6 or {f"r{k}.csv" for k in bad} >= set(out), (seed, bad, out)
        good = fleet_calibrate(diff, short_runs(diff, 61000 + seed, n, poses, noise=noise), PARAMS)
        assert good.inconsistent is False and not good.warnings and good.not_judged is None, (seed, good.warnings)


def test_runs_no_whole_fleet_check_covers_are_named(diff):
    """Two runs of four-pose references among four with references every 5th sample: the four are judged by the
    fleet homogeneity, the two are too few for the likelihood ratio; 'not_judged' names them (batch.whole.UNCOVERED;
    before, nothing said so). Their ratios stand."""
    from wmrkit.batch.whole import UNCOVERED

    runs = short_runs(diff, 3, 4, None) + short_runs(diff, 4, 2, 4, name="f")
    res = fleet_calibrate(diff, runs, PARAMS)
    assert all(q is not None for q in res.residual_ratios) and res.inconsistent is False, res.warnings
    assert res.not_judged == res.to_dict()["not_judged"] == UNCOVERED.format(runs="f0.csv, f1.csv")


def test_one_or_two_runs_of_many_poses_join_the_likelihood_ratio(diff):
    """Two runs with references every 5th sample (27 degrees of freedom or more), both of a left radius +5 %, among
    four four-pose runs of the fleet's robot: too few for the homogeneity, and they were not judged as a whole
    (ratios under 20, the fleet reported clean, nothing said). Now they join the four in the fleet likelihood
    ratio, which flags the fleet and leaves out exactly the two planted runs."""
    from batch_params import TRUE_P

    odd = [TRUE_P[0] + 0.05, *TRUE_P[1:]]
    for seed in range(2):
        runs = short_runs(diff, 100 + seed, 2, None, bad=(0, 1), odd=odd) + short_runs(diff, 200 + seed, 4, 4,
                                                                                          name="f")
        res = fleet_calibrate(diff, runs, PARAMS)
        assert max(res.residual_ratios) < 20 and res.not_judged is None
        assert res.inconsistent is True and len(whole(res)) == 1, (seed, res.warnings)
        assert "(without r0.csv, r1.csv the others agree)" in whole(res)[0]
