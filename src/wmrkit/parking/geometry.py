"""Geometry of the parallel-parking planner (thesis §9.3.2.B): the car, the slot, symmetric arcs (9.27)-(9.31).

Units are SI (metres, radians). The thesis's ``d1 ... d4`` (distances from the ICR to the corners, 9.28) clash with
its rear track ``d1``: here the track is :attr:`Vehicle.track` and the corner distances are ``corner_distance``.

Corners are numbered as in Fig. 9.20, relative to the ICR of the arc being driven: 1 rear outer, 2 front outer,
3 rear inner, 4 front inner ("outer" = the side away from the ICR).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

from .._shapes import as_real
from ..errors import WmrkitError


@dataclass(frozen=True, slots=True)
class Vehicle:
    """A car-like vehicle as the planner sees it (Fig. 9.19). Lengths [m], angle [rad].

    ``a1`` rear axle to front end, ``b1`` rear axle to rear end, ``c1`` width, ``h1`` wheelbase (rear axle to the
    equivalent steering wheel), ``track`` rear track (the thesis's d1; drawing and execution only), ``phi_max``
    maximum equivalent steering angle (a heading: 0 = straight ahead). ``P_f``, the point that follows the path,
    is the rear-axle midpoint.
    """

    a1: float
    b1: float
    c1: float
    h1: float
    track: float
    phi_max: float

    def __post_init__(self) -> None:
        for name in ("a1", "b1", "c1", "h1", "track", "phi_max"):
            value = getattr(self, name)
            if isinstance(value, bool) or not (isinstance(value, numbers.Real) and math.isfinite(value)):
                raise WmrkitError(f"vehicle.{name}: must be a finite number, got {value!r}")
            object.__setattr__(self, name, float(value))  # numpy scalars (np.int64(3)) were refused
        for name in ("a1", "c1", "h1"):
            if getattr(self, name) <= 0:
                raise WmrkitError(f"vehicle.{name}: must be > 0, got {getattr(self, name)} m")
        if self.b1 < 0 or self.track < 0:
            raise WmrkitError("vehicle.b1 and vehicle.d1 (track) must be >= 0")
        problem = wheels_outside(self.a1, self.c1, self.h1, self.track)
        if problem is not None:
            raise WmrkitError(f"vehicle.{problem[0]}: {problem[1]}")
        if not 0 < self.phi_max < math.pi / 2:
            raise WmrkitError(f"vehicle.phi_max: must be in (0, 90) deg, got {math.degrees(self.phi_max):.6g} deg")

    @property
    def length(self) -> float:
        """Overall length ``a1 + b1`` [m]."""
        return self.a1 + self.b1

    @property
    def rho_min(self) -> float:
        """Minimum turning radius of P_f, (9.27) at ``phi_max`` [m]."""
        return turning_radius(self.h1, self.phi_max)


def wheels_outside(a1: float, c1: float, h1: float, track: float) -> tuple[str, str] | None:
    """The field and the reason when wheels stand outside the body (front axle ahead of the front end, rear
    wheels wider than the body): the collision checks see the body's corners only, so they would go unchecked."""
    if a1 < h1:
        return "a1", (f"the front end ({a1:g} m from the rear axle) is behind the front axle (h1 = {h1:g} m); the "
                      "planner checks the body's corners only, so the front wheels would go unchecked")
    if track > c1:
        return "d1", (f"the rear wheels ({track:g} m apart) stand outside the body's width (c1 = {c1:g} m); the "
                      "planner checks the body's corners only, so they would go unchecked")
    return None


@dataclass(frozen=True, slots=True)
class Space:
    """The parking space (Fig. 9.18) and the approach. Lengths [m].

    ``H`` length and ``J`` width of the slot, ``MS`` safety margin, ``dx2`` lateral distance from P_f to the
    obstacles' side line during the detection pass, ``final_gap`` the desired final lateral gap to the curb.
    """

    H: float
    J: float
    MS: float
    dx2: float
    final_gap: float

    def __post_init__(self) -> None:
        for name in ("H", "J", "MS", "dx2", "final_gap"):
            value = getattr(self, name)
            if isinstance(value, bool) or not (isinstance(value, numbers.Real) and math.isfinite(value)):
                raise WmrkitError(f"space.{name}: must be a finite number, got {value!r}")
            object.__setattr__(self, name, float(value))
        for name in ("H", "J", "final_gap"):
            if getattr(self, name) <= 0:
                raise WmrkitError(f"space.{name}: must be > 0, got {getattr(self, name)} m")
        for name in ("MS", "dx2"):  # a problem file refused a negative dx2; Space took it
            if getattr(self, name) < 0:
                raise WmrkitError(f"space.{name}: must be >= 0, got {getattr(self, name)} m")
        problem = no_free_length(self.H, self.MS)
        if problem is not None:
            raise WmrkitError(f"space.MS: {problem}")
        problem = gap_too_wide(self.final_gap, self.J)
        if problem is not None:
            raise WmrkitError(f"space.final_gap: {problem}")

    @property
    def effective_length(self) -> float:
        """``H' = H - 2 MS`` [m] (§9.3.2.B)."""
        return self.H - 2 * self.MS


def no_free_length(H: float, MS: float) -> str | None:
    """Why a slot of length `H` with margins `MS` has no free length ``H - 2 MS > 0`` (the length ratio (9.37)
    divides by it), or None."""
    if H - 2 * MS > 0:
        return None
    return (f"the margins at both ends ({2 * MS:g} m) leave nothing of the slot's length H = {H:g} m "
            "(H - 2 MS must be > 0)")


def gap_too_wide(final_gap: float, J: float) -> str | None:
    """Why a desired gap to the curb `final_gap` is not less than the slot's width `J` (any pose in the slot has a
    smaller one: the planner stopped after its first manoeuvre, whatever gap it left), or None."""
    if final_gap < J:
        return None
    return (f"the gap to the curb ({final_gap:g} m) must be less than the slot's width J = {J:g} m (a plain number "
            "is metres: write e.g. '7 cm')")


def turning_radius(h1: float, phi: float) -> float:
    """Turning radius of P_f for an equivalent steering angle `phi`, eq. (9.27): ``rho = h1 / tan(phi)`` [m]."""
    return h1 / math.tan(phi)


def steering_angle(h1: float, curvature: float) -> float:
    """Equivalent steering heading for a path `curvature` [1/m] (left positive), inverse of (9.27) [rad]."""
    return math.atan(h1 * curvature)


def corner_distance(vehicle: Vehicle, rho: float, corner: int) -> float:
    """Distance from the ICR to corner 1-4, eq. (9.28) [m]."""
    along = vehicle.b1 if corner in (1, 3) else vehicle.a1
    across = rho + vehicle.c1 / 2 if corner in (1, 2) else rho - vehicle.c1 / 2
    return math.hypot(along, across)


def corner_angle(vehicle: Vehicle, rho: float, corner: int) -> float:
    """Angle of corner 1-4 seen from the ICR, eq. (9.30), in ``[0, pi]`` (atan2: also for ``rho < c1 / 2``)."""
    along = vehicle.b1 if corner in (1, 3) else vehicle.a1
    across = rho + vehicle.c1 / 2 if corner in (1, 2) else rho - vehicle.c1 / 2
    return math.atan2(along, across)


def arcs_displacement(rho: float, xi: float) -> tuple[float, float, float]:
    """Two symmetric arcs of angle `xi` and radius `rho`, eq. (9.31): ``(X, Y, Z)`` [m].

    ``X`` lateral and ``Y`` longitudinal displacement; ``Z`` lateral coordinate of the second arc's ICR from the
    start point, toward the displacement side (its longitudinal coordinate is ``Y``).
    """
    c = math.cos(xi)
    return 2 * rho * (1 - c), 2 * rho * math.sin(xi), rho * (1 - 2 * c)


def xi_from_longitudinal(Y: float, rho: float) -> float | None:
    """(9.31)b solved for ``xi``: ``asin(Y / (2 rho))``; None when ``Y > 2 rho`` (no such pair of arcs)."""
    s = Y / (2 * rho)
    return math.asin(s) if 0 <= s <= 1 else None


def xi_from_lateral(X: float, rho: float) -> float | None:
    """(9.31)a solved for ``xi``: ``acos(1 - X / (2 rho))``; None when ``X > 4 rho``."""
    c = 1 - X / (2 * rho)
    return math.acos(c) if -1 <= c <= 1 else None


def arcs_through(X: float, Y: float) -> tuple[float, float]:
    """(9.31)a and b solved together for ``(rho, xi)`` given ``X > 0`` and ``Y > 0``: ``xi = 2 atan(X / Y)``."""
    xi = 2 * math.atan2(X, Y)
    return (X * X + Y * Y) / (4 * X), xi


def check_problem(vehicle: object, *space: object) -> None:
    """:class:`WmrkitError` naming `vehicle` or `space` unless they are a :class:`Vehicle` and (when given) a
    :class:`Space`: a problem's name or a dict raised AttributeError ('str' object has no attribute 'phi_max')."""
    for name, value, kind, fields in (("vehicle", vehicle, Vehicle, "a1, b1, c1, h1, track, phi_max"),
                                      *(("space", s, Space, "H, J, MS, dx2, final_gap") for s in space)):
        if not isinstance(value, kind):
            raise WmrkitError(f"{name}: expected a wmrkit.parking.{kind.__name__}({fields}), got "
                              f"{type(value).__name__} {value!r:.60}")


def length_ratio(vehicle: Vehicle, space: Space) -> float:
    """Free longitudinal space as a fraction, eq. (9.37) over 100: ``((H - 2 MS) - (a1 + b1)) / (H - 2 MS)`` (the
    thesis gives it in percent)."""
    check_problem(vehicle, space)
    free = space.effective_length
    return (free - vehicle.length) / free


def blackburn_min_length(vehicle: Vehicle, rho: float | None = None) -> float:
    """Shortest slot a car enters in one reverse manoeuvre, in closed form (Blackburn 2009) [m].

    The last arc turns about an ICR on the road side at ``rho`` (default ``rho_min``) from P_f; the front outer
    corner sweeps the circle of radius ``sqrt(a1^2 + (rho + c1/2)^2)`` (9.28, d2) about it, and the obstacle's
    corner, level with the car's road side at the end, must stay outside it. With the car's side line at
    ``rho - c1/2`` from the ICR this gives ``dx^2 >= a1^2 + 2 rho c1`` from the final rear axle to that corner,
    so ``H_min = b1 + sqrt(a1^2 + 2 rho c1)``, Blackburn's "sqrt((r + w)^2 - r^2 + (l + k)^2)" with the inner
    radius ``r = rho - c1/2``, width ``w = c1`` and ``l + k = a1``. No margins, no final gap. Valid for
    ``rho >= c1/2`` (ICR outside the body); the default is ``max(rho_min, c1/2)``, the tightest turn the planner
    uses (Algorithm 1).

    S. Blackburn, "The geometry of perfect parking", Royal Holloway, University of London (2009).
    """
    check_problem(vehicle)
    rho = max(vehicle.rho_min, vehicle.c1 / 2) if rho is None else as_real(rho, "rho")  # '1': a bare TypeError
    if not rho >= vehicle.c1 / 2 or not math.isfinite(rho):  # NaN included
        raise WmrkitError(f"blackburn_min_length: rho = {rho:.6g} m: a finite radius >= c1/2 (an ICR outside the "
                          "body) is needed")
    return vehicle.b1 + math.sqrt(vehicle.a1**2 + 2 * rho * vehicle.c1)


def footprint(vehicle: Vehicle) -> tuple[tuple[float, float], ...]:
    """The body's corners in the vehicle frame (x forward, y left, origin P_f), counter-clockwise [m]."""
    a, b, h = vehicle.a1, vehicle.b1, vehicle.c1 / 2
    return ((-b, -h), (a, -h), (a, h), (-b, h))
