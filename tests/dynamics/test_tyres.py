"""Traction models (thesis §7.3, appendix 7.A1): symmetry, slopes, peaks, saturation, peers and the spec's tables."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit.dynamics.tyres import (
    TYRES,
    Tyre,
    coulomb,
    delft_combined,
    friction_ellipse,
    lu_lateral,
    lu_longitudinal,
    magic_formula,
    slip_angle,
    slip_ratio,
    slip_velocities,
)
from wmrkit.errors import ShapeError, UnknownNameError

FZ = 8175.0
speeds = st.floats(0.2, 15)
slips = st.floats(-5, 5)


def test_coulomb_smooth_7_28_limit_and_slope():
    v = np.linspace(-2, 2, 41)
    assert np.allclose(coulomb(v, 0.7, 1e9)[v != 0], 0.7 * np.sign(v[v != 0]))
    assert np.array_equal(coulomb(v, 0.7), 0.7 * np.sign(v))
    h = 1e-7
    assert (coulomb(h, 0.7, 30.0) - coulomb(-h, 0.7, 30.0)) / (2 * h) == pytest.approx(0.7 * 2 / math.pi * 30, 1e-6)


@settings(max_examples=300)
@given(st.floats(-3, 3), st.floats(-3, 3), st.floats(0.1, 2), st.floats(0.1, 2))
def test_friction_ellipse_7_30_is_on_the_boundary_and_dissipates(vx, vy, mx, my):
    if math.hypot(vx, vy) < 1e-6:
        return
    m = friction_ellipse(vx, vy, mx, my)
    assert (m.lateral / mx) ** 2 + (m.longitudinal / my) ** 2 == pytest.approx(1.0, abs=1e-9)
    assert m.lateral * vx + m.longitudinal * vy >= 0  # force -Fz mu opposes the slip
    # maximum dissipation: no other point of the ellipse dissipates more
    t = np.linspace(0, 2 * np.pi, 721)
    assert m.lateral * vx + m.longitudinal * vy >= np.max(mx * np.cos(t) * vx + my * np.sin(t) * vy) - 1e-9


def test_slip_ratio_and_angle_inverse():
    s = np.array([-0.9, -0.3, 0.0, 0.2, 1.0, 1.8])
    a = np.array([-1.2, -0.1, 0.0, 0.05, 0.3, 1.4])
    v_lat, v_long, v_wheel, v_roll = slip_velocities(s, a, 2.0)
    assert np.allclose(slip_ratio(v_long, v_wheel, v_roll), s)
    assert np.allclose(slip_angle(v_lat, v_wheel), a)
    # ch. 3 convention: forward rolling has r phi_dot = -v; a driving (faster) wheel has s < 0
    assert slip_ratio(2.0 - 2.2, 2.0, -2.2) < 0
    with pytest.raises(ShapeError, match=r"^slip ratio: must be in \(-1, 2\], got -1$"):
        slip_velocities(-1.0, 0.0, 1.0)


@pytest.mark.parametrize("model", ["linear", "coulomb", "dugoff", "pacejka"])
@settings(max_examples=200, deadline=None)
@given(v_lat=slips, v_long=slips, v_wheel=st.floats(-10, 10))
def test_friction_never_adds_energy(model, v_lat, v_long, v_wheel):
    """Power of the contact force on the slip velocity is <= 0 (pacejka without its shifts, see the docs)."""
    tyre = Tyre.of(model, {"shifts": 0.0} if model == "pacejka" else {})
    f = tyre.forces(FZ, v_lat, v_long, v_wheel, v_long - v_wheel)
    assert f.lateral * v_lat + f.longitudinal * v_long <= 1e-9


@pytest.mark.parametrize("params", [{}, {"eps": 1e-6}, {"eps": 1.0}, {"cs": 1e12, "calpha": 1e3, "mu": 0.1},
                                    {"cs": 0.0}, {"calpha": 0.0}])
def test_dugoff_opposes_each_slip_component_down_to_standstill_and_in_reverse(params):
    """Dense grid: speeds from 1e-9 to 100 m/s (log-uniform, both signs, zeros), rolling and near-rolling wheels,
    the eps band included; each force component opposes its own slip and |F| <= mu Fz."""
    rng = np.random.default_rng(7)
    n = 200_000

    def sample(scale):
        x = np.exp(rng.uniform(math.log(1e-9), math.log(scale), n)) * rng.choice([-1.0, 1.0], n)
        return np.where(rng.random(n) < 0.02, 0.0, x)

    tyre = Tyre.of("dugoff", params)
    for scale in (1e-2, 1.0, 100.0):
        v_lat, v_wheel = sample(scale), sample(scale)
        v_roll = np.where(rng.random(n) < 0.5, -v_wheel * (1 + sample(0.1)), sample(scale))  # near rolling
        fz = rng.uniform(0, 1e5, n)
        f = tyre.forces(fz, v_lat, v_wheel + v_roll, v_wheel, v_roll)
        assert np.all(f.lateral * v_lat <= 0) and np.all(f.longitudinal * (v_wheel + v_roll) <= 0)
        assert np.all(np.hypot(f.lateral, f.longitudinal) <= tyre.as_dict()["mu"] * fz * (1 + 1e-12))


@pytest.mark.parametrize("model", ["linear", "coulomb", "dugoff", "pacejka"])
@settings(max_examples=150, deadline=None)
@given(v_lat=slips, v_long=slips, v_wheel=speeds)
def test_odd_symmetry(model, v_lat, v_long, v_wheel):
    """Reversing the slip reverses the force (pacejka: pure slips, shifts off; its r_By3 = 4.98 is not odd)."""
    tyre = Tyre.of(model, {"shifts": 0.0} if model == "pacejka" else {})
    roll = v_long - v_wheel
    if model == "pacejka":  # odd in the slip ratio and in the slip angle, each alone
        s, a = float(np.tanh(v_long)) * 0.9, float(np.tanh(v_lat)) * 1.4
        for x, y in ((s, 0.0), (0.0, a)):
            f, g = tyre.forces_at_slip(FZ, x, y, v_wheel), tyre.forces_at_slip(FZ, -x, -y, v_wheel)
            assert np.allclose([f.lateral, f.longitudinal], [-g.lateral, -g.longitudinal], atol=1e-6)
        return
    f = tyre.forces(FZ, v_lat, v_long, v_wheel, roll)
    g = tyre.forces(FZ, -v_lat, -v_long, -v_wheel, -roll)
    assert np.allclose([f.lateral, f.longitudinal], [-g.lateral, -g.longitudinal], atol=1e-6)


def test_slopes_at_the_origin():
    h = 1e-7
    dug = Tyre.of("dugoff", {"cs": 9e4, "calpha": 4e4})
    assert -(dug.forces_at_slip(FZ, h, 0).longitudinal - dug.forces_at_slip(FZ, -h, 0).longitudinal) / (2 * h) \
        == pytest.approx(9e4, rel=1e-5)
    assert -(dug.forces_at_slip(FZ, 0, h).lateral - dug.forces_at_slip(FZ, 0, -h).lateral) / (2 * h) \
        == pytest.approx(4e4, rel=1e-5)
    for v in (1.0, 2.0, 9.0):  # (7.82): k9 = c_sy / (k8 k7), so the slope is c_sy; (7.83): c_sx
        c_sy = math.tan(math.pi / 180 * (84.21 + 5.16 * math.exp(-6.094 / (1 + v))))
        c_sx = 0.3 * math.tan(math.pi / 180 * (84.21 + 5.16 * math.exp(-6.094 / (1 + 5 * v))))
        assert (lu_longitudinal(h, v, 0) - lu_longitudinal(-h, v, 0)) / (2 * h) == pytest.approx(c_sy, rel=1e-6)
        assert (lu_lateral(h, v, 0) - lu_lateral(-h, v, 0)) / (2 * h) == pytest.approx(c_sx, rel=1e-6)
    assert (magic_formula(h, 7.0, 1.3, 0.9, 0.2) - magic_formula(-h, 7.0, 1.3, 0.9, 0.2)) / (2 * h) \
        == pytest.approx(7.0 * 1.3 * 0.9, rel=1e-6)


def test_dugoff_linear_region_is_cs_s_over_1_minus_s():
    dug = Tyre.of("dugoff", {"cs": 5e4, "calpha": 3e4, "mu": 0.9})
    s = np.array([0.001, 0.01, 0.03, 0.05])
    lam = 0.9 * FZ * (1 - s) / (2 * 5e4 * s)
    assert np.all(lam >= 1)  # inside the linear region
    assert np.allclose(-dug.forces_at_slip(FZ, s, 0.0).longitudinal, 5e4 * s / (1 - s))


@pytest.mark.parametrize("model,params", [("coulomb", {"k": 1e6}), ("dugoff", {}), ("pacejka", {"shifts": 0.0})])
def test_saturation_at_mu_fz(model, params):
    tyre = Tyre.of(model, params)
    big = tyre.forces(FZ, 0.0, 50.0, 0.0, 50.0).longitudinal
    mu = {"coulomb": 0.8, "dugoff": 0.8}.get(model)
    if mu is None:  # pacejka: the longitudinal curve tends to k7 sin(k8 atan(k9 (1 - k10) s)) -> k7 sin(k8 pi/2)
        s = slip_ratio(50.0, 1e-3, 50.0, 0.01)
        mu = lu_longitudinal(s, 0.0, 0.0)
    assert abs(big) == pytest.approx(mu * FZ, rel=1e-3)
    s = np.linspace(-1.5, 1.5, 3001)
    f = tyre.forces_at_slip(FZ, np.clip(s, -0.99, 2), 0.0, 2.0).longitudinal
    assert np.max(np.abs(f)) <= 1.0 * FZ * 1.0001


@pytest.mark.parametrize("v,peak_y,s_y,peak_x,a_x", [
    (1, 0.7979, 0.620, 1.1083, 0.535), (2, 0.7958, 0.497, 1.0067, 0.406), (5, 0.7895, 0.295, 0.8444, 0.201),
    (9, 0.7811, 0.179, 0.7749, 0.114), (18, 0.7622, 0.0875, 0.7512, 0.0825)])
def test_pacejka_peaks_match_the_spec_table(v, peak_y, s_y, peak_x, a_x):
    """Digest §9.5 (evaluated independently when the spec was written): peak value k7 and where it is."""
    s = np.linspace(0, 1.2, 120001)
    mu = lu_longitudinal(s, v)
    assert mu.max() == pytest.approx(peak_y, abs=1e-4)
    assert mu.max() == pytest.approx(0.8 - 0.0021 * v, abs=1e-9)  # the peak factor k7 is reached
    assert s[mu.argmax()] == pytest.approx(s_y, abs=2e-3)
    mx = lu_lateral(s, v)
    assert mx.max() == pytest.approx(peak_x, abs=1e-4)
    assert s[mx.argmax()] == pytest.approx(a_x, abs=2e-3)


@pytest.mark.parametrize("s,a,mu_long,mu_lat", [
    (0.05, 0, 0.48878, 0.00825), (0, 0.05, 0.03827, 0.31487), (0.05, 0.05, 0.48640, 0.22417),
    (0.1, 0.2, 0.63438, 0.54704), (-0.1, -0.2, -0.62394, -0.54139)])
def test_pacejka_combined_matches_the_spec_table(s, a, mu_long, mu_lat):
    c = delft_combined(s, a, lu_longitudinal(s, 2.0), lu_lateral(a, 2.0))
    assert c.longitudinal == pytest.approx(mu_long, abs=2e-5)
    assert c.lateral == pytest.approx(mu_lat, abs=2e-5)


def test_combined_weights_are_one_without_cross_slip():
    s = np.linspace(-0.5, 0.5, 11)
    c = delft_combined(s, 0.0, lu_longitudinal(s, 3.0, 0), 0.0, shifts=0.0)
    assert np.allclose(c.longitudinal, lu_longitudinal(s, 3.0, 0))


def test_reverse_motion_is_mirrored():
    t = Tyre.of("pacejka")
    fwd = t.forces(FZ, 0.01, 0.02, 2.0, 0.02 - 2.0)
    rev = t.forces(FZ, -0.01, -0.02, -2.0, -0.02 + 2.0)
    assert np.allclose([fwd.lateral, fwd.longitudinal], [-rev.lateral, -rev.longitudinal])
    # rolling resistance from the shift: a free-rolling wheel (no slip) is braked in both directions
    assert t.forces(FZ, 0, 0, 2.0, -2.0).longitudinal < 0 < t.forces(FZ, 0, 0, -2.0, 2.0).longitudinal


@pytest.mark.parametrize(("v", "k9y", "k7y", "k10y", "k9x", "k7x", "k10x"), [
    (1, 8.2229, 0.7979, 0.9517, 3.2909, 1.1083, -2.7581), (2, 8.9448, 0.7958, 0.9334, 5.0329, 1.0067, -1.7942),
    (5, 11.7698, 0.7895, 0.8808, 9.9275, 0.8444, -1.8970), (9, 15.6399, 0.7811, 0.8044, 14.5500, 0.7749, -3.1124),
    (18, 23.3937, 0.7622, 0.6044, 19.7725, 0.7512, -3.1249)])
def test_pacejka_tyre_is_the_pacejka_package_at_the_spec_coefficients(v, k9y, k7y, k10y, k9x, k7x, k10x):
    """The whole pacejka tyre (Tyre.forces_at_slip, shifts off, pure slips) against the pacejka package built from
    the digest's coefficients at each speed (§9.5, 4 decimals; k8 = 1.57 and 1.2 from (7.82)-(7.83)): every
    point of both curves, the peak, the fall beyond it (k10) and the sign. The package's force has its slip's sign;
    wmrkit's is the ground's force on the wheel, against the slip (docs/conventions.md): F = -package(s)."""
    pacejka = pytest.importorskip("pacejka")
    tyre = Tyre.of("pacejka", {"shifts": 0.0})
    s = np.linspace(-0.9, 0.9, 181)
    alpha = np.linspace(-1.5, 1.5, 181)  # radians, within (-pi/2, pi/2)
    long_peer = pacejka.Tire.from_constants("long", k7y, b_x=k9y, c_x=1.57, e_x=k10y)
    lat_peer = pacejka.Tire.from_constants("lat", k7x, b_x=1.0, c_x=1.0, e_x=0.0, b_y=k9x, c_y=1.2, e_y=k10x)
    fx = long_peer.calculate_forces(FZ, 0.0, s, friction_circle=False, alpha_unit="rad")[1]
    fy = lat_peer.calculate_forces(FZ, alpha, 0.0, friction_circle=False, alpha_unit="rad")[0]
    ours_long = tyre.forces_at_slip(FZ, s, 0.0, float(v)).longitudinal
    ours_lat = tyre.forces_at_slip(FZ, 0.0, alpha, float(v)).lateral
    np.testing.assert_allclose(ours_long, -fx, rtol=0, atol=2e-4 * FZ)  # the table's 4 decimals
    np.testing.assert_allclose(ours_lat, -fy, rtol=0, atol=2e-4 * FZ)
    assert ours_long[-1] < 0 < ours_long[0] and ours_lat[-1] < 0 < ours_lat[0]


def test_magic_formula_agrees_with_the_pacejka_package():
    pacejka = pytest.importorskip("pacejka")
    b, c, e, mu = 11.0, 1.5, 0.3, 0.9
    tire = pacejka.Tire.from_constants("t", mu, b_x=b, c_x=c, e_x=e, b_y=0.6 * b, c_y=1.3, e_y=-0.2)
    x = np.linspace(-0.6, 0.6, 49)
    fy, fx = tire.calculate_forces(FZ, x, x, friction_circle=False, alpha_unit="rad")
    assert np.allclose(fx, magic_formula(x, b, c, mu * FZ, e), rtol=1e-12, atol=1e-9)
    assert np.allclose(fy, magic_formula(x, 0.6 * b, 1.3, mu * FZ, -0.2), rtol=1e-12, atol=1e-9)


def test_tyre_values_and_errors():
    assert set(TYRES) == {"linear", "coulomb", "dugoff", "pacejka"}
    t = Tyre.of("dugoff", {"mu": 0.5})
    assert t.as_dict()["mu"] == 0.5 and t.as_dict()["cs"] == TYRES["dugoff"].defaults["cs"]
    assert hash(t) == hash(Tyre.of("dugoff", {"mu": 0.5})) and t == Tyre.of("dugoff", {"mu": 0.5})
    with pytest.raises(UnknownNameError, match="no parameter 'cz'"):
        Tyre.of("dugoff", {"cz": 1})
    with pytest.raises(UnknownNameError, match="unknown tyre model"):
        Tyre.of("michelin")


def test_the_constructor_is_of_with_the_defaults_and_the_checks():
    """``Tyre("dugoff")``, the dataclass's own constructor, made a tyre with every parameter 0 (``params=()``): no
    force at any slip (``Tyre()`` too: 0 N where pacejka gives 486 N), and ``simulate`` with it stopped on a
    ZeroDivisionError. It now completes the model's defaults and checks the values as :meth:`Tyre.of` does."""
    for model in TYRES:
        assert Tyre(model) == Tyre.of(model)
    assert Tyre() == Tyre.of("pacejka")
    assert Tyre("dugoff", (("mu", 0.5),)) == Tyre.of("dugoff", {"mu": 0.5})
    assert Tyre("dugoff", {"mu": 0.5}).params == Tyre.of("dugoff", {"mu": 0.5}).params
    f = Tyre("pacejka").forces(1000, 0.1, 0.1, 2.0, -1.9)
    assert f == Tyre.of("pacejka").forces(1000, 0.1, 0.1, 2.0, -1.9) and f.longitudinal < -400
    for params, message in (((("cs", -1.0),), "tyre parameter cs: must be >= 0"),
                            ((("mu", math.nan),), "tyre parameter mu must be a finite number, got nan"),
                            ((("mu", 0.5), ("mu", 0.6)), "parameter 'mu' given twice")):
        with pytest.raises(ShapeError, match=message):  # a ValueError naming the parameter, as keyword doors raise
            Tyre("dugoff", params)
    with pytest.raises(UnknownNameError, match="no parameter 'cz'"):
        Tyre("dugoff", (("cz", 1.0),))
    with pytest.raises(UnknownNameError, match="unknown tyre model"):
        Tyre("michelin")


