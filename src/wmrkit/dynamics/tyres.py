"""Traction (tyre-ground friction) models of thesis §7.3 and appendix 7.A1, vectorised, radians only.

Every formula is written once, with numpy ufuncs and no branches, so that the same function serves numpy arrays
(the public API) and is compiled as it is by numba for the simulator (:mod:`wmrkit.dynamics._kernels`).

Axes and signs (``docs/dynamics.md``). A contact's slip velocity ``v_slip = (lateral, longitudinal)`` is the one of
:meth:`wmrkit.Robot.constraint_matrix` (frame Ē: row 0 along the axle / roller axis, row 1 the rolling
direction). Slip ratio and slip angle follow the slip velocity (positive when the contact point slides forward /
to the axle's +x side), which resolves the sign conflict of (7.31) with the ch. 3 convention
(``docs/errata.md``). Friction coefficients ``mu`` are odd functions of the slip with the slip's sign; the force of
the ground on the wheel is ``F = -Fz * mu``: it always opposes the slip (7.27), (7.49).

A tyre *model* is a :class:`TyreKind` of the table :data:`TYRES` (like ``wheels.KINDS``): its parameters with
defaults and units, and one kernel ``forces(p0, p1, p2, p3, fz, v_lat, v_long, v_wheel, v_roll)`` returning
``(F_lat, F_long)`` [N]. A wheel's tyre is a frozen :class:`Tyre` value (model name + parameters).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_reals, real_number
from ..errors import ShapeError, UnknownNameError
from ..limits import MAX_SPEED

TINY = 1e-300


class TyreForces(NamedTuple):
    """Force of the ground on the wheel at the contact, frame Ē [N]: along the axle and along the rolling line."""

    lateral: np.ndarray
    longitudinal: np.ndarray


def _asarray(x: ArrayLike) -> np.ndarray:
    """``np.asarray(x, float)``; the compiled kernels replace it by the identity (:mod:`._kernels`)."""
    return np.asarray(x, dtype=float)


# ---- elementary laws ------------------------------------------------------------------------------------------
def coulomb(v: ArrayLike, mu: ArrayLike, k: ArrayLike = math.inf) -> np.ndarray:
    """Coulomb friction coefficient with the slip's sign, smoothed as in (7.28): ``mu (2/pi) atan(k v)``.

    `k` [s/m] sets the sharpness; ``k = inf`` is the discontinuous Coulomb law ``mu sign(v)``. ``(...) -> (...)``.
    """
    v, k = np.asarray(v, dtype=float), np.asarray(k, dtype=float)
    smooth = mu * (2 / np.pi) * np.arctan(np.where(np.isinf(k), 0.0, k) * v)
    return np.where(np.isinf(k), mu * np.sign(v), smooth)


def friction_ellipse(v_lat: ArrayLike, v_long: ArrayLike, mu_lat: ArrayLike, mu_long: ArrayLike) -> TyreForces:
    """Coupled anisotropic Coulomb coefficients of maximum dissipation (7.30), on the ellipse (7.29).

    ``mu* = (mu_lat^2 v_lat, mu_long^2 v_long) / |(mu_lat v_lat, mu_long v_long)|`` (with the slip's sign; zero
    at zero slip). Returned as coefficients (multiply by ``-Fz`` for the force). ``(...) -> (...), (...)``.
    """
    v_lat, v_long = _asarray(v_lat), _asarray(v_long)
    w = np.maximum(np.sqrt((mu_lat * v_lat) ** 2 + (mu_long * v_long) ** 2), TINY)
    return TyreForces(mu_lat ** 2 * v_lat / w, mu_long ** 2 * v_long / w)


def slip_ratio(v_slip: ArrayLike, v_wheel: ArrayLike, v_roll: ArrayLike, eps: ArrayLike = 1e-3) -> np.ndarray:
    """Longitudinal slip ratio (7.31), sign-corrected: ``s = v_slip / max(|v_roll|, |v_wheel|, eps)``.

    `v_slip` is the longitudinal slip velocity (ch. 3: ``v_wheel + v_roll``, with ``v_roll = r phi_dot``),
    `v_wheel` the wheel centre's speed along its rolling line; `eps` [m/s] regularises the standstill. A
    driving wheel has ``s < 0`` (its contact slides backwards), a braking one ``s > 0``; ``|s| <= 2``.
    """
    return v_slip / np.maximum(np.maximum(np.abs(v_roll), np.abs(v_wheel)), eps)


#: The largest practical slip ``kappa`` :func:`slip_ratio_from_kappa` takes (the rim 1e15 times faster than the wheel
#: moves): beyond about 1e16 its slip ratio rounds to -1, outside (7.31)'s range.
MAX_KAPPA = 1e15


def slip_ratio_from_kappa(kappa: ArrayLike) -> np.ndarray:
    """wmrkit's slip ratio (7.31) of the practical longitudinal slip ``kappa = (r phi_dot - v) / v`` of SAE J670 and
    ISO 8855 (Pacejka's book, the ``pacejka`` package: positive driving), ``v`` the wheel centre's speed:
    ``-kappa / (1 + kappa)`` driving (the rim is the faster), ``-kappa`` braking. ``kappa`` at least -2 (the rim
    turning backwards as fast as the wheel moves: s = 2), at most :data:`MAX_KAPPA`. ``(...) -> (...)``."""
    k = _asarray(kappa)
    ok = np.isfinite(k) & (k >= -2) & (k <= MAX_KAPPA)
    if not np.all(ok):
        raise ShapeError(f"kappa: must be a number in [-2, {MAX_KAPPA:g}], got {k[~ok].flat[0]:g}")
    return np.where(k > 0, -k / (1 + np.maximum(k, 0.0)), -k) + 0.0


def kappa_from_slip_ratio(s: ArrayLike) -> np.ndarray:
    """The practical slip ``kappa`` (SAE, ISO: positive driving) of wmrkit's slip ratio `s` in (-1, 2]: the inverse
    of :func:`slip_ratio_from_kappa`, ``-s / (1 + s)`` driving (``s < 0``), ``-s`` braking. ``(...) -> (...)``."""
    s = _asarray(s)
    if not np.all((s > -1) & (s <= 2)):
        raise ShapeError(f"slip ratio: must be in (-1, 2], got {s[~((s > -1) & (s <= 2))].flat[0]:g}")
    return np.where(s < 0, -s / (1 + np.minimum(s, 0.0)), -s) + 0.0


def slip_angle(v_lat: ArrayLike, v_wheel: ArrayLike, eps: ArrayLike = 1e-3) -> np.ndarray:
    """Slip angle (7.35) [rad] with the lateral slip's sign: ``atan(v_lat / max(|v_wheel|, eps))``."""
    return np.arctan2(v_lat, np.maximum(np.abs(v_wheel), eps))


def magic_formula(x: ArrayLike, b: ArrayLike, c: ArrayLike, d: ArrayLike, e: ArrayLike) -> np.ndarray:
    """Pacejka's magic formula (7.34)/(7.81): ``D sin(C atan(B (1 - E) x + E atan(B x)))``.

    Thesis names: k7 = D (peak), k8 = C (shape), k9 = B (stiffness), k10 = E (curvature); slope at 0 is B C D.
    """
    bx = b * _asarray(x)
    return d * np.sin(c * np.arctan(bx * (1 - e) + e * np.arctan(bx)))


def lu_longitudinal_coefficients(v: ArrayLike, shifts: ArrayLike = 1.0) -> tuple:
    """The speed-dependent terms of (7.82) at wheel speed `v` [m/s]: ``(shift, B, C, D, E)``, mu_y = magic formula
    at ``s + shift``. They depend on the speed alone (the simulator's tyre Jacobian shares them)."""
    v = np.abs(v)
    c_sy = np.tan(np.pi / 180 * (84.21 + 5.16 * np.exp(-6.094 / (1 + v))))
    shift = shifts * (0.0213 + 0.0086 * v) / c_sy
    k8, k7 = 1.57, 0.8 - 0.0021 * v
    k9 = c_sy / (k8 * k7)
    s_m = 0.08 + 0.75 * np.exp(-v / 8)
    k10 = (k9 * s_m - np.tan(0.5 * np.pi / k8)) / (k9 * s_m - np.arctan(k9 * s_m)) - 0.0162 * v
    return shift, k9, k8, k7, k10


def lu_lateral_coefficients(v: ArrayLike, shifts: ArrayLike = 1.0) -> tuple:
    """The speed-dependent terms of (7.83) at wheel speed `v` [m/s]: ``(shift, B, C, D, E)`` (as
    :func:`lu_longitudinal_coefficients`)."""
    v = np.abs(v)
    c_sx = 0.3 * np.tan(np.pi / 180 * (84.21 + 5.16 * np.exp(-6.094 / (1 + 5 * v))))
    shift = shifts * (0.00639 + 0.0026 * v) / c_sx
    k8, k7 = 1.2, 0.75 + 0.5 * np.exp(-v / 3)
    k9 = c_sx / (k8 * k7)
    a_m = 0.087 + 0.63 * np.exp(-v / 3)
    k10 = (k9 * a_m - np.tan(0.5 * np.pi / k8)) / (k9 * a_m - np.arctan(k9 * a_m)) - 0.0162 * v
    return shift, k9, k8, k7, k10


def lu_longitudinal(s: ArrayLike, v: ArrayLike, shifts: ArrayLike = 1.0) -> np.ndarray:
    """Longitudinal coefficient mu_y(s, v) of appendix 7.A1, eq. (7.82) [Lu & Shih 05]; v = wheel speed [m/s].

    ``shifts = 0`` drops the horizontal shift (then mu_y(0) = 0 and the curve is odd).
    """
    shift, k9, k8, k7, k10 = lu_longitudinal_coefficients(v, shifts)
    return magic_formula(s + shift, k9, k8, k7, k10)


def lu_lateral(alpha: ArrayLike, v: ArrayLike, shifts: ArrayLike = 1.0) -> np.ndarray:
    """Lateral coefficient mu_x(alpha, v) of appendix 7.A1, eq. (7.83); alpha in radians, v [m/s]."""
    shift, k9, k8, k7, k10 = lu_lateral_coefficients(v, shifts)
    return magic_formula(alpha + shift, k9, k8, k7, k10)


def delft_combined(s: ArrayLike, alpha: ArrayLike, mu_long: ArrayLike, mu_lat: ArrayLike,
                   shifts: ArrayLike = 1.0) -> TyreForces:
    """Combined-slip weighting (7.84) (Delft-Tyre 97) of the pure coefficients: ``(mu_lat comb, mu_long comb)``.

    Literal transcription of the thesis (constants 1.43, 1.25, 0.513, 0.0056; 1.01, 20.18, 0.137, 4.98, 0.204);
    ``shifts = 0`` drops the horizontal shifts 0.0056 and 0.204 mu_y. Each weight is 1 when the other slip is 0.
    """
    sh_y, sh_x = shifts * 0.0056, shifts * 0.204 * mu_long
    by = 1.25 / np.sqrt(1 + (0.513 * s) ** 2)  # 1.25 cos(atan(0.513 s))
    g_long = np.cos(1.43 * np.arctan(by * (sh_y + alpha))) / np.cos(1.43 * np.arctan(by * sh_y))
    bx = 20.18 / np.sqrt(1 + (0.137 * (alpha - 4.98)) ** 2)  # 20.18 cos(atan(0.137 (alpha - 4.98)))
    g_lat = np.cos(1.01 * np.arctan(bx * (sh_x + s))) / np.cos(1.01 * np.arctan(bx * sh_x))
    return TyreForces(mu_lat * g_lat, mu_long * g_long)


# ---- the tyre models: one kernel each, (F_lat, F_long) from slip velocities ------------------------------------
def linear_forces(c_lat, c_long, _p2, _p3, fz, v_lat, v_long, v_wheel, v_roll):
    """Linear uncoupled friction (7.59): ``F = -(c_lat v_lat, c_long v_long)``, c in N s/m (load absorbed)."""
    return -c_lat * v_lat + 0 * fz, -c_long * v_long + 0 * fz


def coulomb_forces(mu_lat, mu_long, k, _p3, fz, v_lat, v_long, v_wheel, v_roll):
    """Coupled Coulomb friction: direction of maximum dissipation (7.30), magnitude smoothed by (7.28)."""
    w = np.maximum(np.sqrt((mu_lat * v_lat) ** 2 + (mu_long * v_long) ** 2), TINY)
    scale = -fz * (2 / np.pi) * np.arctan(k * np.maximum(np.sqrt(v_lat ** 2 + v_long ** 2), TINY)) / w
    return scale * mu_lat ** 2 * v_lat, scale * mu_long ** 2 * v_long


def dugoff_forces(cs, calpha, mu, eps, fz, v_lat, v_long, v_wheel, v_roll):
    """Dugoff's tyre [Dugoff 70]: stiffnesses cs [N], calpha [N/rad], friction mu; linear region Cs s/(1-s).

    ``lambda = mu Fz (1-|s|) / (2 sqrt((cs s)^2 + (calpha tan a)^2))``, ``f = lambda (2 - lambda)`` below 1;
    ``F_long = -cs s f/(1-|s|)``, ``F_lat = -calpha tan(a) f/(1-|s|)``, |s| clipped at 1 (full sliding).
    """
    s = np.minimum(np.maximum(slip_ratio(v_long, v_wheel, v_roll, eps), -1.0), 1.0)
    tan_a = v_lat / np.maximum(np.abs(v_wheel), eps)
    n = np.maximum(np.sqrt((cs * s) ** 2 + (calpha * tan_a) ** 2), TINY)
    one_minus = 1.0 - np.abs(s)
    lam = mu * np.maximum(fz, 0.0) * one_minus / (2 * n)
    # f / (1 - |s|) without dividing by zero: min(1/(1-|s|), mu Fz (2 - min(lambda, 1)) / (2 n)).
    g = np.minimum(1.0 / np.maximum(one_minus, TINY), mu * np.maximum(fz, 0.0) * (2 - np.minimum(lam, 1.0)) / (2 * n))
    return -calpha * tan_a * g, -cs * s * g


def pacejka_forces(shifts, mu_scale, eps, _p3, fz, v_lat, v_long, v_wheel, v_roll):
    """Thesis appendix 7.A1: (7.82), (7.83) at the wheel speed, weighted by (7.84); mirrored in reverse (§10.1).

    The horizontal shifts (rolling resistance, a lateral bias) are scaled by ``tanh(|v_wheel| / eps)`` so that a
    wheel at rest feels no force without slip (the thesis does not treat standstill).
    """
    return pacejka_at_speed(pacejka_speed_terms(shifts, eps, v_wheel), mu_scale, eps, fz, v_lat, v_long, v_wheel,
                            v_roll)


def pacejka_speed_terms(shifts, eps, v_wheel):
    """The terms of :func:`pacejka_forces` that depend on the wheel speed alone: ``(shifts faded, (7.82)'s,
    (7.83)'s)`` (:func:`lu_longitudinal_coefficients`, :func:`lu_lateral_coefficients`)."""
    shifts = shifts * np.tanh(np.abs(v_wheel) / eps)  # the shifts fade out at standstill: no creep at rest
    return shifts, lu_longitudinal_coefficients(v_wheel, shifts), lu_lateral_coefficients(v_wheel, shifts)


def pacejka_at_speed(terms, mu_scale, eps, fz, v_lat, v_long, v_wheel, v_roll):
    """:func:`pacejka_forces` from its speed terms (:func:`pacejka_speed_terms` at `v_wheel`)."""
    shifts, (sh_y, b_y, c_y, d_y, e_y), (sh_x, b_x, c_x, d_x, e_x) = terms
    sigma = 1.0 - 2.0 * (v_wheel < 0)
    s = sigma * slip_ratio(v_long, v_wheel, v_roll, eps)
    a = sigma * slip_angle(v_lat, v_wheel, eps)
    mu_long = magic_formula(s + sh_y, b_y, c_y, d_y, e_y)
    mu_lat = magic_formula(a + sh_x, b_x, c_x, d_x, e_x)
    comb = delft_combined(s, a, mu_long, mu_lat, shifts)
    load = -sigma * mu_scale * np.maximum(fz, 0.0)
    return load * comb[0], load * comb[1]


# ---- grips: the largest force each model gives, per component (the semi-implicit step's bound) --------------
def coulomb_grip(mu_lat, mu_long, _k, _p3, fz):
    """Largest ``(|F_lat|, |F_long|)`` of :func:`coulomb_forces`: ``mu Fz`` per component ((7.28) below 1)."""
    return mu_lat * np.maximum(fz, 0.0), mu_long * np.maximum(fz, 0.0)


def dugoff_grip(_cs, _calpha, mu, _eps, fz):
    """Largest ``(|F_lat|, |F_long|)`` of :func:`dugoff_forces`: ``mu Fz`` (its magnitude ``n f / (1 - |s|)`` is
    ``mu Fz (1 - lambda / 2)`` below ``lambda = 1``, at most ``mu Fz / 2`` above)."""
    return mu * np.maximum(fz, 0.0), mu * np.maximum(fz, 0.0)


def pacejka_grip(_shifts, mu_scale, _eps, _p3, fz):
    """Largest ``(|F_lat|, |F_long|)`` of :func:`pacejka_forces` at pure slip: the peaks D of (7.83) and (7.82)
    at standstill, 1.25 and 0.8, times ``mu_scale Fz`` (they fall with speed; the weights (7.84) are 1 at pure
    slip and below it at combined slip but for their small shifts)."""
    load = mu_scale * np.maximum(fz, 0.0)
    return 1.25 * load, 0.8 * load


@dataclass(frozen=True, slots=True)
class TyreKind:
    """A tyre model: its parameters (name -> default, in order) with units, and its force kernel."""

    name: str
    code: int
    params: tuple[tuple[str, float, str], ...]  # (name, default, unit), the kernel's p0, p1, ... in this order
    kernel: Callable
    summary: str
    grip: Callable | None = None  # (p0, p1, p2, p3, fz) -> largest (|F_lat|, |F_long|); None: no limit (linear)

    @property
    def defaults(self) -> dict[str, float]:
        """Parameter defaults by name."""
        return {n: d for n, d, _ in self.params}


TYRES: dict[str, TyreKind] = {
    k.name: k
    for k in (
        TyreKind("linear", 0, (("c_lat", 5e4, "N s/m"), ("c_long", 5e4, "N s/m")), linear_forces,
                 "linear uncoupled friction (7.59), the law under which WLS = MCD"),
        TyreKind("coulomb", 1, (("mu_lat", 0.8, ""), ("mu_long", 0.8, ""), ("k", 50.0, "s/m")), coulomb_forces,
                 "coupled Coulomb friction: ellipse (7.29)-(7.30), smoothed as (7.28)", coulomb_grip),
        TyreKind("dugoff", 2, (("cs", 8e4, "N"), ("calpha", 5e4, "N/rad"), ("mu", 0.8, ""), ("eps", 0.01, "m/s")),
                 dugoff_forces, "Dugoff's tyre: stiffnesses cs, calpha and friction mu", dugoff_grip),
        TyreKind("pacejka", 3, (("shifts", 1.0, ""), ("mu_scale", 1.0, ""), ("eps", 0.01, "m/s")), pacejka_forces,
                 "magic formula with the speed-dependent coefficients and combined slip of appendix 7.A1",
                 pacejka_grip),
    )
}
N_PARAMS = 4


def tyre_kind(name: str) -> TyreKind:
    """The :class:`TyreKind` called `name`, or :class:`UnknownNameError` listing the models."""
    try:
        return TYRES[name]
    except KeyError:
        raise UnknownNameError(f"unknown tyre model '{name}' (models: {', '.join(TYRES)})") from None


#: Parameters that must be > 0 (a friction coefficient of 0 transmits nothing; eps regularises a division);
#: every other one must be >= 0 (a negative stiffness would push with the slip), and ``shifts`` is 0 or 1.
POSITIVE_PARAMS = ("mu", "mu_lat", "mu_long", "eps", "mu_scale")
#: Largest tyre parameter (a stiffness of 1e12 N is rigid; beyond it the forces overflow).
MAX_PARAM = 1e12
#: Largest normal load on one tyre [N] (``wmrkit tyre --load``): a thousand tonnes.
MAX_LOAD = 1e7
#: Highest wheel speed [m/s] of the curves appendix 7.A1 fits (Figs. 7.25-7.26: 1-18 m/s longitudinal, 1-9 m/s
#: lateral; a light-motorcycle tyre, Lu & Shih 2005). Beyond it the speed-dependent coefficients extrapolate, and
#: lose their meaning: the longitudinal peak 0.8 - 0.0021 v reaches 0 at 381 m/s. Evaluated there with a warning.
PACEJKA_FITTED_SPEED = 18.0


def beyond_fit(model: str, speed: float) -> str | None:
    """A warning when `model` ("pacejka") is used at a wheel `speed` [m/s] beyond :data:`PACEJKA_FITTED_SPEED`."""
    if model != "pacejka" or not speed > PACEJKA_FITTED_SPEED:
        return None
    return (f"the pacejka tyre at {speed:.4g} m/s: appendix 7.A1 fits its coefficients to wheel speeds up to "
            f"{PACEJKA_FITTED_SPEED:g} m/s; beyond, they extrapolate (the peak force reaches 0 at 381 m/s)")


def param_problem(name: str, value: float) -> str:
    """Why `value` cannot be tyre parameter `name` (a phrase for a one-line error), or ``""``."""
    if value < 0 or (name in POSITIVE_PARAMS and value == 0):
        return f"must be {'> 0' if name in POSITIVE_PARAMS else '>= 0'}, got {value:g}"
    if name == "shifts" and value not in (0.0, 1.0):
        return f"must be 0 or 1, got {value:g}"
    if name == "eps" and value > 1.0:  # a regularisation speed: above 1 m/s it smooths away the friction of motion
        return f"must be at most 1 m/s (a regularisation speed), got {value:g}"
    if value > MAX_PARAM and not (name == "k" and value == math.inf):
        return f"must be at most {MAX_PARAM:g}, got {value:g}"
    return ""


@dataclass(frozen=True, slots=True)
class Tyre:
    """A wheel's tyre: a model of :data:`TYRES` and its parameters (SI), a frozen hashable value."""

    model: str = "pacejka"
    params: tuple[tuple[str, float], ...] = ()  # every parameter of the model, in the model's order

    def __post_init__(self) -> None:
        """Complete the parameters given (pairs or a mapping) with the model's defaults, in its order, and check
        them: ``Tyre(model, params)`` is :meth:`of` (``Tyre("dugoff")`` had every parameter 0, and no force)."""
        kind = tyre_kind(self.model)
        if isinstance(self.params, str) or not all(isinstance(p, tuple | list) and len(p) == 2 for p in
                                                   (self.params.items() if isinstance(self.params, Mapping) else
                                                    self.params)):  # "mu" raised dict()'s "update sequence element"
            raise ShapeError(f"tyre parameters: expected a mapping {{name: value}} such as {{'mu': 0.8}}, got "
                             f"{self.params!r:.60}")
        pairs = list(self.params.items() if isinstance(self.params, Mapping) else self.params)
        params = dict(pairs)
        if len(params) < len(pairs):
            twice = next(n for j, (n, _) in enumerate(pairs) if n in (m for m, _ in pairs[:j]))
            raise ShapeError(f"tyre parameter '{twice}' given twice")
        unknown = [n for n in params if n not in kind.defaults]
        if unknown:
            raise UnknownNameError(f"tyre model '{self.model}' has no parameter '{unknown[0]}' "
                                   f"(parameters: {', '.join(kind.defaults)})")
        for n, v in params.items():
            if not (real_number(v) or (n == "k" and v == math.inf)):  # k = inf: the discontinuous Coulomb
                raise ShapeError(f"tyre parameter {n} must be a finite number, got {v!r}")  # "0.8" was read
            problem = param_problem(n, float(v))
            if problem:
                raise ShapeError(f"tyre parameter {n}: {problem}")
        object.__setattr__(self, "params", tuple((n, float(params.get(n, d))) for n, d, _ in kind.params))

    @classmethod
    def of(cls, model: str, params: Mapping[str, float] | None = None) -> Tyre:
        """A tyre of `model`; parameters not given take the model's defaults; unknown names raise."""
        return cls(model, params or ())

    @property
    def kind(self) -> TyreKind:
        """The model's :class:`TyreKind`."""
        return tyre_kind(self.model)

    def as_dict(self) -> dict[str, float]:
        """Parameters by name."""
        return dict(self.params)

    def vector(self) -> np.ndarray:
        """The kernel's parameters ``(N_PARAMS,)``, zero-padded."""
        out = np.zeros(N_PARAMS)
        out[:len(self.params)] = [v for _, v in self.params]
        return out

    def forces(self, fz: ArrayLike, v_lat: ArrayLike, v_long: ArrayLike, v_wheel: ArrayLike,
               v_roll: ArrayLike) -> TyreForces:
        """Contact forces from slip velocities [m/s] (finite) and the normal load `fz` [N] (in ``[0, MAX_LOAD]``);
        all broadcast."""
        fz, *slips = _broadcast(fz=fz, v_lat=v_lat, v_long=v_long, v_wheel=v_wheel, v_roll=v_roll)
        bad = ~((fz >= 0) & (fz <= MAX_LOAD))  # NaN included
        if bad.any():
            raise ShapeError(f"fz: expected normal loads in [0, {MAX_LOAD:g}] N, got {fz[bad].flat[0]:g}")
        for name, v in zip(("v_lat", "v_long", "v_wheel", "v_roll"), slips, strict=True):
            if not np.isfinite(v).all():
                raise ShapeError(f"{name}: expected finite velocities [m/s], got {v[~np.isfinite(v)].flat[0]:g}")
        return self._forces(fz, *slips)

    def _forces(self, fz: ArrayLike, v_lat: ArrayLike, v_long: ArrayLike, v_wheel: ArrayLike,
                v_roll: ArrayLike) -> TyreForces:
        """:meth:`forces` without the checks of its arguments (the slip models' inner loops)."""
        p = self.vector()
        args = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (fz, v_lat, v_long, v_wheel, v_roll)))
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # callers check the forces are finite
            f_lat, f_long = self.kind.kernel(*p, *args)
        return TyreForces(np.asarray(f_lat, dtype=float), np.asarray(f_long, dtype=float))

    def grip(self, fz: ArrayLike) -> TyreForces:
        """The largest force components ``(|F_lat|, |F_long|)`` [N] the model gives at normal load `fz` [N] (any
        slip): ``mu Fz`` and the like; infinite for the linear model, which does not saturate. ``(...) -> (...)``."""
        fz = as_reals(fz, "fz")
        if self.kind.grip is None:
            return TyreForces(np.full(fz.shape, np.inf), np.full(fz.shape, np.inf))
        lat, long = self.kind.grip(*self.vector(), fz)
        return TyreForces(np.asarray(lat, dtype=float), np.asarray(long, dtype=float))

    def forces_at_slip(self, fz: ArrayLike, slip_ratio: ArrayLike, slip_angle: ArrayLike,
                       speed: ArrayLike = 2.0) -> TyreForces:
        """Contact forces at a slip ratio, a slip angle [rad] and a wheel speed [m/s] (> 0), all broadcast.

        The slip velocities are rebuilt exactly (see :func:`slip_velocities`) and passed to :meth:`forces`. A model
        with a regularisation speed ``eps`` (dugoff, pacejka) refuses a `speed` below it: there it divides the slip
        by ``eps`` instead of the speed, and the forces would be those of a smaller slip than the one asked.
        """
        v_lat, v_long, v_wheel, v_roll = slip_velocities(slip_ratio, slip_angle, speed)
        eps = self.as_dict().get("eps")
        if eps is not None and np.any(v_wheel < eps):
            raise ShapeError(f"speed: must be at least the {self.model} tyre's eps = {eps:g} m/s, got "
                             f"{v_wheel[v_wheel < eps].flat[0]:g} (below eps the model divides the slip by eps, not "
                             "by the speed: the forces would be those of a smaller slip ratio and angle)")
        return self.forces(fz, v_lat, v_long, v_wheel, v_roll)


