"""Per-wheel inverse kinematics (thesis §8.4): closed forms per wheel type, steering policy, feasibility, batching.

Every expected value comes from somewhere other than the code under test: the thesis's closed forms written out
here ((8.9)-(8.28), (8.46)-(8.51), (3.28)-(3.36)), the slip equations of ``Robot.slip_velocity`` (3.22), least
squares (4.11), or the forklift oracle of digest ch8-10 §1.5.3.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from strategies import robots
from wmrkit import Robot, ShapeError, SingularError, Wheel, catalog
from wmrkit.kinematics import _ik_fast
from wmrkit.kinematics.wheel_ik import forward_kinematics, twist_is_determined, wheel_commands, wrap_angle

PI = math.pi
BATCHES = [(), (1,), (5,), (2, 3)]

#: One wheel of every type (8 wheels): the all-types robot of the generic suites.
ZOO = Robot.from_dict({"name": "zoo", "wheels": [
    {"name": "fix", "type": "fixed", "position": [0.3, 0.25], "beta": 1.4, "r": 0.1},
    {"name": "ste", "type": "steerable", "position": [0.4, -0.2], "beta": 0.3, "r": 0.12},
    {"name": "cas", "type": "castor", "position": [-0.3, 0.2], "beta": 2.0, "d": 0.05, "delta": 0.3, "r": 0.04},
    {"name": "swe", "type": "swedish", "position": [-0.35, -0.25], "beta": 1.2, "gamma": 0.7, "r": 0.07,
     "r_r": 0.015},
    {"name": "dbl", "type": "double", "position": [0.1, 0.4], "beta": -0.5, "b": 0.06, "r": 0.05},
    {"name": "dca", "type": "double_castor", "position": [0.0, -0.4], "beta": 0.9, "d": 0.07, "b": 0.05,
     "r": 0.045},
    {"name": "bal", "type": "ball", "position": [0.5, 0.0], "beta": 0.2, "r": 0.03},
    {"name": "ort", "type": "orthogonal", "position": [-0.5, 0.05], "beta": -1.0, "r": 0.06},
]})
ZOO_FREE = Robot(name="zoo-free", wheels=tuple(w for w in ZOO.wheels if w.type != "fixed"))


def one(type_name: str, **fields) -> Robot:
    return Robot.from_dict({"name": type_name, "wheels": [{"name": "w", "type": type_name, **fields}]})


def random_twists(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    return rng.normal(size=(*shape, 3))


# ---- closed forms of the thesis, per wheel type ------------------------------------------------------------
def test_steerable_angle_and_spin_are_8_9_and_8_12():
    rng = np.random.default_rng(1)
    l, alpha, r = 0.6, 2.1, 0.09
    robot = one("steerable", l=l, alpha=alpha, r=r)
    twist = random_twists(rng, (200,))
    vx, vy, w = twist.T
    num, den = -vx + w * l * math.sin(alpha), vy + w * l * math.cos(alpha)
    beta_4q = np.arctan2(num, den)  # (8.9), 4-quadrant
    spin_4q = -np.hypot(num, den) / r  # (8.12)
    near = beta_4q + rng.uniform(-1.4, 1.4, 200)  # current angles closer to the 4-quadrant root ...
    c = wheel_commands(robot, twist, near[:, None])
    np.testing.assert_allclose(np.cos(c.steer[:, 0] - beta_4q), 1.0, atol=1e-12)
    np.testing.assert_allclose(c.spin[:, 0], spin_4q, rtol=1e-12)
    far = near + PI  # ... or to the opposite one: same axle line, spin reversed
    c = wheel_commands(robot, twist, far[:, None])
    np.testing.assert_allclose(np.cos(c.steer[:, 0] - beta_4q), -1.0, atol=1e-12)
    np.testing.assert_allclose(c.spin[:, 0], -spin_4q, rtol=1e-12)
    assert np.all(np.isnan(c.steer_rate)) and c.feasible.all()


def test_two_quadrant_form_matches_when_the_wheel_is_near_zero():
    """(8.9) with atan in (-90, 90) deg and the spin times sign(D): our policy with the current angle at 0."""
    rng = np.random.default_rng(2)
    robot = one("steerable", position=[0.2, 0.3], r=0.1)
    twist = random_twists(rng, (100,))
    vx, vy, w = twist.T
    num, den = -vx + w * 0.3, vy + w * 0.2
    c = wheel_commands(robot, twist, [0.0])
    np.testing.assert_allclose(c.steer[:, 0], np.arctan(num / den), atol=1e-12)
    np.testing.assert_allclose(c.spin[:, 0], -np.sign(den) * np.hypot(num, den) / 0.1, rtol=1e-12)


def test_fixed_wheel_spin_8_12_and_lateral_slip_8_14():
    rng = np.random.default_rng(3)
    l, alpha, beta, r = 0.45, -0.7, 0.4, 0.08
    robot = one("fixed", l=l, alpha=alpha, beta=beta, r=r)
    twist = random_twists(rng, (50,))
    c = wheel_commands(robot, twist)
    row_roll = np.array([-math.sin(beta), math.cos(beta), l * math.cos(beta - alpha)])
    row_lat = np.array([math.cos(beta), math.sin(beta), l * math.sin(beta - alpha)])
    np.testing.assert_allclose(c.spin[:, 0], -(twist @ row_roll) / r, rtol=1e-12)
    np.testing.assert_allclose(c.slip[:, 0], twist @ row_lat, rtol=1e-12, atol=1e-15)
    assert not c.feasible.any()


def test_castor_steer_rate_8_24_and_spin_8_25():
    rng = np.random.default_rng(4)
    l, alpha, d, delta, r = 0.5, 0.8, 0.06, 0.35, 0.05
    robot = one("castor", l=l, alpha=alpha, d=d, delta=delta, r=r)
    twist = random_twists(rng, (50,))
    beta = rng.uniform(-PI, PI, (50, 1))
    c = wheel_commands(robot, twist, beta)
    b = beta[:, 0]
    bd = (np.cos(b + delta) * twist[:, 0] + np.sin(b + delta) * twist[:, 1]
          + (l * np.sin(b + delta - alpha) - d * math.cos(delta)) * twist[:, 2]) / (d * math.cos(delta))
    spin = -(-np.sin(b) * twist[:, 0] + np.cos(b) * twist[:, 1] + l * np.cos(b - alpha) * twist[:, 2]) / (
        r * math.cos(delta))
    np.testing.assert_allclose(c.steer_rate[:, 0], bd, rtol=1e-11)
    np.testing.assert_allclose(c.spin[:, 0], spin, rtol=1e-11)
    np.testing.assert_allclose(c.steer[:, 0], wrap_angle(b), rtol=0, atol=0)  # castors keep their angle
    assert c.feasible.all()


def test_swedish_spin_8_27_and_roller_rate_uses_roller_radius_8_28():
    """(8.28) prints 1/(r sin(gamma)); the derivation (and zero slip) needs the roller radius r_r (errata)."""
    rng = np.random.default_rng(5)
    l, alpha, beta, gamma, r, r_r = 0.4, 2.5, 1.1, 0.6, 0.07, 0.012
    robot = one("swedish", l=l, alpha=alpha, beta=beta, gamma=gamma, r=r, r_r=r_r)
    twist = random_twists(rng, (50,))
    c = wheel_commands(robot, twist)
    bg = beta + gamma
    spin = -(twist @ [math.cos(bg), math.sin(bg), l * math.sin(bg - alpha)]) / (r * math.sin(gamma))
    roller = (twist @ [math.cos(beta), math.sin(beta), l * math.sin(beta - alpha)]) / (r_r * math.sin(gamma))
    np.testing.assert_allclose(c.spin[:, 0], spin, rtol=1e-11)
    np.testing.assert_allclose(c.rates[:, 1], roller, rtol=1e-11)
    np.testing.assert_allclose(robot.slip_velocity(c.velocity(twist)), 0.0, atol=1e-12)
    printed = c.velocity(twist).copy()
    printed[:, 4] *= r_r / r  # the roller rate as printed in (8.28), with r instead of r_r
    assert np.abs(robot.slip_velocity(printed)).max() > 1e-3


def test_double_wheel_is_a_steerable_wheel_steered_by_its_two_spins():
    """(3.28): the mean spin is the centred wheel's; (3.29) with the angle held: r (spin2 - spin1) = 2 b omega."""
    rng = np.random.default_rng(6)
    place = {"position": [0.3, -0.2], "r": 0.05}
    dbl, ste = one("double", b=0.07, **place), one("steerable", **place)
    twist = random_twists(rng, (40,))
    current = rng.uniform(-PI, PI, (40, 1))
    c_d, c_s = wheel_commands(dbl, twist, current), wheel_commands(ste, twist, current)
    np.testing.assert_allclose(c_d.steer, c_s.steer, atol=1e-12)
    np.testing.assert_allclose(c_d.spin, c_s.spin, rtol=1e-11)
    spin1, spin2 = c_d.rates[:, 1], c_d.rates[:, 2]
    np.testing.assert_allclose(np.abs(0.05 * (spin2 - spin1)), np.abs(2 * 0.07 * twist[:, 2]), rtol=1e-10)
    np.testing.assert_array_equal(c_d.steer_rate, 0.0)
    np.testing.assert_allclose(dbl.slip_velocity(c_d.velocity(twist), c_d.beta), 0.0, atol=1e-12)


