"""The generic wheel (thesis ch. 3): parameters, slip rows (3.5)/(3.6)/(3.10), Jacobians (3.16)-(3.19).

One kernel, :func:`generic_slip_rows`, serves every wheel type. A wheel is described by the thesis's
parameters (``l, alpha, beta, d, delta, gamma, r, r_r``; see ``docs/conventions.md``) and expands into one or
two *contact elements*: generic wheels whose variables ``(beta_dot, phi_dot, phi_dot_r)`` are linear maps of
the wheel's own joint rates. Fixed, steerable, castor and Swedish wheels have one element; the double wheel and
the double castor (§3.5.1) are two castors that share the steering joint (3.24), (3.31); the ball and the
orthogonal wheel (§3.5.2-3.5.3) are Swedish-equivalent wheels with ``gamma = 90 deg`` and ``r_r = r``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from ._shapes import as_angle_array, as_angles, finite_number
from .errors import UnknownNameError, WmrkitError
from .units import MAX_ANGLE, MAX_TURNS

if TYPE_CHECKING:
    from .dynamics.tyres import Tyre

HALF_PI = math.pi / 2


@dataclass(frozen=True, slots=True)
class WheelKind:
    """What a wheel type is: its joint rates (velocity-vector columns), joints and fields."""

    name: str
    rates: tuple[str, ...]  # joint rates that enter the slip equations, in column order
    joints: tuple[str, ...]  # joints that may be actuated or sensed
    steers: bool  # its steering angle beta is a configuration variable
    required: tuple[str, ...]  # geometric fields that must be given (besides the position)
    optional: dict[str, float] = field(default_factory=dict)  # fields with their default
    summary: str = ""


KINDS: dict[str, WheelKind] = {
    k.name: k
    for k in (
        WheelKind("fixed", ("spin",), ("spin",), False, ("beta", "r"),
                  summary="conventional wheel with a fixed axle (3.11)"),
        WheelKind("steerable", ("spin",), ("spin", "steer"), True, ("r",), {"beta": 0.0},
                  summary="centred orientable wheel: steering axis through the wheel centre (3.11)"),
        WheelKind("castor", ("steer", "spin"), ("steer", "spin"), True, ("d", "r"), {"beta": 0.0, "delta": 0.0},
                  summary="off-centred orientable wheel, offset d along the steering arm (3.12)"),
        WheelKind("swedish", ("spin", "roller"), ("spin",), False, ("beta", "gamma", "r", "r_r"),
                  summary="Swedish/Mecanum/omni wheel, rollers at angle gamma to the axle (3.13)"),
        WheelKind("double", ("steer", "spin1", "spin2"), ("steer", "spin1", "spin2"), True, ("b", "r"),
                  {"beta": 0.0},
                  summary="two coaxial wheels at +-b about a centred steering axis (3.24)-(3.30)"),
        WheelKind("double_castor", ("steer", "spin1", "spin2"), ("steer", "spin1", "spin2"), True,
                  ("d", "b", "r"), {"beta": 0.0},
                  summary="two coaxial wheels at +-b, trailing the steering axis by d (3.31)-(3.37)"),
        WheelKind("ball", ("spin", "roller"), ("spin",), False, ("beta", "r"),
                  summary="driven sphere; Swedish-equivalent with gamma = 90 deg, r_r = r (§3.5.2)"),
        WheelKind("orthogonal", ("spin", "roller"), ("spin",), False, ("beta", "r"),
                  summary="orthogonal wheel (lateral assembly); Swedish-equivalent, gamma = 90 deg (§3.5.3)"),
    )
}

#: Geometric fields of a wheel, with their kind of quantity.
GEOMETRY_FIELDS: dict[str, str] = {
    "l": "length", "alpha": "angle", "beta": "angle", "d": "length", "delta": "angle",
    "gamma": "angle", "r": "length", "r_r": "length", "b": "length",
}


class WheelError(WmrkitError, ValueError):
    """A wheel built in Python (not read from a description) that the wheel model cannot use; names the field."""


def geometry_problem(type_name: str, v: dict[str, float], *, degenerate: bool = True) -> tuple[str, str] | None:
    """The first geometric field of a wheel of `type_name` (values `v`, SI) that the model cannot use, with why;
    None when all can be used. Descriptions and :class:`Wheel` ask the same question; a :class:`Wheel` built in
    Python may be degenerate (`degenerate=False`: a castor without offset, Swedish rollers along the axle; their
    slip rows (3.12)/(3.13) exist, their Jacobians (3.19) are singular), a description may not. Neither may have
    Swedish rollers larger than the wheel (r_r > r): they sit on its rim."""
    if v.get("l", 0.0) < 0:
        return "l", f"must be >= 0 (the direction is alpha), got {v['l']} m"
    for key in ("r", "r_r", "b"):
        if key in v and v[key] <= 0:
            return key, f"must be > 0, got {v[key]} m"
    if type_name == "swedish" and v["r_r"] > v["r"]:
        return "r_r", (f"a roller sits on the wheel's rim: its radius is at most the wheel's r = {v['r']:g} m "
                       f"(r_r = r: a ball wheel), got {v['r_r']:g} m")
    if not degenerate:
        return None
    if type_name in ("castor", "double_castor") and v["d"] == 0:
        other = "steerable" if type_name == "castor" else "double"
        return "d", f"a {type_name} needs an offset d != 0 (with d = 0 it is a '{other}' wheel)"
    if type_name == "castor" and abs(math.cos(v["delta"])) < 1e-9:
        return "delta", ("a castor with delta = +-90 deg has its axle along the arm and cannot steer itself "
                         "(det J_c = -r d cos(delta) = 0, eq. 3.19)")
    if type_name == "swedish" and abs(math.sin(v["gamma"])) < 1e-9:
        return "gamma", ("a Swedish wheel with gamma = 0 (or 180 deg) has rollers parallel to the axle and does not "
                         "roll (det J_s = r r_r sin(gamma) = 0, eq. 3.19); omni: 90 deg, Mecanum: 45 deg")
    return None


@dataclass(frozen=True, slots=True)
class Wheel:
    """One wheel (or wheel unit) of a robot. A frozen value in SI units (m, rad).

    ``l, alpha``: polar coordinates of the steering joint (or mount point) in the robot frame (3.8).
    ``beta``: absolute angle of the axle (fixed, Swedish, ball, orthogonal, double) or of the steering frame
    S_x (steerable: equal to the axle; castor: axle at ``beta + delta``). ``d``: castor offset along S_y.
    ``gamma``: roller angle from the axle. ``r``, ``r_r``: wheel and roller radii. ``b``: half the spacing of a
    double wheel or double castor. ``actuated``/``sensed``: names of the wheel's joints (``spin``, ``steer``...).
    """

    name: str
    type: str
    l: float
    alpha: float
    beta: float
    r: float
    d: float = 0.0
    delta: float = 0.0
    gamma: float = 0.0
    r_r: float = 0.0
    b: float = 0.0
    actuated: tuple[str, ...] = ()
    sensed: tuple[str, ...] = ()
    # dynamics (thesis Table 7.2; wmrkit.dynamics.mass): inertias [kg m^2] about the axle, the steering axis and the
    # roller axis, the mass [kg] of a castor unit, and the tyre model; zero / None when not described
    spin_inertia: float = 0.0
    steer_inertia: float = 0.0
    roller_inertia: float = 0.0
    mass: float = 0.0
    tyre: Tyre | None = None
    # steering range (wmrkit.control, thesis §8.4.1/§8.6.3): (min, max) HEADING [rad] the steering joint reaches,
    # e.g. (-pi/2, pi/2) for the forklift; None: unlimited
    steer_range: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        kind = KINDS.get(self.type)
        if kind is None:
            raise WheelError(f"wheel '{self.name}': unknown type {self.type!r} (types: {', '.join(KINDS)})")
        for key in ("actuated", "sensed"):  # a string here was read letter by letter: 'left.s', 'left.p', ...
            problem = _joints_problem(getattr(self, key), kind)
            if problem is not None:
                raise WheelError(f"wheel '{self.name}': {key}: {problem}")
        if self.steer_range is not None:
            _check_steer_range(self, kind)
        values = self.geometry()
        if any(hasattr(v, "free_symbols") for v in values.values()):
            return  # symbolic parameters (SymPy, wmrkit.kinematics.symbolic): no numbers to check
        for key, value in values.items():
            if isinstance(value, bool) or not finite_number(value):
                raise WheelError(f"wheel '{self.name}': {key}: expected a finite number, got {value!r}")
            if GEOMETRY_FIELDS[key] == "angle" and abs(value) > MAX_ANGLE:  # as descriptions and with_beta refuse
                raise WheelError(f"wheel '{self.name}': {key}: expected an angle of at most {MAX_TURNS:g} turns [rad], "
                                 f"got {value!r}")
        problem = geometry_problem(self.type, values, degenerate=False)
        if problem is not None:
            raise WheelError(f"wheel '{self.name}': {problem[0]}: {problem[1]}")

    @property
    def kind(self) -> WheelKind:
        """The :class:`WheelKind` of this wheel's type."""
        return KINDS[self.type]

    def geometry(self) -> dict[str, float]:
        """The geometric fields of this wheel's type by name (``l``, ``alpha`` and the type's own), as
        :func:`geometry_problem` takes them."""
        kind = self.kind
        return {key: getattr(self, key) for key in ("l", "alpha", *kind.required, *kind.optional)}

    @property
    def position(self) -> tuple[float, float]:
        """``(x, y)`` of the steering joint / mount point in the robot frame [m]."""
        return (self.l * math.cos(self.alpha), self.l * math.sin(self.alpha))

    @property
    def rate_names(self) -> tuple[str, ...]:
        """Qualified names ``wheel.joint`` of this wheel's rates in the velocity vector."""
        return tuple(f"{self.name}.{j}" for j in self.kind.rates)

    @property
    def heading(self) -> float:
        """Rolling direction [rad] in (-pi, pi]: where the robot moves when the wheel spins forward, 0 = +x.

        The users' steering angle (WPILib, ROS 2, Ackermann texts); ``beta + delta - pi/2``, see
        :func:`heading_from_beta`.
        """
        return float(heading_from_beta(self.beta, self.delta))

    def with_beta(self, beta: float) -> Wheel:
        """The same wheel at another steering angle (or axle direction)."""
        return replace(self, beta=float(as_angles([beta], 1, f"{self.name}: beta")[0]))

    def with_heading(self, heading: float) -> Wheel:
        """The same wheel steered to rolling direction `heading` [rad] (0 = forward along +x)."""
        heading = as_angles([heading], 1, f"{self.name}: heading")[0]
        limit = heading_limit(self.delta)
        if not abs(heading) <= limit:  # within as_angles' limit, its beta (or -heading's) not: named as given
            raise WheelError(f"wheel '{self.name}': heading: {heading / (2 * math.pi):.10g} turns is beyond "
                             f"+-{limit / (2 * math.pi):.10g} turns, where the thesis's beta (heading - delta + 90 "
                             f"deg) of one sign reaches the limit of every angle, {MAX_TURNS:g} turns (no angle to "
                             "steer by)")
        return replace(self, beta=float(beta_from_heading(heading, self.delta)))

    def elements(self) -> tuple[Element, ...]:
        """The contact elements this wheel expands into (see module docstring)."""
        return _ELEMENTS[self.type](self)


