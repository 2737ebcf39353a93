"""Classification (§5.2-5.3, Table 5.1): thesis vehicles, catalog robots, degenerate robots, random robots."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from thesis_vehicles import DEG, bicycle, differential, omni_castor, omni_swedish, robot, tricycle, type3, type5

from strategies import wheels
from wmrkit import Robot, Wheel, catalog
from wmrkit.analysis.classification import TABLE_5_1, classify, instantaneous_mobility
from wmrkit.analysis.icr import icr
from wmrkit.kinematics.linalg import matrix_rank

THESIS = [  # digest §9: (vehicle, m, d, type)
    (omni_swedish(), 3, 0, 1), (omni_castor(), 3, 0, 1),
    (differential(third="swedish"), 2, 0, 2), (differential(third="castor"), 2, 0, 2),
    (type3(omni="swedish"), 2, 1, 3), (type3(omni="castor"), 2, 1, 3),
    (tricycle(), 1, 1, 4), (bicycle(third="swedish"), 1, 1, 4), (bicycle(third="castor"), 1, 1, 4),
    (type5(third="swedish"), 1, 2, 5), (type5(third="castor"), 1, 2, 5),
]


@pytest.mark.parametrize(("vehicle", "m", "d", "kind"), THESIS, ids=lambda v: getattr(v, "name", str(v)))
def test_thesis_vehicles(vehicle, m, d, kind):
    got = classify(vehicle)
    assert (got.mobility, got.steerability, got.type, got.degenerate) == (m, d, kind, False)
    assert not got.coordinated


CATALOG = {  # what the thesis (or the template's own comments) says each catalog robot is
    "thesis-omni-swedish": 1, "thesis-omni-castor": 1, "thesis-diff-swedish": 2, "thesis-diff-castor": 2,
    "thesis-steer-swedish": 3, "thesis-steer-castor": 3, "thesis-tricycle": 4, "thesis-tricycle-ch4": 4,
    "thesis-bicycle-swedish": 4, "thesis-bicycle-castor": 4, "thesis-two-steer-swedish": 5,
    "thesis-two-steer-castor": 5, "forklift": 4, "line-follower": 2, "diff-drive": 2, "mecanum-4": 1, "omni-3": 1,
    "omni-4": 1, "swerve-4": 5, "ackermann": 4, "bicycle": 4, "skid-steer-4": None,
}


@pytest.mark.parametrize("name", sorted(CATALOG))
def test_catalog_robots(name):
    got = classify(catalog.load(name))
    assert got.type == CATALOG[name]
    assert got.degenerate == (CATALOG[name] is None)
    if got.type:
        assert (got.mobility, got.steerability) == {v: k for k, v in TABLE_5_1.items()}[got.type]
    assert got.coordinated == (name in ("ackermann", "swerve-4"))  # the car is a tricycle only when coordinated


def test_skid_steer_fights_and_moves_straight_only():
    got = classify(catalog.load("skid-steer-4"))
    assert got.degenerate and got.mobility == 1 and any("fight" in r for r in got.reasons)


def _fixed(name, x, y, beta):
    return {"name": name, "type": "fixed", "l": math.hypot(x, y), "alpha": math.atan2(y, x), "beta": beta, "r": 0.1}


def test_degenerate_robots():
    # two fixed wheels whose axles cross: the robot can only turn about the crossing point (5.11)
    crossing = classify(robot("x", _fixed("a", 1, 0, 0.0), _fixed("b", 0, 1, math.pi / 2)))
    assert crossing.degenerate and crossing.mobility == 1 and crossing.type is None
    # parallel distinct axles: straight motion only (5.11: "even if parallel")
    parallel = classify(robot("p", _fixed("a", 0, 0.2, 0.0), _fixed("b", 0.5, -0.3, 0.0)))
    assert parallel.degenerate and parallel.mobility == 1
    # three fixed wheels with three different axles: cannot move (5.6-5.8)
    stuck = classify(robot("s", _fixed("a", 1, 0, 0.0), _fixed("b", 0, 1, math.pi / 2), _fixed("c", 1, 1, 0.7)))
    assert stuck.degenerate and stuck.mobility == 0 and any("cannot move" in r for r in stuck.reasons)
    # an orientable wheel centred on the fixed axle pins the ICR (5.12b)
    pinned = classify(robot("o", _fixed("a", 0.5, 0, 0.0), _fixed("b", -0.5, 0, 0.0),
                            {"name": "o", "type": "steerable", "l": 1.0, "alpha": 0.0, "r": 0.1}))
    assert pinned.degenerate and any("centred on the fixed axle" in r for r in pinned.reasons)
    # two orientable wheels on the same centre
    shared = classify(robot("s", {"name": "o1", "type": "steerable", "l": 0.3, "alpha": 0.2, "r": 0.1},
                            {"name": "o2", "type": "steerable", "l": 0.3, "alpha": 0.2, "r": 0.1}))
    assert shared.degenerate and any("share a centre" in r for r in shared.reasons)


def test_type5_mobility_rises_at_aligned_wheels():
    """Digest §7.5: with beta1, beta2 in {0, pi} both axles lie on the X axis and m = 2 (configuration dependence)."""
    r = type5(third="castor")
    got = classify(r)
    assert got.mobility == 1 and len(got.special) == 1 and got.special[0].mobility == 2
    for b1, b2 in [(0, 0), (0, math.pi), (math.pi, 0), (math.pi, math.pi)]:
        beta = np.array([b1, b2, 0.7])
        assert instantaneous_mobility(r, beta) == 2
        a = r.constraint_matrix(beta)
        assert a.shape[-1] - matrix_rank(a) == 2  # k - rank A (6.8), independently
    assert instantaneous_mobility(r, np.array([0.1, 0.0, 0.7])) == 1
    special = np.array(got.special[0].beta)
    assert np.allclose(np.sin(special[:2]), 0.0, atol=1e-12)


def test_icr_formula_erratum_5_21():
    """Wheel 1 at (1, 0) with axle along X, wheel 2 at (2, 1) with axle along Y: ICR (2, 0), not (0, 2)."""
    r = robot("icr", _fixed("a", 1, 0, 0.0), {"name": "b", "type": "steerable", "l": math.hypot(2, 1),
                                                "alpha": math.atan2(1, 2), "beta": math.pi / 2, "r": 0.1})
    got = icr(r)
    assert got.kind == "point"
    np.testing.assert_allclose(got.point, [2.0, 0.0], atol=1e-12)
    b1, b2 = 0.0, math.pi / 2  # (5.21) as printed in the thesis
    l1s, l2s = 1 * math.sin(b1 - 0.0), math.hypot(2, 1) * math.sin(b2 - math.atan2(1, 2))
    thesis = ((l1s * math.sin(b2) - l2s * math.sin(b1)) / math.sin(b1 - b2),
              (l1s * math.cos(b2) - l2s * math.cos(b1)) / math.sin(b1 - b2))
    np.testing.assert_allclose(thesis, [0.0, 2.0], atol=1e-12)  # swapped
    corrected = ((l1s * math.cos(b2) - l2s * math.cos(b1)) / math.sin(b1 - b2),
                 (l1s * math.sin(b2) - l2s * math.sin(b1)) / math.sin(b1 - b2))
    np.testing.assert_allclose(corrected, got.point, atol=1e-12)


def test_icr_sets():
    assert icr(omni_swedish()).kind == "plane"
    line = icr(differential())
    assert line.kind == "line" and np.allclose(np.abs(line.line), [1.0, 0.0, 0.0])
    stuck = robot("s", _fixed("a", 1, 0, 0.0), _fixed("b", 0, 1, math.pi / 2), _fixed("c", 1, 1, 0.7))
    assert icr(stuck).kind == "none"
    assert "translation" in icr(tricycle(beta3=0.0)).describe()
    assert icr(stuck).consistent is None  # fixed axles that miss: no steering can mend it


@pytest.mark.parametrize("phi", [0.0, 0.5, 1.0, -2.0])
@pytest.mark.parametrize(("gap", "kind"), [(5.960464477539063e-08, "line"), (1e-5, "infinity")])
def test_axles_parallel_within_rounding_do_not_meet_far_away(phi, gap, kind):
    """Two fixed wheels turned alike, `gap` m apart along x (6e-8 m: hypothesis's example): their axles are parallel,
    so the robot translates. Turning the frame by `phi` leaves their directions equal only to rounding, which made
    them meet 5e8 m to one side in one frame and 6e8 m to the other in the next. Within rounding of the condition of
    the two axles, the ICR is at infinity, along the wheels, in every frame; a genuine meeting 1e4 sizes away is
    still a point. Axles 6e-8 m apart on a robot of size 0.5 m (1.2e-7 of it) are one axle to the rank rule
    (``linalg.RANK_RTOL`` 1e-6), in every frame too: any point on it."""
    rolling = (-math.sin(1.0 - phi), math.cos(1.0 - phi))  # the axles' direction is beta, 1 - phi when turned

    def turned(name, x, beta=1.0):  # a fixed wheel at (x, 0) of the original frame, in the turned frame
        return Wheel(name, "fixed", l=abs(x), alpha=math.atan2(-math.sin(phi) * x, math.cos(phi) * x),
                     beta=beta - phi, r=0.5)

    got = icr(Robot("r", (turned("w0", 0.0), turned("w1", gap))))
    assert got.kind == kind
    if kind == "line":  # the line through both wheels' mount points, along their axles
        return
    assert min(np.abs(np.array(got.direction) - sign * np.array(rolling)).max() for sign in (1, -1)) < 1e-9
    apart = Robot("r", (turned("w0", 0.0), turned("w1", 1.0, beta=1.0 + 1e-4)))  # axles 1e-4 rad apart: 8.4e3 m
    assert icr(apart).kind == "point" and 1e3 < math.hypot(*icr(apart).point) < 1e5


@pytest.mark.parametrize(("outer", "kind", "hint"), [(23.4429, "point", True), (24.0, "none", True),
                                                     (25.0, "none", False), (30.0, "none", False)])
def test_nearly_meeting_steered_axles_give_the_headings_at_which_they_meet(outer, kind, hint):
    """An Ackermann car steered 30 deg inside has no ICR unless the outside wheel is at atan(L / (L / tan 30 deg +
    track)) = 23.44289865 deg (closed form): headings rounded to 0.0001 deg gave "cannot move" and no more. Now
    the rank rule reads them as rounding (``linalg.HEADING_RESOLUTION``): the ICR, with the headings they were
    rounded from. When the steered wheels miss one point by more, and at most 0.5 deg, the headings at which the
    axles meet come with "no ICR"; they keep the rear axle (fixed) and turn about one point on it."""
    car = catalog.load("ackermann")
    exact = math.degrees(math.atan(2.7 / (2.7 / math.tan(math.radians(30)) + 1.55)))
    assert icr(car, heading=np.radians([30.0, exact])).kind == "point"
    assert icr(car, heading=np.radians([30.0, exact])).consistent is None  # exact headings: no note
    got = icr(car, heading=np.radians([30.0, outer]))
    assert got.kind == kind and (got.consistent is not None) == hint
    if hint:
        headings = np.array([h for _, h in got.consistent])
        meet = icr(car, heading=headings)
        assert meet.kind == "point" and abs(meet.point[0]) < 1e-9  # on the rear axle
        inner, outer_aimed = np.degrees(headings)
        assert math.degrees(math.atan(2.7 / (2.7 / math.tan(math.radians(inner)) + 1.55))) == pytest.approx(
            outer_aimed, abs=1e-9)  # the closed form holds at the aimed headings
        assert max(abs(inner - 30.0), abs(outer_aimed - outer)) == pytest.approx(math.degrees(got.miss[1]))
        start = "no ICR: the robot cannot move without slipping; its steered axles miss one point by"
        if kind == "point":
            start = "ICR at (0.000, 5.452) m; its steered axles miss the ICR by"  # 2.7 / tan(30 deg) + 1.55 / 2
            assert abs(got.point[0]) < 1e-6 and got.miss[1] < 1e-6  # on the rear axle, to the headings' rounding
        assert got.describe().startswith(start)


# ---- random robots: the classification agrees with the rank of the constraint matrix -------------------------
_SIMPLE = ["fixed", "steerable", "castor", "swedish"]


@st.composite
def simple_robots(draw):
    n = draw(st.integers(1, 4))
    ws = tuple(draw(wheels(type_name=draw(st.sampled_from(_SIMPLE)), name=f"w{i}")) for i in range(n))
    return Robot("random", ws)


def _coordinated_beta(r: Robot, rng) -> np.ndarray:
    """Steer every steerable wheel's axle through one ICR allowed by the fixed wheels (written out here)."""
    fixed_rows = [np.array([math.cos(w.beta), math.sin(w.beta), w.l * math.sin(w.beta - w.alpha)])
                  for w in r.wheels if w.type == "fixed"]
    e = np.array(fixed_rows).reshape(-1, 3)
    _, sv, vh = np.linalg.svd(np.vstack([e, np.zeros((3, 3))]))
    rank = int(np.sum(sv > 1e-9 * max(sv.max(), 1.0)))
    if rank == 3:
        return r.beta
    twist = vh[rank:].T @ rng.normal(size=3 - rank)
    x, y = -twist[1], twist[0]  # homogeneous ICR (x, y, w) = (-vy, vx, omega)
    w_icr = twist[2]
    beta = []
    for w in r.wheels:
        if w.type == "steerable":
            px, py = w.l * math.cos(w.alpha), w.l * math.sin(w.alpha)
            beta.append(math.atan2(y - w_icr * py, x - w_icr * px))
        elif w.kind.steers:
            beta.append(rng.uniform(-math.pi, math.pi))
    return np.array(beta)


@settings(max_examples=1000)
@given(simple_robots(), st.integers(0, 2**16))
def test_random_robots_agree_with_the_rank_of_the_constraint_matrix(r, seed):
    pts = np.array([w.position for w in r.wheels])
    gaps = np.linalg.norm(pts[:, None] - pts[None], axis=-1)
    assume(np.all((gaps < 1e-12) | (gaps > 1e-3)))  # no sub-millimetre offsets: ranks need a length scale
    got = classify(r)
    beta = _coordinated_beta(r, np.random.default_rng(seed))
    a = r.constraint_matrix(beta)
    sv = np.linalg.svd(a, compute_uv=False)
    assume(np.all((sv < 1e-12) | (sv > 1e-6)))  # no rank decided by a nanometre (e.g. axles 1e-8 m apart)
    if got.mobility > 0:
        assert a.shape[-1] - int(matrix_rank(a)) == got.mobility  # (6.8) at a generic admissible configuration
    fixed_e = np.array([[math.cos(w.beta), math.sin(w.beta), w.l * math.sin(w.beta - w.alpha)]
                        for w in r.wheels if w.type == "fixed"]).reshape(-1, 3)
    rf = int(matrix_rank(fixed_e)) if len(fixed_e) else 0
    assert got.fixed_rank == rf
    if not got.degenerate:  # Table 5.1 bounds (5.15) and m + d = 3 - rank K_rf*
        assert 1 <= got.mobility <= 3 and 0 <= got.steerability <= 2 and 2 <= got.mobility + got.steerability <= 3
        assert got.mobility + got.steerability == 3 - rf
        assert TABLE_5_1[(got.mobility, got.steerability)] == got.type
    else:
        assert got.type is None and got.reasons


@pytest.mark.parametrize(("gap", "expected"), [(1e-5, (1, 2, 5, False)), (1e-7, (2, 1, 3, True))])
def test_generic_ranks_do_not_depend_on_the_seed_near_a_special_configuration(gap, expected):
    """Two steerable wheels `gap` m apart (and a ball): any two axles meet, so m = 1, d = 2, type 5 and no
    coordination (5.13)-(5.15). The m of a generic configuration is the least met: an ICR drawn 100 m away makes the
    two axles one line to the rank tolerance (m = 2 there). Before, m was the largest met, and 10 of these 40 seeds (the
    first: 8) printed "type 3, m = 2, d = 1; the steered wheels must be coordinated" for wheels 100 nm apart. Wheels
    100 nm apart on this 1 m robot are at one point to the rank rule (1e-7 of its size, below ``linalg.RANK_RTOL``):
    one steered wheel, type 3, with every seed."""
    two = Robot(name="r", wheels=(Wheel(name="a", type="steerable", l=0.0, alpha=0.0, beta=0.0, r=0.5),
                                  Wheel(name="b", type="steerable", l=gap, alpha=0.0, beta=0.0, r=0.5),
                                  Wheel(name="c", type="ball", l=1.0, alpha=-1.0, beta=0.0, r=0.5)))
    for seed in range(40):
        got = classify(two, seed=seed)
        assert (got.mobility, got.steerability, got.type, got.coordinated) == expected, seed


def test_synchro_drive_as_its_equivalent_wheel():
    """§5.5.3: a synchro drive is modelled by one steerable wheel at the turret centre plus its omni support."""
    r = type3(omni="castor", l2=0.3, a2=-2.0, l3=0.3, a3=2.0)
    assert classify(r).type == 3
    assert classify(r).name.startswith("one steered wheel")
    assert classify(omni_swedish(gamma=45 * DEG)).type == 1


def test_axle_rows_not_the_first_row_of_5_3():
    """Erratum 2: (5.17)/(5.23) take the first row of (5.3), -cos(beta) E / |E|^2, which vanishes at beta = 90 deg.

    With axles along y (beta = 90 deg, as in every REP-103 robot) that row is zero and the fixed axle would be lost;
    the rows E_i keep it: a REP-103 differential drive is type 2, not omnidirectional.
    """
    b = math.pi / 2
    l, a = 0.2, math.pi / 2
    e = np.array([math.cos(b), math.sin(b), l * math.sin(b - a)])
    first_row = -math.cos(b) * e / (e @ e)
    assert np.allclose(first_row, 0.0)
    got = classify(catalog.load("diff-drive"))
    assert got.type == 2 and got.fixed_rank == 1


@pytest.mark.parametrize("angle", [0.0, 30.0, 90.0, 135.0])
def test_special_configuration_is_told_in_headings(angle):
    """The text said "(at 0.0 deg, mod 180 deg)" for the direction of the line, which wmrkit's steering door reads
    as a heading: steering both wheels to heading 0 there drives along the line, with m = 1. It now names the
    headings, and steering the wheels to them gives the special m."""
    a, c = math.radians(angle), (math.cos(math.radians(angle)), math.sin(math.radians(angle)))
    r = robot("pair", {"name": "o1", "type": "steerable", "position": [0.5 * c[0], 0.5 * c[1]], "r": 0.1},
              {"name": "o2", "type": "steerable", "position": [-0.5 * c[0], -0.5 * c[1]], "r": 0.1},
              {"name": "s3", "type": "swedish", "position": [-c[1], c[0]], "beta": 0.2, "gamma": 90 * DEG, "r": 0.1,
               "r_r": 0.02})
    (special,) = classify(r).special
    words = special.description.split("headings ")[1]
    h1, h2 = (math.radians(float(x)) for x in words.removesuffix(" deg)").split(" or "))
    assert abs(math.remainder(h1 - a, math.pi)) == pytest.approx(math.pi / 2)
    assert abs(math.remainder(h2 - h1 - math.pi, 2 * math.pi)) < 1e-9
    assert all(-180 < math.degrees(h) <= 180 for h in (h1, h2))
    for h in (h1, h2):
        assert instantaneous_mobility(r, heading=[h, h]) == special.mobility == 2
    assert instantaneous_mobility(r, heading=[a, a]) == 1


def test_fighting_fixed_wheels_are_named_in_description_order():
    """The reason listed the fixed wheels in alphabetical order: w0, w1, w10, w11, ..., w2 for a ring of wheels
    w0..w11; it now names them as the description lists them."""
    ring = [{"name": f"w{i}", "type": "fixed", "r": 0.05, "heading": 0.0,
             "position": [0.5 * math.cos(2 * math.pi * i / 12), 0.5 * math.sin(2 * math.pi * i / 12)]}
            for i in range(12)]
    robot = Robot.from_dict({"name": "ring", "wheels": ring})
    c = classify(robot)
    assert c.degenerate and c.reasons[0].startswith(
        "fixed wheels " + ", ".join(f"w{i}" for i in range(12)) + " have different axles")