@pytest.mark.parametrize("value", [-1.0, -1e-300, 0.0, -0.0])
@pytest.mark.parametrize(("model", "name"), [("coulomb", "mu_lat"), ("coulomb", "mu_long"), ("dugoff", "mu"),
                                             ("dugoff", "eps"), ("pacejka", "mu_scale")])
def test_a_parameter_that_must_be_positive_says_so_of_a_negative_value(model, name, value):
    """'mu_lat=-1' was refused as 'must be >= 0', which 0 is, and 0 is refused too ('must be > 0'): the bound given
    is the one the parameter has, whatever the value's sign. Each of these parameters refuses 0 and accepts 1e-3."""
    Tyre.of(model, {name: 1e-3})
    with pytest.raises(ShapeError, match=rf"^tyre parameter {name}: must be > 0, got "):
        Tyre.of(model, {name: value})


def test_arguments_that_do_not_broadcast_are_named():
    """numpy's 'shape mismatch: objects cannot be broadcast to a single shape' named no argument."""
    from wmrkit.errors import ShapeError

    tyre = Tyre.of("dugoff")
    with pytest.raises(ShapeError, match=r"not broadcast together: slip_ratio \(2,\), slip_angle \(3,\), speed \(\)"):
        tyre.forces_at_slip(FZ, [0.1, 0.2], [0.1, 0.2, 0.3], 2.0)
    with pytest.raises(ShapeError, match=r"fz \(2,\), v_lat \(3,\), v_long \(\)"):
        tyre.forces([FZ, FZ], [0.0, 0.1, 0.2], 0.0, 2.0, -2.0)
    assert tyre.forces_at_slip(np.full((2, 1), FZ), [0.1, 0.2, 0.3], 0.0).longitudinal.shape == (2, 3)


