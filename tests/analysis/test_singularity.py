"""Singularity (ch. 6): the line test (6.17)-(6.20) agrees with the rank test (6.12); singular sets are exact."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq
from thesis_vehicles import DEG, omni_castor, omni_swedish, robot

from strategies import robots
from wmrkit import Robot, UnknownNameError, Wheel, catalog
from wmrkit.analysis.icr import steer_to_icr
from wmrkit.analysis.lines import constraint_lines, line_through
from wmrkit.analysis.singularity import (
    SINGULAR_RTOL,
    is_singular,
    is_singular_rank,
    singular_set,
    singularity_distance,
)
from wmrkit.kinematics.linalg import RANK_RTOL, matrix_rank, nondimensional


@st.composite
def cases(draw):
    r = draw(robots(max_wheels=4))
    names = r.velocity_names
    assigned = tuple(draw(st.lists(st.sampled_from(names), unique=True, max_size=len(names))))
    seed = draw(st.integers(0, 2**16))
    rng = np.random.default_rng(seed)
    if draw(st.booleans()):
        beta = rng.uniform(-np.pi, np.pi, len(r.steer_names))
    else:  # every steered axle through one ICR: the configurations where such robots move
        beta = steer_to_icr(r, rng.normal(size=3))
    return r, assigned, beta


def numerical_tie(r, beta, assigned) -> bool:
    """Whether either test's decision changes when its tolerance is 100 times larger or smaller: the two tests
    measure closeness to singularity differently, and agree away from such ties (e.g. two fixed wheels at one point
    whose axles differ by 1.2e-7 rad: rank test singular, line test not)."""
    line = {bool(is_singular(r, beta, assigned, rtol=SINGULAR_RTOL * f)) for f in (1e-2, 1e2)}
    cols = [r.velocity_index(n) for n in assigned]
    a = nondimensional(r).constraint_matrix(beta)
    free = a[..., [j for j in range(a.shape[-1]) if j not in cols]]
    rank = {int(matrix_rank(free, rtol=RANK_RTOL * f)) for f in (1e-2, 1e2)}
    return len(line) > 1 or len(rank) > 1


@settings(max_examples=1000)
@given(cases())
def test_line_test_equals_rank_test_on_random_robots(case):
    r, assigned, beta = case
    assume(not numerical_tie(r, beta, assigned))
    assert bool(is_singular(r, beta, assigned)) == bool(is_singular_rank(r, beta, assigned))


@settings(max_examples=180)
@given(robots(max_wheels=3), st.integers(0, 2**16))
@example(Robot(name="r", wheels=(Wheel(name="w0", type="steerable", l=0.0, alpha=0.0, beta=0.0, r=0.5),
                                 Wheel(name="w1", type="steerable", l=2.0**-24, alpha=0.0, beta=0.0, r=0.5))), 0)
def test_singular_set_points_are_rank_singular(r, seed):
    """Away from numerical ties (:func:`numerical_tie`): the example's wheels, 6e-8 m apart (1.2e-7 of its size,
    ill-conditioned in docs/limits.md), are singular with w1's axle along x through w0 (an exact singular curve,
    drawn on a 2026-12-01 explore run), where both point tests say "regular" at their tolerance and "singular" at
    100 times it."""
    rng = np.random.default_rng(seed)
    names = [n for n in r.velocity_names if not n.endswith(".roller")]
    m = 3 - int(matrix_rank(constraint_lines(r).lines()))
    assigned = tuple(rng.choice(names, size=min(max(m, 1), len(names)), replace=False).tolist())
    s = singular_set(r, assigned, resolution=24, max_samples=200)
    if s.always or not len(s.configurations):
        return
    beta = np.broadcast_to(r.beta, (len(s.configurations), len(r.steer_names))).copy()
    beta[:, [r.steer_names.index(v) for v in s.variables]] = s.configurations
    regular = ~is_singular_rank(r, beta, assigned)
    assert all(numerical_tie(r, b, assigned) for b in beta[regular])


BATCHES = [(), (1,), (5,), (2, 3)]


@pytest.mark.parametrize("batch", BATCHES, ids=str)
def test_distance_batches_like_a_loop(batch):
    r = catalog.load("thesis-steer-castor")
    beta = np.random.default_rng(0).uniform(-np.pi, np.pi, (*batch, 3))
    a = ("o1.spin", "c2.steer")
    out = singularity_distance(r, beta, a)
    assert out.shape == batch
    for idx in np.ndindex(*batch):
        assert out[idx] == pytest.approx(float(singularity_distance(r, beta[idx], a)), rel=1e-9)


def test_big_batches_use_the_same_measure():
    r = catalog.load("thesis-two-steer-castor")
    beta = np.random.default_rng(2).uniform(-np.pi, np.pi, (5000, 3))
    a = ("o1.spin",)
    big = singularity_distance(r, beta, a)  # closed-form eigenvalues
    small = np.array([float(singularity_distance(r, b, a)) for b in beta[:50]])  # LAPACK
    np.testing.assert_allclose(big[:50], small, rtol=1e-6, atol=1e-7)


def test_unknown_names_raise():
    r = catalog.load("thesis-tricycle")
    with pytest.raises(UnknownNameError, match=r"no velocity 'o3\.steer'"):
        is_singular(r, None, ("o3.steer",))
    with pytest.raises(UnknownNameError, match="no steering wheel 'f1'"):
        singular_set(r, ("vy",), variables=("f1",))


# ---- omnidirectional vehicles (Figs. 6.2, 6.3) -------------------------------------------------------------
def test_omni_swedish_isotropic_design():
    r = omni_swedish(L=0.7)
    assert not is_singular(r, None, ("s1.spin", "s2.spin", "s3.spin"))
    assert not is_singular(r, None, ("vx", "vy", "omega"))
    # roller lines of wheels 2 and 3 meet at (-2L, 0), on the X axis (digest §7.1)
    assert is_singular(r, None, ("s2.spin", "s3.spin", "vx"))
    assert not is_singular(r, None, ("s1.spin", "s2.spin", "vx"))
    assert not is_singular(r, None, ("s1.spin", "s2.spin", "omega"))
    lines = constraint_lines(r, ("s2.spin", "s3.spin")).lines()
    x, y = -2 * 0.7, 0.0
    assert np.allclose(lines @ [y, -x, 1.0], 0.0, atol=1e-12)


def test_omni_swedish_radial_wheels_are_singular():
    r = omni_swedish(L=0.7, offset=math.pi / 2)  # wheel planes through the centre
    assert is_singular(r, None, ("s1.spin", "s2.spin", "s3.spin"))


def test_castor_delta_arm_lines_not_wheel_planes():
    """Erratum 16: with delta != 0 and the spins assigned, concurrent *arm* lines are singular (not planes)."""
    delta, d, L = 0.5, 0.15, 0.6
    alphas = [0.0, 2.1, 4.2]
    target = np.array([0.2, -0.1])

    def make(betas):
        return robot("c3", *({"name": f"c{i + 1}", "type": "castor", "l": L, "alpha": a, "beta": b, "d": d,
                              "delta": delta, "r": 0.1} for i, (a, b) in enumerate(zip(alphas, betas, strict=True))))

    joints = [L * np.array([math.cos(a), math.sin(a)]) for a in alphas]
    # arm (S_y = (-sin b, cos b)) through the target: b = atan2(target - joint) - 90 deg
    arm_betas = [math.atan2(*(target - j)[::-1]) - math.pi / 2 for j in joints]
    spins = ("c1.spin", "c2.spin", "c3.spin")
    assert is_singular(make(arm_betas), None, spins) and is_singular_rank(make(arm_betas), None, spins)
    # wheel planes (along beta + delta + 90 deg, through the contact points) through the target instead
    def plane_residual(b, j):
        contact = j + d * np.array([-math.sin(b), math.cos(b)])
        return float(line_through(contact, [-math.sin(b + delta), math.cos(b + delta)]) @ [target[1], -target[0], 1])

    plane_betas = []
    grid = np.linspace(-np.pi, np.pi, 721)
    for j in joints:
        vals = np.array([plane_residual(b, j) for b in grid])
        i = int(np.flatnonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))[0])
        plane_betas.append(brentq(plane_residual, grid[i], grid[i + 1], args=(j,), xtol=1e-14))
    r = make(plane_betas)
    assert not is_singular(r, None, spins) and not is_singular_rank(r, None, spins)


def test_omni_castor_fig_6_3_sets_match_determinants():
    """Fig. 6.3 (a), (b), (e), (f): det of the wheel-axis / arm lines, from the digest's formulas."""
    L, d = 1.0, 0.2
    rng = np.random.default_rng(5)
    alphas = np.array([0.0, 120 * DEG, 240 * DEG])
    for _ in range(20):
        b = rng.uniform(-np.pi, np.pi, 3)
        r = omni_castor(L=L, d=d, r=0.2, betas=tuple(b))
        axis = np.stack([np.cos(b), np.sin(b), L * np.sin(b - alphas) - d], axis=-1)
        arm = np.stack([-np.sin(b), np.cos(b), L * np.cos(b - alphas)], axis=-1)
        for q_a, rows in [(("c1.steer", "c2.steer", "c3.steer"), axis), (("c1.spin", "c2.spin", "c3.spin"), arm),
                          (("c1.spin", "c2.steer", "c3.steer"), np.stack([arm[0], axis[1], axis[2]])),
                          (("c1.spin", "c2.spin", "c3.steer"), np.stack([arm[0], arm[1], axis[2]]))]:
            distance = float(singularity_distance(r, None, q_a))
            det = abs(np.linalg.det(rows)) / np.prod(np.linalg.norm(rows, axis=1))
            assert (distance < 1e-3) == (det < 1e-3)
        # exact singular set of (a) over beta3 with beta1, beta2 fixed: roots of the determinant
        s = singular_set(r, ("c1.steer", "c2.steer", "c3.steer"), variables=("c3",))
        for b3 in s.configurations[:, 0]:
            bb = b.copy()
            bb[2] = b3
            rows = np.stack([np.cos(bb), np.sin(bb), L * np.sin(bb - alphas) - d], axis=-1)
            assert abs(np.linalg.det(rows)) < 1e-9


