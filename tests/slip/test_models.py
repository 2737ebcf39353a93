"""The three slip models (§7.4): WLS closed form (7.65)-(7.67), WLS = MCD under linear friction, MQE balance."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from slip_helpers import L3, L12, R, forklift_at_axle, thesis_twist_to_rep

from wmrkit import catalog
from wmrkit.dynamics.mass import Body
from wmrkit.errors import ShapeError
from wmrkit.slip.models import LinearFriction, mcd, mqe, normal_loads, wls
from wmrkit.slip.weights import SlipWeightError, SlipWeights

SPINS = ("right_drive.spin", "left_drive.spin")


def closed_form(u1, u2, beta3, k11, k12):
    """The spec's closed form of the tricycle WLS (7.66) with mu_x12 = 1 (thesis frame, u = forward speeds)."""
    a, b, c = 2.0, k11, k12
    ub, dl = (u1 + u2) / 2, (u1 - u2) / (2 * L12)
    cb, sb = np.cos(beta3), np.sin(beta3)
    g = sb * ub + L3 * cb * dl
    den = 1 + c * (cb**2 / a + sb**2 / (2 * b) + L3**2 * cb**2 / (2 * b * L12**2))
    return np.stack([-(c * cb / a) * g / den, ub - (c * sb / (2 * b)) * g / den,
                     dl - (c * L3 * cb / (2 * b * L12**2)) * g / den], axis=-1)


def matrix_form(u1, u2, beta3, k11, k12, mx=1.0):
    """(7.65)-(7.66) literally: A_mu_na, A_mu_a and one 3x3 inverse (thesis frame, phi_dot = -u / r)."""
    my, m3 = k11 * mx, k12 * mx
    cb, sb = np.cos(beta3), np.sin(beta3)
    ana = np.array([[np.sqrt(2 * mx), 0, 0], [0, np.sqrt(my), np.sqrt(my) * L12], [0, np.sqrt(my), -np.sqrt(my) * L12],
                    [np.sqrt(m3) * cb, np.sqrt(m3) * sb, np.sqrt(m3) * L3 * cb]])
    aa = np.array([[0, 0], [np.sqrt(my) * R, 0], [0, np.sqrt(my) * R], [0, 0]])
    phi = -np.array([u1, u2]) / R
    return -np.linalg.solve(ana.T @ ana, ana.T @ aa @ phi)


def forklift_wls(u1, u2, beta3, k11, k12, mx=1.0):
    robot = forklift_at_axle()
    w = SlipWeights.of({"right_drive": (mx, k11 * mx), "left_drive": (mx, k11 * mx), "steer": (k12 * mx, mx)})
    # thesis beta3 (axle angle, 0 = straight) is the catalog's beta (axle +90 deg: straight) minus 90 deg;
    # the spin of the steered wheel is free, so the axle's sign does not matter
    return wls(robot, SPINS, np.stack([u1, u2], -1) / R, np.asarray(beta3)[..., None] + np.pi / 2, w)


@settings(max_examples=200, deadline=None)
@given(st.floats(-5, 5), st.floats(-5, 5), st.floats(-1.5, 1.5), st.floats(-3, 2), st.floats(-3, 2),
       st.sampled_from([1.0, 0.05, 20.0]))
def test_general_wls_is_the_forklift_closed_form(u1, u2, beta3, lk11, lk12, mx):
    """(7.65)-(7.67) as a test of the general solver: the same twist for any speeds, steering and weights. The
    scale mu_x12 = mx != 1 tells the merged row sqrt(2 mu_x12) from the printed sqrt(2) mu_x12 (docs/errata.md)."""
    k11, k12 = 10.0**lk11, 10.0**lk12
    got = forklift_wls(u1, u2, beta3, k11, k12, mx).twist
    want = thesis_twist_to_rep(closed_form(u1, u2, beta3, k11, k12))
    assert np.allclose(got, want, atol=1e-9 * (1 + abs(u1) + abs(u2)))
    assert np.allclose(thesis_twist_to_rep(matrix_form(u1, u2, beta3, k11, k12, mx)), want,
                       atol=1e-9 * (1 + abs(u1)))


