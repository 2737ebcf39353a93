"""The practical slip ``kappa`` of SAE J670 / ISO 8855 (Pacejka's book, the ``pacejka`` package: ``(r phi_dot - v) /
v``, positive driving) at the tyre door: ``wmrkit tyre --kappa`` and ``slip_ratio_from_kappa``. wmrkit's slip ratio
(7.31) has the slip velocity's sign (positive braking) and divides by the faster of rim and wheel; a user bringing
``--slip-ratio 0.1`` from Pacejka's book got a braking tyre (Fx = -2390 N) where they meant a driving one. Checked
against the slip ratio of the wheel's own velocities (:func:`slip_ratio`, (7.31)) and against the ``pacejka``
package, whose force has its slip's sign, on the braking side where both models take the same argument."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from wmrkit.cli.main import main
from wmrkit.dynamics.tyres import MAX_KAPPA, Tyre, kappa_from_slip_ratio, slip_ratio, slip_ratio_from_kappa
from wmrkit.errors import ShapeError

FZ = 8175.0


@given(v=st.floats(0.01, 100), q=st.floats(-1, 1e6))
def test_kappa_is_the_slip_ratio_of_the_wheels_velocities(v, q):
    """A wheel moving at `v` whose rim turns at ``q v`` (``kappa = q - 1``): its slip velocity ``v - q v`` (the
    rim's ``v_roll = -q v``: forward rolling is negative, ch. 3) gives (7.31)'s slip ratio, which is
    ``slip_ratio_from_kappa``; and back."""
    v_roll = -q * v
    s = slip_ratio(v + v_roll, v, v_roll, eps=0.0)
    np.testing.assert_allclose(slip_ratio_from_kappa(q - 1), s, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(kappa_from_slip_ratio(s), q - 1, rtol=1e-9, atol=1e-12)


@given(s=st.floats(-1, 2, exclude_min=True))
def test_the_velocities_of_any_slip_ratio_give_it_back(s):
    """``slip_velocities`` of a slip ratio near -1 (a wheel spinning far faster than it moves, kappa up to 1e15)
    rebuild that slip ratio: before, it clamped it to -0.999999, so ``--slip-ratio -0.99999999`` printed the forces of
    another slip ratio."""
    from wmrkit.dynamics.tyres import slip_velocities

    _, v_long, v_wheel, v_roll = slip_velocities(s, 0.0, 2.0)
    assert float(slip_ratio(v_long, v_wheel, v_roll)) == pytest.approx(s, rel=1e-12, abs=1e-15)


def test_driving_is_positive_kappa_and_a_forward_force():
    assert slip_ratio_from_kappa([0.25, -0.2, 0.0, -2.0]).tolist() == [-0.2, 0.2, 0.0, 2.0]
    tyre = Tyre.of("pacejka")
    assert float(tyre.forces_at_slip(FZ, slip_ratio_from_kappa(0.1), 0.0).longitudinal) > 0  # driving: pushed ahead
    assert float(tyre.forces_at_slip(FZ, slip_ratio_from_kappa(-0.1), 0.0).longitudinal) < 0
    for bad in (np.nan, np.inf, -2.0001, 1.01 * MAX_KAPPA):
        with pytest.raises(ShapeError, match=r"^kappa: must be a number in"):
            slip_ratio_from_kappa(bad)
    for bad in (np.nan, -1.0, 2.0001):
        with pytest.raises(ShapeError, match=r"^slip ratio: must be in \(-1, 2\]"):
            kappa_from_slip_ratio(bad)


def test_braking_forces_are_the_pacejka_packages_at_the_same_kappa():
    """Braking, (7.31)'s slip ratio is ``-kappa`` and the thesis's magic formula takes it as the package's takes
    ``kappa``: with wmrkit's sign (the ground's force on the wheel) the forces at ``kappa`` are the package's at
    ``kappa``, sign included (the package built from the digest's coefficients at 2 m/s, 4 decimals, as
    tests/dynamics/test_tyres.py)."""
    pacejka = pytest.importorskip("pacejka")
    peer = pacejka.Tire.from_constants("long", 0.7958, b_x=8.9448, c_x=1.57, e_x=0.9334)
    kappa = np.linspace(-0.9, 0.0, 91)
    fx = peer.calculate_forces(FZ, 0.0, kappa, friction_circle=False, alpha_unit="rad")[1]
    ours = Tyre.of("pacejka", {"shifts": 0.0}).forces_at_slip(FZ, slip_ratio_from_kappa(kappa), 0.0, 2.0)
    np.testing.assert_allclose(ours.longitudinal, fx, rtol=0, atol=2e-4 * FZ)  # the digest's 4 decimals
    assert (ours.longitudinal[:-1] < 0).all()  # braking: held back, as the package's negative kappa


def test_the_cli_takes_kappa_or_the_slip_ratio(capsys):
    def answer(*argv):
        assert main(["tyre", "dugoff", "--load", "3000", "--json", *argv]) == 0
        return json.loads(capsys.readouterr().out)

    by_kappa, by_ratio = answer("--kappa", "0.25"), answer("--slip-ratio", "-0.2")
    assert by_kappa == by_ratio and by_kappa["kappa"] == 0.25 and by_kappa["Fx"] > 0
    assert main(["tyre", "dugoff", "--load", "3000", "--kappa", "-3", "--json"]) == 2
    assert json.loads(capsys.readouterr().err)["field"] == "--kappa"
    assert main(["tyre", "dugoff", "--load", "3000", "--kappa", "0.1", "--slip-ratio", "0.1"]) == 2  # one or other
    assert "not allowed with argument" in capsys.readouterr().err
