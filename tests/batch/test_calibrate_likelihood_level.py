"""batch calibrate's whole-fleet likelihood ratio of three-pose runs judged at one false-alarm level for every fleet
size: on whitened motions' errors each run's term at the true parameters is ``-m log(1 - B)``, ``B`` a beta
variable, and ``L`` of agreeing runs is distributed as the sum of the terms of all runs but one
(wmrkit.batch.likelihood.threshold)."""

from __future__ import annotations

import numpy as np
import pytest
from batch_params import PARAMS
from test_calibrate_judge import short_runs

from wmrkit.batch.calibrate import fleet_calibrate
from wmrkit.batch.likelihood import LEVEL, likelihood_ratio, threshold


def fleets(rng: np.random.Generator, count: int, g: int) -> tuple[np.ndarray, ...]:
    """`count` agreeing fleets of `g` whitened three-pose runs (6 motion errors, 3 parameters): each run a random
    Jacobian, scaled by its precision drawn over 4 decades (noise levels and travels of every mix), and errors of one
    variance (whitened: test_calibrate_own_noise), at the true parameters; likelihood_ratio's parts."""
    j = rng.normal(size=(count, g, 6, 3)) * 10 ** rng.uniform(-2, 2, (count, g, 1, 1))
    e = rng.normal(size=(count, g, 6))
    a, b = np.einsum("fgki,fgkj->fgij", j, j), np.einsum("fgki,fgk->fgi", j, e)
    own = np.sum(np.square(e - np.einsum("fgki,fgi->fgk", j, np.linalg.solve(a, b[..., None])[..., 0])), axis=-1)
    return a, b, np.sum(e * e, axis=-1), own


def scores(parts: tuple[np.ndarray, ...], limit: float) -> np.ndarray:
    """``L`` of each fleet where it may be over `limit`, else an upper bound (the likelihood at the fleet fit and at
    each run's own fit, where likelihood_ratio starts; its minimum is lower)."""
    a, b, c, own = parts
    d = np.concatenate([np.zeros_like(b[:, :1]), -np.linalg.solve(a, b[..., None])[..., 0]], axis=1)
    rss = np.maximum(c[:, None] + 2 * np.einsum("fsi,fgi->fsg", d, b)
                     + np.einsum("fsi,fgij,fsj->fsg", d, a, d, optimize=True), own[:, None])
    out = 6 * (np.min(np.log(rss).sum(axis=2), axis=1) - np.log(own).sum(axis=1))
    near = out > limit
    out[near] = likelihood_ratio(a[near], b[near], c[near], own[near], 6.0)
    return out


@pytest.mark.parametrize("g", [5, 8])
def test_agreeing_fleets_are_flagged_at_the_stated_level_whatever_their_size(g):
    """40,000 seeded agreeing fleets of `g` runs: ``L`` over its threshold at 1 % and at LEVEL (0.1 %: the
    warning's) in that share of them, within half the level either way (40 +- 6 expected at 0.1 %; the threshold is
    exact for a fleet of one run much quieter than the others, and measured 0.6-1.2 times the level for other
    fleets, docs/batch.md). Before, a fleet was flagged at ``L / G`` over 24 on its unwhitened motions' errors,
    whose distribution depends on the runs' paths and their number (5 runs: mean 10.2 a run, 99.9th percentile 20.5;
    8: 11.1 and 18.2): at no stated level (no threshold function, no LEVEL)."""
    parts = fleets(np.random.default_rng(g), 40000, g)
    limits = [threshold(((6, 3),) * g, level) for level in (0.01, LEVEL)]
    got = scores(parts, min(limits))
    shares = [float(np.mean(got > q)) for q in limits]
    assert all(0.5 * level <= share <= 1.5 * level for share, level in zip(shares, (0.01, LEVEL), strict=True)), \
        shares


def test_the_threshold_is_the_quantile_of_the_sum_of_all_runs_terms_but_one():
    """The threshold against a seeded simulation of its definition: 400,000 sums of the terms ``m log(1 + X / Y)``
    (``X``, ``Y`` chi-square of ``rank`` and ``m - rank`` degrees of freedom) of all runs but one of largest rank,
    for fleets of 5 and 8 three-pose runs, one of rank 2 (two independent motions) among 5, and runs of four poses
    (9 motion errors): the share of the simulated sums over it is the level, within 3 standard errors."""
    rng = np.random.default_rng(0)
    for runs in (((6, 3),) * 5, ((6, 3),) * 8, ((6, 2),) + ((6, 3),) * 4, ((9, 3),) * 5):
        terms = sorted(runs, key=lambda x: x[1])[:-1]
        total = sum(m * np.log1p(rng.chisquare(r, 400000) / rng.chisquare(m - r, 400000)) for m, r in terms)
        for level in (0.05, 0.01, LEVEL):
            share = float(np.mean(total > threshold(tuple(sorted(runs)), level)))
            assert abs(share - level) < 3 * np.sqrt(level / 400000), (runs, level, share)


def test_three_bad_runs_among_six_the_rule_before_missed_are_flagged(diff):
    """3 runs of a left radius +5 % among 6 three-pose runs (levels drawn per run; seeds 36 and 131 of 150 such
    fleets): ``L / G`` on unwhitened motions' errors was 23.3 and 20.4, under 24, and the fleets were reported clean
    (146 of the 150 flagged). On whitened motions ``L`` is over its threshold (150 of the 150; docs/batch.md)."""
    for seed in (36, 131):
        rng = np.random.default_rng(seed)
        bad = sorted(rng.choice(6, 3, replace=False).tolist())
        res = fleet_calibrate(diff, short_runs(diff, 40000 + seed, 6, 3, bad=bad,
                                               noise=rng.choice([1e-6, 1e-5, 1e-4], 6)), PARAMS)
        assert res.inconsistent is True and any("disagree among themselves" in w for w in res.warnings), seed