def test_double_castor_is_a_castor_with_two_spins():
    """(3.35): mean spin = the castor's (d = a, delta = 0); (3.36): same steering rate."""
    rng = np.random.default_rng(7)
    place = {"position": [-0.3, 0.1], "r": 0.04, "d": 0.06}
    dca, cas = one("double_castor", b=0.05, **place), one("castor", **place)
    twist, beta = random_twists(rng, (40,)), rng.uniform(-PI, PI, (40, 1))
    c_d, c_c = wheel_commands(dca, twist, beta), wheel_commands(cas, twist, beta)
    np.testing.assert_allclose(c_d.steer_rate, c_c.steer_rate, rtol=1e-11)
    np.testing.assert_allclose(c_d.spin, c_c.spin, rtol=1e-11)
    np.testing.assert_allclose(dca.slip_velocity(c_d.velocity(twist), beta), 0.0, atol=1e-12)


# ---- steering policy ---------------------------------------------------------------------------------------
def test_closest_angle_is_kept_and_angles_wrap_to_half_open_interval():
    rng = np.random.default_rng(8)
    twist, current = random_twists(rng, (300,)), rng.uniform(-3 * PI, 3 * PI, (300, ZOO.beta.size))
    c = wheel_commands(ZOO, twist, current)
    steered = [ZOO.steer_names.index(n) for n in ("ste", "dbl")]
    gap = wrap_angle(c.beta[:, steered] - current[:, steered])
    assert np.all(np.abs(gap) <= PI / 2 + 1e-12)
    finite = c.steer[~np.isnan(c.steer)]
    assert np.all((finite > -PI) & (finite <= PI))