def test_two_steerable_wheels_a_subnormal_distance_apart_are_always_singular():
    """Found by hypothesis: minors of order 1e-309 used to overflow the root finder; they vanish identically."""
    from wmrkit.robot import Robot
    from wmrkit.wheels import Wheel

    r = Robot(name="r", wheels=(Wheel(name="w0", type="steerable", l=0.0, alpha=0.0, beta=0.0, r=0.5),
                                Wheel(name="w1", type="steerable", l=1.1125369292536007e-308, alpha=0.0, beta=0.0,
                                      r=0.5)))
    s = singular_set(r, ("w0.spin", "w1.spin"), resolution=24, max_samples=200)
    assert s.always and len(s.configurations) == 0
    assert is_singular_rank(r, np.zeros((4, 2)) + np.linspace(-3, 3, 4)[:, None], ("w0.spin", "w1.spin")).all()


def test_a_subnormal_angle_gives_the_answer_of_zero_without_a_warning():
    """Found by hypothesis: a fixed wheel at beta = 2.2e-311 rad (a subnormal) made LAPACK's LU flag a division
    by a subnormal pivot while finding the exact singular values; the answer is that of beta = 0, silently."""
    import warnings

    from wmrkit.analysis.summary import analyze
    from wmrkit.robot import Robot
    from wmrkit.wheels import Wheel

    def car(beta):
        return Robot(name="r", wheels=(Wheel(name="w0", type="fixed", l=0.0, alpha=0.0, beta=0.0, r=0.5),
                                       Wheel(name="w1", type="steerable", l=1.0, alpha=1.0, beta=0.0, r=0.5),
                                       Wheel(name="w2", type="fixed", l=0.0, alpha=0.0, beta=beta, r=0.5)))

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tiny = analyze(car(2.225073858507e-311)).to_dict()
    assert tiny["singular"] == analyze(car(0.0)).to_dict()["singular"]