def _check_steer_range(wheel: Wheel, kind: WheelKind) -> None:
    """``steer_range`` as a description has it (``_description_wheels._steer_range_from_dict``): on a wheel that
    steers, a tuple ``(min, max)`` of headings [rad], min < max within one turn."""
    lo_hi = wheel.steer_range
    where = f"wheel '{wheel.name}': steer_range"
    if not kind.steers:
        raise WheelError(f"{where}: a {kind.name} wheel does not steer")
    if not (isinstance(lo_hi, tuple) and len(lo_hi) == 2 and all(finite_number(v) for v in lo_hi)
            and -2 * math.pi <= lo_hi[0] < lo_hi[1] <= 2 * math.pi and lo_hi[1] - lo_hi[0] <= 2 * math.pi):
        raise WheelError(f"{where}: must be a tuple (min, max) of headings, min < max within one turn [rad], got "
                         f"{lo_hi!r}")


def _joints_problem(joints: object, kind: WheelKind) -> str | None:
    """Why `joints` (a wheel's ``actuated`` or ``sensed``) is no tuple of distinct joints of `kind`; None if it is."""
    if not isinstance(joints, tuple) or not all(isinstance(j, str) for j in joints):
        return f"expected a tuple of joint names ({', '.join(kind.joints)}), got {joints!r}"
    for i, joint in enumerate(joints):
        if joint not in kind.joints:
            return f"no joint '{joint}' on a {kind.name} wheel (joints: {', '.join(kind.joints)})"
        if joint in joints[:i]:
            return f"joint '{joint}' listed twice"
    return None