def test_driving_straight_back_keeps_the_wheel_and_reverses_the_spin():
    swerve = catalog.load("swerve-4")  # all wheels straight ahead (beta = 90 deg)
    c = wheel_commands(swerve, [-1.0, 0.0, 0.0])
    np.testing.assert_array_equal(c.steer, PI / 2)
    np.testing.assert_allclose(c.spin, -1.0 / 0.0508, rtol=1e-14)
    c = wheel_commands(swerve, [0.0, -1.0, 0.0], [PI] * 4)  # atan2(-0.0, -1) would give -pi: never returned
    np.testing.assert_array_equal(c.steer, PI)
    np.testing.assert_array_equal(wrap_angle([-PI, PI, 3 * PI, -3 * PI, 0.0]), [PI, PI, PI, PI, 0.0])


def test_zero_speed_keeps_the_current_angle_and_stops_the_wheel():
    robot = one("steerable", position=[0.5, 0.2], r=0.1)
    c = wheel_commands(robot, np.zeros(3), [7.0])
    assert c.steer[0] == wrap_angle(7.0) and c.spin[0] == 0.0 and c.held[0]
    # turning about the wheel's own steering axis: that wheel's angle is undefined too
    spin_about_wheel = [0.2 * 1.5, -0.5 * 1.5, 1.5]  # v = -omega x p
    c = wheel_commands(ZOO_FREE, [0, 0, 0], ZOO_FREE.beta)
    held = dict(zip(ZOO_FREE.wheel_names, c.held, strict=True))
    assert held["ste"] and held["dbl"] and not held["cas"]  # castors have no angle to choose
    np.testing.assert_array_equal(c.beta, wrap_angle(ZOO_FREE.beta))
    c = wheel_commands(robot, spin_about_wheel, [0.4])
    assert c.steer[0] == 0.4 and c.spin[0] == 0.0 and c.held[0]


# ---- feasibility ---------------------------------------------------------------------------------------------
def test_lateral_motion_of_a_differential_drive_is_reported_not_accepted():
    diff = catalog.load("diff-drive")
    c = wheel_commands(diff, [[1.0, 0.0, 0.5], [1.0, 0.3, 0.5]])
    np.testing.assert_array_equal(c.feasible, [True, False])
    np.testing.assert_allclose(c.slip[1, :2], 0.3, rtol=1e-14)  # lateral row of a wheel on the axle: v_y
    assert c.slip[1, 2] == 0.0  # the castor follows


