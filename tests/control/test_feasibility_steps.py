"""Property: a sampled reference with one step (a teleport, a heading jump, a speed step) at a random sample is one
violation at that sample for robots of types 3 and 5 (l_o != 0), in both frameworks; the same reference without
the step is none (feasibility's folding of a derivative's spike into its signal's step, and its slow turns)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from continuity import feasibility  # Table 8.1's verdict: these shapes are tighter than the car's stops
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from wmrkit import catalog
from wmrkit.control.feasibility import requirement
from wmrkit.control.references import reference_from_samples

ROBOTS = {name: catalog.load(name) for name in ("swerve-4", "thesis-two-steer-castor", "thesis-two-steer-swedish")}
COLUMN = "types 3 and 5, l_o != 0"


@settings(max_examples=90)
@given(st.sampled_from(sorted(ROBOTS)), st.one_of(st.none(), st.tuples(st.floats(-0.4, 0.4), st.floats(-0.4, 0.4))),
       st.floats(0.005, 0.05), st.floats(0.2, 2.0), st.floats(-math.pi, math.pi), st.floats(-math.pi, math.pi),
       st.floats(-0.5, 0.5), st.sampled_from(["position", "theta", "velocity"]), st.floats(0.25, 0.75),
       st.floats(1.5, 3.0), st.booleans(), st.floats(-math.pi, math.pi))
def test_one_step_is_one_violation_at_its_sample(name, point, dt, v, direction, theta0, w, kind, where, factor,
                                                 down, angle):
    """A robot of types 3 and 5 (optionally tracked at a random point off its wheels) following a line at a steady
    speed and turn rate (which it follows: no violation), sampled every `dt` for 10 s, with one step at a random
    sample: a teleport or heading jump (`factor` x 40 typical steps, above the floors) is one violation at that
    sample in both frameworks; a speed step (x 0.3-0.7 or x 1.5-3) is one in the dynamic framework and at most
    that one in the kinematic framework (only where it turns a steered wheel)."""
    robot = ROBOTS[name]
    assume(requirement(robot, point=point).column == COLUMN)
    t = np.arange(0.0, 10.0, dt)
    i = int(where * len(t))
    heading = np.array([math.cos(direction), math.sin(direction)])
    pose = np.column_stack([np.outer(v * t, heading), theta0 + w * t])
    smooth = reference_from_samples("smooth.csv", t, pose)
    for framework in ("kinematic", "dynamic"):
        got = feasibility(robot, smooth, framework, point=point).violations
        assert not got, (framework, [(x.signal, x.t, x.size) for x in got])
    if kind == "position":
        pose[i:, :2] += factor * max(0.01, 40 * v * dt) * np.array([math.cos(angle), math.sin(angle)])
    elif kind == "theta":
        pose[i:, 2] += math.copysign(min(3.0, factor * max(0.05, 40 * abs(w) * dt)), angle)
    else:
        ratio = 1 / factor if down else factor
        pose[i:, :2] = pose[i, :2] + np.outer(ratio * v * (t[i:] - t[i]), heading)
    stepped = reference_from_samples("step.csv", t, pose)
    for framework in ("kinematic", "dynamic"):
        got = [(x.signal, x.t) for x in feasibility(robot, stepped, framework, point=point).violations]
        if kind == "velocity" and framework == "kinematic":
            assert got in ([], [("velocity", t[i])]), got
        else:
            assert got == [(kind, t[i])], (framework, got)


@pytest.mark.parametrize("kappa", [0.3, 0.5, 1.0])
def test_a_sampled_speed_step_on_an_arc_is_found(kappa):
    """A file's speed doubling (1 -> 2 m/s) on an arc of curvature `kappa`, sampled at 32 Hz: its central-difference
    velocity steps in two halves of 0.5 m/s, each under 20 typical steps of the turning velocity there (0.0375 m/s at
    0.3 1/m), so the dynamic framework of omni-3 answered 'feasible' and swerve-4's reported only the acceleration's
    spike one sample early; at 0.5 1/m the whole step is 16 typical steps, and both were missed. The velocity's
    direction is continuous and its size steps by 1 m/s: a velocity jump of 1 m/s at 5 s for both (and for a diff
    drive, with its turn-rate jump). The twist only scales (the heading stays 0): no steered wheel turns, and the
    kinematic framework of swerve-4 has no violation, although at 1 1/m its wheels turn by 0.0625 rad a sample."""
    t = np.arange(0.0, 10.0, 0.03125)
    phi = np.where(t < 5.0, kappa * t, 5 * kappa + 2 * kappa * (t - 5.0))  # the tangent: speed 1, then 2
    pose = np.column_stack([np.sin(phi) / kappa, (1 - np.cos(phi)) / kappa, 0 * t])
    ref = reference_from_samples("arc.csv", t, pose)
    for name in ("omni-3", "swerve-4", "diff-drive"):
        got = [(v.signal, v.t, v.size) for v in feasibility(catalog.load(name), ref, "dynamic").violations]
        assert [g[:2] for g in got] == [("velocity", 5.0)] + ([("chi_rate", 5.0625)] if name == "diff-drive" else []), (
            name, got)
        assert got[0][2] == pytest.approx(1.0, abs=0.01)  # plus the velocity's turning across the samples
    assert feasibility(catalog.load("swerve-4"), ref).feasible


@pytest.mark.parametrize("shape", ["line", "circle", "figure-eight", "square", "arc-line", "corner"])
def test_a_built_in_reference_read_from_a_file_gets_the_same_verdict(shape):
    """Each built-in reference (exact derivatives) and the same poses sampled at its 100 Hz (finite differences, as
    a file is read): the same violations, at times within 2 samples (a file's curvature and turn rate are second
    differences, which start a step 2 samples early), for a robot of each column of Table 8.1, in both frameworks.
    swerve-4 on the arc-line read back had an 'acceleration jump' at 9.41 s the exact one has not (its steering
    rates were taken at samples inside the heading rate's and the acceleration's spread), and with the velocity
    compared with its neighbours' prediction, on the square a 'velocity jump' at each corner (its heading rate was
    78 rad/s at the sample before the corner, which turned its wheels) and on the arc-line a 'velocity jump' of
    0.0016 m/s (the kink of the velocity where the arc meets the line, spread by central differences)."""
    from wmrkit.control.references import builtin_reference

    exact = builtin_reference(shape)
    sampled = reference_from_samples(shape + ".csv", exact.t, exact.pose)
    for name in ("diff-drive", "line-follower", "forklift", "ackermann", "omni-3", "swerve-4", "thesis-steer-castor",
                 "thesis-two-steer-castor"):
        for framework in ("kinematic", "dynamic"):
            want = sorted((v.signal, v.t) for v in feasibility(catalog.load(name), exact, framework).violations)
            got = sorted((v.signal, v.t) for v in feasibility(catalog.load(name), sampled, framework).violations)
            assert [g[0] for g in got] == [w[0] for w in want], (name, framework, want, got)
            assert all(abs(g[1] - w[1]) <= 0.0201 for g, w in zip(got, want, strict=True)), (name, framework, want, got)


@settings(max_examples=75, deadline=None)
@example(dt=0.001, radius=1.0, v=0.3, where=0.25, kind="velocity", amount=0.0, angle=0.0, seed=0)
@given(st.sampled_from([0.01, 0.002, 0.001]), st.floats(1.0, 5.0), st.floats(0.3, 2.0), st.floats(0.2, 0.8),
       st.sampled_from(["position", "velocity"]), st.floats(0.0, 1.0), st.floats(-math.pi, math.pi),
       st.integers(0, 2**32 - 1))
def test_one_step_in_a_noisy_circle_is_found_once_at_its_sample(dt, radius, v, where, kind, amount, angle, seed):
    """A circle (radius 1-5 m, 0.3-2 m/s) sampled every `dt` for 20 s, its positions with Gaussian noise, and one
    step at a random sample: a teleport of 0.02-0.2 m in a random direction (noise 1e-4 m), or the speed stepping
    by x 1.5-3 (noise 1e-3 dt m: 1e-5 m at 100 Hz; the finite-difference velocity's noise, about 1.3e-3 m/s a
    sample, is the same at every rate). It is one violation, at that sample: a position jump for omni-3
    (kinematic), a velocity jump (dynamic). A teleport of 0.04 m at 100 Hz is 2 to 10 typical position steps
    (v dt), and such steps were missed in 25 of 60 random cases; the typical change of a step is that of the noise,
    2.4e-4 m. With 1e-5 m at 1 kHz the velocity's noise was 10 times that, and a speed step of 0.3 -> 0.45 m/s was
    11 typical steps, under the factor 20 that defines a jump: 'no jump' was the documented answer."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 20.0, dt)
    i = int(where * len(t))
    s = v * t
    if kind == "velocity":
        s = np.where(t < t[i], s, v * t[i] + (1.5 + 1.5 * amount) * v * (t - t[i]))
    pose = np.column_stack([radius * np.sin(s / radius), radius * (1 - np.cos(s / radius)), 0 * t])
    if kind == "position":
        pose[i:, :2] += (0.02 + 0.18 * amount) * np.array([math.cos(angle), math.sin(angle)])
    pose[:, :2] += (1e-4 if kind == "position" else 1e-3 * dt) * rng.standard_normal((len(t), 2))
    ref = reference_from_samples("noisy.csv", t, pose)
    got = [(x.signal, x.t) for x in feasibility(catalog.load("omni-3"), ref,
                                                "kinematic" if kind == "position" else "dynamic").violations]
    assert got == [(kind, t[i])], got