def test_spec_oracles_and_consistent_inputs():
    """The numeric WLS values of the spec's reproduction (§11) and the consistent initial state (0, 2, 0.3)."""
    b = np.arctan(-1.35 * 0.3 / 2)
    for k in ((3.2e-3, 19.2), (0.32, 2.0), (5.0, 0.1)):
        assert np.allclose(forklift_wls(2.135, 1.865, b, *k).twist, thesis_twist_to_rep([0, 2, 0.3]), atol=1e-12)
    got = forklift_wls(2.0, 2.0, np.radians(-10), 0.32, 2.0).twist
    assert np.allclose(got, thesis_twist_to_rep([0.011657, 1.993577, 0.242849]), atol=2e-6)


ROBOTS = ("forklift", "skid-steer-4", "mecanum-4", "thesis-diff-castor", "diff-drive", "swerve-4")


def _inputs(robot, rng):
    names = [n for n in robot.sensed if not n.endswith(".steer")]
    q_a = rng.normal(size=(5, len(names))) * 5
    beta = robot.beta + rng.normal(size=(5, len(robot.steer_names))) * 0.3
    return names, q_a, beta


@pytest.mark.parametrize("name", ROBOTS)
def test_wls_equals_mcd_under_linear_friction(name):
    """The equivalence theorem of §7.4.4: with F = -mu v_slip (7.59), MCD's balance equations are WLS's normal
    equations; MCD is solved by Newton from a deliberately wrong start, WLS by least squares."""
    robot = catalog.load(name)
    rng = np.random.default_rng(1)
    names, q_a, beta = _inputs(robot, rng)
    mu = {w.name: tuple(10.0 ** rng.uniform(-2, 2, 2)) for w in robot.wheels}
    weights = SlipWeights.of(mu)
    law = LinearFriction.from_weights(robot, weights)
    want = wls(robot, names, q_a, beta, weights)
    start = wls(robot, names, q_a, beta)  # unweighted: a different answer
    got = mcd(robot, names, q_a, law, beta, start=start)
    assert got.converged.all()
    scale = 1 + np.abs(want.q_dot).max()
    assert np.allclose(got.q_dot, want.q_dot, atol=1e-7 * scale)
    assert np.allclose(got.dissipation, want.dissipation, rtol=1e-6, atol=1e-9)


def test_wls_minimises_the_weighted_slip():
    """J_LS (7.53) at the WLS solution is below J_LS at any perturbed unassigned velocities."""
    robot = catalog.load("skid-steer-4")
    names = [n for n in robot.sensed]
    w = SlipWeights.uniform(0.1, 1.0)
    sol = wls(robot, names, [1.0, 2.0, 1.5, 2.5], None, w)
    mu = w.row_mu(robot)
    a = robot.constraint_matrix()
    rng = np.random.default_rng(2)
    for _ in range(20):
        q = sol.q_dot.copy()
        q[:3] += rng.normal(size=3) * 1e-3
        s = a @ q
        assert s @ (mu * s) > sol.dissipation