def test_the_forklift_differential_cannot_drive_a_turn_about_the_drive_axle_middle(capsys):
    """The forklift's drive spins are one differential. At the steering wheel's +-90 deg heading the robot's only
    motion turns about the middle of the drive axle: the wheels spin opposite, the differential's input stands
    still, and its one motor drives nothing ('actuation: insufficient' there). The actuated singular set, searched
    through the coupling, is exactly those two headings (it said 'never' with each joint on its own); the sensed
    set keeps each joint on its own (two encoders read the turn) and stays 'never'."""
    import json

    from wmrkit.cli.main import main

    r = catalog.load("forklift")
    drives = ("right_drive.spin", "left_drive.spin")
    s = singular_set(r, drives, coupled=True)
    assert s.exact and not s.always and s.coupled
    assert sorted(np.degrees(r.heading_of_beta(s.configurations)).ravel().round(9)) == [-90.0, 90.0]
    assert singular_set(r, drives).never  # each joint on its own
    # Independent: the slip matrix at +-90 deg has a motion with both drive rates opposite (their mean zero)
    for h in (math.pi / 2, -math.pi / 2):
        a = r.constraint_matrix(heading=[h])
        motion = np.linalg.svd(a)[2][-1]
        assert np.allclose(a @ motion, 0, atol=1e-12) and abs(motion[2]) > 0.1  # a turn
        i, j = (r.velocity_index(n) for n in drives)
        assert motion[i] == pytest.approx(-motion[j]) and abs(motion[i]) > 0.1
    assert main(["analyze", "forklift", "--steer", "steer=90deg"]) == 0
    out = capsys.readouterr().out
    assert "actuation: insufficient" in out
    assert ("singular (actuated: differential of right_drive and left_drive): at heading steer = 90.00, "
            "-90.00 deg") in out
    assert "singular (sensed: right_drive.spin, left_drive.spin): never" in out
    assert main(["analyze", "forklift", "--json"]) == 0
    sing = json.loads(capsys.readouterr().out)["singular"]
    assert sing["actuated"]["channels"] == ["differential(right_drive.spin, left_drive.spin)"]
    assert sorted(np.round(np.degrees(sing["actuated"]["headings"]), 9).ravel()) == [-90.0, 90.0]
    assert sing["sensed"]["channels"] == list(drives) and sing["sensed"]["never"]