def _clothoid_with_a_step(slope, step, at, dt):
    """A path driven at 1 m/s (arc length s = t) whose curvature rate is ``slope s`` [1/(m s)], less `step` from
    s = `at` (kappa = slope s^2 / 2 - step (s - at)+), integrated on a 50 times finer grid and sampled every `dt`."""
    from scipy.integrate import cumulative_simpson

    s = np.arange(0.0, 4.0 + dt / 2, dt / 50)
    th = slope * s**3 / 6 - step * np.clip(s - at, 0, None) ** 2 / 2
    xy = [cumulative_simpson(f(th), x=s, initial=0.0)[::50] for f in (np.cos, np.sin)]
    return reference_from_samples("clothoid.csv", s[::50], np.column_stack([*xy, th[::50]]))


@pytest.mark.parametrize("slope, step, dt", [(0.2, 0.3, 0.01), (-0.2, 0.3, 0.01), (0.2, -0.3, 0.01),
                                             (-0.2, 0.5, 0.01), (1.0, 0.5, 0.01),
                                             (0.0, 0.03, 0.01), (0.2, 0.03, 0.001), (-0.2, 0.1, 0.001),
                                             (1.0, 0.1, 0.001), (1.0, -0.5, 0.001)])
@pytest.mark.parametrize("at", [2.0, 2.0037])
def test_a_curvature_rate_step_on_a_slope_is_reported_with_its_size(slope, step, at, dt):
    """A car's curvature-rate step of `step` 1/(m s) where the rate rises steadily by `slope` 1/(m s^2): one
    violation, whose size is the step (closed form). Finite differences spread it over about 5 samples, and only
    those over the jump limit were summed, with the slope's own change: 0.313 for a step of 0.5 on a slope of 1 at
    100 Hz, 0.28 for 0.3 on 0.2."""
    got = feasibility(catalog.load("ackermann"), _clothoid_with_a_step(slope, step, at, dt), "dynamic").violations
    assert [v.signal for v in got] == ["kappa_rate"]
    assert got[0].size == pytest.approx(abs(step), rel=1e-3)