class Element(NamedTuple):
    """A generic wheel (3.8) standing for one contact point of a wheel unit.

    ``beta_offset`` is added to the unit's beta; ``rate_map`` (3, n_rates) maps the unit's joint rates to the
    element's ``(beta_dot, phi_dot, phi_dot_r)``.
    """

    l: float
    alpha: float
    beta_offset: float
    d: float
    delta: float
    gamma: float
    r: float
    r_r: float
    rate_map: tuple[tuple[float, ...], ...]


def _single(w: Wheel, d: float, delta: float, gamma: float, r_r: float, rate_map) -> tuple[Element, ...]:
    return (Element(w.l, w.alpha, 0.0, d, delta, gamma, w.r, r_r, rate_map),)


def _double(w: Wheel) -> tuple[Element, ...]:
    # (3.24) corrected: steering frame at beta + 90 deg so that the common axle is at beta; delta = -90 deg,
    # sub-wheel 1 at d = -b (which puts it at +b along the axle), sub-wheel 2 at d = +b.
    return (
        Element(w.l, w.alpha, HALF_PI, -w.b, -HALF_PI, 0.0, w.r, 0.0, ((1, 0, 0), (0, 1, 0), (0, 0, 0))),
        Element(w.l, w.alpha, HALF_PI, w.b, -HALF_PI, 0.0, w.r, 0.0, ((1, 0, 0), (0, 0, 1), (0, 0, 0))),
    )