def test_a_car_with_a_rear_differential_is_singular_turning_about_the_rear_axle_middle():
    """The Ackermann template drives its rear wheels through a differential: among coordinated steerings its
    actuated model breaks down only with the ICR at the rear axle's middle (the origin), where the rear wheels
    spin opposite."""
    from wmrkit.analysis.coordinated import coordinated_singular_set
    from wmrkit.analysis.icr import icr

    r = catalog.load("ackermann")
    s = coordinated_singular_set(r, ("rear_left.spin", "rear_right.spin"), coupled=True)
    assert len(s.configurations) == 1 and s.coupled
    point = icr(r, s.configurations[0]).point
    assert np.allclose(point, 0.0, atol=1e-7)
    assert coordinated_singular_set(r, ("rear_left.spin", "rear_right.spin")).never


@st.composite
def coupled_cases(draw):
    """A random robot with random rate couplings (differentials and gear trains over its joint rates)."""
    import dataclasses

    from wmrkit.couplings import Coupling

    r = draw(robots(max_wheels=4))
    # the rates a coupling may hold, as in a description: not a roller's (no joint to couple: Robot refuses it)
    rates = [n for n in r.rate_names if n.partition(".")[2] in r.wheel(n.partition(".")[0]).kind.joints]
    assume(len(rates) >= 2)
    order = draw(st.permutations(rates))
    couplings, k = [], 0
    while k + 2 <= len(order) and draw(st.booleans()) | (k == 0):
        size = draw(st.integers(2, min(3, len(order) - k)))
        ratios = tuple(draw(st.sampled_from([0.5, 1.0, -1.0, 2.0, 1 / 3])) for _ in range(size))
        couplings.append(Coupling(draw(st.sampled_from(["differential", "gear"])), tuple(order[k:k + size]), ratios))
        k += size
    r = dataclasses.replace(r, couplings=tuple(couplings))
    assigned = tuple(draw(st.lists(st.sampled_from(r.velocity_names), unique=True, max_size=4)))
    rng = np.random.default_rng(draw(st.integers(0, 2**16)))
    beta = (rng.uniform(-np.pi, np.pi, len(r.steer_names)) if draw(st.booleans())
            else steer_to_icr(r, rng.normal(size=3)))
    return r, assigned, beta