def test_forklift_matches_thesis_closed_forms_8_46_to_8_51():
    """Thesis frame: X right, Y forward, R at the fork tips; ours: x = Y, y = -X (catalog/forklift.yaml)."""
    fork = catalog.load("forklift")
    l12, l3, e, r = 0.45, 2.35, 1.0, 0.23
    rng = np.random.default_rng(9)
    v_th = rng.normal(size=(100, 2)) + np.array([0.0, 1.5])  # (R v_x, R v_y) in the thesis frame
    omega = -v_th[:, 0] / e  # (8.47)
    twist = np.stack([v_th[:, 1], -v_th[:, 0], omega], axis=-1)
    phi1 = -(v_th[:, 1] - l12 / e * v_th[:, 0]) / r  # (8.48), wheel 1 at (l12, -e): our right_drive
    phi2 = -(v_th[:, 1] + l12 / e * v_th[:, 0]) / r
    beta3 = np.arctan((l3 - e) / e * v_th[:, 0] / v_th[:, 1])  # (8.49), 2-quadrant
    phi3 = -np.sign(v_th[:, 1]) * np.hypot((l3 - e) / e * v_th[:, 0], v_th[:, 1]) / r  # (8.51)
    c = wheel_commands(fork, twist)  # current steering: straight ahead
    assert c.feasible.all()
    # thesis axles point along X (= our -y); ours along +y: spins change sign, angles differ by 90 deg
    np.testing.assert_allclose(c.spin[:, 0], -phi1, rtol=1e-12)
    np.testing.assert_allclose(c.spin[:, 1], -phi2, rtol=1e-12)
    np.testing.assert_allclose(c.steer[:, 2], beta3 + PI / 2, atol=1e-12)
    np.testing.assert_allclose(c.spin[:, 2], -phi3, rtol=1e-12)


@pytest.mark.parametrize(("theta_deg", "v_global", "expected"), [
    (0.0, (0.0, 1.0), {"omega": 0.0, "phi1": -4.3478, "phi2": -4.3478, "beta3": 0.0, "phi3": -4.3478}),
    (0.0, (0.5, 1.0), {"omega": -0.5, "phi1": -3.3696, "phi2": -5.3261, "beta3": 34.0193, "phi3": -5.2456}),
    (30.0, (0.3, -0.4), {"phi1": 2.2753, "phi2": 2.0413, "beta3": -9.24, "phi3": 2.1867}),
])
def test_forklift_oracle_values(theta_deg, v_global, expected):
    """Digest ch8-10 §1.5.3 oracle (thesis sign convention, 2-quadrant beta3) mapped into our frame."""
    th = math.radians(theta_deg)
    gx, gy = v_global
    vx_th, vy_th = math.cos(th) * gx + math.sin(th) * gy, -math.sin(th) * gx + math.cos(th) * gy
    c = wheel_commands(catalog.load("forklift"), [vy_th, -vx_th, -vx_th / 1.0])
    got = {"omega": -vx_th, "phi1": -c.spin[0], "phi2": -c.spin[1], "beta3": math.degrees(c.steer[2]) - 90,
           "phi3": -c.spin[2]}
    for key, value in expected.items():
        assert got[key] == pytest.approx(value, abs=0.01 if key == "beta3" else 1e-4), key


# ---- properties over random robots ---------------------------------------------------------------------------
def _feasible(robot: Robot, twist: np.ndarray) -> np.ndarray:
    """Project a twist onto the null space of the fixed wheels' lateral rows (3.11 row 0)."""
    rows = np.array([[math.cos(w.beta), math.sin(w.beta), w.l * math.sin(w.beta - w.alpha)]
                     for w in robot.wheels if w.type == "fixed"]).reshape(-1, 3)
    return twist - np.linalg.pinv(rows) @ (rows @ twist) if len(rows) else twist