def _double_castor(w: Wheel, arm=None, skew=None) -> tuple[Element, ...]:
    # (3.31): beta_i = beta_ik + delta_ik, d_ik = sqrt(a^2 + b^2), delta_i1 = -delta_i2 = atan(b / a), a = d.
    # atan2 extends atan(b/a) to a leading wheel (a < 0): sub-wheel 1 stays at +b along the axle. The closed forms
    # pass their own exact `arm` and `skew` (kinematics._symbolic_matrix).
    if arm is None:
        arm, skew = math.hypot(w.d, w.b), math.atan2(w.b, w.d)
    return (
        Element(w.l, w.alpha, -skew, arm, skew, 0.0, w.r, 0.0, ((1, 0, 0), (0, 1, 0), (0, 0, 0))),
        Element(w.l, w.alpha, skew, arm, -skew, 0.0, w.r, 0.0, ((1, 0, 0), (0, 0, 1), (0, 0, 0))),
    )


_SPIN = ((0,), (1,), (0,))
_ELEMENTS = {
    "fixed": lambda w: _single(w, 0.0, 0.0, 0.0, 0.0, _SPIN),
    "steerable": lambda w: _single(w, 0.0, 0.0, 0.0, 0.0, _SPIN),
    "castor": lambda w: _single(w, w.d, w.delta, 0.0, 0.0, ((1, 0), (0, 1), (0, 0))),
    "swedish": lambda w: _single(w, 0.0, 0.0, w.gamma, w.r_r, ((0, 0), (1, 0), (0, 1))),
    "ball": lambda w: _single(w, 0.0, 0.0, HALF_PI, w.r, ((0, 0), (1, 0), (0, 1))),
    "orthogonal": lambda w: _single(w, 0.0, 0.0, HALF_PI, w.r, ((0, 0), (1, 0), (0, 1))),
    "double": _double,
    "double_castor": _double_castor,
}


def wrap_angle(angle: ArrayLike) -> np.ndarray:
    """Angles wrapped to ``(-pi, pi]`` [rad]; exact (no rounding) for angles already in range. ``(...) -> (...)``."""
    a = np.asarray(angle, dtype=float)
    y = a - 2 * math.pi * np.rint(a / (2 * math.pi))  # np.round's own ufunc (halves to even), without its wrapper
    return np.where(y <= -math.pi, y + 2 * math.pi, np.where(y > math.pi, y - 2 * math.pi, y))


def heading_in_range(heading: ArrayLike, lo: ArrayLike, hi: ArrayLike, tol: float = 1e-12) -> np.ndarray:
    """Whether each `heading` [rad] lies in the steering range ``[lo, hi]`` (a ``steer_range``, counter-clockwise
    from `lo`, any turn of the heading), within `tol`; an infinite end means no range. ``(...) -> (...)`` bool."""
    h, lo, hi = (np.asarray(x, dtype=float) for x in (heading, lo, hi))
    full = ~np.isfinite(lo) | ~np.isfinite(hi)
    lo_, width = np.where(full, 0.0, lo), np.where(full, 0.0, hi - lo)
    off = np.mod(h - lo_ + tol, 2 * np.pi) - tol  # how far past lo, counter-clockwise, in [-tol, 2 pi - tol)
    return full | (off <= width + tol)