def test_mqe_balances_the_centripetal_force():
    """MQE: friction wrench = (M a_cm, c x M a_cm) with a_cm = omega J v_cm (7.40)-(7.42), computed here."""
    robot = forklift_at_axle()
    body = Body(2500.0, 1500.0, (-0.45, 0.0), 0.7)
    w = SlipWeights.of({"right_drive": (1.0, 1.87), "left_drive": (1.0, 1.87), "steer": (0.645, 1.0)})
    law = LinearFriction(tuple(x * 1e4 for x in w.row_mu(robot)))
    beta = np.array([np.arctan(-1.35 * 0.3 / 2) + np.pi / 2])
    sol = mqe(robot, SPINS, np.array([2.135, 1.865]) / R, law, beta, body=body)
    assert sol.converged
    vx, vy, om = sol.twist
    v_cm = np.array([vx - om * 0.0, vy + om * -0.45])
    f = 2500.0 * om * np.array([-v_cm[1], v_cm[0]])
    wrench = robot.constraint_matrix(np.array([np.arctan(-1.35 * 0.3 / 2) + np.pi / 2]))[:, :3].T @ sol.forces
    assert np.allclose(wrench, [f[0], f[1], -0.45 * f[1]], atol=1e-6 * np.abs(f).max())
    plain = mcd(robot, SPINS, np.array([2.135, 1.865]) / R, law, np.array([np.arctan(-1.35 * 0.3 / 2) + np.pi / 2]))
    assert np.allclose(plain.slip, 0, atol=1e-9)  # consistent inputs: no scrubbing in MCD
    assert abs(sol.slip[0]) > 1e-3  # MQE: the centripetal force needs lateral slip at the drive wheels


def test_static_normal_loads_of_the_forklift():
    """(7.64) at rest: with l_CM / l3 = 1/3 every wheel carries a third of M g (8175 N)."""
    loads = normal_loads(forklift_at_axle(), Body(2500.0, 1500.0, (-0.45, 0.0), 0.7))
    assert np.allclose(loads, 2500 * 9.81 / 3)
    # the forward-acceleration and lateral transfers of (7.64), closed form of the spec §5.8
    ax_fwd, ay_left = 0.8, 0.5
    loads = normal_loads(forklift_at_axle(), Body(2500.0, 1500.0, (-0.45, 0.0), 0.7), (ax_fwd, ay_left))
    f3 = (0.45 * 2500 * 9.81 + 0.7 * 2500 * ax_fwd) / L3  # the rear steer wheel gains load
    f1 = 0.5 * (2500 * 9.81 - f3 + 0.7 * 2500 * ay_left / L12)  # the outer (right) wheel gains load
    assert np.allclose(loads, [f1, 2500 * 9.81 - f3 - f1, f3])


def test_bad_weights_are_refused():
    with pytest.raises(SlipWeightError, match="finite number > 0"):
        SlipWeights.of({"a": (0.0, 1.0)})
    with pytest.raises(SlipWeightError, match="lacks"):
        SlipWeights.of({"nope": (1.0, 1.0)}).row_mu(catalog.load("diff-drive"))
    # a string was read as its characters ("12": (1, 2)) and a third value dropped; a lone number raised a TypeError
    for value in ("12", (1.0, 2.0, 3.0), (1.0,), 5.0, None):
        with pytest.raises(SlipWeightError, match=r"mu\['left'\]: expected a pair of friction coefficients"):
            SlipWeights.of({"left": value})  # type: ignore[dict-item]
        with pytest.raises(SlipWeightError, match=r"default: expected a pair of friction coefficients \(lateral, "):
            SlipWeights.of({}, value)  # type: ignore[arg-type]
    assert SlipWeights.of({"left": np.array([1.0, 2.0])}, [3, 4]) == SlipWeights((("left", 1.0, 2.0),), (3.0, 4.0))
    assert SlipWeights.of({"left": (Fraction(1, 2), np.float32(2))}) == SlipWeights((("left", 0.5, 2.0),))