def _coincident_castors_geared():
    """Found by a random draw: four wheels at the origin, two identical double castors geared to a double wheel's
    steering. Where the castors are both at beta = 0 their rows cancel in the gear's line, whose round-off was
    normalised into a spurious unit line: the line test said 'not singular' while the body can rotate in place."""
    from wmrkit.couplings import Coupling

    def wheel(name, kind, **k):
        return Wheel(name, kind, l=0.0, alpha=0.0, beta=0.0, r=0.5, **k)

    robot = Robot("r", (wheel("w0", "double_castor", d=0.5, b=0.5), wheel("w1", "fixed"),
                        wheel("w2", "double", b=0.5), wheel("w3", "double_castor", d=0.5, b=0.5)),
                  couplings=(Coupling("gear", ("w3.spin1", "w0.spin1", "w2.steer"), (0.5, 0.5, 0.5)),))
    return robot, (), np.array([0.0, -0.81011685, 0.0])


@settings(max_examples=600)
@given(coupled_cases())
@example(_coincident_castors_geared())
def test_coupled_line_test_equals_coupled_rank_test_on_random_robots(case):
    """The lines eliminated through the couplings (several wheels together) against the rank test written in the
    coupled variables (coupled_columns' free directions), which shares no code with the elimination."""
    r, assigned, beta = case
    line = {bool(is_singular(r, beta, assigned, rtol=SINGULAR_RTOL * f, coupled=True)) for f in (1e-2, 1e2)}
    rank = {bool(is_singular_rank(r, beta, assigned, coupled=True)) for _ in (0,)}
    assume(len(line) == 1)
    assert line == rank


def test_a_line_through_a_coupling_may_vanish():
    """Two steerable wheels at one point, their spins geared together: the line 'plane of w0 - plane of w1' is
    zero where they point the same way. It is no constraint there (the tests divided by its zero norm: NaN, and an
    SVD that did not converge); with the two axle lines left the model is singular, as the rank test says."""
    from wmrkit.couplings import Coupling
    from wmrkit.robot import Robot
    from wmrkit.wheels import Wheel

    w = [Wheel(name=n, type="steerable", l=0.0, alpha=0.0, beta=0.0, r=0.5) for n in ("w0", "w1")]
    r = Robot(name="r", wheels=tuple(w), couplings=(Coupling("gear", ("w0.spin", "w1.spin"), (0.5, 0.5)),))
    b = np.array([-0.81, -0.81])
    assert is_singular(r, b, (), coupled=True) and is_singular_rank(r, b, (), coupled=True)
    assert singularity_distance(r, b, (), coupled=True) == 0.0


@pytest.mark.parametrize("copies", [1, 100])  # one configuration (SVD) and a map (the Gram route beyond 64)
def test_singularity_distance_drops_a_coupled_line_that_is_round_off(copies):
    """The map kernel forms the lines through a coupling itself: at the @example's configuration the gear's line is
    round-off (4e-16) of its wheels' rows, which it normalised into a spurious unit line (distance 0.39 where the
    line test and the rank test (6.12) say singular). It is zero there, as ConstraintLines.lines makes it."""
    robot, assigned, beta = _coincident_castors_geared()
    assert is_singular(robot, beta, assigned, coupled=True) and is_singular_rank(robot, beta, assigned, coupled=True)
    dist = singularity_distance(robot, np.tile(beta, (copies, 1)), assigned, coupled=True)
    assert np.all(dist < 1e-8)


def test_a_sampled_singular_set_includes_the_described_configuration_when_it_is_singular():
    """Six castors on a circle, all at rest pointing one way, their spins actuated: the spins never measure the
    sideways speed there, so the model is singular as described (rank test 6.12), but the set of configurations
    where all six arm lines meet is of codimension 4 and a random sample misses it: analyze said 'singular: none
    found on the sampled grid' beside 'condition number infinite'. The described configuration is now checked."""
    wheels = [Wheel(f"c{i}", "castor", l=0.5, alpha=i * math.pi / 3, beta=0.0, r=0.05, d=0.05) for i in range(6)]
    r = Robot("castors", tuple(wheels))
    spins = tuple(f"c{i}.spin" for i in range(6))
    assert is_singular_rank(r, None, spins)
    s = singular_set(r, spins, resolution=90, max_samples=720)
    assert not s.never
    assert s.variables == r.steer_names and any(np.allclose(c, r.beta) for c in s.configurations)
    assert all(is_singular_rank(r, c, spins) for c in s.configurations)
