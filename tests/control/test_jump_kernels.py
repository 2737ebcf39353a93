"""The compiled passes of control/_jump_kernels.py give the numpy formulation's bits (control/jumps.py), which
judges short signals: on random signals (steps, kinks, spikes, undefined samples, angles) and on built-in
references, the remainders, sizes, changes, outlier flags, runs and the jumps found are the same."""

import importlib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit import catalog
from wmrkit.control import jumps
from wmrkit.control._jump_kernels import outliers, unpredicted_sizes
from wmrkit.control.references import builtin_reference

feasibility = importlib.import_module("wmrkit.control.feasibility")


def _signal(seed: int, n: int, m: int, kind: int) -> np.ndarray:
    """A smooth signal with steps, kinks and spikes (`kind` 1), undefined samples (2), constant stretches (3)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.01
    x = np.stack([np.sin(t * rng.uniform(0.1, 5)) * rng.uniform(0.1, 3) for _ in range(m)], axis=-1)
    if kind in (1, 2):
        for _ in range(rng.integers(1, 5)):
            k = rng.integers(0, n)
            x[k:] += rng.normal(size=m) * rng.choice([1e-3, 0.1, 1.0])
            x[rng.integers(0, n)] += rng.normal(size=m) * 0.5
            k = rng.integers(0, n)
            x[k:] += np.outer(t[k:] - t[k], rng.normal(size=m))
    if kind == 2:
        x[rng.random(n) < 0.05] = np.nan
    if kind == 3:
        x[rng.integers(0, n):] = x[-1]
        x = np.round(x, 2)
    return x


@settings(max_examples=200, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 90), m=st.integers(1, 3), kind=st.integers(0, 3),
       turn=st.sampled_from([None, np.pi, 2 * np.pi]))
def test_the_compiled_passes_give_the_numpy_bits(seed, n, m, kind, turn):
    x = _signal(seed, n, m, kind)
    d = np.diff(x, axis=0)
    if turn:
        d = jumps._wrap(d, turn)
    rng = np.random.default_rng(seed + 1)
    span = np.where(rng.random(len(d)) < 0.1, rng.uniform(1, 4, len(d)), 1.0)
    skip = np.isnan(d).any(axis=-1) | (rng.random(len(d)) < 0.05)  # as _jumps: undefined, or cut at a rest
    q = np.where(skip[:, None], np.nan, d / span[:, None])
    r0 = np.nan_to_num(jumps._unpredicted(q) * span[:, None])
    r, rsize, change = np.empty_like(q), np.empty(len(q)), np.empty(len(q))
    unpredicted_sizes(q, span, r, rsize, change)
    assert np.array_equal(r, r0)
    assert np.array_equal(rsize, np.sqrt((r0 * r0).sum(axis=-1)))
    assert np.array_equal(change, np.r_[np.sqrt((np.diff(q, axis=0) ** 2).sum(axis=-1)), np.nan][:len(q)],
                          equal_nan=True)
    size = np.sqrt(np.nansum(d * d, axis=-1))
    limit = 20 * span * np.maximum(jumps._typical(rsize / span), jumps._typical(change))
    for s, lim in ((size, limit), (rsize, limit), (rsize, limit / 20)):
        expected = jumps._outliers(d, s, lim, 0.02, turn)
        part, run = np.empty(len(q), dtype=bool), np.empty(len(q))
        outliers(np.ascontiguousarray(d.reshape(len(d), -1)), s, lim, 0.02, float(turn or 0), part, run)
        assert np.array_equal(part, expected[0])
        assert np.array_equal(run, expected[1])


def _verdict(robot, ref, framework):
    v = feasibility.feasibility(robot, ref, framework)
    return v.feasible, [(x.t, x.signal, x.kind, x.size, x.remedy) for x in v.violations]


@pytest.mark.parametrize("name", ["figure-eight", "square", "arc-line", "corner"])
@pytest.mark.parametrize("robot", ["ackermann", "swerve-4", "diff-drive"])
def test_the_compiled_passes_give_the_same_violations(monkeypatch, robot, name):
    robot, ref = catalog.load(robot), builtin_reference(name)
    for framework in ("kinematic", "dynamic"):
        expected = _verdict(robot, ref, framework)
        monkeypatch.setattr(jumps, "COMPILED_FROM", 0)
        assert _verdict(robot, ref, framework) == expected
        monkeypatch.setattr(jumps, "COMPILED_FROM", 1 << 19)


def test_the_compiled_pass_gives_the_chunked_numpy_bits_across_chunks():
    """numpy judges a long signal in chunks of 65536 steps (_unpredicted): the same bits at their seams."""
    for kind in (1, 2):
        d = np.diff(_signal(7 + kind, 3 * (1 << 16) + 6, 2, kind), axis=0)
        span, skip = np.ones(len(d)), np.isnan(d).any(axis=-1)
        q = np.where(skip[:, None], np.nan, d)
        r, rsize, change = np.empty_like(q), np.empty(len(q)), np.empty(len(q))
        unpredicted_sizes(q, span, r, rsize, change)
        assert np.array_equal(r, np.nan_to_num(jumps._unpredicted(q)))