@settings(max_examples=40, deadline=None)
@example(1.0, 0.1, 2.0)  # five changes of at most 0.033, under 20 times the slope's 0.01: not found
@example(-1.0, 0.3, 2.5063)
@example(0.0, 0.1, 2.5063)  # found, but at its first change: 2.48 s
@given(st.floats(-1.0, 1.0), st.one_of(st.floats(0.03, 0.3), st.floats(-0.3, -0.03)), st.floats(1.0, 3.0))
def test_a_small_curvature_rate_step_is_found_on_any_slope_at_its_time(slope, step, at):
    """A curvature-rate step of 0.03 to 0.3 1/(m s) where the rate rises by up to 1 1/(m s^2), at 100 Hz (closed
    form: a clothoid of rate ``slope s``, less `step` from ``s = at``): one violation, of the step's size, reported at
    the first sample after the step or the sample before, whatever the slope."""
    dt = 0.01
    got = feasibility(catalog.load("ackermann"), _clothoid_with_a_step(slope, step, at, dt), "dynamic").violations
    assert [v.signal for v in got] == ["kappa_rate"]
    assert got[0].size == pytest.approx(abs(step), rel=1e-3)
    assert abs(got[0].t - at) <= dt * (1 + 1e-9)


def _smooth_curvature(coefficients, knots, values, dt):
    """A path at 1 m/s (s = t, 4 s) whose curvature is the polynomial `coefficients` (lowest first) plus the cubic
    spline through `values` at `knots`, integrated on a 50 times finer grid and sampled every `dt`."""
    from scipy.integrate import cumulative_simpson
    from scipy.interpolate import CubicSpline

    s = np.arange(0.0, 4.0 + dt / 2, dt / 50)
    kappa = np.polynomial.polynomial.polyval(s, coefficients) + CubicSpline(knots, values)(s)
    th = cumulative_simpson(kappa, x=s, initial=0.0)
    xy = [cumulative_simpson(f(th), x=s, initial=0.0)[::50] for f in (np.cos, np.sin)]
    return reference_from_samples("smooth.csv", s[::50], np.column_stack([*xy, th[::50]]))


@settings(max_examples=40, deadline=None)
@example([0.0, 0.5], [0.0, 0.0], 0.01)  # a clothoid from its start: 'a jump' of 0.25 at 0.01 s
@example([0.0, 0.0, 0.5], [0.0, 0.0], 0.001)
@given(st.lists(st.floats(-0.5, 0.5), min_size=1, max_size=4), st.lists(st.floats(-0.5, 0.5), min_size=2, max_size=8),
       st.sampled_from([0.01, 0.001]))
def test_a_smooth_curvature_has_no_curvature_rate_jump(coefficients, values, dt):
    """Random smooth curvatures (a polynomial of degree up to 3 plus a cubic spline through up to 8 evenly spaced
    knots) driven at 1 m/s: a car follows
    them in the dynamic framework. The curvature rate's first and last samples (one-sided differences, off by about
    half of it) were a jump."""
    ref = _smooth_curvature(coefficients, np.linspace(0.0, 4.0, len(values)), values, dt)
    got = feasibility(catalog.load("ackermann"), ref, "dynamic").violations
    assert not got, [(v.signal, v.t, v.size) for v in got]