def test_errata_7_31_slip_ratio_follows_the_slip_velocity():
    """(7.31) writes s = (phi_dot r - v) / max(...) but calls the numerator v_slip, which ch. 3 defines as
    v + r phi_dot (forward rolling has r phi_dot = -v). wmrkit: s = v_slip / max(|r phi_dot|, |v|), so the force
    -Fz mu(s) opposes the slip: a driving wheel (spinning faster) has s < 0 and is pushed forward (+)."""
    v, roll = 2.0, -2.2  # wheel centre forward at 2 m/s, contact point turning backwards faster (driving)
    assert slip_ratio(v + roll, v, roll) == pytest.approx(-0.2 / 2.2)
    f = Tyre.of("pacejka", {"shifts": 0.0}).forces(FZ, 0.0, v + roll, v, roll)
    assert f.longitudinal > 0  # along +E_y, the rolling direction of the ch. 3 frame: traction
    literal = (-roll - v) / max(abs(roll), abs(v))  # (7.31) with phi_dot r = -roll (ch. 3 sign)
    assert literal == pytest.approx(-slip_ratio(v + roll, v, roll))  # the opposite sign


def test_pacejka_shifts_fade_out_at_standstill():
    t = Tyre.of("pacejka")
    assert t.forces(FZ, 0.0, 0.0, 0.0, 0.0) == (0.0, 0.0)
    moving = t.forces(FZ, 0.0, 0.0, 2.0, -2.0)
    assert moving.longitudinal < -100 and moving.lateral < -10  # rolling resistance and lateral bias at 2 m/s