def heading_from_beta(beta: ArrayLike, delta: ArrayLike = 0.0) -> np.ndarray:
    """The users' steering angle from the thesis's: ``heading = beta + delta - pi/2``, wrapped to (-pi, pi].

    The thesis's β is the angle of the steering frame S_x; the axle lies at ``beta + delta`` and a forward spin
    moves the robot along ``-L_y``, the axle turned by -90 deg (``docs/conventions.md``). So a wheel whose axle
    points left (β = 90°) has heading 0: it rolls straight ahead. For a castor the heading is the direction the
    wheel itself rolls (its arm trails behind the steering joint at heading 0 when d > 0). ``(...) -> (...)``.
    """
    return wrap_angle(np.asarray(beta, dtype=float) + delta - HALF_PI)


def beta_from_heading(heading: ArrayLike, delta: ArrayLike = 0.0) -> np.ndarray:
    """The thesis's β from the users' heading: ``beta = heading - delta + pi/2`` (not wrapped). ``(...) -> (...)``."""
    return np.asarray(heading, dtype=float) - delta + HALF_PI


def heading_limit(delta: float | np.ndarray) -> float | np.ndarray:
    """Largest ``|heading|`` [rad] a wheel of offset `delta` takes, ``MAX_ANGLE - |pi/2 - delta|``: where the
    thesis's β of a heading of one sign or the other (``heading - delta + pi/2``) reaches the limit of every angle.
    ``(...) -> (...)``. Symmetric: -1e6 turns was taken (an ICR 3.5e9 m away, round-off) where +1e6 was refused."""
    return MAX_ANGLE - abs(HALF_PI - delta)  # abs: a float stays a float, an array an array


def slip_row_entries(beta, l, alpha, d, delta, gamma, r, r_r, sin=np.sin, cos=np.cos):
    """Entries of the generic slip rows (3.10) for any backend: numpy arrays, sympy symbols, floats.

    Returns two rows of six entries, columns ``(v_x, v_y, omega, beta_dot, phi_dot, phi_dot_r)``.
    """
    theta = beta + delta + gamma  # ^R theta_E = beta + delta + gamma (3.8)
    c, s, cdg, sdg = cos(theta), sin(theta), cos(delta + gamma), sin(delta + gamma)
    return (
        (c, s, l * sin(theta - alpha) - d * cdg, -d * cdg, r * sin(gamma), 0 * r_r),
        (-s, c, l * cos(theta - alpha) + d * sdg, d * sdg, r * cos(gamma), r_r),
    )


def jacobian_entries(beta, l, alpha, d, delta, gamma, r, r_r, sin=np.sin, cos=np.cos):
    """Entries of the generic wheel Jacobian (3.16)-(3.17) for any backend.

    Three rows of four entries, columns ``(beta_dot, phi_dot, phi_dot_r, omega)``.
    """
    theta = beta + delta + gamma
    cb, sb = cos(beta), sin(beta)
    return (
        (d * cb, r * sin(beta + delta), r_r * sin(theta), l * sin(alpha) + d * cb),
        (d * sb, -r * cos(beta + delta), -r_r * cos(theta), -l * cos(alpha) + d * sb),
        (0 * r, 0 * r, 0 * r, 0 * r + 1),
    )


def _fill(entries, shape: tuple[int, ...]) -> np.ndarray:
    out = np.empty((*shape, len(entries), len(entries[0])))
    for i, row in enumerate(entries):
        for j, value in enumerate(row):
            out[..., i, j] = value
    return out


def generic_slip_rows(
    beta: ArrayLike, l: ArrayLike, alpha: ArrayLike, d: ArrayLike, delta: ArrayLike,
    gamma: ArrayLike, r: ArrayLike, r_r: ArrayLike,
) -> np.ndarray:
    """Slip rows of the generic wheel along the roller axes (frame E-bar), thesis eqs. (3.6), (3.10).

    ``(...) -> (..., 2, 6)``: all arguments broadcast; columns ``(v_x, v_y, omega, beta_dot, phi_dot,
    phi_dot_r)``. ``v_slip = rows @ (twist_robot; beta_dot; phi_dot; phi_dot_r)`` [m/s]. Row 0 is the slip
    along the roller axis E_x, row 1 across it. With ``d = delta = gamma = r_r = 0`` these are the rows
    (3.11) of a fixed wheel: row 0 the lateral constraint, row 1 the rolling constraint.
    """
    args = [np.asarray(a, dtype=float) for a in (beta, l, alpha, d, delta, gamma, r, r_r)]
    return _fill(slip_row_entries(*args), np.broadcast_shapes(*(a.shape for a in args)))