@settings(max_examples=400)
@given(robot=robots(max_wheels=4), raw=st.lists(st.floats(-2, 2), min_size=3, max_size=3))
def test_ik_then_fk_returns_the_twist_and_no_wheel_slips(robot, raw):
    twist = _feasible(robot, np.array(raw))
    c = wheel_commands(robot, twist)
    scale = 1.0 + np.abs(twist).sum() * (1 + max(w.l + w.d + w.b for w in robot.wheels))
    assume(not c.held.any())  # an undefined angle is a policy, not a solution (tested above)
    assert c.feasible
    q = c.velocity(twist)
    slip = robot.slip_velocity(q, c.beta)
    np.testing.assert_allclose(slip, 0.0, atol=1e-9 * scale)
    spins = [n for n in robot.rate_names if n.split(".")[1].startswith("spin")]
    # least squares is only as accurate as its matrix is conditioned: pinv keeps singular values above
    # 1e-15 max(shape) s_max, and errors grow as eps s_max / s_min_kept (e.g. a wheel 1e-12 m off the origin)
    a_na = robot.constraint_matrix(c.beta)[:, [i for i in range(3 + len(robot.rate_names))
                                               if i < 3 or robot.rate_names[i - 3] not in spins]]
    s = np.linalg.svd(a_na, compute_uv=False)
    kept = s[s > 1e-15 * max(a_na.shape) * s[0]]
    cond = kept[0] / kept[-1]
    assume(cond < 1e6)
    got, residual = forward_kinematics(robot, {n: q[3 + robot.rate_names.index(n)] for n in spins}, c.beta)
    assert residual <= 1e-12 * scale * cond  # backward-stable least squares: error ~ eps cond
    if twist_is_determined(robot, spins, c.beta):
        np.testing.assert_allclose(got, twist, atol=1e-12 * scale * cond)


TWO_DOUBLES = Robot.from_dict({"name": "two-doubles", "wheels": [
    {"name": "a", "type": "double", "position": [0.3, 0.1], "b": 0.05, "r": 0.04},
    {"name": "b", "type": "double", "position": [-0.3, -0.1], "b": 0.06, "r": 0.05, "beta": 1.0}]})


@pytest.mark.parametrize("batch_t", BATCHES, ids=str)
@pytest.mark.parametrize("batch_b", [(), (1,), (2, 1)], ids=str)
@pytest.mark.parametrize("robot", [ZOO, ZOO_FREE, TWO_DOUBLES, catalog.load("swerve-4"), catalog.load("mecanum-4"),
                                   catalog.load("forklift")], ids=lambda r: r.name)
def test_batch_equals_loop(robot, batch_t, batch_b):
    rng = np.random.default_rng(10)
    twist = random_twists(rng, batch_t)
    beta = rng.uniform(-PI, PI, (*batch_b, robot.beta.size))
    c = wheel_commands(robot, twist, beta)
    batch = np.broadcast_shapes(batch_t, batch_b)
    assert c.steer.shape == (*batch, len(robot.wheels)) and c.feasible.shape == batch
    assert c.rates.shape == (*batch, len(robot.rate_names)) and c.beta.shape == (*batch, robot.beta.size)
    t_full = np.broadcast_to(twist, (*batch, 3))
    b_full = np.broadcast_to(beta, (*batch, robot.beta.size))
    for idx in np.ndindex(*batch):
        single = wheel_commands(robot, t_full[idx], b_full[idx])
        for field in ("steer", "spin", "steer_rate", "rates", "slip", "beta"):
            np.testing.assert_allclose(getattr(c, field)[idx], getattr(single, field), rtol=1e-13, atol=1e-13,
                                       err_msg=field)
        assert c.feasible[idx] == single.feasible and np.array_equal(c.held[idx], single.held)
    spin_cols = [robot.rate_names.index(f"{w.name}.spin") for w in robot.wheels if "spin" in w.kind.rates]
    spin_wheels = [i for i, w in enumerate(robot.wheels) if "spin" in w.kind.rates]
    np.testing.assert_array_equal(c.spin[..., spin_wheels], c.rates[..., spin_cols])
    for i, w in enumerate(robot.wheels):
        if "spin2" in w.kind.rates:  # (3.28)/(3.35): the unit's spin is the mean of its two wheels'
            pair = c.rates[..., [robot.rate_names.index(f"{w.name}.spin1"), robot.rate_names.index(f"{w.name}.spin2")]]
            np.testing.assert_allclose(c.spin[..., i], pair.mean(axis=-1), rtol=1e-15, atol=1e-15)


def test_large_batch_crosses_blocks_like_small_ones():
    rng = np.random.default_rng(11)
    swerve = catalog.load("swerve-4")
    block = _ik_fast.BLOCK
    twist = random_twists(rng, (2 * block + 500,))  # more than one block of the steering kernel
    twist[::7] = 0.0
    c = wheel_commands(swerve, twist)
    pick = [0, 1, block - 1, block, block + 1, 2 * block + 499, 7 * 300]
    small = wheel_commands(swerve, twist[pick])
    np.testing.assert_array_equal(c.steer[pick], small.steer)
    np.testing.assert_array_equal(c.spin[pick], small.spin)
    assert c.held[::7].all() and not c.held[1::7].any()