def test_forces_at_slip_refuses_a_speed_below_the_regularisation_speed(capsys):
    """`wmrkit tyre dugoff --slip-ratio 0.01 --speed 0.001` printed slip ratio 0.01 with the force of s = 0.001
    (80 N instead of 808: below eps = 0.01 m/s the model divides the slip by eps); now it is refused."""
    from wmrkit.cli.main import main

    dugoff = Tyre.of("dugoff", {"mu": 100.0})
    assert -dugoff.forces_at_slip(1000.0, 0.01, 0.0, 0.01).longitudinal == pytest.approx(80000 * 0.01 / 0.99)
    for tyre in (dugoff, Tyre.of("pacejka")):
        with pytest.raises(ShapeError, match=r"speed: must be at least the .* tyre's eps = 0.01 m/s, got 0.001"):
            tyre.forces_at_slip(1000.0, 0.01, 0.0, [2.0, 0.001])
    assert main(["tyre", "dugoff", "--load", "1000", "--slip-ratio", "0.01", "--speed", "0.001"]) == 2
    assert capsys.readouterr().err.startswith("wmrkit: error: --speed: must be at least the dugoff tyre's eps")


def test_the_jacobian_triple_is_three_tyre_calls_bit_for_bit():
    """contact_forces' forward differences share Pacejka's speed terms (the wheel speed does not change): the
    three forces are those of three separate calls of each model's kernel, to the last bit."""
    from wmrkit.dynamics import _kernels

    rng = np.random.default_rng(7)
    for kind in TYRES.values():
        p = Tyre(kind.name).vector()
        for fz, vl, vg, vw in rng.normal(0.0, 1.0, (50, 4)) * (5e3, 0.3, 0.3, 3.0) + (8e3, 0, 0, 0):
            h = 1e-7 * (1.0 + abs(vl) + abs(vg))
            got = _kernels.tyre_and_jacobian(kind.code, p, fz, vl, vg, vw, h)
            want = (_kernels.tyre(kind.code, p, fz, vl, vg, vw, vg - vw),
                    _kernels.tyre(kind.code, p, fz, vl + h, vg, vw, vg - vw),
                    _kernels.tyre(kind.code, p, fz, vl, vg + h, vw, vg + h - vw))
            assert got == want, kind.name