def rotate_rows_to_robot(rows: ArrayLike, theta: ArrayLike) -> np.ndarray:
    """Slip rows in the robot-coincident frame R-bar, eq. (3.5): ``Rot(theta) @ rows``, theta = beta+delta+gamma.

    ``(..., 2, k), (...) -> (..., 2, k)``. Inverse of (3.6): ``v_slip,E = Rot(-theta) v_slip,R`` (3.7).
    """
    rows, theta = np.asarray(rows, dtype=float), np.asarray(theta, dtype=float)
    c, s = np.cos(theta)[..., None], np.sin(theta)[..., None]
    return np.stack([c * rows[..., 0, :] - s * rows[..., 1, :], s * rows[..., 0, :] + c * rows[..., 1, :]], -2)


def generic_wheel_jacobian(
    beta: ArrayLike, l: ArrayLike, alpha: ArrayLike, d: ArrayLike, delta: ArrayLike,
    gamma: ArrayLike, r: ArrayLike, r_r: ArrayLike,
) -> np.ndarray:
    """Wheel Jacobian of the generic wheel with zero slip, thesis eqs. (3.16)-(3.17).

    ``(...) -> (..., 3, 4)``: ``twist_robot = J @ (beta_dot, phi_dot, phi_dot_r, omega)``. The columns of the
    joints a type lacks are zero; keeping the non-zero ones gives the per-type matrices (3.19).
    """
    args = [np.asarray(a, dtype=float) for a in (beta, l, alpha, d, delta, gamma, r, r_r)]
    return _fill(jacobian_entries(*args), np.broadcast_shapes(*(a.shape for a in args)))


def wheel_slip_rows(wheel: Wheel, beta: ArrayLike | None = None) -> np.ndarray:
    """Slip rows (3.6) of one wheel over ``(twist; the wheel's own rates)``, eqs. (3.11)-(3.13).

    ``(...) -> (..., 2 * n_elements, 3 + n_rates)``; `beta` defaults to the wheel's own.
    """
    beta = np.asarray(wheel.beta if beta is None else as_angle_array(beta, f"{wheel.name}: beta"), dtype=float)
    blocks = []
    for e in wheel.elements():
        g = generic_slip_rows(beta + e.beta_offset, e.l, e.alpha, e.d, e.delta, e.gamma, e.r, e.r_r)
        blocks.append(np.concatenate([g[..., :3], g[..., 3:] @ np.asarray(e.rate_map, dtype=float)], -1))
    return np.concatenate(blocks, axis=-2)


def wheel_jacobian(wheel: Wheel, beta: ArrayLike | None = None) -> np.ndarray:
    """Jacobian (3.19) of a one-element wheel: ``twist_robot = J @ (the wheel's rates; omega)``.

    ``(...) -> (..., 3, n_rates + 1)``. Fixed/steerable: ``(phi_dot, omega)``; castor: ``(beta_dot, phi_dot,
    omega)``; Swedish, ball, orthogonal: ``(phi_dot, phi_dot_r, omega)``. Double wheels have two contact points
    and no single Jacobian: use :meth:`wmrkit.Robot.jacobian_form`.
    """
    elements = wheel.elements()
    if len(elements) != 1:
        raise UnknownNameError(
            f"wheel '{wheel.name}' ({wheel.type}) has {len(elements)} contact points and no single Jacobian; "
            "use Robot.jacobian_form"
        )
    e = elements[0]
    beta = np.asarray(wheel.beta if beta is None else as_angle_array(beta, f"{wheel.name}: beta"), dtype=float)
    j = generic_wheel_jacobian(beta + e.beta_offset, e.l, e.alpha, e.d, e.delta, e.gamma, e.r, e.r_r)
    return np.concatenate([j[..., :3] @ np.asarray(e.rate_map, dtype=float), j[..., 3:]], -1)


def kind_of(type_name: str) -> WheelKind:
    """The :class:`WheelKind` named `type_name`, or :class:`UnknownNameError`."""
    try:
        return KINDS[type_name]
    except KeyError:
        raise UnknownNameError(f"unknown wheel type '{type_name}' (types: {', '.join(KINDS)})") from None