# ---- values and errors ---------------------------------------------------------------------------------------
def test_results_are_read_only_and_to_dict_takes_one_twist():
    c = wheel_commands(ZOO, np.ones((2, 3)))
    for field in ("steer", "spin", "steer_rate", "rates", "slip", "feasible", "beta", "held", "heading"):
        with pytest.raises(ValueError, match="read-only"):
            getattr(c, field)[...] = 0
    with pytest.raises(ShapeError, match=r"to_dict: expected one twist"):
        c.to_dict()
    d = wheel_commands(ZOO, [0.1, 0.2, 0.3]).to_dict()
    assert set(d["wheels"]["dbl"]) == {"heading", "spin", "steer_rate", "spin1", "spin2"}
    assert set(d["wheels"]["swe"]) == {"spin", "steer_rate", "roller"}  # no heading: it does not steer
    assert math.isnan(d["wheels"]["ste"]["steer_rate"]) and "heading" not in d["wheels"]["fix"]


def test_wrong_shapes_name_the_argument():
    with pytest.raises(ShapeError, match=r"twist_robot: expected shape \(\.\.\., 3\), got \(2,\)"):
        wheel_commands(ZOO, [1.0, 2.0])
    with pytest.raises(ShapeError, match=r"beta: expected shape \(\.\.\., 4\)"):
        wheel_commands(ZOO, [1.0, 2.0, 3.0], [0.0])


def test_forward_kinematics_check_judges_rates_from_the_ik():
    """Rates from the IK of a random twist are consistent; scaling one wheel's spin makes that wheel slip."""
    import scipy.linalg

    from wmrkit.kinematics import _ik_fast
    from wmrkit.kinematics.wheel_ik import forward_kinematics_check

    rng = np.random.default_rng(7)
    for name in ("swerve-4", "mecanum-4", "diff-drive", "forklift"):
        robot = catalog.load(name)
        for _ in range(5):
            twist = rng.uniform(-1, 1, 3)
            cmd = wheel_commands(robot, twist)
            if not cmd.feasible:  # project onto the twists the fixed wheels allow (their lateral rows)
                basis = scipy.linalg.null_space(_ik_fast.plan(robot).fixed_lateral.T)
                twist = basis @ (basis.T @ twist)
                cmd = wheel_commands(robot, twist)
                assert cmd.feasible
            rates = {w.name: float(cmd.spin[i]) for i, w in enumerate(robot.wheels) if "spin" in w.kind.rates}
            heading = robot.heading_of_beta(cmd.beta)
            fk = forward_kinematics_check(robot, rates, heading=heading)
            assert fk.consistent and fk.residual < 1e-9 and fk.slipping == ()
            np.testing.assert_allclose(fk.twist, twist, atol=1e-9)
            wrong = dict(rates)
            first = next(iter(wrong))
            wrong[first] += 5.0 + 0.5 * abs(wrong[first])
            bad = forward_kinematics_check(robot, wrong, heading=heading)
            assert not bad.consistent and first in bad.slipping


@pytest.mark.parametrize(("wheel", "field"), [
    (Wheel("c", "castor", l=0.3, alpha=0.0, beta=math.pi / 2, r=0.05, d=0.0), "d"),  # no offset: steerable
    (Wheel("c", "castor", l=0.3, alpha=0.0, beta=math.pi / 2, r=0.05, d=0.05, delta=math.pi / 2), "delta"),
    (Wheel("c", "swedish", l=0.3, alpha=0.0, beta=math.pi / 2, r=0.05, r_r=0.01, gamma=0.0), "gamma"),
])
def test_a_degenerate_wheel_built_in_python_has_no_wheel_commands(wheel, field):
    """Python may build the degenerate wheels a description refuses; their rates are not determined by the twist,
    and wheel_commands answered NaN, inf or 1.6e17 rad/s spins and steering rates, 'feasible'."""
    robot = Robot("r", (wheel, *(w for w in catalog.load("diff-drive").wheels if w.type == "fixed")))
    with pytest.raises(SingularError, match=rf"robot 'r': wheel 'c': {field}: .* no twist determines its rates, so "
                                            r"it has no wheel commands \(8\.4\)"):
        wheel_commands(robot, [0.5, 0.0, 0.2])