def _appendix_7a1(shifts, mu_scale, eps, fz, v_lat, v_long, v_wheel, v_roll):
    """(F_lat, F_long) of one contact, transcribed from the digest of appendix 7.A1 (spec ch. 7, section 9:
    (7.81)-(7.84)) with the sign decision [A] of its section 10 and the library's documented additions: slips
    regularised by eps, the shifts faded by tanh(|v| / eps) at standstill, mirrored in reverse (section 10.1)."""
    v = abs(v_wheel)
    f = shifts * math.tanh(v / eps)
    sigma = -1.0 if v_wheel < 0 else 1.0
    s = sigma * v_long / max(abs(v_roll), v, eps)
    alpha = sigma * math.atan(v_lat / max(v, eps))

    def magic(a, k7, k8, k9, k10):  # (7.81)
        return k7 * math.sin(k8 * math.atan(k9 * (1 - k10) * a + k10 * math.atan(k9 * a)))

    c_sy = math.tan(math.pi / 180 * (84.21 + 5.16 * math.exp(-6.094 / (1 + v))))  # (7.82)
    k7y, k8y = 0.8 - 0.0021 * v, 1.57
    k9y = c_sy / (k8y * k7y)
    s_m = 0.08 + 0.75 * math.exp(-v / 8)
    k10y = (k9y * s_m - math.tan(0.5 * math.pi / k8y)) / (k9y * s_m - math.atan(k9y * s_m)) - 0.0162 * v
    mu_y = magic(s + f * (0.0213 + 0.0086 * v) / c_sy, k7y, k8y, k9y, k10y)
    c_sx = 0.3 * math.tan(math.pi / 180 * (84.21 + 5.16 * math.exp(-6.094 / (1 + 5 * v))))  # (7.83)
    k7x, k8x = 0.75 + 0.5 * math.exp(-v / 3), 1.2
    k9x = c_sx / (k8x * k7x)
    a_m = 0.087 + 0.63 * math.exp(-v / 3)
    k10x = (k9x * a_m - math.tan(0.5 * math.pi / k8x)) / (k9x * a_m - math.atan(k9x * a_m)) - 0.0162 * v
    mu_x = magic(alpha + f * (0.00639 + 0.0026 * v) / c_sx, k7x, k8x, k9x, k10x)
    b_y = 1.25 * math.cos(math.atan(0.513 * s))  # (7.84)
    mu_y_comb = (mu_y * math.cos(1.43 * math.atan(b_y * (f * 0.0056 + alpha)))
                 / math.cos(1.43 * math.atan(b_y * f * 0.0056)))
    b_x = 20.18 * math.cos(math.atan(0.137 * (alpha - 4.98)))
    mu_x_comb = (mu_x * math.cos(1.01 * math.atan(b_x * (f * 0.204 * mu_y + s)))
                 / math.cos(1.01 * math.atan(b_x * f * 0.204 * mu_y)))
    return -sigma * mu_scale * fz * mu_x_comb, -sigma * mu_scale * fz * mu_y_comb