@pytest.mark.parametrize(("call", "message"), [
    # not a mapping: AttributeError "'str' object has no attribute 'items'"
    (lambda: SlipWeights.of("1"), r"mu: expected a mapping \{wheel name: \(mu_lateral, mu_longitudinal\)\}"),
    (lambda: SlipWeights.of([("left", (1.0, 2.0))]), "mu: expected a mapping"),
    (lambda: SlipWeights.of(None), "mu: expected a mapping"),
    (lambda: SlipWeights.of({1: (1.0, 2.0)}), "mu: expected a mapping"),  # a wheel's name is text
    # text and booleans were read as numbers: ("1", "2") as (1, 2), (True, 1) as (1, 1)
    (lambda: SlipWeights.of({"left": ("1", "2")}), r"mu\['left'\]: got the text '1', but the Python API reads no"),
    (lambda: SlipWeights.of({"left": (1.0, 2.0)}, (1, "2 deg")), "default: got the text '2 deg'"),
    (lambda: SlipWeights.of({"left": (True, 1)}), r"mu\['left'\]: expected a pair of friction coefficients"),
    (lambda: SlipWeights.uniform("1"), "default: got the text '1'"),
    (lambda: SlipWeights.uniform(True), "default: expected a pair of friction coefficients"),
    (lambda: SlipWeights((("left", True, 1.0),)), r"wheel 'left' \(lateral\) must be a finite number > 0, got True"),
])
def test_slip_weights_refuse_what_is_not_a_mapping_of_real_pairs(call, message):
    with pytest.raises(SlipWeightError, match=message):
        call()
    with pytest.raises(ValueError):  # SlipWeightError is a ValueError, as the Python doors' errors are
        call()



@pytest.mark.parametrize(("call", "message"), [
    # text was read as numbers: wls(..., ["120", "120"]) as 120 rad/s (meant as rpm?), loads ["8175", ...] as N
    (lambda fk, b: wls(fk, ["right_drive.spin", "left_drive.spin"], ["120", "120"], b), "q_assigned: got the text"),
    (lambda fk, b: mcd(fk, ["right_drive.spin", "left_drive.spin"], [8.0, 8.0], LinearFriction((1.0,) * 6), b,
                       loads=["8175", "8175", "8175"]), "loads: got the text '8175'"),
    (lambda fk, b: normal_loads(fk, accel_cm=("1", "0")), "accel_cm: got the text '1'"),
    # a unit raised numpy's bare "could not convert string to float", naming no argument
    (lambda fk, b: wls(fk, ["right_drive.spin", "left_drive.spin"], ["10 rpm", 1.0], b), "q_assigned: got the text"),
])
def test_slip_models_refuse_text_where_numbers_go(call, message):
    fk = catalog.load("forklift")
    with pytest.raises(ValueError, match=message + ".*the Python API reads no units"):
        call(fk, fk.beta)

@pytest.mark.parametrize("door", ["wls", "wls_model", "from_weights"])
def test_weights_arguments_take_slip_weights_only(door):
    """A mapping passed as `weights` raised AttributeError "'dict' object has no attribute 'row_mu'"."""
    from wmrkit.slip.weights import wls_model

    dd = catalog.load("diff-drive")
    calls = {"wls": lambda w: wls(dd, ["left.spin", "right.spin"], [1.0, 1.0], weights=w),
             "wls_model": lambda w: wls_model(dd, w), "from_weights": lambda w: LinearFriction.from_weights(dd, w)}
    with pytest.raises(SlipWeightError, match=r"weights: expected SlipWeights or None \(SlipWeights.of\("):
        calls[door]({"left": (1.0, 2.0)})
    calls[door](SlipWeights.uniform(1.0, 2.0))


def test_mqe_from_a_start_with_round_off_zeros_converges():
    """Skid steer at the no-slip IK's rates of (1, 0, 0.3): the default start (unweighted least squares) has
    entries like -4e-17 where the answer has exact zeros; scipy's hybr, whose difference step is relative to each
    unknown, stalled there (residual 13.7 N) until such entries were set to 0. The answer turns less than asked (the
    skid steer's scrubbing)."""
    from wmrkit.kinematics.wheel_ik import wheel_commands
    from wmrkit.slip.models import tyre_friction

    robot = catalog.load("skid-steer-4")
    spins = [n for n in robot.rate_names if n.endswith(".spin")]
    ik = wheel_commands(robot, np.array([1.0, 0.0, 0.3]))
    rates = np.array([ik.rates[robot.rate_names.index(j)] for j in spins])
    sol = mqe(robot, spins, rates, tyre_friction(robot))
    assert bool(sol.converged) and float(sol.residual) < 1e-6
    assert 0 < sol.twist[2] < 0.3