def slip_velocities(s: ArrayLike, alpha: ArrayLike, speed: ArrayLike) -> tuple[np.ndarray, ...]:
    """Slip velocities giving slip ratio `s` (> -1) and slip angle `alpha` (|alpha| < pi/2) at wheel `speed` > 0.

    Inverse of :func:`slip_ratio` / :func:`slip_angle`: ``(v_lat, v_long, v_wheel, v_roll)``. For ``s >= 0``
    (braking) ``v_roll = v (s - 1)``; for ``-1 < s < 0`` (driving) ``v_roll = -v / (1 + s)``.
    """
    s, alpha, v = _broadcast(slip_ratio=s, slip_angle=alpha, speed=speed)
    checks = (("slip ratio", s, (s > -1) & (s <= 2), "in (-1, 2]"),
              ("slip angle", alpha, np.abs(alpha) < np.pi / 2, "in (-pi/2, pi/2) rad (-90 to 90 deg)"),
              ("speed", v, (v > 0) & (v <= MAX_SPEED), f"in (0, {MAX_SPEED:g}] m/s"))
    for name, values, ok, allowed in checks:
        if not np.all(ok):
            bad = float(values[~ok].flat[0])  # an angle in degrees too: '--slip-angle 90deg' said "got 1.5708"
            shown = f"{bad:g} rad ({math.degrees(bad):g} deg)" if name == "slip angle" else f"{bad:g}"
            raise ShapeError(f"{name}: must be {allowed}, got {shown}")
    v_roll = np.where(s >= 0, v * (s - 1), -v / (1 + np.minimum(s, 0.0)))  # each branch where it is taken
    return v * np.tan(alpha), v + v_roll, v, v_roll


def _broadcast(**arrays: ArrayLike) -> list[np.ndarray]:
    """The arrays as floats broadcast together, or :class:`ShapeError` naming each one's shape."""
    values = [as_reals(a, name) for name, a in arrays.items()]  # text refused by name ("1000" was read as 1000 N)
    try:
        return list(np.broadcast_arrays(*values))
    except ValueError:
        shapes = ", ".join(f"{name} {a.shape}" for name, a in zip(arrays, values, strict=True))
        raise ShapeError(f"the arguments do not broadcast together: {shapes}") from None