@settings(max_examples=400)
@given(st.sampled_from([0.0, 1.0]), st.floats(0.1, 2.0), st.floats(1e-3, 1.0), st.floats(0.0, 1e5),
       slips, slips, st.one_of(st.floats(-20, 20), st.floats(-0.05, 0.05)), st.floats(-20, 20))
def test_pacejka_forces_are_appendix_7a1_transcribed(shifts, mu_scale, eps, fz, v_lat, v_long, v_wheel, v_roll):
    """The Pacejka tyre (numpy, and compiled for the simulator, with its shared speed terms) at random slips, wheel
    speeds (reverse and standstill included), loads and parameters equals (7.82)-(7.84) written here from the
    digest, scalar, with no code of the library."""
    from wmrkit.dynamics import _kernels

    want = _appendix_7a1(shifts, mu_scale, eps, fz, v_lat, v_long, v_wheel, v_roll)
    tyre = Tyre.of("pacejka", {"shifts": shifts, "mu_scale": mu_scale, "eps": eps})
    got = tyre.forces(fz, v_lat, v_long, v_wheel, v_roll)
    compiled = _kernels.tyre(3, tyre.vector(), fz, v_lat, v_long, v_wheel, v_roll)
    for forces in ((float(got.lateral), float(got.longitudinal)), compiled):
        assert forces == pytest.approx(want, rel=1e-9, abs=1e-9 * fz)