def test_tyre_friction_groups_equal_tyres_and_keeps_each_contact_its_own():
    """The law calls each tyre model once for its contacts: the same forces as each contact's own Tyre."""
    from wmrkit.dynamics.tyres import Tyre
    from wmrkit.slip.models import TyreFriction

    tyres = (Tyre.of("dugoff"), Tyre.of("pacejka"), Tyre.of("dugoff", {"mu": 0.4}), Tyre.of("dugoff"))
    law = TyreFriction(tyres)
    assert len(law.groups) == 3
    rng = np.random.default_rng(5)
    v_slip, v_body = rng.normal(size=(6, 4, 2)), rng.normal(size=(6, 4, 2)) * 3
    loads = rng.uniform(100, 2000, (6, 4))
    got = law(v_slip, v_body, loads)
    for e, tyre in enumerate(tyres):
        v_wheel, v_long = v_body[:, e, 1], v_slip[:, e, 1]
        f = tyre.forces(loads[:, e], v_slip[:, e, 0], v_long, v_wheel, v_long - v_wheel)
        assert np.allclose(got[:, e, 0], f.lateral, rtol=1e-12, atol=0)
        assert np.allclose(got[:, e, 1], f.longitudinal, rtol=1e-12, atol=0)


def test_mqe_over_a_batch_of_steering_angles_is_each_sample_solved_alone():
    """A batch of steering configurations (one load transfer per sample) gives each sample's own answer."""
    from wmrkit.slip.models import tyre_friction

    robot = catalog.load("forklift")
    law = tyre_friction(robot)
    betas = np.pi / 2 + np.array([[0.1], [-0.3], [0.5]])  # beta: the axle angle (pi/2: straight ahead)
    rates = np.array([[10.0, 9.0], [8.0, 9.5], [12.0, 12.5]])
    batch = mqe(robot, SPINS, rates, law, betas)
    assert batch.converged.all()
    for i in range(3):
        alone = mqe(robot, SPINS, rates[i], law, betas[i])
        assert np.allclose(batch.q_dot[i], alone.q_dot, rtol=1e-9, atol=1e-12)
        assert np.allclose(batch.forces[i], alone.forces, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("name", ["diff-drive", "thesis-omni-castor", "thesis-steer-castor", "thesis-two-steer-castor"])
def test_contacts_are_where_the_slip_rows_put_them(name):
    """The body part of a contact's two slip rows (3.12) is the velocity of the contact point p: the omega entry of
    a row along u is u_y p_x - u_x p_y. A castor's contact sat along its axle (-d (cos b, sin b)) instead of along
    its arm, so normal_loads and MQE's load transfer were wrong for castor robots (found by an audit of ch. 7)."""
    from wmrkit.slip.models import contact_positions

    robot = catalog.load(name)
    beta = np.array(robot.beta) + 0.3  # not the described steering
    rows = robot.constraint_matrix(beta)[:, :3].reshape(-1, 2, 3)
    got = contact_positions(robot, beta)
    for (u1, u2), p in zip(rows, got, strict=True):
        m = np.array([[u1[1], -u1[0]], [u2[1], -u2[0]]])
        assert p == pytest.approx(np.linalg.solve(m, [u1[2], u2[2]]), abs=1e-12)


def test_normal_loads_equal_the_dynamic_model_s_on_a_castor_robot():
    """Two implementations of (7.64): the slip models' and the dynamic model's (compiled), on a robot with a castor."""
    from wmrkit.dynamics.model import DynamicModel
    from wmrkit.robot import Robot

    d = catalog.load("diff-drive").to_dict()
    d["body"] = {"mass": 20, "inertia": 0.8, "com": [-0.05, 0.01], "com_height": 0.1}
    for w in d["wheels"]:
        w["inertia"] = {"spin": 0.01, **({"steer": 0.002} if w["type"] == "castor" else {})}
    robot = Robot.from_dict(d)
    assert normal_loads(robot) == pytest.approx(DynamicModel.of(robot).normal_loads(), rel=1e-9)


def test_a_friction_law_that_does_not_fit_the_robot_is_refused_by_name():
    """A LinearFriction of the wrong length gave numpy's broadcast error; NaN or negative coefficients gave a twist."""
    robot = catalog.load("skid-steer-4")
    rates = [1.0, 1.0, 1.0, 1.0]
    for mu, match in (((1.0,) * 4, "2 pairs of coefficients for 4 contacts"), ((1.0, math.nan) * 4, "finite"),
                      ((-1.0, 1.0) * 4, "> 0"), ((), "a .lateral, longitudinal. pair")):
        with pytest.raises(ShapeError, match=match):
            mcd(robot, robot.actuated, rates, LinearFriction(mu))
    with pytest.raises(ShapeError, match=r"shape \(4, 2\), one pair per contact, got shape \(2, 2\)"):
        mqe(robot, robot.actuated, rates, lambda slip, v, loads: -slip[:2])
    with pytest.raises(ShapeError, match="non-finite"):
        mcd(robot, robot.actuated, rates, lambda slip, v, loads: slip * math.inf)
    good = mcd(robot, robot.actuated, rates, LinearFriction((1.0,) * 8))
    assert good.converged.all()


@pytest.mark.parametrize("model", [wls, mcd, mqe])
def test_a_lone_name_for_the_assigned_velocities_is_refused_as_a_string(model):
    """``wls(robot, "front_left.spin", ...)`` read the name as its letters: 'expected distinct velocity names, got
    ['f', 'r', 'o', ...]' (the diff drive's 'left.spin': "has no velocity 'l'"); it is refused naming the string, as
    ``odometry_model`` refuses a lone `sensed` name."""
    robot = catalog.load("skid-steer-4")
    law = () if model is wls else (LinearFriction((1.0,) * 8),)
    with pytest.raises(ShapeError, match=r"expected a sequence of velocity names, got the string 'front_left\.spin'"):
        model(robot, "front_left.spin", [1.0], *law)
    assert model(robot, ("front_left.spin",), [1.0], *law).converged.all()  # a sequence of one name is fine


@pytest.mark.parametrize("free_spin", [False, True])
def test_mcd_with_a_twist_component_assigned_gives_the_tyres_the_body_velocity(free_spin):
    """Assigning omega with the spins (an inverse use, §7.4.3) raised an IndexError when fewer than three velocities
    were left free, and otherwise solved with the contacts' body velocities set to 0, so that the tyre laws took
    every slip as a skid of a wheel at rest (slip angles of 90 deg): vx came out wrong. Here the force balance is
    solved independently with scipy on the robot's own slip rows and tyres."""
    from scipy.optimize import root

    from wmrkit.slip.models import tyre_friction

    robot = catalog.load("skid-steer-4")
    law, loads = tyre_friction(robot), normal_loads(robot)
    spins = robot.sensed[:3] if free_spin else robot.sensed
    q_a = np.array([0.5, 8.0, 12.0, 8.0, 12.0][: 1 + len(spins)])
    sol = mcd(robot, ("omega", *spins), q_a, law, loads=loads)
    a = robot.constraint_matrix()
    cols = [robot.velocity_index(n) for n in ("omega", *spins)]
    free = [c for c in range(a.shape[1]) if c not in cols and c in (0, 1, *map(robot.velocity_index, robot.sensed))]

    def balance(z):
        q = np.zeros(a.shape[1])
        q[cols], q[free] = q_a, z
        return a[:, free].T @ law((a @ q).reshape(4, 2), (a[:, :3] @ q[:3]).reshape(4, 2), loads).reshape(-1)

    want = root(balance, [1.0, 0.0, 12.0][: len(free)], tol=1e-14).x
    assert np.abs(balance(want)).max() < 1e-9
    assert sol.converged
    np.testing.assert_allclose(sol.q_dot[free], want, atol=1e-9)
    assert 0.9 < sol.twist[0] < 1.0  # the wheels' mean rolling speed is 1 m/s: some is lost to the skid


def test_a_start_of_one_sample_serves_a_batch_and_a_start_of_another_batch_is_refused():
    """A `start` whose batch differed from the inputs' raised an IndexError from inside the per-sample loop."""
    robot = catalog.load("skid-steer-4")
    law = LinearFriction((1.0,) * 8)
    rates = np.array([[1.0, 2.0, 1.0, 2.0], [2.0, 1.0, 2.0, 1.0], [1.0, 1.0, 1.0, 1.0]])
    want = mcd(robot, robot.sensed, rates, law)
    one = mcd(robot, robot.sensed, rates, law, start=wls(robot, robot.sensed, rates[:1]))
    assert one.converged.all()
    np.testing.assert_allclose(one.q_dot, want.q_dot, atol=1e-9)
    with pytest.raises(ShapeError, match=r"start: expected velocities of shape \(3, 7\)"):
        mcd(robot, robot.sensed, rates, law, start=wls(robot, robot.sensed, rates[:2]))


@pytest.mark.parametrize("model", ["wls", "mcd", "mqe", "normal_loads"])
def test_inputs_and_steering_of_batches_that_do_not_broadcast_are_refused_naming_both(model):
    """Four samples of rates (or accelerations) against three steering angles: mcd, mqe and normal_loads raised
    numpy's 'shape mismatch: objects cannot be broadcast' (naming neither argument); wls named both."""
    from wmrkit.errors import ShapeError
    from wmrkit.slip.models import tyre_friction

    fk = catalog.load("forklift")
    heading = np.zeros((3, 1))
    calls = {"wls": lambda: wls(fk, SPINS, np.ones((4, 2)), heading=heading),
             "mcd": lambda: mcd(fk, SPINS, np.ones((4, 2)), tyre_friction(fk), heading=heading),
             "mqe": lambda: mqe(fk, SPINS, np.ones((4, 2)), tyre_friction(fk), heading=heading),
             "normal_loads": lambda: normal_loads(fk, accel_cm=np.zeros((4, 2)), heading=heading)}
    name = "accel_cm" if model == "normal_loads" else "q_assigned"
    with pytest.raises(ShapeError, match=rf"{name} \(4, 2\) and the steering configurations \(3,\).*do not broadcast"):
        calls[model]()


@pytest.mark.parametrize(("law", "power_law"), [(lambda n: np.ones_like(n), True), (lambda n: n**2, True),
                                                (lambda n: n**3, True), (lambda n: 1 + n, False),
                                                (lambda n: n + n**2, False)])
def test_mcd_minimises_the_dissipation_only_for_power_law_friction(law, power_law):
    """The block counter-example (7.4)-(7.8): force balance (MCD) is a stationary point of the dissipated power
    ``sum |v| f(|v|)`` exactly when ``f + |v| f' = k f`` (f = 1, |v|^2, |v|^3), not for f = 1 + |v| or |v| + |v|^2.
    The gradient is taken by central differences of the dissipation, independently of the model's equations; an
    asymmetric skid steer (four different wheel speeds) so that the slips differ in size."""
    robot = catalog.load("skid-steer-4")
    rates = np.array([2.0, 7.0, 5.0, 9.0])

    def friction(v, v_body, loads):
        n = np.linalg.norm(v, axis=-1, keepdims=True)
        return -law(n) * v / np.maximum(n, 1e-300)

    sol = mcd(robot, robot.sensed, rates, friction)
    assert sol.converged
    a = robot.constraint_matrix()
    assert robot.velocity_names[3:] == robot.sensed  # q_dot = (twist, rates)

    def dissipation(twist):
        v = np.linalg.norm((a @ np.concatenate([twist, rates])).reshape(-1, 2), axis=1)
        return float(np.sum(v * law(v)))

    h = 1e-6
    grad = np.array([dissipation(sol.twist + h * e) - dissipation(sol.twist - h * e) for e in np.eye(3)]) / (2 * h)
    if power_law:
        assert np.abs(grad).max() < 1e-7
    else:
        assert np.abs(grad).max() > 1e-3