velocities = st.floats(-1e3, 1e3) | st.floats(-1e-3, 1e-3)


@settings(max_examples=300, deadline=None)
@given(model=st.sampled_from(["coulomb", "dugoff", "pacejka"]), fz=st.floats(0.0, 1e5), v_lat=velocities,
       v_long=velocities, v_wheel=velocities, mu=st.floats(0.05, 2.0))
def test_no_force_exceeds_the_tyre_s_grip(model, fz, v_lat, v_long, v_wheel, mu):
    """The semi-implicit step re-linearises a force beyond ``Tyre.grip`` (docs/dynamics.md), so the grip must bound
    every force the model gives, component by component, from standstill to sliding."""
    params = {"coulomb": {"mu_lat": mu, "mu_long": 0.8}, "dugoff": {"mu": mu}, "pacejka": {"mu_scale": mu}}[model]
    tyre = Tyre.of(model, params)
    forces, grip = tyre.forces(fz, v_lat, v_long, v_wheel, v_long - v_wheel), tyre.grip(fz)
    assert abs(forces.lateral) <= grip.lateral * (1 + 1e-12) + 1e-9
    assert abs(forces.longitudinal) <= grip.longitudinal * (1 + 1e-12) + 1e-9


def test_the_grip_is_mu_fz_and_reached_and_the_linear_tyre_has_none():
    assert tuple(Tyre.of("dugoff", {"mu": 0.6}).grip(100.0)) == (60.0, 60.0)
    assert tuple(Tyre.of("coulomb", {"mu_lat": 0.5, "mu_long": 0.9}).grip(100.0)) == (50.0, 90.0)
    assert np.isinf(Tyre.of("linear").grip([1.0, 2.0])).all()
    sliding = Tyre.of("dugoff", {"mu": 0.6}).forces(100.0, 0.0, -50.0, 0.01, -50.01)  # full slip: the grip reached
    assert abs(sliding.longitudinal) == pytest.approx(60.0, rel=1e-3)
    pacejka = Tyre.of("pacejka")  # its lateral peak 1.25 at standstill is reached at a slow wheel's slip angle
    lateral = pacejka.forces(100.0, np.linspace(0, 1, 2001) * 0.02, 0.0, 0.001, -0.001).lateral
    assert np.abs(lateral).max() == pytest.approx(pacejka.grip(100.0).lateral, rel=0.01)


@pytest.mark.parametrize(("call", "message"), [
    # text was read as a number: Tyre.of("dugoff", {"mu": "0.8"}) gave mu = 0.8, forces_at_slip("1000", ...) 1000 N
    (lambda: Tyre.of("dugoff", {"mu": "0.8"}), r"tyre parameter mu must be a finite number, got '0.8'"),
    (lambda: Tyre.of("dugoff", {"mu": True}), "tyre parameter mu must be a finite number, got True"),
    # a string raised dict()'s "dictionary update sequence element #0 has length 1; 2 is required"
    (lambda: Tyre.of("dugoff", "mu"), r"tyre parameters: expected a mapping \{name: value\}"),
    (lambda: Tyre.of("dugoff").forces_at_slip("1000", 0.1, 0.0), "fz: got the text '1000', but the Python API reads"),
    (lambda: Tyre.of("dugoff").forces_at_slip(1000.0, 0.1, "10 deg"), "slip_angle: got the text '10 deg'"),
    (lambda: Tyre.of("dugoff").forces(1000.0, "0", 0.0, 1.0, -1.0), "v_lat: got the text '0'"),
    (lambda: Tyre.of("dugoff").grip("1 kN"), "fz: got the text '1 kN'"),
    # out of range: a ShapeError too, as every keyword door's (a bare WmrkitError escaped `except ValueError`)
    (lambda: Tyre.of("dugoff").forces(-1.0, 0.0, 0.0, 1.0, -1.0), r"^fz: expected normal loads in \[0, 1e\+07\] N"),
    (lambda: Tyre.of("dugoff").forces(1.0, 0.0, np.inf, 1.0, -1.0), "^v_long: expected finite velocities"),
    (lambda: Tyre.of("dugoff").forces_at_slip(1.0, 0.0, 2.0), r"^slip angle: must be in \(-pi/2, pi/2\) rad"),
    (lambda: slip_velocities(0.0, 0.0, 0.0), r"^speed: must be in \(0, "),
])
def test_tyre_doors_refuse_text_and_booleans_by_name(call, message):
    with pytest.raises(ShapeError, match=message):
        call()


def test_tyre_parameters_as_pairs_or_a_mapping_of_real_numbers():
    """What the refusals above leave: a mapping or pairs, NumPy numbers, the discontinuous Coulomb's k = inf."""
    assert Tyre.of("dugoff", {"mu": np.float32(0.5)}) == Tyre.of("dugoff", [("mu", 0.5)]) == Tyre("dugoff", {"mu": 0.5})
    assert Tyre("coulomb", (("k", math.inf),)).as_dict()["k"] == math.inf
